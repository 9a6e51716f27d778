"""The frozen, validated configuration of one training run, loaded from TOML.

A config file holds the flat fields of :class:`TrainConfig` plus three tables,
``[env]`` (arguments of ``surveillance_v1.parallel_env``), ``[policy_kwargs]`` (extra
SB3 policy arguments) and ``[algo_kwargs]`` (extra SB3 algorithm arguments)::

    role = "pursuer"
    opponent = "evader/straight"
    map = "open_room"
    algo = "ppo"
    total_timesteps = 100_000
    seed = 0
    output_dir = "out/training/ppo_pursuer_vs_straight_open_room"

    [env]
    max_cycles = 200

    [algo_kwargs]
    n_steps = 512

Every bad value raises :class:`~envs.errors.InvalidConfigError` naming the field, the
value and what was expected.
"""

from __future__ import annotations

import dataclasses
import inspect
import math
import os
import sys
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10 reads TOML with the tomli backport
    import tomli as tomllib

from envs import validation
from envs.errors import InvalidConfigError, UnknownNameError
from envs.surveillance.config import EnvConfig, env_parameters
from strategies.policies.base import check_role
from strategies.policies.model_files import absolute_model_name, model_policy_name
from training.single_agent import START_CHOICES

__all__ = [
    "ALGORITHMS",
    "MAX_SEED",
    "TrainConfig",
    "absolute_map_name",
    "check_same_maps",
    "load_any_config",
    "load_config",
    "map_fingerprints",
]

ALGORITHMS = ("ppo", "sac")
"""The SB3 algorithms :func:`training.train` runs (continuous actions)."""

MAX_SEED = 2**31 - 1
"""The largest training seed. SB3 seeds numpy's legacy generator, which takes seeds below
2**32 (a larger one was a ``ValueError`` traceback from ``_legacy_seeding`` once the run
had started); a resumed run reseeds from ``seed + timesteps done`` and self-play's stage
``i`` from ``seed + i``, so half the range is kept for those."""

_ENV_KEYS = tuple(k for k in env_parameters() if k not in ("map", "render_mode"))
"""Keys allowed in ``[env]`` (``map`` and ``render_mode`` are not: see the fields)."""

_ALGO_MANAGED = {
    "policy",
    "env",
    "learning_rate",
    "gamma",
    "batch_size",
    "n_steps",
    "policy_kwargs",
    "seed",
    "device",
    "verbose",
    "tensorboard_log",
    "_init_setup_model",
}
"""SB3 constructor arguments set from dedicated fields, so not allowed in ``algo_kwargs``."""


def absolute_map_name(name: str) -> str:
    """``name`` as a run from another directory resolves it: a map file's path made
    absolute (also before a ``~[xS][rotR][off(X,Y)]`` transform); built-in and
    ``random:`` names, and names that are none of these (refused later), as they are.

    Examples:
        >>> absolute_map_name("corner~x10")
        'corner~x10'
    """
    from envs.maps import builtin_names
    from envs.maps.io import split_transform

    if name in builtin_names() or name.startswith("random:"):
        return name
    if Path(name).is_file():
        return str(Path(name).resolve())
    try:
        inner, sim = split_transform(name)
    except ValueError:  # a bad transform: refused with the env's message
        return name
    return name if sim is None else absolute_map_name(inner) + name[len(inner) :]


def opponent_name(name: str, role: str, what: str) -> str:
    """The registry's name of an opponent as a config names it (:func:`model_policy_name`:
    a model as ``zoo:NAME`` or a ``.zip``, checked), a registered name checked too: a
    misspelt one is refused here, as a field of the config (its file named by
    :func:`load_config`), not when the first env is built.

    Raises:
        InvalidConfigError: no such policy or model, or a model of the other role (the
            message starts with ``what``).
    """
    resolved = model_policy_name(name, role, what)
    if resolved == name and not name.partition("/")[2].startswith("sb3:"):
        from strategies.policies.registry import policy_spec

        try:
            policy_spec(name)
        except UnknownNameError as exc:
            raise InvalidConfigError(f"{what}: {exc}") from None
    return resolved


@dataclass(frozen=True)
class TrainConfig:
    """One SB3 training run of one role against a fixed opponent."""

    role: str
    """The learner's role: ``"pursuer"`` or ``"evader"``."""
    opponent: str | tuple[str, ...]
    """The other role's policy name (``"evader/straight"``, ``"pursuer/sb3:PATH"``...), a
    model as ``surveil play`` takes one (``"zoo:NAME"``, a ``.zip`` path relative to the
    current directory, kept as its absolute path), or several: a pool
    (:class:`training.pool.OpponentPool`), one drawn per episode."""
    map: str | tuple[str, ...] = "open_room"
    """Built-in map name, map file path or ``random:SEED``; or several, one per episode.
    A file's path is relative to the current directory and kept absolute
    (:func:`absolute_map_name`), as an opponent model's is."""
    env: dict[str, Any] = field(default_factory=dict)
    """Overrides of ``surveillance_v1.parallel_env`` arguments (``max_cycles``, ...)."""
    start: str = "env"
    """Training starts: ``"env"`` (env sampler), ``"valid"`` or ``"safe"`` (sample_start)."""
    algo: str = "ppo"
    """``"ppo"`` or ``"sac"``."""
    total_timesteps: int = 100_000
    """Environment steps to train for, summed over the ``n_envs`` copies."""
    seed: int = 0
    """Seeds the model, the vector env and (through it) starts and opponents."""
    n_envs: int = 1
    """Copies of the env in the ``DummyVecEnv``."""
    net_arch: tuple[int, ...] = (64, 64)
    """Hidden layer sizes of the actor and the critic MLPs."""
    policy_kwargs: dict[str, Any] = field(default_factory=dict)
    """Other policy constructor arguments (``log_std_init``, ``ortho_init``...)."""
    learning_rate: float = 3e-4
    """Adam learning rate."""
    gamma: float = 0.99
    """Discount factor."""
    batch_size: int = 64
    """Minibatch size (PPO) or replay sample size (SAC)."""
    n_steps: int = 512
    """PPO rollout length per env (ignored by SAC)."""
    algo_kwargs: dict[str, Any] = field(default_factory=dict)
    """Other keyword arguments of the SB3 algorithm (``ent_coef``, ``n_epochs``...)."""
    checkpoint_freq: int = 10_000
    """Write a checkpoint every this many timesteps (resume point after interruption)."""
    eval_episodes: int = 20
    """Episodes of the final evaluation against ``opponent`` (0: skip)."""
    eval_start: str = "safe"
    """Starts of the final evaluation (``"env"``, ``"valid"``, ``"safe"``)."""
    output_dir: str = "out/training/run"
    """Directory for checkpoints, ``model.zip`` and ``provenance.json``."""
    opponent_weights: tuple[float, ...] = ()
    """Weights of the pool's members (empty: uniform), e.g. a Nash mixture (PSRO)."""

    def __post_init__(self) -> None:
        # a warning about a legal env (a range band narrower than two evader steps, rho > 1)
        # is said once every field has passed: the [env] table is checked midway, and its
        # warning came before a later field's refusal ("algo = 'nope'"), as one more thing
        # to fix before the error line
        with warnings.catch_warnings(record=True) as held:
            self._check_fields()
        for w in held:
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)

    def _check_fields(self) -> None:
        put = lambda name, value: object.__setattr__(self, name, value)
        check = _Checker()
        check.role(self.role)
        other = "evader" if self.role == "pursuer" else "pursuer"
        pool = (self.opponent,) if isinstance(self.opponent, str) else tuple(self.opponent)
        if not pool:
            raise InvalidConfigError("opponent: expected a policy name or a non-empty list")
        for name in pool:
            check.string("opponent", name)
            # a model as play, evaluate and tournaments take it: zoo:NAME or a .zip
            if opponent_name(name, other, f"opponent = {name!r}").partition("/")[0] != other:
                article = "an" if self.role == "evader" else "a"
                raise InvalidConfigError(
                    f"opponent: {article} {self.role} learner needs a '{other}/KIND' policy "
                    f"(a model: 'zoo:NAME' or a .zip path), got {name!r}"
                )
        # stored with a model file's absolute path: a rerun (of config.toml, from another
        # directory) plays the file this run played, or is refused as another config
        pool = tuple(absolute_model_name(name) for name in pool)
        put("opponent", pool[0] if len(pool) == 1 and isinstance(self.opponent, str) else pool)
        put("opponent_weights", tuple(self.opponent_weights))
        if self.opponent_weights:
            from training.pool import OpponentPool

            OpponentPool(list(pool), list(self.opponent_weights))  # checks the weights
        # a map file's path made absolute, as the opponent's: a rerun of config.toml from
        # another directory was refused ("map: my_floor.json: no such map file") or
        # played a file of that name there
        if isinstance(self.map, (list, tuple)):  # several maps: one drawn per episode
            if not self.map:
                raise InvalidConfigError("map: expected a map name or a non-empty list")
            put("map", tuple(absolute_map_name(check.string("map", m)) for m in self.map))
        else:
            put("map", absolute_map_name(check.string("map", self.map)))
        put("env", check.table("env", self.env, allowed=_ENV_KEYS))
        try:  # the env's own validation, so a bad [env] value fails here, not mid-run
            for world in self.maps:
                EnvConfig(map=world, **self.env)
        except InvalidConfigError as exc:
            if str(exc).startswith("map:"):
                raise
            raise InvalidConfigError(f"env.{exc}") from None
        except ValueError as exc:  # an unknown map name or an invalid map file
            raise InvalidConfigError(f"map: {exc}") from None
        put("start", check.choice("start", self.start, START_CHOICES))
        put("algo", check.choice("algo", str(self.algo).lower(), ALGORITHMS))
        put("total_timesteps", check.integer("total_timesteps", self.total_timesteps, 1))
        put("seed", check.integer("seed", self.seed, 0, MAX_SEED))
        if self.seed + self.total_timesteps > 2**32 - 1:  # the reseed of a resumed run
            raise InvalidConfigError(
                f"{check.where}: seed + total_timesteps = {self.seed + self.total_timesteps:,}: "
                f"expected at most {2**32 - 1:,} (a resumed run reseeds numpy from seed + "
                "timesteps done, which takes seeds below 2**32)"
            )
        put("n_envs", check.integer("n_envs", self.n_envs, 1))
        if isinstance(self.net_arch, (str, bytes)) or not hasattr(self.net_arch, "__iter__"):
            raise InvalidConfigError(
                f"net_arch: expected a list of layer sizes, got {self.net_arch!r}"
            )
        put(
            "net_arch",
            tuple(check.integer(f"net_arch[{i}]", n, 1) for i, n in enumerate(self.net_arch)),
        )
        put("policy_kwargs", check.table("policy_kwargs", self.policy_kwargs))
        put("learning_rate", check.positive("learning_rate", self.learning_rate))
        gamma = check.positive("gamma", self.gamma)
        if gamma > 1.0:
            raise InvalidConfigError(f"gamma: expected a value in (0, 1], got {self.gamma!r}")
        put("gamma", gamma)
        put("batch_size", check.integer("batch_size", self.batch_size, 1))
        put("n_steps", check.integer("n_steps", self.n_steps, 2))
        put("algo_kwargs", check.table("algo_kwargs", self.algo_kwargs))
        self._check_algo_kwargs()
        self._check_policy_kwargs()
        put("checkpoint_freq", check.integer("checkpoint_freq", self.checkpoint_freq, 1))
        put("eval_episodes", check.integer("eval_episodes", self.eval_episodes, 0))
        put("eval_start", check.choice("eval_start", self.eval_start, START_CHOICES))
        put("output_dir", check.string("output_dir", os.fspath(self.output_dir)))

    def _check_policy_kwargs(self) -> None:
        if "net_arch" in self.policy_kwargs:
            raise InvalidConfigError("policy_kwargs: set net_arch with the net_arch field")
        if self.algo == "ppo":
            from stable_baselines3.common.policies import ActorCriticPolicy as cls
        else:
            from stable_baselines3.sac.policies import SACPolicy as cls
        known = set(inspect.signature(cls.__init__).parameters) - {
            "self",
            "observation_space",
            "action_space",
            "lr_schedule",
            "net_arch",
        }
        unknown = sorted(set(self.policy_kwargs) - known)
        if unknown:
            raise InvalidConfigError(
                f"policy_kwargs: {unknown} are not arguments of {cls.__name__}; "
                f"known: {sorted(known)}"
            )

    def _check_algo_kwargs(self) -> None:
        managed = sorted(set(self.algo_kwargs) & _ALGO_MANAGED)
        if managed:
            raise InvalidConfigError(
                f"algo_kwargs: {managed} are set by their own fields or by train(); "
                f"remove them from algo_kwargs"
            )
        import stable_baselines3

        cls = getattr(stable_baselines3, self.algo.upper())
        known = set(inspect.signature(cls.__init__).parameters) - {"self"}
        unknown = sorted(set(self.algo_kwargs) - known)
        if unknown:
            raise InvalidConfigError(
                f"algo_kwargs: {unknown} are not arguments of stable_baselines3."
                f"{self.algo.upper()}; known: {sorted(known - _ALGO_MANAGED)}"
            )
        for key, value in self.algo_kwargs.items():
            _check_algo_value(self.algo, key, value)

    # ----------------------------------------------------------------- conversions
    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> TrainConfig:
        """Build a config from a mapping (a parsed TOML file).

        Raises:
            InvalidConfigError: an unknown or missing key, or a bad value (named).
        """
        if not isinstance(data, dict):
            raise InvalidConfigError(f"config: expected a table, got {type(data).__name__}")
        names = [f.name for f in dataclasses.fields(cls)]
        unknown = sorted(set(data) - set(names))
        if unknown:
            raise InvalidConfigError(f"config: unknown field(s) {unknown}; fields are {names}")
        missing = [n for n in ("role", "opponent") if n not in data]
        if missing:
            raise InvalidConfigError(f"config: missing required field(s) {missing}")
        data = dict(data)
        for key in ("opponent", "opponent_weights", "net_arch", "map"):
            if isinstance(data.get(key), list):
                data[key] = tuple(data[key])
        return cls(**data)

    @property
    def maps(self) -> tuple[str, ...]:
        """The map(s) as a tuple."""
        return (self.map,) if isinstance(self.map, str) else tuple(self.map)

    def opponent_policy(self) -> Any:
        """The opponent to build envs with: a name, or a new :class:`OpponentPool`
        (a new one per call: each env needs its own stateful policies)."""
        if isinstance(self.opponent, str) and not self.opponent_weights:
            return self.opponent
        from training.pool import OpponentPool

        pool = (self.opponent,) if isinstance(self.opponent, str) else self.opponent
        other = "evader" if self.role == "pursuer" else "pursuer"
        return OpponentPool(list(pool), list(self.opponent_weights) or None, role=other)

    def to_dict(self) -> dict[str, Any]:
        """A JSON/TOML-ready dict that :meth:`from_dict` turns back into this config."""
        d = dataclasses.asdict(self)
        d["net_arch"] = list(self.net_arch)
        if not isinstance(self.opponent, str):
            d["opponent"] = list(self.opponent)
        if not isinstance(self.map, str):
            d["map"] = list(self.map)
        if self.opponent_weights:
            d["opponent_weights"] = list(self.opponent_weights)
        else:  # absent unless used: configs written before pools load and compare equal
            del d["opponent_weights"]
        d["env"] = dict(self.env)
        d["algo_kwargs"] = dict(self.algo_kwargs)
        d["policy_kwargs"] = dict(self.policy_kwargs)
        return d

    def to_toml(self) -> str:
        """This config as TOML text (loadable by :func:`load_config`)."""
        flat = {k: v for k, v in self.to_dict().items() if not isinstance(v, dict)}
        lines = [f"{k} = {_toml_value(v)}" for k, v in flat.items()]
        for table in ("env", "policy_kwargs", "algo_kwargs"):
            items = getattr(self, table)
            if items:
                lines += ["", f"[{table}]"] + [f"{k} = {_toml_value(v)}" for k, v in items.items()]
        return "\n".join(lines) + "\n"

    def env_kwargs(self) -> dict[str, Any]:
        """Keyword arguments of :class:`~training.single_agent.SingleAgentEnv` (no opponent)."""
        return {"map": self.map if isinstance(self.map, str) else list(self.map),
                "start": self.start, **self.env}  # fmt: skip

    def replace(self, **changes: Any) -> TrainConfig:
        """A copy with some fields changed (validated again)."""
        return dataclasses.replace(self, **changes)


def map_fingerprints(names: Any) -> dict[str, dict[str, Any]]:
    """The maps a run plays, by the names its config gives them: each one's geometry
    digest and recommended parameters (:func:`~envs.surveillance.config.map_recommendations`)
    as they resolve now. A config names a map file by its path, so the file edited
    between an interruption and the rerun is seen only here (the config's own values,
    ``[env]`` included, are compared as the config). Recorded when a run starts and
    checked by :func:`check_same_maps` when it resumes: the one home of this check for
    ``surveil train`` (``env.json``) and DAgger (``progress.json``).

    Args:
        names: one map name or an iterable of them.
    """
    from envs.maps import load_map
    from envs.surveillance.config import map_recommendations

    names = [names] if isinstance(names, str) else sorted({str(n) for n in names})
    return {n: {"digest": load_map(n).digest, **map_recommendations(n)} for n in names}


def check_same_maps(recorded: Any, now: dict[str, dict[str, Any]], *, where: str) -> None:
    """Refuse to resume a run whose maps resolve otherwise than when it started.

    Args:
        recorded: the :func:`map_fingerprints` recorded at the start (a map missing from
            it, or a value that is not such a record, is not compared).
        now: the fingerprints as they resolve now.
        where: the message's start: ``"output_dir 'out/x' holds a DAgger run"``.

    Raises:
        InvalidConfigError: naming the first map that changed and what changed in it.
    """
    if not isinstance(recorded, dict):
        return
    for name, fp in now.items():
        was = recorded.get(name)
        if not isinstance(was, dict):
            continue
        diff = sorted(k for k in set(was) | set(fp) if was.get(k) != fp.get(k))
        if diff:
            raise InvalidConfigError(
                f"{where} on another game: map {name!r} resolves to {_shown(fp, diff)} now, "
                f"{_shown(was, diff)} when the run started (its map file or the file's "
                "metadata changed); use another output_dir or delete that one"
            )


def _shown(record: dict[str, Any], keys: list[str]) -> str:
    return ", ".join(f"{k} = {record.get(k)!r}" for k in keys)


def read_toml(path: str | os.PathLike[str]) -> dict[str, Any]:
    """The table of a TOML config file.

    Raises:
        InvalidConfigError: the file is missing or not valid TOML (naming it).
    """
    p = Path(path)
    try:
        with p.open("rb") as fh:
            return tomllib.load(fh)
    except FileNotFoundError:
        raise InvalidConfigError(f"config: no such file {str(p)!r}") from None
    except IsADirectoryError:  # was the bare "/etc: Is a directory"
        raise InvalidConfigError(
            f"config: {str(p)!r} is a directory, expected a TOML file"
        ) from None
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise InvalidConfigError(f"config: {str(p)!r} is not valid TOML ({exc})") from exc
    except RecursionError:  # the parser recurses once per nested array or table
        raise InvalidConfigError(
            f"config: {str(p)!r} is not valid TOML (nested too deeply to read)"
        ) from None


def load_config(path: str | os.PathLike[str], **overrides: Any) -> TrainConfig:
    """Load a :class:`TrainConfig` from a TOML file, with optional field overrides.

    Raises:
        InvalidConfigError: the file is missing or not valid TOML, or a field is bad.
    """
    p = Path(path)
    data = read_toml(p)
    data.update(overrides)
    if data.get("method") == "rl":  # written by load_any_config users for clarity
        del data["method"]
    try:
        return TrainConfig.from_dict(data)
    except InvalidConfigError as exc:  # name the file the value came from
        msg = str(exc)
        msg = msg[len("config.toml: ") :] if msg.startswith("config.toml: ") else msg
        raise InvalidConfigError(f"{p}: {msg}") from None


def load_any_config(path: str | os.PathLike[str], **overrides: Any):
    """A :class:`TrainConfig` or, for a file with ``method = "dagger"``, a
    :class:`~training.dagger.DaggerConfig`.

    Raises:
        InvalidConfigError: as :func:`load_config` (the file is named).
    """
    p = Path(path)
    try:
        with p.open("rb") as fh:
            method = tomllib.load(fh).get("method", "rl")
    except (OSError, tomllib.TOMLDecodeError, UnicodeDecodeError, RecursionError):
        method = "rl"  # load_config reports the problem
    if method == "dagger":
        from training.dagger import load_dagger_config

        return load_dagger_config(p, **overrides)
    if method != "rl":
        raise InvalidConfigError(f"{p}: method = {method!r}: expected 'rl' (default) or 'dagger'")
    return load_config(p, **overrides)


def _toml_value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, float)):
        return repr(v) if math.isfinite(v) else ("nan" if v != v else ("inf" if v > 0 else "-inf"))
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    if v is None:
        raise InvalidConfigError("config: TOML has no null; drop the key instead of None")
    raise InvalidConfigError(f"config: cannot write {type(v).__name__} {v!r} as TOML")


# What SB3 would otherwise accept and fail on deep inside training (n_epochs = 0 is an
# UnboundLocalError in PPO.train; ent_coef = "abc" a ValueError from float()): the
# numeric arguments of PPO and SAC, with the values they take.
_ALGO_VALUES: dict[str, tuple[str, float | None, float | None]] = {
    # name: (kind, lower bound, upper bound); kind "int" or "real", bounds inclusive
    "n_epochs": ("int", 1, None),
    "clip_range": ("real", 1e-12, None),
    "gae_lambda": ("real", 0.0, 1.0),
    "vf_coef": ("real", 0.0, None),
    "max_grad_norm": ("real", 1e-12, None),
    "target_kl": ("real", 1e-12, None),
    "buffer_size": ("int", 1, None),
    "learning_starts": ("int", 0, None),
    "tau": ("real", 1e-12, 1.0),
    "gradient_steps": ("int", -1, None),
    "target_update_interval": ("int", 1, None),
    "stats_window_size": ("int", 1, None),
    "sde_sample_freq": ("int", -1, None),
    "normalize_advantage": ("bool", None, None),
    "use_sde": ("bool", None, None),
    "optimize_memory_usage": ("bool", None, None),
}


def _check_algo_value(algo: str, key: str, value: Any) -> None:
    """Raise InvalidConfigError for an ``[algo_kwargs]`` value SB3 would choke on."""
    where = f"[algo_kwargs] {key}"
    if key == "ent_coef":
        auto = isinstance(value, str) and (value == "auto" or value.startswith("auto_"))
        if algo == "sac" and auto:
            try:
                tail = value[5:]
                if tail and not float(tail) > 0:
                    raise ValueError
            except ValueError:
                raise InvalidConfigError(
                    f"{where} = {value!r}: expected 'auto', 'auto_<initial value > 0>' "
                    "or a number >= 0"
                ) from None
            return
        real = isinstance(value, (int, float)) and not isinstance(value, bool)
        if not real or not math.isfinite(value) or value < 0:
            expected = "a number >= 0" + (" or 'auto'" if algo == "sac" else "")
            raise InvalidConfigError(f"{where} = {value!r}: expected {expected}")
        return
    if key not in _ALGO_VALUES:
        return
    kind, lo, hi = _ALGO_VALUES[key]
    if kind == "bool":
        if not isinstance(value, bool):
            raise InvalidConfigError(f"{where} = {value!r}: expected true or false")
        return
    if kind == "int":
        ok = isinstance(value, int) and not isinstance(value, bool)
    else:
        ok = isinstance(value, (int, float)) and not isinstance(value, bool)
        ok = ok and math.isfinite(value)
    if ok and lo is not None:
        ok = value >= lo
    if ok and hi is not None:
        ok = value <= hi
    if not ok:
        what = "an integer" if kind == "int" else "a number"
        bounds = " and ".join(
            b
            for b in (
                (f">= {lo:g}" if lo is not None else ""),
                (f"<= {hi:g}" if hi is not None else ""),
            )
            if b
        )
        raise InvalidConfigError(f"{where} = {value!r}: expected {what} {bounds}".rstrip())


class _Checker:
    """The config's validators: :mod:`envs.validation`'s rules, located in the config file."""

    where = "config.toml"

    @staticmethod
    def role(value: Any) -> str:
        try:
            return check_role(value)
        except InvalidConfigError:
            raise InvalidConfigError(
                f"config.toml: role = {value!r}: expected 'pursuer' or 'evader'"
            ) from None

    def string(self, name: str, value: Any) -> str:
        return validation.string(name, value, where=self.where)

    def choice(self, name: str, value: Any, options: tuple[str, ...]) -> str:
        return validation.choice(name, value, options, where=self.where)

    def integer(self, name: str, value: Any, minimum: int, maximum: int | None = None) -> int:
        return validation.integer(name, value, minimum=minimum, maximum=maximum, where=self.where)

    def positive(self, name: str, value: Any) -> float:
        return validation.positive(name, value, where=self.where)

    def table(
        self, name: str, value: Any, allowed: tuple[str, ...] | None = None
    ) -> dict[str, Any]:
        d = validation.mapping(name, value, where=f"{self.where} [{name}]")
        if allowed is not None:
            unknown = sorted(set(d) - set(allowed))
            if unknown:
                raise InvalidConfigError(
                    f"[{name}]: unknown key(s) {unknown}; allowed: {list(allowed)}; in {self.where}"
                )
        return dict(d)
