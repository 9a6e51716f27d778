"""Robust tests: surveillance facts that hold for *every* position the discretisation allows.

Both bounds rest on one fact (THEORY.md section 0): while both ends of the rod stay off the
walls, the rod can start or stop touching an obstacle only when a *convex* obstacle vertex
lies on it. So a family of rods that varies continuously, contains one clear (or one
blocked) rod, and never sweeps a convex vertex, is clear (blocked) throughout. The tests
here check "never sweeps a convex vertex" for whole families at once:

* :func:`sweep_hits_vertex` (the pursuer bound). The pursuer moves exactly from A to B
  while the evader, anywhere in a disc of radius ``R`` about a centre, sweeps. Over a
  piece of the step every rod joins a point of [A, B] to a point of the disc.
* :func:`fan_hits_vertex` (the evader bound). The evader sits exactly at e and the pursuer
  anywhere in a disc.

Sharper than "no convex vertex in the hull of the family": the first contact is a
*grazing* one, the rod's line passing v outside the obstacle's interior cone (a rod that
cut into the obstacle would have been blocked before). So a rod through v must come from
a pursuer end A in one of the two grazing wedges at v (beside the obstacle, bounded by
the extensions of the edges at v), and the ray from v away from A must meet the disc;
both are half-plane conditions, linear in the segment's parameter. An evader standing at
a convex corner with the pursuer in the wedge opposite the obstacle (the paper's
admissible orientations at a reflex vertex, Sec. 6) is thus correctly safe.

The range tests are closed forms for a point moving linearly against a disc whose radius
grows linearly (:func:`sweep_range_ok`) and for a point against a square
(:func:`square_range`).

All arrays broadcast; coordinates may be relative to any common origin.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "convex_corners",
    "fan_hits_vertex",
    "segment_crosses_walls",
    "square_range",
    "sweep_hits_vertex",
    "sweep_range_ok",
]


def convex_corners(world) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The convex obstacle vertices of a map with the directions of their two edges.

    Returns:
        ``(v, din, dout)``, each (n, 2): the vertices, the unit direction of the wall edge
        arriving at each one and of the edge leaving it (free space on their left).
    """
    idx = world.convex_vertices
    din = world.edge_dir[world.vertex_prev_edge[idx]]
    dout = world.edge_dir[world.vertex_next_edge[idx]]
    return world.vertices[idx], din, dout


def _cone_normals(vx, vy, cx, cy, R):
    """Inward normals (scaled, not unit) of the cone at apex v spanned by v - D(c, R),
    and whether v lies in the disc itself."""
    wx = vx - cx
    wy = vy - cy
    D2 = wx * wx + wy * wy
    inside = D2 <= R * R
    q = np.sqrt(np.maximum(D2 - R * R, 0.0))
    # n+ = rot(w, beta - pi/2), n- = rot(w, pi/2 - beta), scaled by |w|^2
    npx = wx * R + wy * q
    npy = -wx * q + wy * R
    nmx = wx * R - wy * q
    nmy = wx * q + wy * R
    return inside, npx, npy, nmx, nmy


def _clip(lo, hi, alpha, beta):
    """Intersect [lo, hi] with {s : alpha + s beta >= 0}."""
    alpha = np.asarray(alpha, dtype=float)
    beta = np.asarray(beta, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        root = np.divide(-alpha, beta)
    lo = np.where(beta > 0, np.maximum(lo, root), lo)
    hi = np.where(beta < 0, np.minimum(hi, root), hi)
    return np.where((beta == 0) & (alpha < 0), np.inf, lo), hi


def sweep_hits_vertex(ax, ay, bx, by, vx, vy, cx, cy, R, din, dout, eta=0.0) -> np.ndarray:
    """Whether a rod from a point of the segment A-B to a point of the disc D(c, R) can
    *graze* the convex vertex v: pass through v with its line outside the obstacle's
    interior cone there.

    A continuously moving rod whose ends stay off the walls starts (or stops) touching an
    obstacle only in such a grazing contact at a convex vertex (a contact that crossed
    into the interior would have been preceded by a blocked rod). A rod through v has
    the direction from its pursuer end A to v, so it grazes iff (i) the ray from v away
    from A meets the disc (A lies in the cone of apex v spanned by v - D(c, R), or v is
    in the disc) and (ii) the line misses the interior cone: with ``c1 = cross(dout, v -
    A)`` and ``c2 = cross(-din, v - A)``, ``c1 c2 >= 0`` (two wedges at v, each an
    intersection of two half-planes). Both are linear in A's parameter along the segment.

    Args:
        ax, ay, bx, by: the segment A-B (the pursuer's path over one piece of a step).
        vx, vy: the convex vertex.
        cx, cy, R: the disc that holds every evader position over that piece.
        din: (2,) unit direction of the wall edge arriving at v.
        dout: (2,) unit direction of the wall edge leaving v.
        eta: slack (a length) that widens the grazing wedges, for rounding.

    Returns:
        Boolean array (broadcast shape): True when some rod of the family may graze v.

    Examples:
        A square obstacle in the first quadrant, its corner v at the origin (the wall
        arrives along -x and leaves along +y, free space on the left). A pursuer down
        and to the left, in the wedge opposite the obstacle, never grazes v, however
        close the evader's disc; beside the obstacle, below its bottom edge, it may:

        >>> din, dout = (-1.0, 0.0), (0.0, 1.0)
        >>> bool(sweep_hits_vertex(-1.0, -1.2, -1.3, -0.9, 0, 0, 0.1, 0.1, 0.3, din, dout))
        False
        >>> bool(sweep_hits_vertex(1.5, -1.0, 1.5, -1.0, 0, 0, -0.1, 0.1, 0.3, din, dout))
        True
    """
    inside, npx, npy, nmx, nmy = _cone_normals(vx, vy, cx, cy, R)
    shape = np.broadcast(ax, bx, vx, cx, R).shape
    lo = np.zeros(shape)
    hi = np.ones(shape)
    ex, ey = bx - ax, by - ay
    for nx, ny in ((npx, npy), (nmx, nmy)):  # the cone (irrelevant when v is in the disc)
        alpha = np.where(inside, 1.0, nx * (ax - vx) + ny * (ay - vy))
        beta = np.where(inside, 0.0, nx * ex + ny * ey)
        lo, hi = _clip(lo, hi, alpha, beta)
    # c1(s) = cross(dout, v - A(s)), c2(s) = cross(-din, v - A(s))
    wx, wy = vx - ax, vy - ay
    a1 = dout[0] * wy - dout[1] * wx
    b1 = -(dout[0] * ey - dout[1] * ex)
    a2 = -(din[0] * wy - din[1] * wx)
    b2 = din[0] * ey - din[1] * ex
    hit = np.zeros(shape, dtype=bool)
    for sign in (1.0, -1.0):  # the wedge c1, c2 >= 0 and the wedge c1, c2 <= 0
        l2, h2 = _clip(lo, hi, sign * a1 + eta, sign * b1)
        l2, h2 = _clip(l2, h2, sign * a2 + eta, sign * b2)
        hit |= l2 <= h2
    return hit


def fan_hits_vertex(ex, ey, vx, vy, cx, cy, R, din, dout, eta=0.0) -> np.ndarray:
    """Whether a rod from the exact evader e to a point of the disc D(c, R) can graze the
    convex vertex v (:func:`sweep_hits_vertex` with the segment shrunk to the point e;
    the rod's direction through v is that of v - e)."""
    return sweep_hits_vertex(ex, ey, ex, ey, vx, vy, cx, cy, R, din, dout, eta)


def sweep_range_ok(ox, oy, dx, dy, R0, g, l_min, l_max) -> np.ndarray:
    """Whether ``l_min <= |X - P(t)| <= l_max`` for every t in [0, 1] and every X in the
    disc ``D(o, R0 + g t)``, with the point ``P(t) = t d`` (coordinates relative to P(0)).

    The largest distance ``|o - t d| + R0 + g t`` is convex in t: its maximum is at an
    end. The smallest ``|o - t d| - R0 - g t`` is convex too; its minimum is at an end or
    where its derivative vanishes, which has a closed form (with ``D = |d|``, the
    component of ``o - t d`` along d equals ``-kappa n / sqrt(1 - kappa^2)``,
    ``kappa = g / D``, n the distance from o to d's line).
    """
    ox, oy, dx, dy = np.broadcast_arrays(*(np.asarray(x, dtype=float) for x in (ox, oy, dx, dy)))
    f = lambda t: np.hypot(ox - t * dx, oy - t * dy)
    hi = np.maximum(f(0.0) + R0, f(1.0) + R0 + g)
    lo = np.minimum(f(0.0) - R0, f(1.0) - R0 - g)
    D = np.hypot(dx, dy)
    with np.errstate(divide="ignore", invalid="ignore"):
        ux, uy = dx / D, dy / D
        kappa = g / D
        along0 = ox * ux + oy * uy
        n = np.abs(ox * uy - oy * ux)
        tstar = (along0 + kappa * n / np.sqrt(1.0 - kappa * kappa)) / D
    interior = (D > 0) & (kappa < 1.0) & (tstar > 0.0) & (tstar < 1.0)
    ts = np.where(interior, tstar, 0.0)
    lo = np.where(interior, np.minimum(lo, f(ts) - R0 - g * ts), lo)
    return (lo >= l_min) & (hi <= l_max)


def square_range(ox, oy, half) -> tuple[np.ndarray, np.ndarray]:
    """Smallest and largest distance from the origin to the squares of half-side ``half``
    centred at (ox, oy).

    Examples:
        >>> near, far = square_range(3.0, 4.0, 0.5)
        >>> round(float(near), 4), round(float(far), 4)
        (4.3012, 5.7009)
    """
    ax = np.abs(ox)
    ay = np.abs(oy)
    near = np.hypot(np.maximum(ax - half, 0.0), np.maximum(ay - half, 0.0))
    far = np.hypot(ax + half, ay + half)
    return near, far


def segment_crosses_walls(P: np.ndarray, Q: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Whether each segment P[i]-Q[i] properly crosses some wall edge a[j]-b[j].

    A proper crossing (each segment's ends strictly on opposite sides of the other's line)
    is an obstacle robustly in the way: it stays crossed under small moves of the ends.

    Args:
        P, Q: (k, 2) segments.
        a, b: (m, 2) wall edges.

    Returns:
        (k,) bool.
    """
    out = np.zeros(len(P), dtype=bool)
    chunk = max(1, 4_000_000 // max(1, len(a)))
    for s in range(0, len(P), chunk):
        p = P[s : s + chunk, None, :]
        q = Q[s : s + chunk, None, :]
        u = q - p
        w = b - a
        d1 = u[..., 0] * (a[None, :, 1] - p[..., 1]) - u[..., 1] * (a[None, :, 0] - p[..., 0])
        d2 = u[..., 0] * (b[None, :, 1] - p[..., 1]) - u[..., 1] * (b[None, :, 0] - p[..., 0])
        d3 = w[None, :, 0] * (p[..., 1] - a[None, :, 1]) - w[None, :, 1] * (
            p[..., 0] - a[None, :, 0]
        )
        d4 = w[None, :, 0] * (q[..., 1] - a[None, :, 1]) - w[None, :, 1] * (
            q[..., 0] - a[None, :, 0]
        )
        out[s : s + chunk] = ((d1 * d2 < 0) & (d3 * d4 < 0)).any(axis=1)
    return out
