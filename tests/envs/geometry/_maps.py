"""Test maps for the geometry kernel, built directly with :class:`envs.maps.Map`."""

from __future__ import annotations

import math

import numpy as np
import shapely
from shapely.geometry import Point

from envs.maps import Map


def square_obstacle_map() -> Map:
    """THEORY.md 1.4's world: obstacle [-2, 0]^2 (convex vertex at the origin) in [-5, 5]^2."""
    return Map(
        [(-5, -5), (5, -5), (5, 5), (-5, 5)],
        [[(-2, -2), (0, -2), (0, 0), (-2, 0)]],
        name="square",
    )


def nonconvex_map() -> Map:
    """A U-shaped room (non-convex boundary) with a triangle and an L-shaped obstacle."""
    return Map(
        [(0, 0), (10, 0), (10, 6), (6, 6), (6, 3), (4, 3), (4, 6), (0, 6)],
        [
            [(1, 1), (2.5, 1.2), (1.5, 2.5)],
            [(7, 1), (9, 1), (9, 2), (8, 2), (8, 4), (7, 4)],
        ],
        name="u-room",
    )


def aligned_blocks_map() -> Map:
    """Two blocks whose bottom edges are collinear (grazing, collinear-edge degeneracies)."""
    return Map(
        [(0, 0), (6, 0), (6, 4), (0, 4)],
        [[(1, 1), (2, 1), (2, 2), (1, 2)], [(3, 1), (4, 1), (4, 2), (3, 2)]],
        name="aligned",
    )


def random_convex_polygon(rng: np.random.Generator, center, radius: float, k: int) -> np.ndarray:
    """A random convex polygon with ``k`` vertices on a jittered circle (counter-clockwise)."""
    ang = np.sort(rng.uniform(0, 2 * math.pi, k))
    r = radius * rng.uniform(0.6, 1.0, k)
    pts = np.stack([center[0] + r * np.cos(ang), center[1] + r * np.sin(ang)], axis=1)
    hull = shapely.convex_hull(shapely.multipoints(pts))
    return np.asarray(hull.exterior.coords)[:-1]


def random_map(seed: int, nx: int = 3, ny: int = 3, cell: float = 4.0) -> Map:
    """A rectangle holding an ``nx`` x ``ny`` grid of random non-touching convex polygons."""
    rng = np.random.default_rng(seed)
    obstacles = []
    for i in range(nx):
        for j in range(ny):
            c = (
                (i + 0.5) * cell + rng.uniform(-0.1, 0.1) * cell,
                (j + 0.5) * cell + rng.uniform(-0.1, 0.1) * cell,
            )
            obstacles.append(
                random_convex_polygon(
                    rng, c, cell * rng.uniform(0.15, 0.35), int(rng.integers(3, 8))
                )
            )
    return Map(
        [(0, 0), (nx * cell, 0), (nx * cell, ny * cell), (0, ny * cell)],
        obstacles,
        name=f"random-{seed}",
    )


def all_maps() -> list[Map]:
    """Every test map."""
    return [
        square_obstacle_map(),
        nonconvex_map(),
        aligned_blocks_map(),
        random_map(0),
        random_map(1),
    ]


def sample_free_points(
    world: Map, rng: np.random.Generator, k: int, margin: float = 1e-3
) -> np.ndarray:
    """``k`` uniform points of the free region at least ``margin`` from every wall."""
    lo = np.array(world.bounds[:2])
    hi = np.array(world.bounds[2:])
    out = []
    free = world.free_region
    while len(out) < k:
        p = lo + (hi - lo) * rng.uniform(size=2)
        if free.contains(Point(p)) and free.boundary.distance(Point(p)) > margin:
            out.append(p)
    return np.array(out)


def sample_wall_points(world: Map, rng: np.random.Generator, k: int) -> np.ndarray:
    """``k`` points on the walls: random edges at random parameters (vertices included)."""
    e = rng.integers(0, world.n_edges, k)
    t = rng.uniform(size=k)
    t[rng.uniform(size=k) < 0.2] = 0.0  # some exactly at vertices
    return world.edge_start[e] + t[:, None] * (world.edge_end[e] - world.edge_start[e])
