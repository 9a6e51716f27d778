"""Optimal evasion (Sec. 6.2): shooting invariants, solve_escape optimality, greedy mode."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.interpolate import CubicSpline
from scipy.optimize import brentq, minimize, minimize_scalar

from envs.errors import InfeasibleError, SurveilValueError
from strategies.control.evasion import (
    capped_step,
    escape_path,
    greedy_heading,
    shoot,
    solve_escape,
)
from strategies.control.hamiltonian import f2

FIG11A = {"theta0": math.pi, "lambda1": -1.0, "lambda2_0": 0.41}


# ----------------------------------------------------------------------------- greedy


@pytest.mark.parametrize(
    ("theta", "alpha", "value"),
    [(math.pi, -math.atan(0.5), 1.5), (0.0, math.atan(0.5), 1.5), (math.pi / 2, 0.0, 3.0)],
)
def test_greedy_reference(theta, alpha, value):
    g = greedy_heading(theta, L=1.0, rho=0.5)
    assert g.alpha == pytest.approx(alpha, abs=1e-9)
    assert g.f2 == pytest.approx(value, abs=1e-9)
    assert g.f2 == pytest.approx(f2(g.alpha, theta, L=1.0, rho=0.5), abs=1e-12)


@settings(max_examples=40, deadline=None)
@given(
    theta=st.floats(-4, 4),
    rho=st.floats(0.05, 0.95),
    L=st.floats(0.3, 3),
    branch=st.sampled_from(["+", "-"]),
)
def test_greedy_is_the_numerical_minimiser(theta, rho, L, branch):
    res = minimize_scalar(
        lambda a: abs(f2(a, theta, L=L, rho=rho, branch=branch)),
        bounds=(-1.5707, 1.5707),
        method="bounded",
        options={"xatol": 1e-12},
    )
    g = greedy_heading(theta, L=L, rho=rho, branch=branch)
    assert abs(g.f2) <= res.fun + 1e-9
    assert g.alpha == pytest.approx(res.x, abs=1e-5)


def test_greedy_arc_follows_greedy_heading():
    # λ1 = 0 keeps κ = 0, so the reduced ODE must stay on α = argmin f2 (Fig. 12 mode).
    for branch in ("+", "-"):
        arc = shoot(2.0, 0.0, 0.0, L=1.0, rho=0.6, branch=branch, x_max=3.0)
        g = greedy_heading(arc.theta, L=1.0, rho=0.6, branch=branch)
        np.testing.assert_allclose(arc.alpha, g.alpha, atol=1e-7)


# ----------------------------------------------------------------------------- shoot

SHOTS = [
    ({**FIG11A}, 0.5, "+"),
    ({"theta0": math.pi / 6, "lambda1": 1.0, "lambda2_0": 0.608}, 0.5, "+"),
    ({"theta0": 1.0, "lambda1": 0.3, "lambda2_0": -0.2}, 0.3, "-"),
    ({"theta0": -0.5, "lambda1": -0.3, "lambda2_0": 0.2}, 0.8, "-"),
]


@pytest.mark.parametrize(("kw", "rho", "branch"), SHOTS)
def test_H_constant_and_integrators_agree(kw, rho, branch):
    red = shoot(**kw, L=1.0, rho=rho, branch=branch, x_max=1.5)
    pmp = shoot(**kw, L=1.0, rho=rho, branch=branch, x_max=1.5, method="pmp", step=1 / 800)
    for arc in (red, pmp):
        assert not arc.unbounded
        assert np.ptp(arc.H) <= 1e-6 * max(1.0, abs(arc.H[0]))
    assert red.H[0] == pytest.approx(pmp.H[0], rel=1e-12)
    # compare the two at the pmp grid: θ(x), y(x) by interpolation of the reduced arc
    th = CubicSpline(red.x, red.theta)(pmp.x)
    y = CubicSpline(red.x, red.y)(pmp.x)
    np.testing.assert_allclose(th, pmp.theta, atol=1e-6)
    np.testing.assert_allclose(y, pmp.y, atol=1e-6)
    assert (red.x_c is None) == (pmp.x_c is None)
    if red.x_c is not None:
        assert red.x_c == pytest.approx(pmp.x_c, abs=1e-6)
        assert red.J == pytest.approx(pmp.J, abs=1e-6)
        assert (branch == "+" and red.J > 0) or (branch == "-" and red.J < 0)


def test_fig11a_crossing_near_paper_goal():
    # Fig. 11(a) states x_e = 1 for these multipliers; with L = 1, rho = 0.5 the arc
    # returns to y = 0 at x_c ≈ 0.983 (the paper's L and rho are not given).
    arc = shoot(**FIG11A, L=1.0, rho=0.5, x_max=2.0)
    assert arc.x_c == pytest.approx(0.98338593, abs=1e-6)
    assert arc.J == pytest.approx(1.23407449, abs=1e-6)
    fine = shoot(**FIG11A, L=1.0, rho=0.5, x_max=2.0, step=arc.arclength[1] / 4)
    assert fine.J == pytest.approx(arc.J, abs=1e-7)


@pytest.mark.parametrize("c", [0.1, 2.0, 37.0])
@pytest.mark.parametrize("branch", ["+", "-"])
def test_scale_invariance(c, branch):
    s = 1 if branch == "+" else -1
    l1, l20, th0 = -0.7, 0.3 * s, 2.2
    base = shoot(th0, l1, l20, L=1.2, rho=0.45, branch=branch, x_max=1.0)
    mu0 = 1 + s * l20
    scaled = shoot(th0, c * l1, s * (c * mu0 - 1), L=1.2, rho=0.45, branch=branch, x_max=1.0)
    for name in ("x", "y", "theta", "alpha"):
        np.testing.assert_allclose(getattr(scaled, name), getattr(base, name), atol=1e-12)
    np.testing.assert_allclose(scaled.H, c * base.H, rtol=1e-10)
    np.testing.assert_allclose(1 + s * scaled.lambda2, c * (1 + s * base.lambda2), rtol=1e-10)


def test_branch_minus_is_the_mirror_of_plus():
    minus = shoot(0.8, 0.4, -0.3, L=1.0, rho=0.6, branch="-", x_max=1.2)
    plus = shoot(-0.8, -0.4, 0.3, L=1.0, rho=0.6, branch="+", x_max=1.2)
    np.testing.assert_allclose(minus.y, -plus.y, atol=1e-12)
    np.testing.assert_allclose(minus.theta, -plus.theta, atol=1e-12)
    np.testing.assert_allclose(minus.alpha, -plus.alpha, atol=1e-12)
    np.testing.assert_allclose(minus.lambda2, -plus.lambda2, atol=1e-12)


def test_unbounded_cases():
    # THEORY §4.3: Fig. 11(b)'s multipliers at L = 1, rho = 0.9 lose the minimiser.
    for method in ("reduced", "pmp"):
        arc = shoot(math.pi / 6, 1.0, 0.608, L=1.0, rho=0.9, x_max=2.0, method=method)
        assert arc.unbounded and arc.x[-1] < 2.0 and arc.x_c is None
    # at x = 0 already: λ1/μ above K(-π/2, θ0)
    arc = shoot(0.0, 50.0, 0.0, L=1.0, rho=0.5, x_max=1.0)
    assert arc.unbounded and len(arc.x) == 1


def test_stop_at_crossing_truncates():
    arc = shoot(**FIG11A, L=1.0, rho=0.5, x_max=3.0, stop_at_crossing=True)
    assert arc.x[-2] <= arc.x_c <= arc.x[-1]
    assert arc.pursuer_path().shape == (len(arc.x), 2)
    np.testing.assert_allclose(
        np.linalg.norm(arc.pursuer_path() - arc.evader_path(), axis=1), 1.0, atol=1e-12
    )


# ----------------------------------------------------------------------- solve_escape


def _theta_along(alpha_half, x_e, theta0, L, rho, branch):
    """θ(x_e) - θ0 for headings given at x = 0, h/2, h, ..., x_e (RK4, 2n + 1 values)."""
    s = 1 if branch == "+" else -1
    n = (len(alpha_half) - 1) // 2
    h = x_e / n

    def g(a, th):
        phi = a - th
        c, sp = math.cos(phi), math.sin(phi)
        return s * (math.sqrt(1 - rho * rho * c * c) - s * rho * sp) / (L * rho * math.cos(a))

    th = theta0
    for i in range(n):
        a0, am, a1 = alpha_half[2 * i], alpha_half[2 * i + 1], alpha_half[2 * i + 2]
        k1 = g(a0, th)
        k2 = g(am, th + h / 2 * k1)
        k3 = g(am, th + h / 2 * k2)
        k4 = g(a1, th + h * k3)
        th += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    return th - theta0


def _direct_transcription(theta0, x_e, L, rho, branch, n=20, sub=4):
    """Independent optimum: piecewise-constant α on n cells, SLSQP with y(x_e) = 0."""
    s = 1 if branch == "+" else -1
    h = x_e / (n * sub)

    def g(a, th):  # s f2, vectorised over a batch of profiles
        phi = a - th
        return (np.sqrt(1 - (rho * np.cos(phi)) ** 2) - s * rho * np.sin(phi)) / (
            L * rho * np.cos(a)
        )

    def cost_batch(A):
        th = np.full(A.shape[0], theta0)
        for j in range(n):
            a = A[:, j]
            for _ in range(sub):
                k1 = g(a, th)
                k2 = g(a, th + s * h / 2 * k1)
                k3 = g(a, th + s * h / 2 * k2)
                k4 = g(a, th + s * h * k3)
                th = th + s * h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        return s * (th - theta0)

    def fun(a):
        return float(cost_batch(a[None])[0])

    def jac(a):
        eps = 1e-7
        batch = np.vstack([a, a + eps * np.eye(n)])
        v = cost_batch(batch)
        return (v[1:] - v[0]) / eps

    cons = {
        "type": "eq",
        "fun": lambda a: np.sum(np.tan(a)) * x_e / n,
        "jac": lambda a: x_e / n / np.cos(a) ** 2,
    }
    best = None
    for start in (0.0,):
        a0 = np.full(n, start)
        a0 -= np.mean(a0)  # feasible start: straight line
        res = minimize(
            fun,
            a0,
            jac=jac,
            constraints=[cons],
            method="SLSQP",
            bounds=[(-1.45, 1.45)] * n,
            options={"maxiter": 300, "ftol": 1e-12},
        )
        if abs(cons["fun"](res.x)) < 1e-8 and (best is None or res.fun < best):
            best = res.fun
    return best


CASES = [  # (theta0, x_e, L, rho, branch): seeded, solutions exist
    (math.pi, 1.0, 1.0, 0.5, "+"),
    (2.3, 0.8, 1.3, 0.6, "+"),
    (-0.9, 1.2, 1.0, 0.4, "-"),
    (0.4, 0.6, 0.7, 0.7, "-"),
    (-2.0, 1.5, 1.5, 0.55, "+"),
]


@pytest.mark.parametrize(("theta0", "x_e", "L", "rho", "branch"), CASES)
def test_solve_escape_is_optimal(theta0, x_e, L, rho, branch):
    sol = solve_escape(theta0, x_e, L=L, rho=rho, branch=branch)
    assert sol.success, sol.reason
    arc = sol.arc
    assert arc.x[-1] == x_e and abs(arc.y[-1]) < 1e-11
    assert sol.J == pytest.approx(arc.theta[-1] - theta0, abs=1e-14)
    assert arc.lambda2[-1] == pytest.approx(0.0, abs=1e-12)  # transversality (E3c)
    assert np.ptp(arc.H) <= 1e-6 * max(1.0, abs(arc.H[0]))
    s = 1 if branch == "+" else -1
    assert sol.k == pytest.approx(sol.lambda1 / (1 + s * sol.lambda2_0), rel=1e-12)
    # the returned multipliers reproduce the arc with the paper's algorithm
    again = shoot(
        theta0,
        sol.lambda1,
        sol.lambda2_0,
        L=L,
        rho=rho,
        branch=branch,
        x_max=x_e,
        method="pmp",
        step=x_e / 1000,
    )
    assert again.theta[-1] == pytest.approx(arc.theta[-1], abs=1e-6)
    assert again.y[-1] == pytest.approx(0.0, abs=1e-6)
    # optimality: no worse than an independent direct transcription ...
    direct = _direct_transcription(theta0, x_e, L, rho, branch)
    assert direct is not None
    assert abs(sol.J) <= direct + 1e-7
    assert direct - abs(sol.J) < 1e-3 * max(1.0, abs(sol.J))  # ... and close (gap ~1e-5)
    # ... and than the straight path and perturbations with the same end points
    xs = np.linspace(0.0, x_e, 801)
    straight = abs(_theta_along(np.zeros_like(xs), x_e, theta0, L, rho, branch))
    assert abs(sol.J) <= straight + 1e-9
    a_star = CubicSpline(arc.x, arc.alpha)(xs)
    same = abs(_theta_along(a_star, x_e, theta0, L, rho, branch))
    assert same == pytest.approx(abs(sol.J), abs=1e-6)
    for k, eps in ((1, 0.03), (2, -0.02), (3, 0.01)):  # y += eps sin(kπx/x_e)
        bump = eps * k * math.pi / x_e * np.cos(k * math.pi * xs / x_e)
        pert = np.arctan(np.tan(a_star) + bump)
        assert abs(_theta_along(pert, x_e, theta0, L, rho, branch)) > same + 1e-7


def test_solve_escape_failures_are_reported():
    sol = solve_escape(
        -1.4694468369271578,
        1.7090163413421233,
        L=1.1641292434617974,
        rho=0.8913647185839817,
        branch="-",
    )
    assert not sol.success and "no bounded extremal" in sol.reason and sol.arc is None
    triv = solve_escape(0.3, 1.0, L=1.0, rho=1.3)
    assert not triv.success and "trivially" in triv.reason


@pytest.mark.parametrize(
    ("call", "exc", "match"),
    [
        (lambda: solve_escape(0.0, 0.0, L=1.0, rho=0.5), SurveilValueError, "x_e = 0.0"),
        (lambda: solve_escape(math.nan, 1.0, L=1.0, rho=0.5), SurveilValueError, "theta0"),
        (lambda: solve_escape(0.0, 1.0, L=-1.0, rho=0.5), SurveilValueError, "L = -1.0"),
        (lambda: solve_escape(0.0, 1.0, L=1.0, rho=0.0), SurveilValueError, "rho = 0.0"),
        (lambda: solve_escape(0.0, 1.0, L=1.0, rho=0.5, branch=2), SurveilValueError, "branch"),
        (lambda: shoot(0.0, 1.0, -1.0, L=1.0, rho=0.5, x_max=1.0), SurveilValueError, "lambda2_0"),
        (lambda: shoot(0.0, 1.0, 0.0, L=1.0, rho=1.0, x_max=1.0), InfeasibleError, "rho = 1.0"),
        (
            lambda: shoot(0.0, 1.0, 0.0, L=1.0, rho=0.5, x_max=1.0, method="euler"),
            SurveilValueError,
            "method",
        ),
        (lambda: greedy_heading(0.0, L=1.0, rho=2.0), InfeasibleError, "rho = 2.0"),
    ],
)
def test_bad_input(call, exc, match):
    with pytest.raises(exc, match=match):
        call()


@pytest.mark.parametrize(
    ("theta0", "x_e", "L", "rho"),
    [
        (0.0, 1e4, 1.0, 0.5),
        (np.pi, 10.0, 1e-3, 0.5),
        (0.0, 10.0, 1.0, 1e-3),
        (0.0, 10.0, 1.0, 0.9999),
    ],
)
def test_solve_escape_refuses_runaway_integrations(theta0, x_e, L, rho):
    # x_e / default_step in the millions used to run for minutes; now a prompt, explained failure
    sol = solve_escape(theta0, x_e, L=L, rho=rho)
    assert not sol.success
    assert "RK4 steps" in sol.reason and repr(x_e) in sol.reason


def _reference_integrate(theta0, alpha0, s, L, rho, step, x_target, store, max_steps):
    """integrate_reduced as first written: classical RK4 steps composed of _rhs, the step
    that passes x_target redone from the same state with its length from three Newton
    passes."""
    from strategies.control._integrators import _HALF_PI, REACHED, TOO_LONG, _rhs

    q = 1.0 / (1.0 - rho * rho)

    def rk4(state, d):
        th, a = state[2], state[3]
        k1 = _rhs(th, a, s, L, rho, q)
        k2 = _rhs(th + 0.5 * d * k1[2], a + 0.5 * d * k1[3], s, L, rho, q)
        k3 = _rhs(th + 0.5 * d * k2[2], a + 0.5 * d * k2[3], s, L, rho, q)
        k4 = _rhs(th + d * k3[2], a + d * k3[3], s, L, rho, q)
        return tuple(
            v + d / 6.0 * (k1[i] + 2.0 * (k2[i] + k3[i]) + k4[i]) for i, v in enumerate(state)
        )

    state, sig = (0.0, 0.0, theta0, alpha0, 0.0), 0.0
    rows = [(sig, *state)]
    for _ in range(max_steps):
        new = rk4(state, step)
        if not abs(new[3]) < _HALF_PI:
            return rows, (1 if new[3] > 0 else -1)
        if new[0] >= x_target:
            d = step * (x_target - state[0]) / (new[0] - state[0])
            for _ in range(3):
                new = rk4(state, d)
                d += (x_target - new[0]) / math.cos(new[3])
            new = rk4(state, d)
            row = (sig + d, x_target, *new[1:])
            if store:
                rows.append(row)
            else:
                rows[0] = row
            return rows, REACHED
        state, sig = new, sig + step
        if store:
            rows.append((sig, *state))
        else:
            rows[0] = (sig, *state)
    return rows, TOO_LONG


def test_integrate_reduced_is_rk4_of_the_rhs_bit_for_bit():
    # integrate_reduced writes _rhs out inline at the four stages, in locals (the shooting's
    # inner loop): the same floats, bit for bit, as RK4 composed of _rhs; every outcome
    # (reached, turned back either way, out of steps), rows kept or not
    from strategies.control._integrators import integrate_reduced

    rng = np.random.default_rng(7)
    seen = set()
    for _ in range(400):
        th0, a0 = float(rng.uniform(-4.0, 4.0)), float(rng.uniform(-1.57, 1.57))
        L, rho = float(rng.uniform(0.5, 3.0)), float(rng.uniform(0.05, 0.95))
        step, x_t = float(rng.uniform(0.005, 0.2)), float(rng.uniform(0.05, 2.0))
        s, store = int(rng.choice([-1, 1])), bool(rng.integers(2))
        budget = (
            int(rng.integers(1, 40)) if rng.random() < 0.2 else math.ceil(10 * (x_t + L) / step)
        )
        args = (th0, a0, s, L, rho, step, x_t, store, budget)
        got = integrate_reduced(*args)
        assert repr(got) == repr(_reference_integrate(*args))  # (repr: -0.0 too)
        seen.add(got[1])
    assert seen == {-1, 0, 1, 2}


def test_integrate_reduced_end_is_integrate_reduced_without_ln_mu():
    # the coarse integrations (the shooting's bracketing grid and Brent) read y(x_e) and the
    # status only: integrate_reduced_end is integrate_reduced without ln μ, the same floats
    # in σ, x, y, θ and α, bit for bit, and the same status, every outcome
    from strategies.control._integrators import integrate_reduced, integrate_reduced_end

    rng = np.random.default_rng(86)
    seen = set()
    for _ in range(400):
        th0, a0 = float(rng.uniform(-4.0, 4.0)), float(rng.uniform(-1.57, 1.57))
        L, rho = float(rng.uniform(0.5, 3.0)), float(rng.uniform(0.05, 0.995))
        step, x_t = float(rng.uniform(0.002, 0.2)), float(rng.uniform(0.05, 3.0))
        s = int(rng.choice([-1, 1]))
        budget = (
            int(rng.integers(1, 40)) if rng.random() < 0.2 else math.ceil(10 * (x_t + L) / step)
        )
        rows, status = integrate_reduced(th0, a0, s, L, rho, step, x_t, False, budget)
        end, status_end = integrate_reduced_end(th0, a0, s, L, rho, step, x_t, budget)
        assert status_end == status
        assert repr(end[:5]) == repr(rows[-1][:5]) and math.isnan(end[5])
        seen.add(status)
    assert seen == {-1, 0, 1, 2}


@pytest.mark.parametrize("rho", [0.5, 0.99])
def test_the_coarse_integrations_carry_no_ln_mu(monkeypatch, rho):
    # issue 13: near rho = 1 the coarse integrations are nearly all of a failed solve; they
    # run integrate_reduced_end (no ln μ, ~13% cheaper), integrate_reduced only at the fine
    # step (the arc's rows and its μ), with the same arcs as before
    from strategies.control import evasion

    fine, coarse = [], []
    for name, runs in (("integrate_reduced", fine), ("integrate_reduced_end", coarse)):
        real = getattr(evasion, name)

        def counted(*args, real=real, runs=runs):
            runs.append(args[5])
            return real(*args)

        monkeypatch.setattr(evasion, name, counted)
    step = capped_step(2.0, 2.0, rho)
    for th in (0.0, -0.3, 2.8):
        escape_path(th, 2.0, L=2.0, rho=rho, branch="+", step=step)
    assert coarse and set(coarse) == {8.0 * step}
    assert fine and set(fine) == {step}


@pytest.mark.parametrize(
    ("theta0", "x_e", "L", "rho", "branch"),
    [
        (-4.283643770806559, 0.2999999999999998, 2.0, 0.5, "+"),  # office, the evader's
        (-5.756916611522011, 1.2000000000000002, 2.0, 0.5, "-"),  # corner
        (0.3, 1.0, 1.0, 1.3, "+"),  # rho > 1: no arc
        (0.0, 1e4, 1.0, 0.5, "+"),  # over the step budget: no arc
    ],
)
def test_escape_path_is_the_solutions_evader_path(theta0, x_e, L, rho, branch):
    sol = solve_escape(theta0, x_e, L=L, rho=rho, branch=branch)
    path = escape_path(theta0, x_e, L=L, rho=rho, branch=branch)
    if not sol.success:
        assert path is None
        return
    ref = sol.arc.evader_path()
    assert path.tobytes() == ref.tobytes() and path.flags.c_contiguous


def _counting(monkeypatch, key=lambda args: args[1]):
    """Every integration of the shooting, fine (``integrate_reduced``) or coarse
    (``integrate_reduced_end``), as ``key(args)``."""
    from strategies.control import evasion

    runs = []
    for name in ("integrate_reduced", "integrate_reduced_end"):
        real = getattr(evasion, name)

        def counted(*args, real=real):
            runs.append(key(args))
            return real(*args)

        monkeypatch.setattr(evasion, name, counted)
    return runs


def test_solve_escape_integrates_each_heading_once(monkeypatch):
    # Brent and the polish ask for some headings twice (a bracket's ends, the coarse root)
    # and the winner's rows were integrated again: each (heading, step) is integrated once

    runs = _counting(monkeypatch, lambda args: (args[1].hex(), args[5]))
    sol = solve_escape(-4.29821055010567, 0.9, L=2.0, rho=0.5, branch="+")
    assert sol.success and sol.candidates == 1
    assert len(runs) == len(set(runs)) == 18  # (it was 23: 18 coarse, 4 fine, 1 stored)


@pytest.mark.parametrize("rho", [1.0 - 1e-6, 1e-6])
def test_shoot_refuses_a_default_step_budget_it_cannot_keep(rho):
    # `surveil figure greedy --params '{"rho": 0.999999}'` ran for minutes, growing toward
    # ~100 GB (every RK4 node is kept; the default step scales with min(rho, 1 - rho))
    with pytest.raises(InfeasibleError, match=r"needs \S+e\+0[78] RK4 steps .* pass step="):
        shoot(math.pi, 0.0, 0.0, L=1.0, rho=rho, x_max=2.5)
    assert len(shoot(math.pi, 0.0, 0.0, L=1.0, rho=rho, x_max=2.5, step=0.05).x) > 1


@pytest.mark.parametrize("rho", [1.0, 1.5, 3.0])
def test_the_default_steps_refuse_rho_at_or_above_one(rho):
    # default_step(2, 1, rho) was 0.0 at rho = 1 (capped_step then divided by it:
    # ZeroDivisionError) and negative beyond (-0.00625 at 1.5): no extremal to step along
    from strategies.control.evasion import default_step

    for step in (default_step, capped_step):
        with pytest.raises(InfeasibleError, match=rf"rho = {rho}: optimal evasion .* 0 < rho < 1"):
            step(2.0, 1.0, rho)


@pytest.mark.parametrize(
    ("args", "name"),
    [((2.0, -1.0, 0.5), "L"), ((0.0, 1.0, 0.5), "x_max"), ((2.0, 1.0, 0.0), "rho"),
     ((2.0, 1.0, math.nan), "rho"), ((2.0, 0.0, 0.5), "L")],
)  # fmt: skip
def test_the_default_steps_refuse_a_bad_length_or_ratio(args, name):
    # L = -1 gave a negative step, x_max = 0 or rho = 0 a zero one (capped_step:
    # ZeroDivisionError), rho = NaN a NaN step
    from strategies.control.evasion import default_step

    want = rf"^{name} = \S+: expected a finite number > 0"
    for step in (default_step, capped_step):
        with pytest.raises(SurveilValueError, match=want):
            step(*args)
    assert default_step(2.0, 1.0, 0.5) == pytest.approx(1.0 * 0.5 / 1.5 / 32)


@pytest.mark.parametrize("method", ["reduced", "pmp"])
def test_shoot_refuses_a_step_beyond_the_horizon(method):
    # `surveil figure greedy --params '{"step": 1e12}'` drew an empty figure and exited 0:
    # one RK4 step of 1e12 leapt past x_max and came back as a one-node "unbounded" arc
    with pytest.raises(SurveilValueError, match=r"step = 1000000000000.0: expected at most x_max"):
        shoot(math.pi, 0.0, 0.0, L=1.0, rho=0.5, x_max=2.0, step=1e12, method=method)
    arc = shoot(math.pi, 0.0, 0.0, L=1.0, rho=0.5, x_max=2.0, step=2.0, method=method)
    assert arc.x[-1] == pytest.approx(2.0) and not arc.unbounded  # the horizon itself is fine


def test_solve_escape_refuses_a_step_beyond_the_escape_point():
    with pytest.raises(SurveilValueError, match=r"step = 5: expected at most x_e = 1"):
        solve_escape(math.pi, 1.0, L=1.0, rho=0.5, step=5)


def test_an_explicit_step_is_held_to_the_memory_budget():
    # step = 1e-9 to x_max = 2 is 2e9 kept RK4 nodes: the run grew without bound (killed
    # after 60 s) where the default step's budget refuses at once
    with pytest.raises(InfeasibleError, match=r"step = 1e-09 .* needs 2e\+09 RK4 steps"):
        shoot(math.pi, 0.0, 0.0, L=1.0, rho=0.5, x_max=2.0, step=1e-9)
    with pytest.raises(InfeasibleError, match=r"expected a step of at least 1e-06"):
        solve_escape(math.pi, 2.0, L=1.0, rho=0.5, step=1e-9)


def test_a_failed_escape_at_a_coarse_step_says_the_step_may_be_why():
    # at step 0.5 (above the natural length 1/3) no extremal was found, with the theory
    # blamed ("the arcs turn back"); the default step finds one
    assert solve_escape(math.pi, 2.0, L=1.0, rho=0.5).success
    sol = solve_escape(math.pi, 2.0, L=1.0, rho=0.5, step=0.5)
    assert not sol.success
    assert "the step 0.5 is too coarse" in sol.reason and "natural length 0.333" in sol.reason


def test_a_solve_without_an_arc_stops_brent_at_the_jump(monkeypatch):
    # near rho = 1 the sign changes of y(x_e) are jumps to turned-back arcs (THEORY §4.3);
    # Brent closed on each to 1e-13, 73 integrations to return None (issue 13)
    from strategies.control import evasion

    runs = _counting(monkeypatch)
    step = evasion.capped_step(2.0, 2.0, 0.99)
    assert escape_path(0.0, 2.0, L=2.0, rho=0.99, branch="+", step=step) is None
    assert len(runs) <= 40
    n = len(runs)
    monkeypatch.setattr(evasion, "_JUMP_WIDTH", 0.0)  # no certificate: Brent to the end
    assert escape_path(0.0, 2.0, L=2.0, rho=0.99, branch="+", step=step) is None
    assert len(runs) - n >= 70


def _assert_no_solve_changes(monkeypatch, name, off, *, seed, rhos, x_e, per,
                             modes=("capped", "default")):  # fmt: skip
    """Every solve of seeded random problems (theta0, x_e, rho, branch; the shooting
    evader's capped step, and the default step up to rho 0.95) gives the same arc bit for
    bit, or None, with ``evasion.<name>`` as it is and set to ``off``; and as it is, it
    spares integrations (it cut some, and both outcomes occur)."""
    from strategies.control import evasion

    runs = _counting(monkeypatch)
    rng = np.random.default_rng(seed)
    probs = [
        (rng.uniform(-math.pi, math.pi), rng.uniform(*x_e), rho, "+-"[rng.integers(2)], mode)
        for rho in rhos
        for mode in modes
        for _ in range(per)
        if mode == "capped" or rho <= 0.95
    ]
    steps = {"capped": lambda x_e, rho: capped_step(x_e, 2.0, rho), "default": lambda *_: None}
    counts, paths = [], []
    for value in (getattr(evasion, name), off):
        monkeypatch.setattr(evasion, name, value)
        del runs[:]
        paths.append(
            [
                escape_path(th, x_e, L=2.0, rho=rho, branch=b, step=steps[mode](x_e, rho))
                for th, x_e, rho, b, mode in probs
            ]
        )
        counts.append(len(runs))
    found = 0
    for new, old in zip(*paths, strict=True):
        assert (new is None) == (old is None)
        if new is not None:
            found += 1
            assert new.tobytes() == old.tobytes()
    assert 0 < found < len(probs) and counts[0] < counts[1]


def test_the_jump_certificate_changes_no_solve(monkeypatch):
    # the certificate stops only brackets that close on a jump: every solve (the shooting
    # evader's capped step, rho 0.9-0.99) gives the same arc bit for bit, or None as before
    _assert_no_solve_changes(
        monkeypatch,
        "_JUMP_WIDTH",
        0.0,
        seed=83,
        rhos=(0.9, 0.95, 0.97, 0.99),
        x_e=(0.3, 3.2),
        per=8,
        modes=("capped",),
    )


def test_a_failed_solve_bisects_the_jump(monkeypatch):
    # issue 13: Brent closes on a jump at about 1.5 evaluations a halving (next to a
    # turned-back arc's residual 10 its interpolations land by the reaching end); after
    # _PROBE_AFTER of them the bracket is bisected, one evaluation a halving: 38 -> 29
    # integrations for this failed solve (the grid's 9 included)
    from strategies.control import evasion

    runs = _counting(monkeypatch)
    step = capped_step(2.0, 2.0, 0.99)
    assert escape_path(0.0, 2.0, L=2.0, rho=0.99, branch="+", step=step) is None
    assert len(runs) <= 30
    n = len(runs)
    monkeypatch.setattr(evasion, "_PROBE_AFTER", 10**9)  # never bisected: Brent alone
    assert escape_path(0.0, 2.0, L=2.0, rho=0.99, branch="+", step=step) is None
    assert len(runs) - n >= 36


def test_the_bisection_changes_no_solve(monkeypatch):
    # the bisection stops only brackets that close on a jump; any other bracket goes back to
    # Brent from the start: every solve (the evader's capped step, rho 0.5-0.99, and the
    # default step up to 0.95) gives the same arc bit for bit, or None as before
    _assert_no_solve_changes(
        monkeypatch,
        "_PROBE_AFTER",
        10**9,
        seed=86,
        rhos=(0.5, 0.9, 0.95, 0.97, 0.99),
        x_e=(0.2, 3.6),
        per=6,
    )


def _fine_runs(monkeypatch):
    from strategies.control import evasion

    fine = []
    real = evasion.integrate_reduced

    def counted(*args):
        if args[7]:  # store: the fine grid's integrations (the coarse ones run
            fine.append(args[1])  # integrate_reduced_end)
        return real(*args)

    monkeypatch.setattr(evasion, "integrate_reduced", counted)
    return fine


@pytest.mark.parametrize(
    ("theta0", "x_e", "rho", "most"),
    [(-0.3, 0.7, 0.99, 1), (2.8, 1.2, 0.95, 3), (3.0, 3.1, 0.99, 5)],
)
def test_a_successful_solve_spends_few_fine_integrations(monkeypatch, theta0, x_e, rho, most):
    # near rho = 1 a successful solve's fine integrations (8 x the coarse steps, each row
    # kept) were ~10 of its ~18 ms (issue 13): the coarse root a_c was integrated fine,
    # then a_c -+ 1e-7 for the secant's slope, then the secant's roots. Now a_c is taken
    # where its fine residual already meets the root criterion (first case: 3 -> 1), and
    # the secant's second point is a Newton step on the coarse slope (4 -> 3, 6 -> 5)
    fine = _fine_runs(monkeypatch)
    step = capped_step(x_e, 2.0, rho)
    assert escape_path(theta0, x_e, L=2.0, rho=rho, branch="+", step=step) is not None
    assert len(fine) <= most


def test_a_successful_solve_returns_the_fine_grid_root_arc():
    # the arc escape_path returns is the fine grid's arc from the root of y(x_e) = 0 found
    # independently (brentq on the fine residual to 1e-15 next to the solution's heading),
    # to far below RK4's own error (>= 1e-9 here at a quarter of the step)
    from strategies.control._integrators import REACHED, integrate_reduced

    rng = np.random.default_rng(85)
    checked = 0
    for rho in (0.5, 0.9, 0.95, 0.99):
        for _ in range(6):
            th, x_e = rng.uniform(-math.pi, math.pi), rng.uniform(0.3, 3.2)
            b = "+-"[rng.integers(2)]
            h = capped_step(x_e, 2.0, rho)
            sol = solve_escape(th, x_e, L=2.0, rho=rho, branch=b, step=h)
            path = escape_path(th, x_e, L=2.0, rho=rho, branch=b, step=h)
            assert sol.success == (path is not None)
            if path is None:
                continue
            s = 1 if b == "+" else -1

            def arc(a0, th=th, x_e=x_e, rho=rho, s=s, h=h):
                rows, status = integrate_reduced(th, a0, s, 2.0, rho, h, x_e, True, 10**6)
                assert status == REACHED
                return np.asarray(rows)[:, 1:3]

            a, w = sol.alpha0, 1e-9
            while arc(a - w)[-1, 1] * arc(a + w)[-1, 1] > 0.0:
                w *= 10.0
            root = brentq(lambda a0: arc(a0)[-1, 1], a - w, a + w, xtol=1e-15, rtol=1e-15)
            ref = arc(root)
            assert path.shape == ref.shape
            assert np.max(np.abs(path - ref)) < 1e-12 * x_e
            checked += 1
    assert checked >= 12


def test_a_failed_solve_skips_the_steep_headings_proven_on_one_side(monkeypatch):
    # issue 13: the shooting evader's failed solve on the maze at rho 0.99 (decision_time.py):
    # the grid's headings 0.9 and 1.3 reach x_e high above the axis (arclength 7.8 and 19.8
    # for x_e = 4.8, a fifth of the solve), next to headings of the same sign, so no bracket
    # reads them; _slow_side proves their sign and they are no longer integrated
    from strategies.control import evasion

    runs = _counting(monkeypatch)
    th0, x_e = -0.0586, 4.8
    step = capped_step(x_e, 2.0, 0.99)
    assert escape_path(th0, x_e, L=2.0, rho=0.99, branch="+", step=step) is None
    assert 0.9 not in runs and 1.3 not in runs
    n = len(runs)
    assert escape_path(-th0, x_e, L=2.0, rho=0.99, branch="-", step=step) is None  # mirrored
    assert -0.9 not in runs[n:] and -1.3 not in runs[n:] and len(runs) == 2 * n
    monkeypatch.setattr(evasion, "_slow_side", lambda *args: 0)  # every heading integrated
    assert escape_path(th0, x_e, L=2.0, rho=0.99, branch="+", step=step) is None
    assert 0.9 in runs[2 * n :] and 1.3 in runs[2 * n :] and len(runs) == 3 * n + 2  # 27 -> 29


@pytest.mark.parametrize("seed", [0, 1])
def test_the_slow_side_is_the_coarse_residuals_sign(seed):
    # _slow_side's proof is of the ODE: the coarse RK4 arc from every heading it proves
    # (the capped and the default step, rho 0.3-0.995) ends on that side of the axis, or
    # turns back or runs long on it, as the shooting's residual reads it
    from strategies.control import evasion
    from strategies.control._integrators import REACHED, integrate_reduced_end

    rng = np.random.default_rng(seed)
    proven = 0
    for _ in range(150):
        rho = float(rng.choice([0.3, 0.7, 0.9, 0.95, 0.98, 0.99, 0.995]))
        L = float(rng.uniform(0.5, 4.0))
        x_e = float(rng.uniform(0.05, 4.0)) * L
        th0, s = float(rng.uniform(-2 * math.pi, 2 * math.pi)), int(rng.choice([1, -1]))
        for h in (capped_step(x_e, L, rho), evasion.default_step(x_e, L, rho)):
            if h is None or x_e / h > 4000:
                continue
            for a0 in evasion._ALPHA_GRID:
                side = evasion._slow_side(a0, th0, x_e, L, rho, s)
                if not side:
                    continue
                end, status = integrate_reduced_end(
                    th0, a0, s, L, rho, 8.0 * h, x_e, evasion._max_steps(x_e, L, 8.0 * h)
                )
                y = end[2] if status in (REACHED, 2) else status
                assert y * side > 0.0, (rho, L, x_e, th0, s, a0)
                proven += 1
    assert proven >= 100
    # (no proof where rho * rho underflows; the solve goes on as before)
    assert evasion._slow_side(1.3, 0.0, 1.0, 1.0, 1e-200, 1) == 0
    assert escape_path(0.5, 1.0, L=1.0, rho=1e-200, step=0.1) is None


def test_the_slow_side_changes_no_solve(monkeypatch):
    # headings proven on one side are integrated only next to a heading not proven on that
    # side, so every bracket is the same: every solve (the capped step, rho 0.5-0.995, and
    # the default step up to 0.95) gives the same arc bit for bit, or None as before
    _assert_no_solve_changes(
        monkeypatch,
        "_slow_side",
        lambda *args: 0,
        seed=91,
        rhos=(0.5, 0.9, 0.95, 0.97, 0.99, 0.995),
        x_e=(0.2, 3.6),
        per=6,
    )


def test_a_failed_solve_needs_no_jump_search_where_its_bracket_is_proven_root_free(
    monkeypatch,
):
    # issue 13: decision_time.py's failed solves at rho 0.99 (the maze, s = +1, and l_hall,
    # s = -1) have one grid bracket, an arc turning back next to one reaching x_e far off
    # the axis; Brent and the bisection spent 20 coarse integrations on it to find a jump.
    # _root_free proves no extremal from that bracket reaches (x_e, 0): 7 integrations, the
    # grid's (27 before)
    from strategies.control import evasion

    runs = _counting(monkeypatch)
    cases = [(-0.0586368977823013, 4.8, "+"), (-0.07374376093329116, 5.1, "-")]
    for th0, x_e, b in cases:
        step = capped_step(x_e, 2.0, 0.99)
        del runs[:]
        assert escape_path(th0, x_e, L=2.0, rho=0.99, branch=b, step=step) is None
        assert len(runs) == 7 and set(runs) <= set(evasion._ALPHA_GRID)
    monkeypatch.setattr(evasion, "_root_free", lambda *args: False)  # as before
    for th0, x_e, b in cases:
        del runs[:]
        step = capped_step(x_e, 2.0, 0.99)
        assert escape_path(th0, x_e, L=2.0, rho=0.99, branch=b, step=step) is None
        assert len(runs) == 27


@pytest.mark.parametrize("rho", [0.9, 0.99])
def test_the_phi_tables_bound_the_reduced_odes_arcs(rho):
    # _phi_tables against an independent integration (integrate_reduced in arclength, a
    # fine step): the arclength to phi = 0 and from phi = 0 to the turn back are at most
    # the tables' at the next table point (as _root_free takes them) and near the one
    # before, and the drop of y past the first negative heading is at most the table's
    from strategies.control import evasion
    from strategies.control._integrators import integrate_reduced

    L, tabs = 2.0, evasion._phi_tables(rho)
    checked = 0
    for th0, a0 in [(-0.06, 0.0), (-0.06, 0.01), (-0.2, 0.05), (-0.3, 0.2), (0.05, 0.1)]:
        h = evasion._natural_length(L, rho) / 256.0
        rows, status = integrate_reduced(th0, a0, 1, L, rho, h, 50.0, True, 10**7)
        r = np.asarray(rows)
        assert status == -1  # turned back downward
        sig, y, a = r[:, 0], r[:, 2], r[:, 4]
        phi = a - r[:, 3]
        k = int(np.argmax(phi <= 0.0))
        phi0 = a0 - th0
        if phi0 > 0.0:
            j = math.ceil(phi0 / tabs.slow_step)
            assert L * tabs.slow_len[j - 1] - h <= sig[k] <= L * tabs.slow_len[j] + h
        apk = a[k]
        i = math.ceil(apk / tabs.alpha_step)
        post = sig[-1] - sig[k]
        assert 0.98 * L * tabs.post_len[max(i - 1, 0)] <= post <= L * tabs.post_len[i] + 2 * h
        z = k + int(np.argmax(a[k:] < 0.0))
        assert y[z] - y[z:].min() <= L * tabs.post_drop[i]
        checked += 1
    assert checked == 5


@pytest.mark.parametrize("seed", [0, 1])
def test_a_root_free_bracket_holds_no_coarse_root(seed):
    # _root_free's proof is of the ODE: in every grid bracket it proves root-free (random
    # problems, rho 0.8-0.995, the capped and the default step), coarse RK4 arcs from 60
    # headings each turn back or reach x_e off the axis by more than _JUMP_RESIDUAL, so the
    # shooting would have found no root there
    from strategies.control import evasion
    from strategies.control._integrators import REACHED, integrate_reduced_end

    rng = np.random.default_rng(seed)
    proven = 0
    for _ in range(200):
        rho = float(rng.choice([0.8, 0.9, 0.95, 0.98, 0.99, 0.995]))
        L = float(rng.choice([0.5, 2.0, 4.0]))
        x_e = float(rng.uniform(0.15, 4.0)) * L
        th0, s = float(rng.uniform(-math.pi, math.pi)), int(rng.choice([1, -1]))
        h = capped_step(x_e, L, rho)
        if h is not None and rng.random() < 0.2 and x_e / evasion.default_step(x_e, L, rho) < 4000:
            h = evasion.default_step(x_e, L, rho)
        if h is None:
            continue
        coarse = 8.0 * h
        n = evasion._max_steps(x_e, L, coarse)
        for a_lo, a_hi in zip(evasion._ALPHA_GRID, evasion._ALPHA_GRID[1:], strict=False):
            if not evasion._root_free(a_lo, a_hi, th0, x_e, L, rho, s):
                continue
            proven += 1
            for a0 in np.linspace(a_lo, a_hi, 60):
                end, status = integrate_reduced_end(th0, float(a0), s, L, rho, coarse, x_e, n)
                if status == REACHED:
                    assert s * end[2] / x_e > evasion._JUMP_RESIDUAL, (rho, L, x_e, th0, s, a0)
    assert proven >= 10


def test_root_free_brackets_change_no_solve(monkeypatch):
    # a bracket proven root-free is not polished: every solve (the capped step, rho
    # 0.9-0.995, and the default step up to 0.95) gives the same arc bit for bit, or None
    # as before, with fewer integrations
    _assert_no_solve_changes(
        monkeypatch,
        "_root_free",
        lambda *args: False,
        seed=95,
        rhos=(0.9, 0.95, 0.97, 0.99, 0.995),
        x_e=(0.3, 5.5),
        per=8,
    )


def test_no_root_free_proof_where_the_arcs_need_not_turn_back():
    # at rho 0.5 an arc from phi = 0 need not turn back by phi = -pi (no proof), and near
    # rho = 1 the tables would need too many steps (none is built)
    from strategies.control import evasion

    assert not evasion._root_free(0.0, 0.45, -0.06, 4.0, 2.0, 0.5, 1)
    assert evasion._phi_tables(1.0 - 1e-12) is None
    assert not evasion._root_free(0.0, 0.45, -0.06, 4.0, 2.0, 1.0 - 1e-12, 1)
    assert not evasion._root_free(0.0, 0.45, -0.06, 4.0, 2.0, 1e-320, 1)
