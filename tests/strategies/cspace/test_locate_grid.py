"""Decomposition.locate's grid answers exactly what the region tree answers."""

from __future__ import annotations

import copy
import dataclasses
import math
import pickle

import numpy as np
import pytest
import shapely

from envs.maps import Map
from strategies.cspace import decompose
from tests.strategies.cspace._oracle import corridor, pillar_room, two_rooms


def _shifted_pillars() -> Map:
    """The pillar room far from the origin (the grid's padding scales with coordinates)."""
    dx, dy = 1000.3, -250.7
    w = pillar_room()
    return Map(
        [(x + dx, y + dy) for x, y in [(0, 0), (10, 0), (10, 10), (0, 10)]],
        [
            [(x + dx, y + dy) for x, y in ring]
            for ring in ([(3, 3), (5, 3), (5, 5), (3, 5)], [(6.5, 6), (8.5, 6.4), (7, 8)])
        ],
        name=f"{w.name}_shifted",
    )


def _queries(dec, rng) -> np.ndarray:
    """Uniform points, region vertices (on boundaries), vertices nudged by 1e-12 to 1e-3,
    and points on and just beside the grid's lines."""
    x0, y0, x1, y1 = dec.map.bounds
    uniform = rng.uniform([x0, y0], [x1, y1], size=(3000, 2))
    verts = np.concatenate([np.asarray(r.polygon.exterior.coords) for r in dec.regions])
    verts = verts[rng.integers(0, len(verts), 1500)]
    scale = 10.0 ** rng.uniform(-12, -3, size=(1500, 1))
    nudged = verts + scale * rng.normal(size=(1500, 2))
    g = dec.region_grid()
    nx, ny = g.labels.shape
    i = rng.integers(0, nx + 1, 1500)
    on_x = np.stack([g.origin[0] + i * g.h, rng.uniform(y0, y1, 1500)], axis=1)
    j = rng.integers(0, ny + 1, 1500)
    on_y = np.stack([rng.uniform(x0, x1, 1500), g.origin[1] + j * g.h], axis=1)
    lines = np.concatenate([on_x, on_y])
    beside = lines + rng.choice([-1.0, 1.0], size=(3000, 1)) * 1e-9 * g.h
    return np.concatenate([uniform, verts, nudged, lines, beside])


@pytest.mark.parametrize(
    "make, L", [(corridor, 2.0), (two_rooms, 2.0), (pillar_room, 1.5), (_shifted_pillars, 1.5)]
)
def test_grid_locate_agrees_with_the_tree(make, L):
    dec = decompose(make(), L)
    rng = np.random.default_rng(7)
    pts = _queries(dec, rng)
    g = dec.region_grid()
    fast = sum(g.region(float(x), float(y)) >= 0 for x, y in pts)
    wrong = [
        (tuple(p), dec.locate(p), dec._locate_tree(p))
        for p in pts
        if dec.locate(p) != dec._locate_tree(p)
    ]
    assert not wrong, f"{len(wrong)} of {len(pts)} points located differently, e.g. {wrong[:3]}"
    # the grid answers most of them (else this test checks only the fallback)
    inside = sum(dec._locate_tree(p) is not None for p in pts)
    assert fast >= 0.8 * inside, (fast, inside)


def test_cell_at_unchanged_by_the_grid_and_a_pickle_round_trip():
    dec = decompose(pillar_room(), 1.5)
    rng = np.random.default_rng(3)
    pts = rng.uniform([0, 0], [10, 10], size=(400, 2))
    th = rng.uniform(-math.pi, math.pi, 400)
    copy = pickle.loads(pickle.dumps(dec))
    assert copy._grid is None  # rebuilt on use, not stored
    for (x, y), t in zip(pts, th, strict=True):
        a, b = dec.cell_at(x, y, t), copy.cell_at(x, y, t)
        tree = dec._locate_tree(np.array([x, y]))
        assert (a and a.id) == (b and b.id)
        if a is not None:
            assert a.region in (tree, *dec._neighbours[tree])


def test_squares_near_an_invalid_polygon_ask_the_tree():
    dec = copy.copy(decompose(pillar_room(), 1.5))
    r = max(dec.regions, key=lambda r: r.area)
    x0, y0, x1, y1 = r.polygon.bounds
    bowtie = shapely.Polygon([(x0, y0), (x1, y1), (x1, y0), (x0, y1)])  # self-crossing
    assert not bowtie.is_valid
    dec.regions = tuple(
        dataclasses.replace(q, polygon=bowtie) if q.id == r.id else q for q in dec.regions
    )
    dec._index()
    g = dec.region_grid()
    i0 = math.floor((0.5 * (x0 + x1) - g.origin[0]) / g.h)
    j0 = math.floor((0.5 * (y0 + y1) - g.origin[1]) / g.h)
    assert g.labels[i0, j0] == -2
    rng = np.random.default_rng(5)
    pts = rng.uniform([x0, y0], [x1, y1], size=(500, 2))
    assert all(g.region(float(x), float(y)) == -1 for x, y in pts)
    assert all(dec.locate(p) == dec._locate_tree(p) for p in pts)
