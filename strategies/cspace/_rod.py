"""Semi-free rod test: does a rod lie in the *closed* free region (touching allowed)?

The critical curves of THEORY.md 1.2 are loci of *contact* configurations: the rod
touches walls (at its tip, or with its body at convex vertices, or lying along an edge)
but crosses no obstacle. The kernel's line of sight is stricter (any touch blocks), so
this module adds the predicate the clip needs, vectorised over many rods:

* the evader end P lies in the closed free region;
* the open rod properly crosses no wall edge;
* at every wall vertex the open rod passes through, neither direction of the rod enters
  the obstacle wedge there (a tangent rod passes, a rod cutting the corner does not);
* when P rests on a wall, the rod leaves it into free space.

Together these say the rod lies in the closed free region: a straight segment starting in
free space can leave it only through an edge interior (a proper crossing) or through a
vertex (the wedge test).
"""

from __future__ import annotations

import math

import numpy as np
import shapely

from envs.geometry.segments import segment_contacts
from envs.maps.map import Map
from envs.tolerances import REL_LENGTH_TOL

__all__ = [
    "ROUNDING_REL",
    "WEDGE_TOL",
    "in_closed_free",
    "rods_semifree",
    "rods_semifree_near",
    "wedge_interior",
]

WEDGE_TOL = 1e-9
"""Angle (radians) by which a rod must enter an obstacle wedge to count as entering it.

Contact configurations put the rod exactly along a wedge side (type 4) or tangent to a
corner (types 3, 5); rounding errors of order 1e-15 must not make them penetrate.
"""

ROUNDING_REL = 64.0 * float(np.finfo(float).eps)
"""Relative distance (times the map's scale plus its largest coordinate) within which a
rod passes through a wall vertex by rounding alone: a contact rod (types 3-5) is
computed through its vertices with a few ulps of its coordinates' error. Measured (in
these units) on 80 random stepped corners, five slanted worlds rotated, scaled by 1e-3
and 1e3 and moved by 1e6, the office, maze and pillars: rods within the length tolerance
of a vertex lie within 3e-16 of it when they pass through it in exact arithmetic, and
3e-11 or more when they pass beside it (a tooth 1e-4 wide on a floor: 4e-10)."""

_CHUNK_CELLS = 400_000  # rods x edges per vectorised block


def _obstacle_wedge(world: Map) -> tuple[np.ndarray, np.ndarray]:
    """Per vertex: the angle where its obstacle wedge starts and the wedge's span.

    With free space on the left of every edge, the obstacle at vertex v occupies the
    directions counter-clockwise from ``-d_in`` (back along the incoming edge) to
    ``d_out`` (along the outgoing edge).
    """
    d_in = world.edge_dir[world.vertex_prev_edge]
    d_out = world.edge_dir[world.vertex_next_edge]
    start = np.arctan2(-d_in[:, 1], -d_in[:, 0])
    span = (np.arctan2(d_out[:, 1], d_out[:, 0]) - start) % (2.0 * math.pi)
    return start, span


def wedge_interior(world: Map, vertex: np.ndarray, direction: np.ndarray) -> np.ndarray:
    """Whether each direction points strictly into the obstacle at the given vertex.

    Args:
        world: the map.
        vertex: (k,) vertex indices.
        direction: (k, 2) directions (need not be unit).

    Returns:
        (k,) bool: the direction lies inside the obstacle wedge by more than
        :data:`WEDGE_TOL`.
    """
    start, span = _obstacle_wedge(world)
    ang = (np.arctan2(direction[:, 1], direction[:, 0]) - start[vertex]) % (2.0 * math.pi)
    return (ang > WEDGE_TOL) & (ang < span[vertex] - WEDGE_TOL)


def rods_semifree(world: Map, P: np.ndarray, Q: np.ndarray) -> np.ndarray:
    """Which rods P[k]-Q[k] lie in the closed free region (contacts allowed).

    Args:
        world: the map.
        P: (k, 2) evader ends.
        Q: (k, 2) pursuer ends.

    Returns:
        (k,) bool.
    """
    P = np.asarray(P, dtype=float).reshape(-1, 2)
    Q = np.asarray(Q, dtype=float).reshape(-1, 2)
    k = len(P)
    out = np.zeros(k, dtype=bool)
    if k == 0:
        return out
    eps = REL_LENGTH_TOL * world.scale
    inside = world.contains(P)
    idx = np.flatnonzero(inside)
    if len(idx) == 0:
        return out
    a = world.edge_start[None]
    b = world.edge_end[None]
    n = world.edge_normal[None]
    chunk = max(1, _CHUNK_CELLS // max(1, world.n_edges))
    ok = np.ones(len(idx), dtype=bool)
    for s in range(0, len(idx), chunk):
        rows = idx[s : s + chunk]
        p = P[rows, None, :]
        q = Q[rows, None, :]
        crossing, _, vertex_hit, _, _ = segment_contacts(p, q, a, b, n, eps)
        bad = crossing.any(axis=1)
        r, v = np.nonzero(vertex_hit & ~bad[:, None])
        if len(r):
            d = Q[rows[r]] - P[rows[r]]
            enters = wedge_interior(world, v, d) | wedge_interior(world, v, -d)
            enters[enters] = ~_passes_beside(world, v[enters], P[rows[r[enters]]], d[enters], eps)
            bad[r[enters]] = True
        ok[s : s + chunk] = ~bad
    out[idx] = ok
    # P resting on a wall: the rod must leave it into free space
    near = np.flatnonzero(out & (world.distance_to_walls(P) <= eps))
    for i in near.tolist():
        out[i] = _leaves_wall(world, P[i], Q[i] - P[i], eps)
    return out


def _passes_beside(
    world: Map, v: np.ndarray, P: np.ndarray, d: np.ndarray, eps: float
) -> np.ndarray:
    """For rods ``P + t d`` within ``eps`` of wall vertex ``v`` whose direction enters
    the obstacle wedge there: whether the rod's line misses the vertex's two edges
    (meets their lines only at or past their far ends), so it passes beside ``v``
    rather than through it.

    The wedge test models the obstacle at ``v`` as an infinite wedge, which holds for a
    rod through ``v``; a rod passing ``eps`` beside ``v`` at a shallow angle meets an
    edge's line ``|offset| / |sin(angle)|`` from ``v``, which can be past a short edge's
    far end (the rod of a type-5 conchoid through the corner of a 1e-4 tooth passes its
    other corner 1e-8 above, at 1e-4 rad: it meets the top edge's line at the first
    corner, where it touches). Such a rod crosses no edge at ``v``; whatever it meets
    beyond the far ends is another edge or vertex, tested on its own.
    """
    if len(v) == 0:
        return np.zeros(0, dtype=bool)
    dn = d / np.hypot(d[:, 0], d[:, 1])[:, None]
    rel = world.vertices[v] - P
    off = dn[:, 0] * rel[:, 1] - dn[:, 1] * rel[:, 0]  # signed distance of v from the line
    # not through v by rounding alone (relative to the coordinates' magnitude)
    beside = np.abs(off) > ROUNDING_REL * (world.scale + float(np.abs(world.vertices).max()))
    for e, sign in ((world.vertex_next_edge[v], 1.0), (world.vertex_prev_edge[v], -1.0)):
        u = sign * world.edge_dir[e]  # along the edge, away from v
        c = dn[:, 0] * u[:, 1] - dn[:, 1] * u[:, 0]
        with np.errstate(divide="ignore", invalid="ignore"):
            s = -off / c  # the line meets the edge's line s from v
        meets = (c != 0.0) & (s >= 0.0) & (s < world.edge_length[e] - eps)
        beside &= ~meets
    return beside


def _leaves_wall(world: Map, p: np.ndarray, d: np.ndarray, eps: float) -> bool:
    """For P on a wall: does direction ``d`` leave P into free space?"""
    vd = np.hypot(*(world.vertices - p).T)
    at = np.flatnonzero(vd <= eps)
    if len(at):
        return not bool(wedge_interior(world, at, np.repeat(d[None], len(at), axis=0)).any())
    rel = p - world.edge_start
    s = np.einsum("ej,ej->e", rel, world.edge_dir)
    h = np.einsum("ej,ej->e", rel, world.edge_normal)
    on = (np.abs(h) <= eps) & (s >= 0) & (s <= world.edge_length)
    dn = world.edge_normal[on] @ d
    return bool(np.all(dn >= -WEDGE_TOL * float(np.hypot(*d))))


def in_closed_free(world: Map, P: np.ndarray) -> np.ndarray:
    """Which points lie in the closed free region (within the length tolerance of it)."""
    P = np.asarray(P, dtype=float).reshape(-1, 2)
    free = world.prepared_free_region
    out = shapely.intersects_xy(free, P[:, 0], P[:, 1])
    rest = np.flatnonzero(~out)
    if len(rest):
        eps = REL_LENGTH_TOL * world.scale
        out[rest] = shapely.dwithin(free, shapely.points(P[rest]), eps)
    return out


def rods_semifree_near(
    world: Map, P: np.ndarray, Q: np.ndarray, rod: np.ndarray, edge: np.ndarray
) -> np.ndarray:
    """:func:`rods_semifree` testing each rod only against the given nearby edges.

    Args:
        world: the map.
        P: (k, 2) evader ends.
        Q: (k, 2) pursuer ends.
        rod: (m,) rod of each (rod, edge) pair to test.
        edge: (m,) wall edge of each pair; every edge within reach of rod ``r`` must be
            paired with it (a spatial-index query does that).

    Returns:
        (k,) bool.
    """
    P = np.asarray(P, dtype=float).reshape(-1, 2)
    Q = np.asarray(Q, dtype=float).reshape(-1, 2)
    out = in_closed_free(world, P)
    if len(rod) == 0 or not out.any():
        return out
    eps = REL_LENGTH_TOL * world.scale
    bad = np.zeros(len(P), dtype=bool)
    wall_dist = np.full(len(P), np.inf)
    for s in range(0, len(rod), _CHUNK_CELLS):
        r = rod[s : s + _CHUNK_CELLS]
        f = edge[s : s + _CHUNK_CELLS]
        crossing, _, vertex_hit, _, _ = segment_contacts(
            P[r], Q[r], world.edge_start[f], world.edge_end[f], world.edge_normal[f], eps
        )
        bad[r[crossing]] = True
        a = world.edge_start[f]
        rel = P[r] - a
        t = np.clip((rel * world.edge_dir[f]).sum(axis=1), 0.0, world.edge_length[f])
        foot = a + t[:, None] * world.edge_dir[f]
        np.minimum.at(wall_dist, r, np.hypot(*(P[r] - foot).T))
        hit = np.flatnonzero(vertex_hit & ~crossing)
        if len(hit):
            d = Q[r[hit]] - P[r[hit]]
            v = f[hit]  # each wall vertex starts the edge of the same index
            enters = wedge_interior(world, v, d) | wedge_interior(world, v, -d)
            enters[enters] = ~_passes_beside(world, v[enters], P[r[hit[enters]]], d[enters], eps)
            bad[r[hit[enters]]] = True
    out &= ~bad
    for i in np.flatnonzero(out & (wall_dist <= eps)).tolist():
        out[i] = _leaves_wall(world, P[i], Q[i] - P[i], eps)
    return out
