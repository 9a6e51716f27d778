"""Line of sight and blocking features against shapely, plus exact degenerate cases."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from envs.errors import InvalidConfigError
from envs.geometry import kernel_for
from envs.maps import Feature
from tests.envs.geometry._maps import (
    aligned_blocks_map,
    all_maps,
    nonconvex_map,
    sample_free_points,
    sample_wall_points,
    square_obstacle_map,
)
from tests.envs.geometry._oracles import los_oracle

MAPS = all_maps()


def _segment_point(world, data, label):
    x0, y0, x1, y1 = world.bounds
    x = data.draw(st.floats(x0, x1), label=f"{label}x")
    y = data.draw(st.floats(y0, y1), label=f"{label}y")
    p = np.array([x, y])
    assume(bool(world.contains(p[None])[0]))
    return p


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.filter_too_much])
@given(mi=st.integers(0, len(MAPS) - 1), data=st.data())
def test_line_of_sight_matches_shapely(mi, data):
    world = MAPS[mi]
    k = kernel_for(world)
    p = _segment_point(world, data, "p")
    q = _segment_point(world, data, "q")
    expected = los_oracle(world, p, q)
    assume(expected is not None)
    assert k.line_of_sight(p, q) == expected
    assert k.line_of_sight(q, p) == expected
    assert (k.blocking_feature(p, q) is None) == expected


@pytest.mark.parametrize("world", MAPS, ids=lambda m: m.name)
def test_line_of_sight_random_and_wall_points_match_shapely(world):
    rng = np.random.default_rng(7)
    k = kernel_for(world)
    free = sample_free_points(world, rng, 150)
    wall = sample_wall_points(world, rng, 150)
    pts = np.concatenate([free, wall])
    P = pts[rng.integers(0, len(pts), 600)]
    Q = pts[rng.integers(0, len(pts), 600)]
    many = k.line_of_sight_many(P, Q)
    checked = 0
    for p, q, got in zip(P, Q, many, strict=True):
        expected = los_oracle(world, p, q)
        assert got == k.line_of_sight(p, q)
        if expected is None:
            continue
        checked += 1
        assert got == expected, (p.tolist(), q.tolist())
    assert checked > 400


def test_through_a_vertex_and_grazing_are_blocked():
    world = square_obstacle_map()
    k = kernel_for(world)
    # exactly through the convex vertex (0, 0)
    assert not k.line_of_sight((-1, 1), (1, -1))
    assert k.blocking_feature((-1, 1), (1, -1)) == Feature("vertex", _vertex(world, (0, 0)))
    # just past it, both ways
    assert k.line_of_sight((-1, 1), (1, -0.999))
    assert not k.line_of_sight((-1, 1), (1, -1.001))
    # grazing along the top edge y = 0 and along its extension through the vertex
    assert not k.line_of_sight((-3, 0), (1, 0))
    assert not k.line_of_sight((-1.5, 0), (-0.5, 0))  # both ends on the edge
    assert k.line_of_sight((0.5, 0), (2, 0))  # on the edge's line, beyond the vertex
    # ends resting on walls, leaving into free space, are clear
    assert k.line_of_sight((-1, 0), (-1, 3))
    assert k.line_of_sight((0, 0), (2, 2))


def _vertex(world, xy):
    return int(np.flatnonzero(np.all(np.isclose(world.vertices, xy), axis=1))[0])


def test_segment_through_obstacle_between_wall_points_is_blocked():
    world = square_obstacle_map()
    k = kernel_for(world)
    # top edge to right edge through the obstacle's interior: touches walls only at the ends
    assert not k.line_of_sight((-1, 0), (0, -1))
    assert k.blocking_feature((-1, 0), (0, -1)) is not None
    # bottom-left corner to top-right corner: the diagonal through the obstacle
    assert not k.line_of_sight((-2, -2), (0, 0))
    # outer wall to outer wall along free space
    assert k.line_of_sight((-5, 3), (5, 3))
    assert not k.line_of_sight((-5, -5), (5, -5))  # along the outer wall


def test_collinear_edges_of_two_obstacles():
    world = aligned_blocks_map()
    k = kernel_for(world)
    assert not k.line_of_sight((0.5, 1), (4.5, 1))  # grazes both bottom edges
    assert k.line_of_sight((2.2, 1), (2.8, 1))  # in the gap, on the common line
    assert not k.line_of_sight((2.2, 1), (3.5, 1))  # reaches the second block's edge
    assert k.blocking_feature((2.2, 1), (3.5, 1)) == Feature("vertex", _vertex(world, (3, 1)))
    assert not k.line_of_sight((0.5, 0.5), (4.5, 2.5))


def test_blocking_feature_is_the_nearest_to_p():
    world = nonconvex_map()
    k = kernel_for(world)
    p, q = np.array([0.5, 1.5]), np.array([9.5, 1.5])
    f_pq = k.blocking_feature(p, q)
    f_qp = k.blocking_feature(q, p)
    assert f_pq == Feature("edge", _edge_crossed_first(world, p, q))
    assert f_qp == Feature("edge", _edge_crossed_first(world, q, p))
    assert f_pq != f_qp


def _edge_crossed_first(world, p, q):
    from shapely.geometry import LineString, Point

    best, best_d = None, np.inf
    for e in range(world.n_edges):
        inter = LineString([p, q]).intersection(
            LineString([world.edge_start[e], world.edge_end[e]])
        )
        if not inter.is_empty:
            d = Point(p).distance(inter)
            if d < best_d:
                best, best_d = e, d
    return best


def test_line_of_sight_rejects_bad_input():
    k = kernel_for(square_obstacle_map())
    with pytest.raises(InvalidConfigError, match="line_of_sight p"):
        k.line_of_sight((np.nan, 0), (1, 1))
    with pytest.raises(InvalidConfigError, match="same shape"):
        k.line_of_sight_many(np.zeros((3, 2)), np.zeros((2, 2)))
    assert k.line_of_sight((1, 1), (1, 1))


@pytest.mark.parametrize(
    ("p", "q"),
    [
        ((6.0, 1.0), (6.0 - 1e-15, 1.0 + 1.2e-7)),  # short, tilted by far less than eps
        ((6.0, 1.0), (6.0 - 3e-9, 1.5)),  # within eps of the wall all along
        ((6.0, 0.0), (5.999999999999999, 1.1990778148174307e-07)),  # from the corner
        ((6.0, 1.0), (6.0, 1.5)),  # exactly on the wall
    ],
)
def test_a_segment_lying_along_a_wall_within_eps_is_blocked(p, q):
    """Found by hypothesis: a short segment on a long wall, its tilt below eps, was
    visible, because the wall's far end left the segment's line by more than eps."""
    world = aligned_blocks_map()
    k = kernel_for(world)
    assert world.rings[0][1].tolist() == [6.0, 0.0]  # the right wall is x = 6
    assert not k.line_of_sight(p, q) and not k.line_of_sight(q, p)
    assert not k.line_of_sight_many(np.array([p]), np.array([q]))[0]
    assert k.blocking_feature(p, q) is not None
