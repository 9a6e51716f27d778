"""Exact geometry of the three critical-curve shapes, vectorised over mixed shapes.

A curve is a shape code (:data:`SEGMENT`, :data:`ARC`, :data:`CONCHOID`), a row of six
floats of exact data and a parameter ``t``:

* segment: ``P(t) = o + t d`` (``d`` unit), constant contact orientation ``theta``;
  data ``(ox, oy, dx, dy, theta, 0)``; ``t`` is arc length;
* arc: ``P(psi) = c + R (cos psi, sin psi)``, the rod pointing at the centre
  (``theta = psi + pi``); data ``(cx, cy, R, 0, 0, 0)``;
* conchoid (type 5): the tip ``Q(s) = a + s u`` runs on an edge's line and the rod
  passes vertex ``v``: ``P = Q + L (v - Q) / |v - Q|``, ``theta = atan2(Q - P)``; data
  ``(vx, vy, ax, ay, ux, uy)``; ``s`` is the tip's arc length along the edge.

Besides points, tangents and curvatures, each shape has an *implicit* signed function
``F`` that vanishes on the curve and measures distance to first order (exactly for
segments and arcs), finite and continuous everywhere but at a conchoid's vertex, and a
*projection* that maps a point of the curve back to its parameter. Intersections and
tangencies are found with them (:mod:`strategies.cspace._intersect`).
"""

from __future__ import annotations

import math

import numpy as np

__all__ = [
    "ARC",
    "CONCHOID",
    "SEGMENT",
    "SHAPE_CODES",
    "SHAPE_NAMES",
    "curvature",
    "derivatives",
    "gradient",
    "implicit",
    "orientation",
    "points",
    "polyline_params",
    "project",
]

SEGMENT, ARC, CONCHOID = 0, 1, 2
SHAPE_NAMES = ("segment", "arc", "conchoid")
SHAPE_CODES = {name: i for i, name in enumerate(SHAPE_NAMES)}
TWO_PI = 2.0 * math.pi


def _broadcast(kind, data, t):
    t = np.asarray(t, dtype=float).reshape(-1)
    data = np.asarray(data, dtype=float)
    if data.ndim == 1:
        data = np.broadcast_to(data, (len(t), data.shape[0]))
    kind = np.broadcast_to(np.asarray(kind), (len(t),))
    return kind, data, t


def _conchoid_frame(data: np.ndarray, t: np.ndarray):
    """Tip Q, unit vector ŵ from Q to v, |v - Q| and u·ŵ for conchoid rows."""
    v, a, u = data[:, 0:2], data[:, 2:4], data[:, 4:6]
    Q = a + t[:, None] * u
    w = v - Q
    D = np.hypot(w[:, 0], w[:, 1])
    with np.errstate(divide="ignore", invalid="ignore"):
        wh = w / D[:, None]
    c = (u * wh).sum(axis=1)
    return Q, wh, D, c, u


def points(kind, data, t, L: float) -> np.ndarray:
    """Points ``P(t)`` (k, 2) of curves ``(kind[k], data[k])`` at parameters ``t[k]``."""
    kind, data, t = _broadcast(kind, data, t)
    out = np.empty((len(t), 2))
    m = kind == SEGMENT
    if m.any():
        out[m] = data[m, 0:2] + t[m, None] * data[m, 2:4]
    m = kind == ARC
    if m.any():
        out[m] = data[m, 0:2] + data[m, 2:3] * np.stack([np.cos(t[m]), np.sin(t[m])], axis=1)
    m = kind == CONCHOID
    if m.any():
        Q, wh, _, _, _ = _conchoid_frame(data[m], t[m])
        out[m] = Q + L * wh
    return out


def orientation(kind, data, t, L: float) -> np.ndarray:
    """Contact orientation theta (direction from P to the tip) along the curves."""
    kind, data, t = _broadcast(kind, data, t)
    out = np.empty(len(t))
    m = kind == SEGMENT
    out[m] = data[m, 4]
    m = kind == ARC
    out[m] = t[m] + math.pi
    m = kind == CONCHOID
    if m.any():
        _, wh, _, _, _ = _conchoid_frame(data[m], t[m])
        out[m] = np.arctan2(-wh[:, 1], -wh[:, 0])
    return out


def derivatives(kind, data, t, L: float) -> tuple[np.ndarray, np.ndarray]:
    """First and second derivatives ``P'(t)``, ``P''(t)``, each (k, 2)."""
    kind, data, t = _broadcast(kind, data, t)
    d1 = np.zeros((len(t), 2))
    d2 = np.zeros((len(t), 2))
    m = kind == SEGMENT
    d1[m] = data[m, 2:4]
    m = kind == ARC
    if m.any():
        R = data[m, 2:3]
        cs = np.stack([np.cos(t[m]), np.sin(t[m])], axis=1)
        d1[m] = R * np.stack([-cs[:, 1], cs[:, 0]], axis=1)
        d2[m] = -R * cs
    m = kind == CONCHOID
    if m.any():
        _, wh, D, c, u = _conchoid_frame(data[m], t[m])
        # dŵ/ds = (c ŵ - u)/D, d²ŵ/ds² = ((3c² - 1) ŵ - 2 c u)/D²  (dw/ds = -u)
        d1[m] = u + L * (c[:, None] * wh - u) / D[:, None]
        d2[m] = L * ((3 * c * c - 1)[:, None] * wh - 2 * c[:, None] * u) / (D * D)[:, None]
    return d1, d2


def curvature(kind, data, t, L: float) -> np.ndarray:
    """Signed curvature (positive turning left as ``t`` grows)."""
    d1, d2 = derivatives(kind, data, t, L)
    speed = np.hypot(d1[:, 0], d1[:, 1])
    with np.errstate(divide="ignore", invalid="ignore"):
        k = (d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]) / speed**3
    return np.where(np.isfinite(k), k, 0.0)


def implicit(kind, data, x, L: float) -> np.ndarray:
    """Signed function of points ``x`` (k, 2) vanishing on curve ``k``'s support.

    Segment: signed distance to the line (positive on the left of ``d``). Arc: distance
    to the centre minus R. Conchoid: see :func:`_conchoid_implicit` (``inf`` only at
    ``v``).
    """
    x = np.asarray(x, dtype=float).reshape(-1, 2)
    kind, data, _ = _broadcast(kind, data, np.zeros(len(x)))
    out = np.empty(len(x))
    m = kind == SEGMENT
    if m.any():
        r = x[m] - data[m, 0:2]
        out[m] = data[m, 2] * r[:, 1] - data[m, 3] * r[:, 0]
    m = kind == ARC
    if m.any():
        out[m] = np.hypot(*(x[m] - data[m, 0:2]).T) - data[m, 2]
    m = kind == CONCHOID
    if m.any():
        out[m] = _conchoid_implicit(data[m], x[m], L)
    return out


def _conchoid_implicit(data: np.ndarray, x: np.ndarray, L: float) -> np.ndarray:
    """The conchoids' implicit function, without a pole: ``H / |grad H|``.

    With ``n`` the edge's unit normal, ``h(x) = n . (x - a)`` the height above the edge's
    line (signed positive on ``v``'s side) and ``alpha`` the angle between ``x - v`` and
    ``n``, a point is on the conchoid iff its height is the rod's rise,
    ``H(x) = h(x) - L |cos alpha| = 0``. The distance along the rod from the edge's line,
    ``h / |cos alpha| - L = H / |cos alpha|``, has the same sign but a pole on the line
    through ``v`` parallel to the edge (there the rod never reaches the edge's line):
    a curve ending or sampled on that line (a wall's end cap parallel to the edge, as in
    every rectilinear map) read ``inf`` there and lost its crossing with the conchoid.
    ``H`` is continuous everywhere but at ``v``; divided by its gradient's norm (in closed
    form) it measures distance to first order.
    """
    v, a, u = data[:, 0:2], data[:, 2:4], data[:, 4:6]
    n = np.stack([-u[:, 1], u[:, 0]], axis=1)
    side = np.where(((v - a) * n).sum(axis=1) < 0.0, -1.0, 1.0)
    r = x - v
    rn = np.hypot(r[:, 0], r[:, 1])
    with np.errstate(divide="ignore", invalid="ignore"):
        rh = r / rn[:, None]
        cos = (rh * n).sum(axis=1)
        H = side * ((x - a) * n).sum(axis=1) - L * np.abs(cos)
        # grad |cos alpha| = sign(cos) (n - cos r^) / |r|
        grad = side[:, None] * n - (np.sign(cos) * L / rn)[:, None] * (n - cos[:, None] * rh)
        f = H / np.maximum(np.hypot(grad[:, 0], grad[:, 1]), np.finfo(float).tiny)
    return np.where(np.isfinite(f), f, np.inf)


def gradient(kind, data, x, L: float) -> np.ndarray:
    """Gradient (k, 2) of :func:`implicit` at points ``x`` (conchoids: central differences)."""
    x = np.asarray(x, dtype=float).reshape(-1, 2)
    kind, data, _ = _broadcast(kind, data, np.zeros(len(x)))
    out = np.zeros((len(x), 2))
    m = kind == SEGMENT
    out[m, 0], out[m, 1] = -data[m, 3], data[m, 2]
    m = kind == ARC
    if m.any():
        r = x[m] - data[m, 0:2]
        out[m] = r / np.hypot(r[:, 0], r[:, 1])[:, None]
    m = kind == CONCHOID
    if m.any():
        h = 1e-6 * L
        for k, e in enumerate((np.array([h, 0.0]), np.array([0.0, h]))):
            fp = implicit(CONCHOID, data[m], x[m] + e, L)
            fm = implicit(CONCHOID, data[m], x[m] - e, L)
            out[m, k] = (fp - fm) / (2 * h)
    return out


def project(kind, data, x, t0=None) -> np.ndarray:
    """Parameters of the points ``x`` (k, 2) on the curves (unclamped).

    Segment: the foot of the perpendicular. Arc: the angle about the centre, in
    ``[t0, t0 + 2 pi)`` when ``t0`` is given. Conchoid: the tip where the line through
    ``x`` and ``v`` meets the edge's line (``nan`` if parallel).
    """
    x = np.asarray(x, dtype=float).reshape(-1, 2)
    kind, data, _ = _broadcast(kind, data, np.zeros(len(x)))
    out = np.empty(len(x))
    m = kind == SEGMENT
    if m.any():
        out[m] = ((x[m] - data[m, 0:2]) * data[m, 2:4]).sum(axis=1)
    m = kind == ARC
    if m.any():
        r = x[m] - data[m, 0:2]
        ang = np.arctan2(r[:, 1], r[:, 0])
        if t0 is not None:
            base = np.broadcast_to(np.asarray(t0, dtype=float), (len(x),))[m]
            ang = base + (ang - base) % TWO_PI
        out[m] = ang
    m = kind == CONCHOID
    if m.any():
        v, a, u = data[m, 0:2], data[m, 2:4], data[m, 4:6]
        w = v - x[m]
        r = a - x[m]
        den = w[:, 0] * u[:, 1] - w[:, 1] * u[:, 0]
        num = r[:, 0] * w[:, 1] - r[:, 1] * w[:, 0]
        with np.errstate(divide="ignore", invalid="ignore"):
            out[m] = np.where(np.abs(den) > 0.0, num / den, np.nan)
    return out


def polyline_params(
    kind: np.ndarray, data: np.ndarray, t0: np.ndarray, t1: np.ndarray, L: float, tol: float
) -> tuple[np.ndarray, np.ndarray]:
    """Parameters of polylines within ``tol`` of the curves, for many curves at once.

    Segments get their two ends; arcs a uniform subdivision; conchoids an adaptive one
    (an interval is halved while its chord is farther than ``tol / 4`` from the curve at
    its middle).

    Returns:
        ``(offsets, params)``: curve ``i``'s parameters are
        ``params[offsets[i]:offsets[i + 1]]``, increasing, from ``t0[i]`` to ``t1[i]``.
    """
    kind = np.asarray(kind)
    n = len(kind)
    t0 = np.asarray(t0, dtype=float)
    t1 = np.asarray(t1, dtype=float)
    counts = np.ones(n, dtype=np.int64)  # intervals per curve
    arc = kind == ARC
    if arc.any():
        R = data[arc, 2]
        step = np.where(tol < 2 * R, 2.0 * np.arccos(np.clip(1.0 - tol / R, -1.0, 1.0)), math.pi)
        counts[arc] = np.maximum(1, np.ceil((t1[arc] - t0[arc]) / step)).astype(np.int64)
    # uniform parameters for segments and arcs (and the start of the conchoids)
    cid = np.repeat(np.arange(n), counts + 1)
    start = np.concatenate([[0], np.cumsum(counts + 1)[:-1]])
    j = np.arange(len(cid)) - start[cid]
    params = t0[cid] + (t1 - t0)[cid] * j / counts[cid]
    params[start + counts] = t1  # exact ends
    con = np.flatnonzero(kind == CONCHOID)
    if len(con):
        keep = ~np.isin(cid, con)
        cp_id, cp = _adaptive(data, t0, t1, con, L, tol)
        cid = np.concatenate([cid[keep], cp_id])
        params = np.concatenate([params[keep], cp])
        order = np.lexsort((params, cid))
        cid, params = cid[order], params[order]
    offsets = np.concatenate([[0], np.cumsum(np.bincount(cid, minlength=n))])
    return offsets, params


def _adaptive(data, t0, t1, idx, L: float, tol: float) -> tuple[np.ndarray, np.ndarray]:
    """Adaptive subdivision of conchoids ``idx``: (curve id, parameter) pairs."""
    k = 8
    lo = (t0[idx, None] + (t1 - t0)[idx, None] * np.arange(k) / k).ravel()
    hi = (t0[idx, None] + (t1 - t0)[idx, None] * (np.arange(k) + 1) / k).ravel()
    owner = np.repeat(idx, k)
    done_id, done_t = [idx, owner], [t1[idx], lo]
    for _ in range(40):
        if len(lo) == 0:
            break
        d = data[owner]
        kinds = np.full(len(lo), CONCHOID)
        pa = points(kinds, d, lo, L)
        pb = points(kinds, d, hi, L)
        mid = 0.5 * (lo + hi)
        pm = points(kinds, d, mid, L)
        dev = np.hypot(*(pm - 0.5 * (pa + pb)).T)
        bad = (dev > 0.25 * tol) & (hi - lo > 1e-12 * (np.abs(hi) + np.abs(lo) + L))
        if not bad.any():
            break
        done_id.append(owner[bad])
        done_t.append(mid[bad])
        lo, hi, owner = (
            np.concatenate([lo[bad], mid[bad]]),
            np.concatenate([mid[bad], hi[bad]]),
            np.concatenate([owner[bad], owner[bad]]),
        )
    return np.concatenate(done_id), np.concatenate(done_t)
