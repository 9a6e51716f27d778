"""The grid oracle against the exact decomposition (strategies.cspace.decompose).

Two independent computations of Sec. 4's escapable cells: critical curves, regions and
stop-keyed cells on one side, a grid of evader positions with arcs followed along each
step on the other. The grid's errors are one-sided (see the module docstring of
``tests.oracles.grid_oracle``): what it calls escapable must be escapable exactly;
it may miss escapes through regions thinner than its spacing.
"""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from shapely.geometry import LineString

from envs.maps import Map
from tests.oracles import grid_oracle as go
from tests.strategies.cspace.test_grid_oracle import (
    corridor_world,
    open_room,
    pocket_room,
    two_rooms_world,
)

cspace = pytest.importorskip("strategies.cspace")
decompose = getattr(cspace, "decompose", None)
if decompose is None:  # the exact decomposition has not landed yet
    pytest.skip("strategies.cspace.decompose is not available", allow_module_level=True)

try:
    from envs.maps import random_map
except ImportError:  # pragma: no cover - the generator ships with envs.maps
    random_map = None


def compare_with_exact(
    m: Map, L: float, resolution: float, *, n_points: int = 40, seed: int = 0, points=()
):
    """Verdicts of both methods, and per-arc escapability at points away from every curve.

    ``points`` and points drawn (seeded) in free space are kept when farther than
    ``resolution`` from every critical curve and wall of the exact decomposition, so that
    the grid points around them lie in the same region.

    Returns:
        ``(grid_wins, exact_wins, rows)`` with rows ``(point, arc, grid_escapable,
        exact_escapable)`` for every free arc at the kept points whose exact cell is known.
    """
    d = decompose(m, L)
    grid_wins = go.grid_verdict(m, L, resolution=resolution).evader_wins
    lines = [LineString(c.points) for c in d.curves if len(c.points) >= 2]
    curves = shapely.union_all(lines) if lines else None
    rng = np.random.default_rng(seed)
    xmin, ymin, xmax, ymax = m.bounds
    rows = []
    drawn = rng.uniform((xmin, ymin), (xmax, ymax), size=(40 * n_points, 2))
    cand = np.concatenate([np.reshape(np.asarray(points, dtype=float), (-1, 2)), drawn])
    cand = cand[m.contains(cand) & (m.distance_to_walls(cand) > resolution)]
    if curves is not None:
        cand = cand[shapely.distance(shapely.points(cand), curves) > resolution]
    for p in cand[: len(points) + n_points]:
        safe = go.grid_safe_arcs(m, L, p, resolution=resolution)
        for ca in d.free_arcs(p):
            if ca.escapable is None:
                continue
            grid_esc = not any(
                abs(s.lo - ca.arc.lo) < 1e-12 and abs(s.hi - ca.arc.hi) < 1e-12 for s in safe
            )
            rows.append((tuple(p), ca.arc, grid_esc, ca.escapable))
    return grid_wins, d.evader_wins, rows


PAPER = [
    (corridor_world, 2.0),
    (two_rooms_world, 2.0),
    (open_room, 2.0),
    (pocket_room, 2.0),
    (corridor_world, 1.0),
    (two_rooms_world, 1.0),
]


@pytest.mark.parametrize(("world", "L"), PAPER, ids=[f"{w.__name__}-L{L:g}" for w, L in PAPER])
def test_paper_worlds_agree_with_exact(world, L):
    """No slivers on these worlds: verdicts and arc-by-arc escapability agree."""
    corridor = [(x, y) for x in np.arange(-5.6, 0.0, 0.4) for y in (-0.15, 0.0, 0.15)]
    grid_wins, exact_wins, rows = compare_with_exact(world(), L, 0.25, points=corridor)
    assert grid_wins == exact_wins
    assert len(rows) >= 20
    bad = [r for r in rows if r[2] != r[3]]
    assert not bad, f"{len(bad)} of {len(rows)} arcs disagree, e.g. {bad[:3]}"
    if world is not two_rooms_world or L != 2.0:
        assert not all(r[3] for r in rows)  # some safe arcs were compared too


def _random_worlds():
    if random_map is None:
        pytest.skip("envs.maps.random_map is not available")
    return [random_map(seed, n_obstacles=3, size=10.0, min_gap=1.0) for seed in range(5)]


@pytest.mark.slow
def test_random_maps_grid_escapes_are_exact_escapes():
    """Soundness: a grid-escapable arc is exactly escapable; grid wins imply exact wins."""
    outcomes = []
    for m in _random_worlds():
        for L in (1.5, 2.5):
            grid_wins, exact_wins, rows = compare_with_exact(m, L, 0.4, n_points=10)
            assert exact_wins or not grid_wins, f"{m.name} L={L}: only the grid says evader wins"
            bad = [r for r in rows if r[2] and not r[3]]
            assert not bad, f"{m.name} L={L}: grid-escapable but exactly safe: {bad[:3]}"
            outcomes.append((grid_wins, exact_wins))
    # not vacuous: the grid reaches both verdicts, and the exact one on most maps
    agree = [g for g, e in outcomes if g == e]
    assert set(agree) == {True, False}
    assert len(agree) >= len(outcomes) // 2
