"""Seeded random maps: determinism, exact vertex counts, guaranteed gaps, shapes, validation."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
import shapely
from shapely.geometry import Polygon

from envs.errors import InfeasibleError, InvalidConfigError
from envs.maps import random_map
from envs.maps.random_maps import KINDS


def obstacle_polygons(m) -> list[Polygon]:
    return [Polygon(r) for r in m.rings[1:]]


def polygon_kernel(ring: np.ndarray) -> Polygon:
    """Kernel of a simple polygon (points that see all of it): the intersection of the
    inner half-planes of its edges, each clipped to a big box. Independent of the generator."""
    ring = np.asarray(Polygon(ring).exterior.coords)[:-1]
    if not Polygon(ring).exterior.is_ccw:
        ring = ring[::-1]
    big = 1e3 * (1 + np.abs(ring).max())
    kernel = Polygon(ring).envelope.buffer(1.0)
    for a, b in zip(ring, np.roll(ring, -1, axis=0), strict=True):
        d = (b - a) / np.linalg.norm(b - a)
        n = np.array([-d[1], d[0]])  # inner normal of a CCW ring
        half = Polygon([a - big * d, b + big * d, b + big * d + big * n, a - big * d + big * n])
        kernel = kernel.intersection(half)
    return kernel


def test_same_seed_same_map_different_seeds_differ():
    for kind in KINDS:
        a = random_map(11, kind=kind)
        b = random_map(11, kind=kind)
        assert a == b and a.digest == b.digest and a.name == b.name
        np.testing.assert_array_equal(a.vertices, b.vertices)
    digests = {random_map(s).digest for s in range(12)}
    assert len(digests) == 12


def test_no_global_rng_is_used():
    np.random.seed(0)
    a = random_map(5)
    np.random.seed(1)
    np.random.random(100)
    assert random_map(5) == a


@pytest.mark.parametrize(
    ("n_vertices", "n_obstacles"),
    [
        (8, None),
        (8, 2),
        (16, None),
        (32, 4),
        (64, None),
        (100, 7),
        (128, None),
        (128, 42),
        (520, None),
        (512, 8),
    ],
)
def test_n_vertices_is_exact(n_vertices, n_obstacles):
    m = random_map(3, n_vertices=n_vertices, n_obstacles=n_obstacles)
    assert m.n_vertices == n_vertices + 4 == m.n_edges
    if n_obstacles is not None:
        assert len(m.rings) - 1 == n_obstacles


def test_benchmark_sizes_with_at_least_500_edges():
    m = random_map(0, n_vertices=500, kind="convex")
    assert m.n_edges >= 500


@pytest.mark.parametrize("seed", range(8))
@pytest.mark.parametrize("kind", KINDS)
def test_min_gap_is_guaranteed_and_free_space_connected(seed, kind):
    gap = [0.5, 1.0, 1.5, 2.5][seed % 4]
    m = random_map(seed, kind=kind, min_gap=gap, n_obstacles=4 + 2 * seed)
    polys = obstacle_polygons(m)
    assert len(polys) == 4 + 2 * seed
    outer = Polygon(m.rings[0])
    for p, q in itertools.combinations(polys, 2):
        assert p.distance(q) >= gap - 1e-12
    for p in polys:
        assert outer.exterior.distance(p) >= gap - 1e-12
        assert outer.contains(p)
    free = m.free_region
    assert free.geom_type == "Polygon" and free.is_valid
    # bodies narrower than the gap go everywhere: eroding by just under half of it
    # leaves a single connected piece
    assert free.buffer(-0.499 * gap).geom_type == "Polygon"


def test_size_is_respected():
    m = random_map(1, size=(30.0, 12.0), n_obstacles=5)
    assert m.bounds == (0.0, 0.0, 30.0, 12.0)
    assert random_map(1, size=15, n_obstacles=3).bounds == (0.0, 0.0, 15.0, 15.0)


def test_convex_kind_gives_convex_obstacles():
    m = random_map(4, kind="convex", n_obstacles=8)
    holes = m.vertex_ring > 0
    assert m.vertex_convex[holes].all()
    for p in obstacle_polygons(m):
        assert p.convex_hull.area == pytest.approx(p.area)


def test_star_kind_gives_star_shaped_obstacles_some_not_convex():
    m = random_map(4, kind="star", n_obstacles=10)
    non_convex = 0
    for r in m.rings[1:]:
        assert polygon_kernel(r).area > 0  # star-shaped: its kernel is not empty
        non_convex += Polygon(r).convex_hull.area > Polygon(r).area * (1 + 1e-9)
    assert non_convex >= 3


def test_kernel_oracle_can_fail():
    # a U shape (comb with two deep notches) has an empty kernel
    comb = [
        (0, 0),
        (5, 0),
        (5, 5),
        (4, 5),
        (4, 1),
        (3, 1),
        (3, 5),
        (2, 5),
        (2, 1),
        (1, 1),
        (1, 5),
        (0, 5),
    ]
    assert polygon_kernel(np.array(comb, dtype=float)).area == 0


def test_rectangles_are_axis_aligned():
    m = random_map(2, kind="rectangles", n_obstacles=7)
    for r in m.rings[1:]:
        assert len(r) == 4
        d = np.roll(r, -1, axis=0) - r
        assert np.all((np.abs(d[:, 0]) < 1e-12) | (np.abs(d[:, 1]) < 1e-12))


def test_polygons_kind_mixes_shapes():
    m = random_map(9, n_obstacles=20)
    convex = [bool(m.vertex_convex[m.vertex_ring == k].all()) for k in range(1, len(m.rings))]
    assert any(convex) and not all(convex)


def test_no_obstacles():
    m = random_map(0, n_obstacles=0)
    assert len(m.rings) == 1 and m.n_vertices == 4


def test_name():
    assert random_map(7, kind="star").name == "random_star_7"
    assert random_map(7, name="w").name == "w"


@pytest.mark.parametrize(
    ("kwargs", "pattern"),
    [
        ({"seed": -1}, r"seed = -1"),
        ({"seed": 1.5}, r"seed = 1\.5"),
        ({"seed": True}, r"seed = True"),
        ({"seed": "3"}, r"seed = '3'"),
        ({"n_obstacles": -2}, r"n_obstacles = -2"),
        ({"n_obstacles": 2.0}, r"n_obstacles = 2\.0"),
        ({"n_vertices": -1}, r"n_vertices = -1"),
        ({"n_vertices": 10**9}, r"n_vertices = 1000000000: expected an integer in \[0, 1000000\]"),
        ({"n_vertices": 1e9}, r"n_vertices = 1000000000.0: expected an integer"),
        ({"n_vertices": 10, "n_obstacles": 4}, r"n_vertices = 10.*>= 12"),
        ({"n_vertices": 9, "n_obstacles": 0}, r"n_vertices = 9"),
        (
            {"n_vertices": 10, "kind": "rectangles", "n_obstacles": 3},
            r"n_vertices = 10.*4 \* n_obstacles = 12",
        ),
        ({"kind": "blobs"}, r"kind = 'blobs'.*polygons"),
        ({"size": 0}, r"size = 0"),
        ({"size": -3.0}, r"size = -3\.0"),
        ({"size": float("nan")}, r"size = nan"),
        ({"size": (10.0,)}, r"size = \(10\.0,\)"),
        ({"size": (10.0, float("inf"))}, r"size\[1\] = inf"),
        ({"min_gap": 0.0}, r"min_gap = 0\.0"),
        ({"min_gap": -1}, r"min_gap = -1"),
        ({"min_gap": float("inf")}, r"min_gap = inf"),
    ],
)
def test_bad_parameters_raise_naming_the_value(kwargs, pattern):
    kwargs = {"seed": 0, **kwargs}
    seed = kwargs.pop("seed")
    with pytest.raises(InvalidConfigError, match=pattern):
        random_map(seed, **kwargs)


def test_infeasible_layouts_raise():
    with pytest.raises(InfeasibleError, match="n_obstacles=50"):
        random_map(0, n_obstacles=50, size=10.0, min_gap=1.5)
    with pytest.raises(InfeasibleError, match="too small"):
        random_map(0, n_obstacles=1, size=3.0, min_gap=1.5)


def test_generated_maps_are_valid_against_shapely():
    m = random_map(21, n_vertices=200)
    union = shapely.union_all(obstacle_polygons(m))
    assert union.geom_type == "MultiPolygon" and len(union.geoms) == len(m.rings) - 1
    assert m.free_region.symmetric_difference(Polygon(m.rings[0]).difference(union)).area < 1e-9
    pts = np.random.default_rng(0).uniform(-1, m.bounds[2] + 1, size=(2000, 2))
    expect = shapely.covers(m.free_region, shapely.points(pts))
    np.testing.assert_array_equal(m.contains(pts), expect)


# ------------------------------------------------------------------ random:SEED names
def test_random_names_load_the_seeded_random_map() -> None:
    from envs.maps import load_map

    assert load_map("random:7") == random_map(7)
    assert load_map("random:rectangles:2") == random_map(2, kind="rectangles")
    assert load_map("random:7").digest != load_map("random:8").digest


def test_random_names_work_wherever_a_map_name_does() -> None:
    from envs import surveillance_v1

    env = surveillance_v1.parallel_env(map="random:star:4")
    assert env.config.map == random_map(4, kind="star")
    env.close()


@pytest.mark.parametrize(
    "bad", ["random:", "random:x", "random:-1", "random:blobs:3", "random:1:2:3"]
)
def test_malformed_random_names_say_what_is_expected(bad: str) -> None:
    from envs.errors import InvalidConfigError
    from envs.maps import load_map

    with pytest.raises(InvalidConfigError, match="random:SEED"):
        load_map(bad)
