"""The arrangement of the critical curves: faces (noncritical regions) and their boundaries.

Built from the exact curves, not from their polylines:

1. collinear overlapping segments are merged (:mod:`strategies.cspace._collinear`);
2. every crossing, tangency and curve end lying on another curve becomes a vertex of
   both curves (:mod:`strategies.cspace._noding`), so no curve can dangle or be lost;
3. the curves cut at their vertices are the edges of a planar graph; at each vertex the
   edges are ordered by the directions to their exact points a short way along (closer
   than any other vertex, so no two of them cross in between) and the faces are traced
   half-edge by half-edge;
4. faces are classified: a cycle with an obstacle on its left is not free space; the
   counter-clockwise cycles are the faces' outer boundaries, the clockwise ones their
   holes (assigned to the smallest face around them);
5. a face narrower than the sliver tolerance (twice its area over its perimeter, or, if
   its polygon is wider, no disc of that diameter fitting in it on the exact curves) is a
   sliver of a near-degeneracy the geometry kernel cannot resolve: it is marked, and the
   decomposition steps over it (:mod:`strategies.cspace._build`); a face of perimeter
   below twice the collapse tolerance is a speck, a point pulled apart by a
   near-degeneracy: it is marked too (a sliver and a speck), and its boundary pieces
   separate nothing.

Polylines (within the chord tolerance) only draw the faces' polygons; the topology, the
probe points and the normals across boundaries come from the exact curves.

A *boundary piece* is a maximal chain of edges that separates the same two faces and
lies on the same critical curve(s); the paper's adjacency (THEORY.md 1.3) is constant
along it, so one probe pair decides it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import shapely
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from shapely.geometry import Polygon

from envs.maps.map import Map
from strategies.cspace._collinear import merge_collinear
from strategies.cspace._noding import Curves, Noded, node
from strategies.cspace._rod import ROUNDING_REL
from strategies.cspace._samples import ray_samples
from strategies.cspace._shapes import (
    ARC,
    CONCHOID,
    SEGMENT,
    SHAPE_CODES,
    derivatives,
    points,
    polyline_params,
    project,
)
from strategies.cspace.curves import CriticalCurve
from strategies.cspace.tolerances import Tolerances

__all__ = ["Arrangement", "Piece", "arrange"]


@dataclass(frozen=True, eq=False)
class Piece:
    """A boundary piece between two faces.

    Attributes:
        faces: ``(A, B)``: A lies on the left of each ``segments[k][0] -> [1]``.
        curves: indices of the critical curves (not walls) the piece lies on.
        segments: (m, 2, 2) the polyline segments of the piece, A on their left.
        edges: the arrangement edges of the piece.
        signs: per edge, +1 if A lies on the left as the edge's parameter grows, else -1.
    """

    faces: tuple[int, int]
    curves: tuple[int, ...]
    segments: np.ndarray = field(repr=False)
    edges: np.ndarray = field(repr=False)
    signs: np.ndarray = field(repr=False)

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
        curves: the arrangement's curves (after merging collinear overlaps), in the local
            frame (coordinates minus ``origin``: no cancellation far from (0, 0)).
        noded: its vertices and edges (local frame).
        edge_length: per edge, the length of its polyline.
        origin: the local frame's origin (the centre of the map's bounding box).
        face_of_half_edge: the face on the left of each half-edge (2k: edge k as its
            parameter grows, 2k + 1: backwards), -1 outside the free region.
        bridge: per edge, whether it has the same face on both sides.
        tol: the tolerances it was built with.
        sliver: (F,) faces narrower than the sliver tolerance (twice their area over
            their perimeter, or thinner everywhere on the exact curves when their polygon
            is wider): a near-degeneracy the kernel cannot resolve; they carry no
            cells and the boundaries across them are found by stepping over them.
        speck: (F,) faces whose perimeter is below twice the collapse tolerance (so
            their diameter is below it; also slivers): the faces around one meet at a
            point, its boundary pieces separate nothing.
        stats: counts for diagnostics: ``vertices``, ``edges``, ``dangling`` (edges with
            the same face on both sides: a curve end that lies on no other curve),
            ``slivers`` (faces too thin to probe), ``specks`` (faces collapsed to a
            point), ``orphan_holes`` (clockwise cycles inside no face),
            ``wide_vertices`` (see :class:`Noded`).
    """

    faces: tuple[Polygon, ...]
    pieces: tuple[Piece, ...]
    curves: Curves = field(repr=False)
    noded: Noded = field(repr=False)
    edge_length: np.ndarray = field(repr=False)
    origin: np.ndarray = field(repr=False)
    sliver: np.ndarray = field(repr=False)
    speck: np.ndarray = field(repr=False)
    face_of_half_edge: np.ndarray = field(repr=False)
    bridge: np.ndarray = field(repr=False)
    tol: Tolerances = field(repr=False)
    stats: dict[str, int] = field(default_factory=dict)

    def probes(
        self, edges: np.ndarray, signs: np.ndarray, at: float = 0.5
    ) -> tuple[np.ndarray, np.ndarray]:
        """The exact points of edges at fraction ``at`` of their parameter interval (the
        middles by default) and the unit normals there, pointing to the left (``signs``
        +1) or right (-1) of each edge's growing parameter."""
        edges = np.asarray(edges, dtype=np.intp)
        k = self.noded.curve[edges]
        ta, tb = self.noded.ta[edges], self.noded.tb[edges]
        t = 0.5 * (ta + tb) if at == 0.5 else ta + at * (tb - ta)
        kind, data = self.curves.kind[k], self.curves.data[k]
        p = points(kind, data, t, self.tol.L)
        d1, _ = derivatives(kind, data, t, self.tol.L)
        tan = d1 / np.hypot(d1[:, 0], d1[:, 1])[:, None]
        n = np.asarray(signs, dtype=float)[:, None] * np.stack([-tan[:, 1], tan[:, 0]], axis=1)
        return p + self.origin, n

    def exact_samples(self, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Points inside the given faces found on the exact curves, and their depth along
        the ray (NaN where no ray could be cast): see :mod:`strategies.cspace._samples`."""
        pts, depth = _face_samples(self, np.asarray(faces, dtype=np.intp))
        return pts + self.origin, depth


# ------------------------------------------------------------------ curves
def _origin(world: Map) -> np.ndarray:
    """The local origin of the arrangement: the centre of the map's bounding box."""
    x0, y0, x1, y1 = world.bounds
    return np.array([0.5 * (x0 + x1), 0.5 * (y0 + y1)])


def _local(rows: np.ndarray, kind: np.ndarray, c0: np.ndarray) -> np.ndarray:
    """Shape data moved to the local frame (points translated by ``-c0``)."""
    rows = rows.copy()
    rows[:, 0:2] -= c0
    con = kind == SHAPE_CODES["conchoid"]
    rows[con, 2:4] -= c0
    return rows


@dataclass(frozen=True)
class _Locus:
    """An arc or conchoid of the arrangement: the critical curves ``sources`` (pieces of
    one locus) over the union ``[t0, t1]`` of their parameter intervals."""

    code: int
    row: np.ndarray
    t0: float
    t1: float
    params: np.ndarray
    sources: tuple[int, ...]


def _merge_repeats(curves: tuple[CriticalCurve, ...], ks: list[int], tol: Tolerances) -> list:
    """The arcs and conchoids ``ks``, pieces of one locus that overlap merged into one.

    Two wall vertices at one point (a merged map's obstacles that meet at a corner, or an
    obstacle touching the boundary at one of its corners) give that point's type-2 arcs,
    and its type-5 conchoids with an edge, twice: the same locus over overlapping
    parameter intervals (mostly equal; where they are not, one piece ends where the other
    goes on). Noded as two curves they bound faces of zero area, their edges dangling
    (16 dangling edges and 5 pieces matched by overlap only, two boxes meeting at a corner
    at L = 2); they become one curve over the union of the intervals, standing for both
    (collinear segments are merged the same way by :mod:`strategies.cspace._collinear`).
    One locus: the same shape code and data equal to the merge tolerance (an arc's centre
    and radius; a conchoid's vertex, edge start and direction), found by rounding the
    data to eight merge tolerances (exact repeats, the case above, always share a key).
    Overlap: by more than the merge tolerance over L in the parameter (an arc's angle, a
    conchoid's length along its edge). Everything else is returned as it is, in order, so
    a map without repeated vertices gets the same arrangement as before, bit for bit.
    """
    step = tol.merge
    groups: dict[tuple, list[int]] = {}
    order: list[tuple] = []
    for k in ks:
        c = curves[k]
        row = c.row
        found = None
        key = (c.code, *np.round(row / (8.0 * step)).astype(np.int64).tolist())
        for g in groups.get(key, ()):
            if np.all(np.abs(curves[g[0]].row - row) <= step):
                found = g
                break
        if found is None:
            found = [k]
            groups.setdefault(key, []).append(found)
            order.append((key, len(groups[key]) - 1))
        else:
            found.append(k)
    out = []
    gap = step / tol.L
    for key, i in order:
        members = groups[key][i]
        if len(members) == 1:
            c = curves[members[0]]
            out.append(_Locus(c.code, c.row, c.t0, c.t1, np.asarray(c.params), (members[0],)))
            continue
        first = curves[members[0]]
        period = 2.0 * np.pi if first.shape == "arc" else 0.0
        spans = []
        for k in members:
            c = curves[k]
            t0 = float(c.t0)
            shift = 0.0
            if period:  # arcs: the start in [t0 of the first, + 2 pi)
                shift = np.floor((t0 - first.t0) / period) * period
            spans.append((t0 - shift, float(c.t1) - shift, k, shift))
        spans.sort()
        runs: list[list] = []
        for t0, t1, k, shift in spans:
            if runs and t0 < runs[-1][1] - gap:
                runs[-1][1] = max(runs[-1][1], t1)
                runs[-1][2].append((k, shift))
            else:
                runs.append([t0, t1, [(k, shift)]])
        if period and len(runs) > 1 and runs[-1][1] - period > runs[0][0] + gap:
            last = runs.pop()  # the last run wraps into the first
            runs[0][0] = last[0] - period
            runs[0][1] = max(runs[0][1], last[1] - period)
            runs[0][2] += [(k, shift + period) for k, shift in last[2]]
        if all(len(ms) == 1 for _, _, ms in runs):  # disjoint pieces (of one vertex): as is
            for k in members:
                c = curves[k]
                out.append(_Locus(c.code, c.row, c.t0, c.t1, np.asarray(c.params), (k,)))
            continue
        for t0, t1, ms in runs:
            params = np.unique(
                np.concatenate([np.asarray(curves[k].params) - shift for k, shift in ms])
            )
            params = np.clip(params, t0, t1)
            params = np.unique(np.concatenate([[t0], params, [t1]]))
            srcs = tuple(sorted(k for k, _ in ms))
            out.append(_Locus(first.code, first.row, t0, t1, params, srcs))
    return out


def _curves(world: Map, curves: tuple[CriticalCurve, ...], tol: Tolerances) -> Curves:
    """The arrangement's curves, in the local frame of :func:`_origin`."""
    c0 = _origin(world)
    seg = [k for k, c in enumerate(curves) if c.shape == "segment"]
    other = _merge_repeats(curves, [k for k, c in enumerate(curves) if c.shape != "segment"], tol)
    rows = np.array([curves[k].row for k in seg]).reshape(-1, 6)
    rows[:, 0:2] -= c0
    is_wall = np.array([curves[k].type == 0 for k in seg], dtype=bool)
    lines = merge_collinear(
        rows[:, 0:2],
        rows[:, 2:4],
        np.array([curves[k].t0 for k in seg], dtype=float),
        np.array([curves[k].t1 for k in seg], dtype=float),
        is_wall,
        tol.merge,
    )
    seg_arr = np.asarray(seg, dtype=np.intp)
    ns = len(lines.t0)
    kind = np.concatenate([np.full(ns, SEGMENT), [c.code for c in other]]).astype(int)
    data = np.zeros((ns + len(other), 6))
    data[:ns, 0:2], data[:ns, 2:4] = lines.o, lines.d
    for r, c in enumerate(other):
        data[ns + r] = c.row
    data[ns:] = _local(data[ns:], kind[ns:], c0)
    t0 = np.concatenate([lines.t0, [c.t0 for c in other]])
    t1 = np.concatenate([lines.t1, [c.t1 for c in other]])
    sources = [tuple(int(seg_arr[s]) for s in src) for src in lines.sources]
    sources += [c.sources for c in other]
    plist = [np.array([a, b]) for a, b in zip(lines.t0, lines.t1, strict=True)]
    plist += [c.params for c in other]
    offsets = np.concatenate([[0], np.cumsum([len(p) for p in plist])]).astype(np.intp)
    params = np.concatenate(plist) if plist else np.zeros(0)
    ends = np.stack([points(kind, data, t0, tol.L), points(kind, data, t1, tol.L)], axis=1)
    exact = np.zeros((len(kind), 2), dtype=bool)
    for r, src in enumerate(sources[:ns]):
        if lines.group[r] < 0 and curves[src[0]].type == 0:  # a whole wall: its map vertices
            e = curves[src[0]].features[0].index
            ends[r] = (world.edge_start[e] - c0, world.edge_end[e] - c0)
            exact[r] = True
    return Curves(
        kind=kind,
        data=data,
        t0=t0,
        t1=t1,
        sources=sources,
        wall_sign=np.concatenate([lines.wall_sign, np.zeros(len(other), dtype=np.int8)]),
        group=np.concatenate([lines.group, np.full(len(other), -1)]),
        offsets=offsets,
        params=params,
        ends=ends,
        exact_ends=exact,
    )


# ------------------------------------------------------------------ the planar graph
def _edge_polylines(cv: Curves, nd: Noded, L: float) -> tuple[np.ndarray, np.ndarray]:
    """Polyline of every edge: its end vertices and the curve's polyline points between."""
    ne = len(nd.curve)
    order = np.argsort(nd.curve, kind="stable")
    inner_from = np.zeros(ne, dtype=np.intp)
    inner_to = np.zeros(ne, dtype=np.intp)
    bounds = np.searchsorted(nd.curve[order], np.arange(len(cv) + 1))
    for c in np.flatnonzero(np.diff(bounds)).tolist():
        ks = order[bounds[c] : bounds[c + 1]]
        p = cv.params[cv.offsets[c] : cv.offsets[c + 1]]
        span = 1e-9 * (cv.t1[c] - cv.t0[c])
        inner_from[ks] = cv.offsets[c] + np.searchsorted(p, nd.ta[ks] + span, side="right")
        inner_to[ks] = cv.offsets[c] + np.searchsorted(p, nd.tb[ks] - span, side="left")
    n_inner = np.maximum(inner_to - inner_from, 0)
    counts = n_inner + 2
    offsets = np.concatenate([[0], np.cumsum(counts)]).astype(np.intp)
    pts = np.empty((offsets[-1], 2))
    pts[offsets[:-1]] = nd.vertices[nd.u]
    pts[offsets[1:] - 1] = nd.vertices[nd.v]
    owner = np.repeat(np.arange(ne), n_inner)
    local = np.arange(len(owner)) - np.repeat(np.cumsum(n_inner) - n_inner, n_inner)
    pidx = inner_from[owner] + local
    if len(owner):
        k = nd.curve[owner]
        pts[offsets[owner] + 1 + local] = points(cv.kind[k], cv.data[k], cv.params[pidx], L)
    return offsets, pts


def _rotation(
    cv: Curves, nd: Noded, L: float, e_len: np.ndarray, rounding: float = 0.0
) -> np.ndarray:
    """``next`` of every half-edge (2k: u -> v, 2k + 1: v -> u) for faces on the left.

    At each vertex the half-edges leave in the order of the directions from the vertex
    to their points at one distance from it (to 1e-9 of it, or their half-way points if
    nearer): a quarter of the shortest incident edge's length, or 16 times the vertex's
    distance to its edges' curves if that is farther (never the tangents: a vertex
    stands for every point within the merge tolerance, and two curves merged there may
    pass each other in an order their tangents do not tell). No two incident edges cross
    that close to the vertex, so the order in which they cross that circle is the
    arrangement's. Half-edges whose directions there differ by no more than rounding
    (``rounding`` at both chords' ends: two curves tangent at the vertex with curvatures
    equal within 1e-6, as a notch's type-5 conchoid and its corner's type-2 arc, 1e-19
    apart at a quarter of a 2.8e-6 edge) are ordered among themselves farther out, a
    quarter of the shortest of their own edges: edges of the arrangement do not cross,
    so their order is the same on every circle they cross once.
    """
    ne = len(nd.curve)
    k = np.repeat(np.arange(ne), 2)
    fwd = np.tile([True, False], ne)
    t = np.where(fwd, nd.ta[k], nd.tb[k])
    kind, data = cv.kind[nd.curve[k]], cv.data[nd.curve[k]]
    origin = np.where(fwd, nd.u[k], nd.v[k])
    short = np.full(len(nd.vertices), np.inf)
    np.minimum.at(short, origin, e_len[k])
    d1, _ = derivatives(kind, data, t, L)
    speed = np.maximum(np.hypot(d1[:, 0], d1[:, 1]), 1e-300)
    # a vertex merged from points up to the merge tolerance apart lies that far off its
    # edges' curves: the chords must be much longer than that to give their directions
    off = np.hypot(*(points(kind, data, t, L) - nd.vertices[origin]).T)
    spread = np.zeros(len(nd.vertices))
    np.maximum.at(spread, origin, off)
    reach = np.maximum(0.25 * short[origin], 16.0 * spread[origin])
    most = 0.5 * (nd.tb - nd.ta)[k]
    centre = nd.vertices[origin]
    ang = _chord_angles(kind, data, t, fwd, centre, reach, speed, most, L)
    order = np.lexsort((ang, origin))
    start = np.searchsorted(origin[order], np.arange(len(nd.vertices) + 1))
    deg = np.diff(start)
    if rounding > 0.0:
        order = _untie(
            order, start, ang, reach, rounding, e_len[k], kind, data, t, fwd, centre, speed, most, L
        )
    pos = np.empty(2 * ne, dtype=np.intp)
    pos[order] = np.arange(2 * ne)
    twin = np.arange(2 * ne) ^ 1
    v = origin[twin]
    p = pos[twin] - start[v]
    return order[start[v] + (p - 1) % deg[v]]


def _untie(order, start, ang, reach, rounding, h_len, kind, data, t, fwd, centre, speed, most, L):
    """``order`` with each run of half-edges at one vertex whose chord angles differ by
    at most ``2 rounding / reach`` reordered by their angles a quarter of the run's
    shortest edge out (see :func:`_rotation`)."""
    a = ang[order]
    thr = 2.0 * rounding / reach[order]
    close = np.zeros(len(order), dtype=bool)  # close[i]: order[i] ties with order[i - 1]
    close[1:] = a[1:] - a[:-1] <= thr[1:]
    deg = np.diff(start)
    first, last = start[:-1][deg >= 2], start[1:][deg >= 2] - 1
    close[start[:-1][deg >= 1]] = False
    wrap = a[first] + 2.0 * np.pi - a[last] <= thr[first]
    close[first[wrap]] = True  # the run through the -pi/pi cut
    tied = np.flatnonzero(close)
    if len(tied) == 0:
        return order
    order = order.copy()
    vert = np.searchsorted(start, tied, side="right") - 1
    for vx in np.unique(vert).tolist():
        lo, hi = int(start[vx]), int(start[vx + 1])
        idx = np.arange(lo, hi)
        gaps = np.diff(np.concatenate([a[idx], [a[lo] + 2.0 * np.pi]]))
        tie = gaps <= thr[np.concatenate([idx[1:], [lo]])]
        if tie.all():
            continue  # every direction within rounding: nothing to anchor a run on
        # runs of ties, read circularly from just after a real gap
        cut = int(np.flatnonzero(~tie)[-1]) + 1
        seq = np.roll(idx, -cut)
        links = np.roll(tie, -cut)[:-1]
        runs = np.split(seq, np.flatnonzero(~links) + 1)
        for run in runs:
            if len(run) < 2:
                continue
            h = order[run]
            far = np.full(len(h), 0.25 * float(h_len[h].min()))
            far = np.maximum(far, reach[h])
            new = _chord_angles(
                kind[h], data[h], t[h], fwd[h], centre[h], far, speed[h], most[h], L
            )
            rel = (new - a[run[0]] + np.pi) % (2.0 * np.pi)
            order[run] = h[np.argsort(rel, kind="stable")]
    return order


def _chord_angles(kind, data, t, fwd, centre, reach, speed, most, L):
    """Directions from ``centre`` to the curves' points at distance ``reach`` (or their
    half-way points if nearer; see :func:`_rotation`)."""
    dt = np.minimum(reach / speed, most)
    # the chords' ends on one circle about the vertex (where the edges cross it is their
    # order): a curve whose speed changes fast near the vertex (a conchoid whose tip edge
    # is short: 200 times the rod's speed at its end, a third less 0.4 along) got a chord
    # a quarter longer than its neighbour's, and two curves leaving the vertex 0.2 degrees
    # apart were ordered by their lengths (a 5 mm step on an obstacle's corner, L = 2:
    # three dangling edges). The parameter step is rescaled by reach / chord until the
    # chord is within 1e-9 of the reach (within 0.1 %, a conchoid's angle read 1e-4 off,
    # a fifth of its gap to the arc it leaves a vertex with: a 0.3 mm step, L = 1)
    ang = np.empty(len(t))
    todo = np.arange(len(t))
    for _ in range(60):
        tt = np.where(fwd[todo], t[todo] + dt[todo], t[todo] - dt[todo])
        chord = points(kind[todo], data[todo], tt, L) - centre[todo]
        ang[todo] = np.arctan2(chord[:, 1], chord[:, 0])
        size = np.hypot(chord[:, 0], chord[:, 1])
        scale = np.divide(reach[todo], size, out=np.ones_like(size), where=size > 0)
        done = (np.abs(scale - 1.0) < 1e-9) | ((scale > 1.0) & (dt[todo] >= most[todo]))
        todo = todo[~done]
        if len(todo) == 0:
            break
        dt[todo] = np.minimum(dt[todo] * scale[~done], most[todo])
    return ang


def _valid(poly: Polygon) -> Polygon:
    """The polygon, counter-clockwise; if its polylines cross near a vertex where two
    curves meet at a small angle (within the chord tolerance), its largest valid part."""
    if not poly.is_empty and not poly.is_valid:
        fixed = shapely.make_valid(poly)
        parts = [g for g in getattr(fixed, "geoms", [fixed]) if g.geom_type == "Polygon"]
        poly = max(parts, key=lambda g: g.area) if parts else Polygon()
    return shapely.orient_polygons(poly, exterior_cw=False)


def _cycles(nxt: np.ndarray) -> tuple[np.ndarray, list[np.ndarray]]:
    """Cycle id of every half-edge and each cycle's half-edges in order."""
    n = len(nxt)
    cyc = np.full(n, -1, dtype=np.intp)
    walks: list[np.ndarray] = []
    nl = nxt.tolist()
    for h0 in range(n):
        if cyc[h0] >= 0:
            continue
        walk = [h0]
        h = nl[h0]
        while h != h0:
            walk.append(h)
            h = nl[h]
        arr = np.asarray(walk, dtype=np.intp)
        cyc[arr] = len(walks)
        walks.append(arr)
    return cyc, walks


def arrange(world: Map, curves: tuple[CriticalCurve, ...], tol: Tolerances) -> Arrangement:
    """Node the exact curves, trace the faces in the free region and their boundaries.

    Args:
        world: the map.
        curves: the critical curves (walls included).
        tol: the decomposition's tolerances.

    Returns:
        The :class:`Arrangement`.
    """
    L = tol.L
    cv = _curves(world, curves, tol)
    c0 = _origin(world)
    # a point computed from the map's coordinates is known to rounding of their magnitude
    rounding = ROUNDING_REL * (world.scale + float(np.abs(world.vertices).max()))
    nd = node(cv, L, tol, world.vertices - c0, rounding)
    for attempt in range(2):
        ne = len(nd.curve)
        offsets, pts = _edge_polylines(cv, nd, L)
        # signed area and length of every edge's polyline (local frame: no cancellation)
        rel = pts
        seg_owner = np.repeat(np.arange(ne), np.diff(offsets) - 1)
        a_i = np.delete(np.arange(len(pts)), offsets[1:] - 1)
        cross = rel[a_i, 0] * rel[a_i + 1, 1] - rel[a_i + 1, 0] * rel[a_i, 1]
        e_area = 0.5 * np.bincount(seg_owner, weights=cross, minlength=ne)
        e_len = np.bincount(seg_owner, weights=np.hypot(*(pts[a_i + 1] - pts[a_i]).T), minlength=ne)
        nxt = _rotation(cv, nd, L, e_len, rounding)
        cyc, walks = _cycles(nxt)
        # two dangling edges between the same two vertices, within their curves' rounding
        # of each other, are one edge at floating point (they cross within it, so their
        # orders at the two ends disagree and neither bounds a face): keep one, trace again
        bridge = cyc[0::2] == cyc[1::2]
        twins = _twin_bridges(cv, nd, L, bridge, rounding) if attempt == 0 else []
        if len(twins) == 0:
            break
        keep = np.ones(ne, dtype=bool)
        keep[twins] = False
        nd = Noded(
            nd.vertices, nd.curve[keep], nd.ta[keep], nd.tb[keep], nd.u[keep], nd.v[keep],
            nd.n_points, nd.n_clusters_wide,
        )  # fmt: skip
    nc = len(walks)
    h_edge = np.arange(2 * ne) // 2
    h_fwd = np.arange(2 * ne) % 2 == 0
    c_area = np.bincount(cyc, weights=np.where(h_fwd, 1.0, -1.0) * e_area[h_edge], minlength=nc)
    ws = cv.wall_sign[nd.curve[h_edge]]
    blocked_h = (h_fwd & (ws < 0)) | (~h_fwd & (ws > 0))
    blocked = np.bincount(cyc, weights=blocked_h, minlength=nc) > 0
    area_tol = tol.merge**2
    all_bridges = np.bincount(cyc, weights=~bridge[h_edge], minlength=nc) == 0
    # faces: counter-clockwise cycles, and degenerate ones (zero area but not a tree of
    # dangling edges: two edges whose polylines coincide), which join a neighbour below
    degenerate = ~blocked & (np.abs(c_area) <= area_tol) & ~all_bridges
    # ... and clockwise ones that are not their component's outer boundary
    degenerate |= ~blocked & (c_area < -area_tol) & _not_outer(nd, walks, h_edge, h_fwd, c_area)
    outer = np.flatnonzero((~blocked & (c_area > area_tol)) | degenerate)
    inner = np.flatnonzero(~blocked & (c_area <= area_tol) & ~degenerate)

    # rings: the half-edges of each cycle in order, bridges skipped, each polyline's last
    # point dropped (it is the next one's first); all cycles at once
    ring_xy, ring_off = _rings(walks, bridge, h_edge, h_fwd, offsets, pts)
    n_pts = np.diff(ring_off)
    shells = _polygons(ring_xy, ring_off, outer)
    face_of_cycle = np.full(nc, -1, dtype=np.intp)
    face_of_cycle[outer] = np.arange(len(outer))
    orphans = 0
    faces = list(shells)
    if len(inner) and len(outer):
        h0 = np.array([walks[c][0] for c in inner.tolist()], dtype=np.intp)
        starts = nd.vertices[np.where(h_fwd[h0], nd.u[h_edge[h0]], nd.v[h_edge[h0]])]
        tree = shapely.STRtree(shells)
        qi, qf = tree.query(shapely.points(starts), predicate="within")
        areas = c_area[outer]
        order = np.lexsort((areas[qf], qi))  # per hole, the smallest face around it first
        qi, qf = qi[order], qf[order]
        firsts = np.concatenate([[True], qi[1:] != qi[:-1]]) if len(qi) else qi.astype(bool)
        best = np.full(len(inner), -1, dtype=np.intp)
        best[qi[firsts]] = qf[firsts]
        face_of_cycle[inner] = best
        orphans = int(np.count_nonzero(best < 0))
        holes: dict[int, list[np.ndarray]] = {}
        for i, c in enumerate(inner.tolist()):
            if best[i] >= 0 and c_area[c] < -area_tol and n_pts[c] >= 3:
                holes.setdefault(int(best[i]), []).append(ring_xy[ring_off[c] : ring_off[c + 1]])
        for f, hl in holes.items():
            faces[f] = Polygon(shells[f].exterior.coords, hl)
    bad = np.flatnonzero(~shapely.is_valid(np.array(faces, dtype=object)))
    for f in bad.tolist():
        faces[f] = _valid(faces[f])
    faces = list(shapely.orient_polygons(np.array(faces, dtype=object), exterior_cw=False))
    face_h = face_of_cycle[cyc]
    # slivers: faces narrower than the sliver tolerance (their cells are not probed;
    # the boundaries across them are resolved by stepping over them, see _build)
    nf = len(faces)
    f_area = shapely.area(np.array(faces, dtype=object))
    has = face_h >= 0
    f_perim = np.bincount(face_h[has], weights=e_len[h_edge[has]], minlength=nf)
    sliver = 2.0 * f_area < tol.thin * f_perim
    # specks: faces of half-perimeter (at least their diameter) below the collapse
    # tolerance, a length along the edges' polylines, the same in every frame
    speck = f_perim < 2.0 * tol.collapse
    faces = list(shapely.transform(np.array(faces, dtype=object), lambda x: x + c0))
    pieces = _pieces(cv, nd, curves, face_h, offsets, pts + c0)
    arr = Arrangement(
        tuple(faces), pieces, cv, nd, e_len, c0, sliver, speck, face_h, bridge, tol, {}
    )
    # the polygons are exact only to the chord tolerance (two short curved edges between
    # the same vertices are one chord twice): a face thin on its polygon is a sliver only
    # if it is thin on the exact curves too (twice the depth of its exact sample point)
    cand = np.flatnonzero(sliver)
    # a face thin on the exact curves but not on its polygon (below): the polygon gains
    # area only where a polyline lies outside its face, between a chord and its curve (a
    # conchoid's either side, an arc's only when the face is outside its circle, on the
    # right of the arc as its angle grows; a segment never), by at most chord x length
    h_all = np.flatnonzero(has)
    kind_h = cv.kind[nd.curve[h_edge[h_all]]]
    out_h = (kind_h == CONCHOID) | ((kind_h == ARC) & ~h_fwd[h_all])
    gain = tol.chord * np.bincount(
        face_h[h_all], weights=np.where(out_h, e_len[h_edge[h_all]], 0.0), minlength=nf
    )
    wide = np.flatnonzero(~sliver & (2.0 * f_area < tol.thin * f_perim + 2.0 * gain))
    if len(cand):
        _, depth = arr.exact_samples(cand)
        sliver[cand[np.isfinite(depth) & (2.0 * depth > tol.thin)]] = False
    # and a face wide on its polygon may be thin on the exact curves (the lens between a
    # notch's type-2 arc and the type-5 conchoid tangent to it at the notch's corner:
    # 3e-8 wide, 1e-4 by its polygon, one chord and two). Its polygon's area exceeds the
    # face's by at most its gain (above), so only a face whose polygon's twice area is
    # below thin x perimeter + twice its gain can be one; such a face is a sliver if it
    # is thin everywhere: no disc of diameter thin fits in it on the exact curves (a face
    # thin only on average, a lens between a type-1 line and the type-2 arc tangent to it
    # at its end, is probed where it is wide, as before)
    if len(wide):
        thin_all = _thin_everywhere(cv, nd, L, walks, outer[wide], bridge, h_edge, h_fwd, tol.thin)
        sliver[wide[thin_all]] = True
    sliver |= speck
    stats = {
        "vertices": len(nd.vertices),
        "edges": ne,
        "dangling": int(np.count_nonzero(bridge & ~blocked[cyc[0::2]])),
        "slivers": int(np.count_nonzero(sliver)),
        "specks": int(np.count_nonzero(speck)),
        "orphan_holes": orphans,
        "wide_vertices": nd.n_clusters_wide,
    }
    return Arrangement(
        tuple(faces), pieces, cv, nd, e_len, c0, sliver, speck, face_h, bridge, tol, stats
    )


FINE_STEPS = (1.0, 1.0 / 8.0, 1.0 / 64.0)
"""The polylines that tell whether a face wide on its polygon is thinner than the sliver
tolerance everywhere lie within these times the sliver tolerance of the exact curves,
coarse first; a face is decided as soon as the bounds allow (:func:`_thin_everywhere`)."""

_QUAD_SEGS = 8  # shapely's buffer: segments per quarter circle of an offset's rounded joins


def _not_outer(nd: Noded, walks, h_edge, h_fwd, c_area) -> np.ndarray:
    """Per cycle, whether it is not the outer boundary of its connected component.

    A connected component of the planar graph has exactly one outer (clockwise) cycle;
    every other cycle of it bounds a face. The edges' signed areas of a component sum to
    zero over its cycles, so the outer one is the cycle of least signed area. Any other
    cycle with a negative area on its polylines is a face thinner than the polylines
    can show (e.g. a lens between a type-1 line and the type-2 arc tangent to it at its
    end, cut by another arc within the merge tolerance of the line: its polyline area
    has either sign), not a hole in whichever face surrounds its first vertex.
    """
    nv = len(nd.vertices)
    g = coo_matrix((np.ones(len(nd.u)), (nd.u, nd.v)), shape=(nv, nv))
    _, comp = connected_components(g, directed=False)
    h0 = np.array([w[0] for w in walks], dtype=np.intp)
    c_comp = comp[np.where(h_fwd[h0], nd.u[h_edge[h0]], nd.v[h_edge[h0]])]
    order = np.lexsort((c_area, c_comp))
    first = np.concatenate([[True], c_comp[order][1:] != c_comp[order][:-1]])
    out = np.ones(len(walks), dtype=bool)
    out[order[first]] = False
    return out


_TWIN_AT = (0.25, 0.5, 0.75)  # where two dangling edges are compared (fractions of each)


def _twin_bridges(cv, nd, L, bridge, rounding) -> np.ndarray:
    """Dangling edges to drop: of two with the same end vertices (next to each other in
    the order of their indices) whose points at :data:`_TWIN_AT` lie within the curves'
    own rounding of the other's curve (each to the other), the later."""
    br = np.flatnonzero(bridge & (nd.u != nd.v))
    lo, hi = np.minimum(nd.u[br], nd.v[br]), np.maximum(nd.u[br], nd.v[br])
    order = np.lexsort((br, hi, lo))
    br, lo, hi = br[order], lo[order], hi[order]
    same = (lo[1:] == lo[:-1]) & (hi[1:] == hi[:-1])
    drop: list[int] = []
    for i in np.flatnonzero(same).tolist():  # consecutive pairs in a group of equal ends
        a, b = int(br[i]), int(br[i + 1])
        if a in drop:
            continue
        if _within(cv, nd, L, a, b, rounding) and _within(cv, nd, L, b, a, rounding):
            drop.append(b)
    return np.array(drop, dtype=np.intp)


def _known_to(cv, c, t, L, rounding) -> np.ndarray:
    """How far the points of curve ``c`` at parameters ``t`` may lie off the exact curve:
    ``rounding`` (the map's coordinates'), and for a conchoid P = Q + L (v - Q) / |v - Q|
    also L times the direction's error, up to 2 rounding / |v - Q| (3.7e-9 near the top
    of a conchoid whose pivot is 6.3e-4 from its tip's edge, L = 2.1)."""
    if cv.kind[c] != CONCHOID:
        return np.full(len(t), rounding)
    v, a, u = cv.data[c, 0:2], cv.data[c, 2:4], cv.data[c, 4:6]
    q = a + t[:, None] * u
    return rounding * (1.0 + 2.0 * L / np.hypot(*(v - q).T))


def _within(cv, nd, L, a, b, rounding) -> bool:
    """Whether edge ``a``'s points at :data:`_TWIN_AT` lie within both curves' rounding of
    edge ``b``'s curve (across it, at parameters inside ``b``'s range)."""
    ca, cb = nd.curve[a], nd.curve[b]
    t = nd.ta[a] + np.array(_TWIN_AT) * (nd.tb[a] - nd.ta[a])
    x = points(cv.kind[ca], cv.data[ca], t, L)
    tb = project(cv.kind[cb], cv.data[cb], x, nd.ta[b] if cv.kind[cb] == ARC else None)
    if not np.all((tb >= nd.ta[b]) & (tb <= nd.tb[b])):
        return False
    y = points(cv.kind[cb], cv.data[cb], tb, L)
    d1, _ = derivatives(cv.kind[cb], cv.data[cb], tb, L)
    r = x - y
    across = np.abs(d1[:, 0] * r[:, 1] - d1[:, 1] * r[:, 0]) / np.hypot(*d1.T)
    known = _known_to(cv, ca, t, L, rounding) + _known_to(cv, cb, tb, L, rounding)
    return bool(np.all(across <= known))


def _fine_rings(cv, nd, L, walks, cycles, bridge, h_edge, h_fwd, chord) -> list[Polygon]:
    """The polygons of the given cycles with each edge drawn within ``chord`` of its curve
    (ends at the arrangement's vertices, as the faces' polygons; holes left out)."""
    need = np.zeros(len(nd.curve), dtype=bool)
    need[h_edge[np.concatenate([walks[c] for c in cycles.tolist()])]] = True
    edges = np.flatnonzero(need)
    k = nd.curve[edges]
    off_k, params = polyline_params(cv.kind[k], cv.data[k], nd.ta[edges], nd.tb[edges], L, chord)
    counts = np.full(len(nd.curve), 2, dtype=np.intp)
    counts[edges] = np.diff(off_k)
    offsets = np.concatenate([[0], np.cumsum(counts)]).astype(np.intp)
    pts = np.empty((offsets[-1], 2))
    owner = np.repeat(k, counts[edges])
    at = np.arange(len(owner)) + np.repeat(offsets[edges] - off_k[:-1], counts[edges])
    pts[at] = points(cv.kind[owner], cv.data[owner], params, L)
    pts[offsets[:-1]] = nd.vertices[nd.u]
    pts[offsets[1:] - 1] = nd.vertices[nd.v]
    sub = [walks[c] for c in cycles.tolist()]
    xy, off = _rings(sub, bridge, h_edge, h_fwd, offsets, pts)
    return _polygons(xy, off, np.arange(len(sub)))


def _thin_everywhere(cv, nd, L, walks, cycles, bridge, h_edge, h_fwd, thin) -> np.ndarray:
    """Per cycle, whether no disc of diameter ``thin`` fits inside it on the exact curves
    (holes left out, which can only make a face thinner: a face is marked only when shown).

    On polylines within c of the curves, the polygon's largest disc radius r bounds the
    exact face's R: r - c <= R <= r + c. Eroding the polygon by rho (a negative buffer)
    leaves nothing iff r <= rho; the buffer's rounded joins are chords of arcs of radius
    rho (_QUAD_SEGS a quarter), inside them by at most rho (1 - cos(pi / (4 _QUAD_SEGS))),
    so the eroded polygon is at least the exact one and within that of it. So R < thin / 2
    if eroding by thin / 2 - c leaves nothing, and R >= thin / 2 if eroding by
    (thin / 2 + c) / cos(pi / (4 _QUAD_SEGS)) leaves something; otherwise the next, finer
    step decides (:data:`FINE_STEPS`); a face undecided by the last is not thin everywhere
    (its R is within about thin / 64 of thin / 2)."""
    out = np.zeros(len(cycles), dtype=bool)
    todo = np.arange(len(cycles))
    slack = 1.0 / math.cos(math.pi / (4 * _QUAD_SEGS))
    for step in FINE_STEPS:
        if len(todo) == 0:
            break
        c = step * thin
        rings = _fine_rings(cv, nd, L, walks, cycles[todo], bridge, h_edge, h_fwd, c)
        polys = np.array(rings, dtype=object)
        polys = shapely.make_valid(polys)  # rings within c of a lens thinner than 2 c cross
        wide = ~shapely.is_empty(
            shapely.buffer(polys, -(0.5 * thin + c) * slack, quad_segs=_QUAD_SEGS)
        )
        todo = todo[~wide]
        polys = polys[~wide]
        if 0.5 * thin > c and len(todo):
            thin_all = shapely.is_empty(
                shapely.buffer(polys, -(0.5 * thin - c), quad_segs=_QUAD_SEGS)
            )
            out[todo[thin_all]] = True
            todo = todo[~thin_all]
    return out


def _face_samples(arr: Arrangement, sel: np.ndarray):
    """Exact points inside faces ``sel``: from the middle of each one's longest edge."""
    face_h, e_len = arr.face_of_half_edge, arr.edge_length
    nd, cv, tol = arr.noded, arr.curves, arr.tol
    h = np.arange(len(face_h))
    ok = (face_h >= 0) & ~arr.bridge[h // 2] & np.isin(face_h, sel)
    h = h[ok]
    order = np.lexsort((-e_len[h // 2], face_h[h]))
    h = h[order]
    first = np.searchsorted(face_h[h], sel)
    has = first < len(h)
    has[has] = face_h[h[first[has]]] == sel[has]
    out = np.full((len(sel), 2), np.nan)
    depth = np.full(len(sel), np.nan)
    if not has.any():
        return out, depth
    best = h[first[has]]
    k = best // 2
    sign = np.where(best % 2 == 0, 1.0, -1.0)
    # no ray inside a face is longer than half its boundary (polygons may be degenerate)
    fh = face_h >= 0
    perim = np.bincount(
        face_h[fh], weights=e_len[np.flatnonzero(fh) // 2], minlength=len(arr.faces)
    )
    reach = 0.5 * perim[sel[has]] + tol.merge
    pad = tol.chord + tol.merge
    pts, d = ray_samples(cv, tol.L, nd.curve[k], nd.ta[k], nd.tb[k], sign, reach, tol.touch, pad)
    out[has], depth[has] = pts, d
    return out, depth


def _rings(walks, bridge, h_edge, h_fwd, offsets, pts):
    """The polyline rings of all cycles: (points, per-cycle offsets)."""
    nc = len(walks)
    lens = np.array([len(w) for w in walks], dtype=np.intp)
    hs = np.concatenate(walks) if walks else np.zeros(0, dtype=np.intp)
    cyc = np.repeat(np.arange(nc), lens)
    keep = ~bridge[h_edge[hs]]
    hs, cyc = hs[keep], cyc[keep]
    k = h_edge[hs]
    cnt = np.diff(offsets)[k] - 1
    st = np.where(h_fwd[hs], offsets[k], offsets[k + 1] - 1)
    dr = np.where(h_fwd[hs], 1, -1)
    rep = np.repeat(np.arange(len(hs)), cnt)
    loc = np.arange(len(rep)) - np.repeat(np.cumsum(cnt) - cnt, cnt)
    xy = pts[st[rep] + dr[rep] * loc]
    per = np.bincount(cyc, weights=cnt, minlength=nc).astype(np.intp)
    return xy, np.concatenate([[0], np.cumsum(per)])


def _polygons(xy: np.ndarray, off: np.ndarray, cycles: np.ndarray) -> list[Polygon]:
    """Polygons of the given cycles' rings (empty for rings of fewer than 3 points)."""
    out = [Polygon()] * len(cycles)
    n = off[cycles + 1] - off[cycles]
    ok = np.flatnonzero(n >= 3)
    if len(ok):
        idx = np.concatenate([np.arange(off[c], off[c + 1]) for c in cycles[ok].tolist()])
        ring_id = np.repeat(np.arange(len(ok)), n[ok])
        rings = shapely.linearrings(xy[idx], indices=ring_id)
        for j, poly in zip(ok.tolist(), shapely.polygons(rings).tolist(), strict=True):
            out[j] = poly
    return out


def _pieces(cv, nd, curves, face_h, offsets, pts) -> tuple[Piece, ...]:
    fl, fr = face_h[0::2], face_h[1::2]
    sel = np.flatnonzero((fl >= 0) & (fr >= 0) & (fl != fr))
    if len(sel) == 0:
        return ()
    a = np.minimum(fl[sel], fr[sel])
    b = np.maximum(fl[sel], fr[sel])
    sign = np.where(fl[sel] == a, 1, -1)
    src = [tuple(s for s in cv.sources[c] if curves[s].type != 0) for c in nd.curve[sel].tolist()]
    keys = {}
    kid = np.array(
        [
            keys.setdefault((int(x), int(y), s), len(keys))
            for x, y, s in zip(a, b, src, strict=True)
        ],
        dtype=np.intp,
    )
    # edges of one key that share a vertex belong to one piece
    n = len(sel)
    ends = np.concatenate([nd.u[sel], nd.v[sel]])
    which = np.concatenate([np.arange(n), np.arange(n)])
    combo = np.stack([np.concatenate([kid, kid]), ends], axis=1)
    _, inv = np.unique(combo, axis=0, return_inverse=True)
    inv = inv.ravel()
    g = coo_matrix((np.ones(2 * n), (which, n + inv)), shape=(n + inv.max() + 1,) * 2)
    _, lab = connected_components(g, directed=False)
    lab = lab[:n]
    out = []
    inv_keys = {v: k for k, v in keys.items()}
    order = np.argsort(lab, kind="stable")
    bounds = np.searchsorted(lab[order], np.arange(lab.max() + 2))
    for g_id in range(lab.max() + 1):
        mem = order[bounds[g_id] : bounds[g_id + 1]]
        if len(mem) == 0:
            continue
        x, y, s = inv_keys[int(kid[mem[0]])]
        segs = []
        for m in mem.tolist():
            e = sel[m]
            poly = pts[offsets[e] : offsets[e + 1]]
            if sign[m] < 0:
                poly = poly[::-1]
            segs.append(np.stack([poly[:-1], poly[1:]], axis=1))
        out.append(Piece((x, y), s, np.concatenate(segs), sel[mem], sign[mem]))
    return tuple(out)
