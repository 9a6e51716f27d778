"""The :class:`Map`: a bounded polygonal world, validated once, with precomputed arrays.

Representation
--------------
A world is given as an outer boundary polygon and obstacle polygons. On construction it
is normalised into its *free region*: one polygon with holes. Its boundary is stored as
**walls**, closed rings oriented so that free space lies on the **left** of every edge
(outer ring counter-clockwise, holes clockwise). With that single orientation:

* the unit normal into free space of edge ``a -> b`` is the left normal ``(-dy, dx)``;
* a vertex where the walls turn right is a **convex obstacle vertex** (the paper's
  "reflex vertex", an angle bigger than pi measured in free space: a corner the rod can
  wrap around); one where they turn left is a concave obstacle vertex (a room corner).

A room given as a non-convex outer boundary and the same room given as a rectangle with
obstacle blocks produce the same walls, so nothing downstream depends on which.

Validation rule for touching polygons (see :data:`envs.tolerances.REL_GAP_TOL`): two
obstacles closer than the gap tolerance, or an obstacle that comes that close to the
boundary, are rejected with an :class:`~envs.errors.InvalidMapError` naming both, unless
the map is built with ``merge=True``, in which case the free region is
``boundary - union(obstacles)`` and must still be one connected polygon.
"""

from __future__ import annotations

import functools
import hashlib
import json
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import shapely
from shapely.geometry import Polygon

from envs import validation
from envs.errors import InvalidConfigError, InvalidMapError
from envs.tolerances import COLLINEAR_TOL, REL_GAP_TOL, REL_LENGTH_TOL

__all__ = ["Feature", "Map", "convex_diameter"]


@dataclass(frozen=True)
class Feature:
    """A wall feature of a map: a vertex or an edge, by its index in the map's arrays.

    Attributes:
        kind: ``"vertex"`` or ``"edge"``.
        index: index into ``Map.vertices`` or ``Map.edge_start``.
    """

    kind: str
    index: int

    def __str__(self) -> str:
        return f"{self.kind} {self.index}"


def _as_ring(points: object, what: str) -> np.ndarray:
    """Return ``points`` as an (n, 2) float array without a repeated closing vertex."""
    try:  # one rule for numbers (envs.validation): "1" and True are not coordinates
        arr = validation.finite_array(what, points)
    except InvalidConfigError as exc:
        raise InvalidMapError(str(exc)) from None
    if arr.ndim != 2 or arr.shape[1] != 2:
        raise InvalidMapError(
            f"{what}: expected an (n, 2) array of vertices, got shape {arr.shape}"
        )
    if len(arr) >= 2 and np.array_equal(arr[0], arr[-1]):
        arr = arr[:-1]
    if len(arr) < 3:
        raise InvalidMapError(
            f"{what}: a polygon needs at least 3 distinct vertices, got {len(arr)}"
        )
    return arr


_EPS = float(np.finfo(float).eps)
"""Relative rounding of a float64 coordinate."""

SIZE_RANGE = (1e-30, 1e30)
"""Sizes (the boundary's bounding-box diagonal) a map may have. The kernel's sweep squares
squared lengths (its discriminants), which overflow or underflow float64 near sizes of
1e+-77: a map scaled by 1e100 timed a rod passing a corner at the step's end instead of
halfway, without a word. Measured exact at 1e+-60 (probes under similarities); the
range keeps a wide margin for the theory's higher powers."""

_PAIRS = 1 << 20
"""(point, edge) pairs per batch of ``Map.contains`` / ``Map.distance_to_walls``: about
100 MB of temporaries at the peak. Unbatched, the shooting evader's reset on a 60 x 56 room with 210
pillars (844 edges) asked for 315,000 points at once: over 20 GB, killed by the OOM killer."""


_NEAR_EDGES = 128
"""Maps with at least this many wall edges measure the distance to the walls of many
points through a spatial index of the edges (:meth:`Map._near_distances`): brute force
costs about 0.2 us a (point, edge) pair, the index about 12 us a point whatever the
edges (measured on 300,000 points: equal at about 60 edges; the pillar room's 844: 54 s
brute force, 3.5 s indexed). The values are the same either way."""
_NEAR_PAIRS = 1024
"""... and calls with at least this many (point, edge) pairs (fewer: brute force). The
index costs ~35 us a call before its ~5-12 us a point, brute force ~0.05-0.2 us a pair
whatever the points: a point on a 2700-edge floor plan 103 us brute force, 36 indexed; 2
points on 940 edges 112 and 38; 6 on 280 edges 65 and 49; 1 on 940 edges 34 and 37 (the
decomposition pursuer's clearances on a lazy table: one to a few points a call). With at
least 256 points it was the index from 128 edges, as before."""
_NEAR_CHUNK = 1 << 16  # points per batch of the indexed distances
_CELL_POINTS = 256
"""Calls of :meth:`Map.distance_to_walls` with at most this many points, on maps of at
least ``_NEAR_EDGES`` edges, measure each point against the few edges of its cell
(:meth:`Map._cell_edges`): the decomposition pursuer's clearances on a lazy table, a few
to a hundred grid nodes a call (one point ~15 us on a 280-edge floor plan, 17-36 us
brute force or indexed; ~0.5 us a point more, the index ~5-12)."""
_CELLS_KEPT = 1 << 14  # cells a map keeps (~0.6 KB each; then it starts again)


HULL_ALL_PAIRS = 2048
"""Up to this many convex-hull vertices :func:`convex_diameter` measures every pair (4 M
at most, about 0.1 s); beyond it, the antipodal pairs of the rotating calipers only."""


def convex_diameter(points: np.ndarray | Sequence[Sequence[float]]) -> float:
    """The largest distance between two of ``points`` (an (n, 2) array): the diameter of
    their convex hull, reached at two of its vertices.

    Up to :data:`HULL_ALL_PAIRS` hull vertices every pair is measured; beyond, only the
    antipodal pairs of the rotating calipers (Shamos 1978), O(n), each widened to the
    partner's two neighbours on either side against rounding in the caliper's area
    comparisons. Every pair of a round room's 20,000 hull vertices (4e8) took 11 s in
    ``Map.diameter`` and 23 s in each of ``strategies.cspace.tolerances.diameter``'s
    calls: ``surveil analyze`` spent 57 of its 63 s there before refusing the
    decomposition for its memory.

    Examples:
        >>> convex_diameter([(0, 0), (3, 0), (3, 4), (1, 1)])
        5.0
    """
    pts = np.asarray(points, dtype=float).reshape(-1, 2)
    hull = shapely.convex_hull(shapely.multipoints(pts))
    if hull.geom_type == "Polygon":
        h = np.asarray(hull.exterior.coords, dtype=float)[:-1]
    else:  # every point on a line, or a single point
        h = np.asarray(shapely.get_coordinates(hull), dtype=float)
    n = len(h)
    if n < 2:
        return 0.0
    if n <= HULL_ALL_PAIRS:
        rows = max(1, _PAIRS // n)  # a block of rows at a time
        best = 0.0
        for i in range(0, n, rows):
            d = h[i : i + rows, None, :] - h[None, :, :]
            best = max(best, float(np.einsum("ijk,ijk->ij", d, d).max()))
        return float(np.sqrt(best))
    if _signed_area(h) < 0:  # counter-clockwise, so the areas below are positive
        h = h[::-1]
    # for each edge (h[i], h[i + 1]), the vertex farthest from its line (largest area)
    xs, ys = h[:, 0].tolist(), h[:, 1].tolist()
    partner = np.empty(n, dtype=np.int64)
    j = 1
    for i in range(n):
        ax, ay = xs[i], ys[i]
        ex, ey = xs[(i + 1) % n] - ax, ys[(i + 1) % n] - ay
        cur = ex * (ys[j] - ay) - ey * (xs[j] - ax)
        while True:  # the caliper turns while the next vertex is farther from the edge
            k = (j + 1) % n
            nxt = ex * (ys[k] - ay) - ey * (xs[k] - ax)
            if nxt <= cur:
                break
            j, cur = k, nxt
        partner[i] = j
    ends = np.concatenate([np.arange(n), (np.arange(n) + 1) % n])
    other = np.concatenate([partner, partner])
    best = 0.0
    for k in range(-2, 3):
        d = h[ends] - h[(other + k) % n]
        best = max(best, float(np.einsum("ij,ij->i", d, d).max()))
    return float(np.sqrt(best))


def _finite_points(points: np.ndarray | Sequence[Sequence[float]], what: str) -> np.ndarray:
    """``points`` as a (k, 2) float array, refused (naming the first bad coordinate) when
    one is NaN or infinite. The check is one pass over the points; the query after it is
    a pass over points x edges."""
    p = np.atleast_2d(np.asarray(points, dtype=float))
    if not np.isfinite(p).all():
        validation.points(what, p)  # raises: "... expected finite values, got nan at ..."
    return p


def _segment_distances(
    p: np.ndarray, start: np.ndarray, direction: np.ndarray, length: np.ndarray
) -> np.ndarray:
    """Distance from each point ``p[k]`` (or one point ``p``, (1, 2)) to the segment ``k``
    from ``start[k]`` along the unit ``direction[k]`` for ``length[k]``: the arithmetic of
    every wall distance the map measures one (point, edge) pair at a time."""
    rel = p - start
    t = np.clip(np.einsum("kj,kj->k", rel, direction), 0.0, length)
    closest = start + t[:, None] * direction
    return np.linalg.norm(p - closest, axis=1)


def _clean_ring(ring: np.ndarray, scale: float, what: str) -> np.ndarray:
    """Drop repeated and straight (collinear) vertices; reject degenerate rings."""
    keep = np.linalg.norm(ring - np.roll(ring, 1, axis=0), axis=1) > REL_LENGTH_TOL * scale
    ring = ring[keep]
    changed = True
    while changed and len(ring) >= 3:
        prev_d = ring - np.roll(ring, 1, axis=0)
        next_d = np.roll(ring, -1, axis=0) - ring
        cross = prev_d[:, 0] * next_d[:, 1] - prev_d[:, 1] * next_d[:, 0]
        dot = np.einsum("ij,ij->i", prev_d, next_d)
        norms = np.linalg.norm(prev_d, axis=1) * np.linalg.norm(next_d, axis=1)
        straight = (np.abs(cross) <= COLLINEAR_TOL * norms) & (dot > 0)
        changed = bool(straight.any())
        if changed:
            ring = ring[~straight]
    if len(ring) < 3:
        raise InvalidMapError(f"{what}: degenerate polygon (fewer than 3 non-collinear vertices)")
    return ring


def _canonical_start(ring: np.ndarray) -> np.ndarray:
    """Rotate a ring to start at its vertex with the lowest x (then lowest y)."""
    r = ring + 0.0
    first = int(np.lexsort((r[:, 1], r[:, 0]))[0])
    return np.roll(r, -first, axis=0)


def _signed_area(ring: np.ndarray) -> float:
    x, y = ring[:, 0], ring[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


class Map:
    """A bounded polygonal world with precomputed wall arrays.

    Args:
        boundary: outer boundary polygon, (n, 2) vertices in either orientation.
        obstacles: obstacle polygons, each (m, 2), strictly inside the boundary.
        name: a label used in reports and error messages.
        merge: merge touching or overlapping obstacles (and obstacles touching the
            boundary) instead of rejecting them.

    Raises:
        InvalidMapError: naming the offending polygon and why it is invalid.

    Attributes:
        vertices: (V, 2) all wall vertices, ring after ring.
        vertex_ring: (V,) index of the ring of each vertex (0 = outer boundary).
        vertex_convex: (V,) True at convex obstacle vertices (free-space reflex).
        vertex_prev_edge, vertex_next_edge: (V,) the two wall edges at each vertex.
        edge_start, edge_end: (E,) endpoints of each wall edge (E = V; free on the left).
        edge_dir, edge_normal, edge_length: unit direction, unit normal into free space,
            length of each edge.
        rings: tuple of (n_i, 2) arrays, the walls ring by ring.

    Examples:
        >>> m = Map([(0, 0), (4, 0), (4, 4), (0, 4)], [[(1, 1), (2, 1), (2, 2), (1, 2)]])
        >>> m.n_vertices, int(m.vertex_convex.sum())
        (8, 4)
        >>> bool(m.contains([[0.5, 0.5]])[0]), bool(m.contains([[1.5, 1.5]])[0])
        (True, False)
    """

    def __init__(
        self,
        boundary: Sequence[Sequence[float]] | np.ndarray,
        obstacles: Sequence[Sequence[Sequence[float]] | np.ndarray] = (),
        *,
        name: str = "custom",
        merge: bool = False,
    ) -> None:
        try:
            self.name = validation.string("name", name)
            merge = validation.boolean("merge", merge)
        except InvalidConfigError as exc:
            raise InvalidMapError(str(exc)) from None
        b = _as_ring(boundary, "boundary")
        with np.errstate(over="ignore"):  # +-1e308 corners: an infinite extent, refused below
            ext = b.max(axis=0) - b.min(axis=0)
        span = math.hypot(float(ext[0]), float(ext[1]))  # no overflow nor underflow on the way
        if span <= 0:
            raise InvalidMapError("boundary: degenerate polygon (zero extent)")
        lo, hi = SIZE_RANGE
        if not lo <= span <= hi:
            raise InvalidMapError(
                f"boundary: the map's size (its bounding box's diagonal) is {span:.3g}; "
                f"expected one in [{lo:g}, {hi:g}]: the geometry squares squared lengths, "
                "which overflow or underflow float64 beyond (rescale it, e.g. NAME~xS)"
            )
        far = float(np.abs(b).max())
        if far * _EPS > REL_LENGTH_TOL * span:
            # a coordinate rounds by more than the geometry's length tolerance: walls,
            # line of sight and the decomposition cannot resolve the map any more
            raise InvalidMapError(
                f"boundary: a vertex lies {far:.4g} from the origin, {far / span:.3g} times "
                f"the map's size {span:.4g}: its coordinates round by {far * _EPS:.2g}, more "
                f"than the geometry's length tolerance {REL_LENGTH_TOL:g} x size = "
                f"{REL_LENGTH_TOL * span:.2g}; expected a map within "
                f"{REL_LENGTH_TOL / _EPS:.3g} times its size of the origin (shift it nearer, "
                "e.g. NAME~off(X,Y))"
            )
        self.scale = span
        b = _clean_ring(b, span, "boundary")
        if isinstance(obstacles, (str, bytes)) or not hasattr(obstacles, "__iter__"):
            raise InvalidMapError(
                f"obstacles: expected a sequence of polygons, got {type(obstacles).__name__} "
                f"{obstacles!r}"
            )
        lo_b, hi_b = b.min(axis=0), b.max(axis=0)
        far_out = REL_LENGTH_TOL / _EPS * span  # the far-from-origin rule's reach
        obs = []
        for i, o in enumerate(obstacles):
            ring = _as_ring(o, f"obstacle {i}")
            # a vertex far beyond the boundary's box is refused before the ring is cleaned:
            # cleaning one at +-1e308 overflowed and called the obstacle "degenerate
            # (fewer than 3 non-collinear vertices)"; nearer ones get shapely's verdict
            out = np.flatnonzero(((ring < lo_b - far_out) | (ring > hi_b + far_out)).any(axis=1))
            if len(out):
                k = int(out[0])
                raise InvalidMapError(
                    f"obstacle {i}: not inside the boundary (vertex {k} "
                    f"({ring[k, 0]:.4g}, {ring[k, 1]:.4g}) is over {far_out:.3g} beyond the "
                    f"boundary's bounds {tuple(float(v) for v in (*lo_b, *hi_b))})"
                )
            obs.append(_clean_ring(ring, span, f"obstacle {i}"))
        self.merged = bool(merge)
        self.boundary = b
        self.obstacles = tuple(obs)
        self._free = self._build_free_region(b, obs, merge)
        self._build_arrays()

    # ------------------------------------------------------------------ validation
    def _polygon(self, ring: np.ndarray, what: str) -> Polygon:
        poly = Polygon(ring)
        if not poly.is_valid or not poly.exterior.is_simple:
            reason = shapely.is_valid_reason(poly)
            raise InvalidMapError(f"{what}: polygon is not simple ({reason})")
        if poly.area <= (REL_LENGTH_TOL * self.scale) ** 2 * 1e3:
            raise InvalidMapError(f"{what}: degenerate polygon (area {poly.area:g})")
        return poly

    def _build_free_region(self, b: np.ndarray, obs: list[np.ndarray], merge: bool) -> Polygon:
        outer = self._polygon(b, "boundary")
        gap = REL_GAP_TOL * self.scale
        polys = [self._polygon(o, f"obstacle {i}") for i, o in enumerate(obs)]
        for i, p in enumerate(polys):
            if not outer.buffer(gap * 0.5).contains(p):
                where = "crosses it" if p.intersects(outer) else "lies outside it"
                raise InvalidMapError(
                    f"obstacle {i}: not inside the boundary ({where}; bounds {p.bounds}, "
                    f"boundary bounds {outer.bounds})"
                )
        if not merge:
            for i, p in enumerate(polys):
                if outer.exterior.distance(p) <= gap:
                    raise InvalidMapError(
                        f"obstacle {i}: touches the boundary (distance "
                        f"{outer.exterior.distance(p):g} <= gap tolerance {gap:g}); "
                        "merge it into the boundary or build the map with merge=True"
                    )
            tree = shapely.STRtree(polys)
            for i, p in enumerate(polys):
                for j in tree.query(p.buffer(gap)):
                    j = int(j)
                    if j > i and p.distance(polys[j]) <= gap:
                        # interiors meet: overlap; only boundaries (or a sub-tolerance gap): touch
                        overlap = p.relate_pattern(polys[j], "T********")
                        what = "overlaps" if overlap else "touches"
                        raise InvalidMapError(
                            f"obstacle {i} {what} obstacle {j} (distance "
                            f"{p.distance(polys[j]):g} <= gap tolerance {gap:g}); "
                            "build the map with merge=True to replace them by their union"
                        )
            return Polygon(outer.exterior.coords, [q.exterior.coords for q in polys])
        # merge: subtract the exact union, then an opening (erode, dilate by half the
        # gap tolerance, mitred so corners come back) removes slits thinner than the gap
        if not polys:
            return outer
        free = outer.difference(shapely.union_all(polys))
        if free.is_empty or free.area <= (REL_LENGTH_TOL * self.scale) ** 2 * 1e3:
            raise InvalidMapError(
                "merged map: the obstacles cover the whole boundary (no free space)"
            )
        free = free.buffer(-0.5 * gap, join_style="mitre").buffer(0.5 * gap, join_style="mitre")
        # snap to a power-of-ten grid about 10x the gap, so that (10 +- 1e-8) -> 10
        grid = 10.0 ** np.floor(np.log10(REL_GAP_TOL * self.scale * 10))
        free = shapely.set_precision(free, grid)
        if free.geom_type != "Polygon":
            parts = getattr(free, "geoms", [free])
            raise InvalidMapError(
                f"merged map: free space splits into {len(parts)} disconnected parts; "
                "the pursuer and evader need one connected free region"
            )
        return free

    def _build_arrays(self) -> None:
        free = shapely.orient_polygons(self._free, exterior_cw=False)
        rings = [np.asarray(free.exterior.coords)[:-1]]
        rings += [np.asarray(r.coords)[:-1] for r in free.interiors]
        rings = [_clean_ring(r, self.scale, f"ring {k}") for k, r in enumerate(rings)]
        # free space on the left: outer ring CCW, holes CW
        for k, r in enumerate(rings):
            area = _signed_area(r)
            if (k == 0) != (area > 0):
                rings[k] = r[::-1].copy()
        # canonical numbering: each ring starts at its lowest (x, y) vertex and the holes
        # are sorted, so the same world listed differently gets identical arrays (feature
        # indices in caches and kernels keyed by ``digest`` stay valid)
        rings = [_canonical_start(r) for r in rings]
        rings = [rings[0], *sorted(rings[1:], key=lambda r: tuple(r.ravel()))]
        self.rings: tuple[np.ndarray, ...] = tuple(rings)
        self._free = Polygon(rings[0], rings[1:])
        verts, vring, prev_e, next_e = [], [], [], []
        offset = 0
        for k, r in enumerate(rings):
            n = len(r)
            verts.append(r)
            vring.append(np.full(n, k))
            idx = np.arange(n)
            next_e.append(offset + idx)
            prev_e.append(offset + (idx - 1) % n)
            offset += n
        self.vertices = np.concatenate(verts)
        self.vertex_ring = np.concatenate(vring)
        self.vertex_next_edge = np.concatenate(next_e)
        self.vertex_prev_edge = np.concatenate(prev_e)
        nxt = np.concatenate(
            [
                offset_i + (np.arange(len(r)) + 1) % len(r)
                for offset_i, r in zip(
                    np.cumsum([0] + [len(r) for r in rings[:-1]]), rings, strict=True
                )
            ]
        )
        self.edge_start = self.vertices.copy()
        self.edge_end = self.vertices[nxt]
        self.edge_vertices = np.stack([np.arange(len(self.vertices)), nxt], axis=1)
        d = self.edge_end - self.edge_start
        self.edge_length = np.linalg.norm(d, axis=1)
        self.edge_dir = d / self.edge_length[:, None]
        self.edge_normal = np.stack([-self.edge_dir[:, 1], self.edge_dir[:, 0]], axis=1)
        self.edge_ring = self.vertex_ring.copy()
        din = self.edge_dir[self.vertex_prev_edge]
        dout = self.edge_dir[self.vertex_next_edge]
        turn = din[:, 0] * dout[:, 1] - din[:, 1] * dout[:, 0]
        self.vertex_convex = turn < 0
        for arr in (
            self.vertices,
            self.vertex_ring,
            self.vertex_next_edge,
            self.vertex_prev_edge,
            self.edge_start,
            self.edge_end,
            self.edge_vertices,
            self.edge_length,
            self.edge_dir,
            self.edge_normal,
            self.edge_ring,
            self.vertex_convex,
        ):
            arr.setflags(write=False)
        for r in self.rings:
            r.setflags(write=False)

    # ------------------------------------------------------------------ queries
    @property
    def n_vertices(self) -> int:
        """Number of wall vertices (= number of wall edges)."""
        return len(self.vertices)

    @property
    def n_edges(self) -> int:
        """Number of wall edges."""
        return len(self.edge_start)

    @functools.cached_property
    def bounds(self) -> tuple[float, float, float, float]:
        """``(xmin, ymin, xmax, ymax)`` of the boundary."""
        lo = self.rings[0].min(axis=0)
        hi = self.rings[0].max(axis=0)
        return (float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]))

    @functools.cached_property
    def diameter(self) -> float:
        """The largest distance between two points of the map: no rod longer than this
        fits anywhere (the largest distance between two vertices of the boundary's
        convex hull)."""
        return convex_diameter(self.rings[0])

    @property
    def free_region(self) -> Polygon:
        """The free region as a shapely polygon (for set-up code, not the hot path)."""
        return self._free

    @functools.cached_property
    def prepared_free_region(self) -> Polygon:
        """The free region, prepared for fast repeated shapely predicates."""
        poly = Polygon(self._free.exterior.coords, [r.coords for r in self._free.interiors])
        shapely.prepare(poly)
        return poly

    @property
    def convex_vertices(self) -> np.ndarray:
        """Indices of the convex obstacle vertices (corners the rod can wrap around)."""
        return np.flatnonzero(self.vertex_convex)

    def contains(self, points: np.ndarray | Sequence[Sequence[float]]) -> np.ndarray:
        """Return which points lie in the closed free region (even-odd rule over walls).

        Args:
            points: (k, 2) array of points.

        Returns:
            (k,) bool array.

        Raises:
            InvalidConfigError: a coordinate is NaN or infinite (numpy's comparisons
                read such a point as outside, which hid a position gone bad upstream).
        """
        return self._contains(_finite_points(points, "contains points"))

    def _contains(self, p: np.ndarray) -> np.ndarray:
        """:meth:`contains` of a finite (k, 2) float array."""
        step = self._chunk()
        if len(p) > step:  # bounded memory: (points x edges) temporaries a chunk at a time
            return np.concatenate([self._contains(p[s : s + step]) for s in range(0, len(p), step)])
        a = self.edge_start[None, :, :]
        b = self.edge_end[None, :, :]
        px = p[:, None, 0]
        py = p[:, None, 1]
        cond = (a[..., 1] > py) != (b[..., 1] > py)
        with np.errstate(divide="ignore", invalid="ignore"):
            xint = a[..., 0] + (py - a[..., 1]) * (b[..., 0] - a[..., 0]) / (b[..., 1] - a[..., 1])
        inside = np.count_nonzero(cond & (px < xint), axis=1) % 2 == 1
        return inside | (self._distance_to_walls(p) <= REL_LENGTH_TOL * self.scale)

    def _chunk(self) -> int:
        """Points per batch of :meth:`contains` / :meth:`distance_to_walls`: each builds a
        few (points x edges) float arrays, so a batch holds at most :data:`_PAIRS` pairs
        (the results are per point, so batching changes no value)."""
        return max(1, _PAIRS // len(self.edge_start))

    def distance_to_walls(self, points: np.ndarray | Sequence[Sequence[float]]) -> np.ndarray:
        """Euclidean distance from each point to the nearest wall edge.

        Raises:
            InvalidConfigError: a coordinate is NaN or infinite (the distance was nan or
                inf).
        """
        return self._distance_to_walls(_finite_points(points, "distance_to_walls points"))

    def _distance_to_walls(self, p: np.ndarray) -> np.ndarray:
        """:meth:`distance_to_walls` of a finite (k, 2) float array."""
        if self.n_edges >= _NEAR_EDGES and len(p) <= _CELL_POINTS:
            cells = self._cells_of(p)
            if cells is not None:
                return self._cell_distances(p, cells)
        if self.n_edges >= _NEAR_EDGES and len(p) * self.n_edges >= _NEAR_PAIRS:
            return self._near_distances(p)
        step = self._chunk()
        if len(p) > step:  # bounded memory (see _chunk)
            return np.concatenate(
                [self._distance_to_walls(p[s : s + step]) for s in range(0, len(p), step)]
            )
        rel = p[:, None, :] - self.edge_start[None, :, :]
        t = np.clip(np.einsum("kej,ej->ke", rel, self.edge_dir), 0.0, self.edge_length)
        closest = self.edge_start[None] + t[..., None] * self.edge_dir[None]
        return np.linalg.norm(p[:, None, :] - closest, axis=2).min(axis=1)

    @functools.cached_property
    def _edge_tree(self) -> shapely.STRtree:
        """The wall edges in a spatial index (their order: edge ids)."""
        ends = np.stack([self.edge_start, self.edge_end], axis=1)
        return shapely.STRtree(shapely.linestrings(ends))

    def _pair_distances(self, p: np.ndarray, e: np.ndarray) -> np.ndarray:
        """Distance from each point ``p[k]`` to edge ``e[k]``: :meth:`distance_to_walls`'
        formula, operation for operation (the same floats)."""
        return _segment_distances(p, self.edge_start[e], self.edge_dir[e], self.edge_length[e])

    def _near_distances(self, p: np.ndarray) -> np.ndarray:
        """:meth:`distance_to_walls` of (n, 2) points through the edges' index: for each
        point, the distance ``u`` to the edge the index finds nearest (by the same
        formula) bounds the least one, and every edge nearer lies in the box of half side
        ``u`` round the point; the least over the edges the index gives for that box (a
        few, not all) is the least over all edges, the same float (a minimum of the same
        values)."""
        tree = self._edge_tree
        # beyond the rounding of u (a few ulps of the coordinates)
        slack = 1e-9 * (self.scale + float(np.abs(self.edge_start).max()))
        out = np.empty(len(p))
        for s in range(0, len(p), _NEAR_CHUNK):
            q = p[s : s + _NEAR_CHUNK]
            i, j = tree.query_nearest(shapely.points(q), all_matches=False)
            r = np.empty(len(q))
            r[i] = self._pair_distances(q[i], j)
            r += slack
            boxes = shapely.box(q[:, 0] - r, q[:, 1] - r, q[:, 0] + r, q[:, 1] + r)
            a, e = tree.query(boxes)  # the edges whose bounding boxes meet the box
            least = np.full(len(q), np.inf)
            np.minimum.at(least, a, self._pair_distances(q[a], e))
            out[s : s + _NEAR_CHUNK] = least
        return out

    def nearest_wall_point(self, point: np.ndarray | Sequence[float]) -> tuple[np.ndarray, int]:
        """The closest point of the walls to ``point`` and its edge (the first of the
        nearest edges, by index).

        Measured against the few edges of the point's cell (:meth:`_cell_edges`), which
        hold every edge at the least distance from it: the same point and edge as
        against every edge, in the same arithmetic (on a 2700-edge floor plan ~0.09 ms
        against all of them).

        Raises:
            InvalidConfigError: ``point`` is not two finite coordinates.
        """
        p = np.asarray(point, dtype=float)
        if p.shape != (2,) or not np.isfinite(p).all():
            p = validation.point("nearest_wall_point point", point)  # raises
        cells = self._cells_of(p[None]) if self.n_edges >= _NEAR_EDGES else None
        if cells is None:
            e = None
            start, direction, length = self.edge_start, self.edge_dir, self.edge_length
        else:
            e, start, direction, length = self._cell_edges(*cells[0])
        rel = p[None, :] - start
        t = np.clip(np.einsum("ej,ej->e", rel, direction), 0.0, length)
        closest = start + t[:, None] * direction
        d = np.einsum("ej,ej->e", p - closest, p - closest)
        k = int(np.argmin(d))
        return closest[k], k if e is None else int(e[k])

    @functools.cached_property
    def _cell_size(self) -> float:
        """Side of the cells of :meth:`_cell_edges`: half the side of a square with the
        box's area per edge (~3.3 m on the floor plans of any size: a few edges a cell)."""
        x0, y0, x1, y1 = self.bounds
        return 0.5 * math.sqrt((x1 - x0) * (y1 - y0) / self.n_edges)

    @functools.cached_property
    def _cells(self) -> dict[tuple[float, float], tuple[np.ndarray, ...]]:
        return {}

    @functools.cached_property
    def _cell_origin(self) -> np.ndarray:
        return np.array(self.bounds[:2])

    def _cells_of(self, p: np.ndarray) -> list[tuple[float, float]] | None:
        """The cells (their integer coordinates, as floats) of (k, 2) finite points; None
        when one lies too far out for its cell's centre to be exact (then the caller
        measures against the index or every edge)."""
        if len(p) == 1:  # (most calls) the same arithmetic in Python floats
            x0, y0 = self.bounds[:2]
            s = self._cell_size
            i = math.floor((float(p[0, 0]) - x0) / s)
            j = math.floor((float(p[0, 1]) - y0) / s)
            return [(float(i), float(j))] if abs(i) < 2**40 and abs(j) < 2**40 else None
        c = np.floor((p - self._cell_origin) / self._cell_size)
        if not (np.abs(c) < 2.0**40).all():
            return None
        return list(zip(*c.T.tolist(), strict=True))

    def _cell_edges(
        self, i: float, j: float
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Edges (ascending) that hold, for every point of cell ``(i, j)`` (the square of
        side ``s = _cell_size`` at ``bounds[:2] + s (i, j)``), all its nearest edges, and
        their ``edge_start``, ``edge_dir`` and ``edge_length``.

        A point p of the square lies within its half diagonal ``r`` of the centre c, and
        the distance to an edge changes no faster than the point moves, so p's nearest
        edge e lies within ``d(c, e) <= d(p) + r <= d(c) + 2 r`` of c: the edges within
        ``u + 2 r`` of c, for the distance u to any edge (the one the index finds
        nearest), plus a slack far above the distances' rounding. Measured once a cell.
        """
        key = (i, j)
        cell = self._cells.get(key)
        if cell is None:
            self._build_cells([key])
            cell = self._cells[key]
        return cell

    def _build_cells(self, keys: list[tuple[float, float]]) -> None:
        """:meth:`_cell_edges` of several new cells at once, each index query one call for
        all of them (one cell at a time ~50 us, most of it per call: 4 cells 250 -> 150 us,
        8 cells 395 -> 175 on a 280-edge floor plan): the same centres, distances and
        reaches by the same arithmetic, so the same edges, kept as it keeps them."""
        s = self._cell_size
        x0, y0 = self.bounds[:2]
        ij = np.array(keys)
        c = np.stack([x0 + (ij[:, 0] + 0.5) * s, y0 + (ij[:, 1] + 0.5) * s], axis=1)
        tree = self._edge_tree
        at, near = tree.query_nearest(shapely.points(c), all_matches=False)
        nearest = np.empty(len(c), dtype=np.intp)
        nearest[at] = near
        u = self._pair_distances(c, nearest)
        slack = 1e-9 * (self.scale + float(np.abs(self.edge_start).max()) + np.abs(c).max(axis=1))
        reach = u + math.sqrt(2.0) * s + slack  # 2 r = the diagonal
        box = shapely.box(c[:, 0] - reach, c[:, 1] - reach, c[:, 0] + reach, c[:, 1] + reach)
        cid, e = tree.query(box)
        o = np.lexsort((e, cid))  # by cell, each cell's edges ascending
        cid, e = cid[o], e[o]
        keep = self._pair_distances(c[cid], e) <= reach[cid]
        cid, e = cid[keep], e[keep]
        bounds = np.searchsorted(cid, np.arange(len(c) + 1))
        for k, key in enumerate(keys):
            edges = e[bounds[k] : bounds[k + 1]]
            cell = (edges, self.edge_start[edges], self.edge_dir[edges], self.edge_length[edges])
            for a in cell:
                a.setflags(write=False)
            if len(self._cells) >= _CELLS_KEPT:
                self._cells.clear()
            self._cells[key] = cell

    def _cell_distances(self, p: np.ndarray, cells: list[tuple[float, float]]) -> np.ndarray:
        """:meth:`distance_to_walls` of (k, 2) points in ``cells`` (:meth:`_cells_of`):
        each against its cell's edges by :meth:`_pair_distances`, the least of the same
        floats as against every edge."""
        if len(p) == 1:
            _, start, direction, length = self._cell_edges(*cells[0])
            return _segment_distances(p, start, direction, length).min(keepdims=True)
        new = [key for key in dict.fromkeys(cells) if key not in self._cells]
        if len(new) > 1:  # (a block of nodes on new ground: its cells in one go)
            self._build_cells(new)
        edges = [self._cell_edges(i, j)[0] for i, j in cells]
        n = np.array([len(e) for e in edges])
        first = np.zeros(len(p), dtype=np.intp)
        np.cumsum(n[:-1], out=first[1:])
        d = self._pair_distances(np.repeat(p, n, axis=0), np.concatenate(edges))
        return np.minimum.reduceat(d, first)

    def describe(self, feature: Feature) -> str:
        """Human-readable description of a wall feature, e.g. ``"convex vertex 3 (1, 2)"``."""
        if feature.kind == "vertex":
            v = self.vertices[feature.index]
            kind = "convex" if self.vertex_convex[feature.index] else "concave"
            return f"{kind} vertex {feature.index} ({v[0]:.6g}, {v[1]:.6g})"
        a, b = self.edge_start[feature.index], self.edge_end[feature.index]
        return f"edge {feature.index} ({a[0]:.6g}, {a[1]:.6g})-({b[0]:.6g}, {b[1]:.6g})"

    # ------------------------------------------------------------------ identity
    def to_dict(self) -> dict:
        """Our JSON schema (``envs.maps.io``): name, boundary, obstacles, merge."""
        return {
            "name": self.name,
            "boundary": self.boundary.tolist(),
            "obstacles": [o.tolist() for o in self.obstacles],
            "merge": self.merged,
        }

    @functools.cached_property
    def digest(self) -> str:
        """SHA-256 of the wall geometry; equal maps have equal digests (cache keys).

        Independent of where each ring starts and of the order of the holes (the numbering
        is canonical), so the same world given with its polygons listed differently has the
        same digest and the same vertex and edge indices.
        """

        h = hashlib.sha256()
        for r in self.rings:  # rings are canonically numbered in _build_arrays
            h.update((np.ascontiguousarray(r, dtype="<f8") + 0.0).tobytes())  # -0.0 -> 0.0
            h.update(b"|")
        return h.hexdigest()

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Map) and self.digest == other.digest

    def __hash__(self) -> int:
        return hash(self.digest)

    def __repr__(self) -> str:
        return (
            f"Map(name={self.name!r}, rings={len(self.rings)}, vertices={self.n_vertices}, "
            f"bounds={tuple(round(v, 6) for v in self.bounds)})"
        )

    def __reduce__(self):  # pickles by value, so maps cross process boundaries
        return (_rebuild, (json.dumps(self.to_dict()),))

    # ------------------------------------------------------------------ transforms
    def transformed(
        self,
        matrix: np.ndarray | Sequence[Sequence[float]],
        offset=(0.0, 0.0),
        *,
        name: str | None = None,
    ) -> Map:
        """Return the map under ``x -> matrix @ x + offset`` (a similarity).

        Args:
            matrix: 2x2 linear part (rotation times uniform scale; a reflection is allowed).
            offset: translation.
            name: the new map's name (default: this map's).
        """
        try:
            m = validation.finite_array("transformed matrix", matrix, shape=(2, 2))
            o = validation.point("transformed offset", offset)
        except InvalidConfigError as exc:
            raise InvalidMapError(str(exc)) from None
        f = lambda r: r @ m.T + o
        return Map(
            f(self.boundary),
            [f(q) for q in self.obstacles],
            name=self.name if name is None else name,
            merge=self.merged,
        )


def _rebuild(payload: str) -> Map:
    d = json.loads(payload)
    return Map(d["boundary"], d["obstacles"], name=d["name"], merge=d.get("merge", False))
