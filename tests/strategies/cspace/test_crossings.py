"""Crossing a critical curve changes the stops as THEORY.md 1.4 says; crossing none changes
nothing. Random points, the geometry kernel's exact free arcs and a shapely brute force
as oracles."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely

from envs.geometry import Stop, kernel_for
from envs.maps import Feature, random_map
from strategies.cspace import critical_curves
from tests.strategies.cspace._oracle import (
    brute_free,
    circular_runs,
    corridor,
    pillar_room,
    resolvable,
    stop_pairs,
    stops,
    two_rooms,
)

WORLDS = {
    "corridor": corridor,
    "two_rooms": two_rooms,
    "pillars": pillar_room,
    "random5": lambda: random_map(5, n_vertices=12),
    "random8": lambda: random_map(8, n_vertices=10),
}


def _involved(world, curve) -> set[Feature]:
    """The curve's features, the edges at its vertices and the vertices of its edges."""
    out = set(curve.features)
    for f in curve.features:
        if f.kind == "vertex":
            out.add(Feature("edge", int(world.vertex_prev_edge[f.index])))
            out.add(Feature("edge", int(world.vertex_next_edge[f.index])))
        else:
            for v in world.edge_vertices[f.index]:
                out.add(Feature("vertex", int(v)))
    return out


def _crossing_samples(world, L, rng, per_curve=4, delta=2e-4):
    """Random points on the curves, away from the other curves, with a unit normal."""
    curves = critical_curves(world, L)
    tree = shapely.STRtree([shapely.LineString(c.points) for c in curves])
    for i, c in enumerate(curves):
        if c.type == 0:
            continue
        span = c.t1 - c.t0
        for t in rng.uniform(c.t0 + 0.1 * span, c.t1 - 0.1 * span, per_curve):
            h = 1e-6 * span
            (p0, p, p1), _ = c.evaluate(np.array([t - h, t, t + h]))
            tangent = (p1 - p0) / np.hypot(*(p1 - p0))
            n = np.array([-tangent[1], tangent[0]])
            near = tree.query(shapely.Point(p), "dwithin", 50 * delta + 3 * c.tolerance)
            if set(near.tolist()) - {i}:
                continue
            a, b = p + delta * n, p - delta * n
            if world.distance_to_walls(np.stack([a, b])).min() < 10 * delta:
                continue
            yield c, a, b


@pytest.mark.parametrize("name", list(WORLDS))
@pytest.mark.parametrize("L", [1.5, 2.5])
def test_every_crossing_changes_the_stops_of_the_curves_features(name, L):
    world = WORLDS[name]()
    kernel = kernel_for(world)
    rng = np.random.default_rng(11)
    checked = set()
    n_samples = 0
    for c, a, b in _crossing_samples(world, L, rng):
        fa, fb = kernel.free_arcs(a, L), kernel.free_arcs(b, L)
        sa, sb = stops(fa), stops(fb)
        diff = (sa - sb) + (sb - sa)
        assert diff, f"{c.name}: crossing at {a} / {b} changes nothing"
        involved = _involved(world, c)
        assert {s.feature for s in diff} <= involved, (c.name, diff)
        if c.type == 1:  # a blocked interval of the edge appears: two tip-on-edge stops
            tip = [s for s in diff if s.kind == "tip" and s.feature == c.features[0]]
            assert sum(diff[s] for s in tip) == 2, (c.name, diff)
        if c.type == 3:  # a pinched arc between the two body contacts
            assert abs(len(fa.arcs) - len(fb.arcs)) == 1, c.name
            pinched = {s.feature for s in diff}
            assert pinched == set(c.features), (c.name, diff)
        if c.type in (4, 5):  # the body contact at the curve's vertex appears or goes
            assert Stop("body", c.features[0]) in diff, (c.name, diff)
        checked.add(c.type)
        # the shapely brute force sees the same number of free arcs on each side
        n_samples += 1
        for p, fa_ in ((a, fa), (b, fb)) if n_samples % 3 == 0 else ():
            mask = brute_free(world, p, L, n=2048)
            if fa_.is_full:
                assert mask.all()
            elif resolvable(fa_.arcs, 4 * 2 * math.pi / 2048):
                assert circular_runs(mask) == len(fa_.arcs), (c.name, p)
    assert {1, 2} <= checked


@pytest.mark.parametrize("name", list(WORLDS))
def test_segments_that_cross_no_curve_keep_the_stop_pairs(name):
    world = WORLDS[name]()
    L = 2.0
    kernel = kernel_for(world)
    curves = critical_curves(world, L)
    union = shapely.union_all([shapely.LineString(c.points) for c in curves])
    tol = max(c.tolerance for c in curves)
    rng = np.random.default_rng(3)
    xmin, ymin, xmax, ymax = world.bounds
    n_pairs = 0
    for _ in range(4000):
        p = rng.uniform([xmin, ymin], [xmax, ymax])
        q = p + rng.uniform(0.02, 0.4) * np.array([math.cos(t := rng.uniform(0, 7)), math.sin(t)])
        seg = shapely.LineString([p, q])
        if not world.contains(np.stack([p, q])).all() or seg.distance(union) < 3 * tol + 1e-6:
            continue
        assert stop_pairs(kernel.free_arcs(p, L)) == stop_pairs(kernel.free_arcs(q, L)), (p, q)
        n_pairs += 1
        if n_pairs >= 150:
            break
    assert n_pairs >= 100
