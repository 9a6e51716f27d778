"""Reading the env's ``"state"`` observation for analytic policies (by field name)."""

from __future__ import annotations

import numpy as np

from envs.errors import InvalidObservationError
from envs.surveillance.observations import decode_state

__all__ = ["finite_observation", "read_state"]


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
        InvalidObservationError: the observation is not an array of real numbers, has
            the wrong shape or is not finite.
    """
    obs = finite_observation(
        observation, "observation", "a 'state' observation (an array of real numbers)"
    )
    try:
        view = decode_state(obs, config)
    except ValueError as exc:
        raise InvalidObservationError(f"observation: {exc}") from exc
    return view.evader_pos, view.pursuer_pos, view.evader_vel, view.pursuer_vel


def finite_observation(
    observation, where: str, expected: str = "an array of real numbers"
) -> np.ndarray:
    """``observation`` as a float64 array, refused unless every entry is a finite real
    number (the first bad entry named): the one check of the analytic policies'
    :func:`read_state` and the learned policies' ``act``.

    Args:
        observation: what a policy was given.
        where: the message's prefix (``"observation"``, ``"NAME: observation"``).
        expected: what the message says was expected of a value that is no numbers.

    Raises:
        InvalidObservationError: not numbers, or a NaN or infinite entry.
    """
    try:
        obs = np.asarray(observation, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InvalidObservationError(
            f"{where}: expected {expected}, got {type(observation).__name__} {observation!r}"[:200]
        ) from exc
    if not np.all(np.isfinite(obs)):
        bad = np.flatnonzero(~np.isfinite(obs.ravel()))
        raise InvalidObservationError(
            f"{where}: expected finite values, got {obs.ravel()[bad[0]]} at index "
            f"{int(bad[0])} ({len(bad)} non-finite of {obs.size})"
        )
    return obs
