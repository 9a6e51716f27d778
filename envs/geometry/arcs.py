"""Exact free orientations of a rod at a point (THEORY.md 1.3, "exact free arcs").

For the evader end P and rod length L:

1. clip every wall edge to the closed disk |X - P| <= L (a quadratic in the edge
   parameter), giving a sub-segment [a', b'] or nothing;
2. that sub-segment blocks the short angular arc between atan2(a' - P) and atan2(b' - P);
3. the union of those arcs, complemented on the circle, is the set of free orientations;
4. each free arc's ends are labelled by the clipped endpoint that bounds them: an original
   vertex strictly inside the disk is ("body", vertex), a vertex on the circle is
   ("tip", vertex), a clipped point on the circle is ("tip", edge).

Degenerate cases, decided with the kernel's length tolerance ``eps``:

* Blocked arcs of zero width (an edge tangent to the circle, a vertex exactly on the
  circle whose edges leave the disk, an edge seen end-on) are contacts, not obstacles:
  they do not split a free arc. Free arcs narrower than ``ANGLE_TOL`` are dropped, so a
  configuration pinched to a single orientation (exactly on a type-3 curve) has no arc.
* P on a wall (a type-0 point): the obstacle side is blocked. On an edge interior that
  is the closed half circle behind the edge; at a vertex, the closed wedge the obstacle
  occupies there. The arcs next to it end in ("body", edge) stops, the rod lying along
  the wall. Edges through P are not clipped (their angle at P is undefined).
* P outside the closed free region: no free orientation (an empty tuple).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from envs.geometry.types import TWO_PI, Arc, FreeArcs, Stop, wrap_angle
from envs.maps.map import Feature
from envs.tolerances import ANGLE_TOL

if TYPE_CHECKING:
    from envs.geometry.kernel import Kernel

__all__ = ["free_arcs_at"]


def _angle(v: np.ndarray) -> np.ndarray:
    return np.arctan2(v[..., 1], v[..., 0])


def free_arcs_at(kernel: Kernel, point: np.ndarray, L: float) -> FreeArcs:
    """Free orientations of a rod of length ``L`` whose evader end is at ``point``.

    Args:
        kernel: the map's geometry kernel.
        point: P, shape (2,).
        L: rod length, > 0.

    Returns:
        The :class:`FreeArcs` at P.
    """
    m = kernel.map
    eps = kernel.eps
    P = point
    px, py = float(P[0]), float(P[1])
    # ---- candidates: edges within L (+eps) of P (bounding-box prefilter, then exact)
    r = L + eps
    idx = kernel.edges_in_box(px - r, py - r, px + r, py + r)
    a = m.edge_start[idx]
    u = m.edge_dir[idx]
    length = m.edge_length[idx]
    w = a - P
    s = -(w[:, 0] * u[:, 0] + w[:, 1] * u[:, 1])  # projection of P on the edge line
    sc = np.clip(s, 0.0, length)
    cx = w[:, 0] + sc * u[:, 0]
    cy = w[:, 1] + sc * u[:, 1]
    dist = np.hypot(cx, cy)
    keep = dist <= r
    idx, a, u, length, w, s, dist = (
        idx[keep],
        a[keep],
        u[keep],
        length[keep],
        w[keep],
        s[keep],
        dist[keep],
    )

    lo_list: list[np.ndarray] = []
    wid_list: list[np.ndarray] = []
    lab_lo: list[Stop] = []
    lab_hi: list[Stop] = []

    # ---- P on a wall (type 0): block the obstacle side, drop the edges through P
    on = dist <= eps
    if on.any():
        vd = np.hypot(m.vertices[:, 0] - px, m.vertices[:, 1] - py)
        at_vertex = np.flatnonzero(vd <= eps)
        skip: set[int] = set()
        for v in at_vertex.tolist():
            e_in = int(m.vertex_prev_edge[v])
            e_out = int(m.vertex_next_edge[v])
            skip.update((e_in, e_out))
            lo = math.atan2(-m.edge_dir[e_in, 1], -m.edge_dir[e_in, 0])
            hi = math.atan2(m.edge_dir[e_out, 1], m.edge_dir[e_out, 0])
            lo_list.append(np.array([lo]))
            wid_list.append(np.array([(hi - lo) % TWO_PI]))
            lab_lo.append(Stop("body", Feature("edge", e_in)))
            lab_hi.append(Stop("body", Feature("edge", e_out)))
        for j in np.flatnonzero(on).tolist():
            e = int(idx[j])
            if e in skip:
                continue
            alpha = math.atan2(u[j, 1], u[j, 0])
            lo_list.append(np.array([alpha + math.pi]))
            wid_list.append(np.array([math.pi]))
            lab_lo.append(Stop("body", Feature("edge", e)))
            lab_hi.append(Stop("body", Feature("edge", e)))
        off = ~on
        idx, a, u, length, w, s = idx[off], a[off], u[off], length[off], w[off], s[off]
    elif not kernel.contains_point(px, py):
        return FreeArcs(np.array(P, dtype=float), float(L), ())

    # ---- clip each edge to the closed disk: |w + t u|^2 = L^2, t in [0, length]
    ww = w[:, 0] * w[:, 0] + w[:, 1] * w[:, 1]
    disc = s * s - (ww - L * L)
    ok = disc >= 0.0
    sq = np.sqrt(np.where(ok, disc, 0.0))
    t0 = np.maximum(s - sq, 0.0)
    t1 = np.minimum(s + sq, length)
    ok &= t0 <= t1
    idx, a, u, length, t0, t1, ww = idx[ok], a[ok], u[ok], length[ok], t0[ok], t1[ok], ww[ok]
    pa = a + t0[:, None] * u - P
    pb = a + t1[:, None] * u - P
    ang_a = _angle(pa)
    ang_b = _angle(pb)
    wid = (ang_b - ang_a) % TWO_PI
    flip = wid > math.pi  # P behind the edge's line: the short arc runs b' -> a'
    lo = np.where(flip, ang_b, ang_a)
    wid = np.where(flip, TWO_PI - wid, wid)
    real = wid > ANGLE_TOL  # zero-width arcs are contacts (tangency), not blocks
    if real.any():
        sel = np.flatnonzero(real)
        lo_list.append(lo[sel])
        wid_list.append(wid[sel])
        ev = m.edge_vertices
        da = math.sqrt  # local alias
        for j in sel.tolist():
            e = int(idx[j])
            lab_a = _label(t0[j] <= eps, int(ev[e, 0]), e, da(float(ww[j])), L, eps)
            if t1[j] >= length[j] - eps:
                vb = int(ev[e, 1])
                db = math.hypot(m.vertices[vb, 0] - px, m.vertices[vb, 1] - py)
                lab_b = _label(True, vb, e, db, L, eps)
            else:
                lab_b = Stop("tip", Feature("edge", e))
            if flip[j]:
                lab_a, lab_b = lab_b, lab_a
            lab_lo.append(lab_a)
            lab_hi.append(lab_b)
    if not lo_list:
        full = Arc(-math.pi, math.pi, None, None)
        return FreeArcs(np.array(P, dtype=float), float(L), (full,))
    return FreeArcs(
        np.array(P, dtype=float),
        float(L),
        _complement(np.concatenate(lo_list), np.concatenate(wid_list), lab_lo, lab_hi),
    )


def _label(at_vertex: bool, v: int, e: int, dist_v: float, L: float, eps: float) -> Stop:
    """Stop label of a clipped edge end (THEORY.md 1.3 step 4)."""
    if not at_vertex:
        return Stop("tip", Feature("edge", e))
    if abs(dist_v - L) <= eps:
        return Stop("tip", Feature("vertex", v))
    return Stop("body", Feature("vertex", v))


def _complement(
    lo: np.ndarray, wid: np.ndarray, lab_lo: list[Stop], lab_hi: list[Stop]
) -> tuple[Arc, ...]:
    """Complement a union of closed blocked arcs ``[lo, lo + wid]`` on the circle."""
    if np.any(wid >= TWO_PI - ANGLE_TOL):
        return ()
    c = float(lo[np.argmin(lo)])  # a blocked angle: cut the circle there
    rel = (lo - c) % TWO_PI
    hi = rel + wid
    n = len(rel)
    ids = np.arange(n)
    wrap = hi > TWO_PI
    if wrap.any():  # arcs that wrap past the cut also cover [0, hi - 2 pi]
        rel = np.concatenate([rel, rel[wrap] - TWO_PI])
        hi = np.concatenate([hi, hi[wrap] - TWO_PI])
        ids = np.concatenate([ids, ids[wrap]])
    order = np.argsort(rel, kind="stable")
    rel, hi, ids = rel[order], hi[order], ids[order]
    cmax = np.maximum.accumulate(hi)
    pos = np.arange(len(hi))
    arg = np.maximum.accumulate(np.where(hi >= cmax, pos, -1))
    nxt = np.append(rel[1:], TWO_PI)
    nxt_id = np.append(ids[1:], int(np.argmin(lo)))  # the gap before 2 pi ends at the cut
    gaps = np.flatnonzero(nxt - cmax > ANGLE_TOL)
    arcs = []
    for g in gaps.tolist():
        start = c + float(cmax[g])
        end = c + float(nxt[g])
        lo_w = wrap_angle(start)
        arcs.append(
            Arc(lo_w, lo_w + (end - start), lab_hi[int(ids[arg[g]])], lab_lo[int(nxt_id[g])])
        )
    arcs.sort(key=lambda arc: arc.lo)
    return tuple(arcs)
