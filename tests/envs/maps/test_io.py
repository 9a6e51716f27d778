"""Map files: JSON, GeoJSON and WKT round trips, reading conventions, malformed files."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import shapely
from shapely.geometry import LinearRing, Polygon, shape

from envs.errors import InvalidConfigError, InvalidMapError, UnknownNameError
from envs.maps import Map, builtin_map, load_map, read_map, save_map
from envs.maps.io import map_from_geojson, map_from_wkt, map_to_geojson, map_to_wkt

ROOM = [(0.0, 0.0), (10.0, 0.0), (10.0, 10.0), (0.0, 10.0)]


def box(x0, y0, x1, y1):
    return [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]


MAPS = {
    "plain": Map(ROOM, [box(1, 1, 2, 2), [(5, 5), (7, 5.5), (6, 7.25)]], name="plain"),
    "awkward_floats": Map(
        [(0.1, 0.2), (10 / 3, -1e-7), (7.123456789012345, 0.3), (5, 9.87654321)],
        [[(2, 1), (3.0000001, 1.1), (2.5, 2.5)]],
        name="awkward",
    ),
    "nonconvex": Map(
        [(0, -5), (10, -5), (10, 5), (0, 5), (0, 0.5), (-6, 0.5), (-6, -0.5), (0, -0.5)]
    ),
    "merged": Map(ROOM, [box(1, 1, 3, 3), box(2, 2, 4, 4), box(0, 8, 2, 9)], merge=True, name="m"),
}
META = {"l_min": 2.0, "l_max": 4.5, "v_pursuer": 1.0, "v_evader": 0.5, "note": "ß ✓"}


def assert_same_map(a: Map, b: Map, *, exact_inputs: bool = True) -> None:
    assert a == b
    np.testing.assert_array_equal(np.sort(a.vertices, axis=0), np.sort(b.vertices, axis=0))
    if exact_inputs:
        assert a.merged == b.merged
        assert same_ring(a.boundary, b.boundary)
        assert len(a.obstacles) == len(b.obstacles)
        for p, q in zip(a.obstacles, b.obstacles, strict=True):
            assert same_ring(p, q)


def same_ring(p: np.ndarray, q: np.ndarray) -> bool:
    """Bit-identical vertices in the same cyclic order, in either direction."""
    if p.shape != q.shape:
        return False
    return any(
        np.array_equal(np.roll(r, k, axis=0), q) for r in (p, p[::-1]) for k in range(len(p))
    )


# ---------------------------------------------------------------------- round trips
@pytest.mark.parametrize("key", sorted(MAPS))
def test_json_round_trip_is_exact(tmp_path, key):
    m = MAPS[key]
    p = save_map(m, tmp_path / "w.json", description="a world", metadata=META)
    doc = read_map(p)
    assert_same_map(doc.map, m)
    assert doc.map.name == m.name
    assert doc.description == "a world" and doc.metadata == META


@pytest.mark.parametrize("key", sorted(MAPS))
def test_geojson_round_trip_is_exact(tmp_path, key):
    m = MAPS[key]
    p = save_map(m, tmp_path / "w.geojson", description="d", metadata=META)
    doc = read_map(p)
    assert_same_map(doc.map, m)
    assert doc.map.name == m.name and doc.description == "d" and doc.metadata == META


@pytest.mark.parametrize("key", sorted(MAPS))
def test_wkt_round_trip_keeps_the_walls(tmp_path, key):
    m = MAPS[key]
    p = save_map(m, tmp_path / "w.wkt")
    back = load_map(p)
    # WKT holds the walls, not a merged map's parts: same world, name from the file stem
    assert_same_map(back, m, exact_inputs=not m.merged)
    assert back.name == "w" and not back.merged


def test_wkt_refuses_metadata_that_recommends_parameters(tmp_path):
    # the file loaded back without them and played at L 2-4, V_e 0.5 (a 1.4 m room whose
    # metadata said l_min 0.2 was then refused; a larger one played another game)
    m = MAPS["plain"]
    with pytest.raises(InvalidConfigError, match=r"w\.wkt: metadata recommends l_max = 4\.5, "
                       r"v_evader = 0\.2, and WKT has no room for metadata \(the file would "
                       r"play at the defaults l_max = 4, v_evader = 0\.5\)"):  # fmt: skip
        save_map(m, tmp_path / "w.wkt", metadata={**META, "v_evader": 0.2})
    assert not (tmp_path / "w.wkt").exists()
    # free-form keys, nulls and the defaults themselves (a built-in's) lose no game
    save_map(m, tmp_path / "w.wkt", metadata={"note": "x", "l_min": None, "l_max": 4.0})


def test_geojson_recommendations_outside_metadata_are_refused(tmp_path):
    # "properties": {"l_min": 1.0} (GeoJSON's flat properties) was ignored: the map played
    # at L 2-4 without a word; only properties.metadata is read
    obj = map_to_geojson(MAPS["plain"])
    obj["properties"]["l_min"] = 1.0
    with pytest.raises(InvalidMapError, match=r"properties \{'l_min': 1\.0\} are not read: "
                       r'.*"properties": \{"metadata": \{"l_min": 1\.0\}\}'):  # fmt: skip
        map_from_geojson(obj, source="f.geojson")
    del obj["properties"]["l_min"]
    obj["properties"]["metadata"] = {"l_min": 1.0}
    assert map_from_geojson(obj).metadata == {"l_min": 1.0}


@pytest.mark.parametrize("suffix", [".json", ".geojson"])
def test_a_key_given_twice_in_a_map_file_is_refused(tmp_path, suffix):
    # json keeps a repeated key's last value: the first "obstacles" (or "l_min") was
    # dropped without a word, and the map played without those walls
    walls = "[[[1, 1], [2, 1], [2, 2], [1, 2]]]"
    text = (
        '{"boundary": [[0, 0], [10, 0], [10, 10], [0, 10]], '
        f'"obstacles": {walls}, "obstacles": [], "metadata": {{"l_min": 1}}}}'
    )
    if suffix == ".geojson":  # the same within a feature's properties
        text = json.dumps(map_to_geojson(MAPS["plain"], metadata={"l_min": 1.0}))
        text = text.replace('"metadata": {"l_min": 1.0}', '"metadata": {"l_min": 1.0, "l_min": 3}')
    path = tmp_path / f"twice{suffix}"
    path.write_text(text)
    key = "'obstacles'" if suffix == ".json" else "'l_min'"
    with pytest.raises(InvalidMapError, match=rf"twice{suffix}: key {key} given twice"):
        read_map(path)


def test_geojson_output_follows_rfc7946(tmp_path):
    m = MAPS["plain"]
    obj = json.loads(save_map(m, tmp_path / "w.geojson").read_text())
    assert obj["type"] == "Feature"
    rings = obj["geometry"]["coordinates"]
    assert all(r[0] == r[-1] for r in rings)
    assert LinearRing(rings[0]).is_ccw and not any(LinearRing(r).is_ccw for r in rings[1:])
    # an independent reader (shapely) sees the same free region
    assert shape(obj["geometry"]).symmetric_difference(m.free_region).area < 1e-12


def test_merged_geojson_is_a_collection_with_roles(tmp_path):
    obj = map_to_geojson(MAPS["merged"])
    assert obj["type"] == "FeatureCollection"
    roles = [f["properties"].get("role") for f in obj["features"]]
    assert roles == ["boundary", "obstacle", "obstacle", "obstacle"]
    assert obj["features"][0]["properties"]["merge"] is True


def test_wkt_output_is_read_by_shapely(tmp_path):
    for m in MAPS.values():
        text = map_to_wkt(m)
        assert shapely.from_wkt(text).symmetric_difference(m.free_region).area < 1e-12


def test_wkt_refuses_merged_walls_that_touch_themselves():
    pinch = Map(ROOM, [box(1, 1, 3, 3), box(3, 3, 5, 5)], merge=True)
    with pytest.raises(InvalidMapError, match=r"\.json or \.geojson"):
        map_to_wkt(pinch)


def test_json_file_is_one_ring_per_line(tmp_path):
    text = save_map(MAPS["plain"], tmp_path / "w.json").read_text()
    assert text.count("\n") < 15
    assert json.loads(text)["boundary"] == [list(v) for v in ROOM]


# ---------------------------------------------------------------------- reading conventions
def feature(rings, **props):
    return {
        "type": "Feature",
        "properties": props,
        "geometry": {"type": "Polygon", "coordinates": rings},
    }


def closed(r):
    return [list(p) for p in (*r, r[0])]


def test_geojson_collection_largest_is_the_boundary():
    feats = [
        feature([closed(box(1, 1, 2, 2))]),
        feature([closed(ROOM)]),
        feature([closed(box(5, 5, 6, 6))]),
    ]
    m = map_from_geojson({"type": "FeatureCollection", "features": feats}).map
    assert m == Map(ROOM, [box(1, 1, 2, 2), box(5, 5, 6, 6)])


def test_geojson_role_boundary_wins_and_holes_are_obstacles():
    outer = feature(
        [closed(ROOM), closed(box(7, 7, 8, 8))], role="boundary", name="roles", merge=False
    )
    feats = [feature([closed(box(1, 1, 2, 2))], role="obstacle"), outer]
    obj = {"type": "FeatureCollection", "features": feats, "properties": {"description": "top"}}
    doc = map_from_geojson(obj)
    assert doc.map == Map(ROOM, [box(1, 1, 2, 2), box(7, 7, 8, 8)])
    assert doc.map.name == "roles" and doc.description == "top"


def test_geojson_multipolygon_and_bare_geometry():
    mp = {"type": "MultiPolygon", "coordinates": [[closed(ROOM)], [closed(box(1, 1, 2, 2))]]}
    assert map_from_geojson(mp).map == Map(ROOM, [box(1, 1, 2, 2)])
    gc = {"type": "GeometryCollection", "geometries": [mp]}
    assert map_from_geojson(gc).map == Map(ROOM, [box(1, 1, 2, 2)])


def test_geojson_merge_property_and_override():
    feats = [feature([closed(ROOM)], role="boundary", merge=True)]
    feats += [feature([closed(box(1, 1, 3, 3))]), feature([closed(box(2, 2, 4, 4))])]
    obj = {"type": "FeatureCollection", "features": feats}
    assert map_from_geojson(obj).map.merged
    with pytest.raises(InvalidMapError, match="overlaps"):
        map_from_geojson(obj, merge=False)


def test_wkt_conventions():
    poly = "POLYGON ((0 0, 10 0, 10 10, 0 10, 0 0), (1 1, 2 1, 2 2, 1 2, 1 1))"
    multi = "MULTIPOLYGON (((0 0, 10 0, 10 10, 0 10, 0 0)), ((1 1, 2 1, 2 2, 1 2, 1 1)))"
    coll = (
        "GEOMETRYCOLLECTION (POLYGON ((0 0, 10 0, 10 10, 0 10, 0 0), (5 5, 6 5, 6 6, 5 5)), "
        "POLYGON ((1 1, 2 1, 2 2, 1 2, 1 1)))"
    )
    expect = Map(ROOM, [box(1, 1, 2, 2)])
    assert map_from_wkt(poly) == expect
    assert map_from_wkt(multi) == expect
    assert map_from_wkt(coll) == Map(ROOM, [box(1, 1, 2, 2), [(5, 5), (6, 5), (6, 6)]])
    overlapping = "GEOMETRYCOLLECTION (POLYGON ((0 0, 10 0, 10 10, 0 10, 0 0)), " + (
        "POLYGON ((1 1, 3 1, 3 3, 1 3, 1 1)), POLYGON ((2 2, 4 2, 4 4, 2 4, 2 2)))"
    )
    assert map_from_wkt(overlapping, merge=True).merged


def test_json_file_holding_geojson_is_read_as_geojson(tmp_path):
    p = tmp_path / "world.json"
    p.write_text(json.dumps(map_to_geojson(MAPS["plain"])))
    assert load_map(p) == MAPS["plain"]


def test_json_defaults(tmp_path):
    p = tmp_path / "bare.json"
    p.write_text(json.dumps({"boundary": ROOM}))
    doc = read_map(p)
    assert (
        doc.map.name == "bare"
        and not doc.map.merged
        and doc.description == ""
        and doc.metadata == {}
    )


# ---------------------------------------------------------------------- dispatch
def test_load_map_dispatch(tmp_path):
    assert load_map("corridor") == builtin_map("corridor")
    for suffix in (".json", ".geojson", ".wkt"):
        p = save_map(MAPS["plain"], tmp_path / f"x{suffix}")
        assert load_map(str(p)) == MAPS["plain"]
        assert load_map(p) == MAPS["plain"]
    upper = tmp_path / "UP.JSON"
    upper.write_text(json.dumps({"boundary": ROOM}))
    assert load_map(upper) == Map(ROOM)


def test_load_map_unknown_name_lists_choices():
    with pytest.raises(UnknownNameError, match=r"'no_such_world'.*corridor") as info:
        load_map("no_such_world")
    assert isinstance(info.value, KeyError) and isinstance(info.value, ValueError)


def test_load_map_missing_file_directory_or_unreadable(tmp_path):
    with pytest.raises(InvalidMapError, match=r"^/nonexistent/dir/world\.json: no such map file$"):
        load_map("/nonexistent/dir/world.json")
    folder = tmp_path / "maps.json"
    folder.mkdir()
    with pytest.raises(InvalidMapError, match=r"maps\.json: is a directory, expected a map file"):
        load_map(folder)
    with pytest.raises(InvalidMapError, match="is a directory"):
        load_map(str(folder))
    binary = tmp_path / "binary.json"
    binary.write_bytes(b"\xff\xfe\x00garbage")
    with pytest.raises(InvalidMapError, match=r"binary\.json: not UTF-8 text"):
        load_map(binary)


@pytest.mark.parametrize("name", ["", " "])
def test_load_map_of_an_empty_name_lists_what_a_map_can_be(name):
    # '' was the working directory: ": is a directory, expected a map file or a built-in name"
    with pytest.raises(UnknownNameError, match=rf"^unknown map {name!r}: expected a built-in"):
        load_map(name)


def test_load_map_unsupported_suffix(tmp_path):
    p = tmp_path / "world.txt"
    p.write_text("{}")
    with pytest.raises(InvalidMapError, match=r"world\.txt.*suffix '\.txt'"):
        load_map(p)


def test_merge_keyword_rejected_for_builtins():
    with pytest.raises(InvalidConfigError, match="merge"):
        load_map("corridor", merge=True)


def test_save_map_rejects_bad_suffix_and_metadata(tmp_path):
    with pytest.raises(InvalidConfigError, match=r"\.svg"):
        save_map(MAPS["plain"], tmp_path / "w.svg")
    with pytest.raises(InvalidConfigError, match="metadata"):
        save_map(MAPS["plain"], tmp_path / "w.json", metadata={"f": object()})
    with pytest.raises(InvalidConfigError, match="metadata"):
        save_map(MAPS["plain"], tmp_path / "w.json", metadata={"x": float("nan")})


# ---------------------------------------------------------------------- malformed files
GOOD = {"boundary": ROOM}
SQ = [closed(box(1, 1, 2, 2))]
MALFORMED = [
    ("json", "{not json", r"not valid JSON"),
    ("json", "", r"not valid JSON"),
    ("json", "[]", r"expected a JSON object"),
    ("json", json.dumps({"obstacles": []}), r'missing "boundary"'),
    ("json", json.dumps({**GOOD, "obstacle": []}), r"unknown keys \['obstacle'\]"),
    ("json", json.dumps({"boundary": [[0, 0], [1, "a"], [0, 1]]}), r"boundary: vertex 1"),
    ("json", json.dumps({"boundary": [[0, 0, 0], [1, 0, 0], [0, 1, 0]]}), r"vertex 0.*planar"),
    ("json", json.dumps({"boundary": [[0, 0], [True, 0], [0, 1]]}), r"vertex 1"),
    ("json", json.dumps({"boundary": []}), r"boundary: expected a non-empty list"),
    ("json", json.dumps({"boundary": "square"}), r"boundary: expected a non-empty list"),
    ("json", json.dumps({**GOOD, "obstacles": {"a": 1}}), r'"obstacles" must be a list'),
    ("json", json.dumps({**GOOD, "obstacles": [[[1, 1], [2, 1]]]}), r"obstacle 0: .*at least 3"),
    ("json", json.dumps({**GOOD, "merge": "yes"}), r'"merge" must be true or false'),
    ("json", json.dumps({**GOOD, "name": 3}), r'"name" must be a string'),
    ("json", json.dumps({**GOOD, "metadata": [1]}), r'"metadata" must be a JSON object'),
    (
        "json",
        json.dumps({**GOOD, "obstacles": [box(1, 1, 3, 3), box(2, 2, 4, 4)]}),
        r"obstacle 0 overlaps obstacle 1",
    ),
    (
        "json",
        '{"boundary": [[0, 0], [NaN, 0], [0, 1]]}',
        r"boundary = .*: expected finite values, got nan",
    ),
    (
        "json",
        '{"boundary": [[0, 0], [1' + "0" * 400 + ", 0], [0, 1]]}",  # no float holds it
        r"boundary: vertex 1 has the coordinate 1000.* \(401 digits\), expected finite",
    ),
    (
        "json",
        json.dumps({"boundary": [[0, 0], [10, 10], [10, 0], [0, 10]]}),
        r"boundary: .*not simple",
    ),
    ("geojson", json.dumps({"type": "Point", "coordinates": [0, 0]}), r"'Point' is not a Polygon"),
    ("geojson", json.dumps([1, 2]), r"expected a GeoJSON object"),
    ("geojson", json.dumps(feature([[list(p) for p in ROOM]])), r"ring 0: not closed"),
    ("geojson", json.dumps({"type": "FeatureCollection", "features": []}), r"no Polygon"),
    ("geojson", json.dumps({"type": "FeatureCollection"}), r'without a "features" list'),
    (
        "geojson",
        json.dumps(
            {
                "type": "FeatureCollection",
                "features": [feature([closed(ROOM)], role="boundary")] * 2,
            }
        ),
        r'2 polygons have "role": "boundary"',
    ),
    (
        "geojson",
        json.dumps(
            {"type": "FeatureCollection", "features": [feature([closed(ROOM)], role="wall")]}
        ),
        r'"role" must be',
    ),
    (
        "geojson",
        json.dumps(
            {
                "type": "FeatureCollection",
                "features": [
                    feature([closed(ROOM)]),
                    feature([closed(box(1, 1, 4, 4)), closed(box(2, 2, 3, 3))]),
                ],
            }
        ),
        r"feature 1: an obstacle with holes",
    ),
    (
        "geojson",
        json.dumps({"type": "Feature", "properties": {}, "geometry": None}),
        r"feature 0: expected a GeoJSON geometry",
    ),
    (
        "geojson",
        json.dumps(feature([closed(ROOM), *SQ], merge=1)),
        r'"merge" must be true or false',
    ),
    # rings of fewer than 4 positions: shapely's bare ValueError 'A linearring requires at
    # least 4 coordinates.' (found by helper-123's file probe)
    (
        "geojson",
        json.dumps(feature([[[1, 2]], *SQ])),
        r"feature 0 ring 0: 1 positions; a linear ring needs at least 4",
    ),
    (
        "geojson",
        json.dumps(feature([closed(ROOM), [[1, 1], [2, 2], [1, 1]]])),
        r"feature 0 ring 1: 3 positions; a linear ring needs at least 4",
    ),
    ("wkt", "POLYGN ((0 0, 1 0, 1 1, 0 0))", r"not valid WKT"),
    ("wkt", "", r"not valid WKT"),
    ("wkt", "POLYGON EMPTY", r"empty geometry"),
    ("wkt", "LINESTRING (0 0, 1 1)", r"member 0 is a LineString"),
    ("wkt", "POLYGON Z ((0 0 1, 1 0 1, 1 1 1, 0 0 1))", r"3D"),
    ("wkt", "POLYGON ((0 0, 10 10, 10 0, 0 10, 0 0))", r"boundary: .*not simple"),
    ("wkt", "POLYGON ((0 0, 10 0, 10 10, 0 10))", r"not valid WKT"),
    # a one-point ring: GEOS's message ended in a newline, which the refusal kept (found by
    # helper-123's file probe)
    (
        "wkt",
        "POLYGON ((0 0, 10 0, 10 10, 0 10, 0 0), (6 6))",
        r"not valid WKT \(IllegalArgumentException: point array must contain 0 or >1 elements\)$",
    ),
    (
        "wkt",
        "MULTIPOLYGON (((0 0, 10 0, 10 10, 0 10, 0 0)), "
        "((1 1, 4 1, 4 4, 1 4, 1 1), (2 2, 3 2, 3 3, 2 2)))",
        r"polygon 1: an obstacle with holes",
    ),
    (
        "wkt",
        "POLYGON ((0 0, 10 0, 10 10, 0 10, 0 0), (9 1, 11 1, 11 2, 9 2, 9 1))",
        r"not inside the boundary",
    ),
]


@pytest.mark.parametrize(
    ("fmt", "text", "pattern"), MALFORMED, ids=[f"{f}-{i}" for i, (f, _, _) in enumerate(MALFORMED)]
)
def test_malformed_files_name_the_file_and_the_problem(tmp_path, fmt, text, pattern):
    p = tmp_path / f"broken_{fmt}.{fmt}"
    p.write_text(text, encoding="utf-8")
    with pytest.raises(InvalidMapError, match=pattern) as info:
        load_map(p)
    assert str(info.value).startswith(str(p) + ": ")
    assert "\n" not in str(info.value)  # one line


def test_non_utf8_file(tmp_path):
    p = tmp_path / "latin1.json"
    p.write_bytes(b'{"name": "caf\xe9"}')
    with pytest.raises(InvalidMapError, match=r"latin1\.json: not UTF-8"):
        load_map(p)


@pytest.mark.parametrize("suffix", ["json", "geojson", "wkt"])
def test_a_byte_order_mark_is_read_past(tmp_path, suffix):
    """Windows editors (Notepad's "UTF-8 with BOM", PowerShell 5's ``Out-File``) start a
    UTF-8 file with U+FEFF: the JSON reader refused it ("Unexpected UTF-8 BOM") and the
    WKT reader called '\ufeffPOLYGON' an unknown type."""
    m = MAPS["plain"]
    p = save_map(m, tmp_path / f"bom.{suffix}")
    p.write_bytes(b"\xef\xbb\xbf" + p.read_bytes())
    assert load_map(p) == m


def test_shapely_reads_our_wkt_and_geojson_files_identically(tmp_path):
    """Cross-check with an independent reader: both files describe one polygon."""
    m = MAPS["awkward_floats"]
    wkt = shapely.from_wkt(save_map(m, tmp_path / "a.wkt").read_text())
    gj = shape(json.loads(save_map(m, tmp_path / "a.geojson").read_text())["geometry"])
    assert isinstance(wkt, Polygon) and isinstance(gj, Polygon) and wkt.equals(gj)
    coords = lambda g: np.unique(shapely.get_coordinates(g), axis=0)
    np.testing.assert_array_equal(coords(wkt), coords(gj))
    np.testing.assert_array_equal(coords(wkt), np.unique(m.vertices, axis=0))
    assert Path(tmp_path / "a.wkt").read_text().startswith("POLYGON ((")


def test_touching_polygons_in_a_file_name_the_file_s_own_remedy(tmp_path):
    """Map's "build the map with merge=True" is a keyword a file's reader cannot pass (and
    the surveil command has no option for it): each format names what its author can do."""
    box = [[2, 2], [4, 2], [4, 4], [2, 4]]
    other = [[4, 4], [6, 4], [6, 6], [4, 6]]
    room = [[0, 0], [10, 0], [10, 10], [0, 10]]
    doc = {"boundary": room, "obstacles": [box, other]}
    (tmp_path / "t.json").write_text(json.dumps(doc))
    with pytest.raises(InvalidMapError, match=r'add "merge": true to the map\'s JSON object'):
        load_map(str(tmp_path / "t.json"))
    closed = [[*r, r[0]] for r in (room, box[::-1], other[::-1])]
    gj = {"type": "Polygon", "coordinates": closed}
    (tmp_path / "t.geojson").write_text(json.dumps(gj))
    with pytest.raises(InvalidMapError, match=r'add "merge": true to the properties'):
        load_map(str(tmp_path / "t.geojson"))
    rings = ", ".join("(" + ", ".join(f"{x} {y}" for x, y in r) + ")" for r in closed)
    (tmp_path / "t.wkt").write_text(f"POLYGON ({rings})\n")
    with pytest.raises(InvalidMapError, match=r'write the map as \.json with "merge": true'):
        load_map(str(tmp_path / "t.wkt"))
    for suffix in ("json", "geojson", "wkt"):
        with pytest.raises(InvalidMapError) as err:
            load_map(str(tmp_path / f"t.{suffix}"))
        assert "build the map with merge=True" not in str(err.value)
        assert read_map(tmp_path / f"t.{suffix}", merge=True).map.n_vertices == 12


# ------------------------------------------------------------------ transformed map names
@pytest.mark.parametrize(
    ("name", "base", "scale", "rot", "offset"),
    [
        ("corner~rot0.37", "corner", 1.0, 0.37, (0.0, 0.0)),
        ("maze~x10rot1.1off(3,-2.5)", "maze", 10.0, 1.1, (3.0, -2.5)),
        ("office~x1e-3", "office", 1e-3, 0.0, (0.0, 0.0)),
        ("random:rectangles:3~off(1.5,-2)", "random:rectangles:3", 1.0, 0.0, (1.5, -2.0)),
    ],
)
def test_a_transformed_name_is_its_map_under_the_similarity(name, base, scale, rot, offset):
    """``MAP~[xS][rotR][off(X,Y)]``: every vertex is scale * R(rot) @ v + offset of the
    untransformed map's (the benchmarks' variant worlds by name)."""
    m, ref = load_map(name), load_map(base)
    c, s = np.cos(rot), np.sin(rot)
    for got, want in zip(m.rings, ref.rings, strict=True):
        x, y = np.asarray(want, dtype=float).T
        expected = np.stack([scale * (c * x - s * y), scale * (s * x + c * y)], axis=1) + offset
        got = np.asarray(got, dtype=float)
        first = int(np.argmin(np.linalg.norm(got - expected[0], axis=1)))  # rings start anywhere
        np.testing.assert_allclose(
            np.roll(got, -first, axis=0), expected, rtol=1e-12, atol=1e-12 * max(1.0, scale)
        )
    assert m.name == name
    # a similarity keeps areas up to scale^2 (shapely: independent of our vertices' maths)
    area = Polygon(m.boundary).area
    assert area == pytest.approx(scale**2 * Polygon(ref.boundary).area, rel=1e-9)


def test_a_transformed_built_in_recommends_its_lengths_and_speeds_scaled():
    from envs.surveillance.config import map_recommendations

    base = map_recommendations("corner")
    body = {"body_radius": 0.1}  # the built-ins' bodies, scaled too: the same game
    assert map_recommendations("corner~x10rot1.1") == {
        k: 10 * v for k, v in {**base, **body}.items()
    }
    assert map_recommendations("corner~rot0.3off(4,5)") == {**base, **body}
    assert map_recommendations("random:3~x2") == map_recommendations("random:3")


def test_a_twice_transformed_built_in_recommends_its_lengths_scaled_twice():
    """``corner~x2~rot1`` is the corner under two similarities (load_map reads the base
    ``corner~x2`` first); its recommendation scales as the map does, not the defaults."""
    from envs.surveillance.config import map_recommendations

    base = map_recommendations("corner")
    assert Polygon(load_map("corner~x2~x3rot1").boundary).area == pytest.approx(
        36 * Polygon(load_map("corner").boundary).area, rel=1e-9
    )
    assert map_recommendations("corner~x2~x3rot1") == {
        k: 6 * v for k, v in {**base, "body_radius": 0.1}.items()
    }
    assert map_recommendations("corner~x2~rot1") == map_recommendations("corner~x2")


@pytest.mark.parametrize(
    ("name", "error", "pattern"),
    [
        ("corner~x0", InvalidConfigError, r"'corner~x0' transforms 'corner' by scale 0\.0"),
        ("corner~x1e400", InvalidConfigError, "expected a finite scale > 0"),
        ("nosuch~rot1", UnknownNameError, r"map 'nosuch~rot1': unknown map 'nosuch'"),
        ("corner~sideways", UnknownNameError, r"'~\[xS\]\[rotR\]\[off\(X,Y\)\]'"),
        (
            "corner~x1e-300",
            InvalidMapError,
            r"map 'corner~x1e-300': 'corner' under .*size .* is 1.98e-299; expected one in",
        ),
        # a random map's malformed suffix (rot before x) names the suffix grammar too
        ("random:star:3~rot0.3x0.5", InvalidConfigError, r"'~\[xS\]\[rotR\]\[off\(X,Y\)\]'"),
        ("random:3~", InvalidConfigError, r"'random:3~'.*'~\[xS\]\[rotR\]"),
    ],
)
def test_a_bad_transformed_name_says_what_a_name_can_be(name, error, pattern):
    with pytest.raises(error, match=pattern):
        load_map(name)


def test_a_file_whose_path_holds_a_tilde_is_read_as_the_file(tmp_path):
    d = tmp_path / "maps~x2"
    d.mkdir()
    path = save_map(MAPS["plain"], d / "room.json")
    assert load_map(str(path)).to_dict() == MAPS["plain"].to_dict()
