"""The optimal-control cases (Secs. 5-6, Figs. 9-13) the figures draw.

Fig. 9(a)'s charge (eq. (6) integrated, Sec. 7.2's closed form), Fig. 11's printed
multipliers shot at a fitted rho, and Fig. 13's escape endpoints in the corridor world.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from analysis.figures.cases.cspace import corridor
from envs.maps import Feature, builtin_info

__all__ = [
    "PAPER_SHOTS",
    "SHOT_L",
    "ChargeRotation",
    "EscapeCase",
    "charge_rotation",
    "curve_escape",
    "paper_shot",
    "paper_shot_rho",
    "vertex_escape",
]


# --------------------------------------------------------------------------- Fig. 9
@dataclass(frozen=True)
class ChargeRotation:
    """Fig. 9(a): the evader charges straight at the pursuer (alpha = theta0 = pi) while the
    pursuer turns the rod clockwise at its extreme rate theta_dot- of eq. (6).

    Attributes:
        L, v_p, rho: parameters (the corridor's).
        T: time to turn the rod from pi to pi/2 (Sec. 7.2's closed form, E5/E5b).
        t, theta: the rotation, integrated from eq. (6).
        recoil: how far the pursuer is pushed back along the charge (max over t of
            x_p(0) - x_p(t)): closer than this to the corridor's mouth, it is pushed in.
    """

    L: float
    v_p: float
    rho: float
    T: float
    t: np.ndarray
    theta: np.ndarray
    recoil: float

    def positions(self, evader0) -> tuple[np.ndarray, np.ndarray]:
        """Evader and pursuer positions, the evader starting at ``evader0``."""
        e0 = np.asarray(evader0, dtype=float)
        e = e0 + np.outer(self.t, [-self.rho * self.v_p, 0.0])
        p = e + self.L * np.column_stack([np.cos(self.theta), np.sin(self.theta)])
        return e, p


@functools.cache
def charge_rotation() -> ChargeRotation:
    """The rotation of Fig. 9(a) with the corridor's parameters."""
    from scipy.integrate import solve_ivp

    from strategies.control import straight_leader_time, theta_dot

    info = builtin_info("corridor")
    L, v_p, rho = info.l_min, info.v_pursuer, info.rho
    T = straight_leader_time(math.pi, 0.5 * math.pi, alpha=math.pi, L=L, v_p=v_p, rho=rho)
    sol = solve_ivp(
        lambda _t, y: [theta_dot(math.pi, y[0], L=L, v_p=v_p, rho=rho)[1]],
        (0.0, T),
        [math.pi],
        dense_output=True,
        rtol=1e-11,
        atol=1e-12,
    )
    t = np.linspace(0.0, T, 801)
    theta = sol.sol(t)[0]
    xp = -rho * v_p * t + L * np.cos(theta)
    return ChargeRotation(L, v_p, rho, T, t, theta, float(xp[0] - xp.min()))


# --------------------------------------------------------------------------- Figs. 10-13
PAPER_SHOTS = {
    "a": {"theta0": math.pi, "lambda1": -1.0, "lambda2_0": 0.41, "x_e": 1.0},
    "b": {"theta0": math.pi / 6, "lambda1": 1.0, "lambda2_0": 0.608, "x_e": 0.5},
}
"""The initial values printed under Fig. 11 (L and rho are not given)."""

SHOT_L = 1.0
"""The rod length we draw Figs. 10-12 at (THEORY.md section 7's reference value)."""


@functools.cache
def paper_shot_rho(which: str) -> float:
    """The rho at which Fig. 11(``which``)'s printed multipliers, shot at L = 1, return to
    y = 0 exactly at the printed x_e (one equation: the figure's (L, rho) are a curve, not a
    point; at L = 1 this is the point)."""
    from scipy.optimize import brentq

    from strategies.control import shoot

    p = PAPER_SHOTS[which]

    def miss(rho: float) -> float:
        arc = shoot(
            p["theta0"], p["lambda1"], p["lambda2_0"], L=SHOT_L, rho=rho, x_max=6.0 * p["x_e"]
        )
        return (arc.x_c if arc.x_c is not None else 6.0 * p["x_e"]) - p["x_e"]

    grid = np.linspace(0.1, 0.95, 35)
    vals = [miss(float(r)) for r in grid]
    for a, b, fa, fb in zip(grid, grid[1:], vals, vals[1:], strict=False):
        if fa * fb < 0:
            return float(brentq(miss, a, b, xtol=1e-12))
    raise RuntimeError(f"no rho in (0.1, 0.95) fits Fig. 11({which})")  # pragma: no cover


@functools.cache
def paper_shot(which: str, rho: float | None = None):
    """Fig. 11(``which``)'s printed multipliers shot at L = 1 (rho: fitted by default),
    and the optimal escape to the printed x_e at the same (L, rho)."""
    from strategies.control import shoot, solve_escape

    p = PAPER_SHOTS[which]
    rho = paper_shot_rho(which) if rho is None else rho
    arc = shoot(
        p["theta0"],
        p["lambda1"],
        p["lambda2_0"],
        L=SHOT_L,
        rho=rho,
        x_max=4.0 * p["x_e"],
        stop_at_crossing=True,
    )
    sol = solve_escape(p["theta0"], p["x_e"], L=SHOT_L, rho=rho)
    return arc, sol


@dataclass(frozen=True)
class EscapeCase:
    """Fig. 13: an optimal escape to an endpoint in the corridor world (world frame).

    Attributes:
        kind: ``"vertex"`` or ``"critical_curve"``.
        evader, pursuer: start positions.
        target: the :class:`strategies.control.EscapeTarget`.
        branch: the pursuer's rotation sense compared (the one needing less rotation).
        solution: :func:`strategies.control.solve_escape` in the evader frame.
        evader_path, pursuer_path: the optimal arc mapped back to the world.
        curve: the critical curve(s) drawn dashed (list of (k, 2) polylines).
    """

    kind: str
    evader: np.ndarray
    pursuer: np.ndarray
    target: object
    branch: str
    solution: object
    evader_path: np.ndarray
    pursuer_path: np.ndarray
    curves: tuple[np.ndarray, ...]

    @property
    def needed(self) -> float:
        """Rotation the pursuer needs on ``branch`` to reach an admissible orientation."""
        return self.target.required_rotation(self.branch)

    @property
    def achieved(self) -> float:
        """Rotation it can effect while the evader runs the optimal arc, |J|."""
        return abs(self.solution.J)

    @property
    def evader_escapes(self) -> bool:
        """The pursuer cannot turn far enough in time (on this branch)."""
        return self.achieved < self.needed


def _escape_case(kind, evader, theta, target_fn, curves) -> EscapeCase:
    from strategies.control import from_evader_frame, solve_escape

    dec = corridor()
    e = np.asarray(evader, dtype=float)
    p = e + dec.L * np.array([math.cos(theta), math.sin(theta)])
    t = target_fn(e, p)
    branch = "+" if t.rotation_ccw <= t.rotation_cw else "-"
    sol = solve_escape(t.theta0, t.x_e, L=dec.L, rho=builtin_info("corridor").rho, branch=branch)
    ev = from_evader_frame(sol.arc.evader_path(), e, t.beta)
    pu = from_evader_frame(sol.arc.pursuer_path(), e, t.beta)
    return EscapeCase(kind, e, p, t, branch, sol, ev, pu, tuple(curves))


@functools.cache
def vertex_escape() -> EscapeCase:
    """Fig. 13 left: from (1.5, 1.5), rod at 120 deg, to the mouth's upper corner (0, 0.5),
    whose two type-4 curves bound the admissible orientations."""
    from strategies.control import vertex_escape_target

    dec = corridor()
    m = dec.map
    k = int(np.argmin(np.hypot(*(m.vertices - (0.0, 0.5)).T)))
    prev = m.edge_start[int(np.flatnonzero(np.all(m.edge_end == m.vertices[k], axis=1))[0])]
    nxt = m.edge_end[k]
    curves = [c.points for c in dec.curves if c.type == 4 and Feature("vertex", k) in c.features]
    return _escape_case(
        "vertex",
        (1.5, 1.5),
        math.radians(120.0),
        lambda e, p: vertex_escape_target(e, p, m.vertices[k], prev, nxt, L=dec.L),
        curves,
    )


@functools.cache
def curve_escape() -> EscapeCase:
    """Fig. 13 right: from (3, -3), rod at -135 deg, to the critical curve bounding the
    region of the room-corner pocket cell (an escapable cell, condition (a))."""
    from strategies.control import critical_curve_escape_target

    dec = corridor()
    e = np.array([3.0, -3.0])
    home = dec.locate(e)
    corner = dec.locate((1.7, -3.3))  # the pocket region of the room corner (0, -5)
    cell = next(dec.cells[c] for c in dec.regions[corner].cells if dec.cells[c].escapable)
    piece = next(b for b in dec.boundaries if set(b.regions) == {home, corner})
    pts = piece.segments.reshape(-1, 2)
    return _escape_case(
        "critical_curve",
        e,
        math.radians(-135.0),
        lambda e, p: critical_curve_escape_target(e, p, pts, cell.arc.lo, cell.arc.hi, L=dec.L),
        [pts],
    )
