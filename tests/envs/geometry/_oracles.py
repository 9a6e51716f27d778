"""Independent oracles for the geometry kernel: shapely predicates and brute force."""

from __future__ import annotations

import math

import numpy as np
import shapely
from shapely.geometry import LineString, Point

from envs.maps import Map
from envs.tolerances import REL_LENGTH_TOL


def los_oracle(world: Map, p, q) -> bool | None:
    """Line of sight by shapely: the open segment p-q lies in the interior of free space.

    The ends may rest on walls. Returns None when the answer is within a few ``eps`` of
    changing (a wall vertex or an intersection point that close to the open segment or to
    an end), where the kernel's tolerance decides and exact predicates cannot.
    """
    p = np.asarray(p, float)
    q = np.asarray(q, float)
    eps = REL_LENGTH_TOL * world.scale
    ell = float(np.linalg.norm(q - p))
    if ell <= 8 * eps:
        return None
    d = (q - p) / ell
    rel = world.vertices - p
    t = rel @ d
    h = np.abs(rel[:, 0] * d[1] - rel[:, 1] * d[0])
    inner = (t > 4 * eps) & (t < ell - 4 * eps)
    # an end within a few eps of a wall vertex: which side of the corner the segment
    # leaves by is below the tolerance (p = (0, 1), q = (0, -4.86e-265) beside the corner
    # (0, 0) of a square block, hypothesis: the open segment runs a subnormal length along
    # the block's side)
    if np.any((h < 4 * eps) & ((np.abs(t) < 4 * eps) | (np.abs(t - ell) < 4 * eps))):
        return None
    if np.any(inner & (h <= 0.5 * eps)):
        return False
    if np.any(inner & (h < 4 * eps)):
        return None
    # an edge lying within a few eps of the segment's line where they overlap: grazing
    # within tolerance, unless shapely finds an exact overlap
    ia, ib = world.edge_vertices[:, 0], world.edge_vertices[:, 1]
    flat = (h[ia] < 4 * eps) & (h[ib] < 4 * eps)
    lo = np.minimum(t[ia], t[ib])
    hi = np.maximum(t[ia], t[ib])
    grazing_near = flat & (lo < ell - 4 * eps) & (hi > 4 * eps)
    seg = LineString([p, q])
    inter = seg.intersection(world.free_region.boundary)
    if grazing_near.any():
        return False if inter.length > 4 * eps else None
    ends = [Point(p), Point(q)]
    for g in getattr(inter, "geoms", [inter]):
        if g.is_empty:
            continue
        if g.length > 4 * eps:
            return False  # runs along a wall
        gap = min(g.distance(e) for e in ends)
        if gap > 4 * eps:
            return False
        if gap > 0.5 * eps:
            return None
    if not world.free_region.contains(Point(0.5 * (p + q))):
        return False
    # visible by exact predicates, but the open segment passes within the tolerance of a
    # wall away from its ends (e.g. leaving a corner along a wall at an angle of 1e-8): the
    # kernel's call
    trim = min(0.25 * ell, 256 * eps)  # a wall met at an end at less than ~1 degree
    inner = LineString([p + trim * d, q - trim * d])
    if inner.distance(world.free_region.boundary) < 4 * eps:
        return None
    return True


def rod_blocked_samples(world: Map, point, L: float, thetas: np.ndarray) -> np.ndarray:
    """For P in the free interior: is the closed rod P -> P + L(cos, sin) touching a wall?"""
    P = np.asarray(point, float)
    Q = P + L * np.stack([np.cos(thetas), np.sin(thetas)], axis=1)
    lines = shapely.linestrings(np.stack([np.broadcast_to(P, Q.shape), Q], axis=1))
    boundary = world.free_region.boundary
    shapely.prepare(boundary)
    return shapely.intersects(lines, boundary)


def rod_clearance(world: Map, point, L: float, theta: float) -> float:
    """Signed clearance of the rod: distance to the walls, negative if it crosses one."""
    P = np.asarray(point, float)
    Q = P + L * np.array([math.cos(theta), math.sin(theta)])
    seg = LineString([P, Q])
    boundary = world.free_region.boundary
    if seg.crosses(boundary) or not world.free_region.covers(seg):
        return -1.0
    return float(seg.distance(boundary))


def ray_distance_oracle(world: Map, origin, theta: float, max_range: float) -> float:
    """Distance from ``origin`` to the first wall along a ray, by shapely."""
    o = np.asarray(origin, float)
    end = o + max_range * np.array([math.cos(theta), math.sin(theta)])
    inter = LineString([o, end]).intersection(world.free_region.boundary)
    if inter.is_empty:
        return max_range
    return min(max_range, float(Point(o).distance(inter)))
