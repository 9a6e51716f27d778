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
from strategies.cspace import _batch_arcs, decompose
from strategies.cspace._batch_arcs import free_arcs_batch, free_arcs_few, stop_code, stop_of
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


@pytest.mark.parametrize("name", list(WORLDS))
def test_the_few_points_arcs_are_the_batchs_bit_for_bit(name, monkeypatch):
    """free_arcs_few (a lazy table's batches: a few dozen points, one index query, one
    padded sweep) returns the batch's arrays exactly: at random points, on critical
    curves, at and on walls, at distance L from vertices, outside the free region, in
    batches of 1 to 80 points, at L where chains of edges fit in the disk and merge."""
    make, L = WORLDS[name]
    world = make()
    xmin, ymin, xmax, ymax = world.bounds
    dec = decompose(world, L)
    rng = np.random.default_rng(5)
    ang = rng.uniform(-math.pi, math.pi, len(world.vertices))
    pts = np.vstack(
        [
            rng.uniform([xmin - 1, ymin - 1], [xmax + 1, ymax + 1], size=(600, 2)),
            [b.point for b in dec.boundaries[:150]],
            world.vertices,
            0.5 * (world.edge_start + world.edge_end),
            world.vertices + 1e-3 * world.edge_normal,
            world.vertices + L * np.column_stack([np.cos(ang), np.sin(ang)]),
        ]
    )
    pts = pts[rng.permutation(len(pts))]
    span = max(xmax - xmin, ymax - ymin)
    seen = {"wall": 0, "gaps": 0, "none": 0, "merged": 0}
    chains = _batch_arcs._chains

    def counted(*args):
        seen["merged"] += 1
        return chains(*args)

    monkeypatch.setattr(_batch_arcs, "_chains", counted)
    for length in (L, 0.3 * L, 0.45 * span):
        s = 0
        while s < len(pts):
            k = int(rng.integers(1, 81))
            p = pts[s : s + k]
            s += k
            want, got = free_arcs_batch(world, p, length), free_arcs_few(world, p, length)
            for f in ("offsets", "lo", "hi", "code_lo", "code_hi"):
                assert np.array_equal(getattr(want, f), getattr(got, f)), (f, length, s)
                assert getattr(want, f).dtype == getattr(got, f).dtype, f
            counts = np.diff(got.offsets)
            seen["gaps"] += int((counts > 1).sum())
            seen["none"] += int((counts == 0).sum())
            seen["wall"] += int(world.distance_to_walls(p).min() <= 1e-9)
    assert all(seen.values()), seen
    # a large batch (one chunk of the batch's), and batches it takes in several chunks
    # (its chunk size made small: the few points' answer is then the batch's own)
    many = np.vstack([pts + rng.normal(0.0, 0.05, pts.shape) for _ in range(3)])
    for chunk in (_batch_arcs._CHUNK, len(many) // 2):  # (then at least two chunks)
        monkeypatch.setattr(_batch_arcs, "_CHUNK", chunk)
        for p in (many, many[:700]):
            want, got = free_arcs_batch(world, p, L), free_arcs_few(world, p, L)
            for f in ("offsets", "lo", "hi", "code_lo", "code_hi"):
                assert np.array_equal(getattr(want, f), getattr(got, f)), (f, chunk, len(p))
