"""Small inline worlds for the env tests (independent of the built-in map files)."""

from __future__ import annotations

import numpy as np

from envs.maps import Map


def open_room(size: float = 10.0) -> Map:
    """An empty square room."""
    return Map([(0, 0), (size, 0), (size, size), (0, size)], name="test_open")


def pillar_room() -> Map:
    """A 10 x 10 room with one 2 x 2 pillar in the middle (four convex corners)."""
    return Map(
        [(0, 0), (10, 0), (10, 10), (0, 10)],
        [[(4, 4), (6, 4), (6, 6), (4, 6)]],
        name="test_pillar",
    )


def thin_pillar_room() -> Map:
    """A 10 x 10 room with a tiny 0.1 x 0.1 pillar a rod can sweep across in one step."""
    return Map(
        [(0, 0), (10, 0), (10, 10), (0, 10)],
        [[(4.95, 5.0), (5.05, 5.0), (5.05, 5.1), (4.95, 5.1)]],
        name="test_thin_pillar",
    )


def l_room() -> Map:
    """An L-shaped hall: the square [0, 10]^2 minus [5, 10] x [5, 10] (one convex corner)."""
    return Map([(0, 0), (10, 0), (10, 5), (5, 5), (5, 10), (0, 10)], name="test_l")


def spiky_room() -> Map:
    """A room with narrow features: saw-tooth walls, slits and sharp spikes.

    Bodies pushed around at random must never leave free space here.
    """
    bottom = [(0.0, 0.0)]
    for i in range(10):  # saw teeth along the floor, 0.6 wide and 0.8 tall
        bottom += [(i * 1.0 + 0.2, 0.0), (i * 1.0 + 0.5, 0.8), (i * 1.0 + 0.8, 0.0)]
    boundary = [*bottom, (10.0, 0.0), (10.0, 6.0), (6.2, 6.0), (6.1, 3.0), (6.0, 6.0), (0.0, 6.0)]
    spikes = [
        [(2.0, 3.0), (4.5, 3.05), (2.0, 3.1)],  # a needle 0.1 wide at its base
        [(7.5, 2.0), (8.0, 2.0), (7.75, 4.5)],
        [(1.0, 4.5), (1.3, 4.5), (1.3, 4.8), (1.0, 4.8)],
    ]
    return Map(boundary, spikes, name="test_spiky")


def as_point(p) -> np.ndarray:
    return np.asarray(p, dtype=float)
