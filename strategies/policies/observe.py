"""Reading the env's ``"state"`` observation for analytic policies (by field name)."""

from __future__ import annotations

import numpy as np

from envs.errors import InvalidActionError
from envs.surveillance.observations import decode_state

__all__ = ["read_state"]


def read_state(
    observation: np.ndarray, config
) -> tuple[np.ndarray, np.ndarray, np.ndarray | None, np.ndarray | None]:
    """Evader and pursuer positions and their last realised velocities, in world units.

    Args:
        observation: a ``"state"`` observation (``STATE_LAYOUT``).
        config: the env's ``EnvConfig``.

    Returns:
        ``(evader, pursuer, evader_velocity, pursuer_velocity)``.

    Raises:
        InvalidActionError: the observation has the wrong shape or is not finite.
    """
    obs = np.asarray(observation, dtype=np.float64)
    if not np.all(np.isfinite(obs)):
        raise InvalidActionError(f"observation is not finite: {obs!r}")
    try:
        view = decode_state(obs, config)
    except ValueError as exc:
        raise InvalidActionError(str(exc)) from exc
    return view.evader_pos, view.pursuer_pos, view.evader_vel, view.pursuer_vel
