"""Vectorised segment-versus-wall predicates (numpy, no shapely).

Line of sight is the predicate "the *open* segment p-q touches no wall": crossing an
edge, touching any wall vertex, or running along an edge blocks it. Contact at the
endpoints themselves (a body resting against a wall) does not block, provided the
segment leaves the contact into free space. All comparisons use one absolute length
tolerance ``eps`` (``REL_LENGTH_TOL`` times the map scale), so a vertex closer than
``eps`` to the open segment counts as touching it.
"""

from __future__ import annotations

import numpy as np

__all__ = ["endpoint_on_edge", "point_in_walls", "segment_contacts"]


def segment_contacts(
    p: np.ndarray,
    q: np.ndarray,
    a: np.ndarray,
    b: np.ndarray,
    n: np.ndarray,
    eps: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Classify how segments p-q meet wall edges a-b.

    Broadcasting: ``p, q`` are (k, 1, 2) and ``a, b, n`` are (1, m, 2) (or any shapes that
    broadcast to (k, m, 2)). Edge ``j`` has free space on its left, unit normal ``n``.

    Args:
        p: segment starts.
        q: segment ends.
        a: edge starts (each wall vertex is the start of exactly one edge).
        b: edge ends.
        n: unit normals of the edges into free space.
        eps: absolute length tolerance.

    Returns:
        ``(crossing, t_cross, vertex_hit, t_vertex, along)``, each (k, m):
        ``crossing`` a proper crossing of the edge interior at segment parameter
        ``t_cross``; ``vertex_hit`` edge start ``a`` within ``eps`` of the open segment at
        parameter ``t_vertex``; ``along`` the open segment overlaps the edge collinearly
        (grazing), the first contact being at parameter ``t_vertex`` clipped to 0.
        Also ``p_on`` / ``q_on`` are not returned here; see :func:`endpoint_on_edge`.
    """
    d = q - p
    ell2 = d[..., 0] * d[..., 0] + d[..., 1] * d[..., 1]
    ell = np.sqrt(ell2)
    ap = a - p
    bp = b - p
    # signed distances (times ell) of the edge ends from the segment's line
    oa = d[..., 0] * ap[..., 1] - d[..., 1] * ap[..., 0]
    ob = d[..., 0] * bp[..., 1] - d[..., 1] * bp[..., 0]
    # signed distances of the segment ends from the edge's line (positive = free side)
    op = -(n[..., 0] * ap[..., 0] + n[..., 1] * ap[..., 1])
    oq = n[..., 0] * (q[..., 0] - a[..., 0]) + n[..., 1] * (q[..., 1] - a[..., 1])
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / ell2
        ta = (d[..., 0] * ap[..., 0] + d[..., 1] * ap[..., 1]) * inv
        tb = (d[..., 0] * bp[..., 0] + d[..., 1] * bp[..., 1]) * inv
        t_lo = eps / ell
    t_hi = 1.0 - t_lo
    tol_o = eps * ell
    near_a = np.abs(oa) <= tol_o
    near_b = np.abs(ob) <= tol_o
    crossing = (((oa > tol_o) & (ob < -tol_o)) | ((oa < -tol_o) & (ob > tol_o))) & (
        ((op > eps) & (oq < -eps)) | ((op < -eps) & (oq > eps))
    )
    with np.errstate(divide="ignore", invalid="ignore"):
        t_cross = op / (op - oq)
    vertex_hit = near_a & (ta > t_lo) & (ta < t_hi)
    lo = np.maximum(np.minimum(ta, tb), 0.0)
    hi = np.minimum(np.maximum(ta, tb), 1.0)
    along = near_a & near_b & (lo < t_hi) & (hi > t_lo)
    t_vertex = np.where(along & ~vertex_hit, lo, ta)
    return crossing, t_cross, vertex_hit, t_vertex, along


def endpoint_on_edge(
    x: np.ndarray, a: np.ndarray, u: np.ndarray, n: np.ndarray, length: np.ndarray, eps: float
) -> np.ndarray:
    """Return which points ``x`` lie within ``eps`` of which closed edges (broadcast)."""
    rel0 = x[..., 0] - a[..., 0]
    rel1 = x[..., 1] - a[..., 1]
    s = u[..., 0] * rel0 + u[..., 1] * rel1
    h = n[..., 0] * rel0 + n[..., 1] * rel1
    return (np.abs(h) <= eps) & (s >= -eps) & (s <= length + eps)


def point_in_walls(x: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Even-odd test of points ``x`` (k, 2) against all wall edges ``a-b`` (m, 2).

    Points exactly on a wall get an arbitrary answer; callers only ask about points
    away from the walls.
    """
    px = x[:, None, 0]
    py = x[:, None, 1]
    ay, by = a[None, :, 1], b[None, :, 1]
    ax, bx = a[None, :, 0], b[None, :, 0]
    cond = (ay > py) != (by > py)
    with np.errstate(divide="ignore", invalid="ignore"):
        xint = ax + (py - ay) * (bx - ax) / (by - ay)
    return np.count_nonzero(cond & (px < xint), axis=1) % 2 == 1
