"""Independent oracles and small worlds for the configuration-space tests.

The brute-force free-orientation sampler uses shapely only (a rod is free when the free
region covers it), so it shares no code with the geometry kernel or the curve clip.
"""

from __future__ import annotations

import math
from collections import Counter

import numpy as np
import shapely

from envs.geometry.types import FreeArcs
from envs.maps import Map

CORRIDOR = [(0, -5), (10, -5), (10, 5), (0, 5), (0, 0.5), (-6, 0.5), (-6, -0.5), (0, -0.5)]
"""Fig. 3 (THEORY.md 3): room [0, 10] x [-5, 5], dead-end corridor [-6, 0] x [-0.5, 0.5]."""

TWO_ROOMS = [
    (-16, -5), (-6, -5), (-6, -0.5), (0, -0.5), (0, -5), (10, -5),
    (10, 5), (0, 5), (0, 0.5), (-6, 0.5), (-6, 5), (-16, 5),
]  # fmt: skip
"""Fig. 6: the corridor joining a second room [-16, -6] x [-5, 5]."""


def corridor() -> Map:
    return Map(CORRIDOR, name="corridor")


def two_rooms() -> Map:
    return Map(TWO_ROOMS, name="two_rooms")


def open_room(size: float = 10.0) -> Map:
    return Map([(0, 0), (size, 0), (size, size), (0, size)], name="open_room")


def pillar_room() -> Map:
    """A 10 x 10 room with a square pillar and a triangle (several curve types)."""
    return Map(
        [(0, 0), (10, 0), (10, 10), (0, 10)],
        [[(3, 3), (5, 3), (5, 5), (3, 5)], [(6.5, 6), (8.5, 6.4), (7, 8)]],
        name="pillars",
    )


def brute_free(world: Map, P: np.ndarray, L: float, n: int = 2048) -> np.ndarray:
    """Free mask over ``theta_k = 2 pi k / n``: the free region covers the rod (shapely)."""
    th = 2 * math.pi * np.arange(n) / n
    Q = np.asarray(P, dtype=float) + L * np.stack([np.cos(th), np.sin(th)], axis=1)
    coords = np.stack([np.broadcast_to(P, Q.shape), Q], axis=1)
    rods = shapely.linestrings(coords)
    return shapely.covers(world.prepared_free_region, rods)


def circular_runs(mask: np.ndarray) -> int:
    """Number of maximal runs of True on a circular array (1 for all True)."""
    if mask.all():
        return 1
    return int(np.count_nonzero(mask & ~np.roll(mask, 1)))


def stops(fa: FreeArcs) -> Counter:
    """Multiset of the stops at a point (each arc's lo and hi stop)."""
    c: Counter = Counter()
    for a in fa.arcs:
        if a.stop_lo is not None:
            c[a.stop_lo] += 1
        if a.stop_hi is not None:
            c[a.stop_hi] += 1
    return c


def stop_pairs(fa: FreeArcs) -> frozenset:
    """The set of stop pairs at a point."""
    return frozenset((a.stop_lo, a.stop_hi) for a in fa.arcs)


def resolvable(arcs, step: float) -> bool:
    """Whether every free arc and every blocked gap between them is wider than ``step``."""
    arcs = list(arcs)
    if not arcs or (len(arcs) == 1 and arcs[0].is_full):
        return True
    gaps = [(arcs[(k + 1) % len(arcs)].lo - a.hi) % (2 * math.pi) for k, a in enumerate(arcs)]
    return min(a.width for a in arcs) > step and min(gaps) > step
