"""Continuous-time surveillance check over one step (DESIGN.md, "Geometry kernel").

The pursuer moves linearly ``p0 -> p1`` and the evader ``e0 -> e1`` over ``t in [0, 1]``.
Surveillance breaks at the earliest ``t`` where

* the distance ``|P(t) - E(t)|`` leaves ``[l_min, l_max]``: ``|R + t S|^2`` is a quadratic
  in ``t`` (R = p0 - e0, S = the relative velocity);
* the rod touches a wall. While both ends stay in free space the rod can first touch a
  wall only at a convex obstacle vertex v (THEORY.md section 0), when v lies on the rod:
  ``cross(P(t) - v, E(t) - v) = 0`` (a quadratic in ``t``) with v strictly between the ends.

Frames are checked too: a rod already blocked at ``t = 0`` is reported at time 0, and one
found blocked at ``t = 1`` with no earlier vertex contact (an end pushed into a wall, or
a contact lost to rounding) at time 1. Contacts of an end with a wall are not breaks,
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
    R: np.ndarray, S: np.ndarray, l_min: float, l_max: float, eps: float
) -> tuple[float, str] | None:
    """Earliest ``t`` in [0, 1] where ``|R + t S|`` leaves ``[l_min, l_max]`` (by > eps)."""
    A = float(S @ S)
    B = 2.0 * float(R @ S)
    C = float(R @ R)
    d0 = math.sqrt(C)
    best: tuple[float, str] | None = None
    if d0 > l_max + eps:
        return (0.0, "too_far")
    if d0 < l_min - eps:
        return (0.0, "too_close")
    if A == 0.0:
        return None
    f1 = A + B + C
    if math.sqrt(max(f1, 0.0)) > l_max + eps:
        # convex f, f(0) <= l_max^2 < f(1): the larger root of f = l_max^2 is the exit
        r1, r2 = _quad_roots(A, np.array([B]), np.array([C - l_max * l_max]))
        t = float(np.nanmax([r1[0], r2[0]]))
        best = (min(max(t, 0.0), 1.0), "too_far")
    if l_min > 0.0:
        tm = min(max(-B / (2.0 * A), 0.0), 1.0)
        fm = (A * tm + B) * tm + C
        if math.sqrt(max(fm, 0.0)) < l_min - eps:
            r1, r2 = _quad_roots(A, np.array([B]), np.array([C - l_min * l_min]))
            t = float(np.nanmin([r1[0], r2[0]]))
            t = min(max(t, 0.0), 1.0)
            if best is None or t < best[0]:
                best = (t, "too_close")
    return best


def _vertex_event(
    kernel: Kernel, p0: np.ndarray, e0: np.ndarray, dp: np.ndarray, de: np.ndarray
) -> tuple[float, int] | None:
    """Earliest ``t`` in [0, 1] where a convex vertex lies on the open rod."""
    eps = kernel.eps
    pts = np.stack([p0, p0 + dp, e0, e0 + de])
    lo = pts.min(axis=0) - eps
    hi = pts.max(axis=0) + eps
    vid = kernel.convex_in_box(lo[0], lo[1], hi[0], hi[1])
    if len(vid) == 0:
        return None
    v = kernel.map.vertices[vid]
    A = p0 - v  # P(t) - v = A + t dp
    C = e0 - v  # E(t) - v = C + t de
    c2 = float(dp[0] * de[1] - dp[1] * de[0])
    c1 = (A[:, 0] * de[1] - A[:, 1] * de[0]) + (dp[0] * C[:, 1] - dp[1] * C[:, 0])
    c0 = A[:, 0] * C[:, 1] - A[:, 1] * C[:, 0]
    r1, r2 = _quad_roots(c2, c1, c0)
    ts = np.concatenate([r1, r2])
    ids = np.concatenate([np.arange(len(vid)), np.arange(len(vid))])
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
    with np.errstate(divide="ignore", invalid="ignore"):
        sv = np.einsum("ij,ij->i", v[ids] - Et, rod) / ell2
        margin = eps / ell
    inside = (ell > eps) & (sv > margin) & (sv < 1.0 - margin)
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
    p0: np.ndarray,
    e0: np.ndarray,
    p1: np.ndarray,
    e1: np.ndarray,
    l_min: float,
    l_max: float,
) -> SweepEvent | None:
    """See :meth:`Kernel.sweep`."""
    dp = p1 - p0
    de = e1 - e0
    cands: list[tuple[float, str, Feature | None]] = []
    dist = _first_distance_event(p0 - e0, dp - de, l_min, l_max, kernel.eps)
    if dist is not None:
        cands.append((dist[0], dist[1], None))
    if not kernel.line_of_sight(e0, p0):
        cands.append((0.0, "occluded", kernel.blocking_feature(e0, p0)))
    else:
        hit = _vertex_event(kernel, p0, e0, dp, de)
        if hit is not None:
            cands.append((hit[0], "occluded", Feature("vertex", hit[1])))
        elif not kernel.line_of_sight(e1, p1):
            cands.append((1.0, "occluded", kernel.blocking_feature(e1, p1)))
    if not cands:
        return None
    t, cause, feature = min(cands, key=lambda c: (c[0], _CAUSE_ORDER[c[1]]))
    return SweepEvent(
        time=t,
        cause=cause,
        feature=feature,
        pursuer=p0 + t * dp,
        evader=e0 + t * de,
    )
