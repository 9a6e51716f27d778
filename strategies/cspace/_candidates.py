"""Candidate critical curves of types 1-5 (THEORY.md 1.2), before the semi-free clip.

Each candidate is an exact curve (:mod:`strategies.cspace._shapes`) with a parameter
interval, the wall edges within reach of its rod (a spatial index query, so the work is
proportional to the pairs of features within L, not to the square of the map's size),
and the parameters at which the rod's contact with the walls can change, its
*breakpoints*, all in closed form or polished to double precision:

* types 1, 3, 4 translate a rod of fixed direction: the rod meets a new wall feature
  when it passes a wall vertex or when an end crosses a wall edge;
* type 2 rotates the rod about its tip at a vertex: the vertices within L of it and the
  circle's crossings with the walls;
* type 5 (the conchoid) passes the rod through a convex vertex v with its tip on an
  edge: the lines through v and another vertex, the lines of v's two edges (where the
  rod stops being tangent to the corner), and the evader end crossing a wall (a quartic,
  solved by :func:`~strategies.cspace._intersect.sampled_roots`).

Between consecutive breakpoints the rod is semi-free throughout or nowhere, so the clip
(:mod:`strategies.cspace.curves`) tests one point per sub-interval and the pieces end
exactly at breakpoints, i.e. exactly on the curves those contacts define.
"""

from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass

import numpy as np
import shapely
from scipy.spatial import cKDTree

from envs.maps.map import Feature, Map
from strategies.cspace._intersect import conchoid_samples, sampled_roots
from strategies.cspace._rod import wedge_interior
from strategies.cspace._shapes import ARC, CONCHOID, SEGMENT, points

__all__ = ["CONCHOID_SAMPLES", "Candidates", "candidates", "wall_index"]

CONCHOID_SAMPLES = 24
"""Samples per conchoid and per parametrisation when solving for its wall crossings."""

TWO_PI = 2.0 * math.pi


@dataclass
class Candidates:
    """Candidate curves of types 1-5 for one rod length.

    Attributes:
        type: (m,) curve types.
        kind: (m,) shape codes.
        data: (m, 6) exact shape data.
        t0, t1: (m,) parameter intervals.
        features: per candidate, its defining wall features.
        near_c, near_e: pairs (candidate, wall edge) of edges within reach of the rod,
            sorted by candidate.
        break_c, break_t: breakpoints (candidate, parameter).
    """

    type: np.ndarray
    kind: np.ndarray
    data: np.ndarray
    t0: np.ndarray
    t1: np.ndarray
    features: list[tuple[Feature, ...]]
    near_c: np.ndarray
    near_e: np.ndarray
    break_c: np.ndarray
    break_t: np.ndarray

    def __len__(self) -> int:
        return len(self.type)


class WallIndex:
    """Spatial indexes of a map's walls: an STRtree of edges, a KD-tree of convex vertices."""

    def __init__(self, world: Map) -> None:
        self.tree = shapely.STRtree(
            shapely.linestrings(np.stack([world.edge_start, world.edge_end], axis=1))
        )
        self.convex = world.convex_vertices
        self.convex_tree = cKDTree(world.vertices[self.convex]) if len(self.convex) else None

    def edges_in_boxes(self, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Pairs (box, edge) of edges meeting boxes ``[lo, hi]``, sorted by box."""
        if len(lo) == 0:
            return np.zeros(0, dtype=np.intp), np.zeros(0, dtype=np.intp)
        boxes = shapely.box(lo[:, 0], lo[:, 1], hi[:, 0], hi[:, 1])
        b, e = self.tree.query(boxes)
        order = np.lexsort((e, b))
        return b[order].astype(np.intp), e[order].astype(np.intp)

    def edges_within(self, pts: np.ndarray, r: float) -> tuple[np.ndarray, np.ndarray]:
        """Pairs (point, edge) with the edge within ``r`` of the point."""
        if len(pts) == 0:
            return np.zeros(0, dtype=np.intp), np.zeros(0, dtype=np.intp)
        p, e = self.tree.query(shapely.points(pts), predicate="dwithin", distance=r)
        order = np.lexsort((e, p))
        return p[order].astype(np.intp), e[order].astype(np.intp)


_INDEX: dict[tuple[str, bytes], WallIndex] = {}


def wall_index(world: Map) -> WallIndex:
    """The :class:`WallIndex` of ``world`` (cached for the few most recent maps)."""
    key = (world.digest, hashlib.blake2b(world.vertices.tobytes(), digest_size=16).digest())
    idx = _INDEX.get(key)
    if idx is None:
        if len(_INDEX) >= 8:
            _INDEX.pop(next(iter(_INDEX)))
        idx = _INDEX[key] = WallIndex(world)
    return idx


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def _pairs_of(kind_a: str, a: np.ndarray, kind_b: str, b: np.ndarray) -> list:
    return [(Feature(kind_a, int(x)), Feature(kind_b, int(y))) for x, y in zip(a, b, strict=True)]


def _pad(rows: np.ndarray) -> np.ndarray:
    out = np.zeros((len(rows), 6))
    out[:, : rows.shape[1]] = rows
    return out


def _box_of(points: list[np.ndarray], pad: float) -> tuple[np.ndarray, np.ndarray]:
    stack = np.stack(points, axis=0)
    return stack.min(axis=0) - pad, stack.max(axis=0) + pad


# ------------------------------------------------------------------ breakpoint kernels
def _line_crossings(world: Map, o, d, f, eps: float) -> tuple[np.ndarray, np.ndarray]:
    """Parameters ``lam`` where lines ``o + lam d`` meet wall edges ``f`` (pairs), plus the
    edges' start vertices lying on the lines. Returns (pair index, lam)."""
    a = world.edge_start[f]
    fv = world.edge_end[f] - a
    den = _cross(d, fv)
    r = a - o
    flen = world.edge_length[f]
    ok = np.abs(den) > 1e-14 * flen
    with np.errstate(divide="ignore", invalid="ignore"):
        lam = _cross(r, fv) / den
        mu = _cross(r, d) / den
    tol = eps / flen
    hit = np.flatnonzero(ok & (mu >= -tol) & (mu <= 1.0 + tol))
    on = np.flatnonzero(np.abs(_cross(d, r)) <= eps)
    return np.concatenate([hit, on]), np.concatenate([lam[hit], (r * d).sum(axis=1)[on]])


def _type1(world: Map, L: float, eps: float, index: WallIndex):
    n = world.n_edges
    a, b, u, nrm = world.edge_start, world.edge_end, world.edge_dir, world.edge_normal
    o = a + L * nrm
    theta = np.arctan2(-nrm[:, 1], -nrm[:, 0])
    data = _pad(np.column_stack([o, u, theta]))
    lo, hi = _box_of([a, b, o, b + L * nrm], eps)
    c, f = index.edges_in_boxes(lo, hi)
    k, lam = _line_crossings(world, o[c], u[c], f, eps)
    rel = world.edge_start[f] - a[c]
    h = (rel * nrm[c]).sum(axis=1)
    strip = np.flatnonzero((h >= -eps) & (h <= L + eps))
    bc = np.concatenate([c[k], c[strip]])
    bt = np.concatenate([lam, (rel * u[c]).sum(axis=1)[strip]])
    feats = [(Feature("edge", e),) for e in range(n)]
    return (
        np.full(n, 1),
        np.full(n, SEGMENT),
        data,
        np.zeros(n),
        world.edge_length.copy(),
        feats,
        (c, f),
        (bc, bt),
    )


def _free_wedges(world: Map) -> tuple[np.ndarray, np.ndarray]:
    """Per vertex: start angle and span of the free directions (CCW from d_out)."""
    d_in = world.edge_dir[world.vertex_prev_edge]
    d_out = world.edge_dir[world.vertex_next_edge]
    start = np.arctan2(d_out[:, 1], d_out[:, 0])
    span = (np.arctan2(-d_in[:, 1], -d_in[:, 0]) - start) % TWO_PI
    return start, span


def _type2(world: Map, L: float, eps: float, index: WallIndex):
    nv = world.n_vertices
    v = world.vertices
    start, span = _free_wedges(world)
    data = _pad(np.column_stack([v, np.full(nv, L)]))
    c, f = index.edges_in_boxes(v - (L + eps), v + (L + eps))
    # circle crossings with the edges
    a = world.edge_start[f] - v[c]
    uu = world.edge_dir[f]
    s = -(a * uu).sum(axis=1)
    disc = s * s - ((a * a).sum(axis=1) - L * L)
    ok = disc >= 0
    sq = np.sqrt(np.where(ok, disc, 0.0))
    bc, ba = [], []
    for root in (s - sq, s + sq):
        m = np.flatnonzero(ok & (root >= -eps) & (root <= world.edge_length[f] + eps))
        p = a[m] + root[m, None] * uu[m]
        bc.append(c[m])
        ba.append(np.arctan2(p[:, 1], p[:, 0]))
    # vertices within L
    w = world.edge_start[f] - v[c]
    dist = np.hypot(w[:, 0], w[:, 1])
    m = np.flatnonzero((dist > eps) & (dist <= L + eps))
    bc.append(c[m])
    ba.append(np.arctan2(w[m, 1], w[m, 0]))
    bc = np.concatenate(bc)
    ang = np.concatenate(ba)
    bt = start[bc] + (ang - start[bc]) % TWO_PI
    feats = [(Feature("vertex", i),) for i in range(nv)]
    return (
        np.full(nv, 2),
        np.full(nv, ARC),
        data,
        start.copy(),
        start + span,
        feats,
        (c, f),
        (bc, bt),
    )


def _sliding(world: Map, L: float, eps: float, index: WallIndex, o, e, T):
    """Near edges and breakpoints of rods sliding along their line: ``P(t) = o - t e``,
    tip at ``o + (L - t) e``, ``t`` in ``[0, T]``."""
    lo, hi = _box_of([o - T[:, None] * e, o + L * e], eps)
    c, f = index.edges_in_boxes(lo, hi)
    k, lam = _line_crossings(world, o[c], e[c], f, eps)
    bc = np.concatenate([c[k], c[k]])
    bt = np.concatenate([-lam, L - lam])
    return (c, f), (bc, bt)


def _type4(world: Map, L: float, eps: float, index: WallIndex):
    cv = world.convex_vertices
    vs = np.concatenate([cv, cv])
    edges = np.concatenate([world.vertex_prev_edge[cv], world.vertex_next_edge[cv]])
    ev = world.edge_vertices[edges]
    other = np.where(ev[:, 1] == vs, ev[:, 0], ev[:, 1])
    e = world.vertices[other] - world.vertices[vs]
    e /= np.hypot(e[:, 0], e[:, 1])[:, None]
    o = world.vertices[vs]
    m = len(vs)
    data = _pad(np.column_stack([o, -e, np.arctan2(e[:, 1], e[:, 0])]))
    near, brk = _sliding(world, L, eps, index, o, e, np.full(m, L))
    feats = _pairs_of("vertex", vs, "edge", edges)
    return np.full(m, 4), np.full(m, SEGMENT), data, np.zeros(m), np.full(m, L), feats, near, brk


def _type3(world: Map, L: float, eps: float, index: WallIndex):
    cv = index.convex
    empty = (np.zeros(0, dtype=int),) * 2
    if index.convex_tree is None or len(cv) < 2:
        return (
            np.zeros(0, int),
            np.zeros(0, int),
            np.zeros((0, 6)),
            np.zeros(0),
            np.zeros(0),
            [],
            empty,
            (np.zeros(0, int), np.zeros(0)),
        )
    pairs = index.convex_tree.query_pairs(L, output_type="ndarray")
    ij = np.concatenate([pairs, pairs[:, ::-1]]) if len(pairs) else np.zeros((0, 2), int)
    i, j = cv[ij[:, 0]], cv[ij[:, 1]]
    rel = world.vertices[j] - world.vertices[i]
    d = np.hypot(rel[:, 0], rel[:, 1])
    ev = world.edge_vertices
    adj = (ev[world.vertex_next_edge[i], 1] == j) | (ev[world.vertex_prev_edge[i], 0] == j)
    keep = (d > eps) & (d < L) & ~adj
    i, j, rel, d = i[keep], j[keep], rel[keep], d[keep]
    e = rel / d[:, None]
    tangent = ~(
        wedge_interior(world, i, e)
        | wedge_interior(world, i, -e)
        | wedge_interior(world, j, e)
        | wedge_interior(world, j, -e)
    )
    i, j, e, d = i[tangent], j[tangent], e[tangent], d[tangent]
    o = world.vertices[i]
    m = len(i)
    data = _pad(np.column_stack([o, -e, np.arctan2(e[:, 1], e[:, 0])]))
    near, brk = _sliding(world, L, eps, index, o, e, L - d)
    feats = _pairs_of("vertex", i, "vertex", j)
    return np.full(m, 3), np.full(m, SEGMENT), data, np.zeros(m), L - d, feats, near, brk


def _arc_overlap(a0, aspan, b0, bspan) -> np.ndarray:
    """Whether circular arcs ``[a0, a0 + aspan]`` and ``[b0, b0 + bspan]`` meet."""
    d = (b0 - a0) % TWO_PI
    return (d <= aspan) | (d + bspan >= TWO_PI)


def _type5(world: Map, L: float, eps: float, index: WallIndex):
    cv = index.convex
    pv_idx, e = index.edges_within(world.vertices[cv], L)
    v = cv[pv_idx]
    pv = world.vertices[v]
    a, u, nrm = world.edge_start[e], world.edge_dir[e], world.edge_normal[e]
    h = ((pv - a) * nrm).sum(axis=1)
    cc = ((pv - a) * u).sum(axis=1)
    half = np.sqrt(np.maximum(L * L - h * h, 0.0))
    s0 = np.maximum(0.0, cc - half)
    s1 = np.minimum(world.edge_length[e], cc + half)
    incident = (world.vertex_prev_edge[v] == e) | (world.vertex_next_edge[v] == e)
    keep = ~incident & (h > eps) & (h < L) & (s1 - s0 > eps)
    # the rod must pass v tangentially for some tip on [s0, s1]: the directions from v
    # to the tips must meet the free double wedge at v (outside the obstacle's wedge W
    # and its opposite -W)
    d_in = world.edge_dir[world.vertex_prev_edge[v]]
    d_out = world.edge_dir[world.vertex_next_edge[v]]
    w_start = np.arctan2(-d_in[:, 1], -d_in[:, 0])
    w_span = (np.arctan2(d_out[:, 1], d_out[:, 0]) - w_start) % TWO_PI
    q0 = a + s0[:, None] * u - pv
    q1 = a + s1[:, None] * u - pv
    g0 = np.arctan2(q0[:, 1], q0[:, 0])
    g1 = np.arctan2(q1[:, 1], q1[:, 0])
    sweep = (g1 - g0) % TWO_PI
    back = sweep > math.pi
    g_lo = np.where(back, g1, g0)
    g_span = np.where(back, TWO_PI - sweep, sweep)
    free_span = math.pi - w_span
    feasible = _arc_overlap(g_lo, g_span, w_start + w_span, free_span) | _arc_overlap(
        g_lo, g_span, w_start + w_span + math.pi, free_span
    )
    keep &= feasible
    v, e, pv, a, u, s0, s1 = v[keep], e[keep], pv[keep], a[keep], u[keep], s0[keep], s1[keep]
    m = len(v)
    data = _pad(np.column_stack([pv, a, u]))
    c, f = index.edges_in_boxes(pv - (L + eps), pv + (L + eps))
    # vertex passes: the line through v and w meets the edge's line
    w = world.edge_start[f] - pv[c]
    dist = np.hypot(w[:, 0], w[:, 1])
    den = _cross(u[c], w)
    pas = np.flatnonzero((dist > eps) & (dist <= L + eps) & (np.abs(den) > 1e-14 * dist))
    s_pass = _cross(pv[c] - a[c], w)[pas] / den[pas]
    # the rod along one of v's edges: it stops (or starts) being tangent to the corner
    sides_c, sides_s = [], []
    for e_side in (world.vertex_prev_edge[v], world.vertex_next_edge[v]):
        dd = world.edge_dir[e_side]
        den2 = _cross(u, dd)
        ok = np.flatnonzero(np.abs(den2) > 1e-14)
        sides_c.append(ok)
        sides_s.append(_cross(pv - a, dd)[ok] / den2[ok])
    # the evader end crossing a wall: zeros of the signed distance of P(s) to the wall's line
    owner, ts = conchoid_samples(data[c], s0[c], s1[c], CONCHOID_SAMPLES)
    fl = world.edge_length[f]
    line = _pad(np.column_stack([world.edge_start[f], world.edge_dir[f], np.zeros(len(f))]))
    pair, troot, _ = sampled_roots(
        np.full(len(c), CONCHOID), data[c], owner, ts, np.full(len(c), SEGMENT), line, L, eps
    )
    P = points(CONCHOID, data[c[pair]], troot, L)
    along = ((P - world.edge_start[f[pair]]) * world.edge_dir[f[pair]]).sum(axis=1)
    on = (along >= -eps) & (along <= fl[pair] + eps)
    bc = np.concatenate([c[pas], *sides_c, c[pair[on]]])
    bt = np.concatenate([s_pass, *sides_s, troot[on]])
    feats = _pairs_of("vertex", v, "edge", e)
    return np.full(m, 5), np.full(m, CONCHOID), data, s0, s1, feats, (c, f), (bc, bt)


def candidates(world: Map, L: float, eps: float) -> Candidates:
    """All candidate curves of types 1-5 for rod length ``L`` (before the clip).

    Args:
        world: the map.
        L: rod length.
        eps: the kernel's length tolerance (``REL_LENGTH_TOL * world.scale``).
    """
    index = wall_index(world)
    parts = [f(world, L, eps, index) for f in (_type1, _type2, _type3, _type4, _type5)]
    sizes = [len(p[0]) for p in parts]
    base = np.concatenate([[0], np.cumsum(sizes)[:-1]])
    near_c = np.concatenate([p[6][0] + b for p, b in zip(parts, base, strict=True)])
    near_e = np.concatenate([p[6][1] for p in parts])
    order = np.argsort(near_c, kind="stable")
    return Candidates(
        type=np.concatenate([p[0] for p in parts]).astype(np.int64),
        kind=np.concatenate([p[1] for p in parts]).astype(np.int64),
        data=np.concatenate([p[2] for p in parts]),
        t0=np.concatenate([p[3] for p in parts]).astype(float),
        t1=np.concatenate([p[4] for p in parts]).astype(float),
        features=[f for p in parts for f in p[5]],
        near_c=near_c[order].astype(np.intp),
        near_e=near_e[order].astype(np.intp),
        break_c=np.concatenate([p[7][0] + b for p, b in zip(parts, base, strict=True)]).astype(
            np.intp
        ),
        break_t=np.concatenate([p[7][1] for p in parts]).astype(float),
    )
