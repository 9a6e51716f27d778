"""Noding of the critical curves: every intersection, tangency and end-on-curve point.

The curves of one rod length (walls included, collinear overlaps already merged by
:mod:`strategies.cspace._collinear`) are intersected pairwise wherever their boxes meet
(a spatial index: the work follows the number of nearby pairs). Three kinds of points:

* crossings and tangencies, in closed form or polished roots
  (:mod:`strategies.cspace._intersect`);
* the ends of a curve that lie on another one (within the merge tolerance): a curve's
  end is where the rod gains a contact, which is a point of the curve of that contact,
  so each end is inserted into the curves it ends on (by projection onto their exact
  shape), never left dangling;
* the curves' own ends.

Points closer than the merge tolerance are one vertex (its coordinates: the map's
vertex when one is among them, exact; otherwise their mean). Each curve is then cut at
its vertices, in parameter order, into the edges of the arrangement.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import shapely
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from strategies.cspace._intersect import (
    arc_arc,
    conchoid_samples,
    node_sweep,
    refine_about,
    sampled_roots,
    seg_arc,
    seg_seg,
)
from strategies.cspace._shapes import ARC, CONCHOID, SEGMENT, points, project
from strategies.cspace.tolerances import Tolerances

__all__ = ["Curves", "Noded", "node"]

TWO_PI = 2.0 * np.pi
_CONCHOID_SAMPLES = 32


@dataclass
class Curves:
    """The arrangement's curves (after merging collinear overlaps).

    Attributes:
        kind, data, t0, t1: exact shapes and parameter ranges.
        sources: per curve, the indices of the critical curves it stands for.
        wall_sign: 0 for a critical curve; +1 (-1) for a wall with free space on the left
            (right) as the parameter grows.
        group: collinear group (-1: none); curves of one group never cross.
        offsets, params: polyline parameters of curve ``i``:
            ``params[offsets[i]:offsets[i + 1]]``.
        exact_ends: (m, 2, 2) the curves' end points; (m, 2) bool, whether that end is a
            map vertex (exact coordinates).
    """

    kind: np.ndarray
    data: np.ndarray
    t0: np.ndarray
    t1: np.ndarray
    sources: list[tuple[int, ...]]
    wall_sign: np.ndarray
    group: np.ndarray
    offsets: np.ndarray
    params: np.ndarray
    ends: np.ndarray
    exact_ends: np.ndarray

    def __len__(self) -> int:
        return len(self.kind)


@dataclass
class Noded:
    """Vertices and edges of the arrangement.

    Attributes:
        vertices: (nv, 2) vertex coordinates.
        curve, ta, tb: (ne,) each edge is the piece ``[ta, tb]`` of curve ``curve``.
        u, v: (ne,) its vertices at ``ta`` and ``tb``.
        n_points: points noded (ends, crossings, end-on-curve insertions).
        n_clusters_wide: vertices whose merged points spread over more than 10 merge
            tolerances (chains of near-coincident points; should be 0).
    """

    vertices: np.ndarray
    curve: np.ndarray
    ta: np.ndarray
    tb: np.ndarray
    u: np.ndarray
    v: np.ndarray
    n_points: int
    n_clusters_wide: int


def _boxes(cv: Curves, L: float, pad: float) -> tuple[np.ndarray, np.ndarray]:
    owner = np.repeat(np.arange(len(cv)), np.diff(cv.offsets))
    P = points(cv.kind[owner], cv.data[owner], cv.params, L)
    lo = np.full((len(cv), 2), np.inf)
    hi = np.full((len(cv), 2), -np.inf)
    np.minimum.at(lo, owner, P)
    np.maximum.at(hi, owner, P)
    return lo - pad, hi + pad


def _candidate_pairs(cv: Curves, L: float, pad: float) -> tuple[np.ndarray, np.ndarray]:
    lo, hi = _boxes(cv, L, pad)
    boxes = shapely.box(lo[:, 0], lo[:, 1], hi[:, 0], hi[:, 1])
    i, j = shapely.STRtree(boxes).query(boxes)
    keep = i < j
    i, j = i[keep], j[keep]
    same_group = (cv.group[i] >= 0) & (cv.group[i] == cv.group[j])
    same_support = np.all(cv.data[i] == cv.data[j], axis=1) & (cv.kind[i] == cv.kind[j])
    keep = ~same_group & ~same_support
    return i[keep].astype(np.intp), j[keep].astype(np.intp)


def _clamp(cv: Curves, idx: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Parameters clamped to the curves' ranges (arcs: to the nearer end modulo 2 pi)."""
    t0, t1 = cv.t0[idx], cv.t1[idx]
    arc = cv.kind[idx] == ARC
    if arc.any():
        ta = t0[arc] + (t[arc] - t0[arc]) % TWO_PI
        over = ta > t1[arc]
        to_start = over & ((ta - t1[arc]) > (t0[arc] + TWO_PI - ta))
        ta = np.where(to_start, t0[arc], np.where(over, t1[arc], ta))
        t = t.copy()
        t[arc] = ta
    return np.clip(t, t0, t1)


def _records(cv: Curves, L: float, tol: Tolerances, i, j, rounding: float = 0.0):
    """(curve a, param a, curve b, param b, point) of every crossing and end-on point."""
    ki, kj = cv.kind[i], cv.kind[j]
    di, dj = cv.data[i], cv.data[j]
    out_a, out_ta, out_b, out_tb = [], [], [], []

    def add(a, ta, b, tb):
        out_a.append(a)
        out_ta.append(ta)
        out_b.append(b)
        out_tb.append(tb)

    # segment-segment
    m = np.flatnonzero((ki == SEGMENT) & (kj == SEGMENT))
    if len(m):
        k, ta, tb = seg_seg(di[m, 0:2], di[m, 2:4], dj[m, 0:2], dj[m, 2:4])
        add(i[m[k]], ta, j[m[k]], tb)
    # segment-arc (either order)
    for a_, b_, ka, kb in ((i, j, ki, kj), (j, i, kj, ki)):
        m = np.flatnonzero((ka == SEGMENT) & (kb == ARC))
        if len(m):
            da, db = cv.data[a_[m]], cv.data[b_[m]]
            k, t, psi = seg_arc(da[:, 0:2], da[:, 2:4], db[:, 0:2], db[:, 2], tol.touch)
            add(a_[m[k]], t, b_[m[k]], psi)
    # arc-arc
    m = np.flatnonzero((ki == ARC) & (kj == ARC))
    if len(m):
        k, p1, p2 = arc_arc(di[m, 0:2], di[m, 2], dj[m, 0:2], dj[m, 2], tol.touch, tol.merge)
        add(i[m[k]], p1, j[m[k]], p2)
    # anything with a conchoid: sample the conchoid, follow the other's implicit function
    m = np.flatnonzero((ki == CONCHOID) | (kj == CONCHOID))
    if len(m):
        a_ = np.where(ki[m] == CONCHOID, i[m], j[m])
        b_ = np.where(ki[m] == CONCHOID, j[m], i[m])
        owner, ts = conchoid_samples(cv.data[a_], cv.t0[a_], cv.t1[a_], _CONCHOID_SAMPLES)
        # a conchoid's implicit function turns about its vertex: resolve it there
        both = np.flatnonzero(cv.kind[b_] == CONCHOID)
        if len(both):
            sweep = np.full(len(m), np.inf)
            sweep[both] = node_sweep(cv.data[b_[both]], L)
            centre = cv.data[b_, 0:2]
            owner, ts = refine_about(
                cv.kind[a_], cv.data[a_], owner, ts, centre, sweep, L, tol.merge
            )
        pair, tr, _ = sampled_roots(
            cv.kind[a_],
            cv.data[a_],
            owner,
            ts,
            cv.kind[b_],
            cv.data[b_],
            L,
            tol.touch,
            rounding,
            tol.merge,
        )
        x = points(CONCHOID, cv.data[a_[pair]], tr, L)
        tb = project(cv.kind[b_[pair]], cv.data[b_[pair]], x, cv.t0[b_[pair]])
        add(a_[pair], tr, b_[pair], tb)
    # the ends of each curve that lie on the other one
    for a_, b_ in ((i, j), (j, i)):
        for end in (0, 1):
            ta = cv.t0[a_] if end == 0 else cv.t1[a_]
            x = cv.ends[a_, end]
            tb = project(cv.kind[b_], cv.data[b_], x, cv.t0[b_])
            add(a_, ta, b_, tb)
    a = np.concatenate(out_a).astype(np.intp)
    b = np.concatenate(out_b).astype(np.intp)
    ta = np.concatenate(out_ta)
    tb = np.concatenate(out_tb)
    ok = np.isfinite(ta) & np.isfinite(tb)
    a, b, ta, tb = a[ok], b[ok], ta[ok], tb[ok]
    ta = _clamp(cv, a, ta)
    tb = _clamp(cv, b, tb)
    pa = points(cv.kind[a], cv.data[a], ta, L)
    pb = points(cv.kind[b], cv.data[b], tb, L)
    close = np.hypot(*(pa - pb).T) <= tol.merge
    return a[close], ta[close], b[close], tb[close], 0.5 * (pa + pb)[close]


def node(
    cv: Curves, L: float, tol: Tolerances, exact_points: np.ndarray, rounding: float = 0.0
) -> Noded:
    """Vertices and edges of the arrangement of ``cv`` (see the module docstring).

    ``exact_points`` (the map's vertices) keep their coordinates when they are noded.
    ``rounding``: an implicit function this small at a curve's end that lies on another
    curve has the sign of noise (see :func:`strategies.cspace._intersect.sampled_roots`).
    """
    i, j = _candidate_pairs(cv, L, tol.chord + tol.merge)
    a, ta, b, tb, x = _records(cv, L, tol, i, j, rounding)
    m = len(cv)
    # every point: the curves' ends (exact map vertices first), then the records
    end_pts = cv.ends.reshape(-1, 2)
    exact = cv.exact_ends.reshape(-1)
    pts = np.concatenate([end_pts, x, exact_points])
    is_exact = np.concatenate(
        [exact, np.zeros(len(x), dtype=bool), np.ones(len(exact_points), dtype=bool)]
    )
    n = len(pts)
    pairs = cKDTree(pts).query_pairs(tol.merge, output_type="ndarray")
    g = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    nc, lab = connected_components(g, directed=False)
    size = np.bincount(lab, minlength=nc)
    mean = np.stack([np.bincount(lab, weights=pts[:, k], minlength=nc) for k in (0, 1)], 1)
    mean /= size[:, None]
    verts = mean
    ex = np.flatnonzero(is_exact)
    verts[lab[ex]] = pts[ex]  # a map vertex is exact: it speaks for its cluster
    spread = np.zeros(nc)
    np.maximum.at(spread, lab, np.hypot(*(pts - verts[lab]).T))
    # incidences (curve, parameter, vertex), sorted along each curve
    inc_c = np.concatenate([np.repeat(np.arange(m), 2), a, b])
    inc_t = np.concatenate([np.stack([cv.t0, cv.t1], 1).ravel(), ta, tb])
    rec_lab = lab[2 * m : 2 * m + len(x)]
    inc_v = np.concatenate([lab[: 2 * m], rec_lab, rec_lab])
    order = np.lexsort((inc_t, inc_c))
    inc_c, inc_t, inc_v = inc_c[order], inc_t[order], inc_v[order]
    keep = np.concatenate([[True], (inc_c[1:] != inc_c[:-1]) | (inc_v[1:] != inc_v[:-1])])
    inc_c, inc_t, inc_v = inc_c[keep], inc_t[keep], inc_v[keep]
    nxt = inc_c[1:] == inc_c[:-1]
    e_c = inc_c[:-1][nxt]
    e_ta, e_tb = inc_t[:-1][nxt], inc_t[1:][nxt]
    e_u, e_v = inc_v[:-1][nxt], inc_v[1:][nxt]
    ok = (e_u != e_v) & (e_tb > e_ta)
    return Noded(
        vertices=verts,
        curve=e_c[ok],
        ta=e_ta[ok],
        tb=e_tb[ok],
        u=e_u[ok],
        v=e_v[ok],
        n_points=n,
        n_clusters_wide=int(np.count_nonzero(spread > 10 * tol.merge)),
    )
