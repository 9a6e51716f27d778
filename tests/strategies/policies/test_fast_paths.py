"""The per-step fast paths of the analytic policies answer as the general code does."""

from __future__ import annotations

import numpy as np
import pytest

from strategies.policies import make_policy
from strategies.policies.safety import SafetyTable
from strategies.runner import build_env


@pytest.fixture(scope="module", params=["corridor", "l_hall"])
def pursuer(request):
    config = build_env(request.param, {}).config
    policy = make_policy("pursuer/decomposition")
    policy.reset(role="pursuer", map=config.map, config=config, seed=0)
    return policy


def _points(policy, n: int, seed: int = 0) -> np.ndarray:
    xmin, ymin, xmax, ymax = policy.config.map.bounds
    rng = np.random.default_rng(seed)
    return rng.uniform([xmin - 1.0, ymin - 1.0], [xmax + 1.0, ymax + 1.0], (n, 2))


def test_table_rows_match_the_grid_index(pursuer):
    tab = pursuer.table
    pts = _points(pursuer, 4000)
    idx, ok = tab.grid_index(pts)
    want = np.full(len(pts), -1, dtype=np.int64)
    want[ok] = tab.cell[idx[ok, 0], idx[ok, 1]]
    assert np.array_equal(tab.rows(pts), want)
    assert all(tab.row(p) == SafetyTable._row_search(tab, p) for p in pts[:500])


def test_eager_probe_values_match_the_general_path(pursuer):
    assert pursuer._fast
    for p in _points(pursuer, 300, seed=1):
        fast = pursuer.orientation_values(p)
        pursuer._fast = False
        try:
            slow = pursuer.orientation_values(p)
        finally:
            pursuer._fast = True
        assert np.array_equal(fast, slow)
