"""The vectorised classification and the distinct-row table answer as the eager table."""

from __future__ import annotations

import math

import numpy as np
import pytest

from envs.maps import builtin_map
from strategies.cspace import decompose
from strategies.policies import make_policy
from strategies.policies._batch_classify import classify_points
from strategies.policies.safety import _arc_bins, _classified, safety_table
from strategies.runner import run_episode

FIELDS = ("free", "safe", "guaranteed", "ccw", "cw", "need")


def _world(name: str, angle: float):
    c, s = math.cos(angle), math.sin(angle)
    return builtin_map(name).transformed(np.array([[c, -s], [s, c]]), (3.0, -1.0))


@pytest.mark.parametrize(("name", "angle"), [("corridor", 0.0), ("pillars", 0.61)])
def test_batch_classification_is_the_point_by_points(name, angle):
    # random points, and points on critical curves (their arcs cannot be matched to
    # cells where they lie: both ways nudge them off the curve)
    world = _world(name, angle)
    dec = decompose(world, 2.2)
    nb = 72
    centres = -math.pi + (np.arange(nb) + 0.5) * (2.0 * math.pi / nb)
    x0, y0, x1, y1 = world.bounds
    rng = np.random.default_rng(3)
    pts = rng.uniform((x0, y0), (x1, y1), size=(600, 2))
    pts = pts[world.contains(pts)]
    on_curves = np.array([b.point for b in dec.boundaries[:200]])
    pts = np.vstack([pts, on_curves])
    free, safe = classify_points(dec, pts, 0.25, centres)
    nudged = 0
    for i, p in enumerate(pts):
        arcs, safe_arcs = _classified(dec, p, 0.25)
        nudged += any(ca.escapable is None for ca in dec.free_arcs(p))
        assert np.array_equal(free[i], _arc_bins(arcs, centres)), i
        want = free[i] & _arc_bins(safe_arcs, centres) if safe_arcs is not None else 0 * free[i]
        assert np.array_equal(safe[i], want), i
    assert free.any() and safe.any()
    assert nudged > 0 or name != "corridor"  # the corridor's curves hold unmatched points


@pytest.mark.parametrize("name", ["floor_plan", "office", "random"])
def test_a_lazy_tables_small_batches_are_the_point_by_points(name):
    """A lazy table classifies a few dozen points a batch (free_arcs_few, the cells
    matched per region, each point's arcs or-ed together): the same bins as the eager
    build's point by point classification, at random points, near walls and corners,
    and on critical curves, in batches of 1 to 60 points."""
    from envs.maps import floor_plan, random_map

    world = {
        "floor_plan": lambda: floor_plan(0, n_vertices=200, size=(40.0, 40.0)),
        "office": lambda: builtin_map("office"),
        "random": lambda: random_map(6, n_vertices=20),
    }[name]()
    dec = decompose(world, 2.2)
    nb = 144
    centres = -math.pi + (np.arange(nb) + 0.5) * (2.0 * math.pi / nb)
    x0, y0, x1, y1 = world.bounds
    rng = np.random.default_rng(7)
    near = world.vertices + rng.normal(0.0, 0.05, world.vertices.shape)
    pts = np.vstack(
        [
            rng.uniform((x0, y0), (x1, y1), size=(500, 2)),
            near,
            [b.point for b in dec.boundaries[:100]],
        ]
    )
    pts = pts[world.contains(pts)]
    pts = pts[rng.permutation(len(pts))]
    s = 0
    while s < len(pts):
        k = int(rng.integers(1, 61))
        free, safe = classify_points(dec, pts[s : s + k], 0.1, centres)
        for i, p in enumerate(pts[s : s + k]):
            arcs, safe_arcs = _classified(dec, p, 0.1)
            assert np.array_equal(free[i], _arc_bins(arcs, centres)), (s, i)
            want = free[i] & _arc_bins(safe_arcs, centres) if safe_arcs is not None else 0
            assert np.array_equal(safe[i], want & free[i]), (s, i)
        s += k


@pytest.mark.parametrize(("name", "angle"), [("corridor", 0.3), ("l_hall", 0.61)])
def test_distinct_rows_answer_as_the_eager_table_at_every_node(name, angle):
    world = _world(name, angle)
    eager = safety_table(world, 2.2, 0.25, 48, disk_cache=False)
    distinct = safety_table(world, 2.2, 0.25, 48, disk_cache=False, distinct=True)
    assert np.array_equal(eager.origin, distinct.origin) and eager.shape == distinct.shape
    assert np.array_equal(eager.cell >= 0, distinct.cell >= 0)
    re, rd = eager.cell[eager.cell >= 0], distinct.cell[distinct.cell >= 0]
    for f in FIELDS:
        assert np.array_equal(getattr(eager, f)[re], getattr(distinct, f)[rd]), f
    assert len(distinct.free) < len(eager.free) / 2  # rows are shared
    assert len(np.unique(rd)) == len(distinct.free)  # every row is some node's


def test_distinct_table_is_cached_apart_from_the_eager_one(tmp_path, monkeypatch):
    monkeypatch.setenv("SURVEIL_CACHE_DIR", str(tmp_path))
    world = _world("corridor", 0.2)
    a = safety_table.__wrapped__(world, 2.2, 0.5, 24, distinct=True)
    b = safety_table.__wrapped__(world, 2.2, 0.5, 24)
    c = safety_table.__wrapped__(world, 2.2, 0.5, 24, distinct=True)  # read back
    assert len(list(tmp_path.glob("safety_*.npz"))) == 2
    assert len(a.free) < len(b.free) and np.array_equal(a.cell, c.cell)
    assert np.array_equal(a.ccw, c.ccw)


def test_the_pursuer_plays_the_same_episode_with_distinct_rows():
    world = _world("corridor", 0.3)
    runs = []
    for table in ("eager", "distinct"):
        p = make_policy("pursuer/decomposition", table=table, resolution=0.2)
        runs.append(run_episode(world, p, "evader/shooting", 4, max_cycles=150, start="safe"))
        assert (len(p.table.free) < (p.table.cell >= 0).sum()) == (table == "distinct")
    assert np.array_equal(runs[0].trajectory, runs[1].trajectory)
    assert runs[0].winner == runs[1].winner


def test_auto_stores_distinct_rows_between_the_thresholds(monkeypatch):
    from strategies.policies.decomposition import DecompositionPursuer
    from strategies.policies.lazy_table import LazySafetyTable

    world = _world("corridor", 0.3)
    kinds = []
    for eager, distinct in ((10**9, 10**9), (100, 10**9), (100, 200)):
        monkeypatch.setattr(DecompositionPursuer, "EAGER_TABLE_POINTS", eager)
        monkeypatch.setattr(DecompositionPursuer, "DISTINCT_TABLE_POINTS", distinct)
        p = make_policy("pursuer/decomposition")
        run_episode(world, p, "evader/straight", 0, max_cycles=2, start="valid")
        t = p.table
        if isinstance(t, LazySafetyTable):
            kinds.append("lazy")
        else:
            kinds.append("distinct" if len(t.free) < (t.cell >= 0).sum() else "eager")
    assert kinds == ["eager", "distinct", "lazy"]


def test_the_distinct_build_holds_no_more_than_its_grids_estimate(monkeypatch):
    """The distinct build pointed the grid's nodes at their rows through whole-grid
    temporaries (13 bytes a node: 2.5 GB of corner~x100's 196 million nodes at L_min 2);
    now a chunk at a time, so that the build's grid arrays stay within
    ``grid_bytes`` (tracemalloc, the classification replaced by one row for every point,
    chunks small against the grid: before, the peak was 1.17 x the estimate)."""
    import tracemalloc

    import strategies.cspace.grids as grids
    import strategies.policies._batch_classify as batch
    import strategies.policies.safety as safety
    from envs.maps import load_map

    def one_row(dec, pts, step, centres, progress=None):
        row = np.zeros((1, len(centres)), dtype=bool)
        return np.zeros(len(pts), dtype=np.int32), row, row, np.zeros(1, dtype=bool)

    monkeypatch.setattr(batch, "distinct_rows", one_row)
    monkeypatch.setattr(grids, "_CHUNK", 1 << 16)
    monkeypatch.setattr(safety, "_REMAP_NODES", 1 << 16, raising=False)
    m = load_map("corner~x3")
    decompose(m, 2.1)
    grids.grid_points(m, 1.0)  # the map's prepared geometry made before measuring
    tracemalloc.start()
    try:
        table = safety._build_distinct(m, 2.1, 0.025, 16, False)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert table.cell.size > 40 * (1 << 16)  # the grid's arrays dominate the chunks'
    assert peak <= grids.grid_bytes(m, 0.025), peak / grids.grid_bytes(m, 0.025)
