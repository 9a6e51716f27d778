"""Variable L: Prop. 1's critical lengths, Sec. 3's stratified graph G, Prop. 4's verdict."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely

from envs.errors import InvalidConfigError
from envs.maps import Map
from strategies.cspace import (
    candidate_lengths,
    critical_lengths,
    decompose,
    graph_signature,
    stratified_graph,
    surveillance_verdict,
)
from strategies.cspace._rod import rods_semifree
from tests.strategies.cspace._oracle import corridor, open_room, two_rooms


def two_pillars(gap: float = 2.0) -> Map:
    """Two 2 x 2 pillars side by side, ``gap`` apart, in a 12 x 8 room."""
    x = 5.0 + gap
    return Map(
        [(0, 0), (12, 0), (12, 8), (0, 8)],
        [[(3, 3), (5, 3), (5, 5), (3, 5)], [(x, 3), (x + 2, 3), (x + 2, 5), (x, 5)]],
        name="two_pillars",
    )


def test_candidates_are_distances_and_their_halves():
    world = two_pillars(2.0)
    cands = candidate_lengths(world, 0.5, 6.0)
    assert list(cands) == sorted(set(cands))
    assert all(0.5 < c < 6.0 for c in cands)
    for want in (2.0, 1.0, 3.0, 1.5, math.hypot(2, 2), math.hypot(2, 2) / 2):
        assert any(abs(c - want) < 1e-9 for c in cands), want


@pytest.mark.parametrize("angle", [0.05, 0.37, 0.7, 2.5])
@pytest.mark.parametrize("offset", [(0.0, 0.0), (1e4, -3e4)])
def test_candidates_are_the_same_in_every_frame(angle, offset):
    """Two pillars' corners 6 apart, with l_max = 6: a rotated or shifted copy computed
    that distance as 5.999999999999 and counted it inside (0.5, 6), where the original
    has it at l_max, outside (24 candidates against 23; critical_lengths likewise found
    one more critical length, at l_max, in the rotated frame; E.md probe, s23)."""
    world = two_pillars(2.0)
    c, s = math.cos(angle), math.sin(angle)
    moved = world.transformed([[c, -s], [s, c]], offset)
    here, there = candidate_lengths(world, 0.5, 6.0), candidate_lengths(moved, 0.5, 6.0)
    assert len(here) == len(there) == 23
    np.testing.assert_allclose(there, here, rtol=0, atol=1e-9)


def test_signature_ignores_geometry_but_sees_structure():
    world = two_pillars(2.0)
    a = graph_signature(decompose(world, 1.62))
    assert graph_signature(decompose(world, 1.64)) == a  # no candidate in between
    moved = world.transformed([[1.0, 0.0], [0.0, 1.0]], (4.0, -2.0))
    assert moved.n_vertices == world.n_vertices
    assert graph_signature(decompose(moved, 1.62)) == a
    assert graph_signature(decompose(world, 2.5)) != a


def test_critical_lengths_find_the_type3_birth():
    """A type-3 curve appears at L = d (Prop. 1 (a)): G_L changes there."""
    world = two_pillars(2.0)
    crit = critical_lengths(world, 1.9, 2.1, samples=1)
    assert any(abs(c - 2.0) < 1e-9 for c in crit), crit
    below = graph_signature(decompose(world, 1.95))
    above = graph_signature(decompose(world, 2.05))
    assert below != above


@pytest.mark.slow
def test_critical_lengths_locate_events_prop1_misses_by_bisection():
    """Erratum E10: the end a + L n of edge [(-1, 0), (1, 0)]'s type-1 segment crosses the
    type-2 circle of radius L about v = (3, 1.2) at L* = |w|^2 / (2 w.n), w = v - a,
    which is no vertex-vertex or vertex-edge distance nor half of one."""
    world = Map(
        [(-8, -8), (12, -8), (12, 10), (-8, 10)],
        [[(-1, -2), (1, -2), (1, 0), (-1, 0)], [(3, 1.2), (3.8, 2.0), (3.0, 2.6)]],
    )
    w = np.array([3.0, 1.2]) - np.array([1.0, 0.0])
    star = float(w @ w / (2 * w[1]))
    lo, hi = star - 0.01, star + 0.01
    assert candidate_lengths(world, lo, hi) == ()
    assert graph_signature(decompose(world, lo)) != graph_signature(decompose(world, hi))
    crit = critical_lengths(world, lo, hi, samples=2, tol=2e-4)
    assert crit and min(abs(c - star) for c in crit) < 1e-3, (star, crit)
    for c in crit:  # each reported event separates different structures
        assert lo < c < hi


def test_stratified_graph_links_every_cell_to_the_shorter_rod():
    """Theta_f(P; L') is inside Theta_f(P; L) for L' > L: every cell of G_{i+1} links to G_i."""
    world = two_pillars(2.0)
    sg = stratified_graph(world, 1.7, 2.3, critical=(2.0,))
    assert sg.samples == pytest.approx((1.85, 2.15))
    assert sg.graph.number_of_nodes() == sum(len(d.cells) for d in sg.strata)
    lower, upper = sg.strata
    for c in upper.cells:
        nbrs = [n for n in sg.graph.neighbors((1, c.id)) if n[0] == 0]
        assert nbrs, c
        for _, k in nbrs:  # linked regions overlap
            ra, rb = lower.regions[lower.cells[k].region], upper.regions[c.region]
            assert ra.polygon.intersection(rb.polygon).area > 0
    kinds = {d["kind"] for *_, d in sg.graph.edges(data=True)}
    assert kinds == {"cell", "length"}


def test_verdict_on_the_papers_worlds():
    assert surveillance_verdict(corridor(), 2.0, 4.0).pursuer_can_hold
    assert surveillance_verdict(open_room(), 2.0, 4.0).pursuer_can_hold
    v = surveillance_verdict(two_rooms(), 2.0, 4.0, start=(5.0, 0.0))
    assert v.evader_wins and v.witness_region is not None
    assert all(v.decomposition.cells[c].escapable for c in v.witness_region.cells)
    path = v.evader_path
    assert np.allclose(path[0], (5.0, 0.0)) and np.allclose(path[-1], v.witness_point)
    assert rods_semifree(v.decomposition.map, path[:-1], path[1:]).all()
    assert v.witness_region.polygon.covers(shapely.Point(v.witness_point))


def test_verdict_is_monotone_in_l_min():
    """Prop. 3 + 4: an escape at l_min remains one for every larger l_min."""
    world = two_pillars(1.0)
    wins = [surveillance_verdict(world, lm, 6.0).evader_wins for lm in (0.6, 1.2, 2.0, 3.5)]
    assert wins == sorted(wins)


def test_first_sample_length_avoids_a_critical_l_min():
    world = two_pillars(2.0)
    v = surveillance_verdict(world, 2.0, 3.0)  # 2.0 is a candidate: sample just above
    assert 2.0 < v.L < 2.01
    assert surveillance_verdict(world, 2.2, 3.0).L == 2.2


@pytest.mark.parametrize(("lo", "hi"), [(2.0, 1.0), (0.0, 1.0), (1.0, math.inf)])
def test_bad_ranges_are_rejected(lo, hi):
    with pytest.raises(InvalidConfigError):
        surveillance_verdict(corridor(), lo, hi)


def test_bad_start_is_rejected():
    with pytest.raises(InvalidConfigError, match="start"):
        surveillance_verdict(two_rooms(), 2.0, 4.0, start=(-3.0, 3.0))  # inside a wall


def _candidates_every_pair(world: Map, lo: float, hi: float) -> tuple[float, ...]:
    """Prop. 1's candidates from every pair at once (candidate_lengths before its blocks)."""
    from strategies.cspace.tolerances import diameter

    v = world.vertices
    dvv = np.hypot(*(v[:, None, :] - v[None, :, :]).transpose(2, 0, 1))
    dvv = dvv[np.triu_indices(len(v), k=1)]
    rel = v[:, None, :] - world.edge_start[None, :, :]
    t = np.clip(np.einsum("vej,ej->ve", rel, world.edge_dir), 0.0, world.edge_length)
    foot = world.edge_start[None] + t[..., None] * world.edge_dir[None]
    dve = np.hypot(*(v[:, None, :] - foot).transpose(2, 0, 1)).ravel()
    d = np.concatenate([dvv, dve])
    tol = 1e-9 * diameter(world)
    d = d[d > tol]
    cand = np.unique(np.concatenate([d, 0.5 * d]))
    cand = cand[(cand > lo + tol) & (cand < hi - tol)]
    keep = np.concatenate([[True], np.diff(cand) > tol]) if len(cand) else cand.astype(bool)
    return tuple(float(x) for x in cand[keep])


@pytest.mark.parametrize("block", [1 << 20, 7])
def test_candidates_by_blocks_equal_every_pair_at_once(block, monkeypatch):
    """candidate_lengths measures a block of vertices at a time and keeps runs of close
    values: the same candidates, bit for bit, as every pair at once, on random maps (and
    regular polygons, whose many equal distances make long runs to merge)."""
    from envs.maps.random_maps import random_map
    from strategies.cspace import stratified

    monkeypatch.setattr(stratified, "_CANDIDATE_PAIRS", block)
    worlds = [random_map(seed, kind=kind) for seed in range(4)
              for kind in ("polygons", "star", "rectangles")]  # fmt: skip
    for n in (12, 97, 400):
        a = 2 * np.pi * np.arange(n) / n
        worlds.append(Map(np.stack([5 + 5 * np.cos(a), 5 + 5 * np.sin(a)], axis=1)))
    for world in worlds:
        for lo, hi in ((2.0, 4.0), (0.02 * world.scale, 0.6 * world.scale)):
            assert candidate_lengths(world, lo, hi) == _candidates_every_pair(world, lo, hi)


def test_candidates_of_a_big_room_take_no_square_of_its_vertices_in_memory():
    """A round room of 4,000 vertices: every pair at once peaked at 1.9 GB (20,000: about
    47 GB, before stratified_graph could refuse anything); by blocks, 0.15 GB."""
    import tracemalloc

    a = 2 * np.pi * np.arange(4000) / 4000
    room = Map(np.stack([5 + 5 * np.cos(a), 5 + 5 * np.sin(a)], axis=1))
    tracemalloc.start()
    try:
        assert len(candidate_lengths(room, 2.0, 4.0)) == 924
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 400e6, peak
