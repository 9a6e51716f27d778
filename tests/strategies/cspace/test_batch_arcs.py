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
import shapely

from envs.geometry import kernel_for
from envs.maps import builtin_map, floor_plan, random_map
from strategies.cspace import _batch_arcs, decompose
from strategies.cspace._batch_arcs import (
    WallCells,
    free_arcs_batch,
    free_arcs_few,
    stop_code,
    stop_of,
)
from strategies.cspace._candidates import wall_index
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


@pytest.mark.parametrize("name", list(WORLDS))
def test_wall_cells_give_the_index_querys_pairs_and_its_arcs(name):
    """WallCells (a lazy table's batches find their (point, edge) pairs by square cells
    instead of the wall index's query a point at a time): every pair the query reports
    is a candidate, the candidates kept are exactly the query's pairs within reach (also
    with the border where the query decides made wide, so that most pairs go to it), and
    free_arcs_few's arrays are the batch's bit for bit; points off the cells' grid and
    batches of more points than one chunk's worth of candidates take the query."""
    make, L = WORLDS[name]
    world = make()
    xmin, ymin, xmax, ymax = world.bounds
    dec = decompose(world, L)
    tree = wall_index(world).tree
    eps = kernel_for(world).eps
    rng = np.random.default_rng(8)
    ang = rng.uniform(-math.pi, math.pi, len(world.vertices))
    pts = np.vstack(
        [
            rng.uniform([xmin, ymin], [xmax, ymax], size=(600, 2)),
            [b.point for b in dec.boundaries[:150]],
            world.vertices,
            0.5 * (world.edge_start + world.edge_end),
            world.vertices + 1e-3 * world.edge_normal,
            world.vertices + (L + eps) * np.column_stack([np.cos(ang), np.sin(ang)]),
        ]
    )
    pts = pts[rng.permutation(len(pts))]
    for length in (L, 0.3 * L):
        cells = WallCells(world, tree, length + eps)
        wide = WallCells(world, tree, length + eps)
        wide.border = 0.05 * length  # (the query decides every pair within 5 % of reach)
        s = grid = dropped = 0
        while s < len(pts):
            k = int(rng.integers(1, 81))
            p = pts[s : s + k]
            s += k
            qp, qe = tree.query(shapely.points(p), predicate="dwithin", distance=length + eps)
            pairs = cells.candidates(p)
            if pairs is None:  # a point beyond a reach of the map's bounds (0.3 L)
                lo, hi = np.array([xmin, ymin]), np.array([xmax, ymax])
                assert ((p < lo - cells.reach) | (p > hi + cells.reach)).any() and length < L
                continue
            grid += 1
            pid, e = pairs
            query = set(zip(qp.tolist(), qe.tolist(), strict=True))
            assert query <= set(zip(pid.tolist(), e.tolist(), strict=True))
            # the query's pairs within reach by _blocks' distance: the candidates kept
            a, u = world.edge_start[e], world.edge_dir[e]
            wx, wy = a[:, 0] - p[pid, 0], a[:, 1] - p[pid, 1]
            sc = np.clip(-(wx * u[:, 0] + wy * u[:, 1]), 0.0, world.edge_length[e])
            dist = np.hypot(wx + sc * u[:, 0], wy + sc * u[:, 1])
            for c in (cells, wide):
                keep = dist <= length + eps
                want = keep & np.array(
                    [(i, j) in query for i, j in zip(pid.tolist(), e.tolist(), strict=True)],
                    dtype=bool,
                )
                c.reported(p, pid, e, dist, keep)
                assert np.array_equal(keep, want), (length, s)
                got = free_arcs_few(world, p, length, cells=c)
                ref = free_arcs_batch(world, p, length)
                for f in ("offsets", "lo", "hi", "code_lo", "code_hi"):
                    assert np.array_equal(getattr(ref, f), getattr(got, f)), (f, length, s)
                    assert getattr(ref, f).dtype == getattr(got, f).dtype, f
            # distances 3 % short: the pairs then within reach but beyond it by the
            # query's are in the wide border, where the query's verdict drops them
            short = 0.97 * dist
            keep = short <= length + eps
            want = keep & np.array(
                [(i, j) in query for i, j in zip(pid.tolist(), e.tolist(), strict=True)],
                dtype=bool,
            )
            dropped += int((keep & ~want).sum())
            wide.reported(p, pid, e, short, keep)
            assert np.array_equal(keep, want), (length, s)
        assert grid >= 10 and dropped > 0
        # off the cells' grid, and more points than one chunk's worth: the query's
        far = xmin - length - eps - 3 * cells.side - 1.0
        assert cells.candidates(np.array([[far, ymin]])) is None
        many = np.repeat(pts[:1], cells.points_one_chunk + 1, axis=0)
        assert cells.candidates(many) is None
        off = np.array([[far, ymin], [xmin, ymin]])
        for p in (off, many[:50]):
            got, ref = free_arcs_few(world, p, length, cells=cells), free_arcs_few(world, p, length)
            for f in ("offsets", "lo", "hi", "code_lo", "code_hi"):
                assert np.array_equal(getattr(ref, f), getattr(got, f)), f
