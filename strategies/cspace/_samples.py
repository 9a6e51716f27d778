"""Points deep inside the faces of the arrangement, found on the exact curves.

A face's polygon is exact only to the chord tolerance, which can be the whole width of a
thin face (two nearly parallel curves), so a point chosen on the polygon may lie outside
the face. Here each face gets its point from the exact geometry: from the exact middle
of its longest edge, along the exact normal into the face, a ray is cast and its first
crossing with any curve (walls included) is found in closed form (segments, arcs) or by
polished roots (conchoids); the point is halfway to it. Nothing between the edge and
the first crossing belongs to another face, so the point is inside.
"""

from __future__ import annotations

import numpy as np
import shapely

from strategies.cspace._intersect import conchoid_samples, sampled_roots, seg_arc, seg_seg
from strategies.cspace._noding import Curves, _boxes
from strategies.cspace._shapes import ARC, CONCHOID, SEGMENT, derivatives, points, project

__all__ = ["ray_samples"]

_SAMPLES = 32  # conchoid samples per parametrisation


def _first_hits(
    cv: Curves, L: float, o: np.ndarray, d: np.ndarray, reach: np.ndarray, touch, pad: float
):
    """Distance along each ray ``o + s d`` (``s`` in ``(0, reach]``) to its first curve.

    The curves are looked up by their polylines' boxes grown by ``pad``: an arc or a
    conchoid bulges out of its polyline's box by up to the chord tolerance (its extreme
    point lies between two vertices), so unpadded boxes miss a ray that meets the curve
    only there (a ray across a face between two nearly concentric arcs, near their
    common extreme)."""
    n = len(o)
    best = np.full(n, np.inf)
    lo, hi = _boxes(cv, L, pad)
    tree = shapely.STRtree(shapely.box(lo[:, 0], lo[:, 1], hi[:, 0], hi[:, 1]))
    rays = shapely.linestrings(np.stack([o, o + reach[:, None] * d], axis=1))
    r, c = tree.query(rays)
    if len(r) == 0:
        return best
    kind = cv.kind[c]
    ray_row = np.zeros((len(r), 6))
    ray_row[:, 0:2], ray_row[:, 2:4] = o[r], d[r]
    cand_r, cand_s, cand_c, cand_t = [], [], [], []
    m = np.flatnonzero(kind == SEGMENT)
    if len(m):
        k, s, t = seg_seg(o[r[m]], d[r[m]], cv.data[c[m], 0:2], cv.data[c[m], 2:4])
        cand_r.append(r[m[k]]), cand_s.append(s), cand_c.append(c[m[k]]), cand_t.append(t)
    m = np.flatnonzero(kind == ARC)
    if len(m):
        k, s, psi = seg_arc(o[r[m]], d[r[m]], cv.data[c[m], 0:2], cv.data[c[m], 2], touch)
        t = project(ARC, cv.data[c[m[k]]], points(ARC, cv.data[c[m[k]]], psi, L), cv.t0[c[m[k]]])
        cand_r.append(r[m[k]]), cand_s.append(s), cand_c.append(c[m[k]]), cand_t.append(t)
    m = np.flatnonzero(kind == CONCHOID)
    if len(m):
        cc = c[m]
        owner, ts = conchoid_samples(cv.data[cc], cv.t0[cc], cv.t1[cc], _SAMPLES)
        pair, tr, _ = sampled_roots(
            cv.kind[cc], cv.data[cc], owner, ts, np.full(len(m), SEGMENT), ray_row[m], L, touch
        )
        x = points(CONCHOID, cv.data[cc[pair]], tr, L)
        s = ((x - o[r[m[pair]]]) * d[r[m[pair]]]).sum(axis=1)
        cand_r.append(r[m[pair]]), cand_s.append(s), cand_c.append(cc[pair]), cand_t.append(tr)
    rr = np.concatenate(cand_r)
    ss = np.concatenate(cand_s)
    cc = np.concatenate(cand_c)
    tt = np.concatenate(cand_t)
    slack = 1e-12 * (np.abs(cv.t1[cc]) + np.abs(cv.t0[cc]) + 1.0)
    ok = (tt >= cv.t0[cc] - slack) & (tt <= cv.t1[cc] + slack)
    ok &= (ss > 1e-9 * reach[rr]) & (ss <= reach[rr])
    np.minimum.at(best, rr[ok], ss[ok])
    return best


def ray_samples(
    cv: Curves,
    L: float,
    edge_curve: np.ndarray,
    ta: np.ndarray,
    tb: np.ndarray,
    sign: np.ndarray,
    reach: np.ndarray,
    touch: float,
    pad: float,
) -> tuple[np.ndarray, np.ndarray]:
    """One point inside each face (local frame) and its distance to the boundary along
    the ray (``inf`` if the ray met nothing: the caller falls back).

    Args:
        cv: the arrangement's curves.
        L: rod length.
        edge_curve, ta, tb: per face, its longest edge (curve and parameter range).
        sign: +1 if the face lies on the left of the edge as its parameter grows.
        reach: per face, an upper bound on the ray length (its polygon's diameter).
        touch: the tangency tolerance.
        pad: how far an exact curve may lie outside its polyline's box (the chord
            tolerance and the merge radius, as the noding's candidate pairs).
    """
    t = 0.5 * (ta + tb)
    kind, data = cv.kind[edge_curve], cv.data[edge_curve]
    p = points(kind, data, t, L)
    d1, _ = derivatives(kind, data, t, L)
    tan = d1 / np.hypot(d1[:, 0], d1[:, 1])[:, None]
    n = sign[:, None] * np.stack([-tan[:, 1], tan[:, 0]], axis=1)
    s = _first_hits(cv, L, p, n, reach, touch, pad)
    half = np.where(np.isfinite(s), 0.5 * s, np.nan)
    return p + half[:, None] * n, half
