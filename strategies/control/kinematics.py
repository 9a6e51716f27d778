"""Rod kinematics at constant surveillance distance (paper Secs. 5 and 6.1, eqs. 4-6).

Conventions (THEORY.md §0): the evader E is at ``(x, y)``, the pursuer at
``P = E + L (cos θ, sin θ)``, so θ is the direction *from the evader to the pursuer*.
The evader moves with speed ``V_e = rho * v_p`` in direction α.

Differentiating eq. (1) at constant L gives eq. (5), ``ṗ = ė + L θ̇ (-sin θ, cos θ)``, and
``|ṗ| = v_p`` gives the two roots of eq. (6):

    θ̇± = (v_p / L) (-rho sin(α - θ) ± sqrt(1 - rho² cos²(α - θ)))

Every rate in ``[θ̇⁻, θ̇⁺]`` is achievable with ``|ṗ| <= v_p``. For ``rho > 1`` the square
root can be imaginary: no pursuer velocity keeps L constant. Functions here never return
NaN in that case; they clamp the discriminant at 0 (documented per function) and
:func:`theta_dot_feasible` reports where the clamp was used.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from envs import validation
from envs.errors import SurveilValueError

__all__ = [
    "MinMaxHeading",
    "PursuerCommand",
    "escape_trivial",
    "max_abs_theta_dot",
    "min_max_theta_dot",
    "pursuer_velocity",
    "pursuer_velocity_holding_range",
    "theta_dot",
    "theta_dot_feasible",
    "theta_dot_from_velocities",
]


def _scalar_or_array(a: np.ndarray) -> float | np.ndarray:
    return float(a) if a.ndim == 0 else a


def escape_trivial(rho: float) -> bool:
    """True when the evader is faster than the pursuer (paper footnote 4).

    For ``rho > 1`` the evader escapes by moving straight away from the pursuer: at
    ``α = θ + π`` the discriminant ``1 - rho²`` of eq. (6) is negative, so no pursuer
    velocity keeps L constant and L grows until it exceeds ``L_max``.

    Args:
        rho: speed ratio ``V_e / V_p`` (finite, >= 0).
    """
    return validation.nonnegative("rho", rho) > 1.0


def theta_dot_feasible(alpha, theta, *, rho: float):
    """Where eq. (6) has real roots, i.e. ``1 - rho² cos²(α - θ) >= 0``.

    Always True for ``rho <= 1``. Vectorised over ``alpha`` and ``theta``.
    """
    rho = validation.nonnegative("rho", rho)
    phi = validation.finite_array("alpha", alpha) - validation.finite_array("theta", theta)
    return _scalar_or_array(np.asarray(1.0 - (rho * np.cos(phi)) ** 2 >= 0.0))


def theta_dot(alpha, theta, *, L: float, v_p: float, rho: float):
    """The extreme rod rotation rates θ̇⁺ and θ̇⁻ of eq. (6).

    The printed eq. (6) is correct (THEORY §4.1). For ``rho <= 1``, θ̇⁺ >= 0 >= θ̇⁻, with
    equality possible only at ``rho = 1`` (erratum E1).

    Where the discriminant is negative (only for ``rho > 1``, see
    :func:`theta_dot_feasible`) it is clamped at 0: both values equal
    ``-(v_p / L) rho sin(α - θ)``, the rate that minimises the pursuer's required speed
    (its velocity then matches the evader's perpendicular component; L still changes).

    Args:
        alpha: evader heading(s) α, radians.
        theta: rod orientation(s) θ (evader -> pursuer), radians.
        L: surveillance distance, > 0.
        v_p: pursuer speed bound, > 0.
        rho: speed ratio ``V_e / v_p``, >= 0.

    Returns:
        ``(theta_dot_plus, theta_dot_minus)``, floats or broadcast arrays.

    Examples:
        >>> tp, tm = theta_dot(np.pi / 2, 0.0, L=1.0, v_p=1.0, rho=0.5)
        >>> round(tp, 12), round(tm, 12)
        (0.5, -1.5)
    """
    L = validation.positive("L", L)
    v_p = validation.positive("v_p", v_p)
    rho = validation.nonnegative("rho", rho)
    phi = validation.finite_array("alpha", alpha) - validation.finite_array("theta", theta)
    plus, minus = _theta_dot_rates(phi, L, v_p, rho)
    return _scalar_or_array(plus), _scalar_or_array(minus)


def _theta_dot_rates(phi, L: float, v_p: float, rho: float):
    """:func:`theta_dot` at ``phi = alpha - theta`` on checked inputs (per-step callers)."""
    root = np.sqrt(np.maximum(1.0 - (rho * np.cos(phi)) ** 2, 0.0))
    base = -rho * np.sin(phi)
    k = v_p / L
    return k * (base + root), k * (base - root)


def max_abs_theta_dot(alpha, theta, *, L: float, v_p: float, rho: float):
    """The largest rotation rate the pursuer can effect, ``max(θ̇⁺, -θ̇⁻)``.

    Equals ``(v_p / L) (rho |sin φ| + sqrt(1 - rho² cos² φ))`` with ``φ = α - θ``
    (THEORY §4.1; same discriminant clamp as :func:`theta_dot`).
    """
    tp, tm = theta_dot(alpha, theta, L=L, v_p=v_p, rho=rho)
    return _scalar_or_array(np.maximum(np.asarray(tp), -np.asarray(tm)))


class MinMaxHeading(NamedTuple):
    """Evader headings that minimise the pursuer's best rotation rate (Sec. 6.1)."""

    toward: float
    """Heading straight at the pursuer, ``α = θ`` (wrapped to (-π, π])."""
    away: float
    """Heading straight away from the pursuer, ``α = θ + π`` (wrapped to (-π, π])."""
    rate: float
    """The minimal ``max |θ̇|``: ``(v_p / L) sqrt(1 - rho²)``; 0 when ``rho >= 1``."""


def _wrap(angle: float) -> float:
    """Wrap to (-π, π]."""
    w = math.remainder(angle, 2.0 * math.pi)
    return math.pi if w == -math.pi else w


def min_max_theta_dot(theta: float, *, L: float, v_p: float, rho: float) -> MinMaxHeading:
    """The evader heading minimising ``max |θ̇|``: straight toward or away from the pursuer.

    The paper's reason (concavity of ``|θ̇⁻|`` on (0, π)) is false near the ends (erratum E2),
    but ``g(φ) = rho sin φ + sqrt(1 - rho² cos² φ)`` is unimodal on (0, π) with
    ``g'(φ) = rho cos φ (1 + rho sin φ / sqrt(...))``, so the minima sit at ``φ = kπ``.

    For ``rho > 1`` the clamped rate at ``φ = kπ`` is 0: the pursuer cannot even hold L
    there and the evader escapes trivially (:func:`escape_trivial`).
    """
    theta = validation.real("theta", theta)
    L = validation.positive("L", L)
    v_p = validation.positive("v_p", v_p)
    rho = validation.nonnegative("rho", rho)
    rate = (v_p / L) * math.sqrt(max(1.0 - rho * rho, 0.0))
    return MinMaxHeading(toward=_wrap(theta), away=_wrap(theta + math.pi), rate=rate)


def _rod_frame(theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unit vector along the rod (evader -> pursuer) and its CCW normal ``(-sin θ, cos θ)``."""
    c, s = np.cos(theta), np.sin(theta)
    return np.stack([c, s], axis=-1), np.stack([-s, c], axis=-1)


def pursuer_velocity(evader_velocity, theta, theta_dot, *, L: float) -> np.ndarray:
    """Pursuer velocity realising a rotation rate at constant L (eq. 5).

    ``ṗ = ė + L θ̇ (-sin θ, cos θ)``: the evader's velocity plus a component perpendicular to
    the rod. Note ``L θ̇`` is the *relative* perpendicular speed ``(ṗ - ė)·(-sin θ, cos θ)``,
    not the pursuer's own perpendicular speed as printed in Sec. 5 (erratum E8).
    ``|ṗ| <= v_p`` holds exactly when ``θ̇`` lies in ``[θ̇⁻, θ̇⁺]`` of :func:`theta_dot`.

    Args:
        evader_velocity: ``ė``, shape ``(2,)`` or ``(..., 2)``.
        theta: rod orientation(s) θ.
        theta_dot: requested rotation rate(s).
        L: surveillance distance, > 0.

    Returns:
        Array of shape ``(..., 2)`` (broadcast of the inputs).
    """
    ev = validation.points("evader_velocity", evader_velocity)
    th = validation.finite_array("theta", theta)
    td = validation.finite_array("theta_dot", theta_dot)
    L = validation.positive("L", L)
    _, normal = _rod_frame(th)
    return ev + (L * td)[..., None] * normal


def theta_dot_from_velocities(evader_velocity, pursuer_velocity_, theta, *, L: float):
    """Rotation rate produced by given velocities: ``(ṗ - ė)·(-sin θ, cos θ) / L`` (E8)."""
    ev = validation.points("evader_velocity", evader_velocity)
    pv = validation.points("pursuer_velocity", pursuer_velocity_)
    th = validation.finite_array("theta", theta)
    L = validation.positive("L", L)
    _, normal = _rod_frame(th)
    return _scalar_or_array(np.sum((pv - ev) * normal, axis=-1) / L)


class PursuerCommand(NamedTuple):
    """Result of :func:`pursuer_velocity_holding_range`."""

    velocity: np.ndarray
    """Pursuer velocity, shape ``(2,)``; its norm never exceeds ``v_p`` (up to rounding)."""
    L_dot: float
    """Resulting rate of change of the surveillance distance."""
    feasible: bool
    """False when the requested θ̇ needs more than ``v_p`` (then it is only approximated)."""


def pursuer_velocity_holding_range(
    evader_velocity,
    theta: float,
    theta_dot_: float,
    *,
    L: float,
    L_target: float,
    v_p: float,
    gain: float = 1.0,
) -> PursuerCommand:
    """Pursuer velocity realising θ̇ while steering L toward ``L_target`` within ``v_p``.

    The perpendicular part is that of :func:`pursuer_velocity` (it sets θ̇, eq. 5). A radial
    part ``r (cos θ, sin θ)`` adds ``L̇ = r`` without changing θ̇. The desired
    ``r = gain (L_target - L)`` is clipped to the interval where ``|ṗ| <= v_p``, i.e.
    ``|ė·u + r| <= sqrt(v_p² - (ė·n + L θ̇)²)`` with ``u`` along the rod and ``n`` its normal.

    If the requested θ̇ is not achievable (``|ė·n + L θ̇| > v_p``), the pursuer moves at
    full speed perpendicular to the rod, with the sign of the requested relative rotation,
    and ``feasible`` is False.

    Args:
        evader_velocity: ``ė``, shape ``(2,)``.
        theta: rod orientation θ.
        theta_dot_: requested rotation rate.
        L: current distance, > 0.
        L_target: distance to steer toward (e.g. ``L_min``), > 0.
        v_p: pursuer speed bound, > 0.
        gain: proportional gain of the distance correction, 1/s, >= 0.
    """
    ev = validation.points("evader_velocity", evader_velocity)
    if ev.shape != (2,):
        raise SurveilValueError(f"evader_velocity has shape {ev.shape}: expected (2,)")
    th = validation.real("theta", theta)
    td = validation.real("theta_dot_", theta_dot_)
    L = validation.positive("L", L)
    L_target = validation.positive("L_target", L_target)
    v_p = validation.positive("v_p", v_p)
    gain = validation.nonnegative("gain", gain)
    return _holding_range(ev, th, td, L, L_target, v_p, gain)


def _holding_range(
    ev: np.ndarray, th: float, td: float, L: float, L_target: float, v_p: float, gain: float
) -> PursuerCommand:
    """:func:`pursuer_velocity_holding_range` on checked inputs (per-step callers)."""
    u = np.array([math.cos(th), math.sin(th)])
    n = np.array([-math.sin(th), math.cos(th)])
    perp = float(ev @ n) + L * td  # pursuer's own perpendicular speed
    along_e = float(ev @ u)
    slack2 = v_p * v_p - perp * perp
    if slack2 < 0.0:
        vel = math.copysign(v_p, perp) * n
        return PursuerCommand(velocity=vel, L_dot=-along_e, feasible=False)
    slack = math.sqrt(slack2)
    r = gain * (L_target - L)
    r = min(max(r, -slack - along_e), slack - along_e)  # |along_e + r| <= slack
    vel = (along_e + r) * u + perp * n
    return PursuerCommand(velocity=vel, L_dot=r, feasible=True)
