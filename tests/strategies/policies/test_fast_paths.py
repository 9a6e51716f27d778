"""The per-step fast paths of the analytic policies answer as the general code does."""

from __future__ import annotations

import numpy as np
import pytest

from strategies.policies import make_policy
from strategies.policies.safety import NO_PATH, SafetyTable
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


def _margins_direct(policy, e, theta, cand):
    """ShootingEvader._margins as first written: every candidate through eq. (6)."""
    c, tab = policy.config, policy.table
    rows = tab.rows(cand)
    ok = rows >= 0
    b = tab.bin_of(theta)
    need = []
    for t in (tab.ccw, tab.cw):
        n = np.where(ok, t[np.maximum(rows, 0), b], 0).astype(float)
        need.append(np.where(n >= NO_PATH, 2 * np.pi, n * tab.bin_width))
    margin, branch = np.full(len(cand), -np.inf), np.full(len(cand), "-")
    rho, k = min(policy.rho, 1.0), c.v_pursuer / c.l_min
    d = cand - e
    dist = np.linalg.norm(d, axis=1)
    least = k * (1.0 - rho) * dist / c.v_evader
    live = np.flatnonzero(
        ok & ((need[0] > 0) | (need[1] > 0)) & (np.minimum(*need) - least + 1e-9 > 0)
    )
    if not len(live):
        return margin, branch
    alpha = np.arctan2(d[live, 1], d[live, 0])
    dt = dist[live] / c.v_evader / 8
    for i, sign in ((0, 1.0), (1, -1.0)):
        th = np.full(len(live), theta)
        for _ in range(8):
            phi = alpha - th
            th = (
                th
                + k
                * (-rho * np.sin(phi) + sign * np.sqrt(np.maximum(1 - (rho * np.cos(phi)) ** 2, 0)))
                * dt
            )
        need[i] = need[i][live] - np.abs(th - theta)
    margin[live] = np.minimum(need[0], need[1])
    branch[live] = np.where(need[0] < need[1], "+", "-")
    return margin, branch


@pytest.mark.parametrize("rho", [0.5, 0.9, 1.0])
def test_shooting_margins_are_the_direct_computation(shooter, rho):
    # bit for bit, off the grid and on NO_PATH entries too, and at rho = 1 (where the
    # root's argument reaches 0)
    rng = np.random.default_rng(5)
    saved = shooter.rho
    shooter.rho = rho
    try:
        finite = 0
        for e in _free_points(shooter, 60, seed=6):
            theta = float(rng.uniform(-np.pi, np.pi))
            cand = e + rng.uniform(-4.0, 4.0, (int(rng.integers(1, 200)), 2))
            margin, branch = shooter._margins(e, theta, cand)
            want_margin, want_branch = _margins_direct(shooter, e, theta, cand)
            assert margin.tobytes() == want_margin.tobytes()
            assert np.array_equal(branch, want_branch)
            finite += int(np.isfinite(margin).sum())
        assert finite > 100
    finally:
        shooter.rho = saved
    # every table entry, NO_PATH too (the maps above have none)
    n = np.arange(256, dtype=np.uint8)
    want = np.where(n >= NO_PATH, 2 * np.pi, n.astype(float) * shooter.table.bin_width)
    assert shooter._radians[n].tobytes() == want.tobytes()


def test_shooting_arc_lengths_are_the_norm_formula():
    # the arc's lengths, once per arc, and the nearest point's distances without
    # np.linalg.norm's dispatch: the same floats as the formula _arc_heading used
    from strategies.policies.shooting import _arc_lengths, _row_norms

    rng = np.random.default_rng(3)
    for n in (2, 5, 40, 300):
        path = np.cumsum(rng.normal(scale=0.05, size=(n, 2)), axis=0) + rng.uniform(-9, 9, 2)
        e = path[rng.integers(n)] + rng.normal(scale=1e-3, size=2)
        assert _row_norms(path - e).tobytes() == np.linalg.norm(path - e, axis=1).tobytes()
        want = np.cumsum(np.r_[0.0, np.linalg.norm(np.diff(path, axis=0), axis=1)])
        assert _arc_lengths(path).tobytes() == want.tobytes()
