"""Exact free orientations of a rod at a point (THEORY.md 1.3, "exact free arcs").

Notation (one meaning per letter, project-wide): E is the evader, the rod's reference end
(THEORY.md section 0 calls it P), and P = E + L (cos theta, sin theta) is the pursuer
(THEORY.md's Q). For the evader end E and rod length L:

1. clip every wall edge to the closed disk |X - E| <= L (a quadratic in the edge
   parameter), giving a sub-segment [a', b'] or nothing;
2. that sub-segment blocks the short angular arc between atan2(a' - E) and atan2(b' - E);
3. the union of those arcs, complemented on the circle, is the set of free orientations;
4. each free arc's ends are labelled by the clipped endpoint that bounds them: an original
   vertex strictly inside the disk is ("body", vertex), a vertex on the circle is
   ("tip", vertex), a clipped point on the circle is ("tip", edge).

Degenerate cases, decided with the kernel's length tolerance ``eps``:

* Blocked arcs of zero width (an edge tangent to the circle, a vertex exactly on the
  circle whose edges leave the disk, an edge seen end-on) are contacts, not obstacles:
  they do not split a free arc. Free arcs narrower than ``ANGLE_TOL`` are dropped, so a
  configuration pinched to a single orientation (exactly on a type-3 curve) has no arc.
* E on a wall (a type-0 point): the obstacle side is blocked. On an edge interior that
  is the closed half circle behind the edge; at a vertex, the closed wedge the obstacle
  occupies there. The arcs next to it end in ("body", edge) stops, the rod lying along
  the wall. Edges through E are not clipped (their angle at E is undefined).
* E outside the closed free region: no free orientation (an empty tuple).
* A wall vertex inside the disk ends the blocks of both its edges: its angle is computed
  once, from the vertex's own coordinates, for both. The end of an edge computed as
  ``start + length * direction`` rounds an ulp or so away from the vertex, which seen
  from a point within ~1e-4 of it is more than ``ANGLE_TOL`` and opened a spurious free
  arc between the two blocks, one that depended on the frame (issue 10).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from envs.geometry.types import TWO_PI, Arc, FreeArcs, Stop, wrap_angle
from envs.tolerances import ANGLE_TOL

if TYPE_CHECKING:
    from envs.geometry.kernel import Kernel

__all__ = ["free_arcs_at"]


def free_arcs_at(kernel: Kernel, ex: float, ey: float, L: float) -> FreeArcs:
    """Free orientations of a rod of length ``L`` whose evader end is at E = (ex, ey).

    Args:
        kernel: the map's geometry kernel.
        ex: x of E.
        ey: y of E.
        L: rod length, > 0.

    Returns:
        The :class:`FreeArcs` at E.
    """
    E = np.array([ex, ey])
    eps = kernel.eps
    if L > kernel.map.diameter + eps:
        # P = E + L u lies outside the map whatever u: nothing is free (what the clipping
        # below finds too, up to L ~ 1e154, where squaring L overflowed)
        return FreeArcs(E, float(L), ())
    r = L + eps
    cand = kernel._edges_near_box(ex - r, ey - r, ex + r, ey + r)
    if len(cand) > kernel.numpy_threshold:
        if not isinstance(cand, np.ndarray):
            cand = np.fromiter(cand, dtype=np.intp, count=len(cand))
        blocks = _blocked_numpy(kernel, cand, ex, ey, L)
    else:
        blocks = _blocked_scalar(
            kernel, cand.tolist() if isinstance(cand, np.ndarray) else cand, ex, ey, L
        )
    if blocks is None:  # E outside the closed free region
        return FreeArcs(E, float(L), ())
    lo, wid, lab_lo, lab_hi = blocks
    if not lo:
        return FreeArcs(E, float(L), (Arc(-math.pi, math.pi, None, None),))
    return FreeArcs(E, float(L), _complement(lo, wid, lab_lo, lab_hi))


Blocks = tuple[list[float], list[float], list[Stop], list[Stop]]


def _label(
    kernel: Kernel, at_vertex: bool, v: int, e: int, dist_v: float, L: float, eps: float
) -> Stop:
    """Stop label of a clipped edge end (THEORY.md 1.3 step 4)."""
    if not at_vertex:
        return kernel._tip_edge[e]
    if abs(dist_v - L) <= eps:
        return kernel._tip_vertex[v]
    return kernel._body_vertex[v]


def _on_wall_blocks(
    kernel: Kernel, ex: float, ey: float, on_edges: list[int]
) -> tuple[Blocks, set[int]]:
    """Blocked arcs for E on a wall (type 0), and the edges through E they replace."""
    m = kernel.map
    eps = kernel.eps
    lo: list[float] = []
    wid: list[float] = []
    lab_lo: list[Stop] = []
    lab_hi: list[Stop] = []
    skip: set[int] = set()
    ev = m.edge_vertices
    for e in on_edges:  # E at a vertex of an edge through it: the obstacle's wedge there
        for v in (int(ev[e, 0]), int(ev[e, 1])):
            vx, vy = kernel._vxy[v]
            e_in = int(m.vertex_prev_edge[v])
            e_out = int(m.vertex_next_edge[v])
            if e_in in skip or math.hypot(vx - ex, vy - ey) > eps:
                continue
            skip.update((e_in, e_out))
            a = math.atan2(-kernel._dirs[e_in][1], -kernel._dirs[e_in][0])
            b = math.atan2(kernel._dirs[e_out][1], kernel._dirs[e_out][0])
            lo.append(a)
            wid.append((b - a) % TWO_PI)
            lab_lo.append(kernel._body_edge[e_in])
            lab_hi.append(kernel._body_edge[e_out])
    for e in on_edges:  # E inside an edge: the closed half circle behind it
        if e in skip:
            continue
        skip.add(e)
        ux, uy, _ = kernel._dirs[e]
        lo.append(math.atan2(uy, ux) + math.pi)
        wid.append(math.pi)
        lab_lo.append(kernel._body_edge[e])
        lab_hi.append(kernel._body_edge[e])
    return (lo, wid, lab_lo, lab_hi), skip


def _blocked_scalar(kernel: Kernel, cand, ex: float, ey: float, L: float) -> Blocks | None:
    """Blocked arcs of the candidate edges, one edge at a time (few candidates)."""
    eps = kernel.eps
    recs, dirs, vxy = kernel._recs, kernel._dirs, kernel._vxy
    r2 = (L + eps) ** 2
    near: list[tuple[int, float, float, float, float, float]] = []
    on_edges: list[int] = []
    for e in cand:
        ax, ay = recs[e][0], recs[e][1]
        ux, uy, length = dirs[e]
        wx, wy = ax - ex, ay - ey
        s = -(wx * ux + wy * uy)  # projection of E on the edge's line
        sc = 0.0 if s < 0.0 else (length if s > length else s)
        cx, cy = wx + sc * ux, wy + sc * uy
        d2 = cx * cx + cy * cy
        if d2 > r2:
            continue
        if d2 <= eps * eps:
            on_edges.append(e)
        else:
            near.append((e, wx, wy, ux, uy, s))
    if on_edges:
        (lo, wid, lab_lo, lab_hi), skip = _on_wall_blocks(kernel, ex, ey, on_edges)
    else:
        if not kernel._contains(ex, ey):
            return None
        lo, wid, lab_lo, lab_hi, skip = [], [], [], [], set()
    ev = kernel.map.edge_vertices
    LL = L * L
    for e, wx, wy, ux, uy, s in near:
        if e in skip:
            continue
        length = dirs[e][2]
        ww = wx * wx + wy * wy
        disc = s * s - (ww - LL)  # |w + t u|^2 = L^2, t in [0, length]
        if disc < 0.0:
            continue
        sq = math.sqrt(disc)
        t0 = s - sq
        t1 = s + sq
        t0 = 0.0 if t0 < 0.0 else t0
        inside_b = t1 >= length  # the edge's end vertex lies in the disk
        t1 = length if inside_b else t1
        if t0 > t1:
            continue
        ang_a = math.atan2(wy + t0 * uy, wx + t0 * ux)
        if inside_b:  # from the vertex itself, as the next edge's start
            vb = int(ev[e, 1])
            ang_b = math.atan2(vxy[vb][1] - ey, vxy[vb][0] - ex)
        else:
            ang_b = math.atan2(wy + t1 * uy, wx + t1 * ux)
        w = (ang_b - ang_a) % TWO_PI
        flip = w > math.pi  # E behind the edge's line: the short arc runs b' -> a'
        if flip:
            w = TWO_PI - w
        if w <= ANGLE_TOL:  # zero width: a contact (tangency), not a block
            continue
        la = _label(kernel, t0 <= eps, e, e, math.sqrt(ww), L, eps)
        if t1 >= length - eps:
            vb = int(ev[e, 1])
            lb = _label(kernel, True, vb, e, math.hypot(vxy[vb][0] - ex, vxy[vb][1] - ey), L, eps)
        else:
            lb = kernel._tip_edge[e]
        if flip:
            lo.append(ang_b)
            lab_lo.append(lb)
            lab_hi.append(la)
        else:
            lo.append(ang_a)
            lab_lo.append(la)
            lab_hi.append(lb)
        wid.append(w)
    return lo, wid, lab_lo, lab_hi


def _blocked_numpy(
    kernel: Kernel, idx: np.ndarray, ex: float, ey: float, L: float
) -> Blocks | None:
    """Blocked arcs of the candidate edges, vectorised (many candidates)."""
    m = kernel.map
    eps = kernel.eps
    a = m.edge_start[idx]
    u = m.edge_dir[idx]
    length = m.edge_length[idx]
    wx = a[:, 0] - ex
    wy = a[:, 1] - ey
    s = -(wx * u[:, 0] + wy * u[:, 1])
    sc = np.clip(s, 0.0, length)
    dist = np.hypot(wx + sc * u[:, 0], wy + sc * u[:, 1])
    keep = dist <= L + eps
    on = keep & (dist <= eps)
    if on.any():
        (lo, wid, lab_lo, lab_hi), skip = _on_wall_blocks(kernel, ex, ey, idx[on].tolist())
        keep &= ~on & ~np.isin(idx, list(skip))
    else:
        if not kernel._contains(ex, ey):
            return None
        lo, wid, lab_lo, lab_hi = [], [], [], []
    idx, wx, wy, u, length, s = idx[keep], wx[keep], wy[keep], u[keep], length[keep], s[keep]
    ww = wx * wx + wy * wy
    disc = s * s - (ww - L * L)
    ok = disc >= 0.0
    sq = np.sqrt(np.where(ok, disc, 0.0))
    t0 = np.maximum(s - sq, 0.0)
    t1 = np.minimum(s + sq, length)
    ok &= t0 <= t1
    ang_a = np.arctan2(wy + t0 * u[:, 1], wx + t0 * u[:, 0])
    vb_all = m.edge_vertices[idx, 1]
    end = m.vertices[vb_all]
    ang_b = np.where(  # an end vertex in the disk: from the vertex itself (see above)
        t1 == length,
        np.arctan2(end[:, 1] - ey, end[:, 0] - ex),
        np.arctan2(wy + t1 * u[:, 1], wx + t1 * u[:, 0]),
    )
    w = (ang_b - ang_a) % TWO_PI
    flip = w > math.pi
    w = np.where(flip, TWO_PI - w, w)
    start = np.where(flip, ang_b, ang_a)
    sel = np.flatnonzero(ok & (w > ANGLE_TOL))
    if len(sel) == 0:
        return lo, wid, lab_lo, lab_hi
    vb = vb_all[sel]
    db = np.hypot(m.vertices[vb, 0] - ex, m.vertices[vb, 1] - ey)
    for k, j in enumerate(sel.tolist()):
        e = int(idx[j])
        la = _label(kernel, bool(t0[j] <= eps), e, e, math.sqrt(ww[j]), L, eps)
        if t1[j] >= length[j] - eps:
            lb = _label(kernel, True, int(vb[k]), e, float(db[k]), L, eps)
        else:
            lb = kernel._tip_edge[e]
        if flip[j]:
            la, lb = lb, la
        lab_lo.append(la)
        lab_hi.append(lb)
    lo.extend(start[sel].tolist())
    wid.extend(w[sel].tolist())
    return lo, wid, lab_lo, lab_hi


_PRIORITY = {("body", "edge"): 0, ("body", "vertex"): 1, ("tip", "vertex"): 2, ("tip", "edge"): 3}


def _best(labels: list[Stop]) -> Stop:
    """The label to report when several blocked arcs end at the same angle.

    Ties are structural (the rod touches two features at once, e.g. E exactly on a type-5
    curve, or on a wall next to a vertex), so the choice must not depend on rounding:
    the rod along the wall under E, then a body contact, then a tip contact, then the
    lowest feature index.
    """
    return min(labels, key=lambda st: (_PRIORITY[st.kind, st.feature.kind], st.feature.index))


def _complement(
    lo: list[float], wid: list[float], lab_lo: list[Stop], lab_hi: list[Stop]
) -> tuple[Arc, ...]:
    """Complement a union of closed blocked arcs ``[lo, lo + wid]`` on the circle.

    The circle is cut at the start ``c`` of a blocked arc; arcs that wrap past the cut
    also cover ``[0, hi - 2 pi]`` after it. A sweep in order of start angle then finds
    the gaps; each free arc takes its stops from the blocked arcs that end (start) within
    ``ANGLE_TOL`` of its start (end).
    """
    if max(wid) >= TWO_PI - ANGLE_TOL:
        return ()
    first = min(range(len(lo)), key=lo.__getitem__)
    c = lo[first]
    items = []
    for i, (a, w) in enumerate(zip(lo, wid, strict=True)):
        rel = 0.0 if i == first else (a - c) % TWO_PI
        items.append((rel, rel + w, i))
        if rel + w > TWO_PI:
            items.append((rel - TWO_PI, rel + w - TWO_PI, i))
        if rel <= ANGLE_TOL:  # the arcs starting at the cut again, one turn on: all of
            # them, so that the labels do not depend on which came first in the list
            items.append((TWO_PI + rel, TWO_PI + rel + w, i))
    items.sort()
    gaps = []
    cmax = -math.inf
    for rel, hi, _ in items:
        if cmax > -math.inf and rel - cmax > ANGLE_TOL:
            gaps.append((cmax, rel))
        cmax = max(cmax, hi)
    arcs = []
    for start, end in gaps:
        stop_lo = _best([lab_hi[i] for _, h, i in items if abs(h - start) <= ANGLE_TOL])
        stop_hi = _best([lab_lo[i] for r, _, i in items if abs(r - end) <= ANGLE_TOL])
        arcs.append(_arc(c, start, end, stop_lo, stop_hi))
    arcs.sort(key=lambda arc: arc.lo)
    return tuple(arcs)


def _arc(c: float, start: float, end: float, stop_lo: Stop, stop_hi: Stop) -> Arc:
    lo = wrap_angle(c + start)
    return Arc(lo, lo + (end - start), stop_lo, stop_hi)
