"""Leader-follower cooperative motion (paper Sec. 7): the evader leads, the pursuer follows.

* 7.1 tractrix: the follower dragged by a taut rod behind a straight-moving leader.
  The curve is the *follower's* path (erratum E4); general L, V_e, θ0, leader heading.
* 7.2 minimum follower time while the leader goes straight (closed form with the
  incomplete elliptic integral of the second kind; typo E5, full expression E5b).
* 7.3 wall following: required follower speed ``V_e cos(α - θ)/cos θ``; feasible for
  every leader heading iff ``|cos θ| >= rho`` (E6).
* 7.4 rounding a corner: the rod touches a vertex at distance l from the leader;
  ``p = e + (L/l)(v - e)`` is a *position* relation (E7) and ``ṗ = (I - (L/l) n nᵀ) ė``.
"""

from __future__ import annotations

import itertools
import math
from typing import NamedTuple

import numpy as np
from scipy.special import ellipeinc

from envs import validation
from envs.errors import InfeasibleError, SurveilValueError

__all__ = [
    "Tractrix",
    "corner_feasible",
    "corner_min_distance",
    "corner_pursuer_position",
    "corner_pursuer_velocity",
    "corner_required_speed",
    "straight_leader_time",
    "tractrix",
    "tractrix_numeric",
    "wall_follow_feasible",
    "wall_follow_max_speed",
    "wall_follow_speed",
    "wall_follow_theta_dot",
]


class Tractrix(NamedTuple):
    """Leader and follower along a tractrix, sampled at the requested times."""

    t: np.ndarray
    leader: np.ndarray
    """Leader positions, shape (N, 2)."""
    follower: np.ndarray
    """Follower positions ``leader + L (cos θ, sin θ)``, shape (N, 2)."""
    theta: np.ndarray
    """Rod orientation (leader -> follower), unwrapped."""
    speed: np.ndarray
    """Follower speed ``V_e |cos(α - θ)|`` (never above V_e: always feasible for rho <= 1)."""


def _tractrix_args(t, L, v_e, theta0, alpha, leader_start):
    tt = np.atleast_1d(validation.finite_array("t", t))
    if tt.ndim != 1:
        raise SurveilValueError(f"t has shape {tt.shape}: expected a 1-D array of times")
    v_e = validation.nonnegative("v_e", v_e)
    start = validation.points("leader_start", leader_start)
    reach = v_e * float(np.max(np.abs(tt), initial=0.0)) + float(np.max(np.abs(start)))
    if not math.isfinite(reach):
        # the leader's positions would overflow to inf and the follower's to nan
        raise SurveilValueError(
            f"v_e = {v_e!r} with times up to {float(np.max(np.abs(tt))):.4g}: the leader's "
            "travel v_e t overflows; expected it finite"
        )
    return (
        tt,
        validation.positive("L", L),
        v_e,
        validation.real("theta0", theta0),
        validation.real("alpha", alpha),
        start,
    )


def _leader(tt, v_e, alpha, start):
    return start + (v_e * tt)[:, None] * np.array([math.cos(alpha), math.sin(alpha)])


def tractrix(
    t,
    *,
    L: float = 1.0,
    v_e: float = 1.0,
    theta0: float = 0.5 * math.pi,
    alpha: float = 0.0,
    leader_start=(0.0, 0.0),
) -> Tractrix:
    """Closed-form tractrix (Sec. 7.1, generalised; THEORY §5.1).

    The leader moves from ``leader_start`` in direction α at speed ``v_e``. The dragged
    follower moves along the rod, ``L θ̇ = -v_e sin(α - θ)``, so with ``s = v_e t / L`` and
    ``ψ = θ - α``: ``tan(ψ/2) = tan(ψ0/2) e^s``. For α = 0, θ0 = π/2, L = v_e = 1 the
    follower is the printed ``(t - tanh t, sech t)`` (E4: the follower's curve; t is the
    leader's abscissa in units of L, a time only if ``v_e = L = 1``).
    """
    tt, L, v_e, theta0, alpha, start = _tractrix_args(t, L, v_e, theta0, alpha, leader_start)
    s = v_e * tt / L
    psi0 = theta0 - alpha
    half = 0.5 * psi0
    # 2 atan2(sin(ψ0/2), cos(ψ0/2) e^-s): stable for large s, keeps ψ0's turn count
    psi = 2.0 * np.arctan2(math.sin(half) * np.ones_like(s), math.cos(half) * np.exp(-s))
    psi += psi0 - 2.0 * math.atan2(math.sin(half), math.cos(half))
    theta = alpha + psi
    leader = _leader(tt, v_e, alpha, start)
    follower = leader + L * np.column_stack([np.cos(theta), np.sin(theta)])
    return Tractrix(tt, leader, follower, theta, v_e * np.abs(np.cos(psi)))


def tractrix_numeric(
    t,
    *,
    L: float = 1.0,
    v_e: float = 1.0,
    theta0: float = 0.5 * math.pi,
    alpha: float = 0.0,
    leader_start=(0.0, 0.0),
    substeps: int = 200,
) -> Tractrix:
    """The same motion by RK4 on the follower position: ``ṗ = (ė·u) u``, ``u = (p - e)/|p - e|``.

    An independent check of :func:`tractrix` (a different ODE: positions, not θ).
    ``t`` must be increasing; ``substeps`` RK4 steps (an integer >= 1) are taken between
    samples.
    """
    tt, L, v_e, theta0, alpha, start = _tractrix_args(t, L, v_e, theta0, alpha, leader_start)
    # 0 or fewer steps returned the start at every time, 2.0 a TypeError from range()
    substeps = validation.integer("substeps", substeps, minimum=1, where="tractrix_numeric")
    if np.any(np.diff(tt) < 0):
        raise SurveilValueError("t must be non-decreasing for tractrix_numeric")
    ev = v_e * np.array([math.cos(alpha), math.sin(alpha)])

    def f(time: float, p: np.ndarray) -> np.ndarray:
        u = p - (start + ev * time)
        u = u / math.hypot(u[0], u[1])
        return float(ev @ u) * u

    p = start + ev * tt[0] + L * np.array([math.cos(theta0), math.sin(theta0)])
    out = [p]
    for t0, t1 in itertools.pairwise(tt):
        h = (t1 - t0) / substeps
        for i in range(substeps):
            ti = t0 + i * h
            k1 = f(ti, p)
            k2 = f(ti + h / 2, p + h / 2 * k1)
            k3 = f(ti + h / 2, p + h / 2 * k2)
            k4 = f(ti + h, p + h * k3)
            p = p + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        out.append(p)
    follower = np.array(out)
    leader = _leader(tt, v_e, alpha, start)
    rel = follower - leader
    theta = np.unwrap(np.arctan2(rel[:, 1], rel[:, 0]))
    theta += theta0 - theta[0]
    return Tractrix(tt, leader, follower, theta, v_e * np.abs(np.cos(theta - alpha)))


def straight_leader_time(
    theta0: float, theta1: float, *, alpha: float, L: float, v_p: float, rho: float
) -> float:
    """Minimum time for the follower to turn the rod from θ0 to θ1 while the leader goes
    straight in direction α at full speed (Sec. 7.2), the follower rotating at its extreme
    rate θ̇⁺ (θ1 > θ0, counter-clockwise) or θ̇⁻ (θ1 < θ0, clockwise).

    ``dt/dθ = L / (v_p (-rho sin(α-θ) ± sqrt(1 - rho² cos²(α-θ))))`` (typo E5 fixed), and
    multiplying by the conjugate (valid for rho < 1 only) gives (E5b)

        T = L / (v_p (1 - rho²)) [rho (cos(α-θ1) - cos(α-θ0)) ± (E(φ1|rho²) - E(φ0|rho²))],

    ``φi = π/2 - α + θi``, ``E = scipy.special.ellipeinc`` with parameter ``m = rho²``.

    Args:
        theta0: initial rod orientation.
        theta1: final orientation, *unwrapped*: its sign relative to θ0 sets the direction.
        alpha: leader heading.
        L: rod length, > 0.
        v_p: follower speed bound, > 0.
        rho: speed ratio, 0 <= rho < 1.

    Returns:
        T >= 0 (0 only when θ1 = θ0).

    Raises:
        InfeasibleError: rho >= 1 (the closed form divides by 1 - rho²; at rho = 1 the
            rate θ̇⁺ vanishes when sin(α - θ) >= 0, E1, and T can be infinite).
    """
    th0, th1 = validation.real("theta0", theta0), validation.real("theta1", theta1)
    alpha = validation.real("alpha", alpha)
    L, v_p = validation.positive("L", L), validation.positive("v_p", v_p)
    rho = validation.nonnegative("rho", rho)
    if rho >= 1.0:
        raise InfeasibleError(
            f"rho = {rho!r}: the straight-leader time needs rho < 1 (the closed form divides "
            "by 1 - rho^2; at rho >= 1 the follower may never complete the turn, E1, E5b)"
        )
    sign = 1.0 if th1 >= th0 else -1.0
    m = rho * rho
    phi0, phi1 = 0.5 * math.pi - alpha + th0, 0.5 * math.pi - alpha + th1
    e_diff = float(ellipeinc(phi1, m) - ellipeinc(phi0, m))
    cos_diff = math.cos(alpha - th1) - math.cos(alpha - th0)
    return L / (v_p * (1.0 - m)) * (rho * cos_diff + sign * e_diff)


def wall_follow_theta_dot(alpha, theta, *, L: float, v_e: float):
    """Rod rate keeping the follower on the wall y = 0: ``-v_e sin α / (L cos θ)`` (Sec. 7.3).

    ±inf where ``cos θ = 0`` (rod perpendicular to the wall) and ``sin α != 0``.
    """
    a, th = validation.finite_array("alpha", alpha), validation.finite_array("theta", theta)
    L, v_e = validation.positive("L", L), validation.nonnegative("v_e", v_e)
    with np.errstate(divide="ignore", invalid="ignore"):
        out = -v_e * np.sin(a) / (L * np.cos(th))
    return float(out) if out.ndim == 0 else out


def wall_follow_speed(alpha, theta, *, v_e: float):
    """Required follower velocity along the wall: ``ẋ_p = v_e cos(α - θ) / cos θ`` (Sec. 7.3).

    Signed (negative: the follower moves toward -x). ±inf where ``cos θ = 0``.
    """
    a, th = validation.finite_array("alpha", alpha), validation.finite_array("theta", theta)
    v_e = validation.nonnegative("v_e", v_e)
    with np.errstate(divide="ignore", invalid="ignore"):
        out = v_e * np.cos(a - th) / np.cos(th)
    return float(out) if out.ndim == 0 else out


def wall_follow_max_speed(theta, *, v_e: float):
    """Worst case over leader headings, at ``α = θ + kπ`` for every integer k (E6):
    ``v_e / |cos θ|`` (inf at ``cos θ = 0``)."""
    th = validation.finite_array("theta", theta)
    v_e = validation.nonnegative("v_e", v_e)
    with np.errstate(divide="ignore"):
        out = v_e / np.abs(np.cos(th))
    return float(out) if out.ndim == 0 else out


def wall_follow_feasible(theta, *, rho: float):
    """Whether the follower can hold the wall for every leader heading: ``|cos θ| >= rho``.

    The paper prints ``cos θ >= rho``, right only when cos θ > 0 (E6).
    """
    th = validation.finite_array("theta", theta)
    rho = validation.nonnegative("rho", rho)
    out = np.abs(np.cos(th)) >= rho
    return bool(out) if out.ndim == 0 else out


def _corner_geometry(evader, vertex, L):
    e = validation.points("evader", evader)
    v = validation.points("vertex", vertex)
    L = validation.positive("L", L)
    d = v - e
    ell = np.hypot(d[..., 0], d[..., 1])
    if np.any(ell <= 0.0) or np.any(ell > L * (1.0 + 1e-12)):
        raise SurveilValueError(
            f"distance from evader to vertex = {ell!r}: expected 0 < l <= L = {L!r} "
            "(the vertex must lie on the rod)"
        )
    return e, v, L, d, ell


def corner_pursuer_position(evader, vertex, *, L: float) -> np.ndarray:
    """Pursuer position with the rod through the vertex: ``p = e + (L/l)(v - e)``.

    The paper prints this as a velocity relation, which is dimensionally wrong (E7).
    """
    e, _, L, d, ell = _corner_geometry(evader, vertex, L)
    return e + (L / ell)[..., None] * d


def corner_pursuer_velocity(evader, vertex, evader_velocity, *, L: float) -> np.ndarray:
    """Follower velocity keeping the rod on the vertex (Sec. 7.4, correct final formula).

    ``ṗ = (I - (L/l) n nᵀ) ė`` with ``n = (sin θ, -cos θ)``, θ the direction evader -> vertex:
    the along-rod part of ė passes through, the perpendicular part is scaled by
    ``1 - L/l <= 0`` (a lever about the vertex, E7).
    """
    _, _, L, d, ell = _corner_geometry(evader, vertex, L)
    ev = validation.points("evader_velocity", evader_velocity)
    u = d / ell[..., None]
    n = np.stack([u[..., 1], -u[..., 0]], axis=-1)  # (sin θ, -cos θ)
    perp = np.sum(ev * n, axis=-1)
    return ev - (L / ell * perp)[..., None] * n


def corner_required_speed(ell, *, L: float, v_e: float):
    """Worst-case follower speed over leader headings: ``v_e max(1, (L - l)/l)`` (THEORY §5.4)."""
    ell_a = validation.finite_array("l", ell)
    L, v_e = validation.positive("L", L), validation.nonnegative("v_e", v_e)
    if np.any(ell_a <= 0.0) or np.any(ell_a > L):
        raise SurveilValueError(f"l = {ell!r}: expected 0 < l <= L = {L!r}")
    out = v_e * np.maximum(1.0, (L - ell_a) / ell_a)
    return float(out) if out.ndim == 0 else out


def corner_min_distance(*, L: float, rho: float) -> float:
    """Smallest leader-vertex distance at which the follower can hold the contact for every
    leader heading: ``rho L / (1 + rho)`` (needs rho <= 1, otherwise nothing is feasible)."""
    L, rho = validation.positive("L", L), validation.nonnegative("rho", rho)
    if rho > 1.0:
        raise InfeasibleError(
            f"rho = {rho!r} > 1: the follower cannot even match the leader's speed"
        )
    return rho * L / (1.0 + rho)


def corner_feasible(ell, *, L: float, rho: float):
    """Whether ``corner_required_speed(l) <= v_p``, i.e. ``rho <= 1`` and ``l >= rho L/(1+rho)``."""
    ell_a = validation.finite_array("l", ell)
    L, rho = validation.positive("L", L), validation.nonnegative("rho", rho)
    if np.any(ell_a <= 0.0) or np.any(ell_a > L):
        raise SurveilValueError(f"l = {ell!r}: expected 0 < l <= L = {L!r}")
    out = (rho <= 1.0) & (ell_a >= rho * L / (1.0 + rho))
    return bool(out) if np.ndim(out) == 0 else out
