"""The safety table against its source, the exact decomposition, and the grid oracle.

* Agreement: at random grid points the table's safe bins are the bin centres inside
  ``decompose(map, L).safe_arcs`` (checked with ``Arc.contains``, away from every stop by
  a bin width so a centre sitting on an arc end is not judged).
* Soundness against the grid oracle (an independent computation, one-sided: whatever it
  calls escapable really is): no bin of a grid-escapable arc is safe in the table, except
  at points within a grid step of a critical curve, where the grid and the exact cells
  may legitimately see different sides of the curve.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from shapely.geometry import LineString

from envs.geometry import kernel_for
from envs.maps import builtin_map
from strategies.cspace import decompose
from strategies.policies.safety import SOURCE, TABLE_VERSION, safety_table
from tests.oracles.grid_oracle import grid_graph

RES = 0.25
L = 2.0
N_BINS = 72


def _grid_point(tab, row: int) -> np.ndarray:
    i, j = np.argwhere(tab.cell == row)[0]
    return tab.origin + tab.resolution * np.array([i, j], dtype=float)


@pytest.mark.parametrize("name", ["corridor", "maze"])
def test_safe_bins_are_the_decompositions_safe_arcs(name):
    world = builtin_map(name)
    tab = safety_table(world, L, RES, N_BINS, disk_cache=False)
    dec = decompose(world, L, cache=True)
    kernel = kernel_for(world)
    rng = np.random.default_rng(7)
    counts = {True: 0, False: 0}
    for row in rng.choice(len(tab.safe), size=150, replace=False):
        p = _grid_point(tab, int(row))
        free = kernel.free_arcs(p, L).arcs
        safe = dec.safe_arcs(p)
        stops = np.array([s for a in free if not a.is_full for s in (a.lo, a.hi)])
        for b in range(tab.n_bins):
            th = float(tab.bin_centre(b))
            if (
                len(stops)
                and np.min(np.abs(np.remainder(th - stops + np.pi, 2 * np.pi) - np.pi))
                < tab.bin_width
            ):
                continue
            assert tab.free[row, b] == any(a.contains(th) for a in free), (p, th)
            if not tab.guaranteed[row]:
                assert not safe  # Prop. 2 fallback only where nothing is safe
                assert tab.safe[row, b] == tab.free[row, b]
                continue
            expect = any(a.contains(th) for a in safe)
            assert tab.safe[row, b] == expect, (p, th)
            if tab.free[row, b]:
                counts[expect] += 1
    assert counts[True] > 100 and counts[False] > 20, counts  # both kinds were checked


def test_no_grid_escape_is_safe_in_the_table():
    world = builtin_map("maze")
    tab = safety_table(world, L, RES, N_BINS, disk_cache=False)
    g = grid_graph(world, L, resolution=RES)
    dec = decompose(world, L, cache=True)
    curves = shapely.STRtree([LineString(c.points) for c in dec.curves if len(c.points) > 1])
    esc = np.flatnonzero(g.escapable)
    assert len(esc) > 50  # the maze has escapable cells the grid sees
    centres = tab.bin_centre(np.arange(tab.n_bins))
    checked = exempt = 0
    for node in esc:
        p = g.points[g.node_point[node]]
        row = int(tab.rows(p[None])[0])
        assert row == g.node_point[node]  # the same grid
        lo, hi = g.node_lo[node], g.node_hi[node]
        d = (centres - lo) % (2 * math.pi)
        inner = (d >= tab.bin_width) & (d <= hi - lo - tab.bin_width)
        if not inner.any() or not tab.guaranteed[row]:
            continue
        bad = tab.safe[row] & inner
        if bad.any():
            near = curves.query(shapely.Point(p), predicate="dwithin", distance=RES)
            assert len(near), (p, lo, hi, np.flatnonzero(bad))
            exempt += 1
        else:
            checked += 1
    assert checked > 50 and exempt <= 0.1 * checked, (checked, exempt)


def test_evader_wins_worlds_fall_back_to_free_bins():
    world = builtin_map("office")
    assert decompose(world, L, cache=True).evader_wins
    tab = safety_table(world, L, 0.5, N_BINS, disk_cache=False)
    assert not tab.guaranteed.any()
    assert np.array_equal(tab.safe, tab.free) and tab.free.any()


def test_disk_cache_roundtrip_and_key(tmp_path, monkeypatch):
    monkeypatch.setenv("SURVEIL_CACHE_DIR", str(tmp_path))
    world = builtin_map("corner")
    a = safety_table.__wrapped__(world, L, 0.5, 36)
    files = list(tmp_path.glob("safety_*.npz"))
    assert len(files) == 1 and SOURCE == "decomposition" and TABLE_VERSION >= 2
    b = safety_table.__wrapped__(world, L, 0.5, 36)
    for k in ("cell", "free", "safe", "guaranteed", "ccw", "cw", "origin"):
        assert np.array_equal(getattr(a, k), getattr(b, k)), k
    assert a.shape == b.shape
