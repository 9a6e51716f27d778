"""grid_points: the free grid nodes, built a chunk at a time."""

from __future__ import annotations

import math
import tracemalloc

import numpy as np
import shapely

import strategies.cspace.grids as grids
from envs.maps import Map, load_map
from envs.tolerances import REL_LENGTH_TOL


def test_grid_points_are_the_free_nodes_in_x_major_order(monkeypatch):
    monkeypatch.setattr(grids, "_CHUNK", 1000)  # many chunks, a partial last one
    m = load_map("pillars")
    origin, cell, pts = grids.grid_points(m, 0.1)
    xs = grids.grid_axis(m.bounds[0], m.bounds[2], 0.1)
    ys = grids.grid_axis(m.bounds[1], m.bounds[3], 0.1)
    X, Y = np.meshgrid(xs, ys, indexing="ij")  # node (i, j) is X[i, j], Y[i, j]
    nodes = shapely.points(X.ravel(), Y.ravel())
    inside = shapely.contains(m.free_region, nodes)
    inside &= shapely.distance(m.free_region.boundary, nodes) > REL_LENGTH_TOL * m.scale
    assert np.array_equal(cell.ravel() >= 0, inside)
    assert np.array_equal(pts, np.stack([X.ravel()[inside], Y.ravel()[inside]], axis=1))
    assert np.array_equal(cell.ravel()[inside], np.arange(len(pts)))
    assert np.array_equal(origin, [xs[0], ys[0]])


def test_grid_points_hold_no_array_over_the_whole_grid_beyond_their_results(monkeypatch):
    # two int64 index arrays over every node (16 bytes a node) and idx-sized temporaries:
    # the shooting evader's table on corner~x100 at L_min 2 (196 million nodes) reached
    # 7 GB here; at 2.8 million nodes the peak was 126 MB against 54 MB of results
    monkeypatch.setattr(grids, "_CHUNK", 1 << 16)
    m = load_map("corner~x3")
    tracemalloc.start()
    try:
        _, cell, pts = grids.grid_points(m, 0.025)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    results = cell.nbytes + pts.nbytes + cell.size + 8 * len(pts)  # + keep and idx
    assert peak < 1.25 * results, (peak / 1e6, results / 1e6)


def _peak(world, resolution):
    tracemalloc.start()
    try:
        grids.grid_points(world, resolution)
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def test_grid_bytes_bounds_the_measured_peak_of_grid_points(monkeypatch):
    """safety.table_bytes counted 4 bytes a node of the grid and nothing of its build
    (the memory budget's check of the shooting evader's table on corner~x100 at L_min 2:
    0.8 GB estimated, 4-7 GB taken). grid_bytes counts the build's arrays and one chunk's
    temporaries: measured peaks (tracemalloc) lie within it and above 3/4 of it, where
    the chunk's temporaries dominate (a grid smaller than a chunk) and where the whole
    grid's arrays do."""
    m = load_map("corner~x3")
    grids.grid_points(m, 1.0)  # the map's prepared geometry made before measuring
    ratios = []
    for chunk, h in ((1 << 20, 0.05), (1 << 16, 0.025), (1 << 14, 0.05)):
        monkeypatch.setattr(grids, "_CHUNK", chunk)
        ratios.append(_peak(m, h) / grids.grid_bytes(m, h))
    assert all(0.75 < r <= 1.0 for r in ratios), ratios


def test_only_nodes_near_a_wall_are_tested_against_the_walls(monkeypatch):
    """Free nodes within the length tolerance of a wall are left out (the oracle: shapely
    on every node), on an axis-parallel and a diagonal wall a fraction of the tolerance
    off grid nodes; and only nodes near a wall are made shapely points for that test
    (every free node was: 4.8 of the shooting evader's 21 s reset on a 200 m floor plan
    at L_min 3)."""
    d = 0.4 * REL_LENGTH_TOL * math.hypot(4.0, 4.0)  # the map's scale: its diagonal
    square = [(0.75 + d, 0.75), (2.25, 0.75), (2.25, 2.25), (0.75 + d, 2.25)]
    diagonal = [(2.75 + d, 2.75), (3.75, 2.75), (3.75, 3.75 - d)]  # through (3.25, 3.25)
    m = Map([(0, 0), (4, 0), (4, 4), (0, 4)], [square, diagonal])
    assert m.scale == math.hypot(4.0, 4.0)
    tested = []
    dwithin = shapely.dwithin

    def counted(a, b, distance):
        tested.append(len(b))
        return dwithin(a, b, distance)

    monkeypatch.setattr(shapely, "dwithin", counted)
    _origin, cell, _pts = grids.grid_points(m, 0.5)
    monkeypatch.undo()
    xs = grids.grid_axis(0.0, 4.0, 0.5)
    X, Y = np.meshgrid(xs, xs, indexing="ij")
    nodes = shapely.points(X.ravel(), Y.ravel())
    inside = shapely.contains(m.free_region, nodes)
    near = shapely.distance(m.free_region.boundary, nodes) <= REL_LENGTH_TOL * m.scale
    assert (inside & near).sum() >= 4 + 2  # on the square's left side, the diagonal
    assert np.array_equal(cell.ravel() >= 0, inside & ~near)
    assert not (cell[2, 2] >= 0 or cell[6, 6] >= 0)  # (1.25, 1.25) in the square, (3.25, 3.25)
    assert 0 < sum(tested) < 0.6 * inside.sum(), (sum(tested), inside.sum())
