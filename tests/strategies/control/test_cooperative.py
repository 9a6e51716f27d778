"""Sec. 7 cooperative motion against closed forms, quadrature and finite differences."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import quad, solve_ivp

from envs.errors import InfeasibleError, SurveilValueError
from strategies.control.cooperative import (
    corner_feasible,
    corner_min_distance,
    corner_pursuer_position,
    corner_pursuer_velocity,
    corner_required_speed,
    straight_leader_time,
    tractrix,
    tractrix_numeric,
    wall_follow_feasible,
    wall_follow_max_speed,
    wall_follow_speed,
    wall_follow_theta_dot,
)
from strategies.control.kinematics import theta_dot

# ------------------------------------------------------------------------- 7.1 tractrix


def test_tractrix_reference_and_printed_form():
    t = np.linspace(0.0, 3.0, 31)
    tr = tractrix(t)
    np.testing.assert_allclose(tr.follower[:, 0], t - np.tanh(t), atol=1e-12)
    np.testing.assert_allclose(tr.follower[:, 1], 1.0 / np.cosh(t), atol=1e-12)
    np.testing.assert_allclose(tr.theta, 2 * np.arctan(np.exp(t)), atol=1e-12)
    np.testing.assert_allclose(tr.speed, np.tanh(t), atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(tr.follower - tr.leader, axis=1), 1.0, atol=1e-12)
    one = tractrix([1.0])
    np.testing.assert_allclose(one.follower[0], [0.2384058440, 0.6480542737], atol=1e-9)
    assert one.theta[0] == pytest.approx(2.4365658100, abs=1e-9)


@settings(max_examples=10, deadline=None)
@given(L=st.floats(0.3, 3), v_e=st.floats(0.2, 2), theta0=st.floats(-6, 6), alpha=st.floats(-3, 3))
def test_tractrix_closed_form_matches_position_ode(L, v_e, theta0, alpha):
    t = np.linspace(0.0, 2.0, 5)
    kw = {"L": L, "v_e": v_e, "theta0": theta0, "alpha": alpha, "leader_start": (1.0, -2.0)}
    a, b = tractrix(t, **kw), tractrix_numeric(t, **kw, substeps=100)
    np.testing.assert_allclose(a.follower, b.follower, atol=1e-8)
    np.testing.assert_allclose(a.theta, b.theta, atol=1e-7)
    assert np.all(a.speed <= v_e + 1e-12)


def test_tractrix_speed_is_follower_speed():
    t = np.linspace(0.0, 2.0, 2001)
    tr = tractrix(t, L=1.7, v_e=0.8, theta0=2.0, alpha=0.4)
    fd = np.linalg.norm(np.gradient(tr.follower, t, axis=0), axis=1)
    np.testing.assert_allclose(fd[1:-1], tr.speed[1:-1], atol=1e-5)


# --------------------------------------------------------------------- 7.2 straight leader


def test_straight_leader_reference():
    kw = {"alpha": 0.0, "L": 1.0, "v_p": 1.0, "rho": 0.5}
    assert straight_leader_time(math.pi / 2, math.pi, **kw) == pytest.approx(1.2899496125, abs=1e-9)
    assert straight_leader_time(math.pi / 2, 0.0, **kw) == pytest.approx(2.6232829458, abs=1e-9)


@settings(max_examples=40, deadline=None)
@given(
    th0=st.floats(-4, 4),
    dth=st.floats(-5, 5).filter(lambda d: abs(d) > 1e-3),
    alpha=st.floats(-4, 4),
    rho=st.floats(0.0, 0.95),
    L=st.floats(0.2, 3),
    v_p=st.floats(0.3, 3),
)
def test_straight_leader_matches_quadrature(th0, dth, alpha, rho, L, v_p):
    def dt_dtheta(th):
        tp, tm = theta_dot(alpha, th, L=L, v_p=v_p, rho=rho)
        return 1.0 / (tp if dth > 0 else -tm)

    lo, hi = sorted((th0, th0 + dth))
    expected = quad(dt_dtheta, lo, hi, epsabs=1e-13, epsrel=1e-12, limit=200)[0]
    got = straight_leader_time(th0, th0 + dth, alpha=alpha, L=L, v_p=v_p, rho=rho)
    assert got > 0
    assert got == pytest.approx(expected, rel=1e-9)


def test_straight_leader_simulated_and_refusals():
    # integrate θ̇⁺ in time until θ reaches θ1: the event time is T
    kw = {"L": 1.3, "v_p": 1.0, "rho": 0.6}

    def f(t, th):
        return [theta_dot(0.7, th[0], **kw)[0]]

    ev = lambda t, th: th[0] - 2.5
    ev.terminal = True
    sol = solve_ivp(f, (0, 50), [0.3], events=ev, rtol=1e-12, atol=1e-12)
    assert sol.t_events[0][0] == pytest.approx(
        straight_leader_time(0.3, 2.5, alpha=0.7, **kw), rel=1e-8
    )
    for rho in (1.0, 1.5):
        with pytest.raises(InfeasibleError, match=re.escape(f"rho = {rho}")):
            straight_leader_time(0.0, 1.0, alpha=0.0, L=1.0, v_p=1.0, rho=rho)
    assert straight_leader_time(1.0, 1.0, alpha=0.0, L=1.0, v_p=1.0, rho=0.5) == 0.0


# ---------------------------------------------------------------------- 7.3 wall following


@settings(max_examples=30, deadline=None)
@given(
    alpha=st.floats(-4, 4),
    theta=st.floats(-1.4, 1.4).map(lambda t: t + math.pi * 0),
    flip=st.booleans(),
    L=st.floats(0.3, 3),
    v_e=st.floats(0.2, 2),
)
def test_wall_following_matches_finite_differences(alpha, theta, flip, L, v_e):
    if flip:
        theta += math.pi  # cos θ < 0: the case the printed bound gets wrong (E6)
    # leader moves straight; the follower stays on y = 0: y_e + L sin θ = 0
    e0 = np.array([0.0, -L * math.sin(theta)])
    d = np.array([math.cos(alpha), math.sin(alpha)])
    cos_sign = math.copysign(1.0, math.cos(theta))

    def state(t):
        e = e0 + v_e * t * d
        s = -e[1] / L
        th = math.atan2(s, cos_sign * math.sqrt(1 - s * s))
        return e[0] + L * math.cos(th), th

    h = 1e-6
    (xp1, th1), (xp0, th0_) = state(h), state(-h)
    assert (xp1 - xp0) / (2 * h) == pytest.approx(
        wall_follow_speed(alpha, theta, v_e=v_e), rel=1e-6, abs=1e-6
    )
    dth = math.remainder(th1 - th0_, 2 * math.pi) / (2 * h)
    assert dth == pytest.approx(
        wall_follow_theta_dot(alpha, theta, L=L, v_e=v_e), rel=1e-6, abs=1e-6
    )


def test_wall_following_worst_heading_and_feasibility():
    for theta in (0.3, 1.2, 2.8, -2.0):
        headings = np.linspace(-math.pi, math.pi, 200001)
        worst = np.max(np.abs(wall_follow_speed(headings, theta, v_e=0.7)))
        assert worst == pytest.approx(wall_follow_max_speed(theta, v_e=0.7), rel=1e-8)
        for k in (-1, 0, 1, 2):  # α = θ + kπ for every integer k (E6)
            assert abs(wall_follow_speed(theta + k * math.pi, theta, v_e=0.7)) == (
                pytest.approx(0.7 / abs(math.cos(theta)))
            )
    # E6: |cos θ| >= rho, not cos θ >= rho
    assert wall_follow_feasible(2.8, rho=0.5)  # cos 2.8 ≈ -0.94
    assert not wall_follow_feasible(1.4, rho=0.5)
    np.testing.assert_array_equal(
        wall_follow_feasible(np.array([0.0, 1.5, math.pi]), rho=0.5), [True, False, True]
    )
    assert math.isinf(wall_follow_max_speed(math.pi / 2 + 0.0, v_e=1.0)) or (
        wall_follow_max_speed(math.pi / 2, v_e=1.0) > 1e15
    )


# ---------------------------------------------------------------------- 7.4 corner


@settings(max_examples=30, deadline=None)
@given(
    ex=st.floats(-2, 2),
    ey=st.floats(-2, 2),
    heading=st.floats(-4, 4),
    frac=st.floats(0.1, 0.95),
    v_e=st.floats(0.2, 2),
)
def test_corner_velocity_matches_finite_differences(ex, ey, heading, frac, v_e):
    vertex = np.array([0.3, 0.4])
    e = np.array([ex, ey])
    ell = np.linalg.norm(vertex - e)
    if ell < 0.05:
        return
    L = ell / frac
    e_dot = v_e * np.array([math.cos(heading), math.sin(heading)])
    h = 1e-6
    fd = (
        corner_pursuer_position(e + h * e_dot, vertex, L=L)
        - corner_pursuer_position(e - h * e_dot, vertex, L=L)
    ) / (2 * h)
    got = corner_pursuer_velocity(e, vertex, e_dot, L=L)
    np.testing.assert_allclose(got, fd, atol=1e-6 * max(1.0, L / ell))
    p = corner_pursuer_position(e, vertex, L=L)
    assert np.linalg.norm(p - e) == pytest.approx(L)
    # the vertex is on the rod
    u, w = p - e, vertex - e
    assert abs(u[0] * w[1] - u[1] * w[0]) < 1e-9 * L * ell


def test_corner_required_speed_and_threshold():
    L, v_e = 2.0, 0.6
    e = np.array([0.0, 0.0])
    for ell in (0.3, 0.8, 1.0, 1.9):
        vertex = np.array([ell, 0.0])
        heads = np.linspace(-math.pi, math.pi, 3601)
        e_dots = v_e * np.column_stack([np.cos(heads), np.sin(heads)])
        speeds = np.linalg.norm(
            corner_pursuer_velocity(np.tile(e, (len(heads), 1)), vertex, e_dots, L=L), axis=1
        )
        assert speeds.max() == pytest.approx(corner_required_speed(ell, L=L, v_e=v_e), rel=1e-6)
    rho = 0.5
    l_min = corner_min_distance(L=L, rho=rho)
    assert l_min == pytest.approx(rho * L / (1 + rho))
    v_p = v_e / rho
    assert corner_required_speed(l_min * 1.001, L=L, v_e=v_e) <= v_p
    assert corner_required_speed(l_min * 0.999, L=L, v_e=v_e) > v_p
    assert corner_feasible(l_min * 1.001, L=L, rho=rho)
    assert not corner_feasible(l_min * 0.999, L=L, rho=rho)
    assert not corner_feasible(1.0, L=L, rho=1.2)


def test_bad_input():
    with pytest.raises(SurveilValueError, match="expected 0 < l <= L"):
        corner_pursuer_position([0, 0], [3, 0], L=1.0)
    with pytest.raises(SurveilValueError, match="l = 0"):
        corner_required_speed(0, L=1.0, v_e=1.0)
    with pytest.raises(InfeasibleError, match=r"rho = 1\.5"):
        corner_min_distance(L=1.0, rho=1.5)
    with pytest.raises(SurveilValueError, match="L = -1"):
        tractrix([0.0, 1.0], L=-1)
    with pytest.raises(SurveilValueError, match="theta"):
        wall_follow_speed(0.0, math.nan, v_e=1.0)
    with pytest.raises(SurveilValueError, match=r"rho = -0\.5"):
        straight_leader_time(0.0, 1.0, alpha=0.0, L=1.0, v_p=1.0, rho=-0.5)


@pytest.mark.parametrize("substeps", [0, -3, 2.0, True, "10"])
def test_tractrix_numeric_refuses_a_step_count_that_is_no_positive_integer(substeps):
    # 0 and -3 integrated nothing (the follower stood at its start: no error), 2.0 and
    # "10" raised TypeError from range(), True integrated one step
    with pytest.raises(
        SurveilValueError, match=rf"substeps = {substeps!r}: expected an integer >= 1"
    ):
        tractrix_numeric([0.0, 1.0], substeps=substeps)


def test_tractrix_refuses_a_leader_travel_that_overflows():
    # v_e t = 1e300 * 1e300 was inf: the leader at inf, the follower nan (no error)
    with pytest.raises(SurveilValueError, match=r"v_e = 1e\+300 .* overflows"):
        tractrix([0.0, 1e300], v_e=1e300)
    with pytest.raises(SurveilValueError, match="overflows"):
        tractrix_numeric([0.0, 1e300], v_e=1e300)
    assert np.isfinite(tractrix([0.0, 1e300], v_e=1e-10).follower).all()
