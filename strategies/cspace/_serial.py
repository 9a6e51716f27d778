"""A :class:`~strategies.cspace.decomposition.Decomposition` as plain numeric arrays.

For the on-disk cache (:mod:`strategies.cspace.cache`): every part of a decomposition is
stored as numbers (ragged lists as offsets plus values, polygons as WKB bytes, stops as
the integer codes of :mod:`strategies.cspace._batch_arcs`), so the file can be read with
``numpy.load(..., allow_pickle=False)``: loading it cannot run code. The map itself is
not stored: the cache key names it by its digest and the caller supplies it.
"""

from __future__ import annotations

import numpy as np
import shapely

from envs.geometry.types import Arc
from envs.maps.map import Feature, Map
from strategies.cspace._batch_arcs import stop_code, stop_of
from strategies.cspace._shapes import SHAPE_CODES, SHAPE_NAMES
from strategies.cspace.curves import CriticalCurve
from strategies.cspace.decomposition import Boundary, Cell, Decomposition, Region

__all__ = ["from_arrays", "to_arrays"]

_WIDTH = {"segment": 5, "arc": 3, "conchoid": 6}
_REASONS = (None, "a", "b")


def _ragged(parts: list) -> tuple[np.ndarray, np.ndarray]:
    """(offsets, concatenated values) of a list of arrays."""
    lens = [len(p) for p in parts]
    off = np.concatenate([[0], np.cumsum(lens)]).astype(np.int64)
    return off, (np.concatenate(parts) if parts else np.zeros(0))


def _feature_code(f: Feature) -> int:
    return ((f.kind == "edge") << 32) | f.index


def _feature(code: int) -> Feature:
    return Feature("edge" if code >> 32 else "vertex", code & 0xFFFFFFFF)


def to_arrays(dec: Decomposition) -> dict[str, np.ndarray]:
    """Every part of ``dec`` as named numeric arrays (no Python objects)."""
    a: dict[str, np.ndarray] = {"L": np.array(dec.L), "chord_tol": np.array(dec.chord_tol)}
    cs = dec.curves
    a["c_type"] = np.array([c.type for c in cs], dtype=np.int8)
    a["c_shape"] = np.array([SHAPE_CODES[c.shape] for c in cs], dtype=np.int8)
    feats = np.full((len(cs), 2), -1, dtype=np.int64)
    for i, c in enumerate(cs):
        for k, f in enumerate(c.features):
            feats[i, k] = _feature_code(f)
    a["c_feat"] = feats
    a["c_data"] = np.array([c.row for c in cs]).reshape(-1, 6)
    a["c_t"] = np.array([(c.t0, c.t1, c.tolerance) for c in cs]).reshape(-1, 3)
    a["c_pts_off"], a["c_pts"] = _ragged([c.points for c in cs])
    a["c_par"] = (
        np.concatenate(
            [
                np.asarray(c.params if c.params is not None else np.full(len(c.points), np.nan))
                for c in cs
            ]
        )
        if cs
        else np.zeros(0)
    )
    rs = dec.regions
    wkb = shapely.to_wkb(np.array([r.polygon for r in rs], dtype=object))
    a["r_wkb_off"] = np.concatenate([[0], np.cumsum([len(w) for w in wkb])]).astype(np.int64)
    a["r_wkb"] = np.frombuffer(b"".join(wkb), dtype=np.uint8)
    a["r_point"] = np.array([r.point for r in rs]).reshape(-1, 2)
    a["r_cells_off"], a["r_cells"] = _ragged([np.array(r.cells, dtype=np.int64) for r in rs])
    a["r_bnd_off"], a["r_bnd"] = _ragged([np.array(r.boundaries, dtype=np.int64) for r in rs])
    cl = dec.cells
    a["k_region"] = np.array([c.region for c in cl], dtype=np.int64)
    a["k_stops"] = np.array(
        [(stop_code(c.stops[0]), stop_code(c.stops[1])) for c in cl], dtype=np.int64
    ).reshape(-1, 2)
    a["k_arc"] = np.array([(c.arc.lo, c.arc.hi) for c in cl]).reshape(-1, 2)
    a["k_esc"] = np.array([c.escapable for c in cl], dtype=bool)
    a["k_reason"] = np.array([_REASONS.index(c.reason) for c in cl], dtype=np.int8)
    a["k_via"] = np.array([-1 if c.via is None else c.via for c in cl], dtype=np.int64)
    bs = dec.boundaries
    a["b_regions"] = np.array([b.regions for b in bs], dtype=np.int64).reshape(-1, 2)
    a["b_curves_off"], a["b_curves"] = _ragged([np.array(b.curves, dtype=np.int64) for b in bs])
    a["b_seg_off"], a["b_seg"] = _ragged([b.segments.reshape(-1, 2, 2) for b in bs])
    a["b_point"] = np.array([b.point for b in bs]).reshape(-1, 2)
    a["b_normal"] = np.array([b.normal for b in bs]).reshape(-1, 2)
    a["b_adj_off"], a["b_adj"] = _ragged(
        [np.array(b.adjacent, dtype=np.int64).reshape(-1, 2) for b in bs]
    )
    a["b_resolved"] = np.array([b.resolved for b in bs], dtype=bool)
    return a


def from_arrays(world: Map, a: dict[str, np.ndarray], stats: dict) -> Decomposition:
    """The decomposition stored by :func:`to_arrays` (``world``: the map it belongs to)."""
    L = float(a["L"])
    curves = []
    po, pts, par = a["c_pts_off"], a["c_pts"].reshape(-1, 2), a["c_par"]
    for i in range(len(a["c_type"])):
        shape = SHAPE_NAMES[int(a["c_shape"][i])]
        feats = tuple(_feature(int(f)) for f in a["c_feat"][i] if f >= 0)
        t0, t1, tol = (float(x) for x in a["c_t"][i])
        sl = slice(po[i], po[i + 1])
        curves.append(
            CriticalCurve(
                int(a["c_type"][i]),
                feats,
                shape,
                tuple(float(x) for x in a["c_data"][i, : _WIDTH[shape]]),
                t0,
                t1,
                L,
                pts[sl].copy(),
                tol,
                par[sl].copy(),
            )
        )
    wo, blob = a["r_wkb_off"], a["r_wkb"].tobytes()
    polys = shapely.from_wkb([blob[wo[i] : wo[i + 1]] for i in range(len(wo) - 1)])
    co, cells_of = a["r_cells_off"], a["r_cells"]
    bo, bnd_of = a["r_bnd_off"], a["r_bnd"]
    regions = tuple(
        Region(
            r,
            polys[r],
            a["r_point"][r].copy(),
            tuple(int(x) for x in cells_of[co[r] : co[r + 1]]),
            tuple(int(x) for x in bnd_of[bo[r] : bo[r + 1]]),
        )
        for r in range(len(polys))
    )
    cells = tuple(
        Cell(
            i,
            int(a["k_region"][i]),
            (stop_of(int(a["k_stops"][i, 0])), stop_of(int(a["k_stops"][i, 1]))),
            Arc(
                float(a["k_arc"][i, 0]),
                float(a["k_arc"][i, 1]),
                stop_of(int(a["k_stops"][i, 0])),
                stop_of(int(a["k_stops"][i, 1])),
            ),
            bool(a["k_esc"][i]),
            _REASONS[int(a["k_reason"][i])],
            None if a["k_via"][i] < 0 else int(a["k_via"][i]),
        )
        for i in range(len(a["k_region"]))
    )
    cvo, cv = a["b_curves_off"], a["b_curves"]
    so, seg = a["b_seg_off"], a["b_seg"].reshape(-1, 2, 2)
    ao, adj = a["b_adj_off"], a["b_adj"].reshape(-1, 2)
    boundaries = tuple(
        Boundary(
            i,
            (int(a["b_regions"][i, 0]), int(a["b_regions"][i, 1])),
            tuple(int(x) for x in cv[cvo[i] : cvo[i + 1]]),
            seg[so[i] : so[i + 1]].copy(),
            a["b_point"][i].copy(),
            a["b_normal"][i].copy(),
            tuple((int(x), int(y)) for x, y in adj[ao[i] : ao[i + 1]]),
            bool(a["b_resolved"][i]),
        )
        for i in range(len(a["b_regions"]))
    )
    return Decomposition(
        world, L, tuple(curves), regions, cells, boundaries, float(a["chord_tol"]), stats
    )
