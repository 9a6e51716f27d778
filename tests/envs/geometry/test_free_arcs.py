"""Free orientation arcs against brute-force sampling, stop labels, degenerate points."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from shapely.geometry import LineString, Point

from envs.errors import InvalidConfigError
from envs.geometry import Arc, FreeArcs, kernel_for
from tests.envs.geometry._maps import (
    all_maps,
    nonconvex_map,
    sample_free_points,
    sample_wall_points,
    square_obstacle_map,
)
from tests.envs.geometry._oracles import rod_blocked_samples

MAPS = all_maps()
THETAS = np.linspace(-math.pi, math.pi, 3600, endpoint=False)


def _stop_angles(fa: FreeArcs) -> np.ndarray:
    return np.array([x for a in fa.arcs if not a.is_full for x in (a.lo, a.hi)])


def _angular_gap(thetas: np.ndarray, angles: np.ndarray) -> np.ndarray:
    if len(angles) == 0:
        return np.full(len(thetas), np.inf)
    d = np.abs((thetas[:, None] - angles[None, :] + math.pi) % (2 * math.pi) - math.pi)
    return d.min(axis=1)


def _in_arcs(fa: FreeArcs, thetas: np.ndarray) -> np.ndarray:
    return np.array([fa.contains(t) for t in thetas])


def _check_stop_geometry(world, fa: FreeArcs, tol: float = 1e-7) -> None:
    """Every stop label names the feature the rod touches at that stop angle."""
    P = fa.point
    for arc in fa.arcs:
        for theta, stop in ((arc.lo, arc.stop_lo), (arc.hi, arc.stop_hi)):
            if stop is None:
                continue
            Q = P + fa.L * np.array([math.cos(theta), math.sin(theta)])
            f = stop.feature
            if f.kind == "edge":
                edge = LineString([world.edge_start[f.index], world.edge_end[f.index]])
                if stop.kind == "tip":
                    assert edge.distance(Point(Q)) <= tol, (stop, theta)
                else:  # the rod lies along the edge through P (P on a wall)
                    assert edge.distance(Point(P)) <= tol
                    assert edge.distance(Point(P + 1e-3 * (Q - P))) <= 1e-3 * tol + tol
            else:
                v = world.vertices[f.index]
                if stop.kind == "tip":
                    assert np.linalg.norm(Q - v) <= tol, (stop, theta)
                else:
                    assert world.vertex_convex[f.index]
                    assert LineString([P, Q]).distance(Point(v)) <= tol, (stop, theta)
                    assert np.linalg.norm(v - P) < fa.L


@pytest.mark.parametrize("world", MAPS, ids=lambda m: m.name)
@pytest.mark.parametrize("L", [0.7, 2.0, 4.5])
def test_free_arcs_match_brute_force(world, L):
    rng = np.random.default_rng(int(L * 10))
    k = kernel_for(world)
    band = 1e-6
    for P in sample_free_points(world, rng, 12, margin=1e-2):
        fa = k.free_arcs(P, L)
        blocked = rod_blocked_samples(world, P, L, THETAS)
        clear = _angular_gap(THETAS, _stop_angles(fa)) > band
        free = _in_arcs(fa, THETAS)
        assert np.array_equal(free[clear], ~blocked[clear]), (P.tolist(), fa)
        # stops are exact: just inside an arc is free, just outside is blocked
        for arc in fa.arcs:
            if arc.is_full:
                continue
            inner = np.array([arc.lo + 1e-7, arc.hi - 1e-7])
            outer = np.array([arc.lo - 1e-7, arc.hi + 1e-7])
            assert not rod_blocked_samples(world, P, L, inner).any(), (P.tolist(), arc)
            assert rod_blocked_samples(world, P, L, outer).all(), (P.tolist(), arc)
        _check_stop_geometry(world, fa)
        _check_arcs_well_formed(fa)


def _check_arcs_well_formed(fa: FreeArcs) -> None:
    los = [a.lo for a in fa.arcs]
    assert los == sorted(los)
    for a in fa.arcs:
        assert -math.pi <= a.lo < math.pi
        assert a.hi >= a.lo
    for a, b in zip(fa.arcs, fa.arcs[1:], strict=False):
        assert a.hi < b.lo
    if len(fa.arcs) > 1:
        assert fa.arcs[-1].hi < fa.arcs[0].lo + 2 * math.pi


@pytest.mark.parametrize("world", MAPS, ids=lambda m: m.name)
def test_free_arcs_shrink_as_L_grows(world):
    """Prop. 3's monotonicity: the rod of length L is a prefix of the rod of length L' > L."""
    rng = np.random.default_rng(3)
    k = kernel_for(world)
    for P in sample_free_points(world, rng, 10, margin=1e-2):
        small = k.free_arcs(P, 1.0)
        big = k.free_arcs(P, 2.5)
        for arc in big.arcs:
            for theta in np.linspace(arc.lo, arc.hi, 7):
                assert small.contains(theta, 1e-9)
        assert big.total_width <= small.total_width + 1e-9


def test_free_arcs_on_walls_match_brute_force():
    """Type-0 points: P on an edge or at a vertex; free arcs point into free space."""
    band = 1e-4
    for world in MAPS:
        rng = np.random.default_rng(11)
        k = kernel_for(world)
        for P in sample_wall_points(world, rng, 25):
            fa = k.free_arcs(P, 1.3)
            expected = _wall_point_rod_free(world, P, 1.3, THETAS)
            clear = _angular_gap(THETAS, _stop_angles(fa)) > band
            free = _in_arcs(fa, THETAS)
            assert np.array_equal(free[clear], expected[clear]), (world.name, P.tolist())
            _check_stop_geometry(world, fa, tol=1e-6)
            assert len(fa.arcs) >= 1  # some direction always leaves a wall into free space
            assert fa.total_width <= math.pi + 1e-9 or not _on_edge_interior(world, P)


def _on_edge_interior(world, P):
    d = np.linalg.norm(world.vertices - P, axis=1)
    return bool(d.min() > 1e-6)


def _wall_point_rod_free(world, P, L, thetas):
    """For P on a wall: the rod minus P touches no wall and lies in free space."""
    u = np.stack([np.cos(thetas), np.sin(thetas)], axis=1)
    lines = shapely.linestrings(np.stack([P + 1e-7 * u, P + L * u], axis=1))
    boundary = world.free_region.boundary
    shapely.prepare(boundary)
    mid = P + 0.5 * L * u
    inside = shapely.contains_xy(world.prepared_free_region, mid[:, 0], mid[:, 1])
    return ~shapely.intersects(lines, boundary) & inside


def test_point_outside_free_space_and_far_from_walls():
    world = square_obstacle_map()
    k = kernel_for(world)
    assert k.free_arcs((-1, -1), 0.5).is_empty
    assert k.free_arcs((7, 0), 0.5).is_empty
    fa = k.free_arcs((2.5, 2.5), 1.0)
    assert fa.is_full and fa.contains(0.3) and fa.arc_index(-3.0) == 0
    assert fa.arcs == (Arc(-math.pi, math.pi, None, None),)


def test_free_arcs_many_equals_single():
    world = nonconvex_map()
    k = kernel_for(world)
    pts = sample_free_points(world, np.random.default_rng(5), 20)
    many = k.free_arcs_many(pts, 1.7)
    for p, fa in zip(pts, many, strict=True):
        assert fa.arcs == k.free_arcs(p, 1.7).arcs


def test_free_arcs_commute_with_similarity():
    """Rotating and scaling the world rotates the arcs and keeps the stops."""
    world = nonconvex_map()
    alpha, s = 0.7, 2.5
    R = s * np.array([[math.cos(alpha), -math.sin(alpha)], [math.sin(alpha), math.cos(alpha)]])
    moved = world.transformed(R, (3.0, -1.0))
    k0, k1 = kernel_for(world), kernel_for(moved)
    for P in sample_free_points(world, np.random.default_rng(9), 15, margin=1e-2):
        a0 = k0.free_arcs(P, 1.9)
        a1 = k1.free_arcs(R @ P + (3.0, -1.0), 1.9 * s)
        assert len(a0.arcs) == len(a1.arcs)
        w0 = sorted(a.width for a in a0.arcs)
        w1 = sorted(a.width for a in a1.arcs)
        assert np.allclose(w0, w1, atol=1e-9)
        for a in a0.arcs:
            assert a1.contains(a.mid + alpha, 1e-9)
        kinds0 = sorted((a.stop_lo.kind, a.stop_hi.kind) for a in a0.arcs if not a.is_full)
        kinds1 = sorted((a.stop_lo.kind, a.stop_hi.kind) for a in a1.arcs if not a.is_full)
        assert kinds0 == kinds1


def test_free_arcs_rejects_bad_input():
    k = kernel_for(square_obstacle_map())
    with pytest.raises(InvalidConfigError, match="free_arcs L"):
        k.free_arcs((1, 1), 0.0)
    with pytest.raises(InvalidConfigError, match="free_arcs point"):
        k.free_arcs((1, np.inf), 1.0)
    with pytest.raises(InvalidConfigError, match="free_arcs_many points"):
        k.free_arcs_many(np.zeros((3, 3)), 1.0)
