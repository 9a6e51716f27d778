"""The vectorised free arcs of the build are the geometry kernel's, point for point.

The build computes free arcs for hundreds of thousands of points at once; the cells it
makes are found again at query time by :meth:`Kernel.free_arcs`, so both must report the
same stop pairs (and the same arcs) everywhere: at random points, on critical curves
(boundary probe points), at wall vertices and on walls, in many worlds.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from envs.geometry import kernel_for
from envs.maps import builtin_map, floor_plan, random_map
from strategies.cspace import decompose
from strategies.cspace._batch_arcs import free_arcs_batch, stop_code, stop_of
from tests.strategies.cspace._oracle import hexagons, stars, tilted_block

WORLDS = {
    "tilted_block": (tilted_block, 2.9),
    "stars": (stars, 2.2),
    "hexagons": (hexagons, 3.3),
    "office": (lambda: builtin_map("office"), 2.0),
    "random": (lambda: random_map(6, n_vertices=20), 1.7),
    "floor_plan": (lambda: floor_plan(0, n_vertices=200, size=(40.0, 40.0)), 3.0),
}


@pytest.mark.parametrize("name", list(WORLDS))
def test_batch_free_arcs_are_the_kernels(name):
    make, L = WORLDS[name]
    world = make()
    kernel = kernel_for(world)
    rng = np.random.default_rng(11)
    xmin, ymin, xmax, ymax = world.bounds
    dec = decompose(world, L)
    pts = np.vstack(
        [
            rng.uniform([xmin, ymin], [xmax, ymax], size=(1500, 2)),
            [b.point for b in dec.boundaries[:300]],  # on critical curves
            world.vertices,  # on walls, at corners
            0.5 * (world.edge_start + world.edge_end),  # on walls
            world.vertices + 1e-3 * world.edge_normal,  # just off the walls
        ]
    )
    batch = free_arcs_batch(world, pts, L)
    assert len(batch) == len(pts)
    for i, p in enumerate(pts):
        want = kernel.free_arcs(p, L).arcs
        got = batch.arcs(i)
        assert [(stop_code(a.stop_lo), stop_code(a.stop_hi)) for a in want] == list(
            batch.keys(i)
        ), (i, p)
        assert len(got) == len(want)
        for a, b in zip(want, got, strict=True):
            assert a.stop_lo == b.stop_lo and a.stop_hi == b.stop_hi
            assert math.isclose(a.lo, b.lo, abs_tol=1e-12)
            assert math.isclose(a.hi, b.hi, abs_tol=1e-12)


def test_stop_codes_round_trip():
    fa = kernel_for(builtin_map("corridor")).free_arcs((-3.0, 0.0), 2.0)
    for arc in fa.arcs:
        for stop in (arc.stop_lo, arc.stop_hi):
            assert stop_of(stop_code(stop)) == stop
    assert stop_of(stop_code(None)) is None
