"""Optimal escape trajectories (paper Sec. 6.2, Figs. 10-12): shooting on the PMP extremals.

The model (state equations, H, adjoints, minimiser of H) is in
:mod:`strategies.control.hamiltonian`; read its docstring first. Two integrators:

* ``method="pmp"`` is the paper's algorithm of Fig. 10 with RK4 instead of Euler
  (THEORY §4.3): state ``(y, θ, λ2)``, and at every RK4 stage α is the minimiser of H,
  found by safeguarded Newton on the stationarity condition. It is the reference.
* ``method="reduced"`` (default, much faster) integrates the heading itself, in the
  evader's arclength σ so that headings near ±π/2 are harmless. Along an extremal
  ``κ = λ1/μ = K_s(α, θ)`` and ``κ' = κ ∂f2/∂θ`` (from ``μ' = -μ ∂f2/∂θ``);
  differentiating, the terms in κ cancel (derived here, checked with sympy; not in the
  paper) and

      dα/dx = n_s(φ)² sin φ / ((1 - rho²) L cos α),     φ = α - θ,

  an explicit ODE for the state ``(x, y, θ, α, ln μ)``. Because ``K_s`` is strictly
  decreasing in α, α(0) and the ratio ``λ1/μ(0)`` determine each other one to one, so
  the shooting runs directly on α(0) ∈ (-π/2, π/2).

An arc is *unbounded* (THEORY §4.3) when H has no minimiser at some x, which on the
reduced ODE shows as α reaching ±π/2 (the evader would have to turn back in x).

Scale invariance (THEORY §4.2, fact 1): ``(λ1, 1 + s λ2(0)) -> c (λ1, 1 + s λ2(0))``,
``c > 0``, gives the same trajectory; only ``k = λ1 / (1 + s λ2(0))`` matters.
:func:`solve_escape` reports multipliers normalised by transversality ``λ2(x_e) = 0``
(the paper never imposes it, E3c).

Greedy mode (Fig. 12, λ1 = 0): ``∂H/∂α = 0`` reduces to ``sin α = s rho cos(α - θ)``, so
``α* = atan2(s rho cos θ, 1 - s rho sin θ)``; at θ = π this is ``-arctan rho`` and at θ = 0
``+arctan rho`` with ``f2 = (1 - rho²)/(L rho)`` (THEORY §4.2 fact 4, §7).
"""

from __future__ import annotations

import functools
import itertools
import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from scipy.optimize import brentq

from envs import validation
from envs.errors import InfeasibleError, SurveilValueError
from strategies.control._integrators import (
    REACHED,
    first_return,
    integrate_pmp,
    integrate_reduced,
    integrate_reduced_end,
)
from strategies.control._validate import branch_sign, check_evasion_rho
from strategies.control.hamiltonian import _kappa_scalar, is_unbounded, solve_stationary

__all__ = [
    "EscapeSolution",
    "GreedyHeading",
    "ShootResult",
    "capped_step",
    "default_step",
    "escape_path",
    "greedy_heading",
    "shoot",
    "solve_escape",
]

_HALF_PI = 0.5 * math.pi
_STEPS_PER_SCALE = 32
"""Default RK4 steps per natural length of the extremal ODE (see :func:`default_step`)."""


def default_step(x_max: float, L: float, rho: float) -> float:
    """Default RK4 step (arclength for ``"reduced"``, x for ``"pmp"``).

    Per unit arclength θ turns at up to ``(1 + rho)/(L rho)`` and α at up to
    ``(1 + rho)²/((1 - rho²) L)``, so the natural length is ``L min(rho, 1 - rho)/(1 + rho)``;
    32 steps per natural length keep J and the crossing within ~1e-8 of a 4x finer grid on
    the cases in the tests.

    Raises:
        SurveilValueError: ``x_max`` or ``L`` not a finite number > 0, or ``rho`` not one
            (InvalidConfigError).
        InfeasibleError: ``rho >= 1``: there is no extremal to integrate (the natural
            length is 0 at rho = 1 and negative beyond, and so was the step).
    """
    x_max, L, rho = _step_inputs(x_max, L, rho)
    return min(_natural_length(L, rho) / _STEPS_PER_SCALE, x_max / 32.0)


def _step_inputs(x_max: object, L: object, rho: object) -> tuple[float, float, float]:
    """``(x_max, L, rho)`` of :func:`default_step` and :func:`capped_step`, checked: a
    step for rho >= 1 came back 0 (rho = 1; :func:`capped_step` divided by it) or
    negative, and one for ``L <= 0`` negative."""
    x_max = validation.positive("x_max", x_max)
    L = validation.positive("L", L)
    return x_max, L, check_evasion_rho(rho)


def capped_step(x_max: float, L: float, rho: float) -> float | None:
    """:func:`default_step` with at most ``32² = 1024`` steps to ``x_max`` where that is
    coarser, but never coarser than a quarter of the natural length (the trust limit:
    past a natural length RK4 is not to be trusted, see :func:`solve_escape`); ``None``
    where the default step would need more than the 50,000 steps :func:`solve_escape`
    attempts (it refuses those: rho within ~1e-2 of 1, or ``x_max`` thousands of ``L``).

    32 steps per natural length, counting a natural length as at least 1/32 of the arc:
    the natural length ``L min(rho, 1 - rho)/(1 + rho)`` shrinks to 0 as rho -> 1 (the
    heading's fast scale), and the default step with it (~16,000 steps to 2 L at
    rho = 0.99). Where ``x_max`` is at most 32 natural lengths it is the default step:
    below rho ~ 0.8 always, as ``x_max`` stays within a few ``L``.

    Raises:
        SurveilValueError, InfeasibleError: as :func:`default_step` (rho >= 1 among them).
    """
    x_max, L, rho = _step_inputs(x_max, L, rho)
    h = default_step(x_max, L, rho)
    if x_max / h > _MAX_DEFAULT_STEPS:
        return None
    scale = _STEPS_PER_SCALE * _STEPS_PER_SCALE
    return max(h, min(0.25 * _natural_length(L, rho), x_max / scale))


def _natural_length(L: float, rho: float) -> float:
    """The extremal ODE's natural length ``L min(rho, 1 - rho)/(1 + rho)`` (see
    :func:`default_step`): over one, θ or α can turn by about a radian."""
    return L * min(rho, 1.0 - rho) / (1.0 + rho)


@dataclass(frozen=True)
class ShootResult:
    """One extremal from :func:`shoot`, sampled at the RK4 nodes (evader frame).

    The evader starts at the origin heading for the positive x-axis; ``theta`` is the rod
    orientation (evader -> pursuer). Arrays share one length (shorter when ``unbounded``).
    """

    x: np.ndarray
    y: np.ndarray
    theta: np.ndarray
    alpha: np.ndarray
    lambda2: np.ndarray
    """Adjoint of θ (``μ = 1 + s λ2``)."""
    H: np.ndarray
    """Hamiltonian at each node; constant along an exact extremal."""
    x_c: float | None
    """First return to y = 0 after leaving it (Fig. 10, step 7), or None."""
    J: float | None
    """``θ(x_c) - θ0`` (signed: >= 0 for branch '+', <= 0 for '-'), or None."""
    unbounded: bool
    """H lost its minimiser (THEORY §4.3) before ``x_max``; arrays stop there."""
    theta0: float
    lambda1: float
    lambda2_0: float
    L: float
    rho: float
    branch: int = 1
    arclength: np.ndarray | None = None
    """Evader path length at each node (integration variable of ``"reduced"``)."""

    def evader_path(self) -> np.ndarray:
        """Evader positions, shape (N, 2)."""
        return np.column_stack([self.x, self.y])

    def pursuer_path(self) -> np.ndarray:
        """Pursuer positions ``E + L (cos θ, sin θ)`` (eq. 1), shape (N, 2)."""
        return self.evader_path() + self.L * np.column_stack(
            [np.cos(self.theta), np.sin(self.theta)]
        )


@dataclass(frozen=True)
class EscapeSolution:
    """Result of :func:`solve_escape`."""

    success: bool
    reason: str
    """Empty on success, otherwise why no extremal reaches ``(x_e, 0)``."""
    J: float | None = None
    """``θ(x_e) - θ0`` on the optimal arc (signed like ``ShootResult.J``)."""
    k: float | None = None
    """``λ1 / (1 + s λ2(0))``, the one shooting unknown (THEORY §4.2 fact 1)."""
    lambda1: float | None = None
    """λ1 normalised so that ``λ2(x_e) = 0`` (transversality, E3c)."""
    lambda2_0: float | None = None
    """λ2(0) with the same normalisation."""
    alpha0: float | None = None
    """Initial heading."""
    arc: ShootResult | None = None
    """The extremal on ``[0, x_e]``."""
    candidates: int = 0
    """Number of extremals through ``(x_e, 0)`` found (the one with least ``|J|`` is kept)."""


# ------------------------------------------------------------------------------- shoot


def _build_result(
    rows, status, theta0, lambda1, lambda2_0, s, L, rho, reduced: bool, stop_at_crossing: bool
) -> ShootResult:
    """Assemble a :class:`ShootResult` from integrator rows (see ``_integrators``)."""
    if reduced:
        arr = np.asarray(rows, dtype=float).reshape(-1, 6)
        sig, x, y, th, a, lm = arr.T
        mu = (1.0 + s * lambda2_0) * np.exp(lm)
        lam2 = s * (mu - 1.0)
    else:
        arr = np.asarray(rows, dtype=float).reshape(-1, 5)
        x, y, th, a, lam2 = arr.T
        sig = None
        mu = 1.0 + s * lam2
    phi = a - th
    n = np.sqrt(1.0 - (rho * np.cos(phi)) ** 2) - s * rho * np.sin(phi)
    ca = np.cos(a)
    H = lambda1 * np.tan(a) + mu * n / (L * rho * ca)
    xc = J = None
    if len(x) > 1:
        if reduced:
            t, dx, dy, dth = sig, ca, np.sin(a), s * n / (L * rho)
        else:
            t, dx, dy, dth = x, np.ones_like(x), np.tan(a), s * n / (L * rho * ca)
        tol = 1e-11 * max(float(np.max(np.abs(x))), L)
        xc, thc = first_return(t, x, y, th, dx, dy, dth, tol)
        J = None if thc is None else thc - theta0
    if stop_at_crossing and xc is not None:
        last = int(np.searchsorted(x, xc)) + 1
        x, y, th, a, lam2, H = (v[:last] for v in (x, y, th, a, lam2, H))
        sig = None if sig is None else sig[:last]
    return ShootResult(
        x=x,
        y=y,
        theta=th,
        alpha=a,
        lambda2=lam2,
        H=H,
        x_c=xc,
        J=J,
        unbounded=status in (1, -1),
        theta0=theta0,
        lambda1=lambda1,
        lambda2_0=lambda2_0,
        L=L,
        rho=rho,
        branch=s,
        arclength=sig,
    )


def shoot(
    theta0: float,
    lambda1: float,
    lambda2_0: float,
    *,
    L: float,
    rho: float,
    branch="+",
    x_max: float,
    step: float | None = None,
    method: str = "reduced",
    stop_at_crossing: bool = False,
) -> ShootResult:
    """Integrate one extremal from the origin (Fig. 10 without the outer λ loop).

    Args:
        theta0: initial rod orientation θ(0).
        lambda1: adjoint of y (constant, ``K`` in the paper).
        lambda2_0: adjoint of θ at x = 0; ``μ0 = 1 + s lambda2_0`` must be > 0.
        L: surveillance distance ``L_min``, > 0.
        rho: speed ratio, 0 < rho < 1 (InfeasibleError for rho >= 1).
        branch: ``"+"`` (θ̇⁺, the paper's figures) or ``"-"`` (θ̇⁻).
        x_max: integrate until ``x = x_max``.
        step: RK4 step, arclength for ``"reduced"`` and x for ``"pmp"``
            (default :func:`default_step`).
        method: ``"reduced"`` (explicit heading ODE) or ``"pmp"`` (argmin of H per stage).
        stop_at_crossing: truncate the arrays after the first return to y = 0.

    Returns:
        A :class:`ShootResult`; ``unbounded`` is set (and the arrays stop) where H lost its
        minimiser (THEORY §4.3), e.g. Fig. 11(b)'s multipliers at rho = 0.9.

    Raises:
        SurveilValueError: non-finite input, ``L <= 0``, ``x_max <= 0``, ``step <= 0`` or
            ``step > x_max``, ``1 + s lambda2_0 <= 0`` (μ keeps its sign along the arc,
            so transversality ``λ2(x_e) = 0`` would be impossible), unknown branch or
            method.
        InfeasibleError: ``rho >= 1``, or more than ``_MAX_SHOOT_STEPS`` steps up to
            ``x_max`` (by default: rho within ~1e-4 of 0 or 1, or ``x_max`` ~1e5 ``L``).
    """
    th0 = validation.real("theta0", theta0)
    l1 = validation.real("lambda1", lambda1)
    l20 = validation.real("lambda2_0", lambda2_0)
    L = validation.positive("L", L)
    rho = check_evasion_rho(rho)
    s = branch_sign(branch)
    x_max = validation.positive("x_max", x_max)
    if step is not None:
        h = _explicit_step(step, x_max, "x_max")
    else:
        h = default_step(x_max, L, rho)
        if x_max / h > _MAX_SHOOT_STEPS:
            raise InfeasibleError(
                f"x_max = {x_max!r} with L = {L!r}, rho = {rho!r} needs {x_max / h:.3g} RK4 "
                f"steps of the default step {h:.3g} (budget {_MAX_SHOOT_STEPS:,}: about 1 GB "
                f"and 30 s); pass step= (at least {x_max / _MAX_SHOOT_STEPS:.3g}, coarser than "
                "the default) to integrate anyway"
            )
    if method not in ("reduced", "pmp"):
        raise SurveilValueError(f"method = {method!r}: expected 'reduced' or 'pmp'")
    mu0 = 1.0 + s * l20
    if mu0 <= 0.0:
        raise SurveilValueError(
            f"lambda2_0 = {lambda2_0!r} gives 1 + s*lambda2_0 = {mu0!r} for branch "
            f"{'+' if s > 0 else '-'}: expected > 0 (μ keeps its sign along the arc and "
            "transversality needs μ(x_e) = 1, E3c)"
        )
    if method == "pmp":
        n = max(1, math.ceil(x_max / h))
        rows, unb = integrate_pmp(th0, l1, l20, s, L, rho, x_max / n, n)
        if not rows:
            rows = [(0.0, 0.0, th0, math.nan, l20)]
        return _build_result(
            rows, 1 if unb else 0, th0, l1, l20, s, L, rho, False, stop_at_crossing
        )
    if is_unbounded(th0, l1, l20, L=L, rho=rho, branch=s):
        return _build_result(
            [(0.0, 0.0, 0.0, th0, math.nan, 0.0)],
            1,
            th0,
            l1,
            l20,
            s,
            L,
            rho,
            True,
            stop_at_crossing,
        )
    a0, _ = solve_stationary(l1 / mu0, th0, L, rho, s, 0.0)
    rows, status = integrate_reduced(th0, a0, s, L, rho, h, x_max, True, _max_steps(x_max, L, h))
    return _build_result(rows, status, th0, l1, l20, s, L, rho, True, stop_at_crossing)


_MAX_SHOOT_STEPS = 2_000_000
"""Largest ``x_max / h`` :func:`shoot` integrates with the default step: each step is kept
(rho = 0.9999, x_max = 2.5, L = 1: 1.6 million, 24 s, 0.9 GB; rho = 0.999999 asked for 100
times that)."""


def _explicit_step(step: object, horizon: float, horizon_name: str) -> float:
    """A step the caller chose: finite, > 0, at most the horizon (a longer RK4 step leaps
    past it at once: at ``step = 1e12`` the figure was one node, an "unbounded" arc), and
    at most :data:`_MAX_SHOOT_STEPS` of them to the horizon (every node is kept: at
    ``step = 1e-9`` the integration grew toward a terabyte).

    Raises:
        SurveilValueError: not a finite number > 0, or above the horizon.
        InfeasibleError: so small that the horizon needs more than the budget of steps.
    """
    h = validation.positive("step", step)
    if h > horizon:
        raise SurveilValueError(
            f"step = {step!r}: expected at most {horizon_name} = {horizon!r} (one RK4 step "
            "longer than the horizon leaps past it)"
        )
    if horizon / h > _MAX_SHOOT_STEPS:
        raise InfeasibleError(
            f"step = {step!r} with {horizon_name} = {horizon!r} needs {horizon / h:.3g} RK4 "
            f"steps (budget {_MAX_SHOOT_STEPS:,}: about 1 GB and 30 s); expected a step of "
            f"at least {horizon / _MAX_SHOOT_STEPS:.3g}"
        )
    return h


def _max_steps(x_max: float, L: float, h: float) -> int:
    """Arclength budget: 10 (x_max + L); longer arcs creep toward α = ±π/2."""
    return math.ceil(10.0 * (x_max + L) / h)


# ------------------------------------------------------------------------- solve_escape

_MAX_DEFAULT_STEPS = 50_000
"""Largest ``x_e / h`` :func:`solve_escape` attempts with the default step: beyond it (``x_e``
thousands of times ``L``, or rho within ~1e-2 of 0 or 1) one solve takes seconds to minutes."""

_ALPHA_GRID = (-1.5707, -1.3, -0.9, -0.45, 0.0, 0.45, 0.9, 1.3, 1.5707)
"""Initial headings probed for sign changes of y(x_e) before Brent refines them."""


def solve_escape(
    theta0: float, x_e: float, *, L: float, rho: float, branch="+", step: float | None = None
) -> EscapeSolution:
    """The extremal from the origin to ``(x_e, 0)`` with least rotation ``|θ(x_e) - θ0|``.

    Solves ``y(x_e) = 0`` for the single shooting unknown (THEORY §4.2 fact 1), run on the
    initial heading α(0) (one to one with ``k = λ1/(1 + s λ2(0))`` because ``K_s`` is
    strictly decreasing): a fixed grid of α(0) brackets the sign changes,
    ``scipy.optimize.brentq`` refines each, and the extremal with the least ``|J|`` wins.

    Unlike the paper's step 8, an extremal may touch y = 0 before ``x_e``; ``arc.x_c``
    reports the first return.

    Args:
        theta0: initial rod orientation in the evader frame (target on the +x axis).
        x_e: distance to the escape point, > 0.
        L: surveillance distance ``L_min``, > 0.
        rho: speed ratio ``V_e / V_p``, > 0.
        branch: ``"+"`` if the pursuer turns the rod counter-clockwise, ``"-"`` clockwise.
        step: RK4 arclength step (default :func:`default_step`).

    Returns:
        An :class:`EscapeSolution`; ``success`` is False with a ``reason`` when no bounded
        extremal reaches ``(x_e, 0)``, when ``rho >= 1`` (trivial escape, footnote 4), or
        when the default step would need more than 50,000 RK4 steps to reach ``x_e``
        (pass an explicit ``step`` to force the integration).

    Raises:
        SurveilValueError: non-finite input, ``x_e <= 0``, ``L <= 0``, ``rho <= 0``,
            ``step <= 0`` or ``step > x_e``.
        InfeasibleError: an explicit ``step`` so small that ``x_e`` needs more than
            ``_MAX_SHOOT_STEPS`` of them.
    """
    args, reason = _escape_inputs(theta0, x_e, L, rho, branch, step)
    if reason:
        return EscapeSolution(success=False, reason=reason)
    th0, x_e, L, rho_v, s, h = args
    roots, best = _shoot_escape(*args)
    if best is None:
        coarse = ""
        if step is not None and h > _natural_length(L, rho_v):
            coarse = (
                f"; or the step {h:g} is too coarse: it exceeds the extremals' natural length "
                f"{_natural_length(L, rho_v):.3g}, where RK4 is not to be trusted (the "
                f"default step is {default_step(x_e, L, rho_v):.3g})"
            )
        return EscapeSolution(
            success=False,
            reason=f"no bounded extremal from theta0 = {th0!r} reaches (x_e, 0) = "
            f"({x_e!r}, 0) with L = {L!r}, rho = {rho_v!r}, branch "
            f"{'+' if s > 0 else '-'} (the arcs turn back before x_e, THEORY §4.3){coarse}",
        )
    a0, J, rows = best
    mu0 = math.exp(-rows[-1][5])  # transversality: μ(x_e) = 1, i.e. λ2(x_e) = 0 (E3c)
    k = _kappa_scalar(a0, th0, L, rho_v, s)[0]
    lambda1 = k * mu0
    lambda2_0 = s * (mu0 - 1.0)
    arc = _build_result(rows, REACHED, th0, lambda1, lambda2_0, s, L, rho_v, True, False)
    return EscapeSolution(
        success=True,
        reason="",
        J=float(J),
        k=float(k),
        lambda1=float(lambda1),
        lambda2_0=float(lambda2_0),
        alpha0=float(a0),
        arc=arc,
        candidates=len(roots),
    )


def escape_path(
    theta0: float, x_e: float, *, L: float, rho: float, branch="+", step: float | None = None
) -> np.ndarray | None:
    """``solve_escape(...).arc.evader_path()``, or None where it fails, without the rest of
    the solution (multipliers, H, first return: the shooting evader follows the path only).

    Same arguments and errors as :func:`solve_escape`.
    """
    args, reason = _escape_inputs(theta0, x_e, L, rho, branch, step)
    if reason:
        return None
    best = _shoot_escape(*args)[1]
    if best is None:
        return None
    arr = np.asarray(best[2], dtype=float).reshape(-1, 6)  # as _build_result reads the rows
    return np.column_stack([arr[:, 1], arr[:, 2]])


def _escape_inputs(theta0, x_e, L, rho, branch, step):
    """Validated ``(theta0, x_e, L, rho, s, h)`` of :func:`solve_escape`, and why it does
    not shoot ("" if it does)."""
    th0 = validation.real("theta0", theta0)
    x_e = validation.positive("x_e", x_e)
    L = validation.positive("L", L)
    rho_v = validation.positive("rho", rho)
    s = branch_sign(branch)
    if rho_v >= 1.0:
        return None, (
            f"rho = {rho_v!r} >= 1: the evader escapes trivially by moving away "
            "from the pursuer (footnote 4); at rho = 1, θ̇⁺ can vanish (E1)"
        )
    h = default_step(x_e, L, rho_v) if step is None else _explicit_step(step, x_e, "x_e")
    if step is None and x_e / h > _MAX_DEFAULT_STEPS:
        return None, (
            f"x_e = {x_e!r} with L = {L!r}, rho = {rho_v!r} needs {x_e / h:.3g} RK4 "
            f"steps of the default step {h:.3g} (budget {_MAX_DEFAULT_STEPS}); pass step= "
            "to integrate anyway"
        )
    return (th0, x_e, L, rho_v, s, h), ""


def _shoot_escape(th0: float, x_e: float, L: float, rho: float, s: int, h: float):
    """The roots of ``y(x_e) = 0`` in α(0) (step ``h``) and the least-|J| extremal among
    them as ``(alpha0, J, rows)`` (None if no root reaches ``x_e``)."""
    coarse = 8.0 * h  # bracket and first root on an 8x coarser grid, then polish
    # Brent and the polish evaluate some headings twice (a bracket's ends, the coarse
    # root), and the winner is integrated once more with its rows: each integration is
    # run once, by its exact inputs (the sign of a zero heading too), the fine ones with
    # their rows
    done: dict[tuple[float, float, float], tuple[float, list, int]] = {}

    def residual(a0: float, hh: float = h) -> float:
        key = (a0, math.copysign(1.0, a0), hh)
        if key in done:
            return done[key][0]
        n = _max_steps(x_e, L, hh)
        if hh == h:
            rows, status = integrate_reduced(th0, a0, s, L, rho, hh, x_e, True, n)
            end = rows[-1]
        else:  # the coarse arcs: y(x_e) and the status only (the same floats, without ln μ)
            rows = []
            end, status = integrate_reduced_end(th0, a0, s, L, rho, hh, x_e, n)
        if status != REACHED:  # turned back going up (+1) / down (-1), or wandered (2)
            r = 10.0 * (status if status != 2 else math.copysign(1.0, end[2]))
        else:
            r = end[2] / x_e
        done[key] = (r, rows, status)
        return r

    def turned(a0: float) -> bool:  # the coarse arc from a0 (evaluated) did not reach x_e
        return done[(a0, math.copysign(1.0, a0), coarse)][2] != REACHED

    # the coarse grid; a heading whose arc provably ends on one side of the axis
    # (_slow_side) is integrated only where a neighbour is not known to end on that side:
    # a pair of one sign is never polished, so the brackets are the same
    side = [_slow_side(a, th0, x_e, L, rho, s) for a in _ALPHA_GRID]
    r_grid = [0.0 if side[i] else residual(a, coarse) for i, a in enumerate(_ALPHA_GRID)]
    last = len(_ALPHA_GRID) - 1
    for i, a in enumerate(_ALPHA_GRID):
        if side[i]:
            near = [side[j] or r_grid[j] for j in (i - 1, i + 1) if 0 <= j <= last]
            if all(v * side[i] > 0.0 for v in near):
                r_grid[i] = float(side[i])  # (its sign is all the pairs read)
            else:
                r_grid[i] = residual(a, coarse)
    grid = list(zip(_ALPHA_GRID, r_grid, strict=True))
    roots = []
    # a bracket whose headings provably have no root (_root_free) is not polished: near
    # rho = 1 these are the failed solves' jumps, ~20 coarse integrations each
    for (a_lo, r_lo), (a_hi, r_hi) in itertools.pairwise(grid):
        if r_lo == 0.0 or (r_lo * r_hi < 0.0 and not _root_free(a_lo, a_hi, th0, x_e, L, rho, s)):
            root = _polished_root(residual, a_lo, a_hi, coarse, turned)
            if root is not None:
                roots.append(root)
    best = None
    for a0 in roots:
        residual(a0)  # (every root was evaluated on the fine grid: a lookup)
        _, rows, status = done[(a0, math.copysign(1.0, a0), h)]
        J = rows[-1][3] - th0
        if status == REACHED and (best is None or abs(J) < abs(best[1])):
            best = (a0, J, rows)
    return roots, best


def _slow_side(a0: float, th0: float, x_e: float, L: float, rho: float, s: int) -> int:
    """``s`` if the extremal from heading ``a0`` provably reaches ``x_e`` above the axis
    (``s`` = +1) or below it (-1), else 0 (no proof): the sign of its residual.

    Mirrored by ``s`` (α, θ and y change sign with the branch), take s = +1 and
    ``φ = α - θ``. Along every extremal φ decreases: ``dφ/dσ = (n/L)(n sin φ q - 1/ρ)``
    with ``n sin φ <= (1 - ρ²)/(2ρ)``, so ``dφ/dσ <= -n/(2Lρ) < 0``. Where φ lies in
    (0, π), α rises (``dα/dσ = n² sin φ q/L``) and the rod turns slowly:
    ``n = (1 - ρ²)/(√(1 - ρ² cos² φ) + ρ sin φ) <= (1 - ρ²)/(2ρ sin φ)``, so
    ``dθ/dσ <= (1 - ρ²)/(2Lρ² sin φ)``, ``dα/dσ <= (1 - ρ²)/(4Lρ² sin φ)``, and as
    ``|dφ/dσ| <= dθ/dσ``, ``cos φ`` grows by at most ``(1 - ρ²)/(2Lρ²)`` per unit
    arclength. Over an arclength σ that keeps ``cos φ < 1``, φ stays in (0, φ0] and α in
    ``[α0, α_max]``; if ``α0 > 0``, ``α_max < π/2`` and ``σ cos α_max >= x_e``, the arc
    reaches ``x_e`` within σ with ``y >= x_e tan α0 > 0``.

    Near rho = 1 these are the grid's steep headings on the side where the rod turns
    slowly, its longest coarse integrations (arclength up to 4 ``x_e``; issue 13). The
    proof is of the ODE, the residual that of the coarse RK4 arc; there the heading
    changes by at most ``(1 - ρ²)/(4Lρ² sin φ)`` a unit of arclength, which RK4 follows
    closely, and an arc turning back upward has the same sign. Measured: every one of
    24,273 proven headings of 28,300 random problems (rho 0.3-0.995, L 0.5-4, ``x_e``
    to 4 L, θ0 in (-2π, 2π), the capped and the default step) had the proven sign.
    """
    a, t = s * a0, s * th0
    if not a > 0.0:
        return 0
    phi = math.remainder(a - t, 2.0 * math.pi)
    if not 0.0 < phi < math.pi:
        return 0
    scale = 2.0 * L * rho * rho
    if not scale > 0.0:  # (rho ~1e-160 with an explicit step: no proof)
        return 0
    k_cos = (1.0 - rho * rho) / scale
    k_alpha = 0.5 * k_cos
    c0, s0 = math.cos(phi), math.sin(phi)
    sig = x_e / math.cos(a)
    for _ in range(32):
        c1 = c0 + k_cos * sig
        if c1 >= 1.0:
            return 0
        s_min = min(math.sqrt(1.0 - c1 * c1), s0)
        a_max = a + k_alpha * sig / s_min
        if a_max >= _HALF_PI:
            return 0
        need = x_e / math.cos(a_max)
        if need <= sig:
            return s
        sig = need * 1.001
    return 0


class _PhiTables(NamedTuple):
    """The reduced ODE with φ as the variable (s = +1, L = 1; see :func:`_root_free`)."""

    slow_step: float
    slow_len: np.ndarray
    """Arclength from φ = k ``slow_step`` down to φ = 0 (k = 0, 1, ...)."""
    alpha_step: float
    post_len: np.ndarray
    """Arclength from φ = 0 with heading k ``alpha_step`` until the heading is -π/2 (inf if
    it is not by φ = -π)."""
    post_drop: np.ndarray
    """The most that y falls, past the first negative heading, on the arcs from φ = 0 with
    heading 0 ... k ``alpha_step`` (a running maximum)."""


_PHI_STEPS_PER_C = 32
"""Steps of the φ tables per ``sqrt(1 - ρ²)``, the width in φ of the slow passage at φ = 0."""
_MAX_PHI_STEPS = 20_000


@functools.lru_cache(maxsize=16)
def _phi_tables(rho: float) -> _PhiTables | None:
    """:class:`_PhiTables` for ``rho`` (None where it would need more than
    :data:`_MAX_PHI_STEPS` steps: rho within ~1e-5 of 1). RK4 in φ on ``(σ, α, x, y)``, with
    ``dσ/dφ = 1/F``, ``dα/dφ = G/F``, ``dx/dφ = cos α/F``, ``dy/dφ = sin α/F`` (the
    notation of :func:`_root_free`); σ and α are plain quadratures (Simpson's rule)."""
    c = math.sqrt(1.0 - rho * rho)
    steps = math.ceil(_PHI_STEPS_PER_C * math.pi / c)
    if not c > 0.0 or steps > _MAX_PHI_STEPS:
        return None
    q = 1.0 / (1.0 - rho * rho)

    def fg(phi):
        co, sp = np.cos(phi), np.sin(phi)
        n = np.sqrt(1.0 - rho * rho * co * co) - rho * sp
        f = n * (n * sp * q - 1.0 / rho)  # dφ/dσ < 0
        return 1.0 / f, n * n * sp * q / f

    d = math.pi / steps
    # the slow side: φ from 0 up to π (σ only)
    k = np.arange(steps + 1) * d
    inv, _ = fg(k)
    inv_m, _ = fg(k[:-1] + 0.5 * d)
    slow = np.concatenate(([0.0], np.cumsum(-(d / 6.0) * (inv[:-1] + 4.0 * inv_m + inv[1:]))))
    # the fast side: φ from 0 down to -π, heading 0 at φ = 0
    phis = -k
    inv, g = fg(phis)
    inv_m, g_m = fg(phis[:-1] - 0.5 * d)
    h = -d  # the step in φ
    sig = np.concatenate(([0.0], np.cumsum((h / 6.0) * (inv[:-1] + 4.0 * inv_m + inv[1:]))))
    alp = np.concatenate(([0.0], np.cumsum((h / 6.0) * (g[:-1] + 4.0 * g_m + g[1:]))))
    a_m = np.empty(steps)  # α at the midpoints: Simpson on the half interval (a cubic fit)
    a_m[:] = alp[:-1] + (h / 24.0) * (5.0 * g[:-1] + 8.0 * g_m - g[1:])
    cx = (h / 6.0) * (
        np.cos(alp[:-1]) * inv[:-1] + 4.0 * np.cos(a_m) * inv_m + np.cos(alp[1:]) * inv[1:]
    )
    cy = (h / 6.0) * (
        np.sin(alp[:-1]) * inv[:-1] + 4.0 * np.sin(a_m) * inv_m + np.sin(alp[1:]) * inv[1:]
    )
    x = np.concatenate(([0.0], np.cumsum(cx)))
    y = np.concatenate(([0.0], np.cumsum(cy)))
    a_step = 0.01
    heads = np.arange(0.0, _HALF_PI + a_step, a_step)
    post_len = np.full(heads.size, math.inf)
    drop = np.full(heads.size, math.inf)
    for i, a in enumerate(heads):
        head = a + alp
        end = np.flatnonzero(head <= -_HALF_PI)
        neg = np.flatnonzero(head < 0.0)
        if end.size == 0:
            break
        t, z = end[0], neg[0]
        post_len[i] = sig[t]
        yr = math.sin(a) * x[z : t + 1] + math.cos(a) * y[z : t + 1]
        drop[i] = yr[0] - yr.min()
    return _PhiTables(d, slow, a_step, post_len, np.maximum.accumulate(drop))


def _root_free(
    a_lo: float, a_hi: float, th0: float, x_e: float, L: float, rho: float, s: int
) -> bool:
    """Whether no extremal from a heading in ``[a_lo, a_hi]`` reaches ``(x_e, 0)`` (a proof of
    the ODE; the grid bracket between them need not be polished).

    Mirrored by ``s``, take s = +1, ``φ = α - θ`` and ``q = 1/(1 - ρ²)``. The reduced ODE's
    rates depend on φ alone (module docstring; :func:`_slow_side`): ``dφ/dσ = F(φ) =
    (n/L)(n sin φ q - 1/ρ) < 0`` and ``dα/dσ = G(φ) = n² sin φ q/L``. So α - α0 and the arc
    (turned by α0) are functions of φ: every extremal is a turned piece of one curve per ρ
    (L scales it), tabulated once (:func:`_phi_tables`). For a heading ``a0 >= 0``:

    * φ0 in (0, π): α rises (by at most φ0: ``|dα/dφ| <= 1`` as ``n sin φ <= (1 - ρ²)/(2ρ)``)
      until φ = 0 (unless it turns back upward first: no root), after an arclength
      ``slow(φ0)``, increasing in φ0; there the arc is at
      ``(x0, y0)`` with ``y0 >= x0 tan a0``, heading ``α_pk`` in ``[a0, a0 + φ0]``.
    * From φ = 0 on (or from φ0 <= 0: a tail of it, ``α_pk <= a0 + |φ0|`` as
      ``0 <= dα/dφ < 1`` there) the arc is the tabulated one turned by ``α_pk``: it turns
      back (α = -π/2) within an arclength ``P(α_pk)``, and past its first negative heading
      y falls by at most ``D(α_pk)`` (both tabulated; ``α_pk <= a_cap``).

    So a root needs ``x0 >= x_e - P`` and ``y0 <= D``, hence ``tan a0 <= D/(x_e - P)``
    (``a0 <= a_min``), and then ``x0 <= slow(a_min - θ0)``: if ``slow(a_min - θ0) + P < x_e``
    there is none (and with φ0 <= 0 the whole arc is shorter than ``P < x_e``).

    Near rho = 1 most failed solves are a bracket between an arc that turns back and one
    that reaches ``x_e`` off the axis: a jump, ~20 coarse integrations of Brent and
    :func:`_bisected_jump` to find no root (issue 13). The proof is of the ODE, the
    residual that of the coarse RK4 arc (near rho = 1 its step is ~2 natural lengths, so it
    follows the turn back only roughly). Measured: in each of 1,144 brackets it proved
    root-free (random problems, rho 0.8-0.995, L 0.5-4, ``x_e`` to 4 L, the capped and the
    default step), coarse arcs from 200 headings turned back or reached ``x_e`` off the
    axis by 3.4 % of ``x_e`` or more, on the bracket's side; 3,785 solves (random and the
    shooting evader's recorded ones) gave the same arcs bit for bit, and the same failures.
    """
    lo, hi = sorted((s * a_lo, s * a_hi))
    t = math.remainder(s * th0, 2.0 * math.pi)
    if not (lo >= 0.0 and -math.pi < lo - t and hi - t < math.pi):
        return False
    tabs = _phi_tables(rho)
    if tabs is None:
        return False
    a_cap = hi + max(abs(hi - t), abs(lo - t))
    i = math.ceil(a_cap / tabs.alpha_step)
    if i >= tabs.post_len.size:
        return False
    p = L * float(tabs.post_len[i])
    if not p < x_e:
        return False
    a_min = math.atan(L * float(tabs.post_drop[i]) / (x_e - p))
    phi = min(a_min, hi) - t
    if phi <= 0.0:
        return True
    j = math.ceil(phi / tabs.slow_step)
    return j < tabs.slow_len.size and L * float(tabs.slow_len[j]) + p < x_e


_JUMP_WIDTH = 1e-6
"""Width in α(0) below which a coarse bracket between a turned-back arc and one that
reaches ``x_e`` off the axis (by :data:`_JUMP_RESIDUAL`) is taken for a jump (see
:func:`_polished_root`). Measured: in 1,650 random solves at rho 0.9-0.99 (L = 2, x_e
0.3-3.2, the shooting evader's capped step) no bracket that Brent closed on a root had a
turned-back end once it was narrower than 4e-4 (the least of 1,119 such brackets), 400
times this width; all 245 jumps were stopped. On broader problems (L 0.5-4, x_e to 4 L,
rho 0.5-0.995, 1,598 solves) one such bracket came to 2.4e-6 (rho 0.8, x_e 3.2 L: the root
next to the jump), its reaching end's residual 0.0018 there and 0.0008 at 1.2e-6, below
:data:`_JUMP_RESIDUAL`: that is what kept it from being taken for a jump."""

_JUMP_RESIDUAL = 1e-3
"""Least ``|y(x_e)|/x_e`` of the reaching end for :data:`_JUMP_WIDTH`'s certificate: 1,000
times the residual :func:`_polished_root` accepts as a root (1e-6); at a jump the reaching
arcs end at the turned-back arc's vertical tangent, off the axis (in the same solves
0.0035 or more, median 0.39)."""


class _Jump(Exception):
    """The coarse bracket of :func:`_polished_root` has closed on a jump, not a root."""


class _Probe(Exception):
    """Brent's coarse bracket still has a turned-back end after :data:`_PROBE_AFTER`
    evaluations (args: its ends as ``(α(0), residual)``): bisect it for a jump."""


_PROBE_AFTER = 4
"""Brent evaluations after which a coarse bracket that still has a turned-back end (and a
reaching one off the axis by :data:`_JUMP_RESIDUAL`) is bisected for a jump (see
:func:`_polished_root`). A bracket that closes on a root and is bisected costs the
midpoints up to the first on the other side of the axis, then Brent's own evaluations as
before. Measured on the shooting evader's solves of ``decision_time.py --rho 0.95 / 0.99``
(corridor, l_hall): failed solves 36.5 -> 28.9 integrations at 4 (28.0 at 0, 30.3 at 8),
successful ones 19.1 -> 19.5 (22.7 at 0 and 2); every arc the same, bit for bit."""


def _polished_root(residual, a_lo: float, a_hi: float, coarse: float, turned) -> float | None:
    """Root of ``residual`` (fine step) in ``[a_lo, a_hi]``: Brent on the coarse grid, then
    secant steps on the fine one (the two roots differ by the coarse truncation error);
    Brent on the fine grid if the secant misbehaves. None for a jump, not a root.

    The fine integrations (8 times the coarse steps, every row kept) were most of a
    successful solve near rho = 1 (issue 13). The coarse root is the answer where its
    fine residual already meets the secant's criterion (1e-14: the arc is the same to
    that tolerance; common where the arc is nearly straight, RK4 then being exact to
    rounding at both steps), and the secant's second point is a Newton step on the
    coarse grid's slope at the coarse root (one coarse integration) instead of a fine
    integration 1e-7 away, which only gave the slope.

    Near rho = 1 most sign changes are jumps (THEORY §4.3): from an arc that reaches ``x_e``
    off the axis to one that turns back first, where the reaching arcs end at a vertical
    tangent. Brent closes on such a jump to 1e-13, ~60 coarse integrations for nothing.
    ``turned(a)`` (whether the coarse arc from ``a`` turned back) lets Brent stop there:
    once its bracket (tracked from its evaluations: each lies inside the last bracket and
    replaces the end of its sign) is narrower than :data:`_JUMP_WIDTH` between a turned
    arc and a reaching one off the axis by :data:`_JUMP_RESIDUAL`, it is a jump. Brent's
    evaluations up to there are the same, so a bracket that closes on a root (none does
    this narrow beside a turned arc, see :data:`_JUMP_WIDTH`) gives the same root.

    Brent closes on a jump slowly: next to a turned arc's residual (10) the reaching end's
    (~0.2-0.5) makes its interpolations land beside the reaching end, and it halves the
    bracket only every ~1.5 evaluations (~25 to reach :data:`_JUMP_WIDTH` from a grid
    bracket). So once Brent has spent :data:`_PROBE_AFTER` evaluations and its bracket
    still has a turned end, :func:`_bisected_jump` bisects that bracket: one evaluation a
    halving, each midpoint turning back as the turned end did or reaching on the reaching
    end's side of the axis, to :data:`_JUMP_WIDTH` (the same certificate). Any other
    midpoint (an arc reaching the other side: a root lies between) ends the bisection and
    Brent runs again from the start, its evaluations so far cached, to the same root. The
    two agree wherever the bracket holds one sign change (the jump); a bracket with a pair
    of roots besides, on the reaching side, could send Brent to one of them and the
    bisection past both: in 3,107 random solves (1,907 at rho 0.3-0.995, L 0.5-4, x_e to
    4 L, the capped and the default step; 1,200 at L 2, rho 0.9-0.99) and every benchmark
    row, none did (the same arcs, bit for bit, and the same failures).
    """
    if residual(a_lo, coarse) == 0.0:
        a_c = a_lo
    else:
        f = _jump_watch(residual, a_lo, a_hi, coarse, turned, _PROBE_AFTER)
        try:
            a_c = brentq(f, a_lo, a_hi, args=(coarse,), xtol=1e-13, rtol=1e-13)
        except _Jump:
            return None
        except _Probe as probe:
            if _bisected_jump(residual, coarse, turned, *probe.args):
                return None
            # not a jump by bisection: Brent from the start, its evaluations so far cached
            f = _jump_watch(residual, a_lo, a_hi, coarse, turned)
            try:
                a_c = brentq(f, a_lo, a_hi, args=(coarse,), xtol=1e-13, rtol=1e-13)
            except _Jump:
                return None
    if abs(residual(a_c, coarse)) > 1e-6:  # sign change across a turned-back arc
        return None
    a0, r0 = a_c, residual(a_c)
    if abs(r0) < 1e-14:  # the coarse root is a fine one already (the loop's criterion)
        return a_c
    a1 = a_c + 1e-7 * (1.0 if a_c < 0.0 else -1.0)
    # the second point: a Newton step on the coarse grid's slope at a_c (the fine one's
    # differs by the coarse truncation error), a coarse integration instead of a fine one
    # at a1; where the coarse arc from a1 turned back, or the step leaves the bracket,
    # a1 itself
    r_c1 = residual(a1, coarse)
    if not turned(a1) and r_c1 != residual(a_c, coarse):
        a_n = a_c - r0 * (a1 - a_c) / (r_c1 - residual(a_c, coarse))
        if a_lo <= a_n <= a_hi and a_n != a_c:
            a1 = a_n
    r1 = residual(a1)
    for _ in range(8):
        if abs(r1) < 1e-14:
            return a1
        if r1 == r0:
            break
        a0, r0, a1 = a1, r1, a1 - r1 * (a1 - a0) / (r1 - r0)
        if not a_lo <= a1 <= a_hi:
            break
        r1 = residual(a1)
        if abs(a1 - a0) < 1e-14:
            return a1 if abs(r1) < 1e-9 else None
    r_lo, r_hi = residual(a_lo), residual(a_hi)
    if r_lo * r_hi > 0.0:  # pragma: no cover - the coarse bracket is not a fine one
        return None
    root = brentq(residual, a_lo, a_hi, xtol=1e-14, rtol=1e-14)
    return root if abs(residual(root)) < 1e-9 else None


def _jump_watch(
    residual, a_lo: float, a_hi: float, coarse: float, turned, probe_after: int | None = None
):
    """``residual`` (for Brent on ``[a_lo, a_hi]`` at the ``coarse`` step) that raises
    :class:`_Jump` once the bracket is a jump by :data:`_JUMP_WIDTH` (see
    :func:`_polished_root`), and with ``probe_after`` :class:`_Probe` (the bracket) from
    that many evaluations on while the bracket still has a turned-back end and a reaching
    one off the axis by :data:`_JUMP_RESIDUAL`."""
    ends = [[a_lo, residual(a_lo, coarse)], [a_hi, residual(a_hi, coarse)]]
    count = [0]

    def watched(a0: float, hh: float) -> float:
        r = residual(a0, hh)
        lo, hi = ends
        if lo[0] < a0 < hi[0]:  # Brent's new bracket: a0 and the old end of the other sign
            end = lo if (r > 0.0) == (lo[1] > 0.0) else hi
            end[0], end[1] = a0, r
            if hi[0] - lo[0] < _JUMP_WIDTH and r != 0.0:
                t_lo, t_hi = turned(lo[0]), turned(hi[0])
                if t_lo != t_hi and abs(hi[1] if t_lo else lo[1]) > _JUMP_RESIDUAL:
                    raise _Jump
        count[0] += 1
        if probe_after is not None and count[0] >= probe_after and r != 0.0:
            t_lo, t_hi = turned(lo[0]), turned(hi[0])
            if t_lo != t_hi and abs(hi[1] if t_lo else lo[1]) > _JUMP_RESIDUAL:
                raise _Probe(tuple(lo), tuple(hi))
        return r

    return watched


def _bisected_jump(residual, coarse: float, turned, lo, hi) -> bool:
    """Whether bisection of the coarse bracket ``lo``, ``hi`` (``(α(0), residual)`` pairs:
    one end turned back, the other reaching ``x_e`` off the axis) closes on a jump by
    :data:`_JUMP_WIDTH`: every midpoint either turns back as the turned end did or reaches
    ``x_e`` on the same side of the axis as the reaching end by :data:`_JUMP_RESIDUAL`.
    False at the first midpoint that does neither (an arc reaching the axis's other side:
    a root lies between, Brent finds it)."""
    (a_t, r_t), (a_e, r_e) = (lo, hi) if turned(lo[0]) else (hi, lo)
    while abs(a_e - a_t) >= _JUMP_WIDTH:
        m = a_t + 0.5 * (a_e - a_t)
        if m in (a_t, a_e):  # (no float between: only with _JUMP_WIDTH 0, no certificate)
            return False
        r = residual(m, coarse)
        if turned(m) and r == r_t:  # turned back the same way (10 x the status)
            a_t = m
        elif not turned(m) and (r > 0.0) == (r_e > 0.0) and abs(r) > _JUMP_RESIDUAL:
            a_e = m
        else:
            return False
    return True


# ------------------------------------------------------------------------------ greedy


class GreedyHeading(NamedTuple):
    """Result of :func:`greedy_heading`."""

    alpha: float | np.ndarray
    """``argmin_α |f2(α, θ)|``."""
    f2: float | np.ndarray
    """``f2`` at that heading (signed: >= 0 for '+', <= 0 for '-')."""


def greedy_heading(theta, *, L: float, rho: float, branch="+") -> GreedyHeading:
    """Fig. 12 mode (final y free, so λ1 = 0): the heading minimising the rotation rate.

    Closed form: ``α* = atan2(s rho cos θ, 1 - s rho sin θ)`` (from ``sin α* = s rho
    cos(α* - θ)``, the stationarity condition with λ1 = 0; unique because H is unimodal).

    Examples:
        >>> g = greedy_heading(np.pi, L=1.0, rho=0.5)
        >>> bool(np.isclose(g.alpha, -np.arctan(0.5))), round(g.f2, 12)
        (True, 1.5)
    """
    t = validation.finite_array("theta", theta)
    L = validation.positive("L", L)
    rho = check_evasion_rho(rho)
    s = branch_sign(branch)
    a = np.arctan2(s * rho * np.cos(t), 1.0 - s * rho * np.sin(t))
    phi = a - t
    n = np.sqrt(1.0 - (rho * np.cos(phi)) ** 2) - s * rho * np.sin(phi)
    val = s * n / (L * rho * np.cos(a))
    if a.ndim == 0:
        return GreedyHeading(float(a), float(val))
    return GreedyHeading(a, val)
