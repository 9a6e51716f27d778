"""Built-in maps: load, validity, round trips, the paper's worlds, valid surveillance starts."""

from __future__ import annotations

import math
from importlib import resources

import numpy as np
import pytest
import shapely
from shapely.geometry import LineString, Polygon

from envs.errors import UnknownNameError
from envs.maps import MapInfo, builtin_info, builtin_map, builtin_names, load_map, save_map
from envs.maps.map import Map

from ._helpers import box, walls_equal

REQUIRED = {"corridor", "two_rooms", "corner", "open_room", "pillars", "l_hall", "maze"}
NAMES = builtin_names()


def test_required_maps_are_there():
    assert REQUIRED <= set(NAMES)
    assert len(NAMES) >= 7 and NAMES == sorted(NAMES)


def test_builtin_names_returns_a_copy():
    names = builtin_names()
    names.append("bogus")
    assert "bogus" not in builtin_names()


def test_every_data_file_is_package_data():
    # pyproject declares envs = ["maps/data/*.json"]: every data file must match it
    files = [p.name for p in resources.files("envs.maps").joinpath("data").iterdir() if p.is_file()]
    assert sorted(f[:-5] for f in files if f.endswith(".json")) == NAMES
    assert all(f.endswith(".json") for f in files)


@pytest.mark.parametrize("name", NAMES)
def test_builtin_is_valid_with_description_and_parameters(name):
    info = builtin_info(name)
    assert isinstance(info, MapInfo) and isinstance(info.map, Map)
    assert info.name == name == info.map.name
    assert info.description and "\n" not in info.description
    assert 0 < info.l_min <= info.l_max and info.v_pursuer > 0 and info.v_evader > 0
    assert info.rho == info.v_evader / info.v_pursuer
    assert (info.L_min, info.L_max) == (info.l_min, info.l_max)
    assert info.params() == {
        "l_min": info.l_min,
        "l_max": info.l_max,
        "v_pursuer": info.v_pursuer,
        "v_evader": info.v_evader,
    }
    m = builtin_map(name)
    assert not m.merged  # well-formed: no touching polygons needed merging
    # rebuilding from its parts revalidates it (simple, inside, non-touching)
    assert Map(m.boundary, m.obstacles) == m
    assert m.free_region.is_valid and m.free_region.geom_type == "Polygon"


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("suffix", [".json", ".geojson", ".wkt"])
def test_builtin_round_trips_through_every_format(tmp_path, name, suffix):
    m = builtin_map(name)
    info = builtin_info(name)
    p = save_map(
        m, tmp_path / f"{name}{suffix}", description=info.description, metadata=info.params()
    )
    back = load_map(p)
    assert back == m and back.name == name
    np.testing.assert_array_equal(np.sort(back.vertices, axis=0), np.sort(m.vertices, axis=0))


def test_unknown_builtin_names_the_value_and_the_choices():
    with pytest.raises(UnknownNameError, match=r"'corridoor'.*available.*corridor"):
        builtin_map("corridoor")
    with pytest.raises(UnknownNameError):
        builtin_info(3)  # type: ignore[arg-type]


# ---------------------------------------------------------------------- the paper's worlds
def test_corridor_is_fig3_world():
    m = builtin_map("corridor")
    assert len(m.rings) == 1  # one non-convex outer boundary
    assert m.bounds == (-6.0, -5.0, 10.0, 5.0)
    mouth = m.vertices[m.vertex_convex]
    assert sorted(map(tuple, mouth.tolist())) == [(0.0, -0.5), (0.0, 0.5)]
    width, length = 1.0, 6.0
    l_min = builtin_info("corridor").l_min
    assert width < l_min < length  # the rod cannot turn round in it; corridor longer than L
    assert m.free_region.area == pytest.approx(100 + width * length)


def test_corridor_equals_rectangle_with_blocks_merged():
    blocks = Map(box(-6, -5, 10, 5), [box(-6, -5, 0, -0.5), box(-6, 0.5, 0, 5)], merge=True)
    m = builtin_map("corridor")
    assert walls_equal(m, blocks) and m == blocks


def test_two_rooms_is_fig6_world():
    m = builtin_map("two_rooms")
    blocks = Map(box(-16, -5, 10, 5), [box(-6, -5, 0, -0.5), box(-6, 0.5, 0, 5)], merge=True)
    assert walls_equal(m, blocks) and m == blocks
    assert int(m.vertex_convex.sum()) == 4
    assert 6.0 > 2 * builtin_info("two_rooms").l_min  # corridor longer than 2L (THEORY.md 3)


def test_corner_has_a_single_convex_corner():
    m = builtin_map("corner")
    assert int(m.vertex_convex.sum()) == 1
    assert len(m.rings) == 1


def test_open_room_is_empty_and_larger_than_l():
    m = builtin_map("open_room")
    info = builtin_info("open_room")
    assert len(m.rings) == 1 and m.n_vertices == 4 and not m.vertex_convex.any()
    # somewhere the rod rotates freely: a point at least L_max from every wall
    assert m.free_region.buffer(-info.l_max).area > 0


def test_pillars_are_convex_and_of_different_shapes():
    m = builtin_map("pillars")
    holes = m.rings[1:]
    assert len(holes) >= 3
    assert all(m.vertex_convex[m.vertex_ring == k].all() for k in range(1, len(m.rings)))
    assert {3, 4, 6} <= {len(h) for h in holes}


def test_l_hall_has_a_pillar_and_one_boundary_corner():
    m = builtin_map("l_hall")
    assert len(m.rings) == 2
    assert int(m.vertex_convex[m.vertex_ring == 0].sum()) == 1


@pytest.mark.parametrize("name", ["maze", "office"])
def test_passages_are_wide_enough_for_bodies(name):
    """Every passage is >= 1.5 wide: bodies of radius 0.75 reach every part of the map."""
    if name not in NAMES:
        pytest.skip(f"no built-in {name!r}")
    m = builtin_map(name)
    reachable = m.free_region.buffer(-0.75 + 1e-9)
    assert reachable.geom_type == "Polygon"
    # nothing but corners is lost: the eroded region, grown back, covers all but corners
    regrown = reachable.buffer(0.75)
    assert regrown.area > 0.97 * m.free_region.area


def test_maze_has_several_corridors_and_free_standing_walls():
    m = builtin_map("maze")
    assert len(m.rings) >= 2  # walls standing free of the outer wall make loops
    assert int(m.vertex_convex.sum()) >= 10


# ---------------------------------------------------------------------- surveillance starts
def clear_rod_exists(m: Map, length: float, clearance: float) -> bool:
    """Brute force: is there a rod of this length clear of every wall by ``clearance``?"""
    free = m.free_region
    x0, y0, x1, y1 = m.bounds
    shrunk = free.buffer(-clearance)
    for x in np.linspace(x0, x1, 41)[1:-1]:
        for y in np.linspace(y0, y1, 41)[1:-1]:
            e = (float(x), float(y))
            if not shrunk.contains(shapely.Point(e)):
                continue
            for a in np.linspace(0, 2 * math.pi, 24, endpoint=False):
                p = (e[0] + length * math.cos(a), e[1] + length * math.sin(a))
                if shrunk.contains(LineString([e, p])):
                    return True
    return False


@pytest.mark.parametrize("name", NAMES)
def test_recommended_parameters_admit_surveillance_starts(name):
    info = builtin_info(name)
    for length in (info.l_min, 0.5 * (info.l_min + info.l_max), info.l_max):
        assert clear_rod_exists(info.map, length, clearance=0.25), (name, length)


def test_clear_rod_oracle_can_fail():
    tiny = Map(box(0, 0, 1, 1))
    assert not clear_rod_exists(tiny, 2.0, clearance=0.1)
    assert isinstance(tiny.free_region, Polygon)
