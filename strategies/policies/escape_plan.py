"""Guaranteed escape plans from the exact decomposition K_L (Sec. 4, conditions (a)/(b)).

Every escapable cell kappa of K_L (:func:`strategies.cspace.decompose`) became escapable
at some round of the least fixed point of Sec. 4's definition, through some boundary
piece of its region R: round 0 by condition (a) (across the piece no cell is adjacent to
kappa), round r by condition (b) (across the piece every adjacent cell has a rank < r).
The pieces that qualify at the cell's own round are its *vias*. An evader whose
configuration lies in kappa walks, inside R, to the nearest point of a via and steps
across it; whatever orientation the pursuer then holds, the new cell has a smaller rank,
and at rank 0 the rod has no continuation: surveillance breaks (Sec. 4: "a guaranteed
escape path"). The cell keeps its identity while the evader stays in R (the rod cannot
jump across a wall), so the rank only falls.

The evader has a body: a via piece that runs closer to a wall than its radius everywhere
cannot be crossed. With a ``clearance`` the plan keeps the point evader's escapable cells
but ranks the routes round such pieces first (:func:`escape_ranks`'s ``narrow``).

Where some region carries only escapable cells (Prop. 2, ``Decomposition.witness_regions``)
an evader in a non-escapable cell first walks there: :attr:`EscapePlan.region_next` gives
the next grid point on a shortest grid walk.
"""

from __future__ import annotations

import functools
import heapq
import math
from dataclasses import dataclass

import numpy as np
import shapely

from envs.errors import InvalidConfigError
from envs.maps import Map
from strategies.cspace import Decomposition, decompose
from strategies.cspace.decomposition import largest_first
from strategies.cspace.tolerances import Tolerances
from strategies.policies.safety import SafetyTable, grid_points

__all__ = ["CROSS_REL", "EscapePlan", "Witness", "escape_plan", "escape_ranks"]

CROSS_REL = 1e-3
"""How far past a boundary piece (relative to L) a witness point lies."""

_SAMPLES = 64  # cands crossing points per boundary piece
_CLEAR_TOL = 1e-9  # beyond the rounding of a distance to the walls
_BFS_CHUNK = 1 << 15  # queued points whose neighbours _region_next scans at once


def escape_ranks(
    dec: Decomposition, narrow: frozenset[int] = frozenset()
) -> tuple[np.ndarray, tuple[tuple[int, ...], ...]]:
    """Rank and vias of every cell: the least fixed point of Sec. 4, by rounds.

    A pair (cell kappa, boundary piece b of kappa's region) is *satisfied* at round 0 if
    no cell is adjacent to kappa across b (condition (a)), at round r + 1 if every cell
    adjacent across b has rank <= r (condition (b)). A cell's rank is the first round at
    which one of its pairs is satisfied; its vias are the pieces satisfied then.

    Pieces in ``narrow`` (ones the evader's disc cannot cross; Sec. 4's evader is a
    point) cost more than any route of other crossings: a pair across one is satisfied
    ``n_cells + 1`` rounds after its last adjacent cell (condition (a): ``n_cells``), a
    weighted least fixed point (Knuth's generalisation of Dijkstra's algorithm to
    min-max costs). The escapable set is the same and every crossing of a via still
    lowers the rank; a rank below ``n_cells`` means a route round every narrow piece
    whatever the pursuer does, and then the vias take it. Without ``narrow`` the ranks
    are the rounds above.

    Returns:
        ``(rank, vias)``: (n_cells,) int64 ranks (-1 for a non-escapable cell) and, per
        cell, the ids of its via pieces (empty if not escapable).
    """
    n = len(dec.cells)
    big = n + 1
    across: dict[tuple[int, int], set[int]] = {}
    for c in dec.cells:
        for b in dec.regions[c.region].boundaries:
            across[(c.id, b)] = set()
    for b in dec.boundaries:
        for i, j in b.adjacent:
            across[(i, b.id)].add(j)
            across[(j, b.id)].add(i)
    count = {k: len(v) for k, v in across.items()}
    watchers: dict[int, list[tuple[int, int]]] = {}
    for key, nbrs in across.items():
        for x in nbrs:
            watchers.setdefault(x, []).append(key)
    rank = np.full(n, -1, dtype=np.int64)
    sat: dict[tuple[int, int], int] = {}  # pair -> round at which it is satisfied
    heap: list[tuple[int, int]] = []

    def ready(key: tuple[int, int], after: int) -> None:
        r = after + (big if key[1] in narrow else 1)
        sat[key] = r
        heapq.heappush(heap, (r, key[0]))

    for key in sorted(k for k, m in count.items() if m == 0):  # condition (a)
        ready(key, -1)
    while heap:
        r, c = heapq.heappop(heap)
        if rank[c] >= 0:
            continue
        rank[c] = r
        # condition (b): pairs whose last adjacent cell just became escapable (cells
        # become escapable in rank order, so that cell has the highest rank across)
        for key in watchers.get(c, ()):
            count[key] -= 1
            if count[key] == 0 and rank[key[0]] < 0:
                ready(key, r)
    vias: list[list[int]] = [[] for _ in range(n)]
    for (c, b), r in sorted(sat.items()):
        if r == rank[c]:
            vias[c].append(b)
    return rank, tuple(tuple(v) for v in vias)


def _samples(segments: np.ndarray, chord_tol: float) -> tuple[np.ndarray, ...]:
    """A piece's (m, 2, 2) ``segments`` without the empty ones: their starts,
    directions, lengths, unit directions, and samples along them (about ``_SAMPLES``,
    no closer than ``chord_tol``) with each sample's segment."""
    p0, p1 = segments[:, 0], segments[:, 1]
    d = p1 - p0
    ln = np.hypot(d[:, 0], d[:, 1])
    keep = ln > 0
    p0, d, ln = p0[keep], d[keep], ln[keep]
    u = d / ln[:, None]
    step = max(chord_tol, float(ln.sum()) / _SAMPLES)
    m = np.maximum(1, np.ceil(ln / step).astype(int))
    seg = np.repeat(np.arange(len(ln)), m)
    frac = (np.arange(int(m.sum())) - np.repeat(np.cumsum(m) - m, m) + 0.5) / m[seg]
    return p0, d, ln, u, p0[seg] + frac[:, None] * d[seg], seg


@dataclass(frozen=True)
class Witness:
    """Where an evader in an escapable cell goes next.

    Attributes:
        boundary: the via piece crossed.
        cross: (2,) the point of the piece the evader walks to.
        normal: (2,) unit normal there, pointing out of the cell's region.
        target: (2,) ``cross + CROSS_REL * L * normal``, just across the piece.
    """

    boundary: int
    cross: np.ndarray
    normal: np.ndarray
    target: np.ndarray


@dataclass(frozen=True, eq=False)
class EscapePlan:
    """Ranks and vias of the escapable cells of K_L, and the walk to a witness region.

    Attributes:
        dec: the decomposition.
        rank: (n_cells,) round of the fixed point at which the cell became escapable, -1
            if not escapable (with a clearance: :func:`escape_ranks`'s weighted rounds).
        vias: per cell, the boundary pieces that make it escapable at its rank.
        points: (n, 2) grid points (the rows of the matching eager ``SafetyTable``; none
            where the map has no witness region: nothing walks there).
        region: (n,) bool, the grid point lies in a witness region (Prop. 2).
        region_next: (n,) next grid point toward the nearest witness-region point (-1
            where none is reachable or the point is in a witness region).
        grid: the grid's nodes and their rows of ``points`` (:meth:`row`), or ``None``
            with no points.
    """

    dec: Decomposition
    rank: np.ndarray
    vias: tuple[tuple[int, ...], ...]
    points: np.ndarray
    region: np.ndarray
    region_next: np.ndarray
    grid: _PlanGrid | None = None

    def row(self, point: np.ndarray) -> int:
        """The row of ``points`` (and of ``region``, ``region_next``) of the grid point
        nearest to ``point``, or of the nearest free one around it (-1 if none): what the
        eager ``SafetyTable.row`` answers. Not a row of a distinct or lazy table: those
        number their rows otherwise (issue 13: the shooting evader looked up its walk to
        a witness region with its distinct table's rows, the wrong grid points)."""
        return -1 if self.grid is None else self.grid.row(point)

    @functools.cached_property
    def _pieces(self) -> dict[int, tuple[np.ndarray, ...]]:
        return {}

    def _piece(self, b: int) -> tuple[np.ndarray, ...]:
        """Boundary ``b``'s segment starts, directions, lengths, left normals (into A),
        and samples along the piece with their segment (computed on first use: a plan
        crosses few of the pieces)."""
        got = self._pieces.get(b)
        if got is not None:
            return got
        p0, d, ln, u, s, seg = _samples(self.dec.boundaries[b].segments, self.dec.chord_tol)
        got = (p0, d, ln, np.stack([-u[:, 1], u[:, 0]], axis=1), s, seg)
        self._pieces[b] = got
        return got

    @functools.cached_property
    def _keeps(self) -> dict[tuple[int, float], np.ndarray]:
        return {}

    def _keep(self, b: int, clearance: float) -> np.ndarray:
        """Which samples of piece ``b`` keep ``clearance`` from the walls (first use)."""
        got = self._keeps.get((b, clearance))
        if got is None:
            s = self._piece(b)[4]
            clear = self.dec.map.distance_to_walls(s) if len(s) else np.zeros(0)
            got = self._keeps[(b, clearance)] = clear >= clearance
        return got

    @functools.cached_property
    def _ends(self) -> dict[int, np.ndarray]:
        return {}

    def _end_distances(self, b: int) -> np.ndarray:
        """The distances to the walls of piece ``b``'s segments' starts, then ends."""
        got = self._ends.get(b)
        if got is None:
            p0, d = self._piece(b)[:2]
            got = self._ends[b] = self.dec.map.distance_to_walls(np.concatenate([p0, p0 + d]))
        return got

    @functools.cached_property
    def _spans(self) -> dict[tuple[int, float, float], tuple | None]:
        return {}

    def _span(self, b: int, clearance: float, margin: float) -> tuple | None:
        """What :meth:`witness` needs of piece ``b`` that does not depend on the evader's
        position (computed on first use): the segments' starts, directions, squared
        lengths, the bounds of the projection parameter that keep ``margin`` from the
        piece's ends (and which segments have such points, ``None`` without a margin),
        their left normals, per segment [room at its start, room at its end, length]
        (room: distance to the walls beyond ``clearance``), and the samples that keep
        ``clearance`` from the walls and ``margin`` from the ends, with their segments'
        normals. ``None`` for an empty piece."""
        key = (b, clearance, margin)
        if key in self._spans:
            return self._spans[key]
        p0, d, ln, nrm, s, seg = self._piece(b)
        got = None
        if len(ln):
            lo, hi, live = 0.0, 1.0, None
            ok = self._keep(b, clearance).copy()
            if margin > 0.0:
                # keep `margin` (arc length) from the piece's ends, where it meets other
                # pieces: a step across near an end can cross one of those instead (into
                # a cell of any rank). A piece shorter than 2 margins: its midpoint only.
                cum = np.r_[0.0, np.cumsum(ln)]  # the piece is a chain of its segments
                arc_lo, arc_hi = margin, cum[-1] - margin
                if arc_hi < arc_lo:
                    arc_lo = arc_hi = 0.5 * cum[-1]
                lo = np.clip((arc_lo - cum[:-1]) / ln, 0.0, 1.0)
                hi = np.clip((arc_hi - cum[:-1]) / ln, 0.0, 1.0)
                pos = cum[seg] + np.einsum("ij,ij->i", s - p0[seg], d[seg]) / ln[seg]
                ok &= (pos >= arc_lo - 1e-12) & (pos <= arc_hi + 1e-12)
                # none on segments wholly within a margin of an end
                live = (cum[:-1] <= arc_hi) & (cum[1:] >= arc_lo)
            ok = np.flatnonzero(ok)
            ln2, room = self._room(b, clearance)
            got = (p0, d, ln2, lo, hi, live, nrm, room, s[ok], nrm[seg[ok]])
        self._spans[key] = got
        return got

    @functools.cached_property
    def _rooms(self) -> dict[tuple[int, float], tuple[np.ndarray, list]]:
        return {}

    def _room(self, b: int, clearance: float) -> tuple[np.ndarray, list]:
        """Piece ``b``'s segments' squared lengths and, per segment, [room at its start,
        room at its end, length] (room: the distance to the walls less ``clearance``):
        the part of :meth:`_span` that does not depend on its margin (made once for
        both of :meth:`prepare`'s margins)."""
        got = self._rooms.get((b, clearance))
        if got is None:
            ln = self._piece(b)[2]
            ends = self._end_distances(b) - clearance
            room = np.stack([ends[: len(ln)], ends[len(ln) :], ln], axis=1).tolist()
            got = self._rooms[(b, clearance)] = (ln**2, room)
        return got

    @functools.cached_property
    def _polygons(self) -> dict:
        return {}

    def _polygon(self, region: int, offset: float = 0.0):
        """``region``'s polygon grown by ``offset`` (shrunk if negative), prepared for
        point and line tests (made on first use)."""
        poly = self._polygons.get((region, offset))
        if poly is None:
            poly = self.dec.regions[region].polygon
            poly = poly.buffer(offset) if offset else poly
            shapely.prepare(poly)
            self._polygons[(region, offset)] = poly
        return poly

    def _inside(self, region: int):
        """The region's polygon grown by a few polyline tolerances (for line tests)."""
        return self._polygon(region, 4.0 * self.dec.chord_tol + CROSS_REL * self.dec.L)

    def inside(self, region: int, point: np.ndarray) -> bool:
        """Whether ``point`` lies in ``region``'s polygon."""
        return bool(shapely.contains_xy(self._polygon(region), float(point[0]), float(point[1])))

    def well_inside(self, region: int, point: np.ndarray) -> bool:
        """Whether ``point`` lies in ``region`` farther than a few polyline tolerances from
        its boundary (then the configuration's cell cannot have changed since it was
        identified in that region: the rod cannot cross a wall; nearer, the exact curve
        may lie on either side of the polyline)."""
        poly = self._polygon(region, -4.0 * self.dec.chord_tol)
        return bool(shapely.contains_xy(poly, float(point[0]), float(point[1])))

    def well_inside_many(self, region: int, points: np.ndarray) -> np.ndarray:
        """(n,) bool: :meth:`well_inside` for each of ``points`` (n, 2)."""
        poly = self._polygon(region, -4.0 * self.dec.chord_tol)
        return shapely.contains_xy(poly, points[:, 0], points[:, 1])

    def prepare(self, clearance: float, margins: tuple[float, ...]) -> None:
        """Build now what :meth:`witness` (at ``clearance`` and each of ``margins``),
        :meth:`inside` and :meth:`well_inside` would otherwise build on first use: the
        spans of every escapable cell's vias, the polygons of the regions on either side
        of them, and every region's shrunk polygon (issue 13: built during an episode,
        they cost 1-2 ms in each decision that enters a new cell). The samples' wall
        clearance is tested in one batch, measured only near the walls
        (:func:`_clear_within`: the same test, a fraction of the time). Idempotent (cached
        on the plan)."""
        dec = self.dec
        esc = np.flatnonzero(self.rank >= 0).tolist()
        vias = sorted({b for c in esc for b in self.vias[c]})
        new = [b for b in vias if (b, clearance) not in self._keeps]
        if new:
            got = [self._piece(b) for b in new]
            counts = np.cumsum([len(g[4]) for g in got])[:-1]
            near = _clear_within(dec.map, np.concatenate([g[4] for g in got]), clearance)
            for b, keep in zip(new, np.split(near >= clearance, counts), strict=True):
                self._keeps[(b, clearance)] = keep
        new = [b for b in vias if b not in self._ends]
        if new:
            got = [self._piece(b)[:2] for b in new]
            counts = np.cumsum([2 * len(p0) for p0, _ in got])[:-1]
            pts = np.concatenate([x for p0, d in got for x in (p0, p0 + d)])
            # a segment's end is mostly the next one's start: each point measured once
            # (the same distances: a function of the point's value)
            pts, back = np.unique(pts, axis=0, return_inverse=True)
            dist = dec.map.distance_to_walls(pts)[back.ravel()] if len(pts) else np.zeros(0)
            for b, ends in zip(new, np.split(dist, counts), strict=True):
                self._ends[b] = ends
        for b in vias:
            for margin in margins:
                self._span(b, clearance, margin)
        grown = 4.0 * dec.chord_tol + CROSS_REL * dec.L  # (_inside's offset)
        self._polygons_at(sorted({dec.cells[c].region for c in esc}), grown)
        self._polygons_at(sorted({r for b in vias for r in dec.boundaries[b].regions}), 0.0)
        self._polygons_at(range(len(dec.regions)), -4.0 * dec.chord_tol)

    def _polygons_at(self, regions, offset: float) -> None:
        """:meth:`_polygon` of each of ``regions`` at ``offset``, buffered and prepared
        in one vectorised call each (the same polygons: a region's buffer is computed
        alone either way; one call at a time was 2.8 s of the shooting evader's reset on
        a 60 x 56 room with 210 pillars)."""
        todo = [r for r in regions if (r, offset) not in self._polygons]
        if not todo:
            return
        polys = np.array([self.dec.regions[r].polygon for r in todo], dtype=object)
        if offset:
            polys = shapely.buffer(polys, offset, quad_segs=16)
        shapely.prepare(polys)
        self._polygons.update(((r, offset), p) for r, p in zip(todo, polys.tolist(), strict=True))

    def cell_at(self, point: np.ndarray, theta: float) -> int:
        """The cell holding configuration ``(point, theta)``, -1 if none is identified."""
        c = self.dec.cell_at(float(point[0]), float(point[1]), float(theta))
        return -1 if c is None else c.id

    @functools.cached_property
    def _witness_region(self) -> np.ndarray:
        out = np.zeros(len(self.dec.regions), dtype=bool)
        out[list(self.dec.witness_regions)] = True
        return out

    def in_witness_region(self, cell: int) -> bool:
        """Whether ``cell``'s region is a witness region (False for ``cell`` -1)."""
        return cell >= 0 and bool(self._witness_region[self.dec.cells[cell].region])

    def witness(
        self,
        cell: int,
        point: np.ndarray,
        clearance: float = 0.0,
        exclude: frozenset[int] = frozenset(),
        margin: float = 0.0,
    ) -> Witness | None:
        """The crossing of one of ``cell``'s vias nearest to ``point``.

        Candidates are the point of each via piece nearest to ``point`` (projection onto
        the piece's polyline) and samples along the pieces, nearest first; a crossing
        must keep ``clearance`` from the walls (the evader's disc) and should land in the
        region across its piece (the point ``CROSS_REL * L`` across: near a piece's end
        it can lie across another piece, in a cell of any rank). The first candidate
        that lands across and is reachable in a straight line inside the cell's region
        is taken, else the first that lands across, else (none does) the first in a
        straight line, else the nearest one.

        Args:
            cell: the configuration's cell.
            point: the evader's position.
            clearance: the least distance from the walls of a usable crossing.
            exclude: via pieces not to use (ones the evader could not reach, or that
                would take it back where it came from).
            margin: the least arc length along the piece between a crossing and the
                piece's ends (the midpoint of a piece shorter than two margins).

        Returns:
            The :class:`Witness`, or ``None`` if the cell is not escapable or no crossing
            of its vias keeps ``clearance`` (the evader cannot carry the plan out).
        """
        if self.rank[cell] < 0:
            return None
        dec = self.dec
        reg = dec.cells[cell].region
        p = np.asarray(point, dtype=float)
        px, py = p[0], p[1]
        # (distance, boundary, points, normals, index, sign): the crossing is
        # points[index], the normal out of the region sign * normals[index]
        cands = []
        nearest = []  # the projections that may lie nearer the walls than `clearance`
        # (the samples keep it)
        for b in self.vias[cell]:
            if b in exclude:
                continue
            span = self._span(b, clearance, margin)
            if span is None:
                continue
            p0, d, ln2, lo, hi, live, nrm, room, s, s_nrm = span
            sign = 1.0 if dec.boundaries[b].regions[1] == reg else -1.0  # left normal -> A
            t = np.clip(np.einsum("ij,ij->i", p - p0, d) / ln2, lo, hi)
            q = p0 + t[:, None] * d
            dist = np.hypot(q[:, 0] - px, q[:, 1] - py)
            if live is not None:
                dist = np.where(live, dist, np.inf)
            k = int(np.argmin(dist))
            # the distance to the walls is 1-Lipschitz: q[k] keeps `clearance` if its
            # distance along the segment from either end is less than that end's room
            a, z, n = room[k]
            tk = float(t[k])
            if max(a - tk * n, z - (1.0 - tk) * n) <= _CLEAR_TOL:
                nearest.append(len(cands))
            cands.append((float(dist[k]), b, q, nrm, k, sign))
            ds = np.hypot(s[:, 0] - px, s[:, 1] - py)
            order = np.argsort(ds)[:8]
            cands.extend(
                (dj, b, s, s_nrm, j, sign)
                for dj, j in zip(ds[order].tolist(), order.tolist(), strict=True)
            )
        if not cands:
            return None
        if nearest:
            clear = dec.map.distance_to_walls(np.array([cands[i][2][cands[i][4]] for i in nearest]))
            for i in reversed(np.flatnonzero(clear < clearance).tolist()):
                del cands[nearest[i]]
            if not cands:
                return None  # every crossing is closer to a wall than the evader's disc allows
        cands.sort(key=lambda c: c[0])
        poly = self._inside(reg)
        step = CROSS_REL * dec.L

        def lands(c) -> bool:
            # the point just across lies in the region across the piece: near the
            # piece's ends (a junction of critical curves) it can lie across another
            # piece, in a cell of any rank (issue 13)
            pair = dec.boundaries[c[1]].regions
            q, n = c[2][c[4]], c[5] * c[3][c[4]]
            return self.inside(pair[0] if pair[1] == reg else pair[1], q + step * n)

        def direct(c) -> bool:
            return c[0] == 0.0 or shapely.covers(poly, shapely.LineString([p, c[2][c[4]]]))

        # nearest first: one that lands across and is in a straight line, else the
        # nearest that lands across, else (none lands) the first in a straight line
        fallback = None
        for c in cands:
            if lands(c):
                if direct(c):
                    break
                fallback = fallback or c
        else:
            c = fallback or next((c for c in cands if direct(c)), cands[0])
        _, b, pts, nrms, i, sign = c
        q, n = pts[i], sign * nrms[i]
        return Witness(int(b), q, n, q + step * n)


def _region_next(world: Map, cell: np.ndarray, pts: np.ndarray, h: float, region: np.ndarray):
    """Next hop on a shortest 8-neighbour grid walk to the region (breadth first).

    Two neighbouring grid points are joined when both keep more than half the step from
    the walls: the two discs of that radius are free and cover the segment between them.

    The search runs a level at a time over the grid's neighbour offsets, in the order of
    ``scipy.sparse.csgraph.breadth_first_order`` on the graph with the region's points
    joined to a source node ``n`` (how it was computed, with the same predecessors):
    the source's neighbours (the region's points) in index order, then each level's
    points in the order they were reached, each scanning its neighbours in index order,
    those of larger index first (the graph's rows), then those of smaller index (its
    transpose's rows), a point taking the first that reaches it as its next hop. The
    sparse graph's arrays took about 440 MB on a 200 m floor plan at L_min 3 (1.7
    million points), its peak memory; this holds a few arrays over the points.
    """
    n = len(pts)
    clear = _clear_within(world, pts, 0.5 * h * math.hypot(1, 1))
    nx, ny = cell.shape
    # the grid with a border of -1 (no node), flat: a node's neighbours are fixed offsets
    pad = np.full((nx + 2, ny + 2), -1, dtype=np.int32)
    pad[1:-1, 1:-1] = cell
    pad = pad.ravel()
    at = np.flatnonzero(pad >= 0)  # row k's flat index (rows are x-index major)
    # the neighbours in the scipy graph's order: rows (larger index), then the transpose
    # (smaller); x-index major, so (i, j + 1) < (i + 1, j - 1) < (i + 1, j) < (i + 1, j + 1)
    steps = ((0, 1), (1, -1), (1, 0), (1, 1), (-1, -1), (-1, 0), (-1, 1), (0, -1))
    offset = np.array([di * (ny + 2) + dj for di, dj in steps])
    kind = np.array([int(di != 0 and dj != 0) for di, dj in steps])  # 1: a diagonal
    # a point joins along an axis (kind 0) / a diagonal (1) when it keeps more than half
    # that step from the walls, and so does its neighbour
    ok = np.stack([clear > 0.5 * h, clear > 0.5 * h * math.hypot(1, 1)], axis=1)
    nxt = np.full(n, -1, dtype=np.int64)
    seen = region.copy()
    front = np.flatnonzero(region)
    while len(front):
        level = []
        # a slice of the queue at a time (a witness region can hold most of the grid's
        # points): the points the earlier slices reached are seen by the later ones
        for s in range(0, len(front), _BFS_CHUNK):
            parent = front[s : s + _BFS_CHUNK]
            nb = pad[at[parent][:, None] + offset]  # (parent in queue order, scan order)
            live = (nb >= 0) & ok[parent][:, kind]
            r, c = np.nonzero(live)
            live[r, c] = ok[nb[r, c], kind[c]]
            hops = np.where(live, nb, -1).ravel()
            got = np.flatnonzero(hops >= 0)
            got = got[~seen[hops[got]]]
            child, first = np.unique(hops[got], return_index=True)
            first = got[first]
            order = np.argsort(first, kind="stable")  # the queue: first reached, first out
            child, first = child[order], first[order]
            nxt[child] = parent[first // len(steps)]
            seen[child] = True
            level.append(child)
        front = np.concatenate(level)
    return nxt


def _clear_within(world: Map, pts: np.ndarray, reach: float) -> np.ndarray:
    """(n,) distance from each point to the walls (``Map.distance_to_walls``) where it
    may be at most ``reach``, ``inf`` elsewhere.

    Only the points within ``reach`` of a wall edge's bounding box (found by bisection on
    x) are measured: the others lie farther than ``reach`` from every edge. On office
    measuring every grid point was a third of the reset.
    """
    out = np.full(len(pts), np.inf)
    if not len(pts):
        return out
    reach += _CLEAR_TOL * world.scale
    order = np.argsort(pts[:, 0], kind="stable")
    xs, ys = pts[order, 0], pts[order, 1]
    lo = np.minimum(world.edge_start, world.edge_end) - reach
    hi = np.maximum(world.edge_start, world.edge_end) + reach
    first = np.searchsorted(xs, lo[:, 0], "left")
    last = np.searchsorted(xs, hi[:, 0], "right")
    near = np.zeros(len(pts), dtype=bool)
    for k in range(len(lo)):
        y = ys[first[k] : last[k]]
        near[first[k] : last[k]] |= (y >= lo[k, 1]) & (y <= hi[k, 1])
    idx = np.sort(order[near])
    for s in range(0, len(idx), 65536):
        out[idx[s : s + 65536]] = world.distance_to_walls(pts[idx[s : s + 65536]])
    return out


def _inside_any(pts: np.ndarray, polygons: list) -> np.ndarray:
    """(n,) bool: the point lies inside one of ``polygons`` (``shapely.contains_xy``),
    testing each polygon only on the points within its bounding box (found by
    bisection on x: on an evader-win map every region can be a witness, and testing
    all of them at every grid point took seconds at reset)."""
    out = np.zeros(len(pts), dtype=bool)
    if not polygons:
        return out
    order = np.argsort(pts[:, 0], kind="stable")
    xs, ys = pts[order, 0], pts[order, 1]
    for poly in polygons:
        x0, y0, x1, y1 = poly.bounds
        lo, hi = np.searchsorted(xs, x0, "left"), np.searchsorted(xs, x1, "right")
        k = lo + np.flatnonzero((ys[lo:hi] >= y0) & (ys[lo:hi] <= y1))
        out[order[k[shapely.contains_xy(poly, xs[k], ys[k])]]] = True
    return out


def _narrow(dec: Decomposition, clearance: float) -> frozenset[int]:
    """The boundary pieces no crossing of which keeps ``clearance`` from the walls: no
    sample along the piece (:meth:`EscapePlan.witness`'s samples) does.

    A piece whose middle vertex keeps ``clearance`` is not narrow: only the others are
    sampled (a few percent of them), their samples measured in one call (one a piece
    spent 22 s of the shooting evader's 74 s reset on a 200 m floor plan at L_min 3,
    below the walls' spatial index's batch size: the same distances). Only the points
    within ``clearance`` of a wall's box are measured (:func:`_clear_within`): the
    others keep it (the same tests; measuring every piece's middle vertex took 0.8 s of
    the reset on a 60 x 56 room with 210 pillars, 0.05 s so).
    """
    if clearance <= 0.0 or not dec.boundaries:
        return frozenset()
    world = dec.map
    mid = np.array([b.segments[len(b.segments) // 2, 0] for b in dec.boundaries])
    near = np.flatnonzero(_clear_within(world, mid, clearance) < clearance).tolist()
    samples = [_samples(dec.boundaries[i].segments, dec.chord_tol)[4] for i in near]
    if not samples:
        return frozenset()
    counts = [len(s) for s in samples]
    clear = _clear_within(world, np.concatenate(samples).reshape(-1, 2), clearance)
    out = []
    for i, n, d in zip(near, counts, np.split(clear, np.cumsum(counts)[:-1]), strict=True):
        if not n or d.max() < clearance:
            out.append(dec.boundaries[i].id)
    return frozenset(out)


def body_witness_regions(dec: Decomposition, clearance: float) -> tuple[int, ...]:
    """Prop. 2 for an evader with a body: the regions whose cells all escape by routes
    that cross only boundary pieces a disc of radius ``clearance`` can cross, largest
    first (``dec.witness_regions`` at clearance 0).

    Sec. 4's evader is a point. A crossing that comes closer to a wall than the body's
    radius everywhere along its piece (:func:`_narrow`) is not one the body can make; a
    cell escapes without one iff its weighted rank (:func:`escape_ranks`) is below
    ``n_cells``. Where no region qualifies, the theory's escape is open only to a point:
    an evader with this body wins, if at all, by beating the pursuer's bounded speed
    (issue 13: every world on which the shooting evader failed to escape in the
    evader benchmarks is such a world, for the 0.1 body of the benchmarks).
    """
    rank, _ = escape_ranks(dec, _narrow(dec, clearance))
    ok = (rank >= 0) & (rank < len(dec.cells))
    return largest_first(r for r in dec.regions if all(ok[c] for c in r.cells))


class _Held:
    """A decomposition handed to :func:`escape_plan`, equal to any other: not part of the
    plan cache's key (the plan of a map and rod length is the same whichever copy of its
    decomposition it is built on)."""

    __slots__ = ("dec",)

    def __init__(self, dec: Decomposition | None) -> None:
        self.dec = dec

    def __eq__(self, other: object) -> bool:
        return isinstance(other, _Held)

    def __hash__(self) -> int:
        return 0


def escape_plan(
    world: Map,
    L: float,
    resolution: float = 0.1,
    clearance: float = 0.0,
    dec: Decomposition | None = None,
) -> EscapePlan:
    """The :class:`EscapePlan` of ``world`` for a rod of length ``L`` (cached in memory,
    on the other arguments than ``dec``).

    The decomposition comes from :func:`strategies.cspace.decompose` (cached on disk), or
    is ``dec`` where the caller holds it already (the shooting evader's lazy table's: read
    back from the disk cache it took 0.9 s of the reset on a 200 m floor plan at L_min 3,
    with a second point-location grid, and a second copy in memory); the same plan (the
    cache's round trip is exact). The grid is the safety table's at the same
    ``resolution``. With ``clearance`` (the evader's body radius) the vias avoid the
    pieces no crossing of which keeps that distance from the walls wherever a route
    without them exists (:func:`escape_ranks`'s ``narrow``; issue 13: a rank-1 cell of
    random:polygons:0 whose only via runs within 0.094 of a wall, where the pursuer
    pinned the evader).

    Raises:
        InvalidConfigError: ``dec`` is not the decomposition of ``world`` at ``L`` (with
            the default polyline tolerance), naming what differs.
    """
    if dec is not None:
        chord = Tolerances.of(world, L).chord
        if dec.map != world or dec.L != L or dec.chord_tol != chord:
            raise InvalidConfigError(
                f"escape_plan(dec=...): the decomposition of map {dec.map.name!r} at L = "
                f"{dec.L:g}, chord_tol = {dec.chord_tol:g}: expected that of map "
                f"{world.name!r} at L = {L:g}, chord_tol = {chord:g}"
            )
    return _escape_plan(world, L, resolution, clearance, _Held(dec))


@functools.lru_cache(maxsize=8)
def _escape_plan(
    world: Map, L: float, resolution: float, clearance: float, held: _Held
) -> EscapePlan:
    dec = held.dec if held.dec is not None else decompose(world, L, cache=True)
    dec.region_grid()  # the point-location grid of cell_at, built here rather than mid-episode
    rank, vias = escape_ranks(dec, _narrow(dec, clearance))
    if not dec.witness_regions:
        # nothing to walk to: no grid (on the corridor at L_min 0.2 it was 8 of the
        # shooting evader's 8.6 s reset from a warm disk cache, issue 13)
        none = np.zeros(0, dtype=np.int64)
        return EscapePlan(dec, rank, vias, np.zeros((0, 2)), none.astype(bool), none)
    origin, cell, pts = grid_points(world, resolution)
    region = _inside_any(pts, [dec.regions[r].polygon for r in dec.witness_regions])
    if region.any():
        nxt = _region_next(world, cell, pts, resolution, region)
    else:
        nxt = np.full(len(pts), -1, dtype=np.int64)
    grid = _PlanGrid(origin, float(resolution), (int(cell.shape[0]), int(cell.shape[1])), cell)
    return EscapePlan(dec, rank, vias, pts, region, nxt, grid)


escape_plan.cache_clear = _escape_plan.cache_clear  # (tests: a plan no earlier one filled)


@dataclass(frozen=True, eq=False)
class _PlanGrid:
    """An escape plan's grid: node ``(i, j)`` at ``origin + resolution (i, j)`` is row
    ``cell[i, j]`` of the plan's points (-1 outside the free region), looked up as an
    eager :class:`~strategies.policies.safety.SafetyTable` is (the same grid and rows)."""

    origin: np.ndarray
    resolution: float
    shape: tuple[int, int]
    cell: np.ndarray

    rows = SafetyTable.rows
    row = SafetyTable.row
    _row_search = SafetyTable._row_search
