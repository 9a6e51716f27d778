"""Corridor junctions: a plus-shaped crossroads and a T-junction, centred on the origin.

Worlds with no obstacle inside, only the free space's outline: arms of length ``arm`` and
width ``width`` meeting in a ``width`` x ``width`` square. With corridors narrower than
L_min every cell is escapable (Prop. 2 holds: the evader wins), which makes them test
worlds for evaders that must leave a cell through a crossing near a wall (issue 13).

Examples:
    >>> len(crossroads().boundary), len(t_junction().boundary)
    (12, 8)
    >>> crossroads(arm=4.0, width=1.6).bounds
    (-4.8, -4.8, 4.8, 4.8)
"""

from __future__ import annotations

from envs import validation
from envs.maps.map import Map

__all__ = ["crossroads", "t_junction"]


def crossroads(arm: float = 4.0, width: float = 1.6) -> Map:
    """Four arms of length ``arm`` and width ``width`` meeting at the origin.

    Raises:
        InvalidConfigError: ``arm`` or ``width`` is not a finite number > 0.
    """
    arm, width = _sizes("crossroads", arm, width)
    h = width / 2
    r = h + arm
    pts = [(h, -r), (h, -h), (r, -h), (r, h), (h, h), (h, r), (-h, r), (-h, h), (-r, h),
           (-r, -h), (-h, -h), (-h, -r)]  # fmt: skip
    return Map(pts, name="plus")


def t_junction(arm: float = 3.0, width: float = 1.6) -> Map:
    """A corridor along x with one arm of length ``arm`` up the y axis.

    Raises:
        InvalidConfigError: ``arm`` or ``width`` is not a finite number > 0.
    """
    arm, width = _sizes("t_junction", arm, width)
    h = width / 2
    pts = [(-arm - h, -h), (arm + h, -h), (arm + h, h), (h, h), (h, arm + h), (-h, arm + h),
           (-h, h), (-arm - h, h)]  # fmt: skip
    return Map(pts, name="tee")


def _sizes(where: str, arm: float, width: float) -> tuple[float, float]:
    """``arm`` and ``width`` checked: an arm of length 0 would leave a bare square named a
    junction, a negative one a self-crossing outline (refused by :class:`Map` without
    naming the argument)."""
    return (
        validation.positive("arm", arm, where=where),
        validation.positive("width", width, where=where),
    )
