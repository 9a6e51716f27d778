"""Seeded random maps: non-touching obstacles in a rectangle with a guaranteed gap.

:func:`random_map` places obstacles one at a time at uniformly random positions and keeps
a placement only if its exact (shapely) distance to every obstacle already placed, and to
the boundary, is at least ``min_gap``. Disjoint simple polygons strictly inside a
rectangle leave one connected free region (a polygon with holes), and every passage
between two walls is at least ``min_gap`` wide, so bodies narrower than that can go
everywhere. A seed fixes the map: one ``np.random.default_rng(seed)`` drives every draw.

Obstacle shapes (``kind``):

* ``"convex"``: vertices at jittered parameter angles on a random ellipse, so the
  polygon is strictly convex;
* ``"star"``: vertices at jittered angles around a centre at random radii, so the polygon
  is star-shaped about its centre and in general not convex;
* ``"polygons"``: each obstacle convex or star-shaped at random;
* ``"rectangles"``: axis-aligned rectangles (4 vertices each).

``n_vertices`` fixes the total number of obstacle vertices (the map then has
``n_vertices + 4`` walls), for benchmarks that sweep the map's complexity.
"""

from __future__ import annotations

import math

import numpy as np
import shapely
from shapely.geometry import Polygon

from envs import validation
from envs.errors import InfeasibleError, InvalidConfigError
from envs.maps.map import Map

__all__ = ["KINDS", "MAX_OBSTACLES", "MAX_VERTICES", "random_map"]

KINDS = ("polygons", "convex", "star", "rectangles")
"""Obstacle shape families accepted by :func:`random_map`."""

_DEFAULT_N_OBSTACLES = 6
_TARGET_RADIUS = 2.0  # obstacle circumradius aimed at when the size is chosen automatically
_FILL = 0.55  # obstacle disks at the largest radius (plus half the gap) would cover this much
_COUNTS = {"convex": (3, 9), "star": (5, 13)}  # default vertex counts, [low, high)
_MIN_SIN = 1e-6  # |sin| of every turn of a generated polygon, far above COLLINEAR_TOL
_TRIES = 60  # positions tried per radius before the radius shrinks
_SHRINK = 0.85
_SMALLEST = 0.25  # give up once the radius falls below this fraction of the first one


MAX_VERTICES = 1_000_000
"""Upper bound of ``n_vertices`` (and of the vertices drawn per map): a typo such as
``n_vertices=1e9`` fails at once instead of exhausting memory."""

MAX_OBSTACLES = 100_000
"""Upper bound of ``n_obstacles``."""


def _size(size: object, n: int, min_gap: float) -> tuple[float, float]:
    if size is None:
        # room for n obstacles of circumradius _TARGET_RADIUS at the packing fraction _FILL
        share = math.pi * (_TARGET_RADIUS + 0.5 * min_gap) ** 2 / _FILL
        side = max(10.0, math.sqrt(max(n, 1) * share), 2 * (_TARGET_RADIUS + min_gap) + 1.0)
        return side, side
    if isinstance(size, (tuple, list, np.ndarray)):
        if len(size) != 2:
            raise InvalidConfigError(f"size = {size!r}: expected a number or (width, height)")
        return validation.positive("size[0]", size[0]), validation.positive("size[1]", size[1])
    s = validation.positive("size", size)
    return s, s


def _vertex_counts(rng: np.random.Generator, kinds: list[str], n_vertices: int | None) -> list[int]:
    n = len(kinds)
    if n_vertices is None:
        # convex: 3 to 8 vertices; star: 5 to 12, enough to be non-convex most of the time
        return [4 if k == "rectangles" else int(rng.integers(*_COUNTS[k])) for k in kinds]
    if kinds and kinds[0] == "rectangles":
        if n_vertices != 4 * n:
            raise InvalidConfigError(
                f"n_vertices = {n_vertices}: rectangles have 4 vertices each, "
                f"expected 4 * n_obstacles = {4 * n}"
            )
        return [4] * n
    if n_vertices < 3 * n:
        raise InvalidConfigError(
            f"n_vertices = {n_vertices}: each of the n_obstacles = {n} obstacles needs at least "
            f"3 vertices, expected n_vertices >= {3 * n}"
        )
    counts = np.full(n, n_vertices // n)
    counts[rng.permutation(n)[: n_vertices % n]] += 1
    return [int(k) for k in counts]


def _jittered_angles(rng: np.random.Generator, k: int) -> np.ndarray:
    """k increasing angles in [0, 2 pi) + offset, each in its own slot of 2 pi / k."""
    slot = 2 * np.pi / k
    return rng.uniform() * slot + slot * (np.arange(k) + 0.8 * rng.uniform(size=k))


def _turn_sines(ring: np.ndarray) -> np.ndarray:
    a = ring - np.roll(ring, 1, axis=0)
    b = np.roll(ring, -1, axis=0) - ring
    cross = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    return np.abs(cross) / (np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1))


def _shape(rng: np.random.Generator, kind: str, k: int, r: float) -> np.ndarray:
    """A simple polygon with k vertices inside the disk of radius r about the origin."""
    while True:
        if kind == "rectangles":
            beta = rng.uniform(0.3, 0.5 * np.pi - 0.3)  # half-diagonal r at angle beta
            hw, hh = r * math.cos(beta), r * math.sin(beta)
            return np.array([(-hw, -hh), (hw, -hh), (hw, hh), (-hw, hh)])
        t = _jittered_angles(rng, k)
        if kind == "convex":
            aspect, phi = rng.uniform(0.5, 1.0), rng.uniform(0, np.pi)
            local = np.stack([r * np.cos(t), aspect * r * np.sin(t)], axis=1)
            c, s = math.cos(phi), math.sin(phi)
            ring = local @ np.array([[c, s], [-s, c]])
        else:  # star-shaped about the origin
            radii = r * rng.uniform(0.3, 1.0, size=k)
            ring = np.stack([radii * np.cos(t), radii * np.sin(t)], axis=1)
        if _turn_sines(ring).min() > _MIN_SIN:  # no vertex Map would drop as straight
            return ring


def random_map(
    seed: int,
    *,
    n_obstacles: int | None = None,
    n_vertices: int | None = None,
    size: float | tuple[float, float] | None = None,
    min_gap: float = 1.5,
    kind: str = "polygons",
    name: str | None = None,
) -> Map:
    """A seeded random map: non-touching obstacles in the rectangle [0, W] x [0, H].

    Args:
        seed: seed of the map's ``np.random.default_rng`` (an integer >= 0); the same
            seed and parameters give the same map (equal digests).
        n_obstacles: number of obstacles (default 6, or ``n_vertices // 6`` when
            ``n_vertices`` is given, at least 1).
        n_vertices: total number of obstacle vertices, split as evenly as possible;
            the map has ``n_vertices + 4`` walls. Default: at random, 3 to 8 per convex
            and 5 to 12 per star-shaped obstacle.
        size: ``W`` (a square) or ``(W, H)``; default: a square large enough for
            obstacles of circumradius about 2 (at least 10 x 10).
        min_gap: the smallest distance between two obstacles and between an obstacle and
            the boundary (the narrowest passage).
        kind: obstacle shapes, one of :data:`KINDS`.
        name: the map's name (default ``"random_{kind}_{seed}"``).

    Returns:
        The validated map.

    Raises:
        InvalidConfigError: naming a parameter value out of range.
        InfeasibleError: if the obstacles do not fit (size too small for ``n_obstacles``
            and ``min_gap``).

    Examples:
        >>> m = random_map(3, n_obstacles=4, n_vertices=20)
        >>> m.n_vertices, len(m.rings)
        (24, 5)
        >>> m == random_map(3, n_obstacles=4, n_vertices=20)
        True
    """
    seed = validation.integer("seed", seed, minimum=0)
    kind = validation.choice("kind", kind, KINDS)
    if n_vertices is not None:
        n_vertices = validation.integer("n_vertices", n_vertices, minimum=0, maximum=MAX_VERTICES)
    if n_obstacles is None:
        if n_vertices is None:
            n_obstacles = _DEFAULT_N_OBSTACLES
        elif kind == "rectangles":
            n_obstacles = n_vertices // 4
        else:
            n_obstacles = max(1, n_vertices // 6) if n_vertices >= 3 else 0
    n = validation.integer("n_obstacles", n_obstacles, minimum=0, maximum=MAX_OBSTACLES)
    if n == 0 and n_vertices:
        raise InvalidConfigError(f"n_vertices = {n_vertices}: expected 0 with n_obstacles = 0")
    min_gap = validation.positive("min_gap", min_gap)
    width, height = _size(size, n, min_gap)
    rng = np.random.default_rng(seed)
    if kind == "polygons":
        kinds = [("convex", "star")[int(b)] for b in rng.integers(0, 2, size=n)]
    else:
        kinds = [kind] * n
    counts = _vertex_counts(rng, kinds, n_vertices)

    # first radius: the obstacle's share of the room at packing fraction _FILL, and small
    # enough that the disk plus min_gap on both sides fits across the room
    fit = 0.5 * min(width, height) - min_gap
    share = math.sqrt(_FILL * width * height / (math.pi * max(n, 1))) - 0.5 * min_gap
    r_max = min(fit, share)
    if n and r_max <= 0:
        raise InfeasibleError(
            f"size={(width, height)} is too small for n_obstacles={n} with min_gap={min_gap}"
        )
    placed: list[Polygon] = []
    centres: list[tuple[float, float, float]] = []
    for i, (shape_kind, k) in enumerate(zip(kinds, counts, strict=True)):
        r = rng.uniform(0.6, 1.0) * r_max
        first = r
        while True:
            local = _shape(rng, shape_kind, k, r)
            xy = rng.uniform(
                [min_gap + r, min_gap + r],
                [width - min_gap - r, height - min_gap - r],
                size=(_TRIES, 2),
            )
            hit = None
            for cx, cy in xy:
                if all(
                    math.hypot(cx - x, cy - y) >= r + rj + min_gap
                    or shapely.distance(Polygon(local + np.array((cx, cy))), placed[j]) >= min_gap
                    for j, (x, y, rj) in enumerate(centres)
                ):
                    hit = (float(cx), float(cy))
                    break
            if hit is not None:
                break
            r *= _SHRINK
            if r < _SMALLEST * first:
                raise InfeasibleError(
                    f"could not place obstacle {i + 1} of n_obstacles={n} in size="
                    f"{(width, height)} with min_gap={min_gap}; use a larger size, fewer "
                    "obstacles or a smaller gap"
                )
        placed.append(Polygon(local + hit))
        centres.append((*hit, r))
    boundary = [(0.0, 0.0), (width, 0.0), (width, height), (0.0, height)]
    obstacles = [np.asarray(p.exterior.coords)[:-1] for p in placed]
    return Map(boundary, obstacles, name=name or f"random_{kind}_{seed}")
