"""A wall edge within a few 1e-6 L of L (issue 10: hexagons seed 989049 at L = 2).

One regular hexagon of side ``L (1 + r)`` in a small room. When the side is near L, the
type-2 arcs about two neighbouring vertices, the type-4 segments along the edges beside
them and their ends meet within about ``|r| L`` of each other: faces and boundary pieces
a few ``|r| L`` across, some of them next to a wall vertex. Two things went wrong there:

* the kernel computed the angle of a wall vertex inside the disk twice (as the end of
  one edge, ``start + length * direction``, and as the start of the next), an ulp apart;
  seen from within ~1e-4 of the vertex that is more than ``ANGLE_TOL``, and a spurious
  free arc between two body-on-vertex stops opened, differently in every frame. It now
  takes both from the vertex's coordinates;
* the kernel compares angles to ``ANGLE_TOL``, so near the end of a type-4 segment on a
  type-2 arc its stops are not the exact ones in a cusp about ``ANGLE_TOL * L**2 / d``
  wide at distance d from that end: faces within about ``sqrt(ANGLE_TOL) * L`` of it
  cannot be sampled. Faces of half-perimeter below ``COLLAPSE_REL * L`` (a length, not
  a coordinate) are now *specks*: they carry no cells and their pieces separate
  nothing, as if the curves met at one point, which they do when the side is exactly L.

Every offset is exact (no warning) and its counts and verdict are invariant under a
rotation and scalings by 1e3 and 1e-3.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from envs.geometry import kernel_for
from envs.maps import Map
from strategies.cspace._batch_arcs import free_arcs_batch, stop_code
from strategies.cspace._build import build_decomposition

L = 2.0

OFFSETS = (-1e-4, -2e-5, -5e-6, -1e-6, -3e-7, 0.0, 3e-7, 1e-6, 5e-6, 2e-5, 1e-4)


def _hexagon_room(side: float) -> Map:
    a = 0.3 + 2.0 * math.pi * np.arange(6) / 6
    hexagon = np.c_[side * np.cos(a), side * np.sin(a)]
    h = 4.2
    return Map([(-h, -h), (h, -h), (h, h), (-h, h)], [hexagon], name="hexagon")


def _similar(world: Map, angle: float, scale: float) -> Map:
    c, s = math.cos(angle), math.sin(angle)
    return world.transformed([[scale * c, -scale * s], [scale * s, scale * c]], (0.0, 0.0))


def _build(world: Map, length: float):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        d = build_decomposition(world, length)
    assert d.exact and d.unresolved == 0
    return d


def _fingerprint(world: Map, length: float) -> tuple:
    d = _build(world, length)
    return len(d.regions), len(d.cells), len(d.escapable), bool(d.evader_wins)


@pytest.mark.parametrize("r", OFFSETS)
def test_hexagon_side_near_L(r):
    world = _hexagon_room(L * (1.0 + r))
    base = _fingerprint(world, L)
    assert _fingerprint(_similar(world, 0.7, 1.0), L) == base
    assert _fingerprint(_similar(world, 0.0, 1e3), 1e3 * L) == base
    assert _fingerprint(_similar(world, 2.1, 1e-3), 1e-3 * L) == base


@pytest.mark.parametrize("r", [-1e-6, 1e-6])
def test_specks_collapse_to_the_exact_degeneracy(r):
    """Within the collapse tolerance of the degenerate world (side exactly L), the
    pulled-apart meeting points are specks and the answer is the degenerate one."""
    exact = _fingerprint(_hexagon_room(L), L)
    d = _build(_hexagon_room(L * (1.0 + r)), L)
    assert d.stats["specks"] > 0
    assert (len(d.regions), len(d.cells), len(d.escapable), bool(d.evader_wins)) == exact


@pytest.mark.parametrize("angle", [0.0, 0.7, 2.1])
def test_no_spurious_arc_next_to_a_wall_vertex(angle):
    """Within 1e-8..1e-3 of a hexagon vertex, no free arc between two body contacts with
    one vertex (the two edges' blocks meet exactly), and the batch agrees with the kernel."""
    world = _similar(_hexagon_room(L * (1.0 - 1e-4)), angle, 1.0)
    kernel = kernel_for(world)
    V = np.asarray(world.vertices)[4:]  # the hexagon's
    d = np.geomspace(1e-8, 1e-3, 11)
    t = np.linspace(-1.0, 1.0, 7)
    pts = []
    for v in V:
        out = math.atan2(v[1], v[0])  # away from the hexagon's centre
        pts.append(v + (d[:, None, None] * np.stack([np.cos(out + t), np.sin(out + t)], -1)))
    pts = np.concatenate([p.reshape(-1, 2) for p in pts])
    batch = free_arcs_batch(world, pts, L)
    for i, p in enumerate(pts):
        arcs = kernel.free_arcs(p, L).arcs
        assert not [a for a in arcs if a.stop_lo == a.stop_hi and a.stop_lo.kind == "body"]
        assert tuple((stop_code(a.stop_lo), stop_code(a.stop_hi)) for a in arcs) == batch.keys(i)
