"""The robust tests against brute force (dense sampling) and shapely."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely

from strategies.referee.robust import (
    convex_corners,
    fan_hits_vertex,
    segment_crosses_walls,
    square_range,
    sweep_hits_vertex,
    sweep_range_ok,
)
from tests.strategies.referee.conftest import dead_end


def _corner(angle: float):
    """A convex vertex at the origin whose obstacle occupies the wedge from direction 0
    counter-clockwise to ``angle`` (< pi), free space on the left of both edges: the
    wall arrives along direction pi (from +x) and leaves along ``angle``."""
    din = np.array([-1.0, 0.0])
    dout = np.array([math.cos(angle), math.sin(angle)])
    return np.zeros(2), din, dout


def _in_interior_cone(u, angle):
    a = math.atan2(u[1], u[0]) % (2 * math.pi)
    return 0.0 < a < angle


def _brute_graze(A, B, v, c, R, angle, n=600):
    """Some pursuer end on A-B sends a rod through v, beyond which the ray meets the disc,
    with the rod's line outside the obstacle's interior cone."""
    for s in np.linspace(0.0, 1.0, n):
        P = A + s * (B - A)
        w = v - P
        norm = math.hypot(*w)
        if norm < 1e-12:
            continue
        u = w / norm
        if _in_interior_cone(u, angle) or _in_interior_cone(-u, angle):
            continue
        t = max(0.0, float((c - v) @ u))
        if math.hypot(*(v + t * u - c)) <= R:
            return True
    return False


@pytest.mark.parametrize("angle", [0.5 * math.pi, 0.3, 2.6])
def test_sweep_hits_vertex_matches_brute_force(angle):
    v, din, dout = _corner(angle)
    rng = np.random.default_rng(7)
    disagree = 0
    for _ in range(600):
        A = rng.uniform(-2, 2, 2)
        B = A + rng.uniform(-1, 1, 2) * rng.integers(0, 2)  # some degenerate segments
        c = rng.uniform(-1.5, 1.5, 2)
        R = rng.uniform(0.0, 0.6)
        got = bool(sweep_hits_vertex(*A, *B, *v, *c, R, din, dout))
        disagree += got != _brute_graze(A, B, v, c, R, angle)
    # the brute force samples the segment: it may miss a sliver, never invent a hit
    assert disagree <= 3


def test_sweep_hits_vertex_is_sound_against_pursuer_in_the_safe_wedge():
    # square obstacle to the upper right of v: a pursuer down-left (the wedge opposite
    # the obstacle) never grazes v, however close the evader's disc is
    v, din, dout = _corner(0.5 * math.pi)
    assert not sweep_hits_vertex(-1.0, -1.2, -1.3, -0.9, *v, 0.1, 0.1, 0.3, din, dout)
    # beside the obstacle (below its bottom edge's extension) it may
    assert sweep_hits_vertex(1.5, -1.0, 1.5, -1.0, *v, -0.1, 0.1, 0.3, din, dout)


def test_fan_hits_vertex_is_the_degenerate_sweep():
    v, din, dout = _corner(1.2)
    rng = np.random.default_rng(3)
    for _ in range(200):
        e, c = rng.uniform(-2, 2, 2), rng.uniform(-2, 2, 2)
        R = rng.uniform(0, 0.5)
        assert bool(fan_hits_vertex(*e, *v, *c, R, din, dout)) == bool(
            sweep_hits_vertex(*e, *e, *v, *c, R, din, dout)
        )


def test_sweep_range_ok_matches_dense_sampling():
    rng = np.random.default_rng(11)
    for _ in range(300):
        o = rng.uniform(-2.5, 2.5, 2)
        d = rng.uniform(-0.7, 0.7, 2) * rng.integers(0, 2)
        R0, g = rng.uniform(0, 0.2), rng.uniform(0, 0.4)
        got = bool(sweep_range_ok(o[0], o[1], d[0], d[1], R0, g, 1.0, 2.0))
        t = np.linspace(0, 1, 4001)
        dist = np.hypot(o[0] - t * d[0], o[1] - t * d[1])
        R = R0 + g * t
        lo, hi = (dist - R).min(), (dist + R).max()
        if min(abs(lo - 1.0), abs(hi - 2.0)) < 1e-4:
            continue  # too close to call by sampling
        assert got == (lo >= 1.0 and hi <= 2.0)


def test_square_range_matches_sampling():
    rng = np.random.default_rng(5)
    for _ in range(100):
        o = rng.uniform(-3, 3, 2)
        near, far = square_range(o[0], o[1], 0.25)
        g = np.linspace(-0.25, 0.25, 101)
        X, Y = np.meshgrid(o[0] + g, o[1] + g)
        dist = np.hypot(X, Y)
        # the nearest point may fall between samples (<= half a sample step away)
        assert dist.min() - 0.0025 <= near <= dist.min() + 1e-12
        assert far == pytest.approx(dist.max(), abs=1e-9)  # a corner: sampled exactly


def test_segment_crosses_walls_matches_shapely():
    world = dead_end()
    rng = np.random.default_rng(2)
    P = rng.uniform((-2.5, -2.5), (5, 2.5), size=(400, 2))
    Q = rng.uniform((-2.5, -2.5), (5, 2.5), size=(400, 2))
    got = segment_crosses_walls(P, Q, world.edge_start, world.edge_end)
    walls = shapely.LineString(np.vstack([world.rings[0], world.rings[0][:1]]))
    for i in range(len(P)):
        seg = shapely.LineString([P[i], Q[i]])
        inter = seg.intersection(walls)
        # a proper crossing is a transversal intersection at a point inside both
        points = shapely.get_coordinates(inter)
        proper = any(
            min(np.hypot(*(p - P[i])), np.hypot(*(p - Q[i]))) > 1e-9
            and np.min(np.hypot(*(world.vertices - p).T)) > 1e-9
            for p in points
        )
        assert got[i] == proper, (P[i], Q[i])


def test_convex_corners_of_the_dead_end():
    v, din, dout = convex_corners(dead_end())
    assert sorted(map(tuple, v.round(6))) == [(0.0, -0.25), (0.0, 0.25)]
    # the edges meet at a right angle, free space on their left
    assert np.allclose(np.abs(np.einsum("ij,ij->i", din, dout)), 0.0)


def _segment_distance(P, a, b):
    ab = b - a
    t = np.clip(((P - a) @ ab) / (ab @ ab), 0.0, 1.0)
    return np.hypot(*(P - (a + t[:, None] * ab)).T)


def test_sweep_hits_vertex_with_clearance_is_sound_against_brute_force():
    """Random corners (obstacle angles 20 - 175 degrees, short and long edges), pursuer
    segments, discs and clearances: wherever dense sampling finds a pursuer end in a
    grazing wedge whose ray beyond v meets the disc at a point ``clear`` from both wall
    edges, the test with the clearance says hit; and it never says hit where the plain
    test does not (it only narrows)."""
    rng = np.random.default_rng(7)
    grazes = narrowed = 0
    lam = np.linspace(0.0, 1.5, 751)
    for _ in range(400):
        alpha = math.radians(rng.uniform(20.0, 175.0))
        rot = rng.uniform(0.0, 2.0 * math.pi)
        dout = np.array([math.cos(rot), math.sin(rot)])
        din = -np.array([math.cos(rot - alpha), math.sin(rot - alpha)])
        lin, lout = rng.uniform(0.05, 2.0, 2)
        v = rng.uniform(-1.0, 1.0, 2)
        a = v + rng.uniform(-2.0, 2.0, 2)
        b = a + rng.uniform(-0.6, 0.6, 2)
        c = v + rng.uniform(-0.5, 0.5, 2)
        R = rng.uniform(0.01, 0.4)
        clear = rng.uniform(0.0, 0.15)
        args = (a[0], a[1], b[0], b[1], v[0], v[1], c[0], c[1], R, din, dout, 0.0)
        got = bool(sweep_hits_vertex(*args, clear=clear, lengths=(lin, lout)))
        plain = bool(sweep_hits_vertex(*args))
        assert plain or not got
        narrowed += plain and not got
        found = False
        for s in np.linspace(0.0, 1.0, 201):
            u = v - (a + s * (b - a))
            c1 = dout[0] * u[1] - dout[1] * u[0]
            c2 = -din[0] * u[1] + din[1] * u[0]
            if not ((c1 > 1e-9 and c2 > 1e-9) or (c1 < -1e-9 and c2 < -1e-9)):
                continue
            E = v + lam[:, None] * (u / np.hypot(*u))
            ok = np.hypot(*(E - c).T) <= R
            ok &= _segment_distance(E, v - lin * din, v) >= clear + 1e-9
            ok &= _segment_distance(E, v, v + lout * dout) >= clear + 1e-9
            if ok.any():
                found = True
                break
        grazes += found
        assert got or not found, (alpha, rot, v, a, b, c, R, clear, lin, lout)
    assert grazes > 40 and narrowed > 5  # the sample exercises both sides
