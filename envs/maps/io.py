"""Map files: our JSON schema, GeoJSON and WKT (set-up code, not the hot path).

Formats
-------
**JSON** (``.json``), our schema::

    {"name": "corridor", "boundary": [[x, y], ...], "obstacles": [[[x, y], ...], ...],
     "merge": false, "description": "...", "metadata": {"l_min": 2.0, ...}}

``boundary`` is required; ``obstacles`` (default none), ``merge`` (default false),
``name`` (default: the file stem), ``description`` and ``metadata`` (any JSON object;
its ``l_min``, ``l_max``, ``v_pursuer``, ``v_evader`` and ``body_radius`` are the map's
recommended parameters, :func:`file_parameters`) are optional. Unknown keys are
rejected, so a misspelt key is an error instead of a silently empty map. A ``.json``
file holding a GeoJSON object (it has a ``"type"`` member) is read as GeoJSON.

**GeoJSON** (``.geojson``, RFC 7946): a ``Feature``, a ``FeatureCollection`` or a bare
geometry, made of ``Polygon`` and ``MultiPolygon`` geometries.

* One polygon: its exterior ring is the boundary and its holes are the obstacles.
* Several: the polygon whose feature has ``"role": "boundary"`` in its properties is the
  boundary, or else the one with the largest exterior among those not marked
  ``"role": "obstacle"``; the boundary's holes and every other polygon are obstacles.
* ``name``, ``description``, ``metadata`` and ``merge`` are read from the
  collection's top-level ``"properties"`` member, then from the boundary's feature. A
  recommended parameter (``l_min``, ...) given there beside them, not in ``metadata``,
  is refused: it would not be read.

**WKT** (``.wkt``): a ``POLYGON`` with holes (boundary and obstacles), or a
``MULTIPOLYGON`` / ``GEOMETRYCOLLECTION`` of polygons whose first member is the boundary
(its holes are obstacles too) and whose other members are obstacles. WKT has no room for
a name or a merge flag: the name is the file stem and ``merge`` is a keyword argument.

Writing: JSON and GeoJSON keep the map's own boundary and obstacles and its merge flag,
so a merged map is saved as its parts. WKT saves the walls (the free region after
merging) as one ``POLYGON`` with holes, which loads back as the same map without a flag.
Coordinates are written at full precision (shortest round-trip ``repr``), so every
format round-trips exactly.

Every problem with a file raises :class:`~envs.errors.InvalidMapError` naming the file
and what is wrong with it.
"""

from __future__ import annotations

import json
import math
import os
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import shapely
from shapely.errors import ShapelyError
from shapely.geometry import Polygon

from envs import validation
from envs.errors import InvalidConfigError, InvalidMapError, UnknownNameError
from envs.files import written_whole
from envs.maps.map import Map

__all__ = [
    "FORMATS",
    "RANDOM_PREFIX",
    "MapDocument",
    "file_parameters",
    "load_map",
    "map_from_dict",
    "map_from_geojson",
    "map_from_wkt",
    "map_to_dict",
    "map_to_geojson",
    "map_to_wkt",
    "read_map",
    "recommended_parameters",
    "save_map",
]

FORMATS: dict[str, str] = {".json": "json", ".geojson": "geojson", ".wkt": "wkt"}
"""File suffix -> format name, for :func:`load_map` and :func:`save_map`."""

_SCHEMA_KEYS = ("name", "description", "boundary", "obstacles", "merge", "metadata")


@dataclass(frozen=True)
class MapDocument:
    """A map as read from a file, with the file's description and metadata.

    Attributes:
        map: the validated map.
        description: a one-line description (empty if the file has none).
        metadata: free-form metadata, e.g. recommended parameters ``l_min``, ``l_max``,
            ``v_pursuer``, ``v_evader``.
    """

    map: Map
    description: str = ""
    metadata: Mapping[str, Any] = field(default_factory=dict)


# ---------------------------------------------------------------------- helpers
def _fail(source: str, problem: str) -> InvalidMapError:
    return InvalidMapError(f"{source}: {problem}")


def _is_number(x: object) -> bool:
    return validation.is_real(x)


def _ring(obj: object, source: str, what: str) -> list[list[float]]:
    """Check that ``obj`` is a list of ``[x, y]`` number pairs and return it."""
    if not isinstance(obj, list) or not obj:
        raise _fail(source, f"{what}: expected a non-empty list of [x, y] pairs, got {obj!r:.80}")
    for k, p in enumerate(obj):
        if not isinstance(p, list) or len(p) != 2 or not all(_is_number(c) for c in p):
            dims = f" ({len(p)} coordinates; a map is planar)" if isinstance(p, list) else ""
            raise _fail(source, f"{what}: vertex {k} is {p!r:.60}, expected [x, y] numbers{dims}")
        for c in p:
            try:
                float(c)
            except OverflowError:  # a JSON integer of 400 digits: no float holds it
                raise _fail(
                    source,
                    f"{what}: vertex {k} has the coordinate {str(c)[:20]}... ({len(str(c))} "
                    "digits), expected finite numbers (a float's range ends near 1.8e308)",
                ) from None
    return obj


_MERGE_REMEDY = "build the map with merge=True"
"""How :class:`Map` names its remedy for touching polygons: a keyword a file cannot pass."""


def _build(
    source: str, boundary: Any, obstacles: list, *, name: str, merge: bool, remedy: str
) -> Map:
    """Build the map, re-raising validation errors with the file's name in front, and
    Map's ``merge=True`` remedy for touching polygons told as the file's reader can act
    on it (``remedy``): a ``"merge": true`` member in JSON and GeoJSON; for WKT, which
    has no room for it, ``read_map(..., merge=True)`` or a JSON copy (``surveil`` has no
    flag for it)."""
    try:
        return Map(boundary, obstacles, name=name, merge=merge)
    except InvalidMapError as exc:
        raise _fail(source, str(exc).replace(_MERGE_REMEDY, remedy)) from exc


def _check_common(d: Mapping[str, Any], source: str) -> tuple[str | None, str, dict, bool | None]:
    """Validate the optional ``name``, ``description``, ``metadata`` and ``merge`` members."""
    name = d.get("name")
    if name is not None and not isinstance(name, str):
        raise _fail(source, f'"name" must be a string, got {name!r}')
    description = d.get("description", "")
    if description is None:
        description = ""
    if not isinstance(description, str):
        raise _fail(source, f'"description" must be a string, got {description!r}')
    metadata = d.get("metadata", {})
    if metadata is None:
        metadata = {}
    if not isinstance(metadata, dict):
        raise _fail(source, f'"metadata" must be a JSON object, got {metadata!r:.80}')
    merge = d.get("merge")
    if merge is not None and not isinstance(merge, bool):
        raise _fail(source, f'"merge" must be true or false, got {merge!r}')
    return name, description, metadata, merge


def _closed(ring: np.ndarray, ccw: bool) -> list[list[float]]:
    """The ring closed (first vertex repeated) and oriented CCW (or CW)."""
    r = np.asarray(ring, dtype=float)
    x, y = r[:, 0], r[:, 1]
    area = float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))
    if (area > 0) != ccw:
        r = r[::-1]
    return [[float(a), float(b)] for a, b in (*r, r[0])]


def _stem(source: str) -> str:
    return Path(source).stem if source and not source.startswith("<") else "custom"


# ---------------------------------------------------------------------- our JSON schema
def map_from_dict(d: object, *, source: str = "<dict>", merge: bool | None = None) -> MapDocument:
    """Read our JSON schema (see the module docstring).

    Args:
        d: the decoded JSON object.
        source: where it came from, for error messages and the default name.
        merge: override the document's ``merge`` flag (``None`` keeps it).

    Raises:
        InvalidMapError: naming ``source`` and the problem.
    """
    if not isinstance(d, dict):
        raise _fail(source, f"expected a JSON object with a 'boundary', got {type(d).__name__}")
    unknown = sorted(set(d) - set(_SCHEMA_KEYS))
    if unknown:
        raise _fail(source, f"unknown keys {unknown}; expected some of {list(_SCHEMA_KEYS)}")
    if "boundary" not in d:
        raise _fail(source, 'missing "boundary" (a list of [x, y] vertices)')
    name, description, metadata, file_merge = _check_common(d, source)
    boundary = _ring(d["boundary"], source, "boundary")
    obstacles = d.get("obstacles", [])
    if obstacles is None:
        obstacles = []
    if not isinstance(obstacles, list):
        raise _fail(source, f'"obstacles" must be a list of polygons, got {obstacles!r:.80}')
    obstacles = [_ring(o, source, f"obstacle {i}") for i, o in enumerate(obstacles)]
    use_merge = bool(file_merge) if merge is None else merge
    m = _build(
        source,
        boundary,
        obstacles,
        name=name or _stem(source),
        merge=use_merge,
        remedy='add "merge": true to the map\'s JSON object (or pass merge=True)',
    )
    return MapDocument(m, description, metadata)


def map_to_dict(
    m: Map, *, description: str = "", metadata: Mapping[str, Any] | None = None
) -> dict[str, Any]:
    """Our JSON schema for ``m`` (its boundary, obstacles and merge flag)."""
    d: dict[str, Any] = {"name": m.name}
    if description:
        d["description"] = description
    d["merge"] = m.merged
    if metadata:
        d["metadata"] = dict(metadata)
    d["boundary"] = [[float(x), float(y)] for x, y in m.boundary]
    d["obstacles"] = [[[float(x), float(y)] for x, y in o] for o in m.obstacles]
    return d


def _dump_json(d: Mapping[str, Any]) -> str:
    """JSON with one ring per line: readable, diffable, and exact (floats use repr)."""
    lines = []
    for key, value in d.items():
        if key == "obstacles" and value:
            rings = ",\n    ".join(json.dumps(o) for o in value)
            lines.append(f'  "obstacles": [\n    {rings}\n  ]')
        else:
            lines.append(f"  {json.dumps(key)}: {json.dumps(value, allow_nan=False)}")
    return "{\n" + ",\n".join(lines) + "\n}\n"


# ---------------------------------------------------------------------- GeoJSON
def _geojson_polygons(
    geom: object, props: Mapping[str, Any], source: str, what: str
) -> list[tuple[list, Mapping[str, Any], str]]:
    """(rings, properties, label) for every polygon of a GeoJSON geometry."""
    if not isinstance(geom, dict) or "type" not in geom:
        raise _fail(source, f"{what}: expected a GeoJSON geometry object, got {geom!r:.80}")
    kind = geom["type"]
    if kind == "GeometryCollection":
        parts = geom.get("geometries")
        if not isinstance(parts, list):
            raise _fail(source, f'{what}: GeometryCollection without a "geometries" list')
        out = []
        for k, g in enumerate(parts):
            out += _geojson_polygons(g, props, source, f"{what} geometry {k}")
        return out
    coords = geom.get("coordinates")
    if kind == "Polygon":
        polys, labels = [coords], [what]
    elif kind == "MultiPolygon":
        if not isinstance(coords, list):
            raise _fail(
                source, f"{what}: MultiPolygon coordinates must be a list, got {coords!r:.60}"
            )
        polys, labels = coords, [f"{what} polygon {k}" for k in range(len(coords))]
    else:
        raise _fail(source, f"{what}: geometry type {kind!r} is not a Polygon or MultiPolygon")
    out = []
    for rings, label in zip(polys, labels, strict=True):
        if not isinstance(rings, list) or not rings:
            raise _fail(source, f"{label}: expected a list of linear rings, got {rings!r:.60}")
        checked = [_ring(r, source, f"{label} ring {j}") for j, r in enumerate(rings)]
        for j, r in enumerate(checked):
            if len(r) < 4:  # RFC 7946 3.1.6; shapely raised a bare ValueError on fewer
                raise _fail(
                    source,
                    f"{label} ring {j}: {len(r)} positions; a linear ring needs at least 4 "
                    "(3 vertices and the first repeated)",
                )
            if r[0] != r[-1]:
                raise _fail(
                    source, f"{label} ring {j}: not closed (first vertex {r[0]} != last {r[-1]})"
                )
        out.append((checked, props, label))
    return out


def map_from_geojson(
    obj: object, *, source: str = "<geojson>", merge: bool | None = None
) -> MapDocument:
    """Read a GeoJSON ``Feature``, ``FeatureCollection`` or geometry (see the module docstring).

    Args:
        obj: the decoded GeoJSON object.
        source: where it came from, for error messages and the default name.
        merge: override the document's ``merge`` property (``None`` keeps it).

    Raises:
        InvalidMapError: naming ``source`` and the problem.
    """
    if not isinstance(obj, dict) or "type" not in obj:
        raise _fail(source, "expected a GeoJSON object (with a 'type' member)")
    top = obj.get("properties") if obj["type"] == "FeatureCollection" else None
    if top is not None and not isinstance(top, dict):
        raise _fail(source, f'top-level "properties" must be an object, got {top!r:.60}')
    if obj["type"] == "FeatureCollection":
        features = obj.get("features")
        if not isinstance(features, list):
            raise _fail(source, 'FeatureCollection without a "features" list')
    elif obj["type"] == "Feature":
        features = [obj]
    else:
        features = [{"type": "Feature", "geometry": obj, "properties": None}]
    polygons = []
    for k, f in enumerate(features):
        if not isinstance(f, dict) or f.get("type") != "Feature":
            raise _fail(source, f"feature {k}: expected a GeoJSON Feature, got {f!r:.60}")
        props = f.get("properties") or {}
        if not isinstance(props, dict):
            raise _fail(source, f'feature {k}: "properties" must be an object, got {props!r:.60}')
        role = props.get("role")
        if role not in (None, "boundary", "obstacle"):
            raise _fail(
                source, f'feature {k}: "role" must be "boundary" or "obstacle", got {role!r}'
            )
        polygons += _geojson_polygons(f.get("geometry"), props, source, f"feature {k}")
    if not polygons:
        raise _fail(source, "no Polygon found (a map needs at least its boundary)")
    marked = [i for i, (_, props, _) in enumerate(polygons) if props.get("role") == "boundary"]
    if len(marked) > 1:
        labels = [polygons[i][2] for i in marked]
        raise _fail(
            source, f'{len(marked)} polygons have "role": "boundary" ({labels}); expected one'
        )
    if marked:
        b = marked[0]
    else:
        candidates = [i for i, (_, props, _) in enumerate(polygons) if props.get("role") is None]
        if not candidates:
            raise _fail(source, 'every polygon has "role": "obstacle"; which one is the boundary?')
        b = max(candidates, key=lambda i: Polygon(polygons[i][0][0]).area)
    b_rings, b_props, _ = polygons[b]
    obstacles = list(b_rings[1:])
    for i, (rings, _, label) in enumerate(polygons):
        if i == b:
            continue
        if len(rings) > 1:
            raise _fail(
                source,
                f"{label}: an obstacle with holes would enclose free space cut off from the rest",
            )
        obstacles.append(rings[0])
    meta = {**b_props, **(top or {})}
    flat = [k for k in FILE_RECOMMENDATIONS if k in meta]
    if flat:  # GeoJSON properties are free-form: these would be ignored without a word
        where = {k: meta[k] for k in flat}
        raise _fail(
            source,
            f"properties {where} are not read: a map's recommended parameters go in its "
            f'"metadata" property (e.g. "properties": {{"metadata": {json.dumps(where)}}})',
        )
    name, description, metadata, file_merge = _check_common(meta, source)
    use_merge = bool(file_merge) if merge is None else merge
    m = _build(
        source,
        b_rings[0],
        obstacles,
        name=name or _stem(source),
        merge=use_merge,
        remedy='add "merge": true to the properties of the collection or the boundary\'s '
        "feature (or pass merge=True)",
    )
    return MapDocument(m, description, metadata)


def map_to_geojson(
    m: Map, *, description: str = "", metadata: Mapping[str, Any] | None = None
) -> dict[str, Any]:
    """GeoJSON for ``m``: one Polygon with holes, or a FeatureCollection if merged.

    A merged map's obstacles may overlap or touch, which one polygon cannot hold, so it is
    written as a boundary feature (``"role": "boundary"``, carrying ``"merge": true``)
    and one feature per obstacle. Rings follow RFC 7946 (exterior CCW, holes CW).
    """
    props: dict[str, Any] = {"name": m.name, "merge": m.merged}
    if description:
        props["description"] = description
    if metadata:
        props["metadata"] = dict(metadata)
    outer = _closed(m.boundary, ccw=True)
    if not m.merged:
        holes = [_closed(o, ccw=False) for o in m.obstacles]
        return {
            "type": "Feature",
            "properties": props,
            "geometry": {"type": "Polygon", "coordinates": [outer, *holes]},
        }
    features = [
        {
            "type": "Feature",
            "properties": {"role": "boundary", **props},
            "geometry": {"type": "Polygon", "coordinates": [outer]},
        }
    ]
    features += [
        {
            "type": "Feature",
            "properties": {"role": "obstacle"},
            "geometry": {"type": "Polygon", "coordinates": [_closed(o, ccw=True)]},
        }
        for o in m.obstacles
    ]
    return {"type": "FeatureCollection", "features": features}


# ---------------------------------------------------------------------- WKT
def map_from_wkt(
    text: str, *, source: str = "<wkt>", name: str | None = None, merge: bool = False
) -> Map:
    """Read a WKT ``POLYGON``, ``MULTIPOLYGON`` or ``GEOMETRYCOLLECTION`` (first = boundary).

    Args:
        text: the WKT string.
        source: where it came from, for error messages and the default name.
        name: the map's name (default: the file stem).
        merge: build the map with ``merge=True``.

    Raises:
        InvalidMapError: naming ``source`` and the problem.
    """
    if not isinstance(text, str):
        raise _fail(source, f"expected WKT text, got {type(text).__name__} {text!r}")
    try:
        with np.errstate(invalid="ignore"):  # NaN coordinates: refused below, in one line
            geom = shapely.from_wkt(text.strip())
    except (ShapelyError, TypeError, ValueError) as exc:
        # one line: some GEOS messages end in a newline ("point array must contain 0 or
        # >1 elements\n" for a one-point ring)
        raise _fail(source, f"not valid WKT ({' '.join(str(exc).split())})") from exc
    if geom is None or geom.is_empty:
        raise _fail(source, "empty geometry (a map needs at least its boundary)")
    if geom.has_z:
        raise _fail(source, "3D coordinates; a map is planar (x, y)")
    parts = [geom] if geom.geom_type == "Polygon" else list(getattr(geom, "geoms", [geom]))
    polys: list[Polygon] = []
    for k, g in enumerate(parts):
        if g.geom_type == "Polygon":
            polys.append(g)
        elif g.geom_type == "MultiPolygon":
            polys.extend(g.geoms)
        else:
            raise _fail(source, f"member {k} is a {g.geom_type}; expected polygons only")
    boundary = polys[0]
    obstacles = [np.asarray(r.coords) for r in boundary.interiors]
    for k, p in enumerate(polys[1:], start=1):
        if len(p.interiors):
            raise _fail(
                source,
                f"polygon {k}: an obstacle with holes would enclose free space cut off "
                "from the rest",
            )
        obstacles.append(np.asarray(p.exterior.coords))
    return _build(
        source,
        np.asarray(boundary.exterior.coords),
        obstacles,
        name=name or _stem(source),
        merge=merge,
        remedy="pass merge=True (WKT has no room for the flag; the surveil command has no "
        'option for it: write the map as .json with "merge": true)',
    )


def _wkt_ring(ring: np.ndarray) -> str:
    pts = [*ring, ring[0]]
    return "(" + ", ".join(f"{float(x)!r} {float(y)!r}" for x, y in pts) + ")"


def map_to_wkt(m: Map) -> str:
    """``m``'s walls as one ``POLYGON`` with holes, coordinates at full precision.

    Raises:
        InvalidMapError: if the walls of a merged map touch themselves (obstacles that
            met at a single point), which reads back only with ``merge=True``; save such a
            map as JSON or GeoJSON, which keep the merge flag.
    """
    if m.merged:
        try:
            Map(m.rings[0], m.rings[1:])
        except InvalidMapError as exc:
            raise InvalidMapError(
                f"map {m.name!r}: its merged walls touch themselves ({exc}); WKT cannot "
                "carry the merge flag, save it as .json or .geojson"
            ) from exc
    return "POLYGON (" + ", ".join(_wkt_ring(r) for r in m.rings) + ")\n"


# ---------------------------------------------------------------------- files
def _format_of(path: Path, *, for_writing: bool) -> str:
    fmt = FORMATS.get(path.suffix.lower())
    if fmt is None:
        msg = (
            f"{path}: unsupported map file suffix {path.suffix!r}; "
            f"expected one of {sorted(FORMATS)}"
        )
        raise InvalidConfigError(msg) if for_writing else InvalidMapError(msg)
    return fmt


def read_map(path: str | os.PathLike[str], *, merge: bool | None = None) -> MapDocument:
    """Read a map file by suffix (``.json``, ``.geojson``, ``.wkt``).

    Args:
        path: the file.
        merge: override the file's merge flag (``None``: the file's, or False for WKT).

    Returns:
        The map with the file's description and metadata.

    Raises:
        InvalidMapError: naming the file and the problem (also a missing file, a
            directory, an unreadable file or one that is not UTF-8 text).
    """
    p = Path(path)
    fmt = _format_of(p, for_writing=False)
    source = str(p)
    try:  # "utf-8-sig": past a byte order mark (Windows editors write one)
        text = p.read_text(encoding="utf-8-sig")
    except UnicodeDecodeError as exc:
        raise _fail(source, f"not UTF-8 text ({exc})") from exc
    except FileNotFoundError:
        raise _fail(source, "no such map file") from None
    except IsADirectoryError:
        raise _fail(source, "is a directory, expected a map file") from None
    except OSError as exc:
        raise _fail(source, f"cannot read the map file ({exc.strerror or exc})") from None
    if fmt == "wkt":
        return MapDocument(map_from_wkt(text, source=source, merge=bool(merge)))
    try:
        obj = json.loads(text, object_pairs_hook=validation.json_pairs_once)
    except validation.DuplicateKeyError as dup:  # json kept the last: half a map, silently
        raise _fail(
            source,
            f"key {dup.key!r} given twice in one object (JSON keeps only the last); "
            "expected each key once",
        ) from None
    except json.JSONDecodeError as exc:
        raise _fail(source, f"not valid JSON ({exc})") from exc
    except RecursionError:  # the decoder recurses once per nested [ or {
        raise _fail(
            source, "JSON nested too deeply to read (no map nests beyond a few levels)"
        ) from None
    if fmt == "geojson" or (isinstance(obj, dict) and "type" in obj and "boundary" not in obj):
        return map_from_geojson(obj, source=source, merge=merge)
    return map_from_dict(obj, source=source, merge=merge)


RANDOM_PREFIX = "random:"
"""Map names ``random:SEED`` and ``random:KIND:SEED`` are seeded random maps."""


def _random_by_name(name: str) -> Map:
    from envs.maps.random_maps import KINDS, random_map

    parts = name[len(RANDOM_PREFIX) :].split(":")
    kind, seed_text = ("polygons", parts[0]) if len(parts) == 1 else (parts[0], parts[-1])
    if len(parts) > 2 or kind not in KINDS or not seed_text.isdigit():
        # a '~' here is a suffix split_transform could not read (e.g. rot before x)
        suffix = (
            f", optionally followed by '{TRANSFORM_SEPARATOR}[xS][rotR][off(X,Y)]' (in that order)"
            if TRANSFORM_SEPARATOR in name
            else ""
        )
        raise InvalidConfigError(
            f"{name!r} is not a random map name; expected 'random:SEED' or "
            f"'random:KIND:SEED' with SEED an integer >= 0 and KIND one of {list(KINDS)}"
            f"{suffix}"
        )
    return random_map(int(seed_text), kind=kind)


TRANSFORM_SEPARATOR = "~"
"""``MAP~[xS][rotR][off(X,Y)]`` names ``MAP`` (any name :func:`load_map` takes) under a
similarity: scaled by S about the origin, rotated by R radians, then shifted by (X, Y)."""
_NUMBER = r"-?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?"
_TRANSFORM = re.compile(
    rf"(?:x(?P<s>{_NUMBER}))?(?:rot(?P<r>{_NUMBER}))?(?:off\((?P<x>{_NUMBER}),(?P<y>{_NUMBER})\))?"
)


@dataclass(frozen=True)
class Similarity:
    """``x -> scale * R(rotation) @ x + offset``, the transform of a ``MAP~...`` name."""

    scale: float = 1.0
    rotation: float = 0.0
    offset: tuple[float, float] = (0.0, 0.0)

    @property
    def matrix(self) -> np.ndarray:
        """The linear part, ``scale`` times the rotation by ``rotation`` radians."""
        c, s = math.cos(self.rotation), math.sin(self.rotation)
        return self.scale * np.array([[c, -s], [s, c]])

    def label(self) -> str:
        """The suffix after ``~`` that names this transform (empty for the identity);
        every number written so it reads back as the same float."""
        parts = []
        if self.scale != 1.0:
            parts.append(f"x{self.scale!r}")
        if self.rotation != 0.0:
            parts.append(f"rot{self.rotation!r}")
        if self.offset != (0.0, 0.0):
            parts.append(f"off({float(self.offset[0])!r},{float(self.offset[1])!r})")
        return "".join(parts)


def split_transform(name: str) -> tuple[str, Similarity | None]:
    """``(MAP, transform)`` of a name ``MAP~[xS][rotR][off(X,Y)]``; ``(name, None)`` when
    the name has no such suffix (a file whose path holds a ``~`` stays a file).

    Raises:
        InvalidConfigError: a suffix that parses but scales by S <= 0 (or not finite).

    Examples:
        >>> split_transform("corner~x10rot1.1")
        ('corner', Similarity(scale=10.0, rotation=1.1, offset=(0.0, 0.0)))
        >>> split_transform("~/maps/a.json")
        ('~/maps/a.json', None)
    """
    base, sep, spec = name.rpartition(TRANSFORM_SEPARATOR)
    m = _TRANSFORM.fullmatch(spec) if sep and spec else None
    if not base or m is None or Path(name).is_file():
        return name, None
    scale = float(m["s"]) if m["s"] else 1.0
    rotation = float(m["r"]) if m["r"] else 0.0
    offset = (float(m["x"]), float(m["y"])) if m["x"] else (0.0, 0.0)
    if not (math.isfinite(scale) and scale > 0) or not all(
        math.isfinite(v) for v in (rotation, *offset)
    ):
        raise InvalidConfigError(
            f"{name!r} transforms {base!r} by scale {scale!r}, rotation {rotation!r}, "
            f"offset {offset!r}: expected a finite scale > 0 and finite rotation and offset"
        )
    return base, Similarity(scale, rotation, offset)


BODY_RADIUS = 0.1
"""The agents' disc radius the built-ins are played with (the env's default)."""

GLOBAL_DEFAULTS: dict[str, float] = {"l_min": 2.0, "l_max": 4.0, "v_pursuer": 1.0, "v_evader": 0.5}
"""The recommended ``l_min``, ``l_max``, ``v_pursuer``, ``v_evader`` of a map without its own
(a :class:`Map` object, a random map, a map file whose metadata recommends none)."""

FILE_RECOMMENDATIONS = ("l_min", "l_max", "v_pursuer", "v_evader", "body_radius")
"""The keys of a map file's ``metadata`` that are applied as recommended parameters."""


def file_parameters(path: str | os.PathLike[str]) -> dict[str, float] | None:
    """The recommended parameters in map file ``path``'s ``metadata``: those of
    :data:`FILE_RECOMMENDATIONS` it gives, the rest of ``l_min``, ``l_max``, ``v_pursuer``,
    ``v_evader`` from :data:`GLOBAL_DEFAULTS`; ``None`` when it gives none of them (a
    ``null`` gives none; or ``path`` names no file: :func:`load_map` says why). Other
    metadata keys are free-form.

    Raises:
        InvalidMapError: a recommended value that is not a finite number > 0 (naming the
            file and the key), ``l_max`` not above ``l_min``, or a body radius (given, or
            the default 0.1) not below ``l_min / 2``.
    """
    p = Path(path)
    if p.suffix.lower() not in FORMATS or not p.is_file():
        return None
    metadata = read_map(p).metadata
    # a null is no recommendation (as the env's own None for these parameters)
    given = {k: metadata[k] for k in FILE_RECOMMENDATIONS if metadata.get(k) is not None}
    if not given:
        return None
    out = dict(GLOBAL_DEFAULTS)
    for key, value in given.items():
        try:
            out[key] = validation.positive(key, value, where=f"{p} metadata")
        except InvalidConfigError as exc:
            raise InvalidMapError(str(exc)) from None
    if out["l_max"] <= out["l_min"]:
        said = {  # as the file wrote it, or the default it left
            k: f"{given[k]!r}"
            if k in given
            else f"{out[k]!r} (the default; add it to the metadata)"
            for k in ("l_min", "l_max")
        }
        raise InvalidMapError(
            f"{p} metadata: l_max = {said['l_max']}: expected a value > l_min = {said['l_min']}"
        )
    body = out.get("body_radius", BODY_RADIUS)
    if body >= 0.5 * out["l_min"]:  # the env's own bound, said of the file (not of --config)
        said = f"{given['body_radius']!r}" if "body_radius" in given else f"{body!r} (the default"
        said += "" if "body_radius" in given else "; add body_radius to the metadata)"
        raise InvalidMapError(
            f"{p} metadata: body_radius = {said}: expected a value in (0, l_min / 2 = "
            f"{0.5 * out['l_min']:g})"
        )
    return out


def scaled_parameters(params: Mapping[str, float], scale: float) -> dict[str, float]:
    """Recommended parameters for a map scaled by ``scale``: lengths, speeds and the body
    radius (:data:`BODY_RADIUS` unless given) times ``scale``, the same game up to the
    similarity."""
    out = dict(params)
    out.setdefault("body_radius", BODY_RADIUS)
    return {k: v * scale for k, v in out.items()}


def recommended_parameters(name: Any) -> dict[str, float] | None:
    """The recommended parameters of a map argument: a built-in's
    (:func:`builtin_parameters`), a map file's (:func:`file_parameters`), either scaled by
    S when transformed (``NAME~xS...``, :func:`scaled_parameters`); ``None`` for a random
    map, a :class:`Map` object or a file recommending nothing (the env's
    :data:`GLOBAL_DEFAULTS` apply)."""
    from envs.maps.builtin import builtin_info, builtin_names

    if isinstance(name, str):
        if name in builtin_names():
            return builtin_info(name).params()
        if TRANSFORM_SEPARATOR in name:
            base, similarity = split_transform(name)
            if similarity is not None:
                recommended = recommended_parameters(base)
                if recommended is None:
                    return None
                return scaled_parameters(recommended, similarity.scale)
        if name.startswith(RANDOM_PREFIX):
            return None
    if isinstance(name, (str, os.PathLike)):
        return file_parameters(name)
    return None


def builtin_parameters(name: Any) -> dict[str, float] | None:
    """The recommended ``l_min``, ``l_max``, ``v_pursuer``, ``v_evader`` of a map *name*
    that is a built-in, or a built-in transformed (``NAME~xS...``: lengths and speeds
    times S, and ``body_radius`` = S times :data:`BODY_RADIUS`, so the game is the same
    up to the similarity); ``None`` for anything else (files, random maps, :class:`Map`
    objects: no recommendation).

    Examples:
        >>> builtin_parameters("corridor~x10rot0.3")
        {'l_min': 20.0, 'l_max': 40.0, 'v_pursuer': 10.0, 'v_evader': 5.0, 'body_radius': 1.0}
    """
    from envs.maps.builtin import builtin_info, builtin_names

    if not isinstance(name, str):
        return None
    if name in builtin_names():
        return builtin_info(name).params()
    base, similarity = split_transform(name) if TRANSFORM_SEPARATOR in name else (name, None)
    if similarity is None:
        return None
    # the base may be transformed itself (``corner~x2~rot1``, which load_map reads as the
    # built-in under both similarities): its recommendation scales again
    recommended = builtin_parameters(base)
    if recommended is None:
        return None
    return scaled_parameters(recommended, similarity.scale)


def load_map(path_or_name: str | os.PathLike[str], *, merge: bool | None = None) -> Map:
    """Load a map from a file (by suffix), a built-in map by name, or a seeded random map.

    Args:
        path_or_name: a ``.json``, ``.geojson`` or ``.wkt`` file, a name from
            :func:`envs.maps.builtin.builtin_names`, or ``"random:SEED"`` /
            ``"random:KIND:SEED"`` for :func:`envs.maps.random_maps.random_map` with its
            defaults (``KIND`` one of its ``KINDS``, default ``"polygons"``): a whole
            family of worlds by name, for training on many maps and testing on held-out
            seeds.
            Any of these followed by ``~[xS][rotR][off(X,Y)]`` is that map scaled by S,
            rotated by R radians about the origin, then shifted by (X, Y) (e.g.
            ``corner~rot0.37``, ``maze~x10rot1.1off(3,-2)``: the benchmarks' transformed
            worlds); a built-in's recommended lengths and speeds scale with it
            (:func:`envs.surveillance.config.map_recommendations`).
        merge: for files, override the file's merge flag (see :func:`read_map`).

    Raises:
        UnknownNameError: for a name that is neither a built-in nor a map file.
        InvalidMapError: naming the file and the problem (a missing file included).
        InvalidConfigError: a malformed ``random:`` name, a transform scaling by S <= 0.

    Examples:
        >>> load_map("corridor").n_vertices
        8
        >>> load_map("random:3").name
        'random_polygons_3'
    """
    from envs.maps.builtin import builtin_map, builtin_names

    if isinstance(path_or_name, str) and TRANSFORM_SEPARATOR in path_or_name:
        base, similarity = split_transform(path_or_name)
        if similarity is not None:
            try:
                m = load_map(base, merge=merge)
            except UnknownNameError as exc:
                raise UnknownNameError(f"map {path_or_name!r}: {exc}") from None
            try:
                return m.transformed(similarity.matrix, similarity.offset, name=path_or_name)
            except InvalidMapError as exc:
                raise InvalidMapError(
                    f"map {path_or_name!r}: {base!r} under that transform is no valid map: {exc}"
                ) from None
    if isinstance(path_or_name, str) and path_or_name.startswith(RANDOM_PREFIX):
        return _random_by_name(path_or_name)

    if not isinstance(path_or_name, (str, os.PathLike)):
        raise UnknownNameError(
            f"map: expected a built-in name {builtin_names()} or a map file path, got "
            f"{type(path_or_name).__name__} {path_or_name!r}"
        )
    if isinstance(path_or_name, str) and Path(path_or_name).suffix.lower() not in FORMATS:
        if path_or_name in builtin_names():
            if merge is not None:
                raise InvalidConfigError(
                    f"merge={merge!r} applies to map files, not to the built-in {path_or_name!r}"
                )
            return builtin_map(path_or_name)
        if path_or_name.strip() and Path(path_or_name).is_dir():  # Path("") is "."
            raise _fail(path_or_name, "is a directory, expected a map file or a built-in name")
        if not Path(path_or_name).is_file():
            raise UnknownNameError(
                f"unknown map {path_or_name!r}: expected a built-in name {builtin_names()}, "
                f"a map file ending in one of {sorted(FORMATS)}, 'random:[KIND:]SEED', or "
                "one of these followed by '~[xS][rotR][off(X,Y)]' (scaled, rotated, shifted)"
            )
    return read_map(path_or_name, merge=merge).map


def save_map(
    map: Map,
    path: str | os.PathLike[str],
    *,
    description: str = "",
    metadata: Mapping[str, Any] | None = None,
) -> Path:
    """Write ``map`` to ``path`` in the format its suffix names (see the module docstring).

    Args:
        map: the map.
        path: a ``.json``, ``.geojson`` or ``.wkt`` file (parent directories must exist).
        description: one line stored with JSON and GeoJSON (WKT has no room for it).
        metadata: a JSON-serialisable mapping stored with JSON and GeoJSON (a ``.wkt``
            file is refused metadata recommending parameters other than the defaults it
            would play at: it could not keep them).

    Returns:
        The path written.

    Raises:
        InvalidConfigError: for an unsupported suffix, metadata that is not JSON, or a
            ``.wkt`` file with metadata recommending parameters other than the defaults.
    """
    p = Path(path)
    fmt = _format_of(p, for_writing=True)
    if metadata is not None:
        try:
            json.dumps(dict(metadata), allow_nan=False)
        except (TypeError, ValueError) as exc:
            raise InvalidConfigError(
                f"metadata {metadata!r:.80} is not JSON-serialisable ({exc})"
            ) from exc
    if fmt == "wkt":
        # the file plays at the global defaults: a recommendation of another value is lost
        defaults = {**GLOBAL_DEFAULTS, "body_radius": BODY_RADIUS}
        lost = [k for k in FILE_RECOMMENDATIONS
                if (metadata or {}).get(k) not in (None, defaults[k])]  # fmt: skip
        if lost:
            raise InvalidConfigError(
                f"{p}: metadata recommends {', '.join(f'{k} = {metadata[k]!r}' for k in lost)}, "
                "and WKT has no room for metadata (the file would play at the defaults "
                f"{', '.join(f'{k} = {defaults[k]:g}' for k in lost)}); save it as .json or "
                ".geojson"
            )
        text = map_to_wkt(map)
    elif fmt == "geojson":
        text = (
            json.dumps(map_to_geojson(map, description=description, metadata=metadata), indent=1)
            + "\n"
        )
    else:
        text = _dump_json(map_to_dict(map, description=description, metadata=metadata))
    with written_whole(p, "map file") as tmp:  # a full disk leaves the old file as it was
        tmp.write_text(text, encoding="utf-8")
    return p
