"""Sec. 6.2 model: Hamiltonian, adjoints (both branches), minimiser of H, THEORY §4.3."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from envs.errors import InfeasibleError, SurveilValueError
from strategies.control.hamiltonian import (
    adjoint_lambda2,
    df2_dtheta,
    dH_dalpha,
    f2,
    hamiltonian,
    is_unbounded,
    kappa_bounds,
    minimise_hamiltonian,
    stationary_kappa,
)
from strategies.control.kinematics import theta_dot

rhos = st.floats(0.05, 0.95)
thetas = st.floats(-4.0, 4.0)
branches = st.sampled_from(["+", "-"])


def test_fig11a_hamiltonian_reference():
    # THEORY §4.2 fact 3: θ0 = π, λ1 = -1, λ2 = 0.41, L = 1, rho = 0.5 -> H = 2.416242.
    m = minimise_hamiltonian(math.pi, -1.0, 0.41, L=1.0, rho=0.5)
    assert not m.unbounded and not m.fallback
    h = hamiltonian(m.alpha, math.pi, -1.0, 0.41, L=1.0, rho=0.5)
    assert h == pytest.approx(2.416242, abs=5e-7)


@settings(max_examples=40, deadline=None)
@given(alpha=st.floats(-1.4, 1.4), theta=thetas, rho=rhos, L=st.floats(0.3, 3.0), branch=branches)
def test_f2_is_theta_dot_over_x_dot(alpha, theta, rho, L, branch):
    tp, tm = theta_dot(alpha, theta, L=L, v_p=1.0, rho=rho)
    expected = (tp if branch == "+" else tm) / (rho * math.cos(alpha))
    assert f2(alpha, theta, L=L, rho=rho, branch=branch) == pytest.approx(expected, rel=1e-12)


@settings(max_examples=40, deadline=None)
@given(
    alpha=st.floats(-1.4, 1.4),
    theta=thetas,
    rho=rhos,
    l1=st.floats(-3, 3),
    l2=st.floats(-0.9, 3),
    branch=branches,
)
def test_adjoint_and_partials_match_finite_differences(alpha, theta, rho, l1, l2, branch):
    kw = {"L": 1.3, "rho": rho, "branch": branch}
    eps = 1e-6
    fd_th = (f2(alpha, theta + eps, **kw) - f2(alpha, theta - eps, **kw)) / (2 * eps)
    assert df2_dtheta(alpha, theta, **kw) == pytest.approx(fd_th, rel=1e-6, abs=1e-6)
    dH_th = (
        hamiltonian(alpha, theta + eps, l1, l2, **kw)
        - hamiltonian(alpha, theta - eps, l1, l2, **kw)
    ) / (2 * eps)
    assert adjoint_lambda2(alpha, theta, l2, **kw) == pytest.approx(-dH_th, rel=1e-6, abs=1e-6)
    dH_a = (
        hamiltonian(alpha + eps, theta, l1, l2, **kw)
        - hamiltonian(alpha - eps, theta, l1, l2, **kw)
    ) / (2 * eps)
    assert dH_dalpha(alpha, theta, l1, l2, **kw) == pytest.approx(dH_a, rel=1e-5, abs=1e-5)


@settings(max_examples=30, deadline=None)
@given(theta=thetas, rho=rhos, branch=branches)
def test_stationary_kappa_is_strictly_decreasing(theta, rho, branch):
    a = np.linspace(-1.5707, 1.5707, 2001)
    k = stationary_kappa(a, theta, L=0.8, rho=rho, branch=branch)
    assert np.all(np.diff(k) < 0)
    lo, hi = kappa_bounds(theta, L=0.8, rho=rho, branch=branch)
    assert lo == pytest.approx(k[-1], abs=1e-3) and hi == pytest.approx(k[0], abs=1e-3)


@settings(max_examples=60, deadline=None)
@given(theta=thetas, rho=rhos, l1=st.floats(-3, 3), l2=st.floats(-0.9, 3), branch=branches)
def test_minimiser_matches_dense_grid(theta, rho, l1, l2, branch):
    kw = {"L": 1.0, "rho": rho, "branch": branch}
    m = minimise_hamiltonian(theta, l1, l2, **kw)
    # the bounded case has its minimum inside; the unbounded one dives at an end
    grid = np.linspace(-1.5707963, 1.5707963, 20001)
    h = hamiltonian(grid, theta, l1, l2, **kw)
    if m.unbounded:
        assert is_unbounded(theta, l1, l2, **kw)
        # non-strict: at mu = 0 and lambda1 = 0, H is identically 0 (hypothesis found it),
        # the limiting case that is_unbounded counts as unbounded by convention
        assert min(h[0], h[-1]) <= h[1:-1].min() + 1e-12
    else:
        h_star = hamiltonian(m.alpha, theta, l1, l2, **kw)
        assert h_star <= h.min() + 1e-9
        assert dH_dalpha(m.alpha, theta, l1, l2, **kw) == pytest.approx(0.0, abs=1e-6)


def test_unbounded_when_mu_not_positive_and_mirror_symmetry():
    assert is_unbounded(0.3, 0.2, -1.0, L=1.0, rho=0.5)  # μ = 0
    assert is_unbounded(0.3, 0.2, 1.0, L=1.0, rho=0.5, branch="-")  # μ = 1 - λ2 = 0
    a, th = np.linspace(-1.4, 1.4, 9), 0.7
    np.testing.assert_allclose(
        f2(a, th, L=1.0, rho=0.4, branch="-"), -f2(-a, -th, L=1.0, rho=0.4, branch="+"), rtol=1e-13
    )


def test_bad_input():
    with pytest.raises(InfeasibleError, match=r"rho = 1\.0"):
        f2(0.1, 0.2, L=1.0, rho=1.0)
    with pytest.raises(SurveilValueError, match="rho = 0"):
        f2(0.1, 0.2, L=1.0, rho=0)
    with pytest.raises(SurveilValueError, match="branch = 'x'"):
        f2(0.1, 0.2, L=1.0, rho=0.5, branch="x")
    with pytest.raises(SurveilValueError, match="lambda1"):
        minimise_hamiltonian(0.0, math.nan, 0.0, L=1.0, rho=0.5)
