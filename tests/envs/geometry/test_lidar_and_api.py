"""Lidar ray distances against shapely; the kernel cache and the value types."""

from __future__ import annotations

import math

import numpy as np
import pytest

from envs.errors import InvalidConfigError
from envs.geometry import Arc, FreeArcs, Kernel, Stop, kernel_for, wrap_angle
from envs.maps import Feature, Map
from tests.envs.geometry._maps import all_maps, sample_free_points, square_obstacle_map
from tests.envs.geometry._oracles import ray_distance_oracle


@pytest.mark.parametrize("world", all_maps(), ids=lambda m: m.name)
def test_ray_distances_match_shapely(world):
    rng = np.random.default_rng(4)
    k = kernel_for(world)
    angles = np.linspace(-math.pi, math.pi, 37)
    for o in sample_free_points(world, rng, 12, margin=1e-3):
        for max_range in (0.8, 50.0):
            got = k.ray_distances(o, angles, max_range)
            want = [ray_distance_oracle(world, o, a, max_range) for a in angles]
            np.testing.assert_allclose(got, want, atol=1e-9)


def test_rays_through_vertices_and_from_walls():
    world = square_obstacle_map()
    k = kernel_for(world)
    # into the concave room corner (5, 5) and onto the convex corner (0, 0)
    assert k.ray_distances((4, 4), [math.pi / 4], 10)[0] == pytest.approx(math.sqrt(2))
    assert k.ray_distances((1, 1), [-3 * math.pi / 4], 10)[0] == pytest.approx(math.sqrt(2))
    # from a point on the bottom wall: rays into free space see past the wall it rests on
    d = k.ray_distances((3, -5), [math.pi / 2, -math.pi / 2, 0.0, math.pi / 4], 20)
    np.testing.assert_allclose(d, [10.0, 0.0, 2.0, 2 * math.sqrt(2)])
    # from the top edge of the obstacle, straight up and straight down into it
    d = k.ray_distances((-1, 0), [math.pi / 2, -math.pi / 2], 20)
    np.testing.assert_allclose(d, [5.0, 0.0])
    assert k.ray_distances((1, 1), [], 3.0).shape == (0,)
    with pytest.raises(InvalidConfigError, match="max_range"):
        k.ray_distances((1, 1), [0.0], 0.0)
    with pytest.raises(InvalidConfigError, match="angles"):
        k.ray_distances((1, 1), [np.nan], 1.0)


def test_kernel_for_caches_by_digest():
    a = square_obstacle_map()
    b = Map(a.boundary, a.obstacles, name="same walls, another name")
    assert kernel_for(a) is kernel_for(a)
    assert kernel_for(a) is kernel_for(b)
    assert isinstance(kernel_for(a), Kernel)
    # the same walls with rings starting elsewhere: the numbering is canonical, so equal
    # digests mean identical arrays and one shared kernel with valid feature indices
    c = Map(np.roll(a.boundary, 1, axis=0), [np.roll(o, 2, axis=0) for o in a.obstacles])
    assert c.digest == a.digest and np.array_equal(c.vertices, a.vertices)
    kc = kernel_for(c)
    assert np.array_equal(kc.map.vertices, c.vertices)
    f = kc.blocking_feature((-1, 1), (1, -1))  # through the convex vertex (0, 0)
    assert f.kind == "vertex" and tuple(c.vertices[f.index]) == (0.0, 0.0)
    with pytest.raises(InvalidConfigError, match="expected a Map"):
        kernel_for("square")
    with pytest.raises(InvalidConfigError, match="expected a Map"):
        Kernel(None)


def test_wrap_angle_and_arc_helpers():
    assert wrap_angle(math.pi) == -math.pi
    assert wrap_angle(3 * math.pi / 2) == pytest.approx(-math.pi / 2)
    stop = Stop("tip", Feature("edge", 0))
    arc = Arc(3.0, 3.5, stop, stop)  # wraps past pi
    assert arc.width == pytest.approx(0.5)
    assert arc.contains(3.2) and arc.contains(3.4 - 2 * math.pi) and not arc.contains(0.0)
    assert arc.contains(3.0) and arc.contains(3.5)  # closed
    assert not arc.is_full
    assert arc.mid == pytest.approx(wrap_angle(3.25))
    full = Arc(-math.pi, math.pi)
    assert full.is_full and full.contains(123.0)
    fa = FreeArcs(np.zeros(2), 1.0, (Arc(-1.0, 0.5, stop, stop), arc))
    assert fa.arc_index(0.0) == 0 and fa.arc_index(3.1) == 1 and fa.arc_index(2.0) is None
    assert not fa.contains(2.0) and fa.contains(-1.0)
    assert fa.total_width == pytest.approx(2.0)
    assert not fa.is_full and not fa.is_empty and len(fa) == 2
    assert str(stop) == "tip-edge 0"
