"""SB3 training (PPO, SAC) of one role from a :class:`TrainConfig`, with resume and provenance.

:func:`train` builds a ``DummyVecEnv`` of :class:`~training.single_agent.SingleAgentEnv`,
trains on the CPU with one torch thread, and writes into ``config.output_dir``:

* ``config.toml`` -- the config of the run (a resumed run must match it);
* ``train.lock`` -- held while a process trains there (a second one is refused);
* ``env.json`` -- the maps the run plays, by name: each one's geometry digest and
  recommended parameters (:func:`~training.config.map_fingerprints`, as DAgger's
  ``progress.json`` records them): a resumed run must play the same (a map file edited
  in between is refused, not trained on without a word);
* ``checkpoints/ckpt_<timesteps>.zip`` -- written as it goes (atomically, the last two
  kept); a rerun of an interrupted run continues from the newest one with the
  remaining timesteps;
* ``model.zip`` -- the final model, loadable as ``make_policy("ROLE/sb3:.../model.zip")``;
* ``provenance.json`` -- config, git SHA, versioned env id, package versions,
  timesteps, wall time, evaluation.

A resumed run continues from the checkpoint's weights and counters with the env and
model reseeded from ``seed + timesteps``: deterministic given the checkpoint, but not bit
for bit the run that was never interrupted (the rollout in progress is lost).
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import re
import subprocess
import sys
import time
import warnings
from dataclasses import asdict, dataclass, field
from importlib import metadata
from pathlib import Path
from typing import Any

import numpy as np

from envs import pidlock
from envs.errors import InvalidConfigError
from envs.files import written_whole
from envs.maps.map import Map
from envs.surveillance_v1 import ENV_ID
from strategies.policies import Policy, make_policy
from training.config import TrainConfig, check_same_maps, load_config, map_fingerprints
from training.single_agent import SingleAgentEnv, sb3_params

__all__ = [
    "ENV_NAME",
    "EVAL_SEED_OFFSET",
    "CheckpointWarning",
    "EvalResult",
    "TrainResult",
    "evaluate_model",
    "latest_checkpoint",
    "load_policy",
    "read_provenance",
    "train",
    "train_from_config",
]

ENV_NAME = "surveillance_v1"
"""The versioned env every model here is trained on (recorded in provenance)."""

EVAL_SEED_OFFSET = 1_000_003
"""The final evaluation uses ``seed + EVAL_SEED_OFFSET``: starts the training never drew."""

KEEP_CHECKPOINTS = 2
_CKPT = re.compile(r"^ckpt_(\d+)\.zip$")
_BUFFER = re.compile(r"^replay_buffer_(\d+)\.pkl$")
_PACKAGES = (
    "numpy",
    "torch",
    "stable-baselines3",
    "gymnasium",
    "pettingzoo",
    "pymunk",
    "shapely",
    "scipy",
)


# --------------------------------------------------------------------------- results
@dataclass(frozen=True)
class EvalResult:
    """A model's record against one opponent.

    Attributes:
        role: the model's role.
        opponent: the opponent's name.
        episodes: episodes played.
        successes: episodes the model won (pursuer: surveillance held to the horizon;
            evader: surveillance broke).
        success_rate: ``successes / episodes``.
        mean_escape_time: mean time (s) at which surveillance broke, over the episodes
            where it did (NaN if it never did).
        escape_times: those times, in episode order.
        causes: escape causes and their counts.
        maps: the maps played (a DAgger recipe's list draws one per episode).
    """

    role: str
    opponent: str
    episodes: int
    successes: int
    success_rate: float
    mean_escape_time: float
    escape_times: tuple[float, ...] = ()
    causes: dict[str, int] = field(default_factory=dict)
    maps: tuple[str, ...] = ()

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict (NaN written as ``None``)."""
        d = asdict(self)
        d["escape_times"] = list(self.escape_times)
        if math.isnan(self.mean_escape_time):
            d["mean_escape_time"] = None
        return d


@dataclass(frozen=True)
class TrainResult:
    """What :func:`train` produced.

    Attributes:
        config: the run's config.
        output_dir: where everything was written.
        model_path: the final ``model.zip``.
        provenance_path: ``provenance.json``.
        timesteps: timesteps the final model has been trained for.
        wall_time: seconds spent in this call (training and evaluation).
        resumed_from: the checkpoint this call continued from, if any.
        evaluation: the final evaluation against the opponent (``None`` if skipped).
        already_trained: ``output_dir`` held a finished run at least this long, returned
            as is (nothing trained: ``wall_time`` is 0).
    """

    config: TrainConfig
    output_dir: Path
    model_path: Path
    provenance_path: Path
    timesteps: int
    wall_time: float
    resumed_from: Path | None
    evaluation: EvalResult | None
    already_trained: bool = False

    @property
    def policy_name(self) -> str:
        """The registry name that loads this model: ``"ROLE/sb3:PATH"``."""
        return f"{self.config.role}/sb3:{self.model_path}"


# --------------------------------------------------------------------------- helpers
def _algo_class(algo: str):
    import stable_baselines3

    return getattr(stable_baselines3, algo.upper())


def latest_checkpoint(output_dir: str | os.PathLike[str]) -> tuple[int, Path] | None:
    """The newest ``checkpoints/ckpt_<timesteps>.zip`` in ``output_dir``, if any."""
    found = []
    ckdir = Path(output_dir) / "checkpoints"
    if ckdir.is_dir():
        for p in ckdir.iterdir():
            m = _CKPT.match(p.name)
            if m:
                found.append((int(m.group(1)), p))
    return max(found) if found else None


def read_provenance(path: str | os.PathLike[str]) -> dict[str, Any]:
    """The ``provenance.json`` of a model zip (or of a run directory).

    Raises:
        InvalidConfigError: there is no readable ``provenance.json`` next to it.
    """
    p = Path(path)
    prov = (p if p.is_dir() else p.parent) / "provenance.json"
    try:
        return json.loads(prov.read_text())
    except (OSError, json.JSONDecodeError) as exc:
        raise InvalidConfigError(f"{str(prov)!r}: no readable provenance ({exc})") from exc


def _provenance_or_none(path: str | os.PathLike[str]) -> dict[str, Any] | None:
    try:
        return read_provenance(path)
    except InvalidConfigError:
        return None


def load_policy(
    path: str | os.PathLike[str], *, role: str | None = None, deterministic: bool = True
) -> Policy:
    """A trained model zip as a Policy: ``make_policy("ROLE/sb3:PATH")``.

    The role and the algorithm come from the ``provenance.json`` beside the zip when
    there is one (the algorithm is passed explicitly: ``SB3Policy`` cannot tell PPO
    from A2C by the zip alone, as both save ``common.policies.ActorCriticPolicy``).

    Raises:
        InvalidConfigError: no role given and no provenance to read it from.
    """
    prov = _provenance_or_none(path)
    if role is None:
        if prov is None:
            raise InvalidConfigError(f"{os.fspath(path)!r}: pass role=, no provenance.json")
        role = prov["role"]
    name = f"{role}/sb3:{os.fspath(path)}"
    return make_policy(name, deterministic=deterministic, **sb3_params(name))


def _atomic_write(path: Path, text: str) -> None:
    with written_whole(path, "training output") as tmp:  # a full disk: named, none left
        tmp.write_text(text)


def _save_model(model, path: Path) -> None:
    with written_whole(path, "training output") as tmp:  # ends in .zip: SB3 adds none
        model.save(str(tmp))


def _git(*args: str) -> str | None:
    root = Path(__file__).resolve().parents[1]
    try:
        out = subprocess.run(["git", *args], cwd=root, capture_output=True, text=True, timeout=10)
    except (OSError, subprocess.SubprocessError):
        return None
    return out.stdout.strip() if out.returncode == 0 else None


def _git_state() -> dict[str, Any]:
    """HEAD's SHA and whether the code this package runs differs from it (``None``: no git)."""
    sha = _git("rev-parse", "HEAD")
    status = _git("status", "--porcelain", "--", "envs", "strategies", "training")
    return {"git_sha": sha or None, "git_dirty": None if status is None else bool(status)}


def _versions() -> dict[str, str | None]:
    out: dict[str, str | None] = {"python": sys.version.split()[0]}
    for name in _PACKAGES:
        try:
            out[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            out[name] = None
    return out


_RESUME_FREE = {"total_timesteps", "eval_episodes", "eval_start", "checkpoint_freq", "output_dir"}
"""Fields a resumed run may change: they do not alter what has been learned so far."""


def _check_resumable(config: TrainConfig, out: Path) -> None:
    """Refuse to continue a run of another config. Only a run with something learned
    (a checkpoint or a model) is one: a run stopped before its first checkpoint (an
    opponent model that failed to load at the first reset, an early Ctrl-C) left its
    ``config.toml`` and nothing to continue, and the corrected rerun starts afresh."""
    stored = out / "config.toml"
    if not stored.is_file() or not _latest_checkpoint_exists(out):
        return
    before = load_config(stored).to_dict()
    now = config.to_dict()
    diff = sorted(k for k in now if k not in _RESUME_FREE and before.get(k) != now[k])
    if diff:
        raise InvalidConfigError(
            f"output_dir {str(out)!r} holds a run with a different config (fields {diff}: "
            f"{[before.get(k) for k in diff]} there, {[now[k] for k in diff]} now); "
            f"use another output_dir or delete that one"
        )


def _check_same_envs(config: TrainConfig, out: Path) -> None:
    """Refuse to resume a run whose maps now resolve to other games (``config.toml`` names a
    map file by its path: its geometry or recommended parameters may have changed since),
    by :func:`~training.config.check_same_maps`; record them in ``env.json`` for the first
    segment (and for a run of a surveil without ``env.json``)."""
    names = [config.map] if isinstance(config.map, str) else [str(m) for m in config.map]
    now = map_fingerprints(names)
    stored = out / "env.json"
    if stored.is_file() and _latest_checkpoint_exists(out):
        try:
            before = json.loads(stored.read_text())
        except ValueError:  # a torn write: nothing to compare with
            before = None
        if isinstance(before, list) and len(before) == len(names):
            # an older surveil's env.json: the resolved env config of each map in the
            # config's order, whose values include [env]'s (compared as the config): its
            # geometry digest is what it says of the map alone
            before = {
                n: {**now[n], "digest": e.get("map_digest") if isinstance(e, dict) else None}
                for n, e in zip(names, before, strict=True)
            }
        where = f"output_dir {str(out)!r} holds a run"
        check_same_maps(before, now, where=where)
    _atomic_write(stored, json.dumps(now, indent=1, sort_keys=True))


def _latest_checkpoint_exists(out: Path) -> bool:
    return latest_checkpoint(out) is not None or (out / "model.zip").is_file()


def _make_vec_env(config: TrainConfig):
    from stable_baselines3.common.monitor import Monitor
    from stable_baselines3.common.vec_env import DummyVecEnv

    def factory():
        return Monitor(SingleAgentEnv(config.role, config.opponent_policy(), **config.env_kwargs()))

    return DummyVecEnv([factory] * config.n_envs)


def _new_model(config: TrainConfig, vec_env):
    cls = _algo_class(config.algo)
    kwargs: dict[str, Any] = {
        "learning_rate": config.learning_rate,
        "gamma": config.gamma,
        "batch_size": config.batch_size,
        "policy_kwargs": {**config.policy_kwargs, "net_arch": list(config.net_arch)},
        "seed": config.seed,
        "device": "cpu",
        "verbose": 0,
    }
    if config.algo == "ppo":
        kwargs["n_steps"] = config.n_steps
    kwargs.update(config.algo_kwargs)
    return cls("MlpPolicy", vec_env, **kwargs)


def _load_checkpoint(out: Path, cls, vec_env):
    """The newest checkpoint that loads, as ``(timesteps, path, model)``, or None.

    A damaged checkpoint (truncated by a crash, a flipped bit) is skipped with a one-line
    warning naming it, and the next older one is tried: an intact older checkpoint is
    never blocked by a broken newer one.
    """
    ckdir = out / "checkpoints"
    if not ckdir.is_dir():
        return None
    found = sorted(
        ((int(m.group(1)), p) for p in ckdir.iterdir() if (m := _CKPT.match(p.name))),
        reverse=True,
    )
    for done, path in found:
        try:
            return done, path, cls.load(str(path), env=vec_env, device="cpu")
        except Exception as exc:  # a damaged zip fails in zipfile, json, torch or pickle
            warnings.warn(
                f"checkpoint {path} cannot be loaded ({type(exc).__name__}: {exc}); "
                "trying an older one",
                CheckpointWarning,
                stacklevel=3,
            )
    return None


class CheckpointWarning(RuntimeWarning):
    """A checkpoint could not be loaded and was skipped."""


def _quiet_logger(model) -> None:
    """Give SB3 a logger that writes nothing, so ``learn`` makes no SB3-<date> folder.

    Without one, SB3 configures a default logger in the system temp directory on every
    ``learn`` call (``stable_baselines3.common.utils.configure_logger``).
    """
    from stable_baselines3.common.logger import Logger

    model.set_logger(Logger(folder=None, output_formats=[]))


def _checkpoint_callback(config: TrainConfig, out: Path, start: int):
    from stable_baselines3.common.callbacks import BaseCallback

    class Checkpoint(BaseCallback):
        """Saves at the start of a rollout, when the previous one has been trained on."""

        def __init__(self) -> None:
            super().__init__()
            self.last = start

        def _on_step(self) -> bool:
            return True

        def _on_rollout_start(self) -> None:
            n = self.model.num_timesteps
            if n - self.last >= config.checkpoint_freq:
                self.last = n
                _checkpoint(self.model, config, out)

    return Checkpoint()


def _progress_callback(config: TrainConfig, start: int):
    """Progress of a run on stderr: a bar over the timesteps on a terminal, else a line at
    every tenth of them (a log keeps lines, not a bar's redraws: SB3's rich bar, used
    before, showed a log only its final state)."""
    from stable_baselines3.common.callbacks import BaseCallback
    from tqdm import tqdm

    total = config.total_timesteps
    label = f"{config.algo} {config.role}"

    class Progress(BaseCallback):
        def __init__(self) -> None:
            super().__init__()
            self.bar = None
            self.tenth = 10 * start // total  # tenths already reported (a resumed run)
            self.t0 = time.perf_counter()

        def _on_training_start(self) -> None:
            if sys.stderr.isatty():
                self.bar = tqdm(total=total, initial=start, unit="step", desc=label,
                                file=sys.stderr, dynamic_ncols=True)  # fmt: skip

        def _on_step(self) -> bool:
            n = min(int(self.model.num_timesteps), total)
            if self.bar is not None:
                self.bar.update(n - self.bar.n)
            elif 10 * n // total > self.tenth:
                self.tenth = 10 * n // total
                took = time.perf_counter() - self.t0
                print(f"{label}: {n:,} of {total:,} timesteps ({took:.0f} s)", file=sys.stderr,
                      flush=True)  # fmt: skip
            return True

        def _on_training_end(self) -> None:
            if self.bar is not None:
                self.bar.close()

    return Progress()


def _checkpoint(model, config: TrainConfig, out: Path) -> None:
    """Write ``checkpoints/ckpt_<timesteps>.zip`` (and SAC's replay buffer), keep the last two."""
    ckdir = out / "checkpoints"
    ckdir.mkdir(parents=True, exist_ok=True)
    if config.algo == "sac":  # the buffer first: a checkpoint never lacks its buffer
        buf = ckdir / f"replay_buffer_{model.num_timesteps}.pkl"
        with written_whole(buf, "training output") as tmp:
            model.save_replay_buffer(str(tmp))
    _save_model(model, ckdir / f"ckpt_{model.num_timesteps}.zip")
    old = sorted((int(m.group(1)), p) for p in ckdir.iterdir() if (m := _CKPT.match(p.name)))
    for _, p in old[:-KEEP_CHECKPOINTS]:
        p.unlink(missing_ok=True)
    # each checkpoint has its own buffer: one shared file (replay_buffer.pkl, still read
    # by older runs) paired an older checkpoint, resumed when the newest was damaged or
    # not yet written, with the newer buffer
    kept = {n for n, _ in old[-KEEP_CHECKPOINTS:]}
    for p in ckdir.iterdir():
        m = _BUFFER.match(p.name)
        if (m is not None and int(m.group(1)) not in kept) or p.name == "replay_buffer.pkl":
            p.unlink(missing_ok=True)


# --------------------------------------------------------------------------- training
def train(
    config: TrainConfig,
    *,
    init_model: str | os.PathLike[str] | None = None,
    callbacks: list[Any] | None = None,
    progress_bar: bool = False,
) -> TrainResult:
    """Train ``config.role`` against ``config.opponent``, resuming if interrupted.

    Args:
        config: the run.
        init_model: a model zip to start from instead of fresh weights (self-play warm
            start; ignored when resuming from a checkpoint).
        callbacks: extra SB3 callbacks (run after the checkpoint callback).
        progress_bar: show the progress on stderr (a bar on a terminal, else a line at
            every tenth of the timesteps).

    Returns:
        The :class:`TrainResult`. If ``output_dir`` already holds a finished run with at
        least ``total_timesteps``, it is returned as is, without training.

    Raises:
        InvalidConfigError: ``output_dir`` holds a run with another config, or another
            process is training there now.
    """
    import torch

    t0 = time.perf_counter()
    torch.set_num_threads(1)
    out = Path(config.output_dir)
    out.mkdir(parents=True, exist_ok=True)
    with _output_dir_lock(out):
        return _train(config, out, t0, init_model, callbacks, progress_bar)


@contextlib.contextmanager
def _output_dir_lock(out: Path):
    """Hold ``out/train.lock`` while a run trains there, or refuse naming the holder: two
    runs in one ``output_dir`` at once both trained, writing each other's checkpoints and
    model (identical configs: identical files; other timesteps: interleaved). A POSIX
    record lock (:mod:`envs.pidlock`, as a tournament store's)."""
    try:
        f = pidlock.acquire(out.resolve() / "train.lock")
    except pidlock.LockHeldError as e:
        raise InvalidConfigError(
            f"output_dir {str(out)!r} is being trained by {e.holder}; wait for that run "
            "to finish (or stop it), or use another output_dir"
        ) from None
    try:
        yield
    finally:
        pidlock.release(f)


def _train(config, out, t0, init_model, callbacks, progress_bar) -> TrainResult:
    """:func:`train`'s body, with ``output_dir``'s lock held."""
    _check_resumable(config, out)
    model_path, prov_path = out / "model.zip", out / "provenance.json"
    previous = None
    if model_path.is_file() and prov_path.is_file():
        previous = read_provenance(out)
        if previous.get("timesteps", -1) >= config.total_timesteps:
            # a finished run at least this long: returned as is, and its config.toml
            # (the values that produced the model) is left alone
            return _result_from_provenance(config, out, previous)
    # the envs first: an opponent that does not resolve (a misspelt name) must not leave a
    # config.toml behind, which would refuse the corrected rerun as "a different config"
    vec_env = _make_vec_env(config)
    _check_same_envs(config, out)
    _atomic_write(out / "config.toml", config.to_toml())
    cls = _algo_class(config.algo)
    ckpt = _load_checkpoint(out, cls, vec_env)
    resumed_from = None
    if ckpt is not None:
        done, path, model = ckpt
        buf = out / "checkpoints" / f"replay_buffer_{done}.pkl"
        if config.algo == "sac" and not buf.is_file():
            buf = out / "checkpoints" / "replay_buffer.pkl"  # a run of an older surveil
        if config.algo == "sac" and buf.is_file():
            model.load_replay_buffer(str(buf))
        model.set_random_seed(config.seed + done)
        model._last_obs = None  # start fresh episodes in the new env copies
        resumed_from = path
    elif init_model is not None:
        model = cls.load(str(init_model), env=vec_env, device="cpu")
        model.set_random_seed(config.seed)
        model._last_obs = None
        # a warm start is a new run of total_timesteps: the loaded counter (the earlier
        # run's) left none to train, and self-play's later rounds returned their warm
        # start unchanged
        model.num_timesteps = 0
        done = 0
    else:
        model = _new_model(config, vec_env)
        done = 0
    _quiet_logger(model)
    remaining = config.total_timesteps - model.num_timesteps
    if remaining > 0:
        cbs = [_checkpoint_callback(config, out, model.num_timesteps), *(callbacks or [])]
        if progress_bar:
            cbs.append(_progress_callback(config, int(model.num_timesteps)))
        model.learn(
            total_timesteps=remaining,
            callback=cbs,
            reset_num_timesteps=resumed_from is None,
        )
    # model.zip is replaced only beside its provenance, at the end: written first, an
    # interrupt during the evaluation left an extended run's model beside the shorter
    # run's provenance, and a rerun at the shorter length returned it as that model
    pending = out / "model.next.zip"
    _save_model(model, pending)
    timesteps = int(model.num_timesteps)
    if remaining > 0:  # the final state is a checkpoint too: a longer rerun continues it
        _checkpoint(model, config, out)
    vec_env.close()
    train_time = time.perf_counter() - t0

    evaluation = None
    if config.eval_episodes > 0:
        learner = make_policy(f"{config.role}/sb3:{pending}", algo=config.algo.upper())
        evaluation = evaluate_model(
            learner,
            config.opponent_policy(),
            episodes=config.eval_episodes,
            seed=config.seed + EVAL_SEED_OFFSET,
            role=config.role,
            map=config.map,
            start=config.eval_start,
            env=config.env,
        )
    wall = time.perf_counter() - t0
    provenance = {
        "env_id": ENV_NAME,
        "registry_id": ENV_ID,
        "role": config.role,
        "opponent": config.opponent if isinstance(config.opponent, str) else list(config.opponent),
        "algo": config.algo,
        "config": config.to_dict(),
        "env_config": SingleAgentEnv(
            config.role, config.opponent_policy(), **config.env_kwargs()
        ).config.to_dict(),
        **_git_state(),
        "packages": _versions(),
        "timesteps": timesteps,
        "resumed_from": None if resumed_from is None else resumed_from.name,
        "resumed_at": done if resumed_from is not None else None,
        "init_model": None if init_model is None else str(init_model),
        "train_seconds": round(train_time, 3),
        "wall_seconds": round(wall, 3),
        "evaluation": None if evaluation is None else evaluation.to_dict(),
        "created": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
    }
    # every segment of the run, oldest first: a resumed or extended run keeps the story
    segment = {
        k: provenance[k]
        for k in ("created", "timesteps", "resumed_from", "resumed_at", "train_seconds")
    }
    segment["git_sha"] = provenance.get("git_sha")
    segment["total_timesteps"] = config.total_timesteps
    history = list((previous or {}).get("history") or [])
    if previous is not None and not history:  # written before histories were kept
        history = [{k: previous.get(k) for k in segment}]
    provenance["history"] = [*history, segment]
    os.replace(pending, model_path)
    _atomic_write(prov_path, json.dumps(provenance, indent=2) + "\n")
    return TrainResult(
        config, out, model_path, prov_path, timesteps, wall, resumed_from, evaluation
    )


def _result_from_provenance(config: TrainConfig, out: Path, prov: dict[str, Any]) -> TrainResult:
    ev = prov.get("evaluation")
    evaluation = None
    if ev is not None:
        ev = dict(ev)
        ev["escape_times"] = tuple(ev.get("escape_times", ()))
        ev["maps"] = tuple(ev.get("maps", ()))  # absent in provenance written before
        if ev.get("mean_escape_time") is None:
            ev["mean_escape_time"] = math.nan
        evaluation = EvalResult(**ev)
    return TrainResult(
        config,
        out,
        out / "model.zip",
        out / "provenance.json",
        int(prov["timesteps"]),
        0.0,
        None,
        evaluation,
        already_trained=True,
    )


def train_from_config(
    path: str | os.PathLike[str],
    *,
    output_dir: str | os.PathLike[str] | None = None,
    total_timesteps: int | None = None,
    seed: int | None = None,
    progress_bar: bool = False,
) -> TrainResult:
    """Load a TOML config (optionally overriding some fields) and :func:`train` it.

    Raises:
        InvalidConfigError: the file or a field is bad.
    """
    overrides: dict[str, Any] = {}
    if output_dir is not None:
        overrides["output_dir"] = os.fspath(output_dir)
    if total_timesteps is not None:
        overrides["total_timesteps"] = total_timesteps
    if seed is not None:
        overrides["seed"] = seed
    return train(load_config(path, **overrides), progress_bar=progress_bar)


# --------------------------------------------------------------------------- evaluation
def evaluate_model(
    path: str | os.PathLike[str] | Policy,
    opponent: str | Policy,
    episodes: int = 20,
    seed: int = 0,
    *,
    role: str | None = None,
    map: str | None = None,
    start: str | None = None,
    env: dict[str, Any] | None = None,
    deterministic: bool = True,
) -> EvalResult:
    """Play a trained model against ``opponent`` and count its wins.

    ``role``, ``map`` and ``env`` default to those in the ``provenance.json`` beside the
    model (the settings it was trained with, which matter: the observation holds the
    time as a fraction of ``max_cycles``): an RL recipe's ``map`` and ``env``, a DAgger
    recipe's ``maps`` (one drawn per episode) and ``env`` with its rollouts'
    ``max_cycles``. The env gives the model the observation it was trained on (its
    ``observation_options``: the state for a model with analytic features); ``start``
    defaults to ``"safe"``.

    Args:
        path: the model zip (or an already built Policy, with ``role`` and ``map`` given).
        opponent: the other role's policy name or Policy.
        episodes: episodes to play (>= 1).
        seed: seeds the episode stream (starts, env, opponent, model).
        role, map, start, env: see above.
        deterministic: use the model's deterministic action.

    Returns:
        The :class:`EvalResult`.

    Raises:
        InvalidConfigError: bad arguments, or settings missing with no provenance.
    """
    if isinstance(episodes, bool) or not isinstance(episodes, int) or episodes < 1:
        raise InvalidConfigError(f"episodes: expected an integer >= 1, got {episodes!r}")
    from envs import validation

    validation.integer("seed", seed, minimum=0)  # was numpy's "expected non-negative integer"
    if isinstance(path, Policy):
        learner = path
        if role is None or map is None:
            raise InvalidConfigError("evaluate_model: pass role= and map= with a Policy")
    else:
        prov = _provenance_or_none(path)
        if role is None or map is None or env is None:
            if prov is None:
                read_provenance(path)  # raises, naming the missing file
            cfg = prov["config"]
            role = role or prov["role"]
            # an RL recipe names one map, a DAgger recipe a list (it had no "map": KeyError)
            map = map or cfg.get("map") or list(cfg["maps"])
            if env is None:
                env = dict(cfg["env"])
                if "maps" in cfg and "max_cycles" in cfg:  # a DAgger recipe's rollouts
                    env.setdefault("max_cycles", cfg["max_cycles"])
        learner = load_policy(path, role=role, deterministic=deterministic)
    # the observation the model reads (a DAgger recipe keeps it out of "env"; a model with
    # features builds its input from the state)
    seen = getattr(learner, "observation_options", None) or {}
    game = SingleAgentEnv(role, opponent, map=map, start=start or "safe", **{**(env or {}), **seen})
    rng = np.random.default_rng(np.random.SeedSequence(int(seed)).spawn(1)[0])
    successes, times, causes = 0, [], {}
    obs, _ = game.reset(seed=int(seed))
    for k in range(episodes):
        if k:
            obs, _ = game.reset()
        learner.reset(
            role=role, map=game.config.map, config=game.config, seed=int(rng.integers(2**31 - 1))
        )
        while True:
            obs, _, terminated, truncated, info = game.step(learner.act(obs))
            if terminated or truncated:
                break
        if terminated:
            times.append(float(info["break_at"]))
            cause = str(info.get("cause"))
            causes[cause] = causes.get(cause, 0) + 1
        successes += int(terminated) if role == "evader" else int(not terminated)
    game.close()
    return EvalResult(
        role=role,
        opponent=opponent if isinstance(opponent, str) else opponent.name,
        episodes=episodes,
        successes=successes,
        success_rate=successes / episodes,
        mean_escape_time=float(np.mean(times)) if times else math.nan,
        escape_times=tuple(times),
        causes=causes,
        maps=tuple(_map_name(m) for m in ([map] if isinstance(map, str | Map) else map)),
    )


def _map_name(m: Any) -> str:
    return m.name if isinstance(m, Map) else str(m)
