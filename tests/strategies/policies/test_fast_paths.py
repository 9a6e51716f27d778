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


@pytest.fixture(scope="module", params=["corridor", "maze"])
def shooter(request):
    config = build_env(request.param, {}).config
    policy = make_policy("evader/shooting")
    policy.reset(role="evader", map=config.map, config=config, seed=0)
    return policy


def _free_points(policy, n: int, seed: int) -> np.ndarray:
    pts = _points(policy, 4 * n, seed)
    return pts[policy.table.rows(pts) >= 0][:n]


def test_shooting_candidates_are_the_table_rows_along_the_rays(shooter):
    tab, rays, n_r, cols = shooter.table, shooter.rays, shooter._n_r, shooter._cols
    for e in _free_points(shooter, 200, seed=2):
        pts = e + shooter._offsets
        rows = tab.rows(pts).reshape(rays, n_r)
        sub = (np.cumsum(rows < 0, axis=1) == 0)[:, cols]  # up to each ray's first wall
        near = np.linalg.norm(shooter._corner_points - e, axis=1) <= n_r * tab.resolution
        cand, cand_rows, corners, corner_rows = shooter._candidates(e)
        assert cand.tobytes() == pts.reshape(rays, n_r, 2)[:, cols][sub].tobytes()
        assert np.array_equal(cand_rows, rows[:, cols][sub])
        assert corners.tobytes() == shooter._corner_points[near].tobytes()
        assert np.array_equal(corner_rows, tab.rows(corners))


def test_shooting_wall_test_is_the_distance_to_the_walls(shooter):
    # along a walk of small steps, with the radius at the walk's own distances (the
    # bound from the last computed distance must never settle a borderline case)
    world = shooter.config.map
    rng = np.random.default_rng(4)
    start = _free_points(shooter, 1, seed=3)[0]
    walk = start + np.cumsum(rng.normal(0.0, 0.05, (400, 2)), axis=0)
    dist = world.distance_to_walls(walk)
    shooter._wall_last = None
    computed = 0
    for i, e in enumerate(walk):
        r = float(dist[i - 3]) if i % 4 == 0 else 0.3
        before = shooter._wall_last
        assert shooter._near_wall(e, r) == bool(dist[i] <= r), i
        computed += shooter._wall_last is not before
    assert computed < len(walk)  # the bound settled some
