"""Value types returned by the geometry kernel: sweep events, stops, free arcs.

Angles follow THEORY.md section 0: theta is the direction from the evader E to the
pursuer P = E + L (cos theta, sin theta), in radians, counter-clockwise. (One meaning per
letter, project-wide: E the evader, P the pursuer; THEORY.md writes them P and Q.)
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from envs.maps.map import Feature
from envs.tolerances import ANGLE_TOL

__all__ = ["Arc", "FreeArcs", "Stop", "SweepEvent", "wrap_angle"]

TWO_PI = 2.0 * math.pi


def wrap_angle(theta: float) -> float:
    """Return ``theta`` wrapped into ``[-pi, pi)``."""
    w = (float(theta) + math.pi) % TWO_PI - math.pi
    return -math.pi if w >= math.pi else w


@dataclass(frozen=True)
class SweepEvent:
    """The first moment within one step where surveillance breaks.

    Attributes:
        time: fraction of the step in ``[0, 1]``.
        cause: ``"occluded"``, ``"too_far"`` or ``"too_close"``.
        feature: for ``"occluded"`` the wall feature the rod touches first (a convex
            vertex when the rod sweeps onto a corner between frames), else ``None``.
        pursuer: pursuer position at ``time``.
        evader: evader position at ``time``.
    """

    time: float
    cause: str
    feature: Feature | None
    pursuer: np.ndarray = field(compare=False)
    evader: np.ndarray = field(compare=False)


@dataclass(frozen=True)
class Stop:
    """The wall feature met when the rod rotates out of a free arc (THEORY.md 1.3).

    Attributes:
        kind: ``"body"`` (the rod's body touches the feature) or ``"tip"`` (the pursuer
            end P touches it).
        feature: ``("body", convex vertex strictly inside the disk |X - E| < L)``,
            ``("tip", vertex exactly on the circle)`` or ``("tip", edge)``. One more label
            occurs only when E itself lies on a wall (a type-0 point): ``("body", edge)``,
            the rod lying along the wall edge through E.
    """

    kind: str
    feature: Feature

    def __str__(self) -> str:
        return f"{self.kind}-{self.feature}"


@dataclass(frozen=True)
class Arc:
    """A closed arc of free orientations ``[lo, hi]``, counter-clockwise.

    ``lo`` lies in ``[-pi, pi)`` and ``hi >= lo`` (``hi`` may exceed ``pi`` when the arc
    wraps). The full circle is ``Arc(-pi, pi, None, None)``.

    Attributes:
        lo: start angle (radians).
        hi: end angle (radians), ``hi - lo`` is the width.
        stop_lo: what the rod hits when it rotates clockwise past ``lo``.
        stop_hi: what the rod hits when it rotates counter-clockwise past ``hi``.
    """

    lo: float
    hi: float
    stop_lo: Stop | None = None
    stop_hi: Stop | None = None

    @property
    def width(self) -> float:
        """Angular width ``hi - lo`` in radians."""
        return self.hi - self.lo

    @property
    def is_full(self) -> bool:
        """True for the full circle (no stops)."""
        return self.stop_lo is None and self.stop_hi is None and self.width >= TWO_PI - ANGLE_TOL

    @property
    def mid(self) -> float:
        """The middle orientation of the arc, wrapped into ``[-pi, pi)``."""
        return wrap_angle(0.5 * (self.lo + self.hi))

    def contains(self, theta: float, tol: float = ANGLE_TOL) -> bool:
        """Return whether orientation ``theta`` lies in the closed arc (within ``tol``)."""
        if self.is_full:
            return True
        d = (float(theta) - self.lo) % TWO_PI
        return d <= self.width + tol or d >= TWO_PI - tol


@dataclass(frozen=True)
class FreeArcs:
    """The free orientations of a rod of length ``L`` with its evader end at ``point``.

    Attributes:
        point: the evader position E, shape (2,).
        L: rod length.
        arcs: disjoint closed arcs sorted by ``lo``; empty when no orientation is free.
    """

    point: np.ndarray = field(compare=False)
    L: float
    arcs: tuple[Arc, ...]

    @property
    def is_full(self) -> bool:
        """True when every orientation is free (no wall within reach)."""
        return len(self.arcs) == 1 and self.arcs[0].is_full

    @property
    def is_empty(self) -> bool:
        """True when no orientation is free."""
        return not self.arcs

    @property
    def total_width(self) -> float:
        """Sum of the arc widths (radians)."""
        return float(sum(a.width for a in self.arcs))

    def arc_index(self, theta: float, tol: float = ANGLE_TOL) -> int | None:
        """Index of the arc containing ``theta``, or ``None`` if ``theta`` is blocked."""
        for i, a in enumerate(self.arcs):
            if a.contains(theta, tol):
                return i
        return None

    def contains(self, theta: float, tol: float = ANGLE_TOL) -> bool:
        """Return whether orientation ``theta`` is free (closed arcs, within ``tol``)."""
        return self.arc_index(theta, tol) is not None

    def __len__(self) -> int:
        return len(self.arcs)

    def __iter__(self):
        return iter(self.arcs)
