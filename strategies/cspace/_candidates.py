"""Candidate critical curves of types 1-5 (THEORY.md 1.2), before the semi-free clip.

Each candidate is an exact parametric curve ``P(t)`` with the contact orientation
``theta(t)`` of the rod there, a parameter interval, and the parameter values at which the
rod's contact with the walls can change (its *breakpoints*). Between consecutive
breakpoints the rod is either semi-free throughout or nowhere, so the clip in
:mod:`strategies.cspace.curves` tests one point per sub-interval:

* types 1, 3, 4 translate a rod of fixed direction: the rod meets a new wall feature when
  it passes a wall vertex or when an end crosses a wall edge, both solved exactly;
* type 2 rotates the rod about its tip at a vertex: vertices within L of it and the
  circle's crossings with the walls, exact;
* type 5 (the conchoid) passes the rod through a convex vertex: vertex passes are exact,
  the evader end crossing a wall is found on a grid and refined by bisection.

Shapes (``_Cand.shape``) and their exact data:

* ``"segment"``: ``P(t) = o + t d`` (``d`` unit), constant ``theta``; data
  ``(ox, oy, dx, dy, theta)``.
* ``"arc"``: ``P(psi) = c + R (cos psi, sin psi)``, the rod pointing at the centre,
  ``theta = psi + pi``; data ``(cx, cy, R)``.
* ``"conchoid"``: tip ``Q(s) = a + s u`` on an edge, the rod through vertex ``v``:
  ``P = Q + L (v - Q)/|v - Q|``, ``theta = atan2(Q - P)``; data ``(vx, vy, ax, ay, ux, uy)``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from envs.maps.map import Feature, Map
from envs.tolerances import REL_LENGTH_TOL
from strategies.cspace._rod import wedge_interior

__all__ = ["CONCHOID_GRID", "candidates", "evaluate"]

CONCHOID_GRID = 48
"""Uniform samples per conchoid where the evader end may cross a wall (then bisected)."""

TWO_PI = 2.0 * math.pi


@dataclass
class _Cand:
    type: int
    features: tuple[Feature, ...]
    shape: str
    data: tuple[float, ...]
    t0: float
    t1: float
    breaks: np.ndarray
    grid: int = 0
    specials: tuple[float, ...] = field(default=())


def evaluate(
    shape: str, data: np.ndarray, t: np.ndarray, L: float
) -> tuple[np.ndarray, np.ndarray]:
    """Evader end P and contact orientation theta at parameters ``t``.

    Args:
        shape: ``"segment"``, ``"arc"`` or ``"conchoid"``.
        data: (k, m) per-sample exact data (see the module docstring), or (m,).
        t: (k,) parameters.
        L: rod length.

    Returns:
        ``(P (k, 2), theta (k,))``.
    """
    t = np.asarray(t, dtype=float).reshape(-1)
    data = np.broadcast_to(np.asarray(data, dtype=float), (len(t), np.shape(data)[-1]))
    if shape == "segment":
        P = data[:, 0:2] + t[:, None] * data[:, 2:4]
        return P, data[:, 4].copy()
    if shape == "arc":
        P = data[:, 0:2] + data[:, 2:3] * np.stack([np.cos(t), np.sin(t)], axis=1)
        return P, t + math.pi
    if shape == "conchoid":
        v, a, u = data[:, 0:2], data[:, 2:4], data[:, 4:6]
        Q = a + t[:, None] * u
        d = v - Q
        d /= np.hypot(d[:, 0], d[:, 1])[:, None]
        return Q + L * d, np.arctan2(-d[:, 1], -d[:, 0])
    raise ValueError(f"unknown curve shape {shape!r}")


# ------------------------------------------------------------------------ helpers
def _line_wall_params(world: Map, o: np.ndarray, d: np.ndarray, eps: float) -> np.ndarray:
    """Parameters ``lam`` where the line ``o + lam d`` (d unit) meets the walls."""
    c, f = world.edge_start, world.edge_end - world.edge_start
    den = d[0] * f[:, 1] - d[1] * f[:, 0]
    co = c - o
    ok = np.abs(den) > 1e-14 * world.edge_length
    with np.errstate(divide="ignore", invalid="ignore"):
        lam = (co[:, 0] * f[:, 1] - co[:, 1] * f[:, 0]) / den
        mu = (co[:, 0] * d[1] - co[:, 1] * d[0]) / den
    hit = ok & (mu >= -1e-12) & (mu <= 1.0 + 1e-12)
    w = world.vertices - o
    on = np.abs(d[0] * w[:, 1] - d[1] * w[:, 0]) <= eps
    return np.concatenate([lam[hit], w[on] @ d])


def _circle_wall_angles(world: Map, c: np.ndarray, R: float) -> np.ndarray:
    """Angles (about ``c``) where the circle of radius ``R`` meets the wall edges."""
    a = world.edge_start - c
    u = world.edge_dir
    s = -(a * u).sum(axis=1)
    disc = s * s - ((a * a).sum(axis=1) - R * R)
    ok = disc >= 0
    sq = np.sqrt(np.where(ok, disc, 0.0))
    out = []
    for root in (s - sq, s + sq):
        m = ok & (root >= 0) & (root <= world.edge_length)
        p = a[m] + root[m, None] * u[m]
        out.append(np.arctan2(p[:, 1], p[:, 0]))
    return np.concatenate(out)


def _free_wedge(world: Map, v: int) -> tuple[float, float]:
    """Start angle and span of the free directions at vertex ``v`` (CCW from d_out)."""
    d_in = world.edge_dir[world.vertex_prev_edge[v]]
    d_out = world.edge_dir[world.vertex_next_edge[v]]
    start = math.atan2(d_out[1], d_out[0])
    span = (math.atan2(-d_in[1], -d_in[0]) - start) % TWO_PI
    return start, span


def _tangent_at(world: Map, v: int, d: np.ndarray) -> bool:
    """Whether the line through vertex ``v`` along ``d`` stays out of the obstacle there."""
    dd = np.stack([d, -d])
    return not bool(wedge_interior(world, np.array([v, v]), dd).any())


# ------------------------------------------------------------------------ the types
def _type1(world: Map, L: float, eps: float) -> list[_Cand]:
    out = []
    for e in range(world.n_edges):
        a, u, n, ln = (
            world.edge_start[e],
            world.edge_dir[e],
            world.edge_normal[e],
            world.edge_length[e],
        )
        o = a + L * n
        lam = _line_wall_params(world, o, u, eps)
        rel = world.vertices - a
        h = rel @ n
        strip = (h >= -eps) & (h <= L + eps)
        breaks = np.concatenate([lam, rel[strip] @ u])
        theta = math.atan2(-n[1], -n[0])
        out.append(
            _Cand(1, (Feature("edge", e),), "segment", (*o, *u, theta), 0.0, float(ln), breaks)
        )
    return out


def _type2(world: Map, L: float, eps: float) -> list[_Cand]:
    out = []
    for v in range(world.n_vertices):
        c = world.vertices[v]
        start, span = _free_wedge(world, v)
        dist = np.hypot(*(world.vertices - c).T)
        near = (dist > eps) & (dist <= L + eps)
        ang = np.concatenate(
            [np.arctan2(*(world.vertices[near] - c).T[::-1]), _circle_wall_angles(world, c, L)]
        )
        breaks = start + (ang - start) % TWO_PI
        specials = []
        for e in (world.vertex_prev_edge[v], world.vertex_next_edge[v]):
            n = world.edge_normal[e]
            specials.append(start + (math.atan2(n[1], n[0]) - start) % TWO_PI)
        out.append(
            _Cand(
                2,
                (Feature("vertex", v),),
                "arc",
                (*c, L),
                start,
                start + span,
                breaks,
                specials=tuple(specials),
            )
        )
    return out


def _sliding(world: Map, L: float, o: np.ndarray, e: np.ndarray, eps: float) -> np.ndarray:
    """Breakpoints of a rod sliding along its line: ``P(t) = o - t e``, tip at ``L - t``."""
    lam = _line_wall_params(world, o, e, eps)
    return np.concatenate([-lam, L - lam])


def _type4(world: Map, L: float, eps: float) -> list[_Cand]:
    out = []
    for v in world.convex_vertices.tolist():
        for edge in (int(world.vertex_prev_edge[v]), int(world.vertex_next_edge[v])):
            w = world.edge_vertices[edge]
            other = int(w[0] if w[1] == v else w[1])
            e = world.vertices[other] - world.vertices[v]
            e = e / np.hypot(*e)
            o = world.vertices[v]
            theta = math.atan2(e[1], e[0])
            out.append(
                _Cand(
                    4,
                    (Feature("vertex", v), Feature("edge", edge)),
                    "segment",
                    (*o, *(-e), theta),
                    0.0,
                    L,
                    _sliding(world, L, o, e, eps),
                )
            )
    return out


def _type3(world: Map, L: float, eps: float) -> list[_Cand]:
    out = []
    cv = world.convex_vertices
    adjacent = {tuple(sorted(map(int, ev))) for ev in world.edge_vertices}
    for i in cv.tolist():
        rel = world.vertices[cv] - world.vertices[i]
        dist = np.hypot(rel[:, 0], rel[:, 1])
        for j, d in zip(cv.tolist(), dist.tolist(), strict=True):
            if j == i or d <= eps or d >= L or (min(i, j), max(i, j)) in adjacent:
                continue
            e = (world.vertices[j] - world.vertices[i]) / d
            if not (_tangent_at(world, i, e) and _tangent_at(world, j, e)):
                continue
            o = world.vertices[i]
            T = L - d
            out.append(
                _Cand(
                    3,
                    (Feature("vertex", i), Feature("vertex", j)),
                    "segment",
                    (*o, *(-e), math.atan2(e[1], e[0])),
                    0.0,
                    T,
                    _sliding(world, L, o, e, eps),
                )
            )
    return out


def _type5(world: Map, L: float, eps: float) -> list[_Cand]:
    out = []
    verts = world.vertices
    for v in world.convex_vertices.tolist():
        pv = verts[v]
        rel_v = verts - pv
        dist_v = np.hypot(rel_v[:, 0], rel_v[:, 1])
        near = np.flatnonzero((dist_v > eps) & (dist_v <= L + eps))
        incident = {int(world.vertex_prev_edge[v]), int(world.vertex_next_edge[v])}
        for e in range(world.n_edges):
            if e in incident:
                continue
            a, u, n, ln = (
                world.edge_start[e],
                world.edge_dir[e],
                world.edge_normal[e],
                world.edge_length[e],
            )
            h = float(n @ (pv - a))
            if h <= eps or h >= L:
                continue
            c = float(u @ (pv - a))
            half = math.sqrt(L * L - h * h)
            s0, s1 = max(0.0, c - half), min(float(ln), c + half)
            if s1 - s0 <= eps:
                continue
            # the rod must pass v tangentially somewhere on [s0, s1]
            ss = np.linspace(s0, s1, 9)
            dirs = pv - (a + ss[:, None] * u)
            vv = np.full(len(ss), v)
            if (wedge_interior(world, vv, dirs) | wedge_interior(world, vv, -dirs)).all():
                continue
            w = rel_v[near]
            den = w[:, 0] * u[1] - w[:, 1] * u[0]
            num = w[:, 0] * (a - pv)[1] - w[:, 1] * (a - pv)[0]
            ok = np.abs(den) > 1e-14
            breaks = -num[ok] / den[ok]
            out.append(
                _Cand(
                    5,
                    (Feature("vertex", v), Feature("edge", e)),
                    "conchoid",
                    (*pv, *a, *u),
                    s0,
                    s1,
                    breaks,
                    grid=CONCHOID_GRID,
                )
            )
    return out


def candidates(world: Map, L: float) -> list[_Cand]:
    """All candidate curves of types 1-5 for rod length ``L`` (before the clip)."""
    eps = REL_LENGTH_TOL * world.scale
    return (
        _type1(world, L, eps)
        + _type2(world, L, eps)
        + _type3(world, L, eps)
        + _type4(world, L, eps)
        + _type5(world, L, eps)
    )
