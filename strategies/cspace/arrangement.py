"""The arrangement of the critical curves: faces (noncritical regions) and shared boundaries.

The curve polylines and the walls are noded together with shapely's snap-rounding overlay
(``unary_union`` with a ``grid_size`` of :data:`SNAP_REL` times the map scale, so an end
that lies on another curve up to rounding is noded onto it), then polygonised. Each face
in the free region is a noncritical region R (THEORY.md 1.3) up to the polyline
tolerance of the arcs and conchoids.

A *boundary piece* is a maximal chain of noded segments that separates the same two faces
and comes from the same critical curve(s); the paper's adjacency (THEORY.md 1.3) is
constant along it, so one sample point decides it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import shapely
from scipy.spatial import cKDTree
from shapely.geometry import Polygon

from envs.maps.map import Map
from strategies.cspace.curves import CriticalCurve

__all__ = ["SNAP_REL", "Arrangement", "Piece", "arrange"]

SNAP_REL = 1e-9
"""Snap-rounding grid of the overlay, relative to the map scale."""


@dataclass(frozen=True, eq=False)
class Piece:
    """A boundary piece between two faces.

    Attributes:
        faces: ``(A, B)``: A lies on the left of ``segments[k][0] -> segments[k][1]``.
        curves: indices of the critical curves the piece lies on.
        segments: (m, 2, 2) the noded segments of the piece, each directed with A on
            its left.
    """

    faces: tuple[int, int]
    curves: tuple[int, ...]
    segments: np.ndarray

    @property
    def length(self) -> float:
        """Total length of the piece."""
        d = self.segments[:, 1] - self.segments[:, 0]
        return float(np.hypot(d[:, 0], d[:, 1]).sum())


@dataclass(frozen=True, eq=False)
class Arrangement:
    """Faces of the curve arrangement inside the free region and their shared boundaries.

    Attributes:
        faces: face polygons (exteriors counter-clockwise).
        pieces: the boundary pieces between two faces.
        wall_length: per face, the length of its boundary on the walls.
    """

    faces: tuple[Polygon, ...]
    pieces: tuple[Piece, ...]
    wall_length: np.ndarray


def _snap_vertices(polylines: list[np.ndarray], r: float) -> list[np.ndarray]:
    """Make polyline vertices closer than ``r`` bitwise identical (one representative)."""
    sizes = [len(p) for p in polylines]
    allv = np.concatenate(polylines)
    pairs = cKDTree(allv).query_pairs(r, output_type="ndarray")
    if len(pairs):
        parent = np.arange(len(allv))

        def find(i: int) -> int:
            while parent[i] != i:
                parent[i] = parent[parent[i]]
                i = parent[i]
            return i

        for i, j in pairs.tolist():
            ri, rj = find(i), find(j)
            if ri != rj:
                parent[max(ri, rj)] = min(ri, rj)
        roots = np.array([find(i) for i in range(len(allv))])
        allv = allv[roots]
    out, s = [], 0
    for n in sizes:
        out.append(allv[s : s + n])
        s += n
    return out


def arrange(world: Map, curves: tuple[CriticalCurve, ...]) -> Arrangement:
    """Node and polygonise the curves; keep the faces inside the free region.

    Args:
        world: the map.
        curves: the critical curves (walls included).

    Returns:
        The :class:`Arrangement`.
    """
    g = SNAP_REL * world.scale
    polylines = _snap_vertices([c.points for c in curves], 4 * g)
    lines = [shapely.linestrings(p) for p in polylines]
    noded = shapely.unary_union(lines, grid_size=g)
    polys = shapely.get_parts(shapely.polygonize(shapely.get_parts(noded)))
    faces = []
    for poly in polys:
        if poly.area <= (10 * g) ** 2:
            continue
        rp = shapely.point_on_surface(poly)
        if world.contains([[rp.x, rp.y]])[0]:
            faces.append(shapely.orient_polygons(poly, exterior_cw=False))
    # directed segments: the face on the left of each
    left: dict[tuple[float, float, float, float], int] = {}
    for f, poly in enumerate(faces):
        for ring in (poly.exterior, *poly.interiors):
            c = np.asarray(ring.coords)
            for p, q in zip(c[:-1].tolist(), c[1:].tolist(), strict=True):
                left[(p[0], p[1], q[0], q[1])] = f
    wall_length = np.zeros(len(faces))
    internal = []
    for (x0, y0, x1, y1), f in left.items():
        other = left.get((x1, y1, x0, y0))
        if other is None:
            wall_length[f] += float(np.hypot(x1 - x0, y1 - y0))
        elif f < other:
            internal.append((x0, y0, x1, y1, f, other))
    pieces = _group_pieces(internal, curves, polylines, g)
    return Arrangement(tuple(faces), pieces, wall_length)


def _group_pieces(internal, curves, polylines, g: float) -> tuple[Piece, ...]:
    if not internal:
        return ()
    seg = np.array([s[:4] for s in internal]).reshape(-1, 2, 2)
    fa = np.array([s[4] for s in internal])
    fb = np.array([s[5] for s in internal])
    mids = shapely.points(0.5 * (seg[:, 0] + seg[:, 1]))
    tree = shapely.STRtree([shapely.linestrings(p) for p in polylines])
    qi, ci = tree.query(mids, predicate="dwithin", distance=8 * g)
    src: list[list[int]] = [[] for _ in range(len(seg))]
    for i, c in zip(qi.tolist(), ci.tolist(), strict=True):
        if curves[c].type != 0:
            src[i].append(c)
    keys = [(int(fa[i]), int(fb[i]), tuple(sorted(src[i]))) for i in range(len(seg))]
    # union segments of the same key that share an endpoint
    parent = list(range(len(seg)))

    def find(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    at: dict[tuple, int] = {}
    for i in range(len(seg)):
        for end in (seg[i, 0], seg[i, 1]):
            k = (keys[i], float(end[0]), float(end[1]))
            j = at.setdefault(k, i)
            if j != i:
                ri, rj = find(i), find(j)
                if ri != rj:
                    parent[ri] = rj
    groups: dict[int, list[int]] = {}
    for i in range(len(seg)):
        groups.setdefault(find(i), []).append(i)
    out = []
    for members in groups.values():
        a, b, src_c = keys[members[0]]
        out.append(Piece((a, b), src_c, seg[members]))
    return tuple(out)
