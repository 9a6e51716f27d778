"""Hostile input to the map API raises InvalidMapError / UnknownNameError naming it."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from envs.errors import InvalidConfigError, InvalidMapError, UnknownNameError
from envs.maps import Map, load_map
from envs.maps.io import map_from_wkt

SQUARE = [(0, 0), (4, 0), (4, 4), (0, 4)]


@pytest.mark.parametrize("obstacles", [None, 5, "abc"])
def test_obstacles_not_a_sequence_of_polygons(obstacles):
    with pytest.raises(InvalidMapError, match="obstacles"):
        Map(SQUARE, obstacles)


@pytest.mark.parametrize(
    ("matrix", "offset"),
    [
        (np.eye(3), (0, 0)),
        ("x", (0, 0)),
        ([[1, 0]], (0, 0)),
        (np.eye(2), (1, 2, 3)),
        (np.eye(2), (math.nan, 0)),
        ([[math.inf, 0], [0, 1]], (0, 0)),
        (np.eye(2), "ab"),
    ],
)
def test_transformed_rejects_bad_matrix_or_offset(matrix, offset):
    with pytest.raises(InvalidMapError, match="transformed"):
        Map(SQUARE).transformed(matrix, offset)


def test_transformed_accepts_integer_reflection():
    m = Map(SQUARE, [[(1, 1), (2, 1), (2, 2)]]).transformed(np.array([[-1, 0], [0, 1]]), (4, 0))
    assert m.bounds == (0.0, 0.0, 4.0, 4.0)
    assert int(m.vertex_convex.sum()) == 3


@pytest.mark.parametrize("text", [None, 5, {"type": "Polygon"}, b"POLYGON ((0 0, 1 0, 1 1))"])
def test_wkt_requires_text(text):
    with pytest.raises(InvalidMapError, match="expected WKT text"):
        map_from_wkt(text)


@pytest.mark.parametrize("value", [3, None, 2.5, ["corridor"]])
def test_load_map_rejects_non_names(value):
    with pytest.raises(UnknownNameError, match=repr(value).replace("[", r"\[")):
        load_map(value)


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
@pytest.mark.parametrize("n", [2, 20_000])
def test_point_queries_refuse_a_point_that_is_not_finite(bad, n):
    """``Map.contains`` and ``Map.distance_to_walls`` answered numpy's way: a NaN or
    infinite point was outside the map (False) at distance nan or inf, so a position
    gone NaN upstream read as a position off the map. They raise, as the kernel's point
    queries do, naming the first such coordinate; a batch of many points (chunked, or
    through the walls' spatial index) alike."""
    angles = np.linspace(0.0, 2.0 * math.pi, 200, endpoint=False)  # 204 edges: the index
    m = Map(SQUARE, [np.c_[2.0 + 0.5 * np.cos(angles), 2.0 + 0.5 * np.sin(angles)]])
    points = np.full((n, 2), 0.5)
    points[-1, 1] = bad
    got = rf"got {bad} at index \({n - 1}, 1\)"
    with pytest.raises(InvalidConfigError, match=rf"contains points = .*: expected finite .*{got}"):
        m.contains(points)
    with pytest.raises(InvalidConfigError, match=rf"distance_to_walls points = .*{got}"):
        m.distance_to_walls(points)
    points[-1, 1] = 3.0  # finite points are answered as before
    assert m.contains(points).all()
    assert (m.distance_to_walls(points) == 0.5).all()


@pytest.mark.parametrize("build", ["crossroads", "t_junction"])
@pytest.mark.parametrize(
    ("arm", "width", "named"),
    [(0.0, 2.0, "arm = 0.0"), (-1.0, 2.0, "arm = -1.0"), (math.nan, 2.0, "arm = nan"),
     (3.0, math.inf, "width = inf"), (3.0, 0.0, "width = 0.0")],
)  # fmt: skip
def test_a_junction_of_no_or_negative_size_is_refused_naming_it(build, arm, width, named):
    # An arm of length 0 was a bare width x width square named "plus" or "tee"; a
    # negative one failed as "boundary: polygon is not simple", naming no argument.
    from envs.maps import junctions

    expected = rf"^{build}: {re.escape(named)}: expected a finite number > 0$"
    with pytest.raises(InvalidConfigError, match=expected):
        getattr(junctions, build)(arm=arm, width=width)
