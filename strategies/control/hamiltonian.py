"""Sec. 6.2: state equations in x, the Hamiltonian, both adjoints, and its minimiser over α.

The evader starts at the origin and must reach ``(x_e, 0)``; ``x`` is the independent
variable, the control is the heading ``α ∈ (-π/2, π/2)`` and the state is ``(y, θ)``:

    dy/dx = f1 = tan α
    dθ/dx = f2 = θ̇ˢ / (V_e cos α) = s n_s(φ) / (L rho cos α),  φ = α - θ,
    n_s(φ) = sqrt(1 - rho² cos² φ) - s rho sin φ >= 0,

where ``s = +1`` is the paper's θ̇⁺ branch (the pursuer turns the rod counter-clockwise)
and ``s = -1`` the θ̇⁻ branch. The evader minimises the rotation *magnitude*
``s (θ(x_e) - θ0) = ∫ s f2 dx``. With λ1, λ2 the adjoints of y and θ:

    H = s f2 + λ1 f1 + λ2 f2 = λ1 tan α + (s + λ2) f2 = λ1 tan α + μ g_s,
    μ = 1 + s λ2,   g_s = s f2 = n_s / (L rho cos α) >= 0.

For ``s = +1`` this is the paper's Hamiltonian (correct as printed, THEORY §4.2). The
adjoints are ``λ1' = 0`` and ``λ2' = -(s + λ2) ∂f2/∂θ`` with
``∂f2/∂θ = cos φ / (L cos α) (1 - s rho sin φ / sqrt(...))``: the printed adjoint for
``s = +1``, the bracket ``(1 + rho sin φ / sqrt(...))`` for θ̇⁻ (E3b).

Minimising H over α (the paper's step 3). ``∂H/∂α = 0`` is ``λ1 / μ = K_s(α, θ)`` with

    K_s(α, θ) = -cos²α ∂g_s/∂α = n_s(φ) (s rho cos φ cos α / h - sin α) / (L rho),
    ∂K_s/∂α = -n_s(φ) cos α (h + s rho sin φ) / (L rho h³) < 0     (rho < 1),

``h = sqrt(1 - rho² cos² φ)`` (derived here and checked with sympy; not in the paper).
So for ``μ > 0`` the stationarity condition has at most one root and H is unimodal in α:
the minimiser is unique when it exists, and a bracketed Newton iteration finds it safely.
It exists iff ``K_s(π/2, θ) < λ1/μ < K_s(-π/2, θ)``; otherwise H is unbounded below at
``α -> ±π/2`` (THEORY §4.3) and :func:`minimise_hamiltonian` reports ``unbounded``.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from scipy.optimize import minimize_scalar

from envs import validation
from strategies.control._validate import branch_sign, check_evasion_rho

__all__ = [
    "HamiltonianMinimum",
    "adjoint_lambda2",
    "dH_dalpha",
    "df2_dtheta",
    "f1",
    "f2",
    "hamiltonian",
    "is_unbounded",
    "kappa_bounds",
    "minimise_hamiltonian",
    "stationary_kappa",
]

_HALF_PI = 0.5 * math.pi


def _out(a: np.ndarray) -> float | np.ndarray:
    return float(a) if a.ndim == 0 else a


def _common(alpha, theta, L, rho, branch):
    a = validation.finite_array("alpha", alpha)
    t = validation.finite_array("theta", theta)
    return a, t, validation.positive("L", L), check_evasion_rho(rho), branch_sign(branch)


def _n_h(phi: np.ndarray, rho: float, s: int) -> tuple[np.ndarray, np.ndarray]:
    h = np.sqrt(1.0 - (rho * np.cos(phi)) ** 2)
    return h - s * rho * np.sin(phi), h


def f1(alpha):
    """``dy/dx = tan α``."""
    return _out(np.tan(validation.finite_array("alpha", alpha)))


def f2(alpha, theta, *, L: float, rho: float, branch="+"):
    """``dθ/dx = θ̇ˢ / (V_e cos α)`` (correct as printed for θ̇⁺; depends on L and rho only)."""
    a, t, L, rho, s = _common(alpha, theta, L, rho, branch)
    n, _ = _n_h(a - t, rho, s)
    return _out(s * n / (L * rho * np.cos(a)))


def df2_dtheta(alpha, theta, *, L: float, rho: float, branch="+"):
    """``∂f2/∂θ = cos φ / (L cos α) (1 - s rho sin φ / sqrt(1 - rho² cos² φ))`` (E3b)."""
    a, t, L, rho, s = _common(alpha, theta, L, rho, branch)
    phi = a - t
    n, h = _n_h(phi, rho, s)
    return _out(np.cos(phi) * n / (h * L * np.cos(a)))


def hamiltonian(alpha, theta, lambda1, lambda2, *, L: float, rho: float, branch="+"):
    """``H = λ1 tan α + (s + λ2) f2`` (for ``s = +1`` the paper's H)."""
    a, t, L, rho, s = _common(alpha, theta, L, rho, branch)
    l1 = validation.finite_array("lambda1", lambda1)
    l2 = validation.finite_array("lambda2", lambda2)
    n, _ = _n_h(a - t, rho, s)
    return _out(l1 * np.tan(a) + (s + l2) * s * n / (L * rho * np.cos(a)))


def dH_dalpha(alpha, theta, lambda1, lambda2, *, L: float, rho: float, branch="+"):
    """``∂H/∂α = (λ1 - μ K_s(α, θ)) / cos² α`` with ``μ = 1 + s λ2`` (THEORY §4.2)."""
    a = validation.finite_array("alpha", alpha)
    mu = 1.0 + branch_sign(branch) * validation.finite_array("lambda2", lambda2)
    k = np.asarray(stationary_kappa(a, theta, L=L, rho=rho, branch=branch))
    return _out((validation.finite_array("lambda1", lambda1) - mu * k) / np.cos(a) ** 2)


def adjoint_lambda2(alpha, theta, lambda2, *, L: float, rho: float, branch="+"):
    """``λ2' = -∂H/∂θ = -(s + λ2) ∂f2/∂θ`` (printed adjoint for θ̇⁺, E3b)."""
    s = branch_sign(branch)
    l2 = validation.finite_array("lambda2", lambda2)
    return _out(-(s + l2) * np.asarray(df2_dtheta(alpha, theta, L=L, rho=rho, branch=branch)))


def stationary_kappa(alpha, theta, *, L: float, rho: float, branch="+"):
    """``K_s(α, θ)``: the ratio ``λ1/μ`` at which α minimises H (strictly decreasing in α)."""
    a, t, L, rho, s = _common(alpha, theta, L, rho, branch)
    phi = a - t
    n, h = _n_h(phi, rho, s)
    return _out(n * (s * rho * np.cos(phi) * np.cos(a) / h - np.sin(a)) / (L * rho))


def kappa_bounds(theta, *, L: float, rho: float, branch="+"):
    """``(K_s(π/2, θ), K_s(-π/2, θ))``: H has a minimiser iff ``λ1/μ`` lies strictly inside."""
    t = validation.finite_array("theta", theta)
    L = validation.positive("L", L)
    rho = check_evasion_rho(rho)
    s = branch_sign(branch)
    n_up, _ = _n_h(_HALF_PI - t, rho, s)
    n_dn, _ = _n_h(-_HALF_PI - t, rho, s)
    return _out(-n_up / (L * rho)), _out(n_dn / (L * rho))


def is_unbounded(theta, lambda1, lambda2, *, L: float, rho: float, branch="+") -> bool:
    """THEORY §4.3: H -> -∞ at an end of (-π/2, π/2).

    That happens when ``μ <= 0`` or when ``λ1 L rho sin α + μ n_s(α - θ) < 0`` at
    ``α = +π/2`` or ``α = -π/2`` (the numerator of ``H cos α``; ``= 0`` counts as unbounded:
    the infimum is then approached at the boundary, not attained).
    """
    t = validation.real("theta", theta)
    l1 = validation.real("lambda1", lambda1)
    L = validation.positive("L", L)
    rho = check_evasion_rho(rho)
    s = branch_sign(branch)
    mu = 1.0 + s * validation.real("lambda2", lambda2)
    if mu <= 0.0:
        return True
    for sa in (1.0, -1.0):
        n, _ = _n_h(np.asarray(sa * _HALF_PI - t), rho, s)
        if l1 * L * rho * sa + mu * float(n) <= 0.0:
            return True
    return False


class HamiltonianMinimum(NamedTuple):
    """Result of :func:`minimise_hamiltonian`."""

    alpha: float
    """The minimiser; NaN when ``unbounded``."""
    unbounded: bool
    """True when H has no minimum on (-π/2, π/2) (THEORY §4.3)."""
    iterations: int
    """Newton/bisection iterations used."""
    fallback: bool
    """True when the bounded scalar minimiser had to be used."""


def _kappa_scalar(a: float, t: float, L: float, rho: float, s: int) -> tuple[float, float]:
    """``K_s(α, θ)`` and ``∂K_s/∂α`` in scalar math (hot path)."""
    phi = a - t
    c, sp = math.cos(phi), math.sin(phi)
    ca, sa = math.cos(a), math.sin(a)
    h = math.sqrt(1.0 - rho * rho * c * c)
    n = h - s * rho * sp
    k = n * (s * rho * c * ca / h - sa) / (L * rho)
    dk = -n * ca * (h + s * rho * sp) / (L * rho * h * h * h)
    return k, dk


def solve_stationary(
    kappa: float,
    theta: float,
    L: float,
    rho: float,
    s: int,
    alpha_guess: float = 0.0,
    tol: float = 1e-14,
    max_iter: int = 60,
) -> tuple[float, int]:
    """Root of ``K_s(α, θ) = kappa`` on (-π/2, π/2): Newton safeguarded by bisection.

    Assumes ``kappa`` lies strictly inside :func:`kappa_bounds` (the caller checks); since
    ``K_s`` is strictly decreasing the bracket ``[-π/2, π/2]`` always holds the root.
    Returns ``(alpha, iterations)``; ``iterations == max_iter`` means no convergence.
    """
    lo, hi = -_HALF_PI, _HALF_PI  # K - kappa > 0 at lo, < 0 at hi
    a = min(max(alpha_guess, lo + 1e-12), hi - 1e-12)
    for it in range(1, max_iter + 1):
        k, dk = _kappa_scalar(a, theta, L, rho, s)
        r = k - kappa
        if r > 0.0:
            lo = a
        else:
            hi = a
        step = r / dk if dk < 0.0 else 0.0
        a_new = a - step
        if not (lo < a_new < hi) or dk >= 0.0:
            a_new = 0.5 * (lo + hi)
        if abs(a_new - a) <= tol * (1.0 + abs(a)) or hi - lo <= tol:
            return a_new, it
        a = a_new
    return a, max_iter


def minimise_hamiltonian(
    theta: float,
    lambda1: float,
    lambda2: float,
    *,
    L: float,
    rho: float,
    branch="+",
    alpha_guess: float | None = None,
) -> HamiltonianMinimum:
    """``argmin_α H(θ, α)`` over (-π/2, π/2) (Fig. 10, step 3).

    Newton on the stationarity condition ``λ1/μ = K_s(α, θ)`` of THEORY §4.2, safeguarded
    by bisection on ``[-π/2, π/2]`` (``K_s`` is strictly decreasing, so the root is unique);
    if that ever fails to converge, a bounded scalar minimisation of H is the fallback.

    Args:
        theta: rod orientation θ.
        lambda1: adjoint of y (constant).
        lambda2: adjoint of θ at this x.
        L: surveillance distance, > 0.
        rho: speed ratio, 0 < rho < 1.
        branch: ``"+"`` (θ̇⁺) or ``"-"`` (θ̇⁻).
        alpha_guess: Newton start (e.g. the previous step's α); default 0.
    """
    t = validation.real("theta", theta)
    l1 = validation.real("lambda1", lambda1)
    l2 = validation.real("lambda2", lambda2)
    L = validation.positive("L", L)
    rho = check_evasion_rho(rho)
    s = branch_sign(branch)
    mu = 1.0 + s * l2
    if is_unbounded(t, l1, l2, L=L, rho=rho, branch=s):
        return HamiltonianMinimum(math.nan, True, 0, False)
    guess = 0.0 if alpha_guess is None else validation.real("alpha_guess", alpha_guess)
    a, it = solve_stationary(l1 / mu, t, L, rho, s, guess)
    if it < 60:
        return HamiltonianMinimum(a, False, it, False)

    def h_of(al: float) -> float:  # pragma: no cover - fallback, not reached in tests
        return l1 * math.tan(al) + mu * float(_n_h(np.asarray(al - t), rho, s)[0]) / (
            L * rho * math.cos(al)
        )

    res = minimize_scalar(
        h_of, bounds=(-_HALF_PI + 1e-9, _HALF_PI - 1e-9), method="bounded", options={"xatol": 1e-12}
    )
    return HamiltonianMinimum(float(res.x), False, it, True)  # pragma: no cover
