"""The model zoo: small trained policies shipped in the repo, each reproducible by one command.

Each model lives in ``training/zoo/models/<name>/`` as ``model.zip`` (an SB3 model, a
[64, 64] MLP), ``config.toml`` (the :class:`~training.config.TrainConfig` it was trained
from) and ``provenance.json`` (git SHA, package versions, timesteps, wall time, the
evaluation against its training opponent).

Examples:
    >>> from training import zoo
    >>> "ppo_pursuer_vs_straight_open_room" in zoo.list_models()
    True

Command line::

    python -m training.zoo list
    python -m training.zoo info NAME
    python -m training.zoo reproduce NAME [--output-dir DIR] [--install] [--no-progress]
    python -m training.zoo evaluate NAME --opponent evader/shooting [--episodes 50]
"""

from __future__ import annotations

import os
import re
import shutil
import warnings
from pathlib import Path
from typing import Any

from envs.errors import UnknownNameError
from strategies.policies import Policy
from training.config import TrainConfig, load_any_config
from training.dagger import DaggerConfig, DaggerResult, dagger
from training.train import TrainResult, load_policy, read_provenance, train

__all__ = [
    "MODELS_DIR",
    "ReproducibilityWarning",
    "code_changed_since",
    "config",
    "info",
    "install",
    "list_models",
    "load",
    "model_path",
    "policy_name",
    "reproduce",
    "run_config",
    "trained_env",
    "training_maps",
]

MODELS_DIR = Path(__file__).resolve().parent / "models"
"""Where the shipped models live."""

_FILES = ("model.zip", "config.toml", "provenance.json")


def list_models() -> list[str]:
    """Names of the shipped models, sorted."""
    if not MODELS_DIR.is_dir():
        return []
    return sorted(p.name for p in MODELS_DIR.iterdir() if all((p / f).is_file() for f in _FILES))


def _dir(name: str) -> Path:
    if name not in list_models():
        raise UnknownNameError(
            f"unknown zoo model {name!r}; known models: {', '.join(list_models()) or 'none'}"
        )
    return MODELS_DIR / name


def model_path(name: str) -> Path:
    """The ``model.zip`` of ``name``.

    Raises:
        UnknownNameError: listing the known models.
    """
    return _dir(name) / "model.zip"


def info(name: str) -> dict[str, Any]:
    """The provenance record of ``name`` (config, versions, timesteps, evaluation)."""
    return read_provenance(_dir(name))


def config(name: str) -> TrainConfig | DaggerConfig:
    """The training config of ``name`` (RL or DAgger, by its ``method``)."""
    return load_any_config(_dir(name) / "config.toml")


def run_config(
    name: str, output_dir: str | os.PathLike[str] | None = None
) -> TrainConfig | DaggerConfig:
    """The config :func:`reproduce` trains ``name`` with: its recipe, writing to
    ``output_dir`` (default ``out/zoo/<name>``)."""
    return config(name).replace(output_dir=os.fspath(output_dir or Path("out/zoo") / name))


def trained_env(name: str) -> str | None:
    """The env version ``name`` was trained on, e.g. ``"surveillance_v0"``.

    Its provenance's ``env_id`` when it has one (RL runs record it; DAgger runs since
    surveillance_v1); else the latest ``envs/surveillance_vN.py`` at the commit it was
    trained at (the runner played the latest version then); ``None`` when neither tells (no
    git, or a commit this clone does not have).
    """
    prov = info(name)
    if prov.get("env_id"):
        return str(prov["env_id"])
    from training.train import _git

    sha = prov.get("git_sha")
    listing = _git("ls-tree", "--name-only", sha, "envs/") if sha else None
    if not listing:
        return None
    found = [int(v) for v in re.findall(r"^envs/surveillance_v(\d+)\.py$", listing, re.M)]
    return f"surveillance_v{max(found)}" if found else None


def training_maps(name: str) -> list[str]:
    """The maps ``name`` trained on (a DAgger recipe's ``maps``, an RL recipe's ``map``)."""
    cfg = config(name)
    return list(getattr(cfg, "maps", None) or [cfg.map])


def policy_name(name: str) -> str:
    """The registry name that plays ``name``: ``"ROLE/sb3:PATH"``."""
    return f"{info(name)['role']}/sb3:{model_path(name)}"


def load(name: str, *, deterministic: bool = True) -> Policy:
    """The model ``name`` as a Policy (reset it with its role before ``act``).

    Raises:
        UnknownNameError: listing the known models.
    """
    return load_policy(model_path(name), deterministic=deterministic)


def reproduce(
    name: str,
    output_dir: str | os.PathLike[str] | None = None,
    *,
    install_result: bool = False,
    progress_bar: bool = False,
) -> TrainResult | DaggerResult:
    """Retrain ``name`` from its stored config (same seed, same hyperparameters).

    The result is the same model, bit for bit, on the same package versions and CPU
    (torch runs one thread; every random draw is seeded by the config).

    Args:
        name: a zoo model.
        output_dir: where to train (default ``out/zoo/<name>``); resumes if interrupted.
        install_result: replace the shipped model and provenance with the retrained ones
            (the shipped recipe, config.toml, is kept: it is what was retrained, and the
            run's copy differs only in ``output_dir``).
        progress_bar: show the progress on stderr: a bar on a terminal, else a line per
            DAgger episode or per tenth of an RL run's timesteps (and, for DAgger, a line
            per iteration on stdout). ``python -m training.zoo reproduce`` shows it unless
            given ``--no-progress``.
    """
    cfg = run_config(name, output_dir)
    from training.train import ENV_NAME

    changed = code_changed_since(info(name).get("git_sha"))
    was = trained_env(name)
    if changed:
        env = (
            f"it trained on {was} and training now plays {ENV_NAME}, whose episodes differ; "
            if was is not None and was != ENV_NAME
            else ""
        )
        warnings.warn(
            f"{name} was trained at {info(name)['git_sha'][:12]}; {env}the code it trains "
            f"with has changed since ({', '.join(changed[:5])}"
            f"{', ...' if len(changed) > 5 else ''}), so the retrained model may differ: "
            "check that commit out to reproduce it bit for bit",
            ReproducibilityWarning,
            stacklevel=2,
        )
    if isinstance(cfg, DaggerConfig):
        result = dagger(cfg, verbose=progress_bar)
        if install_result:
            install(name, cfg.output_dir, keep_config=True)
        return result
    result = train(cfg, progress_bar=progress_bar)
    if install_result:
        install(name, result.output_dir, keep_config=True)
    return result


class ReproducibilityWarning(UserWarning):
    """``reproduce`` runs code that differs from the code the model was trained with."""


def code_changed_since(sha: str | None) -> list[str]:
    """Files under envs/, strategies/ and training/ (models excluded) that differ between
    commit ``sha`` and the working tree; ``[]`` when they are the same or git cannot tell
    (no git, or an unknown commit)."""
    from training.train import _git

    if not sha:
        return []
    out = _git("diff", "--name-only", sha, "--", "envs", "strategies", "training",
               ":(exclude)training/zoo/models")  # fmt: skip
    return [] if not out else out.splitlines()


def install(name: str, run_dir: str | os.PathLike[str], *, keep_config: bool = False) -> Path:
    """Copy a finished run's model, config and provenance into the zoo as ``name``.

    Args:
        keep_config: keep the zoo's own ``config.toml`` where ``name`` has one (a
            reproduced run: the same recipe, the run's copy naming its own output_dir).

    Raises:
        UnknownNameError: the run directory lacks one of the files.
    """
    src = Path(run_dir)
    missing = [f for f in _FILES if not (src / f).is_file()]
    if missing:
        raise UnknownNameError(f"{str(src)!r} is not a finished run: missing {missing}")
    dst = MODELS_DIR / name
    dst.mkdir(parents=True, exist_ok=True)
    for f in _FILES:
        if keep_config and f == "config.toml" and (dst / f).is_file():
            continue
        shutil.copyfile(src / f, dst / f)
    return dst
