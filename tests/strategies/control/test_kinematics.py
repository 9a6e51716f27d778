"""Eq. (6) kinematics: reference values of THEORY §7, the |ṗ| = V_p identity, E1/E2/E8."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from envs.errors import SurveilValueError
from strategies.control.kinematics import (
    escape_trivial,
    max_abs_theta_dot,
    min_max_theta_dot,
    pursuer_velocity,
    pursuer_velocity_holding_range,
    theta_dot,
    theta_dot_feasible,
    theta_dot_from_velocities,
)

angles = st.floats(-10.0, 10.0, allow_nan=False)
lengths = st.floats(0.1, 10.0)
speeds = st.floats(0.1, 5.0)
ratios = st.floats(0.0, 1.0)

REFERENCE = [  # THEORY §7: V_p = L = 1, rho = 0.5, theta = 0, alpha = phi
    (0.0, 0.8660254038, -0.8660254038),
    (math.pi / 6, 0.6513878189, -1.1513878189),
    (math.pi / 2, 0.5, -1.5),
    (math.pi, 0.8660254038, -0.8660254038),
    (3 * math.pi / 2, 1.5, -0.5),
]


@pytest.mark.parametrize(("phi", "plus", "minus"), REFERENCE)
def test_reference_values(phi, plus, minus):
    tp, tm = theta_dot(phi, 0.0, L=1.0, v_p=1.0, rho=0.5)
    assert tp == pytest.approx(plus, abs=1e-9)
    assert tm == pytest.approx(minus, abs=1e-9)
    for td in (tp, tm):  # |ė + L θ̇ (-sin θ, cos θ)| = V_p
        v = pursuer_velocity(0.5 * np.array([math.cos(phi), math.sin(phi)]), 0.0, td, L=1.0)
        assert np.linalg.norm(v) == pytest.approx(1.0, abs=1e-12)


@settings(max_examples=200, deadline=None)
@given(alpha=angles, theta=angles, L=lengths, v_p=speeds, rho=ratios)
def test_both_roots_give_pursuer_speed_vp(alpha, theta, L, v_p, rho):
    tp, tm = theta_dot(alpha, theta, L=L, v_p=v_p, rho=rho)
    e_dot = rho * v_p * np.array([math.cos(alpha), math.sin(alpha)])
    for td in (tp, tm):
        v = e_dot + L * td * np.array([-math.sin(theta), math.cos(theta)])
        assert np.linalg.norm(v) == pytest.approx(v_p, rel=1e-9)
    assert tp >= -1e-12 and tm <= 1e-12  # E1: >= and <=


def test_strict_signs_below_one_and_zero_rate_at_rho_one():
    phi = np.linspace(0.0, 2 * math.pi, 721)
    tp, tm = theta_dot(phi, 0.0, L=1.0, v_p=1.0, rho=0.99)
    assert np.all(tp > 0) and np.all(tm < 0)
    tp1, _ = theta_dot(phi, 0.0, L=1.0, v_p=1.0, rho=1.0)
    up = np.sin(phi) >= 0  # E1: θ̇⁺ = 0 whenever sin(α - θ) >= 0 at rho = 1
    assert np.max(np.abs(tp1[up])) < 1e-7
    assert np.all(tp1[np.sin(phi) < -1e-3] > 0)


def test_min_and_max_of_max_abs_theta_dot_reference():
    vals = max_abs_theta_dot(
        np.array([0.0, math.pi / 2, math.pi, 1.5 * math.pi]), 0.0, L=1.0, v_p=1.0, rho=0.5
    )
    np.testing.assert_allclose(vals, [math.sqrt(0.75), 1.5, math.sqrt(0.75), 1.5], atol=1e-12)


@settings(max_examples=40, deadline=None)
@given(theta=angles, L=lengths, v_p=speeds, rho=st.floats(0.01, 0.99))
def test_min_max_heading_is_the_grid_minimum(theta, L, v_p, rho):
    # E2: the minimum is at φ = kπ even though g is not concave; checked by brute force.
    best = min_max_theta_dot(theta, L=L, v_p=v_p, rho=rho)
    grid = theta + np.linspace(0.0, 2 * math.pi, 4001)
    rates = max_abs_theta_dot(grid, theta, L=L, v_p=v_p, rho=rho)
    assert best.rate == pytest.approx(rates.min(), rel=1e-9)
    assert best.rate == pytest.approx((v_p / L) * math.sqrt(1 - rho * rho), rel=1e-12)
    for heading in (best.toward, best.away):
        assert max_abs_theta_dot(heading, theta, L=L, v_p=v_p, rho=rho) == pytest.approx(
            best.rate, rel=1e-9
        )
    assert math.cos(best.toward - theta) == pytest.approx(1.0)
    assert math.cos(best.away - theta) == pytest.approx(-1.0)


def test_rho_above_one_is_nan_free_and_flagged():
    phi = np.linspace(0.0, 2 * math.pi, 13)
    tp, tm = theta_dot(phi, 0.0, L=2.0, v_p=1.0, rho=1.5)
    assert np.all(np.isfinite(tp)) and np.all(np.isfinite(tm))
    ok = theta_dot_feasible(phi, 0.0, rho=1.5)
    assert not ok[0] and ok[3]  # φ = 0 infeasible, φ = π/2 feasible
    np.testing.assert_allclose(tp[~ok], -0.5 * 1.5 * np.sin(phi[~ok]), atol=1e-12)
    np.testing.assert_allclose(tm[~ok], tp[~ok])
    assert escape_trivial(1.5) and not escape_trivial(1.0)
    assert min_max_theta_dot(0.3, L=1.0, v_p=1.0, rho=1.5).rate == 0.0
    assert all(theta_dot_feasible(phi, 0.0, rho=1.0))


@settings(max_examples=100, deadline=None)
@given(alpha=angles, theta=angles, L=lengths, v_p=speeds, rho=ratios, t=st.floats(0.0, 1.0))
def test_pursuer_velocity_in_rate_interval_is_within_speed(alpha, theta, L, v_p, rho, t):
    tp, tm = theta_dot(alpha, theta, L=L, v_p=v_p, rho=rho)
    td = tm + t * (tp - tm)
    e_dot = rho * v_p * np.array([math.cos(alpha), math.sin(alpha)])
    v = pursuer_velocity(e_dot, theta, td, L=L)
    assert np.linalg.norm(v) <= v_p * (1 + 1e-9)
    assert theta_dot_from_velocities(e_dot, v, theta, L=L) == pytest.approx(td, abs=1e-9)
    # E8: L θ̇ is the relative perpendicular speed, not the pursuer's own.
    n = np.array([-math.sin(theta), math.cos(theta)])
    assert L * td == pytest.approx(float((v - e_dot) @ n), abs=1e-9)


def _simulate(command, t_end=4.0, steps=4000, L=1.5, v_p=1.0, rho=0.7):
    """RK4 on (e, p, θ) with ė = rho v_p (cos a(t), sin a(t)) and ṗ from ``command``."""

    def f(t, z):
        a = 0.3 + math.sin(2.0 * t)
        e_dot = rho * v_p * np.array([math.cos(a), math.sin(a)])
        p_dot, th_dot = command(t, z, a, e_dot)
        return np.concatenate([e_dot, p_dot, [th_dot]])

    z = np.array([0.0, 0.0, L * math.cos(2.0), L * math.sin(2.0), 2.0])
    h = t_end / steps
    speeds_ = []
    for i in range(steps):
        t = i * h
        k1 = f(t, z)
        k2 = f(t + h / 2, z + h / 2 * k1)
        k3 = f(t + h / 2, z + h / 2 * k2)
        k4 = f(t + h, z + h * k3)
        z = z + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        speeds_.append(np.linalg.norm(k1[2:4]))
    return z, max(speeds_)


def test_integrated_pursuer_keeps_distance_and_orientation():
    L, v_p, rho = 1.5, 1.0, 0.7

    def command(t, z, a, e_dot):
        tp, tm = theta_dot(a, z[4], L=L, v_p=v_p, rho=rho)
        td = tm + 0.8 * (tp - tm)
        return pursuer_velocity(e_dot, z[4], td, L=L), td

    z, vmax = _simulate(command, L=L, v_p=v_p, rho=rho)
    rel = z[2:4] - z[0:2]
    assert np.linalg.norm(rel) == pytest.approx(L, abs=1e-9)
    assert math.remainder(math.atan2(rel[1], rel[0]) - z[4], 2 * math.pi) == pytest.approx(
        0.0, abs=1e-9
    )
    assert vmax <= v_p * (1 + 1e-9)


def test_holding_range_converges_to_target_within_speed():
    L0, target, v_p, rho = 2.0, 1.5, 1.0, 0.5

    def command(t, z, a, e_dot):
        rel = z[2:4] - z[0:2]
        L = float(np.linalg.norm(rel))
        th = math.atan2(rel[1], rel[0])
        _, tm = theta_dot(a, th, L=L, v_p=v_p, rho=rho)
        cmd = pursuer_velocity_holding_range(
            e_dot, th, 0.5 * tm, L=L, L_target=target, v_p=v_p, gain=2.0
        )
        assert cmd.feasible
        assert np.linalg.norm(cmd.velocity) <= v_p * (1 + 1e-12)
        assert theta_dot_from_velocities(e_dot, cmd.velocity, th, L=L) == pytest.approx(
            0.5 * tm, abs=1e-12
        )
        return cmd.velocity, 0.0

    z, _ = _simulate(command, t_end=6.0, steps=1500, L=L0, v_p=v_p, rho=rho)
    assert np.linalg.norm(z[2:4] - z[0:2]) == pytest.approx(target, abs=1e-3)


def test_holding_range_reports_unachievable_rate():
    cmd = pursuer_velocity_holding_range([0.5, 0.0], 0.0, 5.0, L=1.0, L_target=1.0, v_p=1.0)
    assert not cmd.feasible
    np.testing.assert_allclose(cmd.velocity, [0.0, 1.0], atol=1e-12)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"alpha": math.nan, "theta": 0.0, "L": 1.0, "v_p": 1.0, "rho": 0.5}, "alpha"),
        ({"alpha": 0.0, "theta": math.inf, "L": 1.0, "v_p": 1.0, "rho": 0.5}, "theta"),
        ({"alpha": 0.0, "theta": 0.0, "L": 0.0, "v_p": 1.0, "rho": 0.5}, "L = 0.0"),
        ({"alpha": 0.0, "theta": 0.0, "L": -1.0, "v_p": 1.0, "rho": 0.5}, "L = -1.0"),
        ({"alpha": 0.0, "theta": 0.0, "L": 1.0, "v_p": math.nan, "rho": 0.5}, "v_p"),
        ({"alpha": 0.0, "theta": 0.0, "L": 1.0, "v_p": 1.0, "rho": -0.1}, "rho = -0.1"),
    ],
)
def test_bad_input_raises_named_error(kwargs, match):
    alpha, theta = kwargs.pop("alpha"), kwargs.pop("theta")
    with pytest.raises(SurveilValueError, match=match):
        theta_dot(alpha, theta, **kwargs)
    assert issubclass(SurveilValueError, ValueError)


def test_bad_vector_shapes_raise():
    with pytest.raises(SurveilValueError, match="evader_velocity"):
        pursuer_velocity([1.0, 2.0, 3.0], 0.0, 0.1, L=1.0)
    with pytest.raises(SurveilValueError, match="gain"):
        pursuer_velocity_holding_range([0, 0], 0, 0, L=1, L_target=1, v_p=1, gain=-1)
