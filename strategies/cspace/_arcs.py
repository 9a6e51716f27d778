"""Small helpers on the kernel's free arcs: stop pairs (cell keys) and overlaps."""

from __future__ import annotations

import math

from envs.geometry.types import Arc, FreeArcs, Stop

__all__ = ["OVERLAP_TOL", "StopPair", "overlap", "pairs"]

OVERLAP_TOL = 1e-9
"""Arcs overlapping by at most this many radians only touch: not adjacent (footnote 3)."""

StopPair = tuple[Stop | None, Stop | None]
"""A cell's key within its region: the stops ``(s-, s+)`` of its free arc."""

_TWO_PI = 2.0 * math.pi


def pairs(fa: FreeArcs) -> tuple[StopPair, ...]:
    """The stop pairs of the free arcs at a point, in the order of the arcs."""
    return tuple((a.stop_lo, a.stop_hi) for a in fa.arcs)


def overlap(a: Arc, b: Arc) -> float:
    """Length (radians) of the overlap of two closed arcs; negative when disjoint."""
    if a.is_full:
        return b.width
    if b.is_full:
        return a.width
    best = -math.inf
    for shift in (-_TWO_PI, 0.0, _TWO_PI):
        best = max(best, min(a.hi, b.hi + shift) - max(a.lo, b.lo + shift))
    return best
