"""The continuous-time sweep: corner passes between clear frames, distance events at the
analytic time, and random steps against dense time sampling with shapely."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from shapely.geometry import LineString, Point

from envs.errors import InvalidConfigError
from envs.geometry import Kernel, kernel_for
from envs.maps import Feature, Map
from tests.envs.geometry._maps import all_maps, sample_free_points, square_obstacle_map


def _vertex(world: Map, v) -> int:
    return int(np.flatnonzero(np.all(world.vertices == np.asarray(v, float), axis=1))[0])


def test_rod_jumping_over_a_small_block_between_clear_frames():
    world = Map(
        [(-5, -5), (5, -5), (5, 5), (-5, 5)],
        [[(-0.2, -0.2), (0.2, -0.2), (0.2, 0.2), (-0.2, 0.2)]],
    )
    k = kernel_for(world)
    e0, e1 = np.array([-3.0, -1.0]), np.array([-3.0, 1.1])
    p0, p1 = np.array([3.0, -0.9]), np.array([3.0, 1.0])
    assert k.line_of_sight(e0, p0) and k.line_of_sight(e1, p1)  # the frames alone miss it
    ev = k.sweep(p0, e0, p1, e1, 0.0, 10.0)
    assert ev is not None and ev.cause == "occluded"

    # closed form: the rod's height at x = vx is linear in t (ends at fixed x = -3, 3)
    def t_hit(vx, vy):
        s = (vx + 3.0) / 6.0
        y0 = e0[1] + (p0[1] - e0[1]) * s
        y1 = e1[1] + (p1[1] - e1[1]) * s
        return (vy - y0) / (y1 - y0)

    first = min((t_hit(-0.2, -0.2), (-0.2, -0.2)), (t_hit(0.2, -0.2), (0.2, -0.2)))
    assert ev.time == pytest.approx(first[0], abs=1e-12)
    assert ev.feature == Feature("vertex", _vertex(world, first[1]))
    np.testing.assert_allclose(ev.pursuer, p0 + ev.time * (p1 - p0))
    np.testing.assert_allclose(ev.evader, e0 + ev.time * (e1 - e0))
    assert LineString([ev.evader, ev.pursuer]).distance(Point(first[1])) < 1e-12


def test_rod_swinging_past_a_corner_between_clear_frames():
    world = square_obstacle_map()
    k = kernel_for(world)
    # evader above the top edge moving right, pursuer right of the obstacle moving down:
    # the rod swings from above the corner (0, 0) to its right, past the corner
    e0, e1 = np.array([-1.7, 0.2]), np.array([1.5, 0.3])
    p0, p1 = np.array([0.9, 0.3]), np.array([1.6, -2.0])
    assert k.line_of_sight(e0, p0) and k.line_of_sight(e1, p1)
    ev = k.sweep(p0, e0, p1, e1, 0.0, 10.0)
    assert ev is not None and ev.cause == "occluded"
    assert ev.feature == Feature("vertex", _vertex(world, (0, 0)))
    # closed form: cross(P(t), E(t)) = 0 for the corner at the origin
    dp, de = p1 - p0, e1 - e0
    c2 = dp[0] * de[1] - dp[1] * de[0]
    c1 = p0[0] * de[1] - p0[1] * de[0] + dp[0] * e0[1] - dp[1] * e0[0]
    c0 = p0[0] * e0[1] - p0[1] * e0[0]
    roots = sorted(r.real for r in np.roots([c2, c1, c0]) if 0 <= r.real <= 1)
    assert ev.time == pytest.approx(roots[0], abs=1e-12)
    # just after the event the rod cuts the obstacle
    t = ev.time + 1e-6
    seg = LineString([e0 + t * de, p0 + t * dp])
    assert seg.crosses(world.free_region.boundary)


@pytest.mark.parametrize(
    ("e0", "e1", "p0", "p1", "l_min", "l_max", "cause", "time"),
    [
        ((2, 2), (2, 2), (2.5, 2), (4.5, 2), 0.0, 2.0, "too_far", 0.75),
        ((2, 2), (2, 2), (4, 2), (2.5, 2), 1.0, 3.0, "too_close", 2 / 3),
        ((0, 3), (1, 3), (2, 3), (4, 3), 0.0, 2.5, "too_far", 0.5),
        ((1, 1), (1, 1), (1, 2), (3, 2), 0.5, 2.0, "too_far", math.sqrt(3) / 2),
        (
            (1, 1),
            (1, 1),
            (4, 1),
            (1, 4),
            2.5,
            4.0,
            "too_close",
            (1 - math.sqrt(1 - 2 * (1 - 2.5**2 / 9))) / 2,
        ),
        ((1, 1), (1, 1), (1, 5), (1, 4), 0.0, 3.0, "too_far", 0.0),
        ((1, 1), (1, 1), (1, 1.2), (1, 4), 0.5, 4.0, "too_close", 0.0),
    ],
)
def test_distance_events_at_the_analytic_time(e0, e1, p0, p1, l_min, l_max, cause, time):
    k = kernel_for(square_obstacle_map())
    ev = k.sweep(p0, e0, p1, e1, l_min, l_max)
    assert ev is not None
    assert ev.cause == cause and ev.feature is None
    assert ev.time == pytest.approx(time, abs=1e-12)
    d = np.linalg.norm(ev.pursuer - ev.evader)
    if time > 0:
        assert d == pytest.approx(l_max if cause == "too_far" else l_min, abs=1e-12)


def test_quiet_step_and_blocked_start():
    world = square_obstacle_map()
    k = kernel_for(world)
    assert k.sweep((3, 3), (2, 2), (3.5, 3), (2.5, 2), 0.5, 3.0) is None
    assert k.sweep((3, 3), (3, 3), (3, 3), (3, 3), 0.0, 3.0) is None
    ev = k.sweep((1, -1), (-1, 1), (2, -1), (-1, 2), 0.0, 5.0)  # through (0, 0) at t = 0
    assert ev.time == 0.0 and ev.cause == "occluded"
    assert ev.feature == Feature("vertex", _vertex(world, (0, 0)))
    # blocked at t = 0 by an edge
    ev = k.sweep((-1, -3), (-1, 1), (-1, -3), (-1, 1), 0.0, 5.0)
    assert ev.time == 0.0 and ev.feature.kind == "edge"


def _dense_failures(world, p0, e0, p1, e1, l_min, l_max, n=2000):
    t = np.linspace(0.0, 1.0, n + 1)
    P = p0 + t[:, None] * (p1 - p0)
    E = e0 + t[:, None] * (e1 - e0)
    lines = shapely.linestrings(np.stack([E, P], axis=1))
    boundary = world.free_region.boundary
    shapely.prepare(boundary)
    d = np.linalg.norm(P - E, axis=1)
    fail = shapely.intersects(lines, boundary) | (d > l_max) | (d < l_min)
    return t, fail


def _random_steps(world, rng, n, l_min, l_max, reach):
    k = kernel_for(world)
    pts = sample_free_points(world, rng, 4 * n, margin=1e-3)
    out = []
    i = 0
    while len(out) < n and i + 1 < len(pts):
        e0 = pts[i]
        p0 = e0 + rng.uniform(l_min, l_max) * np.array(
            [math.cos(a := rng.uniform(-math.pi, math.pi)), math.sin(a)]
        )
        e1 = e0 + rng.uniform(-reach, reach, 2)
        p1 = p0 + rng.uniform(-reach, reach, 2)
        i += 1
        ok = world.contains(np.stack([p0, e1, p1])).all()
        if not ok or world.distance_to_walls(np.stack([p0, e1, p1])).min() < 1e-3:
            continue
        if not (k.line_of_sight(e0, e1) and k.line_of_sight(p0, p1) and k.line_of_sight(e0, p0)):
            continue  # the bodies' own paths must stay in free space
        out.append((p0, e0, p1, e1))
    return out


@pytest.mark.parametrize("world", all_maps(), ids=lambda m: m.name)
def test_sweep_matches_dense_sampling(world):
    rng = np.random.default_rng(21)
    k = kernel_for(world)
    l_min, l_max = 0.3, 3.0
    events = 0
    for p0, e0, p1, e1 in _random_steps(world, rng, 40, l_min, l_max, reach=1.5):
        ev = k.sweep(p0, e0, p1, e1, l_min, l_max)
        # the env's shortcut (start known clear) must not change any answer
        fast = k.sweep(p0, e0, p1, e1, l_min, l_max, start_clear=True)
        assert (ev is None) == (fast is None)
        if ev is not None:
            assert (fast.time, fast.cause, fast.feature) == (ev.time, ev.cause, ev.feature)
        t, fail = _dense_failures(world, p0, e0, p1, e1, l_min, l_max)
        if ev is None:
            assert not fail.any(), (p0, e0, p1, e1)
            continue
        events += 1
        # no sampled failure before the event, and the event is a real boundary contact
        if fail.any():
            assert t[np.argmax(fail)] >= ev.time - 1e-9
        assert ev.time <= (t[np.argmax(fail)] if fail.any() else 1.0) + 1e-9
        d = np.linalg.norm(ev.pursuer - ev.evader)
        if ev.cause == "occluded":
            v = world.vertices[ev.feature.index]
            assert ev.feature.kind == "vertex" and world.vertex_convex[ev.feature.index]
            assert LineString([ev.evader, ev.pursuer]).distance(Point(v)) < 1e-9
        elif ev.cause == "too_far":
            assert d == pytest.approx(l_max, abs=1e-9)
        else:
            assert d == pytest.approx(l_min, abs=1e-9)
    assert events >= 5


def test_sweep_rejects_bad_input():
    k = kernel_for(square_obstacle_map())
    with pytest.raises(InvalidConfigError, match="l_min <= l_max"):
        k.sweep((1, 1), (2, 2), (1, 1), (2, 2), 2.0, 1.0)
    with pytest.raises(InvalidConfigError, match="sweep p1"):
        k.sweep((1, 1), (2, 2), (1, np.nan), (2, 2), 0.0, 1.0)
    with pytest.raises(InvalidConfigError, match="sweep l_max"):
        k.sweep((1, 1), (2, 2), (1, 1), (2, 2), 0.0, -1.0)


@pytest.mark.parametrize("numpy_path", [False, True])
@pytest.mark.parametrize(
    ("dx", "touches"), [(0.0, True), (1e-12, True), (-1e-12, True), (1e-6, False)]
)
def test_rod_grazing_a_corner_is_a_touch(dx, touches, numpy_path):
    """cross(P(t) - v, E(t) - v) = 2 (t - 1/2)^2 for dx = 0: the rod's line touches the
    corner (0, 0) at t = 1/2 and backs off; touching blocks (within eps), missing not."""
    world = square_obstacle_map()
    k = Kernel(world)
    k.numpy_threshold = 0 if numpy_path else 10**9
    p0, p1 = np.array([0.5 + dx, 0.0]), np.array([0.5 + dx, -2.0])
    e0, e1 = np.array([-1.0, 1.0]), np.array([0.0, 1.0])
    assert k.line_of_sight(e0, p0) and k.line_of_sight(e1, p1)
    ev = k.sweep(p0, e0, p1, e1, 0.0, 10.0)
    if not touches:
        assert ev is None
        return
    assert ev is not None and ev.cause == "occluded"
    assert ev.time == pytest.approx(0.5, abs=1e-5)
    assert ev.feature == Feature("vertex", _vertex(world, (0, 0)))


def test_occlusion_wins_a_tie_at_time_zero():
    k = kernel_for(square_obstacle_map())
    ev = k.sweep((1, -1), (-1, 1), (1, -1), (-1, 1), 0.0, 1.0)  # too far and occluded
    assert (ev.time, ev.cause) == (0.0, "occluded")
    ev = k.sweep((1, 1), (-1, 1), (1, 1), (-1, 1), 0.0, 1.0)  # too far only
    assert (ev.time, ev.cause) == (0.0, "too_far")
