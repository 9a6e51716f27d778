"""Seeded floor plans: rooms along corridors, walls with doors, for realistic large maps.

:func:`floor_plan` lays out a building ``W x H`` (metres, say) as horizontal *bands*: a
corridor with a row of rooms on each side, the rows of neighbouring bands back to back.
Two vertical corridors at the ends join the horizontal ones, so the wall blocks between
them are islands (holes of the free region). Every room has a door onto its corridor,
some also one onto a neighbour. Walls have a thickness; the free region is the exact
union of the rooms, corridors and door openings (axis-aligned rectangles, so vertices
are exact), turned by ``angle`` if asked (slanted walls everywhere), and validated by
:class:`~envs.maps.Map`.

The plan's size is fixed by ``size``; its complexity by ``n_vertices``: the rooms are made
as wide as needed for the map to have about that many wall vertices (within 30 %: a
small building may not fit fewer rooms; ``Map.n_vertices`` is the count). One
``np.random.default_rng(seed)`` drives every draw: the same seed and parameters give the
same map.

Examples:
    >>> m = floor_plan(1, n_vertices=300, size=(60.0, 60.0))
    >>> 255 <= m.n_vertices <= 345, len(m.rings) > 1
    (True, True)
    >>> m == floor_plan(1, n_vertices=300, size=(60.0, 60.0))
    True
"""

from __future__ import annotations

import math

import numpy as np
import shapely

from envs import validation
from envs.errors import InfeasibleError, InvalidConfigError
from envs.maps.map import Map

__all__ = ["floor_plan"]

_TRIES = 12  # room-width adjustments to reach the requested vertex count
_TOLERANCE = 0.15  # relative error accepted on the vertex count


def _rooms_along(rng, x0: float, x1: float, width: float, door: float, wall: float):
    """Split ``[x0, x1]`` into rooms about ``width`` wide: their (left, right) wall centres."""
    span = x1 - x0
    smallest = 2.0 * (door + 2.0 * wall)  # a room fits a door in each side wall
    n = max(1, min(round(span / width), math.floor(span / smallest)))
    nominal = span / n
    cuts = x0 + nominal * (np.arange(1, n) + rng.uniform(-0.2, 0.2, size=n - 1))
    edges = np.concatenate([[x0], cuts, [x1]])
    return list(zip(edges[:-1].tolist(), edges[1:].tolist(), strict=True))


def _layout(rng, W, H, room_w, depth, corridor, wall, door, p_link):
    """Boxes of free space (xmin, ymin, xmax, ymax) of one layout."""
    boxes = []
    band = 2 * depth + corridor + 2 * wall
    n_bands = max(1, math.floor((H - wall) / band))
    depth_b = (H - wall - n_bands * (corridor + 2 * wall)) / (2 * n_bands) - wall
    x_left, x_right = wall + corridor, W - wall - corridor
    h = 0.5 * wall
    # the two vertical corridors
    boxes.append((wall, wall, wall + corridor, H - wall))
    boxes.append((W - wall - corridor, wall, W - wall, H - wall))
    y = wall
    for _ in range(n_bands):
        lower = (y, y + depth_b)
        cy0 = y + depth_b + wall
        cor = (cy0, cy0 + corridor)
        upper = (cor[1] + wall, cor[1] + wall + depth_b)
        boxes.append((wall, cor[0], W - wall, cor[1]))
        for (ya, yb), door_y in ((lower, (lower[1], cor[0])), (upper, (cor[1], upper[0]))):
            rooms = _rooms_along(rng, x_left + wall, x_right - wall, room_w, door, wall)
            for k, (a, b) in enumerate(rooms):
                lo, hi = a + h, b - h
                boxes.append((lo, ya, hi, yb))
                dx = rng.uniform(lo + wall, max(lo + wall, hi - wall - door))
                boxes.append((dx, door_y[0] - 1e-9, dx + door, door_y[1] + 1e-9))
                if k + 1 < len(rooms) and rng.uniform() < p_link:
                    dy = rng.uniform(ya + wall, max(ya + wall, yb - wall - door))
                    boxes.append((hi - 1e-9, dy, hi + wall + 1e-9, dy + door))
        y = upper[1] + wall
    return boxes


def floor_plan(
    seed: int,
    *,
    n_vertices: int = 1000,
    size: float | tuple[float, float] = (200.0, 200.0),
    corridor: float = 2.5,
    room_depth: float = 8.0,
    wall: float = 0.25,
    door: float = 1.2,
    p_link: float = 0.3,
    angle: float = 0.0,
    name: str | None = None,
) -> Map:
    """A seeded floor plan: rooms along corridors, joined by doors.

    Args:
        seed: seed of the plan's ``np.random.default_rng`` (an integer >= 0).
        n_vertices: the wall vertices aimed at (the room width is adjusted to reach it
            within 15 %), at least 40.
        size: the building ``W`` (a square) or ``(W, H)``.
        corridor: corridor width.
        room_depth: depth of the rooms from their corridor (rounded so that the bands
            fill the building).
        wall: wall thickness.
        door: door width (the narrowest passage of the plan).
        p_link: probability that a room also has a door to its neighbour.
        angle: rotation of the whole plan, radians (slanted walls).
        name: the map's name (default ``"floor_plan_{seed}"``).

    Returns:
        The validated :class:`~envs.maps.Map`.

    Raises:
        InvalidConfigError: naming a parameter out of range.
        InfeasibleError: if no layout of the given size reaches the vertex count.
    """
    seed = validation.integer("seed", seed, minimum=0)
    n_vertices = validation.integer("n_vertices", n_vertices, minimum=40, maximum=200_000)
    if isinstance(size, (tuple, list)):
        if len(size) != 2:
            raise InvalidConfigError(f"size = {size!r}: expected a number or (width, height)")
        W, H = validation.positive("size[0]", size[0]), validation.positive("size[1]", size[1])
    else:
        W = H = validation.positive("size", size)
    corridor = validation.positive("corridor", corridor)
    room_depth = validation.positive("room_depth", room_depth)
    wall = validation.positive("wall", wall)
    door = validation.positive("door", door)
    p_link = validation.real("p_link", p_link, minimum=0.0, maximum=1.0)
    angle = validation.real("angle", angle)
    if door + 2 * wall >= room_depth or 2 * corridor + 4 * wall + 2 * door >= W:
        raise InvalidConfigError(
            f"door = {door:g}, wall = {wall:g}: too wide for rooms {room_depth:g} deep in a "
            f"building {W:g} wide"
        )
    if H < 2 * room_depth + corridor + 3 * wall:
        raise InvalidConfigError(
            f"size = {(W, H)}: expected a height of at least one band, "
            f"2 * room_depth + corridor + 3 * wall = {2 * room_depth + corridor + 3 * wall:g}"
        )
    name = f"floor_plan_{seed}" if name is None else validation.string("name", name)
    # about 10 vertices per room: fix the room width by the count, then correct it
    band = 2 * room_depth + corridor + 2 * wall
    rows = 2 * max(1, math.floor((H - wall) / band))
    room_w = rows * (W - 2 * corridor) / max(n_vertices / 10.0, 1.0)
    best = None
    for _ in range(_TRIES):
        room_w = max(room_w, 2 * door + 4 * wall)
        rng = np.random.default_rng(seed)
        boxes = np.array(_layout(rng, W, H, room_w, room_depth, corridor, wall, door, p_link))
        free = shapely.union_all(shapely.box(*boxes.T))
        free = shapely.set_precision(free, 1e-9 * max(W, H))
        if free.geom_type != "Polygon":
            raise InfeasibleError(f"floor_plan({seed}): the rooms do not form one connected plan")
        world = _map(free, angle, name)
        err = world.n_vertices / n_vertices - 1.0
        if best is None or abs(err) < abs(best[0]):
            best = (err, world)
        if abs(err) <= _TOLERANCE:
            break
        room_w *= (1.0 + err) ** 1.1
    err, world = best
    if abs(err) > 2 * _TOLERANCE:
        raise InfeasibleError(
            f"floor_plan({seed}): n_vertices = {n_vertices} is out of reach for a "
            f"{W:g} x {H:g} building (closest: {round((1 + err) * n_vertices)})"
        )
    return world


def _map(free, angle: float, name: str) -> Map:
    """The free region as a map, turned by ``angle``."""
    if angle:
        c, s = math.cos(angle), math.sin(angle)
        free = shapely.transform(free, lambda x: x @ np.array([[c, s], [-s, c]]))
    holes = [np.asarray(r.coords)[:-1] for r in free.interiors]
    return Map(np.asarray(free.exterior.coords)[:-1], holes, name=name)
