"""Small example worlds of the figures (the paper draws its catalog and Fig. 8 on sketches).

The paper's own worlds (Figs. 3, 6, 9) are the built-in maps ``corridor``, ``two_rooms``
and ``corner`` (THEORY.md section 3); the ones here only serve the illustrations: one
obstacle feature set per critical-curve type (Fig. 2), the births of escapable cells
(Fig. 8) and the L-shaped hall whose critical length Prop. 1 misses (erratum E10).
"""

from __future__ import annotations

import numpy as np

from envs.errors import InvalidConfigError
from envs.maps import Feature, Map

__all__ = [
    "edge_near",
    "l_hall",
    "pillar_room",
    "room_corner",
    "staggered_pillars",
    "two_pillars",
    "vertex_above_floor",
    "vertex_near",
]


def pillar_room() -> Map:
    """A 10 x 8 room with a 2 x 2 square pillar [4, 6] x [3, 5] (four convex corners)."""
    return Map(
        [(0, 0), (10, 0), (10, 8), (0, 8)],
        [[(4, 3), (6, 3), (6, 5), (4, 5)]],
        name="pillar_room",
    )


def two_pillars(gap: float = 2.0) -> Map:
    """Two 2 x 2 pillars side by side with facing corners ``gap`` apart, in a 12 x 8 room."""
    x = 5.0 + gap
    return Map(
        [(0, 0), (12, 0), (12, 8), (0, 8)],
        [[(3, 3), (5, 3), (5, 5), (3, 5)], [(x, 3), (x + 2, 3), (x + 2, 5), (x, 5)]],
        name=f"two_pillars_{gap:g}",
    )


def staggered_pillars() -> Map:
    """Two 2 x 2 pillars, the second raised by 1: the corners (5, 5) and (6, 4) are
    sqrt(2) apart, so a type-3 curve threads between them once L > sqrt(2)."""
    return Map(
        [(0, 0), (11, 0), (11, 9), (0, 9)],
        [[(3, 3), (5, 3), (5, 5), (3, 5)], [(6, 4), (8, 4), (8, 6), (6, 6)]],
        name="staggered_pillars",
    )


def vertex_above_floor(height: float = 1.2) -> Map:
    """A 12 x 8 room with a narrow triangle whose lowest vertex v = (6, height) points at
    the floor: v and the floor edge define a type-5 curve once L > height."""
    return Map(
        [(0, 0), (12, 0), (12, 8), (0, 8)],
        [[(5.4, height + 2.5), (6.0, height), (6.6, height + 2.5)]],
        name=f"vertex_above_floor_{height:g}",
    )


def room_corner(size: float = 6.0) -> Map:
    """An empty square room ``[0, size]^2``: four concave corners (type-2 pockets)."""
    return Map([(0, 0), (size, 0), (size, size), (0, size)], name=f"room_{size:g}")


def l_hall(width: float = 4.0, arm: float = 10.0) -> Map:
    """An L-shaped hall, arms ``arm`` long and ``width`` wide, one convex corner at
    (width, width).

    Its outer walls x = 0 and y = 0 give two type-1 lines x = L and y = L that always meet
    at (L, L); that point lies on the type-2 circle of radius L about the convex corner
    when sqrt(2) (width - L) = L, i.e. L = (2 - sqrt 2) width (8 - 4 sqrt 2 for width 4):
    a triple point, which no vertex-vertex or vertex-edge distance (or half of one)
    predicts (erratum E10).
    """
    w, a = float(width), float(arm)
    return Map([(0, 0), (a, 0), (a, w), (w, w), (w, a), (0, a)], name=f"l_hall_{w:g}")


def vertex_near(world: Map, xy) -> Feature:
    """The wall vertex at ``xy`` (exactly one within 1e-9 of it)."""
    d = np.hypot(*(world.vertices - np.asarray(xy, dtype=float)).T)
    i = int(np.argmin(d))
    if d[i] > 1e-9 * world.scale:
        raise InvalidConfigError(f"no vertex of {world.name!r} at {tuple(xy)}")
    return Feature("vertex", i)


def edge_near(world: Map, a, b) -> Feature:
    """The wall edge joining ``a`` and ``b`` (in either direction)."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    tol = 1e-9 * world.scale
    for e in range(world.n_edges):
        s, t = world.edge_start[e], world.edge_end[e]
        if (np.allclose(s, a, atol=tol) and np.allclose(t, b, atol=tol)) or (
            np.allclose(s, b, atol=tol) and np.allclose(t, a, atol=tol)
        ):
            return Feature("edge", e)
    raise InvalidConfigError(f"no edge of {world.name!r} joins {tuple(a)} and {tuple(b)}")
