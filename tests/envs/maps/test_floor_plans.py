"""Seeded floor plans: rooms along corridors, reproducible, validated, one connected plan."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely

from envs.errors import InvalidConfigError
from envs.maps import Map, floor_plan


def test_same_seed_same_plan_other_seed_other_plan():
    a = floor_plan(4, n_vertices=300, size=(60.0, 50.0))
    assert a == floor_plan(4, n_vertices=300, size=(60.0, 50.0))
    assert a != floor_plan(5, n_vertices=300, size=(60.0, 50.0))
    assert a.name == "floor_plan_4"


@pytest.mark.parametrize(("n", "size"), [(200, 40.0), (600, (120.0, 80.0)), (1000, (200.0, 200.0))])
def test_vertex_count_and_structure(n, size):
    m = floor_plan(1, n_vertices=n, size=size)
    assert isinstance(m, Map)
    assert abs(m.n_vertices / n - 1.0) <= 0.3
    W, H = (size, size) if isinstance(size, float) else size
    x0, y0, x1, y1 = m.bounds
    assert x0 >= -1e-9 and y0 >= -1e-9 and x1 <= W + 1e-9 and y1 <= H + 1e-9
    assert len(m.rings) > 1  # the wall blocks between corridors are islands
    free = m.free_region
    assert free.is_valid and free.geom_type == "Polygon"
    # rooms and corridors: most of the building is free space, walls are thin
    assert 0.6 * W * H < free.area < W * H
    # every door is at least the door width: a disc of radius 0.55 passes everywhere
    opened = free.buffer(-0.55).buffer(0.55)
    assert opened.geom_type == "Polygon" and opened.area > 0.9 * free.area


def test_rotated_plans_are_the_same_plan_turned():
    a = floor_plan(2, n_vertices=200, size=40.0)
    b = floor_plan(2, n_vertices=200, size=40.0, angle=0.5)
    assert a.n_vertices == b.n_vertices
    assert math.isclose(a.free_region.area, b.free_region.area, rel_tol=1e-9)
    c, s = math.cos(0.5), math.sin(0.5)
    turned = shapely.transform(a.free_region, lambda x: x @ np.array([[c, s], [-s, c]]))
    assert turned.symmetric_difference(b.free_region).area < 1e-6 * a.free_region.area


@pytest.mark.parametrize(
    "kwargs",
    [
        {"n_vertices": 10},
        {"n_vertices": True},
        {"size": -5.0},
        {"size": (10.0,)},
        {"door": "wide"},
        {"p_link": 1.5},
        {"size": 10.0},  # no room for a band of rooms
    ],
)
def test_bad_parameters_are_named(kwargs):
    with pytest.raises(InvalidConfigError):
        floor_plan(0, **kwargs)


def test_docstring_examples_run():
    import doctest

    import envs.maps.floor_plans

    result = doctest.testmod(envs.maps.floor_plans)
    assert result.attempted > 0 and result.failed == 0
