"""Escape endpoints of optimal evader trajectories (paper Sec. 6.2 end, Fig. 13).

Plain numpy geometry in, an :class:`EscapeTarget` out; no Map object, so the policy layer
adapts whatever map representation it has.

* **Convex obstacle vertex** (the paper's "reflex vertex", THEORY §0). The two type-4
  critical curves leave v along the extensions of its edges, in the directions
  ``v - prev`` and ``v - next``. With the evader at v the pursuer needs unbounded speed
  unless the rod lies in the wedge between them (the vertical angle of the obstacle's
  wedge, narrower than π): that CCW arc ``[theta_i, theta_f]`` is the admissible set.
* **Critical curve bounding an escapable cell**. The evader heads for the nearest point
  of the curve (the x-axis is perpendicular to the curve there). The cell's orientations
  ``[escapable_from, escapable_to]`` (CCW) are escapable; admissible is the complement.

The evader frame puts the evader at the origin and the endpoint at ``(x_e, 0)``, which
is what :func:`strategies.control.evasion.solve_escape` expects.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from envs import validation
from envs.errors import SurveilValueError
from strategies.control._validate import branch_sign

__all__ = [
    "EscapeTarget",
    "critical_curve_escape_target",
    "from_evader_frame",
    "to_evader_frame",
    "vertex_escape_target",
]

_TWO_PI = 2.0 * math.pi


def _wrap(a: float) -> float:
    """Wrap to (-π, π]."""
    w = math.remainder(a, _TWO_PI)
    return math.pi if w == -math.pi else w


def _ccw(a_from: float, a_to: float) -> float:
    """CCW angle from ``a_from`` to ``a_to`` in [0, 2π)."""
    return (a_to - a_from) % _TWO_PI


@dataclass(frozen=True)
class EscapeTarget:
    """An escape endpoint and the rod orientations the pursuer must reach by then."""

    kind: str
    """``"vertex"`` or ``"critical_curve"``."""
    position: np.ndarray
    """World coordinates of the endpoint, shape (2,)."""
    theta_i: float
    """Start of the CCW arc of admissible rod orientations at the endpoint (world)."""
    theta_f: float
    """End of that arc (world)."""
    beta: float
    """World direction of the evader frame's +x axis (evader -> endpoint)."""
    x_e: float
    """Distance from the evader to the endpoint (0 if the evader is already there)."""
    theta0: float
    """Current rod orientation in the evader frame, in (-π, π]."""
    theta_i_frame: float
    """``theta_i`` in the evader frame."""
    theta_f_frame: float
    """``theta_f`` in the evader frame."""
    rotation_ccw: float
    """Counter-clockwise rotation (>= 0) bringing the rod into the admissible arc."""
    rotation_cw: float
    """Clockwise rotation (>= 0) bringing the rod into the admissible arc."""

    def required_rotation(self, branch="+") -> float:
        """Rotation the pursuer needs on branch ``"+"`` (CCW, θ̇⁺) or ``"-"`` (CW, θ̇⁻)."""
        return self.rotation_ccw if branch_sign(branch) > 0 else self.rotation_cw


def to_evader_frame(points, evader, beta: float) -> np.ndarray:
    """World points -> evader frame: translate the evader to 0, rotate by ``-beta``."""
    p = validation.points("points", points) - validation.points("evader", evader)
    c, s = math.cos(validation.real("beta", beta)), math.sin(beta)
    return np.stack([c * p[..., 0] + s * p[..., 1], -s * p[..., 0] + c * p[..., 1]], axis=-1)


def from_evader_frame(points, evader, beta: float) -> np.ndarray:
    """Evader-frame points -> world (inverse of :func:`to_evader_frame`)."""
    p = validation.points("points", points)
    c, s = math.cos(validation.real("beta", beta)), math.sin(beta)
    rot = np.stack([c * p[..., 0] - s * p[..., 1], s * p[..., 0] + c * p[..., 1]], axis=-1)
    return rot + validation.points("evader", evader)


def _point(name: str, value) -> np.ndarray:
    p = validation.points(name, value)
    if p.shape != (2,):
        raise SurveilValueError(f"{name} has shape {p.shape}: expected a point of shape (2,)")
    return p


def _make(kind, position, theta_i, theta_f, evader, pursuer, L) -> EscapeTarget:
    L = validation.positive("L", L)
    rod = pursuer - evader
    if np.hypot(*rod) == 0.0:
        raise SurveilValueError("pursuer coincides with evader: the rod orientation is undefined")
    theta = math.atan2(rod[1], rod[0])
    d = position - evader
    x_e = float(np.hypot(*d))
    beta = math.atan2(d[1], d[0]) if x_e > 0.0 else 0.0
    inside = _ccw(theta_i, theta) <= _ccw(theta_i, theta_f)
    return EscapeTarget(
        kind=kind,
        position=position.copy(),
        theta_i=_wrap(theta_i),
        theta_f=_wrap(theta_f),
        beta=beta,
        x_e=x_e,
        theta0=_wrap(theta - beta),
        theta_i_frame=_wrap(theta_i - beta),
        theta_f_frame=_wrap(theta_f - beta),
        rotation_ccw=0.0 if inside else _ccw(theta, theta_i),
        rotation_cw=0.0 if inside else _ccw(theta_f, theta),
    )


def vertex_escape_target(
    evader, pursuer, vertex, prev_vertex, next_vertex, *, L: float, obstacle_ccw: bool | None = None
) -> EscapeTarget:
    """Escape endpoint at a convex obstacle vertex (Fig. 13, left).

    Args:
        evader: evader position, shape (2,).
        pursuer: pursuer position (gives the current θ).
        vertex: the convex obstacle vertex v.
        prev_vertex: v's predecessor on the obstacle boundary.
        next_vertex: v's successor.
        L: surveillance distance (validated; the type-4 curves have length L).
        obstacle_ccw: if given, the obstacle's vertex order (True: counter-clockwise);
            then a concave vertex (no type-4 curves) raises.

    Raises:
        SurveilValueError: bad points, collinear edges, or (with ``obstacle_ccw``) a
            concave vertex.
    """
    e, p = _point("evader", evader), _point("pursuer", pursuer)
    v = _point("vertex", vertex)
    a, b = _point("prev_vertex", prev_vertex), _point("next_vertex", next_vertex)
    d1, d2 = v - a, v - b  # directions of the two type-4 curves
    if np.hypot(*d1) == 0.0 or np.hypot(*d2) == 0.0:
        raise SurveilValueError("vertex coincides with a neighbour: degenerate edge")
    cross = float(d1[0] * d2[1] - d1[1] * d2[0])
    if abs(cross) <= 1e-12 * float(np.hypot(*d1) * np.hypot(*d2)):
        raise SurveilValueError(
            f"vertex {v.tolist()} has collinear edges: no corner, no type-4 curves"
        )
    if obstacle_ccw is not None:
        turn = float((v - a)[0] * (b - v)[1] - (v - a)[1] * (b - v)[0])
        if (turn > 0) != bool(obstacle_ccw):
            raise SurveilValueError(
                f"vertex {v.tolist()} is a concave obstacle vertex (free-space convex): "
                "no type-4 critical curves leave it"
            )
    t1, t2 = math.atan2(d1[1], d1[0]), math.atan2(d2[1], d2[0])
    theta_i, theta_f = (t1, t2) if _ccw(t1, t2) < math.pi else (t2, t1)  # narrow wedge
    return _make("vertex", v, theta_i, theta_f, e, p, L)


def critical_curve_escape_target(
    evader, pursuer, curve, escapable_from: float, escapable_to: float, *, L: float
) -> EscapeTarget:
    """Escape endpoint on a critical curve bounding an escapable cell (Fig. 13, right).

    Args:
        evader: evader position, shape (2,).
        pursuer: pursuer position.
        curve: the critical curve as a polyline, shape (k, 2), k >= 2 (types 1, 3, 4
            are segments; sample arcs and conchoids finely).
        escapable_from: start of the CCW arc of escapable orientations of the cell.
        escapable_to: its end. The admissible arc is the complement.
        L: surveillance distance.
    """
    e, p = _point("evader", evader), _point("pursuer", pursuer)
    pts = validation.points("curve", curve)
    if pts.ndim != 2 or pts.shape[0] < 2:
        raise SurveilValueError(f"curve has shape {pts.shape}: expected (k, 2) with k >= 2")
    lo = validation.real("escapable_from", escapable_from)
    hi = validation.real("escapable_to", escapable_to)
    a, b = pts[:-1], pts[1:]
    ab = b - a
    len2 = np.einsum("ij,ij->i", ab, ab)
    t = np.clip(np.einsum("ij,ij->i", e - a, ab) / np.where(len2 > 0, len2, 1.0), 0.0, 1.0)
    foot = a + t[:, None] * ab
    best = foot[int(np.argmin(np.hypot(*(foot - e).T)))]
    return _make("critical_curve", best, hi, lo, e, p, L)
