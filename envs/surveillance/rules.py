"""The rules of the game as pure functions: surveillance status, rewards, episode end.

Surveillance holds while the segment pursuer-evader (the rod) touches no wall and
``L_min <= |P - E| <= L_max`` (paper, Sec. 2). The evader wins the moment it breaks
(escape: the episode *terminates* for both agents); the pursuer wins if it holds until
``max_cycles`` steps have passed (the episode is *truncated*).

Reward schemes (pursuer's view; the evader always receives the negation, so both are
zero-sum at every step):

``"zero_sum"`` (dense)
    ``+1 / max_cycles`` for every step in which surveillance held throughout, and
    ``-1`` on escape. A pursuer that holds to the horizon collects exactly ``+1``; one
    that loses at step k collects ``(k - 1) / max_cycles - 1`` in ``[-1, 0)``.
``"sparse"``
    ``-1`` on escape; ``+1`` at the horizon if surveillance held to the end; 0 otherwise.

Each component is reported separately in the step's ``info`` (``reward_surveillance``,
``reward_escape``, ``reward_horizon``), signed for the receiving agent.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Protocol

from envs.maps import Feature

__all__ = [
    "CAUSES",
    "RewardComponents",
    "Status",
    "in_range",
    "reward_components",
    "surveillance_status",
    "truncated",
]

CAUSES = ("occluded", "too_far", "too_close")
"""Why surveillance broke: a wall on the rod, the rod longer than L_max, or shorter than L_min."""


class _LineOfSight(Protocol):
    def blocking_feature(self, p: object, q: object) -> Feature | None: ...


@dataclass(frozen=True)
class Status:
    """Surveillance status of one configuration.

    Attributes:
        holds: True when surveillance holds.
        cause: ``None`` when it holds, else one of :data:`CAUSES` (range is checked first).
        feature: the occluding wall feature when ``cause == "occluded"``.
        distance: |P - E|.
    """

    holds: bool
    cause: str | None
    feature: Feature | None
    distance: float


def in_range(distance: float, l_min: float, l_max: float) -> str | None:
    """Return ``None`` if ``l_min <= distance <= l_max``, else the range cause.

    Examples:
        >>> in_range(1.0, 1.0, 4.0) is None, in_range(0.5, 1.0, 4.0), in_range(5.0, 1.0, 4.0)
        (True, 'too_close', 'too_far')
    """
    if distance < l_min:
        return "too_close"
    if distance > l_max:
        return "too_far"
    return None


def surveillance_status(
    kernel: _LineOfSight,
    pursuer: tuple[float, float],
    evader: tuple[float, float],
    l_min: float,
    l_max: float,
) -> Status:
    """Surveillance status of the configuration (pursuer, evader) at one instant.

    Args:
        kernel: the map's geometry kernel (``envs.geometry.kernel_for(map)``).
        pursuer: pursuer position Q.
        evader: evader position E.
        l_min: L_min.
        l_max: L_max.

    Returns:
        The :class:`Status`; the range is tested before line of sight.
    """
    d = math.hypot(pursuer[0] - evader[0], pursuer[1] - evader[1])
    cause = in_range(d, l_min, l_max)
    if cause is not None:
        return Status(False, cause, None, d)
    feature = kernel.blocking_feature(pursuer, evader)
    if feature is not None:
        return Status(False, "occluded", feature, d)
    return Status(True, None, None, d)


@dataclass(frozen=True)
class RewardComponents:
    """One step's reward for the pursuer, split by source (the evader gets the negation).

    Attributes:
        surveillance: dense reward for a step with surveillance held throughout.
        escape: penalty when the evader escapes.
        horizon: bonus when surveillance holds until truncation (``"sparse"`` only).
    """

    surveillance: float
    escape: float
    horizon: float

    @property
    def total(self) -> float:
        """The pursuer's reward: the sum of the components."""
        return self.surveillance + self.escape + self.horizon


def reward_components(
    kind: str, *, escaped: bool, truncated: bool, max_cycles: int
) -> RewardComponents:
    """The pursuer's reward components for one step.

    Args:
        kind: ``"zero_sum"`` or ``"sparse"`` (see the module docstring).
        escaped: surveillance broke during the step.
        truncated: the step reached ``max_cycles`` (ignored when ``escaped``).
        max_cycles: the episode horizon in steps.

    Examples:
        >>> reward_components("zero_sum", escaped=False, truncated=False, max_cycles=4).total
        0.25
        >>> reward_components("sparse", escaped=False, truncated=True, max_cycles=4).total
        1.0
        >>> reward_components("sparse", escaped=True, truncated=True, max_cycles=4).total
        -1.0
    """
    escape = -1.0 if escaped else 0.0
    if kind == "zero_sum":
        return RewardComponents(0.0 if escaped else 1.0 / max_cycles, escape, 0.0)
    if kind == "sparse":
        return RewardComponents(0.0, escape, 1.0 if (truncated and not escaped) else 0.0)
    raise ValueError(f"reward: expected 'zero_sum' or 'sparse', got {kind!r}")


def truncated(step: int, max_cycles: int) -> bool:
    """True once ``step`` (steps taken so far) reaches the horizon ``max_cycles``."""
    return step >= max_cycles
