"""Tests of the :class:`Map` world model against shapely as the independent oracle."""

from __future__ import annotations

import math
import pickle
import warnings

import numpy as np
import pytest
import shapely
from shapely.geometry import Point, Polygon

from envs.errors import InvalidConfigError, InvalidMapError
from envs.maps import Map
from envs.tolerances import REL_GAP_TOL

from ._helpers import box, regular, walls_equal

ROOM = [(0.0, 0.0), (10.0, 0.0), (10.0, 10.0), (0.0, 10.0)]


# A set of valid worlds reused by the property tests below.
WORLDS = {
    "room_square": Map(ROOM, [box(4, 4, 6, 6)]),
    "pillars": Map(
        box(0, 0, 20, 12),
        [
            box(2, 2, 4, 4),
            [(8, 2), (11, 2), (9.5, 5)],
            regular(15, 6, 2, 6),
            regular(6, 9, 1.5, 5, 0.3),
        ],
    ),
    "corridor": Map(
        [(0, -5), (10, -5), (10, 5), (0, 5), (0, 0.5), (-6, 0.5), (-6, -0.5), (0, -0.5)]
    ),
    "star_hole": Map(
        box(-5, -5, 5, 5),
        [[(0, 3), (0.8, 0.8), (3, 0), (0.8, -0.8), (0, -3), (-0.8, -0.8), (-3, 0), (-0.8, 0.8)]],
    ),
    "merged": Map(ROOM, [box(2, 2, 5, 4), box(4, 3, 6, 7), box(0, 8, 3, 9)], merge=True),
}


# ---------------------------------------------------------------------- validation
@pytest.mark.parametrize(
    ("boundary", "obstacles", "pattern"),
    [
        pytest.param(
            [(0, 0), (10, 10), (10, 0), (0, 10)],
            [],
            r"boundary: .*not simple",
            id="bowtie-boundary",
        ),
        pytest.param(
            ROOM,
            [[(1, 1), (3, 3), (3, 1), (1, 3)]],
            r"obstacle 0: .*not simple",
            id="bowtie-obstacle",
        ),
        pytest.param(ROOM, [[(1, 1), (2, 1), (3, 1)]], r"obstacle 0: degenerate", id="collinear"),
        pytest.param(
            ROOM, [[(1, 1), (2, 2), (3, 3), (4, 4)]], r"obstacle 0: degenerate", id="collinear-4"
        ),
        pytest.param(ROOM, [[(1, 1), (2, 1)]], r"obstacle 0: .*at least 3", id="two-vertices"),
        pytest.param(
            ROOM,
            [[(1, 1), (1, 1), (1, 1)]],
            r"obstacle 0: .*(at least 3|degenerate)",
            id="one-point",
        ),
        pytest.param(
            ROOM,
            [[(1, 1), (2, float("nan")), (3, 3)]],
            r"obstacle 0 = .*: expected finite values, got nan",
            id="nan",
        ),
        pytest.param(
            ROOM,
            [[(1, 1), (2, float("inf")), (3, 3)]],
            r"obstacle 0 = .*: expected finite values, got inf",
            id="inf",
        ),
        pytest.param(
            [(0, 0), (1, 0), (2, 0)], [], r"boundary: degenerate", id="collinear-boundary"
        ),
        pytest.param(
            [(0, 0), (1, 1), (float("nan"), 0)],
            [],
            r"boundary = .*: expected finite values, got nan",
            id="nan-boundary",
        ),
        pytest.param(ROOM, [[1, 2, 3]], r"obstacle 0: .*\(n, 2\)", id="bad-shape"),
        pytest.param(
            ROOM,
            [box(11, 11, 12, 12)],
            r"obstacle 0: not inside the boundary \(lies outside",
            id="outside",
        ),
        pytest.param(
            ROOM,
            [box(9, 1, 11, 2)],
            r"obstacle 0: not inside the boundary \(crosses",
            id="crossing",
        ),
        pytest.param(
            ROOM,
            [box(1, 1, 2, 2), box(-1, 4, 1, 5)],
            r"obstacle 1: not inside",
            id="second-crossing",
        ),
        pytest.param(
            ROOM,
            [box(1, 1, 3, 3), box(2, 2, 4, 4)],
            r"obstacle 0 overlaps obstacle 1",
            id="overlap",
        ),
        pytest.param(
            ROOM, [box(1, 1, 5, 5), box(2, 2, 3, 3)], r"obstacle 0 overlaps obstacle 1", id="nested"
        ),
        pytest.param(
            ROOM,
            [box(1, 1, 3, 3), box(3, 1, 5, 3)],
            r"obstacle 0 touches obstacle 1",
            id="shared-edge",
        ),
        pytest.param(
            ROOM,
            [box(1, 1, 3, 3), box(3, 3, 5, 5)],
            r"obstacle 0 touches obstacle 1",
            id="shared-vertex",
        ),
        pytest.param(
            ROOM,
            [box(6, 6, 7, 7), box(1, 1, 3, 3), box(3 + 1e-8, 1, 5, 3)],
            r"obstacle 1 touches obstacle 2",
            id="tiny-gap",
        ),
        pytest.param(
            ROOM, [box(0, 1, 2, 2)], r"obstacle 0: touches the boundary", id="touch-boundary-edge"
        ),
        pytest.param(
            ROOM,
            [[(5, 0), (6, 1), (5, 2), (4, 1)]],
            r"obstacle 0: touches the boundary",
            id="touch-boundary-vertex",
        ),
        pytest.param(
            ROOM, [box(1e-8, 1, 2, 2)], r"obstacle 0: touches the boundary", id="near-boundary"
        ),
    ],
)
def test_invalid_maps_raise_naming_polygon_and_reason(boundary, obstacles, pattern):
    with pytest.raises(InvalidMapError, match=pattern):
        Map(boundary, obstacles)


def test_errors_are_value_errors():
    with pytest.raises(ValueError):
        Map(ROOM, [box(1, 1, 3, 3), box(2, 2, 4, 4)])


def test_a_map_too_far_from_the_origin_for_its_size_is_refused():
    """A float64 coordinate X rounds by eps |X|; beyond REL_LENGTH_TOL / eps (4.5e6) sizes
    from the origin that exceeds the length tolerance every geometry test uses (the corner
    at rot 0.3 decomposes exactly at offset 1e7, is inexact at 1e8 and the decomposition
    raised a bare ValueError at 1e9)."""
    from envs.maps.io import load_map

    square = np.array(box(0, 0, 10, 10), dtype=float)
    assert Map(square + 1e6).scale == pytest.approx(Map(square).scale)  # 7e4 sizes: fine
    with pytest.raises(InvalidMapError, match=r"lies 1e\+08 from the origin.*shift it"):
        Map(square + 1e8)
    assert load_map("corner~rot0.3off(1e7,1e7)").n_vertices == load_map("corner").n_vertices
    with pytest.raises(InvalidMapError, match="from the origin"):
        load_map("corner~rot0.3off(1e9,1e9)")


@pytest.mark.parametrize("size", [1e100, 1e160, 1e-100, 1e-200])
def test_a_map_of_a_size_float64_geometry_cannot_square_is_refused(size):
    """Found by probing the kernel under similarities (helper-123): the sweep squares
    squared lengths (its discriminants), which overflow or underflow float64 at sizes
    near 1e+-77. The room below scaled by 1e100 (or 1e-100) was accepted, and its sweep
    timed the rod passing the block's corners at the step's end (t = 1) instead of
    t = 1/2, without a word; at 1e160 the triangle was refused as "fewer than 3
    non-collinear vertices" and at 1e-200 as "zero extent", after numpy overflow
    warnings. Now one message names the size."""
    tri = size * np.array([(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)])
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no overflow warnings on the way
        with pytest.raises(InvalidMapError, match=r"size .* expected one in \[1e-30, 1e\+30\]"):
            Map(tri)


@pytest.mark.parametrize("far", [1e308, 1e8])
def test_an_obstacle_vertex_far_beyond_the_boundary_is_named(far):
    """helper-123's map-file probe: an obstacle with a vertex at -1e308 and one at 1e308
    was refused as "degenerate polygon (fewer than 3 non-collinear vertices)" (cleaning
    its ring overflowed, after numpy warnings); one at 1e308 and the rest inside got the
    right reason, after warnings too."""
    for ring in ([(-far, 1.0), (far, 1.0), (1.0, 2.0)], [(1.0, 1.0), (far, 1.0), (1.0, 2.0)]):
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            with pytest.raises(
                InvalidMapError, match=r"obstacle 0: not inside the boundary \(vertex \d \("
            ):
                Map(ROOM, [ring])


def test_sizes_within_the_range_keep_the_kernel_s_answers():
    from envs.geometry import kernel_for

    base = Map(ROOM, [box(1, 1, 3, 3)])
    # a level rod from x = 0.5 to 4 moves down past the block's top corners at t = 1/2
    step = ((0.5, 5.0), (4.0, 5.0), (0.5, 1.0), (4.0, 1.0))
    want = kernel_for(base).sweep(*step, 0.0, 10.0)
    for s in (1e-31, 5e28):  # sizes 1.4e-30 and 7e29
        m = base.transformed(s * np.eye(2))
        got = kernel_for(m).sweep(*(s * np.array(x) for x in step), 0.0, 10.0 * s)
        assert (got.cause, got.time) == pytest.approx((want.cause, want.time), abs=1e-9)


def test_gap_just_above_tolerance_is_accepted():
    scale = math.hypot(10, 10)
    gap = 10 * REL_GAP_TOL * scale
    m = Map(ROOM, [box(1, 1, 3, 3), box(3 + gap, 1, 5, 3)])
    assert len(m.rings) == 3


def test_closing_vertex_and_straight_vertices_are_dropped():
    m = Map([(0, 0), (5, 0), (10, 0), (10, 10), (0, 10), (0, 0)])
    assert m.n_vertices == 4


def test_merge_disconnecting_obstacles_raise():
    with pytest.raises(InvalidMapError, match="disconnected"):
        Map(ROOM, [box(4, 0, 6, 10)], merge=True)


def test_merge_covering_everything_raises():
    with pytest.raises(InvalidMapError, match="no free space"):
        Map(ROOM, [ROOM], merge=True)


# ---------------------------------------------------------------------- merge
MERGE_CASES = {
    "overlap": [box(1, 1, 3, 3), box(2, 2, 4, 4)],
    "nested": [box(1, 1, 5, 5), box(2, 2, 3, 3)],
    "shared-edge": [box(1, 1, 3, 3), box(3, 1, 5, 3)],
    "partial-edge": [box(1, 1, 3, 3), box(3, 2, 5, 6)],
    "shared-vertex": [box(1, 1, 3, 3), box(3, 3, 5, 5)],
    "tiny-gap": [box(1, 1, 3, 3), box(3 + 1e-8, 1, 5, 3)],
    "touch-boundary": [box(0, 1, 2, 2), box(7, 7, 8, 8)],
    "triangle-chain": [
        [(1, 1), (4, 1), (2.5, 3)],
        [(2.5, 3), (4, 5), (1, 5)],
        [(3, 1.5), (6, 1.5), (6, 2.5)],
    ],
}


@pytest.mark.parametrize("name", sorted(MERGE_CASES))
def test_merge_matches_shapely_union(name):
    obstacles = MERGE_CASES[name]
    m = Map(ROOM, obstacles, merge=True)
    ref = Polygon(ROOM).difference(shapely.union_all([Polygon(o) for o in obstacles]))
    # merging closes slits below the gap tolerance (the 1e-8 one of "tiny-gap") and snaps
    # the walls to a decimal grid about ten times that tolerance (see Map): compare on it
    grid = 10.0 ** np.floor(np.log10(REL_GAP_TOL * m.scale * 10))
    tol = grid
    assert m.free_region.symmetric_difference(ref).area < tol * ref.boundary.length
    # every wall vertex lies on the reference boundary and every reference vertex on a wall
    ref_vertices = np.concatenate(
        [np.asarray(ref.exterior.coords)] + [np.asarray(r.coords) for r in ref.interiors]
    )
    assert shapely.distance(shapely.points(m.vertices), ref.boundary).max() < tol
    assert m.distance_to_walls(ref_vertices).max() < tol
    # walls are exactly the reference rings (straight vertices dropped by both)
    ref_map = Map(
        np.asarray(ref.exterior.coords),
        [np.asarray(r.coords) for r in ref.interiors],
        merge=True,
    )
    assert walls_equal(m, ref_map, tol)


def test_merge_of_separate_obstacles_changes_nothing():
    obstacles = [box(1, 1, 3, 3), regular(7, 7, 1.5, 6)]
    assert walls_equal(Map(ROOM, obstacles), Map(ROOM, obstacles, merge=True), tol=1e-4)


# ---------------------------------------------------------------------- orientation
@pytest.mark.parametrize("name", sorted(WORLDS))
def test_orientation_outer_ccw_holes_cw(name):
    m = WORLDS[name]
    areas = [shapely.geometry.LinearRing(r).is_ccw for r in m.rings]
    assert areas[0] is True
    assert not any(areas[1:])


@pytest.mark.parametrize("name", sorted(WORLDS))
def test_normals_point_into_free_space(name):
    m = WORLDS[name]
    eps = 1e-4 * m.scale
    mid = 0.5 * (m.edge_start + m.edge_end)
    inside = shapely.points(mid + eps * m.edge_normal)
    outside = shapely.points(mid - eps * m.edge_normal)
    assert shapely.contains(m.free_region, inside).all()
    assert not shapely.intersects(m.free_region, outside).any()
    np.testing.assert_allclose(np.linalg.norm(m.edge_normal, axis=1), 1.0)
    np.testing.assert_allclose(np.einsum("ij,ij->i", m.edge_normal, m.edge_dir), 0.0, atol=1e-15)
    np.testing.assert_allclose(
        m.edge_start + m.edge_length[:, None] * m.edge_dir, m.edge_end, atol=1e-12 * m.scale
    )


@pytest.mark.parametrize("name", sorted(WORLDS))
def test_edge_vertex_incidence(name):
    m = WORLDS[name]
    idx = np.arange(m.n_vertices)
    np.testing.assert_array_equal(m.edge_start[m.vertex_next_edge], m.vertices)
    np.testing.assert_array_equal(m.edge_end[m.vertex_prev_edge], m.vertices)
    np.testing.assert_array_equal(m.edge_vertices[:, 0], idx)
    np.testing.assert_array_equal(m.vertices[m.edge_vertices[:, 1]], m.edge_end)


@pytest.mark.parametrize("name", sorted(WORLDS))
def test_vertex_convex_matches_disk_oracle(name):
    """A convex obstacle vertex is one where a tiny disk around it is MORE than half free.

    Its angle measured in free space exceeds pi (the paper's "reflex vertex"): the obstacle
    fills less than half of the disk. A room corner (concave obstacle vertex) is less
    than half free.
    """
    m = WORLDS[name]
    eps = 1e-3 * m.edge_length.min()
    free = m.free_region
    for i, v in enumerate(m.vertices):
        disk = Point(v).buffer(eps, quad_segs=64)
        fraction = disk.intersection(free).area / disk.area
        assert abs(fraction - 0.5) > 1e-3  # no straight vertices survive cleaning
        assert bool(m.vertex_convex[i]) == (fraction > 0.5), (name, i, v, fraction)
    np.testing.assert_array_equal(m.convex_vertices, np.flatnonzero(m.vertex_convex))


def test_convex_vertex_counts():
    assert WORLDS["corridor"].convex_vertices.size == 2  # the two corridor mouth corners
    assert int(WORLDS["room_square"].vertex_convex.sum()) == 4
    assert int(WORLDS["star_hole"].vertex_convex.sum()) == 4  # the four star tips


# ---------------------------------------------------------------------- queries
@pytest.mark.parametrize("name", sorted(WORLDS))
def test_contains_matches_shapely(name):
    m = WORLDS[name]
    rng = np.random.default_rng(1234)
    x0, y0, x1, y1 = m.bounds
    pts = rng.uniform([x0 - 1, y0 - 1], [x1 + 1, y1 + 1], size=(3000, 2))
    # points on the walls are in the closed free region: add vertices and edge points
    t = rng.uniform(size=(m.n_edges, 1))
    on_walls = np.concatenate([m.vertices, m.edge_start + t * (m.edge_end - m.edge_start)])
    expect = shapely.covers(m.free_region, shapely.points(pts))
    far = m.distance_to_walls(pts) > 1e-9 * m.scale
    np.testing.assert_array_equal(m.contains(pts)[far], expect[far])
    assert m.contains(on_walls).all()


@pytest.mark.parametrize("name", sorted(WORLDS))
def test_distance_to_walls_matches_shapely(name):
    m = WORLDS[name]
    rng = np.random.default_rng(7)
    x0, y0, x1, y1 = m.bounds
    pts = rng.uniform([x0 - 1, y0 - 1], [x1 + 1, y1 + 1], size=(500, 2))
    expect = shapely.distance(shapely.points(pts), m.free_region.boundary)
    np.testing.assert_allclose(m.distance_to_walls(pts), expect, atol=1e-12)


def test_wall_queries_on_many_points_and_edges_keep_memory_bounded():
    # both built (points x edges) float arrays at once: the shooting evader's reset on a
    # 60 x 56 room with 210 pillars (844 edges) asked for 315,000 points and was killed by
    # the OOM killer at 23 GB; here 8,000 points peaked at 655 MB
    import tracemalloc

    m = Map(
        box(0, 0, 60, 56),
        [
            box(4 * i + 1.6, 4 * j + 1.6, 4 * i + 2.4, 4 * j + 2.4)
            for i in range(15)
            for j in range(14)
        ],
    )
    assert m.n_edges == 844
    pts = np.random.default_rng(3).uniform(-1, 61, size=(8000, 2))
    tracemalloc.start()
    try:
        dist, inside = m.distance_to_walls(pts), m.contains(pts)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 250e6, f"{peak / 1e6:.0f} MB"
    expect = shapely.distance(shapely.points(pts), m.free_region.boundary)
    np.testing.assert_allclose(dist, expect, atol=1e-12)
    far = dist > 1e-9 * m.scale
    np.testing.assert_array_equal(
        inside[far], shapely.covers(m.free_region, shapely.points(pts))[far]
    )


def test_describe_names_features():
    from envs.maps import Feature

    m = WORLDS["room_square"]
    i = int(m.convex_vertices[0])
    assert m.describe(Feature("vertex", i)).startswith(f"convex vertex {i} (")
    assert m.describe(Feature("vertex", 0)).startswith("concave vertex 0 (")
    assert m.describe(Feature("edge", 2)).startswith("edge 2 (")


# ---------------------------------------------------------------------- equivalent worlds
def test_non_convex_boundary_equals_rectangle_with_blocks():
    """An L-shaped room equals a rectangle minus a corner block merged into the boundary."""
    l_room = Map([(0, 0), (8, 0), (8, 3), (3, 3), (3, 8), (0, 8)])
    blocks = Map(box(0, 0, 8, 8), [box(3, 3, 8, 8)], merge=True)
    assert walls_equal(l_room, blocks)
    assert l_room == blocks


def test_corridor_room_equals_rectangle_with_blocks():
    corridor = WORLDS["corridor"]
    blocks = Map(box(-6, -5, 10, 5), [box(-6, -5, 0, -0.5), box(-6, 0.5, 0, 5)], merge=True)
    assert walls_equal(corridor, blocks)
    assert corridor.digest == blocks.digest
    np.testing.assert_array_equal(
        np.sort(corridor.vertices[corridor.vertex_convex], axis=0),
        np.sort(blocks.vertices[blocks.vertex_convex], axis=0),
    )


# ---------------------------------------------------------------------- identity
@pytest.mark.parametrize("name", sorted(WORLDS))
def test_pickle_round_trip(name):
    m = WORLDS[name]
    m2 = pickle.loads(pickle.dumps(m))
    assert m2 == m and m2.name == m.name and m2.merged == m.merged
    for attr in ("vertices", "vertex_convex", "edge_normal", "edge_vertices"):
        np.testing.assert_array_equal(getattr(m2, attr), getattr(m, attr))


@pytest.mark.parametrize("name", sorted(WORLDS))
@pytest.mark.parametrize("reflect", [False, True])
def test_transformed_is_a_similarity(name, reflect):
    m = WORLDS[name]
    rng = np.random.default_rng(5)
    angle, s = rng.uniform(0, 2 * np.pi), rng.uniform(0.3, 3.0)
    rot = s * np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
    if reflect:
        rot = rot @ np.diag([1.0, -1.0])
    offset = rng.uniform(-50, 50, size=2)
    t = m.transformed(rot, offset)
    # merged walls are snapped to a decimal grid (see test_merge_matches_shapely_union)
    tol = 1e-9 * t.scale if not m.merged else 10.0 ** np.floor(np.log10(REL_GAP_TOL * t.scale * 10))
    image = m.vertices @ rot.T + offset
    # vertex i maps to a vertex of t with the same convexity
    d = np.linalg.norm(image[:, None, :] - t.vertices[None, :, :], axis=2)
    match = d.argmin(axis=1)
    assert d.min(axis=1).max() < tol
    assert len(set(match.tolist())) == m.n_vertices == t.n_vertices
    np.testing.assert_array_equal(t.vertex_convex[match], m.vertex_convex)
    assert t.free_region.area == pytest.approx(s * s * m.free_region.area, rel=1e-6)
    # the two wall edges at each vertex keep their lengths times s (a reflection swaps them)
    pair = lambda mp, idx: np.sort(
        np.stack(
            [mp.edge_length[mp.vertex_prev_edge[idx]], mp.edge_length[mp.vertex_next_edge[idx]]], 1
        ),
        1,
    )
    np.testing.assert_allclose(pair(t, match), s * pair(m, np.arange(m.n_vertices)), atol=3 * tol)


def test_digest_is_canonical():
    a = Map(ROOM, [box(1, 1, 2, 2), regular(7, 7, 1, 5)])
    rotated_start = Map(ROOM[2:] + ROOM[:2], [regular(7, 7, 1, 5), box(1, 1, 2, 2)[::-1]])
    assert (
        a.digest == rotated_start.digest and a == rotated_start and hash(a) == hash(rotated_start)
    )
    quarter = np.array([[0.0, -1.0], [1.0, 0.0]])
    back = a.transformed(quarter).transformed(quarter.T)
    assert back == a


@pytest.mark.parametrize(
    "change",
    [
        pytest.param(lambda: Map(ROOM, [box(1, 1, 2, 2.000001)]), id="moved-vertex"),
        pytest.param(lambda: Map(ROOM, [box(1, 1, 2, 2), box(5, 5, 6, 6)]), id="extra-obstacle"),
        pytest.param(lambda: Map(ROOM), id="no-obstacle"),
        pytest.param(lambda: Map(box(0, 0, 10, 11), [box(1, 1, 2, 2)]), id="bigger-room"),
        pytest.param(lambda: Map(ROOM, [[(1, 1), (2, 1), (2, 2)]]), id="triangle"),
        pytest.param(
            lambda: Map(ROOM, [box(1, 1, 2, 2)]).transformed(np.eye(2), (1e-6, 0)), id="shifted"
        ),
    ],
)
def test_digest_differs_for_changed_maps(change):
    base = Map(ROOM, [box(1, 1, 2, 2)], name="base")
    other = change()
    assert other.digest != base.digest and other != base
    assert Map(ROOM, [box(1, 1, 2, 2)], name="renamed").digest == base.digest


def test_arrays_are_read_only():
    m = WORLDS["room_square"]
    with pytest.raises(ValueError):
        m.vertices[0, 0] = 1.0
    with pytest.raises(ValueError):
        m.rings[0][0, 0] = 1.0


@pytest.mark.parametrize(
    "bad", [[(0, 0), ("10", 0), (10, 10)], [(0, 0), (True, 0), (10, 10)], [(0, 0), (None, 1)]]
)
def test_coordinates_follow_the_number_rule(bad):
    """Strings and bools are not coordinates (envs.validation), in code as in files."""
    with pytest.raises(InvalidMapError, match=r"^boundary = .*: expected real numbers"):
        Map(bad, [])


def test_name_merge_and_transforms_follow_the_number_rule():
    square = [(0, 0), (4, 0), (4, 4), (0, 4)]
    with pytest.raises(InvalidMapError, match=r"merge = 'yes': expected true or false"):
        Map(square, merge="yes")
    with pytest.raises(InvalidMapError, match=r"name = 3: expected a non-empty string"):
        Map(square, name=3)
    m = Map(square)
    with pytest.raises(InvalidMapError, match=r"transformed matrix = .*: expected an array"):
        m.transformed([["1", 0], [0, 1]])
    with pytest.raises(InvalidMapError, match=r"transformed offset = \[True, 0\]"):
        m.transformed(np.eye(2), [True, 0])
    with pytest.raises(InvalidMapError, match=r"transformed matrix = .*: expected finite"):
        m.transformed([[np.nan, 0], [0, 1]])
    assert m.transformed(np.eye(2), (1, 2)).bounds == (1.0, 2.0, 5.0, 6.0)


def _count_pair_distances(monkeypatch) -> list[int]:
    """Count the (point, edge) pairs Map._pair_distances measures from now until
    ``monkeypatch.undo()``: one entry a call, its number of pairs."""
    pairs: list[int] = []
    measure = Map._pair_distances

    def counted(self, p, e):
        pairs.append(len(e))
        return measure(self, p, e)

    monkeypatch.setattr(Map, "_pair_distances", counted)
    return pairs


def test_wall_distances_of_many_points_read_few_edges_and_keep_every_float(monkeypatch):
    """The shooting evader's reset measures the walls' distance of 10^5-10^6 points (its
    escape plan's crossings and grid walk): against every edge, 113 of the 163 s of its
    reset on a 200 m floor plan at L_min 3, 54 s for 300,000 points of the 844-edge pillar
    room. Through the edges' spatial index: the same floats as against every edge, each
    point measured against a few edges."""
    import envs.maps.map as map_module

    room = Map(
        box(0, 0, 60, 56),
        [
            box(4 * i + 1.6, 4 * j + 1.6, 4 * i + 2.4, 4 * j + 2.4)
            for i in range(15)
            for j in range(14)
        ],
    )
    turned = room.transformed(np.array([[0.6, -0.8], [0.8, 0.6]]) * 1e3, (5e5, -3e5))
    rng = np.random.default_rng(11)
    for m in (room, turned):
        x0, y0, x1, y1 = m.bounds
        k = rng.integers(0, m.n_edges, 3000)
        on = m.edge_start[k] + rng.uniform(size=(3000, 1)) * (m.edge_end[k] - m.edge_start[k])
        pts = np.concatenate(
            [
                rng.uniform([x0 - 1, y0 - 1], [x1 + 1, y1 + 1], size=(20000, 2)),
                on,  # on the walls, and within rounding of them
                on + rng.normal(scale=1e-9 * m.scale, size=on.shape),
                m.vertices,
            ]
        )
        pairs = _count_pair_distances(monkeypatch)
        got = m.distance_to_walls(pts)
        monkeypatch.undo()
        assert sum(pairs) < 0.05 * len(pts) * m.n_edges, sum(pairs) / len(pts)
        monkeypatch.setattr(map_module, "_NEAR_EDGES", 10**9)  # every edge
        assert np.array_equal(got, m.distance_to_walls(pts))
        monkeypatch.undo()


def _count_segment_distances(monkeypatch) -> list[int]:
    """Count the (point, edge) pairs measured one pair at a time (the map's
    ``_segment_distances``, which its cells and its index both use) from now until
    ``monkeypatch.undo()``: one entry a call, its number of pairs."""
    import envs.maps.map as map_module

    pairs: list[int] = []
    measure = map_module._segment_distances

    def counted(p, start, direction, length):
        pairs.append(len(start))
        return measure(p, start, direction, length)

    monkeypatch.setattr(map_module, "_segment_distances", counted)
    return pairs


def _pillar_room() -> Map:
    """60 x 56 room with 210 square pillars (844 edges, all axis-aligned: exact ties)."""
    return Map(
        box(0, 0, 60, 56),
        [
            box(4 * i + 1.6, 4 * j + 1.6, 4 * i + 2.4, 4 * j + 2.4)
            for i in range(15)
            for j in range(14)
        ],
    )


def _probe_points(m: Map, rng, k: int) -> np.ndarray:
    """k points anywhere round the map, k on its walls, k within rounding of them, and
    its vertices."""
    x0, y0, x1, y1 = m.bounds
    e = rng.integers(0, m.n_edges, k)
    on = m.edge_start[e] + rng.uniform(size=(k, 1)) * (m.edge_end[e] - m.edge_start[e])
    return np.concatenate(
        [
            rng.uniform([x0 - 3, y0 - 3], [x1 + 3, y1 + 3], size=(k, 2)),
            on,
            on + rng.normal(scale=1e-9 * m.scale, size=on.shape),
            m.vertices,
        ]
    )


def test_wall_distances_of_a_few_points_on_a_large_map_read_their_cells_edges(monkeypatch):
    """The decomposition pursuer measures the walls' distance of one to a hundred grid
    nodes at a time (its clearances on a lazy table): against all 2696 edges of a 346 m
    floor plan that was a quarter of its decision time (~0.1 ms a point), through the
    edges' index ~35 us a call and 5-12 us a point. A call of at most _CELL_POINTS points
    measures each against the few edges of its cell, which hold every edge nearest to
    any point of it: the same floats as against every edge; a few points on a small map
    stay brute force."""
    import envs.maps.map as map_module
    from envs.maps import floor_plan

    big = floor_plan(0, n_vertices=2993, size=(346.0, 346.0))
    turned = _pillar_room().transformed(np.array([[0.6, -0.8], [0.8, 0.6]]) * 1e3, (5e5, -3e5))
    small = Map(box(0, 0, 10, 8), [box(2, 2, 3, 3), box(5, 4, 6, 6.5)])
    rng = np.random.default_rng(12)
    for m, celled in ((big, True), (turned, True), (small, False)):
        pts = _probe_points(m, rng, 300)
        pairs = _count_segment_distances(monkeypatch)
        # one point a call, six, and a hundred
        got = [
            m.distance_to_walls(pts[i : i + n]) for n in (1, 6, 100) for i in range(0, len(pts), n)
        ]
        monkeypatch.undo()
        assert (len(pairs) > 0) == celled
        if celled:
            assert sum(pairs) < 0.02 * 3 * len(pts) * m.n_edges, sum(pairs) / (3 * len(pts))
        monkeypatch.setattr(map_module, "_NEAR_EDGES", 10**9)  # every edge
        want = m.distance_to_walls(pts)
        monkeypatch.undo()
        assert np.array_equal(np.concatenate(got), np.tile(want, 3))  # the same floats
        assert (want == 0.0).sum() >= 300  # the points on the walls


def test_the_cells_new_to_a_call_are_measured_in_one_go(monkeypatch):
    """A call of distance_to_walls over points in several cells not met yet (a block of
    the pursuer's grid nodes on new ground) finds their edges in one index query each for
    all of them (_build_cells, not _cell_edges a cell at a time): the same edges as one
    cell at a time, the same floats as against every edge."""
    import envs.maps.map as map_module
    from envs.maps import floor_plan

    m, alone = (floor_plan(1, n_vertices=300, size=(110.0, 110.0)) for _ in range(2))
    rng = np.random.default_rng(14)
    built = []
    monkeypatch.setattr(map_module.Map, "_cell_edges", _counted(Map._cell_edges, built))
    pts = rng.uniform(20.0, 40.0, size=(60, 2))
    got = m.distance_to_walls(pts)
    cells = set(m._cells_of(pts))
    assert len(cells) > 10 and not built  # every cell built together
    monkeypatch.undo()
    assert all(
        all(np.array_equal(a, b) for a, b in zip(m._cells[c], alone._cell_edges(*c), strict=True))
        for c in cells
    )
    monkeypatch.setattr(map_module, "_NEAR_EDGES", 10**9)  # every edge
    assert np.array_equal(got, m.distance_to_walls(pts))


def _counted(method, calls: list):
    """``method`` counting its cells not kept yet in ``calls``."""

    def counted(self, i, j):
        if (i, j) not in self._cells:
            calls.append((i, j))
        return method(self, i, j)

    return counted


def _nearest_against_every_edge(m: Map, p: np.ndarray) -> tuple[np.ndarray, int]:
    """The closest wall point and its edge (the first of the nearest) against every edge,
    in nearest_wall_point's arithmetic."""
    rel = p[None, :] - m.edge_start
    t = np.clip(np.einsum("ej,ej->e", rel, m.edge_dir), 0.0, m.edge_length)
    closest = m.edge_start + t[:, None] * m.edge_dir
    d = np.einsum("ej,ej->e", p - closest, p - closest)
    k = int(np.argmin(d))
    return closest[k], k


def test_the_nearest_wall_point_is_the_one_against_every_edge(monkeypatch):
    """Map.nearest_wall_point (the pursuer's wall push, the evaders' wall readings) reads
    the few edges of the point's cell: the same point and the same edge, the first of the
    nearest on a tie (the pillar room's corners), as against every edge."""
    from envs.maps import floor_plan

    room = _pillar_room()
    big = floor_plan(0, n_vertices=2993, size=(346.0, 346.0))
    small = Map(box(0, 0, 10, 8), [box(2, 2, 3, 3), box(5, 4, 6, 6.5)])
    rng = np.random.default_rng(13)
    corners = np.array([[0.5, 0.5], [59.5, 0.5], [0.5, 55.5], [59.5, 55.5]])  # two walls alike
    d = np.linalg.norm(corners[:, None, :] - room.edge_start[None], axis=2)
    assert ((np.abs(d - 0.5 * math.sqrt(2.0)) < 1e-12).sum(axis=1) == 1).all()  # (the corner)
    turned = room.transformed(np.array([[0.6, -0.8], [0.8, 0.6]]) * 1e3, (5e5, -3e5))
    for m in (room, turned, big, small):
        pts = _probe_points(m, rng, 500)
        if m is room:
            pts = np.concatenate([pts, corners])
        for p in pts:
            q, k = m.nearest_wall_point(p)
            want_q, want_k = _nearest_against_every_edge(m, p)
            assert k == want_k and np.array_equal(q, want_q), p
            assert type(k) is int
    for p in corners:  # a tie: the first of the two walls' edges
        _, k = room.nearest_wall_point(p)
        rel = p - room.edge_start
        t = np.clip(np.einsum("ej,ej->e", rel, room.edge_dir), 0.0, room.edge_length)
        gap = rel - t[:, None] * room.edge_dir
        tied = np.flatnonzero(np.einsum("ej,ej->e", gap, gap) == 0.25)
        assert len(tied) == 2 and k == tied[0]
    with pytest.raises(InvalidConfigError, match="nan"):
        room.nearest_wall_point([np.nan, 1.0])


def _brute_diameter(points: np.ndarray) -> float:
    d = points[:, None, :] - points[None, :, :]
    return float(np.sqrt(np.einsum("ijk,ijk->ij", d, d).max()))


@pytest.mark.parametrize("kind", ["cloud", "ellipse", "polygon", "grid", "thin"])
def test_convex_diameter_s_calipers_equal_every_pair(kind, monkeypatch):
    """The rotating calipers (used beyond HULL_ALL_PAIRS hull vertices, forced here for
    every input) find the farthest pair exactly, on random inputs: clouds, points of an
    ellipse at any scale, a regular polygon off the origin, duplicate-laden integer grids
    and a nearly flat cloud (collinear hull vertices, near-tied areas)."""
    import envs.maps.map as map_module

    monkeypatch.setattr(map_module, "HULL_ALL_PAIRS", 0)
    rng = np.random.default_rng(["cloud", "ellipse", "polygon", "grid", "thin"].index(kind))
    for _ in range(150):
        n = int(rng.integers(3, 300))
        if kind == "cloud":
            p = rng.normal(size=(n, 2)) * rng.uniform(0.01, 100)
        elif kind == "ellipse":
            t = rng.uniform(0, 2 * np.pi, n)
            p = np.c_[np.cos(t), rng.uniform(0.01, 1) * np.sin(t)] * 10 ** rng.uniform(-5, 5)
        elif kind == "polygon":
            t = 2 * np.pi * np.arange(n) / n
            p = np.c_[np.cos(t), np.sin(t)] + rng.uniform(-100, 100, 2)
        elif kind == "grid":
            p = rng.integers(0, 5, size=(n, 2)).astype(float)
        else:
            a = rng.uniform(0, np.pi)
            p = np.c_[np.cos(a), np.sin(a)] * rng.uniform(-1, 1, (n, 1))
            p = p + rng.normal(size=p.shape) * 1e-9
        assert map_module.convex_diameter(p) == _brute_diameter(p)


def test_convex_diameter_of_degenerate_inputs():
    from envs.maps.map import convex_diameter

    assert convex_diameter([(1.0, 2.0)]) == 0.0
    assert convex_diameter([(0.0, 0.0), (1.0, 1.0), (3.0, 3.0)]) == math.hypot(3.0, 3.0)
    assert Map(regular(3.0, 3.0, 2.0, 5000)).diameter == pytest.approx(4.0)  # calipers
