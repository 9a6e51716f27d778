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


def sweep_hits_vertex(
    ax, ay, bx, by, vx, vy, cx, cy, R, din, dout, eta=0.0, clear=0.0, lengths=None
) -> np.ndarray:
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

    **The disc end keeps its clearance** (``clear > 0`` with the edge ``lengths``). For A
    in one grazing wedge, the ray from v away from A runs into the opposite wedge, beside
    one of v's two wall edges (the edge leaving v when ``c1, c2 >= 0``, the one arriving
    at it when ``c1, c2 <= 0``). When the obstacle's angle at v is at least a right angle
    (``din . dout >= 0``), every point of that wedge projects onto the edge's line at or
    beyond v, so a point of it less than ``clear`` from the edge's line, and projecting
    onto the edge itself, is less than ``clear`` from the wall: not a position of an
    opponent that keeps ``clear`` from the walls. Where the whole disc projects onto the
    edge (its far side at most the edge's length from v), condition (i) is then tested
    against ``D(c, R)`` cut by the line ``clear`` off the edge: a narrower cone (the
    chord's ends and the tangent points above the line span it), so a pursuer looking
    past a jamb at an evader that hugs the wall beyond it, which the plain disc always
    let hide, is not; everywhere else the disc's cone as before.

    Args:
        ax, ay, bx, by: the segment A-B (the pursuer's path over one piece of a step).
        vx, vy: the convex vertex.
        cx, cy, R: the disc that holds every evader position over that piece.
        din: (2,) unit direction of the wall edge arriving at v.
        dout: (2,) unit direction of the wall edge leaving v.
        eta: slack (a length) that widens the grazing wedges, for rounding.
        clear: the clearance every disc position keeps from the walls (0: not used).
        lengths: ``(arriving, leaving)`` lengths of v's two wall edges (needed when
            ``clear > 0``).

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

        From a pursuer 1.5 below the obstacle and 0.1 beside the wall x = 0, the ray from
        v away from it runs up along that wall, 0.02 from it at y = 0.3. The plain test
        lets an evader disc about (-0.1, 0.3) of radius 0.15 stand on it; an evader that
        keeps 0.02 from the walls still may, one that keeps 0.1 may not (the ray is that
        far from the wall only at y = 1.5, far above the disc):

        >>> long = (10.0, 10.0)
        >>> for clear in (0.0, 0.02, 0.1):
        ...     print(bool(sweep_hits_vertex(0.1, -1.5, 0.1, -1.5, 0, 0, -0.1, 0.3, 0.15,
        ...                                  din, dout, clear=clear, lengths=long)))
        True
        True
        False
    """
    inside, npx, npy, nmx, nmy = _cone_normals(vx, vy, cx, cy, R)
    shape = np.broadcast(ax, bx, vx, cx, R).shape
    ex, ey = bx - ax, by - ay
    din = np.asarray(din, dtype=float)
    dout = np.asarray(dout, dtype=float)
    # c1(s) = cross(dout, v - A(s)), c2(s) = cross(-din, v - A(s))
    wx, wy = vx - ax, vy - ay
    a1 = dout[0] * wy - dout[1] * wx
    b1 = -(dout[0] * ey - dout[1] * ex)
    a2 = -(din[0] * wy - din[1] * wx)
    b2 = din[0] * ey - din[1] * ex
    cut = clear > 0.0 and lengths is not None and float(din @ dout) >= -1e-9
    hit = np.zeros(shape, dtype=bool)
    for sign in (1.0, -1.0):  # the wedge c1, c2 >= 0 and the wedge c1, c2 <= 0
        lo = np.zeros(shape)
        hi = np.ones(shape)
        cone = [  # the disc's cone (irrelevant when v is in the disc)
            (
                np.where(inside, 1.0, nx * (ax - vx) + ny * (ay - vy)),
                np.where(inside, 0.0, nx * ex + ny * ey),
            )
            for nx, ny in ((npx, npy), (nmx, nmy))
        ]
        if cut:
            # the ray runs beside the edge leaving v (sign +1) or arriving at it (sign -1)
            e = dout if sign > 0 else -din
            n = np.array([-dout[1], dout[0]]) if sign > 0 else np.array([-din[1], din[0]])
            length = float(lengths[1] if sign > 0 else lengths[0])
            applies, empty, r1, r2 = _cut_cone(vx, vy, cx, cy, R, e, n, length, clear)
            refined = []
            for (rx, ry), turn in ((r1, 1.0), (r2, -1.0)):
                # turn * cross(r, v - A(s)) >= 0, linear in s
                alpha = turn * (rx * wy - ry * wx)
                beta = -turn * (rx * ey - ry * ex)
                refined.append((alpha + eta, beta))
            cone = [
                (np.where(applies, ra, ca), np.where(applies, rb, cb))
                for (ra, rb), (ca, cb) in zip(refined, cone, strict=True)
            ]
            lo = np.where(applies & empty, np.inf, lo)
        for alpha, beta in cone:
            lo, hi = _clip(lo, hi, alpha, beta)
        l2, h2 = _clip(lo, hi, sign * a1 + eta, sign * b1)
        l2, h2 = _clip(l2, h2, sign * a2 + eta, sign * b2)
        hit |= l2 <= h2
    return hit


def _cut_cone(vx, vy, cx, cy, R, e, n, length, clear):
    """The cone of apex v spanned by ``D(c, R)`` cut to the side of the line ``clear``
    off the wall edge that runs from v along ``e``, ``n`` its unit normal into free space.

    Returns:
        ``(applies, empty, r1, r2)``: where the cut applies (the whole disc projects onto
        the edge: ``(c - v) . e + R <= length``), where the cut disc is empty, and the
        cone's bounding unit directions ``r1`` and ``r2``, counter-clockwise from ``r1``
        to ``r2`` (the cone spans less than a half-turn), as ``(x, y)`` pairs of arrays
        (meaningless where it does not apply or is empty).
    """
    e = np.asarray(e, dtype=float)
    n = np.asarray(n, dtype=float)
    wx, wy = np.broadcast_arrays(np.asarray(cx - vx, dtype=float), np.asarray(cy - vy, dtype=float))
    R = np.broadcast_to(np.asarray(R, dtype=float), wx.shape)
    pe = wx * e[0] + wy * e[1]
    pn = wx * n[0] + wy * n[1]
    applies = pe + R <= length
    empty = pn + R < clear
    big = np.inf
    tmin = np.full(wx.shape, big)
    tmax = np.full(wx.shape, -big)

    def take(x, y, ok):
        nonlocal tmin, tmax
        th = np.arctan2(y, x)
        tmin = np.where(ok, np.minimum(tmin, th), tmin)
        tmax = np.where(ok, np.maximum(tmax, th), tmax)

    # the chord's ends, where the line n = clear cuts the circle
    dh = clear - pn
    half2 = R * R - dh * dh
    chord = (half2 >= 0.0) & (pn - R < clear)
    half = np.sqrt(np.maximum(half2, 0.0))
    take(pe - half, np.full(wx.shape, clear), chord)
    take(pe + half, np.full(wx.shape, clear), chord)
    # the tangent points from v, where they lie on the kept side
    D2 = pe * pe + pn * pn
    out = D2 > R * R
    q = np.sqrt(np.maximum(D2 - R * R, 0.0))
    with np.errstate(invalid="ignore", divide="ignore"):
        phi = np.arctan2(pn, pe)
        beta = np.arcsin(np.clip(R / np.sqrt(np.maximum(D2, 1e-300)), 0.0, 1.0))
    for sgn in (1.0, -1.0):
        ang = phi + sgn * beta
        tx, ty = q * np.cos(ang), q * np.sin(ang)
        take(tx, ty, out & (ty >= clear))
    empty = empty | (tmin > tmax)
    tmin = np.where(empty, 0.0, tmin)
    tmax = np.where(empty, 0.0, tmax)
    r1 = (np.cos(tmin) * e[0] + np.sin(tmin) * n[0], np.cos(tmin) * e[1] + np.sin(tmin) * n[1])
    r2 = (np.cos(tmax) * e[0] + np.sin(tmax) * n[0], np.cos(tmax) * e[1] + np.sin(tmax) * n[1])
    if e[0] * n[1] - e[1] * n[0] < 0.0:  # (e, n) turns clockwise: the angles run clockwise
        r1, r2 = r2, r1
    return applies, empty, r1, r2


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
