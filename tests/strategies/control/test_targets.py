"""Escape endpoints of Fig. 13 in the evader frame."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from envs.errors import SurveilValueError
from strategies.control.targets import (
    critical_curve_escape_target,
    from_evader_frame,
    to_evader_frame,
    vertex_escape_target,
)

SQUARE = (-2.0, 0.0, -2.0, 0.0)  # obstacle [-2, 0]^2, convex vertex at the origin


def _rod_hits_square(p, theta, L, n=4000):
    x0, x1, y0, y1 = SQUARE
    t = np.linspace(0.0, L, n)
    xs, ys = p[0] + t * math.cos(theta), p[1] + t * math.sin(theta)
    return bool(np.any((xs > x0) & (xs < x1) & (ys > y0) & (ys < y1)))


def test_square_vertex_admissible_wedge():
    # the square's CCW order is (-2,-2), (0,-2), (0,0), (-2,0)
    t = vertex_escape_target(
        [3.0, 1.0], [3.0, 2.5], [0.0, 0.0], [0.0, -2.0], [-2.0, 0.0], L=1.5, obstacle_ccw=True
    )
    assert t.kind == "vertex"
    assert t.theta_i == pytest.approx(0.0) and t.theta_f == pytest.approx(math.pi / 2)
    swapped = vertex_escape_target([3.0, 1.0], [3.0, 2.5], [0, 0], [0, -2], [-2, 0], L=1.5)
    assert (swapped.theta_i, swapped.theta_f) == (t.theta_i, t.theta_f)
    assert t.x_e == pytest.approx(math.hypot(3, 1))
    np.testing.assert_allclose(
        to_evader_frame(t.position, [3.0, 1.0], t.beta), [t.x_e, 0.0], atol=1e-12
    )
    assert t.theta0 == pytest.approx(math.remainder(math.pi / 2 - t.beta, 2 * math.pi))


def test_admissible_wedge_matches_brute_force_rod_collisions():
    # With the evader at v, the rod survives every small evader move iff θ is in the wedge.
    t = vertex_escape_target([3.0, 1.0], [3.0, 2.5], [0, 0], [-2, 0], [0, -2], L=1.5)
    eps = 1e-3
    moves = [
        eps * np.array([math.cos(a), math.sin(a)])
        for a in np.linspace(-math.pi / 2 + 0.01, math.pi - 0.01, 400)
    ]  # free wedge
    for theta in np.linspace(-math.pi / 2 + 0.05, math.pi - 0.05, 40):
        inside = (theta - t.theta_i) % (2 * math.pi) <= (t.theta_f - t.theta_i) % (2 * math.pi)
        hit = any(_rod_hits_square(m, theta, 1.5) for m in moves)
        assert hit != inside, theta


def test_required_rotations():
    v, a, b = [0, 0], [-2, 0], [0, -2]
    below = vertex_escape_target([3, 1], [3, -0.5], v, a, b, L=1.5)  # θ = -π/2
    assert below.rotation_ccw == pytest.approx(math.pi / 2)
    assert below.rotation_cw == pytest.approx(math.pi)
    assert below.required_rotation("+") == below.rotation_ccw
    assert below.required_rotation("-") == below.rotation_cw
    inside = vertex_escape_target([3, 1], [4, 2], v, a, b, L=1.5)
    assert inside.rotation_ccw == inside.rotation_cw == 0.0


def test_critical_curve_target():
    curve = np.array([[2.0, -5.0], [2.0, 5.0]])
    t = critical_curve_escape_target([0.0, 0.0], [-1.0, 0.0], curve, 0.0, math.pi / 2, L=1.0)
    assert t.kind == "critical_curve"
    np.testing.assert_allclose(t.position, [2.0, 0.0])
    assert t.x_e == pytest.approx(2.0) and t.beta == pytest.approx(0.0)
    # admissible = complement of the escapable arc [0, π/2]
    assert t.theta_i == pytest.approx(math.pi / 2) and t.theta_f == pytest.approx(0.0)
    assert t.rotation_ccw == t.rotation_cw == 0.0  # θ = π is admissible
    t2 = critical_curve_escape_target([0, 0], [0.6, 0.8], curve, 0.0, math.pi / 2, L=1.0)
    assert t2.rotation_ccw == pytest.approx(math.pi / 2 - math.atan2(0.8, 0.6))
    assert t2.rotation_cw == pytest.approx(math.atan2(0.8, 0.6))
    poly = np.array([[1.0, 3.0], [1.0, 1.0], [3.0, 1.0]])  # nearest point: the corner
    t3 = critical_curve_escape_target([0, 0], [-1, 0], poly, 0.0, 1.0, L=1.0)
    np.testing.assert_allclose(t3.position, [1.0, 1.0])


@settings(max_examples=50, deadline=None)
@given(
    pts=st.lists(st.tuples(st.floats(-50, 50), st.floats(-50, 50)), min_size=1, max_size=5),
    e=st.tuples(st.floats(-50, 50), st.floats(-50, 50)),
    beta=st.floats(-7, 7),
)
def test_frame_round_trip(pts, e, beta):
    p = np.array(pts)
    q = to_evader_frame(p, e, beta)
    np.testing.assert_allclose(from_evader_frame(q, e, beta), p, atol=1e-9)
    np.testing.assert_allclose(
        np.linalg.norm(q, axis=1), np.linalg.norm(p - np.array(e), axis=1), atol=1e-9
    )


def test_bad_input():
    with pytest.raises(SurveilValueError, match="concave"):
        vertex_escape_target([3, 1], [3, 2], [0, 0], [0, -2], [-2, 0], L=1, obstacle_ccw=False)
    with pytest.raises(SurveilValueError, match="collinear"):
        vertex_escape_target([3, 1], [3, 2], [0, 0], [-2, 0], [2, 0], L=1)
    with pytest.raises(SurveilValueError, match="evader"):
        vertex_escape_target([math.nan, 1], [3, 2], [0, 0], [-2, 0], [0, -2], L=1)
    with pytest.raises(SurveilValueError, match="L = 0"):
        vertex_escape_target([3, 1], [3, 2], [0, 0], [-2, 0], [0, -2], L=0)
    with pytest.raises(SurveilValueError, match="curve"):
        critical_curve_escape_target([0, 0], [1, 0], [[1.0, 1.0]], 0.0, 1.0, L=1.0)
