"""Continuous-time surveillance check over one step (DESIGN.md, "Geometry kernel").

The pursuer P moves linearly ``p0 -> p1`` and the evader E ``e0 -> e1`` over ``t in [0, 1]``
(one meaning per letter project-wide: P the pursuer, E the evader; THEORY.md section 0
writes them Q and P).
Surveillance breaks at the earliest ``t`` where

* the distance ``|P(t) - E(t)|`` leaves ``[l_min, l_max]``: ``|R + t S|^2`` is a quadratic
  in ``t`` (R = p0 - e0, S = the relative velocity);
* the rod touches a wall. While both ends stay in free space the rod can first touch a
  wall only at a convex obstacle vertex v (THEORY.md section 0), when v lies on the rod:
  ``cross(P(t) - v, E(t) - v) = 0`` (a quadratic in ``t``) with v strictly between the ends.
  A graze (the rod's line reaching v and backing off, no real root) counts when the
  closest approach, at the quadratic's extremum, is within ``eps``, as in line of sight.

Candidate vertices come from the kernel's grid over the bounding box of the four points
(the rod stays in their convex hull during the step). The earliest event wins; at equal
times "occluded" comes before "too_far" before "too_close".

Frames are checked too: a rod already blocked at ``t = 0`` is reported at time 0, and one
found blocked at ``t = 1`` with no earlier vertex contact (an end pushed into a wall, or
a contact lost to rounding) at time 1; their feature is the blocking feature nearest the
evader. Contacts of an end with a wall are not breaks,
as in :meth:`Kernel.line_of_sight`; two ends resting on the same wall edge *between*
frames (the rod lying along the wall) are not detected.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from envs.geometry.types import SweepEvent
from envs.maps.map import Feature

if TYPE_CHECKING:
    from envs.geometry.kernel import Kernel

__all__ = ["sweep_step"]

_CAUSE_ORDER = {"occluded": 0, "too_far": 1, "too_close": 2}
_NO_CANDIDATE = (math.inf, -1)
"""Returned by :func:`_vertex_event` when no convex vertex lies near the swept rod."""


def _quad_roots(c2: float, c1: np.ndarray, c0: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Real roots of ``c2 t^2 + c1 t + c0`` (c2 scalar), stable; NaN where absent.

    A discriminant that is negative only by rounding (a tangent contact) counts as zero.
    """
    disc = c1 * c1 - 4.0 * c2 * c0
    scale = c1 * c1 + abs(4.0 * c2) * np.abs(c0)
    disc = np.where((disc < 0.0) & (disc >= -1e-12 * scale), 0.0, disc)
    with np.errstate(divide="ignore", invalid="ignore"):
        sq = np.sqrt(disc)  # NaN where disc < 0
        qq = -0.5 * (c1 + np.where(c1 >= 0.0, sq, -sq))
        r1 = np.where(qq != 0.0, c0 / qq, np.nan)
        r2 = qq / c2 if c2 != 0.0 else np.full_like(qq, np.nan)
        # qq == 0 means c1 == 0 and disc == 0: a double root at 0 when c0 == 0
        r1 = np.where((qq == 0.0) & (c0 == 0.0), 0.0, r1)
    return r1, r2


def _first_distance_event(
    rx: float, ry: float, sx: float, sy: float, l_min: float, l_max: float, eps: float
) -> tuple[float, str] | None:
    """Earliest ``t`` in [0, 1] where ``|R + t S|`` leaves ``[l_min, l_max]`` (by > eps).

    ``f(t) = |R + t S|^2 = A t^2 + B t + C`` is convex: with ``f(0)`` in range, it leaves
    through ``l_max`` only if ``f(1)`` is out (at the larger root of ``f = l_max^2``), and
    through ``l_min`` only if its minimum on [0, 1] is (at the smaller root of
    ``f = l_min^2``).
    """
    A = sx * sx + sy * sy
    B = 2.0 * (rx * sx + ry * sy)
    C = rx * rx + ry * ry
    d0 = math.sqrt(C)
    if d0 > l_max + eps:
        return (0.0, "too_far")
    if d0 < l_min - eps:
        return (0.0, "too_close")
    if A == 0.0:
        return None
    best: tuple[float, str] | None = None
    if math.sqrt(max(A + B + C, 0.0)) > l_max + eps:
        t = max(_roots(A, B, C - l_max * l_max), default=1.0)
        best = (min(max(t, 0.0), 1.0), "too_far")
    if l_min > 0.0:
        tm = min(max(-B / (2.0 * A), 0.0), 1.0)
        if math.sqrt(max((A * tm + B) * tm + C, 0.0)) < l_min - eps:
            t = min(_roots(A, B, C - l_min * l_min), default=tm)
            t = min(max(t, 0.0), 1.0)
            if best is None or t < best[0]:
                best = (t, "too_close")
    return best


def _roots(c2: float, c1: float, c0: float) -> list[float]:
    """Real roots of ``c2 t^2 + c1 t + c0`` (stable formula; a discriminant negative
    only by rounding, a tangency, counts as zero)."""
    disc = c1 * c1 - 4.0 * c2 * c0
    if disc < 0.0:
        if disc < -1e-12 * (c1 * c1 + abs(4.0 * c2 * c0)):
            return []
        disc = 0.0
    sq = math.sqrt(disc)
    qq = -0.5 * (c1 + (sq if c1 >= 0.0 else -sq))
    out = []
    if qq != 0.0:
        out.append(c0 / qq)
        if c2 != 0.0:
            out.append(qq / c2)
    elif c0 == 0.0:
        out.append(0.0)
    return out


def _vertex_event(
    kernel: Kernel,
    p0x: float,
    p0y: float,
    e0x: float,
    e0y: float,
    dpx: float,
    dpy: float,
    dex: float,
    dey: float,
) -> tuple[float, int] | None:
    """Earliest ``t`` in [0, 1] where a convex vertex lies on the open rod."""
    eps = kernel.eps
    xs = (p0x, p0x + dpx, e0x, e0x + dex)
    ys = (p0y, p0y + dpy, e0y, e0y + dey)
    cand = kernel.vgrid.query_box(min(xs) - eps, min(ys) - eps, max(xs) + eps, max(ys) + eps)
    if not cand:
        return _NO_CANDIDATE
    if len(cand) > kernel.numpy_threshold:
        return _vertex_event_numpy(
            kernel,
            np.fromiter(cand, dtype=np.intp),
            np.array([p0x, p0y]),
            np.array([e0x, e0y]),
            np.array([dpx, dpy]),
            np.array([dex, dey]),
        )
    lo = (min(xs) - eps, min(ys) - eps)
    hi = (max(xs) + eps, max(ys) + eps)
    c2 = dpx * dey - dpy * dex
    best_t = math.inf
    best_v = -1
    vxy = kernel._vxy
    for v in cand:
        vx, vy = vxy[v]
        if not (lo[0] <= vx <= hi[0] and lo[1] <= vy <= hi[1]):
            continue
        ax, ay = p0x - vx, p0y - vy  # P(t) - v = A + t dp
        cx, cy = e0x - vx, e0y - vy  # E(t) - v = C + t de
        c1 = ax * dey - ay * dex + dpx * cy - dpy * cx
        c0 = ax * cy - ay * cx
        if abs(c2) + abs(c1) + abs(c0) <= eps * (math.hypot(ax, ay) + math.hypot(cx, cy)):
            # v stays on the rod's line: test the start, end and dot-product roots
            ts = [0.0, 1.0, 0.5]
            for r in _roots(
                dpx * dex + dpy * dey, ax * dex + ay * dey + cx * dpx + cy * dpy, ax * cx + ay * cy
            ):
                ts += [r, r + 1e-9]
        else:
            ts = _roots(c2, c1, c0)
            if not ts and c2 != 0.0:  # no crossing: a near miss may still touch
                ts = [-c1 / (2.0 * c2)]
        for t in ts:
            if not (-1e-12 <= t <= 1.0 + 1e-12) or t >= best_t:
                continue
            t = min(max(t, 0.0), 1.0)
            ex, ey = e0x + t * dex, e0y + t * dey
            rx, ry = p0x + t * dpx - ex, p0y + t * dpy - ey
            ell2 = rx * rx + ry * ry
            if ell2 <= eps * eps:
                continue
            ell = math.sqrt(ell2)
            if abs((vx - ex) * ry - (vy - ey) * rx) > eps * ell:
                continue  # v not on the rod's line (within eps) at this time
            sv = ((vx - ex) * rx + (vy - ey) * ry) / ell2
            margin = eps / ell
            if margin < sv < 1.0 - margin:
                best_t, best_v = t, v
    return None if best_v < 0 else (best_t, best_v)


def _vertex_event_numpy(
    kernel: Kernel,
    vid: np.ndarray,
    p0: np.ndarray,
    e0: np.ndarray,
    dp: np.ndarray,
    de: np.ndarray,
) -> tuple[float, int] | None:
    """:func:`_vertex_event` vectorised over many candidate vertices."""
    eps = kernel.eps
    v = kernel.map.vertices[vid]
    pts = np.stack([p0, p0 + dp, e0, e0 + de])
    box = np.all((v >= pts.min(axis=0) - eps) & (v <= pts.max(axis=0) + eps), axis=1)
    vid, v = vid[box], v[box]
    if len(vid) == 0:
        return None
    A = p0 - v  # P(t) - v = A + t dp
    C = e0 - v  # E(t) - v = C + t de
    c2 = float(dp[0] * de[1] - dp[1] * de[0])
    c1 = (A[:, 0] * de[1] - A[:, 1] * de[0]) + (dp[0] * C[:, 1] - dp[1] * C[:, 0])
    c0 = A[:, 0] * C[:, 1] - A[:, 1] * C[:, 0]
    r1, r2 = _quad_roots(c2, c1, c0)
    # no crossing: the extremum of the cross product, where a near miss may still touch
    ext = np.where(np.isnan(r1) & (c2 != 0.0), -c1 / (2.0 * c2) if c2 != 0.0 else np.nan, np.nan)
    ts = np.concatenate([r1, r2, ext])
    ids = np.tile(np.arange(len(vid)), 3)
    # a vertex on the rod's line for the whole step (cross identically zero): test the
    # start, the end and the roots of the dot product instead
    scale_c = np.abs(c1) + np.abs(c0) + abs(c2)
    line = scale_c <= eps * (np.hypot(A[:, 0], A[:, 1]) + np.hypot(C[:, 0], C[:, 1]) + 1e-300)
    if line.any():
        extra_t, extra_i = _on_line_candidates(A[line], C[line], dp, de)
        ts = np.concatenate([ts, extra_t])
        ids = np.concatenate([ids, np.flatnonzero(line)[extra_i]])
    ok = np.isfinite(ts) & (ts >= -1e-12) & (ts <= 1.0 + 1e-12)
    if not ok.any():
        return None
    ts = np.clip(ts[ok], 0.0, 1.0)
    ids = ids[ok]
    # keep roots with v strictly inside the rod (projection parameter away from the ends)
    Pt = p0 + ts[:, None] * dp
    Et = e0 + ts[:, None] * de
    rod = Pt - Et
    ell2 = np.einsum("ij,ij->i", rod, rod)
    ell = np.sqrt(ell2)
    rel = v[ids] - Et
    on_line = np.abs(rel[:, 0] * rod[:, 1] - rel[:, 1] * rod[:, 0]) <= eps * ell
    with np.errstate(divide="ignore", invalid="ignore"):
        sv = np.einsum("ij,ij->i", rel, rod) / ell2
        margin = eps / ell
    inside = (ell > eps) & on_line & (sv > margin) & (sv < 1.0 - margin)
    if not inside.any():
        return None
    k = np.flatnonzero(inside)
    j = k[np.argmin(ts[k])]
    return float(ts[j]), int(vid[ids[j]])


def _on_line_candidates(
    A: np.ndarray, C: np.ndarray, dp: np.ndarray, de: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Candidate times for vertices that stay on the rod's line: 0, 1, dot-product roots."""
    d2 = float(dp @ de)
    d1 = A @ de + C @ dp
    d0 = np.einsum("ij,ij->i", A, C)
    r1, r2 = _quad_roots(d2, d1, d0)
    n = len(A)
    t = np.concatenate([np.zeros(n), np.ones(n), r1, r2, np.full(n, 0.5)])
    # just after a root the dot product may already be negative
    t = np.concatenate([t, r1 + 1e-9, r2 + 1e-9])
    return t, np.tile(np.arange(n), 7)


def sweep_step(
    kernel: Kernel,
    p0: tuple[float, float],
    e0: tuple[float, float],
    p1: tuple[float, float],
    e1: tuple[float, float],
    l_min: float,
    l_max: float,
    start_clear: bool = False,
) -> SweepEvent | None:
    """See :meth:`Kernel.sweep` (arguments already validated, as float pairs)."""
    p0x, p0y = p0
    e0x, e0y = e0
    dpx, dpy = p1[0] - p0x, p1[1] - p0y
    dex, dey = e1[0] - e0x, e1[1] - e0y
    cands: list[tuple[float, str, Feature | None]] = []
    dist = _first_distance_event(
        p0x - e0x, p0y - e0y, dpx - dex, dpy - dey, l_min, l_max, kernel.eps
    )
    if dist is not None:
        cands.append((dist[0], dist[1], None))
    if not start_clear and not kernel._los(e0x, e0y, p0x, p0y):
        cands.append((0.0, "occluded", kernel.blocking_feature(e0, p0)))
    elif dist is None or dist[0] > 0.0:
        hit = _vertex_event(kernel, p0x, p0y, e0x, e0y, dpx, dpy, dex, dey)
        if hit is _NO_CANDIDATE:
            # no convex vertex near the swept rod: clear at t = 0 with both ends free, it
            # cannot become blocked by t = 1 (it would have to sweep over a vertex first)
            pass
        elif hit is not None:
            cands.append((hit[0], "occluded", Feature("vertex", hit[1])))
        elif not kernel._los(e1[0], e1[1], p1[0], p1[1]):
            cands.append((1.0, "occluded", kernel.blocking_feature(e1, p1)))
    if not cands:
        return None
    t, cause, feature = min(cands, key=lambda c: (c[0], _CAUSE_ORDER[c[1]]))
    return SweepEvent(
        time=t,
        cause=cause,
        feature=feature,
        pursuer=np.array([p0x + t * dpx, p0y + t * dpy]),
        evader=np.array([e0x + t * dex, e0y + t * dey]),
    )
