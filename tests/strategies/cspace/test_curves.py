"""Critical curves of types 0-5 (THEORY.md 1.2): geometry, semi-free clip, tolerances."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely

from envs.errors import InvalidConfigError
from envs.maps import random_map
from strategies.cspace import critical_curves
from strategies.cspace._rod import rods_semifree
from tests.strategies.cspace._oracle import corridor, pillar_room, two_rooms

WORLDS = {
    "corridor": corridor,
    "two_rooms": two_rooms,
    "pillars": pillar_room,
    "random3": lambda: random_map(3, n_vertices=10),
}


def _rod(P, theta, L):
    return P + L * np.stack([np.cos(theta), np.sin(theta)], axis=-1)


@pytest.mark.parametrize("name", ["pillars", "random3"])
def test_rods_semifree_agrees_with_shapely_on_random_rods(name):
    world = WORLDS[name]()
    rng = np.random.default_rng(7)
    xmin, ymin, xmax, ymax = world.bounds
    P = rng.uniform([xmin, ymin], [xmax, ymax], size=(3000, 2))
    P = P[world.contains(P)]
    theta = rng.uniform(-math.pi, math.pi, len(P))
    L = rng.uniform(0.3, 4.0, len(P))
    Q = P + L[:, None] * np.stack([np.cos(theta), np.sin(theta)], axis=1)
    want = shapely.covers(world.prepared_free_region, shapely.linestrings(np.stack([P, Q], 1)))
    got = rods_semifree(world, P, Q)
    assert len(P) > 1500
    assert np.array_equal(got, want)


@pytest.mark.parametrize("name", list(WORLDS))
@pytest.mark.parametrize("L", [1.3, 2.0, 3.1])
def test_curve_points_are_semifree_contacts_with_their_features(name, L):
    world = WORLDS[name]()
    curves = critical_curves(world, L)
    rng = np.random.default_rng(1)
    seen = set()
    for c in curves:
        t = rng.uniform(c.t0, c.t1, 6)
        P, theta = c.evaluate(t)
        assert np.all(world.contains(P)), c.name
        if c.type == 0:
            continue
        seen.add(c.type)
        Q = _rod(P, theta, L)
        rods = shapely.linestrings(np.stack([P, Q], axis=1))
        # closed free region covers the contact rod (an independent clip check)
        assert np.all(shapely.covers(world.free_region.buffer(1e-9), rods)), c.name
        f = c.features
        if c.type == 1:
            e = f[0].index
            a, n = world.edge_start[e], world.edge_normal[e]
            assert np.allclose((P - a) @ n, L)
            assert np.allclose(theta % (2 * math.pi), math.atan2(-n[1], -n[0]) % (2 * math.pi))
        elif c.type == 2:
            v = world.vertices[f[0].index]
            assert np.allclose(np.hypot(*(P - v).T), L)
            assert np.allclose(Q, v)
        elif c.type in (3, 4):
            v = world.vertices[f[0].index]
            d = np.hypot(*(P - v).T)
            cross = (Q - P)[:, 0] * (v - P)[:, 1] - (Q - P)[:, 1] * (v - P)[:, 0]
            assert np.allclose(cross / L, 0.0, atol=1e-9)
            assert np.all(d <= L + 1e-9)
            if c.type == 3:
                w = world.vertices[f[1].index]
                cross2 = (Q - P)[:, 0] * (w - P)[:, 1] - (Q - P)[:, 1] * (w - P)[:, 0]
                assert np.allclose(cross2 / L, 0.0, atol=1e-9)
                assert np.all(np.hypot(*(P - w).T) > d)
        elif c.type == 5:
            v = world.vertices[f[0].index]
            e = f[1].index
            a, u, n = world.edge_start[e], world.edge_dir[e], world.edge_normal[e]
            h = float((v - a) @ n)
            X = (P - v) @ u
            Y = (P - v) @ n  # local frame of THEORY.md 1.2: Y along the normal
            assert np.all(Y > 0)
            assert np.allclose((X**2 + Y**2) * (Y + h) ** 2, L**2 * Y**2, rtol=1e-9, atol=1e-9)
            assert np.allclose((Q - a) @ n, 0.0, atol=1e-9)
    assert {1, 2, 4} <= seen


@pytest.mark.parametrize("name", ["corridor", "pillars", "random3"])
def test_contacts_of_types_3_4_5_block_a_rotation(name):
    """Rotating the contact rod a little one way (or both) makes it hit the features."""
    world = WORLDS[name]()
    L = 3.1
    delta = 1e-3
    free = world.free_region
    for c in critical_curves(world, L):
        if c.type not in (3, 4, 5):
            continue
        t = np.linspace(c.t0, c.t1, 7)[1:-1]
        P, theta = c.evaluate(t)
        for dth in (delta, -delta):
            Q = _rod(P, theta + dth, L)
            ok = shapely.covers(free, shapely.linestrings(np.stack([P, Q], 1)))
            if dth > 0:
                plus = ok
            else:
                minus = ok
        assert not np.any(plus & minus), c.name


@pytest.mark.parametrize("name", ["corridor", "pillars", "random3"])
def test_polylines_stay_within_their_tolerance(name):
    world = WORLDS[name]()
    for c in critical_curves(world, 2.0, chord_tol=1e-3):
        if c.shape == "segment":
            assert c.tolerance == 0.0 and len(c.points) == 2
            continue
        assert c.tolerance == pytest.approx(1e-3)
        t = np.linspace(c.t0, c.t1, 4001)
        exact, _ = c.evaluate(t)
        line = shapely.LineString(c.points)
        dist = shapely.distance(shapely.points(exact), line)
        assert dist.max() <= 1.01e-3, c.name
        # and the polyline's inner vertices lie on the exact curve (a conchoid's end
        # may be its vertex, where the projection through the vertex is undefined)
        inner = c.points[1:-1]
        P, _ = c.evaluate(c.project(inner))
        assert np.allclose(P, inner, atol=1e-9)


def test_corridor_catalog_matches_the_paper():
    """Fig. 3: corridor narrower than L: types 1, 2, 3, 4, 5 all present and where expected."""
    world = corridor()
    curves = critical_curves(world, 2.0)
    by_type = {t: [c for c in curves if c.type == t] for t in range(6)}
    assert len(by_type[0]) == world.n_edges
    # the dead end's type-1 line x = -4 crosses the corridor
    dead = [c for c in by_type[1] if np.allclose(c.points[:, 0], -4.0)]
    assert len(dead) == 1 and np.allclose(sorted(dead[0].points[:, 1]), [-0.5, 0.5])
    # type-1 lines of the corridor walls lie outside the corridor: clipped away
    walls = {
        e
        for e in range(world.n_edges)
        if abs(abs(world.edge_start[e, 1]) - 0.5) < 1e-12
        and abs(world.edge_end[e, 1] - world.edge_start[e, 1]) < 1e-12
    }
    assert len(walls) == 2
    assert not any(c.features[0].index in walls for c in by_type[1])
    # type-4 extensions of the corridor walls into the room, of length L
    ext = [c for c in by_type[4] if c.features[1].index in walls]
    assert len(ext) == 2 and all(c.length == pytest.approx(2.0) for c in ext)
    assert by_type[3] and by_type[5]


def test_type3_appears_at_the_vertex_distance():
    """Prop. 1 (a): a type-3 curve between two convex vertices at distance d exists iff L > d."""
    from envs.maps import Map

    world = Map(
        [(0, 0), (12, 0), (12, 8), (0, 8)],
        [[(3, 3), (5, 3), (5, 5), (3, 5)], [(7, 3), (9, 3), (9, 5), (7, 5)]],
    )
    d = 2.0  # (5, 3)-(7, 3) and (5, 5)-(7, 5)
    for L, want in ((d - 0.05, False), (d + 0.05, True)):
        got = any(c.type == 3 for c in critical_curves(world, L))
        assert got is want, L


@pytest.mark.parametrize("bad", [0.0, -1.0, math.nan, math.inf, "two", None])
def test_bad_length_is_rejected(bad):
    with pytest.raises(InvalidConfigError, match="L"):
        critical_curves(corridor(), bad)


def test_non_map_is_rejected():
    with pytest.raises(InvalidConfigError, match="Map"):
        critical_curves([(0, 0), (1, 0), (0, 1)], 1.0)
