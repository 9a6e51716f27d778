"""The safety table against independent oracles: shapely and brute force.

The escape plan is tested in ``test_escape_plan.py``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from shapely.geometry import LineString

from envs.maps import builtin_map
from strategies.policies.safety import NO_PATH, safety_table

RES = 0.25  # coarse grids keep these tests fast


@pytest.fixture(scope="module")
def corridor():
    return builtin_map("corridor")


def test_free_bins_match_shapely(corridor):
    tab = safety_table(corridor, 2.0, RES, 72, disk_cache=False)
    free = corridor.free_region
    rng = np.random.default_rng(0)
    rows = rng.choice(len(tab.free), size=40, replace=False)
    inv = {int(tab.cell[i, j]): (i, j) for i, j in zip(*np.nonzero(tab.cell >= 0), strict=False)}
    checked = 0
    for r in rows:
        p = tab.origin + RES * np.array(inv[int(r)])
        for b in range(tab.n_bins):
            verdicts = set()
            for d in (-1e-4, 1e-4):  # skip bins whose centre sits on an arc end
                th = float(tab.bin_centre(b)) + d
                q = p + 2.0 * np.array([math.cos(th), math.sin(th)])
                verdicts.add(bool(free.contains(LineString([p, q]))))
            if len(verdicts) == 1:
                assert tab.free[r, b] == verdicts.pop(), (p, b)
                checked += 1
    assert checked > 0.9 * 40 * tab.n_bins


def test_rotation_tables_by_brute_force(corridor):
    tab = safety_table(corridor, 2.0, RES, 72, disk_cache=False)
    rng = np.random.default_rng(1)
    assert not np.any(tab.safe & ~tab.free)
    for r in rng.choice(len(tab.safe), size=30, replace=False):
        safe = tab.safe[r]
        for b in range(tab.n_bins):
            ccw = next((k for k in range(tab.n_bins) if safe[(b + k) % tab.n_bins]), NO_PATH)
            cw = next((k for k in range(tab.n_bins) if safe[(b - k) % tab.n_bins]), NO_PATH)
            assert (tab.ccw[r, b], tab.cw[r, b]) == (ccw, cw)


def test_safe_cells_exist_in_the_corridor_but_not_between_two_rooms(corridor):
    assert safety_table(corridor, 2.0, RES, 72, disk_cache=False).guaranteed.any()
    two = safety_table(builtin_map("two_rooms"), 2.0, RES, 72, disk_cache=False)
    assert not two.guaranteed.any()  # Prop. 2: every cell escapable
    assert np.array_equal(two.safe, two.free)  # falls back to keeping the rod free
