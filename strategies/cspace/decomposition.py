"""The cylindrical decomposition of Q_L, its connectivity graph G_L and escapable cells.

Sections 3-4 of the paper, THEORY.md 1.3:

* **regions**: faces of the exact arrangement of the semi-free critical curves
  (:mod:`strategies.cspace.arrangement`; faces with equal stops on both sides of a curve
  are one region), each checked noncritical at several points;
* **cells**: above each region, one cell per free arc at a sample point of the region,
  keyed by its stop pair ``(s-, s+)`` (constant over the region);
* **adjacency** across a boundary piece shared by regions R and R': at a point p of the
  piece's exact curve, the free arcs at ``p +- eps n`` are matched to the cells of R and R'
  by their stop pairs; two cells are adjacent iff their arcs overlap with positive length
  (the paper's footnote 3);
* **escapable cells**: the least fixed point of Sec. 4's recursive definition: kappa
  above R is escapable if across some boundary piece of R (not a wall: the evader cannot
  cross walls) (a) no cell is adjacent to kappa, or (b) every adjacent cell is escapable;
* **Prop. 2**: the evader wins if some region carries only escapable cells (a region
  with no free orientation at all counts: the rod cannot exist there). When no rod of
  length L fits anywhere in the map, :meth:`Decomposition.summary` says so.

The tolerances the result is exact up to are stated in :mod:`strategies.cspace.tolerances`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import networkx as nx
import numpy as np
import shapely
import shapely.ops
from shapely.geometry import Polygon

from envs.errors import InvalidConfigError
from envs.geometry import kernel_for
from envs.geometry.types import Arc, FreeArcs
from envs.maps.map import Map
from strategies.cspace._arcs import StopPair, pairs
from strategies.cspace.curves import CriticalCurve, _check_map, check_length
from strategies.cspace.tolerances import diameter, min_length

__all__ = [
    "Boundary",
    "Cell",
    "CellArc",
    "Decomposition",
    "Region",
    "decompose",
    "largest_first",
]


def largest_first(regions) -> tuple[int, ...]:
    """The ids of ``regions``, largest area first; areas equal to 1e-9 of the largest
    (mirror images, whose computed areas differ in the last bits) in id order, so that
    which of two mirror rooms comes first does not hang on rounding."""
    regions = list(regions)
    if not regions:
        return ()
    quantum = 1e-9 * max(r.area for r in regions)
    return tuple(r.id for r in sorted(regions, key=lambda r: (-round(r.area / quantum), r.id)))


@dataclass(frozen=True)
class Cell:
    """A free cell kappa = (R, [s-, s+]) above a region (Sec. 3).

    Attributes:
        id: index into ``Decomposition.cells`` (a node of ``graph``).
        region: the region R below it.
        stops: ``(s-, s+)``, the stops of its free arc (``(None, None)``: full circle).
        arc: its free arc at the region's sample point.
        escapable: whether it is an escapable cell (Sec. 4).
        reason: ``"a"`` (no adjacent cell across ``via``), ``"b"`` (every adjacent
            cell across ``via`` is escapable) or ``None``.
        via: the boundary piece across which the evader escapes, or ``None``.
    """

    id: int
    region: int
    stops: StopPair
    arc: Arc
    escapable: bool = False
    reason: str | None = None
    via: int | None = None


@dataclass(frozen=True, eq=False)
class Region:
    """A noncritical region R.

    Attributes:
        id: index into ``Decomposition.regions``.
        polygon: its polygon (arcs and conchoids as polylines).
        point: a sample point well inside it.
        cells: ids of the cells above it.
        boundaries: ids of its boundary pieces shared with other regions.
    """

    id: int
    polygon: Polygon = field(repr=False)
    point: np.ndarray = field(repr=False)
    cells: tuple[int, ...]
    boundaries: tuple[int, ...]

    @property
    def area(self) -> float:
        """Area of the region's polygon."""
        return float(self.polygon.area)


@dataclass(frozen=True, eq=False)
class Boundary:
    """A boundary piece between two regions, on one or more critical curves.

    Attributes:
        id: index into ``Decomposition.boundaries``.
        regions: ``(A, B)``; ``normal`` points from B into A.
        curves: indices into ``Decomposition.curves``.
        segments: (m, 2, 2) its noded segments.
        point: the probe point on the exact curve.
        normal: unit normal at ``point`` pointing into A.
        adjacent: pairs ``(cell of A, cell of B)`` whose arcs overlap across it.
        resolved: False if the probe arcs could not be matched to the regions' cells
            by their stops (then matched by overlap; see ``Decomposition.unresolved``).
    """

    id: int
    regions: tuple[int, int]
    curves: tuple[int, ...]
    segments: np.ndarray = field(repr=False)
    point: np.ndarray = field(repr=False)
    normal: np.ndarray = field(repr=False)
    adjacent: tuple[tuple[int, int], ...]
    resolved: bool = True


@dataclass(frozen=True)
class CellArc:
    """A free arc at a query point with the cell it belongs to.

    Attributes:
        arc: the free arc at the point.
        cell: the cell's id, or ``None`` if it could not be identified.
        escapable: whether that cell is escapable (``None`` if unidentified).
    """

    arc: Arc
    cell: int | None
    escapable: bool | None


class Decomposition:
    """The decomposition K_L of the configuration space slice Q_L (Secs. 3-4).

    Build it with :func:`decompose`. Answers point queries (which cell holds a
    configuration, the free and the safe arcs at a point) and the Prop. 2 verdict.

    Attributes:
        map: the world.
        L: rod length.
        curves: the semi-free critical curves (walls included).
        regions: the noncritical regions.
        cells: the free cells, ``cells[i].id == i``.
        boundaries: boundary pieces between regions.
        graph: the connectivity graph G_L (networkx) over cell ids; node attributes
            ``region``, ``stops``, ``escapable``; edge attribute ``boundaries``.
        chord_tol: polyline tolerance of arcs and conchoids.
        unresolved: number of boundary pieces matched by overlap, not stops (0 unless
            the arrangement is not exact; a warning says so when it happens).
        stats: counts from the build: ``vertices``, ``edges``, ``faces`` of the
            arrangement, ``merged_faces`` (neighbours with equal stops),
            ``slivers`` (faces too thin to probe), and the exactness checks, all 0 on
            a sound build: ``dangling`` (curve pieces with one face on both sides),
            ``orphan_holes``, ``noncritical_violations`` (check points whose stops are
            not their region's), ``slivers_unresolved``, ``unresolved_passages`` (1 if
            the map has a passage narrower than the tolerances resolve,
            :attr:`.tolerances.Tolerances.unresolved`).
        timings: seconds spent in each phase of the build (empty when loaded).
    """

    def __init__(
        self,
        world: Map,
        L: float,
        curves: tuple[CriticalCurve, ...],
        regions: tuple[Region, ...],
        cells: tuple[Cell, ...],
        boundaries: tuple[Boundary, ...],
        chord_tol: float,
        stats: dict[str, int] | None = None,
    ) -> None:
        self.map = world
        self.L = L
        self.curves = curves
        self.regions = regions
        self.cells = cells
        self.boundaries = boundaries
        self.chord_tol = chord_tol
        self.unresolved = sum(not b.resolved for b in boundaries)
        self.stats = dict(stats or {})
        self.timings: dict[str, float] = {}
        self._graph: nx.Graph | None = None
        self._index()

    @property
    def graph(self) -> nx.Graph:
        """The connectivity graph G_L (networkx), built on first use.

        Nodes are cell ids with attributes ``region``, ``stops``, ``escapable``; an edge
        joins adjacent cells, with attribute ``boundaries`` (the pieces across which).
        """
        if self._graph is None:
            g = nx.Graph()
            for c in self.cells:
                g.add_node(c.id, region=c.region, stops=c.stops, escapable=c.escapable)
            for b in self.boundaries:
                for i, j in b.adjacent:
                    if g.has_edge(i, j):
                        g.edges[i, j]["boundaries"].append(b.id)
                    else:
                        g.add_edge(i, j, boundaries=[b.id])
            self._graph = g
        return self._graph

    @property
    def n_adjacencies(self) -> int:
        """Number of adjacent cell pairs (edges of G_L), without building the graph."""
        return len({(min(i, j), max(i, j)) for b in self.boundaries for i, j in b.adjacent})

    # ------------------------------------------------------------------ indexing
    def _index(self) -> None:
        self._tree = shapely.STRtree([r.polygon for r in self.regions])
        self._cell_of: list[dict[StopPair, int]] = [
            {self.cells[c].stops: c for c in r.cells} for r in self.regions
        ]
        nb: list[set[int]] = [set() for _ in self.regions]
        for b in self.boundaries:
            a, c = b.regions
            nb[a].add(c)
            nb[c].add(a)
        self._neighbours = [tuple(sorted(s)) for s in nb]
        self._kernel = kernel_for(self.map)
        self._grid: _RegionGrid | None = None

    def region_grid(self) -> _RegionGrid:
        """The uniform grid that answers most :meth:`locate` queries without the tree
        (built on first use, a few tens of ms on the largest built-in maps; see
        :class:`_RegionGrid`)."""
        if self._grid is None:
            self._grid = _RegionGrid.build(self)
        return self._grid

    def __getstate__(self) -> dict:
        state = self.__dict__.copy()
        for k in ("_tree", "_cell_of", "_neighbours", "_kernel", "_graph", "_grid"):
            state.pop(k, None)
        return state

    def __setstate__(self, state: dict) -> None:
        self.__dict__.update(state)
        self._graph = None
        self.timings = getattr(self, "timings", {})
        self._index()

    # ------------------------------------------------------------------ verdict
    @property
    def rod_fits(self) -> bool:
        """Whether a rod of length L fits somewhere in the map (some cell exists)."""
        return bool(self.cells)

    @property
    def exact(self) -> bool:
        """Whether every exactness check of the build passed (see ``stats``)."""
        return not self.unresolved and not any(self.stats.get(k) for k in _CHECKS)

    @property
    def escapable(self) -> frozenset[int]:
        """Ids of the escapable cells."""
        return frozenset(c.id for c in self.cells if c.escapable)

    @property
    def witness_regions(self) -> tuple[int, ...]:
        """Regions whose cylinder holds only escapable cells (Prop. 2), largest first.

        Areas equal to 1e-9 of the largest (mirror images, whose computed areas differ in
        the last bits) are in id order: which of two rooms comes first no longer hangs on
        rounding (at L = 2 the two_rooms' middles have areas 36.021165555610615 and
        36.02116555561061, and Fig. 6's evader walked to whichever came first).
        """
        return largest_first(
            [r for r in self.regions if all(self.cells[c].escapable for c in r.cells)]
        )

    @property
    def evader_wins(self) -> bool:
        """Prop. 2: some region carries only escapable cells (an infinitely fast pursuer
        with this fixed L cannot keep surveillance)."""
        return bool(self.witness_regions)

    @property
    def witness_region(self) -> Region | None:
        """The largest region with only escapable cells, or ``None`` if the pursuer wins."""
        w = self.witness_regions
        return self.regions[w[0]] if w else None

    # ------------------------------------------------------------------ queries
    def locate(self, point) -> int | None:
        """The region containing ``point`` (nearest region within the polyline tolerance),
        or ``None`` outside the free region.

        Raises:
            InvalidConfigError: ``point`` is not a finite (x, y) pair.
        """
        p = _point(point)
        r = self.region_grid().region(float(p[0]), float(p[1]))
        return self._locate_tree(p) if r < 0 else r

    def _locate_tree(self, p: np.ndarray) -> int | None:
        """:meth:`locate` of a checked point through the region tree (no grid)."""
        pt = shapely.Point(p)
        hits = self._tree.query(pt, predicate="intersects")
        if len(hits):
            return int(hits[0])
        if not self._kernel.contains_point(float(p[0]), float(p[1])):
            return None
        near = self._tree.nearest(pt)
        return None if near is None else int(near)

    @property
    def neighbours(self) -> list[tuple[int, ...]]:
        """Each region's neighbours (the regions it shares a boundary with), sorted."""
        return self._neighbours

    def _match(self, region: int | None, fa: FreeArcs) -> list[int | None]:
        """Cells of the arcs at a point located in ``region`` (neighbours as fallback)."""
        if region is None:
            return [None] * len(fa.arcs)
        keys = pairs(fa)
        cands = (region, *self._neighbours[region])
        for r in cands:
            table = self._cell_of[r]
            if len(table) == len(keys) and all(k in table for k in keys):
                return [table[k] for k in keys]
        out: list[int | None] = []
        for k in keys:
            out.append(next((self._cell_of[r][k] for r in cands if k in self._cell_of[r]), None))
        return out

    def free_arcs(self, point) -> tuple[CellArc, ...]:
        """The free arcs at ``point`` with their cells and escapability.

        Raises:
            InvalidConfigError: ``point`` is not a finite (x, y) pair.
        """
        p = _point(point)
        fa = self._kernel.free_arcs(p, self.L)
        ids = self._match(self.locate(p), fa)
        return tuple(
            CellArc(a, i, None if i is None else self.cells[i].escapable)
            for a, i in zip(fa.arcs, ids, strict=True)
        )

    def safe_arcs(self, point) -> tuple[Arc, ...]:
        """The free arcs at ``point`` whose cells are not escapable (where the pursuer
        must keep the rod)."""
        return tuple(ca.arc for ca in self.free_arcs(point) if ca.escapable is False)

    def cell_at(self, x: float, y: float, theta: float) -> Cell | None:
        """The cell holding configuration ``(x, y, theta)``, or ``None`` if not free.

        Raises:
            InvalidConfigError: non-finite or non-numeric ``x``, ``y`` or ``theta``.
        """
        p = _point((x, y), "(x, y)")
        theta = _angle(theta)
        fa = self._kernel.free_arcs(p, self.L)
        k = fa.arc_index(theta)
        if k is None:
            return None
        i = self._match(self.locate(p), fa)[k]
        return None if i is None else self.cells[i]

    def region_cells(self, region: int) -> tuple[Cell, ...]:
        """The cells above a region."""
        return tuple(self.cells[c] for c in self.regions[region].cells)

    def summary(self) -> str:
        """A few lines describing the decomposition and its verdict."""
        types = np.bincount([c.type for c in self.curves], minlength=6)
        n_esc = sum(c.escapable for c in self.cells)
        lines = [
            f"decomposition of {self.map.name!r} at L = {self.L:g}",
            "  critical curves by type 0-5: " + ", ".join(str(int(t)) for t in types),
            f"  {len(self.regions)} regions, {len(self.cells)} cells, "
            f"{self.n_adjacencies} adjacencies, {n_esc} escapable cells",
        ]
        if not self.exact:
            bad = {k: v for k, v in self.stats.items() if v and k in _CHECKS}
            if self.unresolved:
                bad["matched by overlap only"] = self.unresolved
            lines.append("  NOT EXACT: " + ", ".join(f"{k} {v}" for k, v in bad.items()))
        w = self.witness_region
        if not self.rod_fits:
            lines.append(
                f"  verdict: no rod of length L = {self.L:g} fits anywhere in this map "
                f"(its diameter is {diameter(self.map):.4g}): every position and "
                "orientation is blocked, so surveillance at this distance is impossible"
            )
        else:
            # a verdict from an inexact arrangement can be wrong (one unmatched piece
            # makes a cell escapable by condition (a)): say so on the verdict's line
            head = "  verdict" if self.exact else "  verdict (UNRELIABLE: not exact, see above)"
            if w is None:
                lines.append(f"{head}: every region has a non-escapable cell: the pursuer can hold")
            else:
                x, y = w.point
                lines.append(
                    f"{head}: the evader wins (Prop. 2); witness region {w.id} "
                    f"near ({x:.3g}, {y:.3g})"
                )
        return "\n".join(lines)

    def __repr__(self) -> str:
        return (
            f"Decomposition(map={self.map.name!r}, L={self.L:g}, regions={len(self.regions)}, "
            f"cells={len(self.cells)}, evader_wins={self.evader_wins})"
        )


_GRID_PER_REGION = 16  # grid squares per region, on average, of the locate grid
_GRID_MAX = 1 << 20  # at most this many squares


@dataclass(frozen=True, eq=False)
class _RegionGrid:
    """A uniform grid over the regions for :meth:`Decomposition.locate`.

    Every square (grown by ``pad`` on every side, which covers the rounding of a
    point's square index) keeps the regions whose polygons may meet it: those whose
    boundary segments pass within ``2 pad`` of it, and those holding its centre (a
    polygon whose boundary misses the square and which holds its centre holds all of
    it; one that holds neither misses it). A square that no boundary meets is labelled
    with the region holding its centre, if exactly one does.

    :meth:`region` answers only what the region tree would
    (:meth:`Decomposition._locate_tree`: the first polygon intersecting the point): a
    labelled square's region, else the one candidate whose polygon intersects the point
    if exactly one does (then no other polygon does: it would be a candidate). Where
    none or several do, or an invalid polygon is near, it answers -1 and ``locate`` asks
    the tree.

    Attributes:
        origin: (x0, y0) corner of square (0, 0).
        h: side of a square.
        labels: (nx, ny) int32 region of each square, -1 if not labelled, -2 near an
            invalid polygon (ask the tree).
        start, cand: the candidates of flat square k are ``cand[start[k]:start[k + 1]]``.
        polygons: the regions' polygons (prepared).
    """

    origin: tuple[float, float]
    h: float
    labels: np.ndarray
    start: np.ndarray
    cand: np.ndarray
    polygons: np.ndarray

    @classmethod
    def build(cls, dec: Decomposition) -> _RegionGrid:
        from scipy import ndimage

        polys = np.array([r.polygon for r in dec.regions], dtype=object)
        if not len(polys):
            z = np.zeros(0, dtype=np.int64)
            return cls((0.0, 0.0), 1.0, np.full((0, 0), -1, dtype=np.int32), z, z, polys)
        x0, y0, x1, y1 = (float(v) for v in shapely.total_bounds(polys))
        w, ht = max(x1 - x0, 1e-9), max(y1 - y0, 1e-9)
        h = math.sqrt(w * ht / min(_GRID_PER_REGION * len(polys), _GRID_MAX))
        nx, ny = math.ceil(w / h) + 1, math.ceil(ht / h) + 1
        pad = 1e-9 * max(w, ht, abs(x0), abs(y0), abs(x1), abs(y1), 1.0)

        def squares(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
            # flat indices of the squares meeting the boxes [lo, hi] grown by 2 pad
            # (each box at most two squares wide: its corners' squares are all of them)
            i0 = np.floor((lo[:, 0] - 2 * pad - x0) / h).astype(np.int64)
            j0 = np.floor((lo[:, 1] - 2 * pad - y0) / h).astype(np.int64)
            i1 = np.floor((hi[:, 0] + 2 * pad - x0) / h).astype(np.int64)
            j1 = np.floor((hi[:, 1] + 2 * pad - y0) / h).astype(np.int64)
            i0, i1 = np.clip(i0, 0, nx - 1), np.clip(i1, 0, nx - 1)
            j0, j1 = np.clip(j0, 0, ny - 1), np.clip(j1, 0, ny - 1)
            return np.stack([i * ny + j for i in (i0, i1) for j in (j0, j1)], axis=1)

        valid = shapely.is_valid(polys)
        ids = np.flatnonzero(valid)
        rings, owner = shapely.get_rings(polys[valid], return_index=True)
        rings = shapely.segmentize(rings, 0.25 * h)
        xy, ring = shapely.get_coordinates(rings, return_index=True)
        same = ring[1:] == ring[:-1]
        a, b = xy[:-1][same], xy[1:][same]
        sq = squares(np.minimum(a, b), np.maximum(a, b))
        m = len(polys)  # (square, region) pairs as square * m + region
        pairs = np.unique(sq * m + ids[owner[ring[:-1][same]]][:, None])
        hit = np.zeros(nx * ny, dtype=bool)
        hit[pairs // m] = True
        lost = np.zeros(nx * ny, dtype=bool)  # near an invalid polygon: ask the tree
        for p in polys[~valid]:
            bx0, by0, bx1, by1 = p.bounds
            i0, j0 = (max(0, math.floor((v - 2 * pad - o) / h)) for v, o in ((bx0, x0), (by0, y0)))
            i1, j1 = (math.floor((v + 2 * pad - o) / h) for v, o in ((bx1, x0), (by1, y0)))
            lost.reshape(nx, ny)[i0 : i1 + 1, j0 : j1 + 1] = True
        # squares joined by a side, none met by a boundary: inside the same polygons
        comp, n = ndimage.label(~(hit | lost).reshape(nx, ny))
        comp = comp.ravel()
        rep = np.full(n + 1, -1, dtype=np.int64)
        free = np.flatnonzero(comp)
        rep[comp[free[::-1]]] = free[::-1]  # the first square of each component
        # the centres of the met squares and of one square per component
        asked = np.concatenate([np.flatnonzero(hit), rep[1:]])
        ci, cj = np.divmod(asked, ny)
        centres = shapely.points(x0 + (ci + 0.5) * h, y0 + (cj + 0.5) * h)
        pt, reg = dec._tree.query(centres, predicate="intersects")
        n_hit = int(hit.sum())
        held = np.bincount(pt, minlength=len(asked))[n_hit:]
        labels_c = np.full(n + 1, -1, dtype=np.int32)
        one = pt >= n_hit
        one &= held[np.maximum(pt - n_hit, 0)] == 1
        labels_c[pt[one] - n_hit + 1] = reg[one]
        labels = labels_c[comp]
        labels[comp == 0] = -1
        labels[lost] = -2
        # candidates of the met squares: their boundaries' regions and centres' holders
        inner = pt < n_hit
        both = np.unique(np.concatenate([pairs, asked[pt[inner]] * m + reg[inner]]))
        start = np.searchsorted(both // m, np.arange(nx * ny + 1)).astype(np.int64)
        shapely.prepare(polys)
        return cls((x0, y0), h, labels.reshape(nx, ny), start, both % m, polys)

    def region(self, x: float, y: float) -> int:
        """The region the tree would answer for ``(x, y)``, or -1 (then ask the tree)."""
        i = math.floor((x - self.origin[0]) / self.h)
        j = math.floor((y - self.origin[1]) / self.h)
        nx, ny = self.labels.shape
        if not (0 <= i < nx and 0 <= j < ny):
            return -1
        r = int(self.labels[i, j])
        if r != -1:
            return max(r, -1)  # -2: near an invalid polygon
        k = i * ny + j
        s, e = int(self.start[k]), int(self.start[k + 1])
        if s == e:
            return -1
        c = self.cand[s:e]
        got = np.flatnonzero(shapely.intersects_xy(self.polygons[c], x, y))
        return int(c[got[0]]) if len(got) == 1 else -1


_CHECKS = (
    "dangling",
    "orphan_holes",
    "noncritical_violations",
    "slivers_unresolved",
    "unresolved_passages",
)


def _point(point: object, what: str = "point") -> np.ndarray:
    """``point`` as a finite float (x, y) array, or InvalidConfigError naming it."""
    try:
        p = np.asarray(point, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InvalidConfigError(f"{what} = {point!r}: expected a finite (x, y) point") from exc
    if p.shape != (2,) or not np.all(np.isfinite(p)):
        raise InvalidConfigError(f"{what} = {point!r}: expected a finite (x, y) point")
    return p


def _angle(theta: object) -> float:
    """``theta`` as a finite float, or InvalidConfigError naming it."""
    try:
        t = float(theta)
    except (TypeError, ValueError) as exc:
        raise InvalidConfigError(f"theta = {theta!r}: expected a finite angle") from exc
    if not np.isfinite(t):
        raise InvalidConfigError(f"theta = {theta!r}: expected a finite angle")
    return t


def decompose(
    map: Map,
    L: float,
    *,
    chord_tol: float | None = None,
    cache: bool = False,
    cache_dir=None,
    progress: bool | None = None,
    memory_budget: float | str | None = None,
) -> Decomposition:
    """The decomposition K_L of the slice Q_L for rod length ``L`` (Secs. 3-4).

    Args:
        map: the world.
        L: rod length (the surveillance distance), > 0.
        chord_tol: polyline tolerance of arcs and conchoids (default
            ``CHORD_TOL_REL * L``).
        cache: read and write the on-disk cache (:mod:`strategies.cspace.cache`).
        cache_dir: cache directory (default ``$SURVEIL_CACHE_DIR`` or ``~/.cache/surveil``).
        progress: show a progress bar on standard error (``None``: when the build is
            estimated to take more than a few seconds and standard error is a terminal).
        memory_budget: refuse, before starting, a build estimated to need more memory
            (bytes, or ``"2GB"``; default ``$SURVEIL_MEMORY_BUDGET`` or half the RAM).

    Returns:
        The :class:`Decomposition`.

    Raises:
        InvalidConfigError: for a non-map or a bad ``L`` / ``chord_tol`` / budget, or an
            ``L`` shorter than the map's tolerances resolve (:func:`.tolerances.min_length`).
        InfeasibleError: if the build would exceed the memory budget (the message gives
            the estimate and how to change it).
    """
    from strategies.memory import memory_budget as _budget

    world = _check_map(map)
    L = check_length(L)
    if L < min_length(world):
        raise InvalidConfigError(
            f"L = {L:g}: too short to decompose on map {world.name!r}: expected L >= "
            f"{min_length(world):.3g} (its diameter {diameter(world):.4g} times "
            f"{min_length(world) / diameter(world):.2g}; the geometry's tolerances are "
            "relative to the map's size)"
        )
    if chord_tol is not None:
        chord_tol = check_length(chord_tol, "chord_tol")
    if progress is not None and not isinstance(progress, bool):
        raise InvalidConfigError(f"progress = {progress!r}: expected True, False or None")
    budget = _budget(memory_budget)

    def build() -> Decomposition:
        return _build(world, L, chord_tol, progress, budget)

    if cache:
        from strategies.cspace.cache import cached_decomposition

        return cached_decomposition(world, L, chord_tol=chord_tol, cache_dir=cache_dir, build=build)
    return build()


def _build(world: Map, L: float, chord_tol, progress: bool | None, budget: float):
    from strategies.cspace._budget import check_budget
    from strategies.cspace._build import build_decomposition
    from strategies.cspace._progress import Progress

    show = progress
    if L < diameter(world):
        est = check_budget(world, L, budget)
        if show is None and est.seconds < 5.0:
            show = False
    bar = Progress(show, label=f"decompose {world.name} L={L:g}")
    return build_decomposition(world, L, chord_tol, bar)
