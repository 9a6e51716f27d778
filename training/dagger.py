"""DAgger on stable-baselines3: imitate an analytic expert, the result an ordinary SB3 model.

Dataset aggregation (Ross, Gordon and Bagnell, 2011): roll out a mixture of the expert and
the learner (the expert acts with probability ``beta_i = beta ** i`` at iteration ``i``, so
iteration 0 is the expert alone), label every visited observation with the expert's action,
add it to the dataset, and fit the learner to the whole dataset by supervised regression.
The learner visits its own mistakes and is told what the expert would have done there,
which plain behaviour cloning never shows it.

Rollouts go through the shared episode runner (:func:`strategies.runner.run_episode`); the
learner is the policy network of an SB3 PPO model (``MlpPolicy``), fitted by mean squared
error between its action mean and the expert's action, so the result loads and plays like
any trained model (``ROLE/sb3:PATH``) and can be fine-tuned by PPO
(:mod:`training.finetune`).

**Learners that see lidar.** The analytic experts read the ``"state"`` vector; a learner
meant for maps it has never seen reads ``"lidar"`` (ray distances plus the relative
vector, normalised by the ranges, so nothing in it names the map or its size). Each
visited state is then labelled by the expert from the state and shown to the learner as
the lidar vector the env would have given it at that instant
(:meth:`envs.surveillance.observations.LidarEncoder.encode_state`).

**Many maps, many opponents.** ``maps`` cycles through built-ins, map files and seeded
random maps (``"random:SEED"``); ``opponent`` is one policy or a pool
(:class:`training.pool.OpponentPool`, one drawn per episode).

**Nothing is lost.** After every iteration the model, the dataset and the curves are
written to ``output_dir``; a rerun with the same config continues from the last finished
iteration and ends with the same model, bit for bit, as an uninterrupted run (every
random draw of an iteration is seeded by ``(seed, iteration)``).

The disagreement, the mean distance between the learner's and the expert's actions on the
states the learner's own rollouts visit, is recorded per iteration: DAgger's progress
measure, and what a test checks falls.

Example::

    from training.dagger import DaggerConfig, dagger
    result = dagger(DaggerConfig(role="pursuer", expert="pursuer/decomposition",
                                 opponent=("evader/shooting", "evader/straight"),
                                 maps=("corridor", "random:1"),
                                 observation={"observation": "lidar", "n_rays": 32},
                                 output_dir="out/dagger/pursuer"))
    print(result.disagreement)  # one value per iteration, falling
"""

from __future__ import annotations

import dataclasses
import json
import os
import re
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from envs import validation
from envs.errors import InvalidConfigError
from strategies.policies import make_policy
from strategies.policies.base import check_role
from strategies.policies.learner_inputs import LearnerInputs, check_features
from strategies.policies.model_files import absolute_model_name, model_policy_name
from strategies.runner import check_observation_options, run_episode
from training.config import (
    MAX_SEED,
    absolute_map_name,
    check_same_maps,
    map_fingerprints,
    opponent_name,
)

__all__ = ["DaggerConfig", "DaggerResult", "dagger", "load_dagger_config"]


@dataclass(frozen=True)
class DaggerConfig:
    """One DAgger run: a role imitating an expert against an opponent or a pool."""

    role: str
    """The learner's role."""
    expert: str
    """The analytic policy that labels states (``"pursuer/decomposition"``...)."""
    opponent: str | tuple[str, ...]
    """The other role's policy, or several: a pool, one drawn per episode."""
    expert_params: dict[str, Any] = field(default_factory=dict)
    """Parameters of the expert (``{"range_margin": 0.15}``...)."""
    opponent_weights: tuple[float, ...] = ()
    """Weights of the pool's members (empty: uniform)."""
    maps: tuple[str, ...] = ("open_room",)
    """Worlds, used in turn: built-in names, map files, ``random:SEED`` names."""
    env: dict[str, Any] = field(default_factory=dict)
    """Env overrides for every episode (a built-in's recommendations fill the rest)."""
    observation: dict[str, Any] = field(default_factory=lambda: {"observation": "state"})
    """What the learner sees: ``{"observation": "lidar", "n_rays": 32}`` or the state."""
    features: tuple[str, ...] = ()
    """Analytic features appended to what the learner sees
    (:data:`strategies.policies.learner_inputs.LEARNER_FEATURES`), computed with
    ``expert_params``: ``("safety_table",)`` gives a decomposition learner the pursuer's
    turn choice, ``("escape_plan",)`` a shooting learner the evader's plan. A model
    trained with features plays only through
    :class:`~strategies.policies.learned.SB3Policy`, which computes them from the state."""
    iterations: int = 5
    episodes: int = 4
    """Episodes per iteration."""
    max_cycles: int = 300
    beta: float = 0.5
    """The expert acts with probability ``beta ** iteration``."""
    start: str = "valid"
    net_arch: tuple[int, ...] = (64, 64)
    epochs: int = 30
    """Passes over the whole dataset per fit."""
    batch_size: int = 256
    learning_rate: float = 1e-3
    radial_weight: float = 1.0
    """Weight of the action error along the line of sight (1: plain MSE); see :func:`_fit`."""
    validation_episodes: int = 0
    """Episodes the learner plays *alone* after each fit (fixed seeds, the top-level start
    and env; ``validation_maps`` and ``validation_opponent`` when set, else the top-level
    maps and the opponent or pool): a learner-only learning curve. With more than 0,
    ``model.zip`` is the iteration that won most of them (ties: the later one) and
    ``model_last.zip`` the last iteration, from which a resumed run continues: DAgger's
    last iteration is not always its best."""
    validation_opponent: str | tuple[str, ...] = ()
    """Whom the validation episodes are played against (empty: the training opponent or
    pool). Select against the opponent the model is meant to beat, e.g. the
    ``evader/shooting`` of issue 9's target, while training against a wider pool."""
    validation_maps: tuple[str, ...] = ()
    """The worlds of the validation episodes, used in turn (empty: ``maps``)."""
    curriculum: tuple[dict[str, Any], ...] = ()
    """Stages played first, in order: ``{"iterations": n, "start": ..., "maps": [...],
    "env": {...}}`` (each key but ``iterations`` optional, overriding the top-level
    value for those iterations), e.g. escapable starts, then safe ones; a wide sensor range,
    then the narrow one; simple maps, then cluttered ones. The top-level settings apply
    after the last stage."""
    seed: int = 0
    output_dir: str = "out/dagger"

    def __post_init__(self) -> None:
        where = "DaggerConfig"
        put = lambda name, value: object.__setattr__(self, name, value)
        check_role(self.role)
        for name in ("expert", "output_dir", "start"):
            validation.string(name, getattr(self, name), where=where)
        if not self.expert.startswith(self.role + "/"):
            raise InvalidConfigError(
                f"{where}: expert = {self.expert!r} does not play the {self.role}"
            )
        other = "evader" if self.role == "pursuer" else "pursuer"
        pool = (self.opponent,) if isinstance(self.opponent, str) else tuple(self.opponent)
        if not pool or not all(_plays(o, other, f"{where}: opponent") for o in pool):
            raise InvalidConfigError(
                f"{where}: opponent = {self.opponent!r}: expected one or more "
                f"'{other}/KIND' policy names (or models: 'zoo:NAME', a .zip path)"
            )
        pool = tuple(absolute_model_name(o) for o in pool)  # a rerun plays the same files
        put("opponent", pool[0] if len(pool) == 1 else pool)
        put("opponent_weights", tuple(float(w) for w in self.opponent_weights))
        if self.opponent_weights:
            from training.pool import OpponentPool

            OpponentPool(list(pool), list(self.opponent_weights))  # checks the weights
        put("maps", (self.maps,) if isinstance(self.maps, str) else tuple(self.maps))
        if not self.maps or not all(isinstance(m, str) and m for m in self.maps):
            raise InvalidConfigError(f"{where}: maps = {self.maps!r}: expected map names or files")
        put("maps", tuple(absolute_map_name(m) for m in self.maps))  # as the opponent's files
        vm = self.validation_maps
        put("validation_maps", (vm,) if isinstance(vm, str) else tuple(vm))
        if not all(isinstance(m, str) and m for m in self.validation_maps):
            raise InvalidConfigError(
                f"{where}: validation_maps = {vm!r}: expected map names or files"
            )
        put("validation_maps", tuple(absolute_map_name(m) for m in self.validation_maps))
        vo = self.validation_opponent
        vpool = (vo,) if isinstance(vo, str) else tuple(vo)
        if not all(_plays(o, other, f"{where}: validation_opponent") for o in vpool):
            raise InvalidConfigError(
                f"{where}: validation_opponent = {vo!r}: expected '{other}/KIND' policy names "
                "(or models: 'zoo:NAME', a .zip path)"
            )
        vpool = tuple(absolute_model_name(o) for o in vpool)
        put("validation_opponent", vpool[0] if len(vpool) == 1 else vpool)
        validation.mapping("env", self.env, where=where)
        validation.mapping("expert_params", self.expert_params, where=where)
        make_policy(self.expert, **self.expert_params)  # unknown names and parameters fail here
        put("observation", check_observation_options(self.observation, f"{where}: observation"))
        put("features", check_features(self.features, role=self.role, expert=self.expert,
                                        where=where))  # fmt: skip
        for name, lo in (("iterations", 1), ("episodes", 1), ("max_cycles", 1), ("epochs", 1),
                         ("batch_size", 1), ("validation_episodes", 0)):  # fmt: skip
            validation.integer(name, getattr(self, name), minimum=lo, where=where)
        # the learner's SB3 model seeds numpy's legacy generator (seeds below 2**32)
        validation.integer("seed", self.seed, minimum=0, maximum=MAX_SEED, where=where)
        validation.unit_interval("beta", self.beta, where=where, open=False)
        validation.positive("learning_rate", self.learning_rate, where=where)
        validation.positive("radial_weight", self.radial_weight, where=where)
        from strategies.policies.starts import START_KINDS

        validation.choice("start", self.start, START_KINDS, where=where)
        stages = []
        for i, stage in enumerate(self.curriculum):
            at = f"{where}: curriculum[{i}]"
            stage = dict(validation.mapping("curriculum stage", stage, where=at))
            unknown = sorted(set(stage) - {"iterations", "start", "maps", "env"})
            if unknown or "iterations" not in stage:
                raise InvalidConfigError(
                    f"{at} = {stage!r}: expected 'iterations' and optionally 'start', 'maps', "
                    f"'env'" + (f"; unknown {unknown}" if unknown else "")
                )
            validation.integer("iterations", stage["iterations"], minimum=1, where=at)
            if "start" in stage:
                validation.choice("start", stage["start"], START_KINDS, where=at)
            if "maps" in stage:
                m = stage["maps"]
                stage["maps"] = (m,) if isinstance(m, str) else tuple(m)
                if not stage["maps"] or not all(isinstance(x, str) and x for x in stage["maps"]):
                    raise InvalidConfigError(f"{at}: maps = {m!r}: expected map names")
                stage["maps"] = tuple(absolute_map_name(x) for x in stage["maps"])
            if "env" in stage:
                stage["env"] = dict(validation.mapping("env", stage["env"], where=at))
            stages.append(stage)
        put("curriculum", tuple(stages))
        put("net_arch", tuple(self.net_arch))
        for i, n in enumerate(self.net_arch):
            validation.integer(f"net_arch[{i}]", n, minimum=1, where=where)

    def stage(self, iteration: int) -> tuple[tuple[str, ...], str, dict[str, Any]]:
        """The maps, start kind and env overrides of ``iteration`` (curriculum first)."""
        first = 0
        for stage in self.curriculum:
            if iteration < first + stage["iterations"]:
                env = {**self.env, **stage.get("env", {})}
                return stage.get("maps", self.maps), stage.get("start", self.start), env
            first += stage["iterations"]
        return self.maps, self.start, dict(self.env)

    @property
    def pool(self) -> tuple[str, ...]:
        """The opponent(s) as a tuple."""
        return (self.opponent,) if isinstance(self.opponent, str) else tuple(self.opponent)

    def opponent_policy(self) -> Any:
        """The opponent to play: a name, or an :class:`~training.pool.OpponentPool`."""
        other = "evader" if self.role == "pursuer" else "pursuer"
        if isinstance(self.opponent, str) and not self.opponent_weights:
            return model_policy_name(self.opponent, other, f"opponent = {self.opponent!r}")
        from training.pool import OpponentPool

        return OpponentPool(list(self.pool), list(self.opponent_weights) or None, role=other)

    def to_dict(self) -> dict[str, Any]:
        """A JSON/TOML-ready dict (``method = "dagger"``) that :meth:`from_dict` reads back."""
        d: dict[str, Any] = {"method": "dagger"}
        for f in dataclasses.fields(self):
            v = getattr(self, f.name)
            d[f.name] = list(v) if isinstance(v, tuple) else (dict(v) if isinstance(v, dict) else v)
        d["curriculum"] = [
            {k: (list(x) if isinstance(x, tuple) else x) for k, x in s.items()}
            for s in self.curriculum
        ]
        for name in ("validation_episodes", "validation_opponent", "validation_maps", "features"):
            if not getattr(self, name):  # absent unless used: older records compare equal
                del d[name]
        return d

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> DaggerConfig:
        """Build a config from a mapping (a parsed TOML file).

        Raises:
            InvalidConfigError: an unknown or missing key, or a bad value (named).
        """
        data = dict(data)
        method = data.pop("method", "dagger")
        if method != "dagger":
            raise InvalidConfigError(f"config: method = {method!r}: expected 'dagger'")
        names = [f.name for f in dataclasses.fields(cls)]
        unknown = sorted(set(data) - set(names))
        if unknown:
            raise InvalidConfigError(f"config: unknown field(s) {unknown}; fields are {names}")
        missing = [n for n in ("role", "expert", "opponent") if n not in data]
        if missing:
            raise InvalidConfigError(f"config: missing required field(s) {missing}")
        for key in ("maps", "net_arch", "opponent_weights", "curriculum", "validation_maps",
                    "features"):  # fmt: skip
            if isinstance(data.get(key), list):
                data[key] = tuple(data[key])
        for key in ("opponent", "validation_opponent"):
            if isinstance(data.get(key), list):
                data[key] = tuple(data[key])
        return cls(**data)

    def to_toml(self) -> str:
        """This config as TOML text (loadable by :func:`load_dagger_config`)."""
        from training.config import _toml_value

        d = self.to_dict()
        tables = {k: d.pop(k) for k in ("env", "observation", "expert_params")}
        stages = d.pop("curriculum")
        if not d["opponent_weights"]:
            del d["opponent_weights"]
        lines = [f"{k} = {_toml_value(v)}" for k, v in d.items()]
        for name, items in tables.items():
            if items:
                lines += ["", f"[{name}]"] + [f"{k} = {_toml_value(v)}" for k, v in items.items()]
        for stage in stages:
            lines += ["", "[[curriculum]]"]
            for k, v in stage.items():
                if isinstance(v, dict):
                    inner = ", ".join(f"{a} = {_toml_value(b)}" for a, b in v.items())
                    lines.append(f"{k} = {{{inner}}}")
                else:
                    lines.append(f"{k} = {_toml_value(v)}")
        return "\n".join(lines) + "\n"

    def replace(self, **changes: Any) -> DaggerConfig:
        """A copy with some fields changed (validated again)."""
        return dataclasses.replace(self, **changes)


def load_dagger_config(path: str | os.PathLike[str], **overrides: Any) -> DaggerConfig:
    """Load a :class:`DaggerConfig` from a TOML file (``method = "dagger"``).

    Raises:
        InvalidConfigError: the file is missing or not valid TOML, or a field is bad
            (the message names the file).
    """
    from training.config import read_toml

    p = Path(path)
    data = read_toml(p)
    data.update(overrides)
    try:
        return DaggerConfig.from_dict(data)
    except InvalidConfigError as exc:
        raise InvalidConfigError(f"{p}: {exc}") from None


@dataclass
class DaggerResult:
    """What :func:`dagger` produced.

    Attributes:
        model_path: the SB3 PPO zip (with ``provenance.json`` beside it).
        disagreement: per iteration, the mean |learner - expert| action distance on the
            states visited that iteration (measured before refitting).
        samples: dataset size after each iteration.
        held: per iteration, the share of episodes the learner's role won.
        wall_seconds: total time (of this call; a resumed run adds to the stored one in
            ``provenance.json``).
        fit_error: per iteration, the mean |learner - expert| on the whole dataset after
            the fit (how well the network imitates what it was shown).
        episodes: per iteration, one record per episode (map, opponent, winner, steps).
        validation: per iteration, the share of the validation episodes the learner won
            alone (empty without ``validation_episodes``).
        best_iteration: the iteration ``model_path`` holds.
    """

    model_path: Path
    disagreement: list[float]
    samples: list[int]
    held: list[float]
    wall_seconds: float
    fit_error: list[float] = field(default_factory=list)
    episodes: list[list[dict[str, Any]]] = field(default_factory=list)
    validation: list[float] = field(default_factory=list)
    best_iteration: int = -1


class _Rollout:
    """The policy that plays during a DAgger rollout: expert or learner, step by step.

    Both see every step (the expert keeps its internal state in sync); the action taken is
    the expert's with probability ``beta``; every observation is stored with the expert's
    action (its label) and the learner's (for the disagreement). With ``learner_obs``
    options other than the state, the learner's observation is the lidar vector of the
    same instant (built from the state the expert reads), followed by any analytic
    ``features`` (:class:`~strategies.policies.learner_inputs.LearnerInputs`).
    """

    uses_state = True

    def __init__(
        self, expert, model, beta: float, seed: int, learner_obs=None, features=()
    ) -> None:
        self.expert, self.model, self.beta = expert, model, beta
        self.rng = np.random.default_rng(seed)
        self.name = f"dagger({expert.name})"
        self.inputs = LearnerInputs(learner_obs, features)
        self.obs: list[np.ndarray] = []
        self.labels: list[np.ndarray] = []
        self.learned: list[np.ndarray] = []

    @property
    def roles(self):
        return self.expert.roles

    @property
    def role(self):
        return self.expert.role

    def reset(self, *, role, map, config, seed):
        out = self.expert.reset(role=role, map=map, config=config, seed=seed)
        # the features reuse the expert's own tables (same parameters, same map)
        self.inputs.reset(config, role, expert=self.expert if self.inputs.features else None)
        return out

    def act(self, observation):
        label = np.asarray(self.expert.act(observation), dtype=np.float32)
        seen = self.inputs(observation)
        own, _ = self.model.predict(seen, deterministic=True)
        own = np.clip(np.asarray(own, dtype=np.float32), -1.0, 1.0)
        self.obs.append(seen)
        self.labels.append(label)
        self.learned.append(own)
        return label if self.rng.random() < self.beta else own

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        return self.act(observation), state


def _line_of_sight(obs: np.ndarray, observation: dict[str, Any]) -> np.ndarray:
    """Unit vectors along the line of sight in each observation (zeros where unseen)."""
    from envs.surveillance.observations import STATE_LAYOUT, lidar_layout

    if observation.get("observation", "state") == "state":
        return np.asarray(obs[:, STATE_LAYOUT["theta"]], dtype=np.float32)
    kind = observation["observation"]
    rel = obs[
        :, lidar_layout(int(observation.get("n_rays", 32)), kind == "lidar_track")["other_rel"]
    ]
    n = np.linalg.norm(rel, axis=1, keepdims=True)
    return np.where(n > 0, rel / np.maximum(n, 1e-12), 0.0).astype(np.float32)


def _fit(model, obs: np.ndarray, act: np.ndarray, cfg: DaggerConfig, rng) -> float:
    """Regress the policy's action mean onto the expert's actions; returns the last loss.

    The loss is the squared error with its component along the line of sight weighted by
    ``radial_weight``: an error along the line of sight changes L, and L leaving
    ``[L_min, L_max]`` ends the episode, while an error across it only turns the rod a
    little. Plain regression shrinks the actions it is unsure of toward their mean, which
    for a pursuer imitating one that holds L just above L_min means drifting into
    ``"too_close"``.
    """
    import torch

    policy = model.policy
    opt = torch.optim.Adam(policy.parameters(), lr=cfg.learning_rate)
    x_all = torch.as_tensor(obs)
    y_all = torch.as_tensor(act)
    u_all = torch.as_tensor(_line_of_sight(obs, cfg.observation))
    extra = cfg.radial_weight - 1.0
    loss_value = float("nan")
    for _ in range(cfg.epochs):
        order = rng.permutation(len(obs))
        for s in range(0, len(order), cfg.batch_size):
            idx = torch.as_tensor(order[s : s + cfg.batch_size])
            dist = policy.get_distribution(x_all[idx])
            err = dist.distribution.mean - y_all[idx]
            loss = (err * err).sum(dim=1).mean()
            if extra:
                loss = loss + extra * ((err * u_all[idx]).sum(dim=1) ** 2).mean()
            opt.zero_grad()
            loss.backward()
            opt.step()
            loss_value = float(loss.detach())
    return loss_value


def _learner_env(cfg: DaggerConfig):
    """The env whose observation space the learner's network is built for (never stepped)."""
    from training.single_agent import SingleAgentEnv

    env = SingleAgentEnv(cfg.role, cfg.pool[0], map=cfg.maps[0], **{**cfg.env, **cfg.observation})
    env.observation_space = LearnerInputs(cfg.observation, cfg.features).space(
        env.observation_space
    )
    return env


def _resume(cfg: DaggerConfig, out: Path, env) -> tuple[Any, dict[str, Any], list, list] | None:
    """The model, curves and dataset of the last finished iteration in ``out``, if any."""
    from stable_baselines3 import PPO

    prog_path = out / "progress.json"
    if not prog_path.is_file():
        _settle(out, -1)  # an iteration 0 stopped before its commit
        return None
    try:
        progress = json.loads(prog_path.read_text())
        stored = DaggerConfig.from_dict(progress["config"])
    except (ValueError, KeyError, InvalidConfigError) as exc:
        raise InvalidConfigError(
            f"output_dir {str(out)!r}: unreadable {prog_path.name} ({exc}); delete it to start over"
        ) from None
    before = stored.replace(output_dir=cfg.output_dir).to_dict()
    now = cfg.to_dict()
    diff = sorted(k for k in now if k not in ("iterations", "output_dir") and before[k] != now[k])
    if diff:
        raise InvalidConfigError(
            f"output_dir {str(out)!r} holds a DAgger run with a different config (fields "
            f"{diff}: {[before[k] for k in diff]} there, {[now[k] for k in diff]} now); "
            "use another output_dir or delete that one"
        )
    where = f"output_dir {str(out)!r} holds a DAgger run"
    check_same_maps(progress.get("maps"), _map_fingerprints(cfg), where=where)  # none: older
    _settle(out, len(progress["samples"]) - 1)
    try:
        last = out / "model_last.zip"
        model = PPO.load(str(last if last.is_file() else out / "model.zip"), env=env, device="cpu")
        with np.load(out / "dataset.npz") as data:
            obs, act = list(data["obs"]), list(data["act"])
    except Exception as exc:  # a damaged file: say which, do not guess
        raise InvalidConfigError(
            f"output_dir {str(out)!r}: cannot resume ({type(exc).__name__}: {exc}); "
            "delete the directory to start over"
        ) from None
    if len(obs) != progress["samples"][-1]:
        raise InvalidConfigError(
            f"output_dir {str(out)!r}: dataset.npz holds {len(obs)} samples, "
            f"progress.json {progress['samples'][-1]}; delete the directory to start over"
        )
    return model, progress, obs, act


def _map_fingerprints(cfg: DaggerConfig) -> dict[str, dict[str, Any]]:
    """:func:`~training.config.map_fingerprints` of every map the run plays (curriculum
    stages included)."""
    return map_fingerprints({str(m) for it in range(cfg.iterations) for m in cfg.stage(it)[0]})


def _write_iteration(out: Path, model, obs, act, progress: dict[str, Any], best: bool) -> None:
    """Model, dataset and curves of a finished iteration (``model.zip`` too when it is the
    best so far, or there is no validation), committed by ``progress.json``.

    The model and dataset are written beside the last iteration's as ``NAME.next-K``,
    then ``progress.json`` is replaced (the commit), then they take their names
    (:func:`_settle`). Replaced one by one, a Ctrl-C between them resumed with iteration
    K's model and K - 1's dataset: a different model at the end, and nothing said.
    """
    import shutil

    tag = f".next-{len(progress['samples']) - 1}"
    model.save(str(out / f"model_last{tag}.zip"))
    if best:
        shutil.copyfile(out / f"model_last{tag}.zip", out / f"model{tag}.zip")
    np.savez_compressed(out / f"dataset{tag}.npz", obs=np.asarray(obs), act=np.asarray(act))
    tmp_json = out / "progress.json.tmp"
    tmp_json.write_text(json.dumps(progress, indent=2) + "\n")
    os.replace(tmp_json, out / "progress.json")
    _settle(out, len(progress["samples"]) - 1)


_NEXT = re.compile(r"(model_last|model|dataset)\.next-(\d+)\.(zip|npz)")


def _settle(out: Path, committed: int) -> None:
    """Finish or undo an interrupted :func:`_write_iteration`: files of the iteration
    ``progress.json`` commits (``committed``, -1 for none) take their names, others go."""
    for path in sorted(out.iterdir()):
        m = _NEXT.fullmatch(path.name)
        if m is None:
            continue
        if int(m.group(2)) == committed:
            os.replace(path, out / f"{m.group(1)}.{m.group(3)}")
        else:
            path.unlink()


def _plays(name: Any, role: str, where: str) -> bool:
    """Whether ``name`` is a policy name of ``role``: ``ROLE/KIND``, or a model as users
    name one (``zoo:NAME``, a ``.zip``: the file is checked, and the role it was trained
    for, raising InvalidConfigError)."""
    if not isinstance(name, str):
        return False
    return opponent_name(name, role, f"{where} = {name!r}").startswith(role + "/")


def _validate(cfg: DaggerConfig, model, opponent) -> float:
    """The share of ``cfg.validation_episodes`` fixed-seed episodes the learner wins alone.

    Against ``cfg.validation_opponent`` on ``cfg.validation_maps`` when they are set,
    else against ``opponent`` (the training one) on ``cfg.maps``.
    """
    wins = 0
    other = "evader" if cfg.role == "pursuer" else "pursuer"
    maps = cfg.validation_maps or cfg.maps
    if cfg.validation_opponent:
        vo = cfg.validation_opponent
        if isinstance(vo, str):
            opponent = model_policy_name(vo, other, f"validation_opponent = {vo!r}")
        else:
            from training.pool import OpponentPool

            opponent = OpponentPool(list(vo), role=other)
    for k in range(cfg.validation_episodes):
        seed = 10_000_019 + cfg.seed * 1_003 + k
        learner = _Rollout(make_policy(cfg.expert, **cfg.expert_params), model, 0.0, seed,
                           cfg.observation, cfg.features)  # fmt: skip
        pair = {cfg.role: learner, other: opponent}
        r = run_episode(maps[k % len(maps)], pair["pursuer"], pair["evader"], seed,
                        max_cycles=cfg.max_cycles, overrides=cfg.env, start=cfg.start)  # fmt: skip
        wins += r.winner == cfg.role
    return wins / cfg.validation_episodes


def _episode_bar(cfg: DaggerConfig, first: int, verbose: bool):
    """A bar over the episodes still to play on stderr, when ``verbose`` on a terminal."""
    if not (verbose and sys.stderr.isatty()):
        return None
    from tqdm import tqdm

    total = cfg.iterations * cfg.episodes
    return tqdm(total=total, initial=first * cfg.episodes, unit="episode",
                desc=f"dagger {cfg.role}", file=sys.stderr, dynamic_ncols=True)  # fmt: skip


def dagger(cfg: DaggerConfig, *, verbose: bool = False) -> DaggerResult:
    """Run DAgger; writes ``model.zip``, ``provenance.json`` and the curves to ``output_dir``.

    Resumes from the last finished iteration found in ``output_dir`` (see the module
    docstring); raising ``iterations`` continues a finished run.

    Args:
        cfg: the run.
        verbose: print one line per iteration on stdout, and the episodes as they end on
            stderr (a bar on a terminal, else a line each).

    Raises:
        InvalidConfigError: bad names, maps or env parameters (before any rollout), an
            ``output_dir`` holding a different run, or one another process runs in now
            (``output_dir/train.lock``, as :func:`training.train.train`).
    """
    from training.train import _output_dir_lock

    t0 = time.perf_counter()
    out = Path(cfg.output_dir)
    out.mkdir(parents=True, exist_ok=True)
    with _output_dir_lock(out):
        return _dagger(cfg, out, t0, verbose)


def _dagger(cfg: DaggerConfig, out: Path, t0: float, verbose: bool) -> DaggerResult:
    """:func:`dagger`'s body, with ``output_dir``'s lock held."""
    import torch
    from stable_baselines3 import PPO

    from training.train import ENV_ID, ENV_NAME, _git_state, _versions

    torch.set_num_threads(1)
    env = _learner_env(cfg)
    resumed = _resume(cfg, out, env)
    if resumed is None:
        torch.manual_seed(cfg.seed)
        model = PPO("MlpPolicy", env, policy_kwargs={"net_arch": list(cfg.net_arch)},
                    seed=cfg.seed, device="cpu", verbose=0)  # fmt: skip
        progress: dict[str, Any] = {
            "config": cfg.to_dict(),
            "maps": _map_fingerprints(cfg),
            "disagreement": [], "samples": [], "held": [], "fit_error": [], "episodes": [],
            "wall_seconds": 0.0,
        }  # fmt: skip
        data_obs: list[np.ndarray] = []
        data_act: list[np.ndarray] = []
    else:
        model, progress, data_obs, data_act = resumed
        progress["config"] = cfg.to_dict()
        progress["maps"] = _map_fingerprints(cfg)  # checked by _resume; a new stage's too
    opponent = cfg.opponent_policy()
    first = len(progress["samples"])
    bar = _episode_bar(cfg, first, verbose)
    for it in range(first, cfg.iterations):
        t_it = time.perf_counter()
        beta = cfg.beta**it
        wins, seen_l, seen_e, records = 0, [], [], []
        maps, start, env_overrides = cfg.stage(it)
        for ep in range(cfg.episodes):
            seed = cfg.seed * 100_003 + it * 1_009 + ep
            world = maps[(it * cfg.episodes + ep) % len(maps)]
            expert = make_policy(cfg.expert, **cfg.expert_params)
            roll = _Rollout(expert, model, beta, seed, cfg.observation, cfg.features)
            other = "evader" if cfg.role == "pursuer" else "pursuer"
            pair = {cfg.role: roll, other: opponent}
            r = run_episode(world, pair["pursuer"], pair["evader"], seed, max_cycles=cfg.max_cycles,
                            overrides=env_overrides, start=start)  # fmt: skip
            wins += r.winner == cfg.role
            if bar is not None:
                bar.update(1)
            elif verbose:  # not a terminal: a line per episode (a generalist's take minutes)
                print(f"dagger {cfg.role} iteration {it} episode {ep + 1}/{cfg.episodes}: "
                      f"{r.winner} won in {r.steps} steps on {world}",
                      file=sys.stderr, flush=True)  # fmt: skip
            records.append({"map": world, "start": start, "l_max": r.config.l_max,
                            "opponent": r.evader if other == "evader" else r.pursuer,
                            "winner": r.winner, "steps": r.steps})  # fmt: skip
            data_obs.extend(roll.obs)
            data_act.extend(roll.labels)
            seen_l.extend(roll.learned)
            seen_e.extend(roll.labels)
        d = np.linalg.norm(np.asarray(seen_l) - np.asarray(seen_e), axis=1)
        X, Y = np.asarray(data_obs), np.clip(np.asarray(data_act), -1, 1)
        _fit(model, X, Y, cfg, np.random.default_rng([cfg.seed, it]))
        pred, _ = model.predict(X, deterministic=True)
        progress["disagreement"].append(float(d.mean()) if len(d) else float("nan"))
        progress["held"].append(wins / cfg.episodes)
        progress["fit_error"].append(float(np.linalg.norm(np.clip(pred, -1, 1) - Y, axis=1).mean()))
        progress["samples"].append(len(data_obs))
        progress["episodes"].append(records)
        best = True
        if cfg.validation_episodes:
            won = _validate(cfg, model, opponent)
            curve = progress.setdefault("validation", [])
            curve.append(won)
            best = won >= max(curve)
            if best:
                progress["best_iteration"] = it
        progress["wall_seconds"] = round(progress["wall_seconds"] + time.perf_counter() - t_it, 3)
        _write_iteration(out, model, data_obs, data_act, progress, best)
        if verbose:
            say = print if bar is None else bar.write  # a line above the bar on a terminal
            say(f"dagger {cfg.role} iteration {it}: beta {beta:.3f}, samples {len(data_obs)}, "
                f"disagreement {progress['disagreement'][-1]:.3f}, fit error "
                f"{progress['fit_error'][-1]:.3f}, won {wins}/{cfg.episodes}"
                + (f", learner alone won {progress['validation'][-1]:.2f}"
                   if cfg.validation_episodes else "") + ", "
                f"{time.perf_counter() - t_it:.0f} s", file=sys.stdout)  # fmt: skip
            sys.stdout.flush()
    if bar is not None:
        bar.close()
    provenance = {
        "env_id": ENV_NAME,  # the version it trained on (its model card names it)
        "registry_id": ENV_ID,
        "role": cfg.role,
        "opponent": cfg.opponent if isinstance(cfg.opponent, str) else list(cfg.opponent),
        "algo": "ppo",
        "method": "dagger",
        "expert": cfg.expert,
        "config": cfg.to_dict(),
        "env_config": env.config.to_dict(),
        "maps": list(cfg.maps),
        "net_arch": list(cfg.net_arch),
        "parameters": int(sum(p.numel() for p in model.policy.parameters())),
        "disagreement": progress["disagreement"],
        "samples": progress["samples"],
        "held": progress["held"],
        "fit_error": progress["fit_error"],
        "validation": progress.get("validation", []),
        "best_iteration": progress.get("best_iteration", len(progress["samples"]) - 1),
        "wall_seconds": progress["wall_seconds"],
        **_git_state(),
        "versions": _versions(),
    }
    (out / "config.toml").write_text(cfg.to_toml())
    tmp = out / "provenance.json.tmp"
    tmp.write_text(json.dumps(provenance, indent=2) + "\n")
    os.replace(tmp, out / "provenance.json")
    env.close()
    return DaggerResult(out / "model.zip", progress["disagreement"], progress["samples"],
                        progress["held"], time.perf_counter() - t0, progress["fit_error"],
                        progress["episodes"], progress.get("validation", []),
                        provenance["best_iteration"])  # fmt: skip
