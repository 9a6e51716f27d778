"""Independent oracles and small worlds for the configuration-space tests.

The brute-force free-orientation sampler uses shapely only (a rod is free when the free
region covers it), so it shares no code with the geometry kernel or the curve clip.
"""

from __future__ import annotations

import math
import warnings
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


# ---------------------------------------------------------------------- slanted worlds
def _regular(n: int, r: float, c=(0.0, 0.0), phase: float = 0.0) -> np.ndarray:
    a = phase + 2 * math.pi * np.arange(n) / n
    return np.c_[c[0] + r * np.cos(a), c[1] + r * np.sin(a)]


def _star(n: int, r_out: float, r_in: float, c, phase: float = 0.0) -> np.ndarray:
    a = phase + math.pi * np.arange(2 * n) / n
    r = np.where(np.arange(2 * n) % 2 == 0, r_out, r_in)
    return np.c_[c[0] + r * np.cos(a), c[1] + r * np.sin(a)]


def _rotated(points, angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.asarray(points, dtype=float) @ np.array([[c, s], [-s, c]])


TILTED_BLOCK = [(6.924, 4.301), (4.916, 3.676), (5.431, 2.022), (7.438, 2.647)]
"""Issue 10: the block whose verdict along L used to be non-monotone (wrong in 2.84-3.04)."""


def tilted_block() -> Map:
    """A 12 x 8 room with one tilted block (issue 10)."""
    return Map([(0, 0), (12, 0), (12, 8), (0, 8)], [TILTED_BLOCK], name="tilted_block")


def slanted_corridor(angle: float = 0.4) -> Map:
    """Fig. 3's corridor world turned by ``angle``: every wall slanted."""
    return Map(_rotated(CORRIDOR, angle), name="slanted_corridor")


def skew_corridor() -> Map:
    """A dead-end corridor whose walls are neither parallel nor axis-aligned."""
    return Map(
        [(0, -5), (10, -5), (10, 5), (0, 5), (0, 0.6), (-6, 1.8), (-6.2, 0.9), (0, -0.6)],
        name="skew_corridor",
    )


def triangles() -> Map:
    return Map(
        [(0, 0), (12, 0), (12, 9), (0, 9)],
        [_regular(3, 1.5, (3, 3), 0.3), _regular(3, 1.2, (8, 5), 1.1), _regular(3, 1.0, (5, 7), 2)],
        name="triangles",
    )


def hexagons() -> Map:
    """A hexagonal room with two hexagonal pillars."""
    return Map(
        _regular(6, 9, (0, 0), 0.1),
        [_regular(6, 1.5, (-2.5, 1), 0.2), _regular(6, 1.3, (2.8, -1.5), 0.5)],
        name="hexagons",
    )


def stars() -> Map:
    """Two star-shaped (non-convex) obstacles."""
    return Map(
        [(0, 0), (14, 0), (14, 10), (0, 10)],
        [_star(5, 1.8, 0.8, (4, 4), 0.2), _star(4, 1.5, 0.6, (10, 6), 0.7)],
        name="stars",
    )


def rotated_room() -> Map:
    """A room with two blocks, all turned by an odd angle."""
    return Map(
        _rotated([(0, 0), (10, 0), (10, 7), (0, 7)], 0.37),
        [
            _rotated([(3, 2), (5, 2), (5, 4), (3, 4)], 0.37),
            _rotated([(6.5, 3), (8, 3), (8, 5.5), (6.5, 5.5)], 0.37),
        ],
        name="rotated_room",
    )


def assert_exact(dec, seed: int, per_region: int, slivers: bool = True) -> None:
    """Assert ``dec`` is exact (no dangling edge, nothing unresolved; with ``slivers`` no
    unresolved sliver either) and that the kernel's stops are constant over each region
    at ``per_region`` random points (:func:`stops_constant`, generator seeded ``seed``),
    with more than two points a region checked on average."""
    assert dec.exact and dec.stats["dangling"] == 0 and dec.unresolved == 0, dec.stats
    if slivers:
        assert dec.stats["slivers_unresolved"] == 0, dec.stats
    n, bad = stops_constant(dec, np.random.default_rng(seed), per_region=per_region)
    assert not bad, bad[:5]
    assert n > 2 * len(dec.regions)


def assert_cells_are_brute_force_arcs(dec, single_samples: bool = True) -> None:
    """Assert that at each region's sample point ``dec`` has as many cells as the shapely
    brute force (:func:`brute_free`, 2048 directions) has free arcs, one full arc where
    every direction is free. Regions whose arcs are narrower than the brute force
    resolves are skipped; more than 60 % of the regions must be checked.

    ``single_samples=False``: a free direction between two blocked ones does not count (a
    rod through the point where two walls meet is free in that one direction only, a
    zero-width arc, which the kernel drops).
    """
    checked = 0
    for r in dec.regions:
        arcs = [dec.cells[c].arc for c in r.cells]
        if not resolvable(arcs, 4 * 2 * math.pi / 2048):
            continue  # narrower than the brute force resolves
        mask = brute_free(dec.map, r.point, dec.L, n=2048)
        if not single_samples:
            mask &= np.roll(mask, 1) | np.roll(mask, -1)
        if len(arcs) == 1 and arcs[0].is_full:
            assert mask.all(), r.id
        else:
            assert circular_runs(mask) == len(arcs) or (not arcs and not mask.any()), r.id
        checked += 1
    assert checked > 0.6 * len(dec.regions)


def stops_constant(dec, rng, per_region: int = 6, inset: float | None = None) -> tuple[int, list]:
    """Check that the kernel's stop pairs are the region's at random points of each region.

    Points are drawn at least ``inset`` (default three polyline tolerances) inside each
    region's polygon. Returns the number of points checked and the failures.
    """
    from envs.geometry import kernel_for

    kernel = kernel_for(dec.map)
    inset = 3 * dec.chord_tol if inset is None else inset
    n, bad = 0, []
    for r in dec.regions:
        want = frozenset(dec.cells[c].stops for c in r.cells)
        inner = r.polygon.buffer(-inset)
        if inner.is_empty:
            continue
        xmin, ymin, xmax, ymax = inner.bounds
        pts = rng.uniform([xmin, ymin], [xmax, ymax], size=(40 * per_region, 2))
        pts = pts[shapely.contains_xy(inner, pts[:, 0], pts[:, 1])][:per_region]
        for p in pts:
            n += 1
            if stop_pairs(kernel.free_arcs(p, dec.L)) != want:
                bad.append((r.id, tuple(p)))
    return n, bad


def fingerprint(dec) -> tuple:
    """What must not change under a similarity: region, cell and escapable counts, verdict."""
    return (len(dec.regions), len(dec.cells), len(dec.escapable), dec.evader_wins)


def exact_decomposition(world: Map, L: float):
    """``decompose(world, L)`` with every warning an error, asserted exact (no dangling or
    unresolved piece)."""
    from strategies.cspace import decompose

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        dec = decompose(world, L)
    assert dec.exact, dec.stats
    assert dec.stats["dangling"] == 0 and dec.unresolved == 0, dec.stats
    return dec


def similar(world: Map, angle: float, scale: float, offset) -> Map:
    """``world`` rotated by ``angle``, scaled by ``scale`` and moved by ``offset``."""
    c, s = scale * math.cos(angle), scale * math.sin(angle)
    return world.transformed([[c, -s], [s, c]], offset)
