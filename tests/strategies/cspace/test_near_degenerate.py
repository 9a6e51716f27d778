"""A wall edge within a few 1e-6 L of L (issue 10: hexagons seed 989049 at L = 2).

One regular hexagon of side ``L (1 + r)`` in a small room. When the side is near L, the
type-2 arcs about two neighbouring vertices, the type-4 segments along the edges beside
them and their ends meet within about ``|r| L`` of each other: faces and boundary pieces
a few 1e-6 L across. There the kernel's stops are not everywhere the exact ones: it takes
a wall edge blocking less than ``ANGLE_TOL`` for a contact, which near the end of a type-4
segment on a type-2 arc is a cusp about ``ANGLE_TOL * L**2 / d`` wide at distance d from
that end (about 1e-6 L at d = 2e-6 L), and next to a wall vertex the two computations of
its angle round apart by more than ``ANGLE_TOL``. The probes at the middle of such a
piece could fall in a cusp on every offset; they now also try other points of the edge.

The offsets marked xfail are still inexact or not invariant under a similarity (some
faces are smaller than the kernel can resolve and are neither slivers nor sampled at a
point where its stops are exact): see issue 10.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from envs.maps import Map
from strategies.cspace._build import build_decomposition

L = 2.0

STILL_INEXACT = {-2e-5, -5e-6, -1e-6, 2e-5}


def _hexagon_room(side: float) -> Map:
    a = 0.3 + 2.0 * math.pi * np.arange(6) / 6
    hexagon = np.c_[side * np.cos(a), side * np.sin(a)]
    h = 4.2
    return Map([(-h, -h), (h, -h), (h, h), (-h, h)], [hexagon], name="hexagon")


def _similar(world: Map, angle: float, scale: float) -> Map:
    c, s = math.cos(angle), math.sin(angle)
    return world.transformed([[scale * c, -scale * s], [scale * s, scale * c]], (0.0, 0.0))


def _fingerprint(world: Map, length: float) -> tuple:
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        d = build_decomposition(world, length)
    assert d.exact and d.unresolved == 0
    return len(d.regions), len(d.cells), len(d.escapable), bool(d.evader_wins)


@pytest.mark.parametrize(
    "r",
    [
        pytest.param(
            r,
            marks=pytest.mark.xfail(strict=True, reason="issue 10: not yet exact")
            if r in STILL_INEXACT
            else (),
        )
        for r in (-2e-5, -5e-6, -1e-6, 0.0, 1e-6, 5e-6, 2e-5)
    ],
)
def test_hexagon_side_near_L(r):
    world = _hexagon_room(L * (1.0 + r))
    base = _fingerprint(world, L)
    assert _fingerprint(_similar(world, 0.7, 1.0), L) == base
    assert _fingerprint(_similar(world, 0.0, 1e3), 1e3 * L) == base
