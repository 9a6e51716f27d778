"""Self-play: alternate rounds of pursuer and evader training, each against the latest other.

Round 0 trains ``config.role`` against ``config.opponent`` (a fixed policy), then the
other role against that fresh model; every later stage trains one role against the
other role's newest model, loaded through the ``ROLE/sb3:PATH`` policy name, warm
started from its own previous model. Each stage is an ordinary :func:`training.train`
run in ``output_dir/round<k>_<role>``, so an interrupted self-play resumes stage by stage
(finished stages are skipped, the interrupted one continues from its checkpoint).
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

from envs.errors import InvalidConfigError
from training.config import TrainConfig
from training.train import TrainResult, train

__all__ = ["SelfPlayResult", "self_play"]


@dataclass(frozen=True)
class SelfPlayResult:
    """The stages of a self-play run, in training order.

    Attributes:
        stages: one :class:`TrainResult` per (round, role).
    """

    stages: tuple[TrainResult, ...]

    def latest(self, role: str) -> TrainResult:
        """The last stage that trained ``role``.

        Raises:
            InvalidConfigError: no stage trained that role.
        """
        for stage in reversed(self.stages):
            if stage.config.role == role:
                return stage
        raise InvalidConfigError(f"self-play trained no {role!r} model")

    @property
    def policy_names(self) -> dict[str, str]:
        """``{"pursuer": "pursuer/sb3:PATH", "evader": "evader/sb3:PATH"}`` of the latest models."""
        return {role: self.latest(role).policy_name for role in ("pursuer", "evader")}


def self_play(
    config: TrainConfig,
    rounds: int = 2,
    *,
    output_dir: str | os.PathLike[str] | None = None,
    warm_start: bool = True,
    progress_bar: bool = False,
) -> SelfPlayResult:
    """Run ``rounds`` rounds of alternating training.

    Args:
        config: the first stage's run; ``role`` trains first against ``opponent``. Every
            stage uses its ``total_timesteps``, algorithm and hyperparameters; stage ``i``
            is seeded with ``config.seed + i``.
        rounds: rounds (>= 1); each trains both roles once.
        output_dir: base directory (default ``config.output_dir``).
        warm_start: start each role's later stages from its previous model.
        progress_bar: show each stage's progress on stderr (see :func:`training.train.train`).

    Returns:
        The :class:`SelfPlayResult`.

    Raises:
        InvalidConfigError: bad ``rounds``.
    """
    if isinstance(rounds, bool) or not isinstance(rounds, int) or rounds < 1:
        raise InvalidConfigError(f"rounds: expected an integer >= 1, got {rounds!r}")
    base = Path(output_dir if output_dir is not None else config.output_dir)
    first = config.role
    second = "evader" if first == "pursuer" else "pursuer"
    latest: dict[str, TrainResult] = {}
    stages: list[TrainResult] = []
    for k in range(rounds):
        for role in (first, second):
            other = second if role == first else first
            opponent = latest[other].policy_name if other in latest else config.opponent
            stage_config = config.replace(
                role=role,
                opponent=opponent,
                seed=config.seed + len(stages),
                output_dir=str(base / f"round{k}_{role}"),
            )
            init = latest[role].model_path if warm_start and role in latest else None
            result = train(stage_config, init_model=init, progress_bar=progress_bar)
            latest[role] = result
            stages.append(result)
    return SelfPlayResult(tuple(stages))
