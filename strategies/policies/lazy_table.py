"""A safety table filled on demand, for maps too large to tabulate up front.

:func:`strategies.policies.safety.safety_table` classifies every grid point of the map
when it is built: on a 200 m x 200 m floor plan at L_min = 3 that is 1.7 million points,
about 1 GB and 200 s. A pursuer only ever looks at the points around the evader (its
probes reach ``V_e pi / omega``), so :class:`LazySafetyTable` has the same grid, the
same rows and the same answers as the eager table, but classifies a grid point the first
time a lookup touches it (the points new to a lookup in one vectorised batch,
:func:`~strategies.policies._batch_classify.classify_points`: ~0.2 ms a batch and ~1 us
a point more, so a caller that knows where it looks next passes those points too,
``rows(points, step, steps)``) and keeps it. Ready as soon as the decomposition is;
memory grows with the area the evader has visited, not with the map.

Example:
    >>> from envs.maps import builtin_map
    >>> from strategies.policies.safety import safety_table
    >>> world = builtin_map("corridor")
    >>> lazy = LazySafetyTable(world, 2.2, 0.5, 36)
    >>> eager = safety_table(world, 2.2, 0.5, 36, disk_cache=False)
    >>> import numpy as np
    >>> p = np.array([[3.0, 1.0], [8.0, -2.0]])
    >>> rows = lazy.rows(p)  # classifies the two points: look them up afterwards
    >>> bool((lazy.free[rows] == eager.free[eager.rows(p)]).all()), lazy.classified
    (True, 2)
"""

from __future__ import annotations

import functools
import math
from typing import Any

import numpy as np
import shapely

from envs.errors import MemoryBudgetError
from envs.maps import Map
from envs.tolerances import REL_LENGTH_TOL
from strategies.cspace.grids import check_grid_spacing, grid_axis, grid_size
from strategies.memory import memory_budget
from strategies.policies._batch_classify import _cell_keys, classify_points
from strategies.policies.safety import NO_PATH, SafetyTable

__all__ = ["LAZY_POINTS", "LazySafetyTable"]

LAZY_POINTS = 1_000_000
"""Free-region grid points above which a policy's ``table="auto"`` fills its safety table
lazily (``DecompositionPursuer.DISTINCT_TABLE_POINTS``, ``ShootingEvader``'s): the built-in
maps at L_min = 0.5 (the paper's worlds scaled x3) stay tabulated, a 200 m floor plan or
``corner~x100`` at L_min 2 (115 million points) do not."""

_UNKNOWN = -2  # a grid node not classified yet (-1: outside the free region)


_BYTES_PER_NODE = 6
"""The grid's per-node arrays: the row index (int32), the membership flag (int8) and
whether a wall may pass within the map's length tolerance (bool)."""

_TILE_BITS = 6
_TILE = 1 << _TILE_BITS
"""Grid nodes a side of a tile: the per-node arrays are allocated a tile at a time, where
lookups first touch the grid (the whole grid's were 0.98 GB on corner~x100 at L_min 2,
196 million nodes, for a few thousand nodes looked at in an episode)."""

_AROUND = 2
"""Grid nodes either way of a node :meth:`LazySafetyTable.row` finds unclassified that
join its batch: the pursuer looks up the evader's own node each decision, and an evader
on new ground met a node of its own a step (a batch of one: ~0.3 ms, most of a batch's
cost; 5 x 5 nodes: 525 batches instead of 561 over 1829 decisions on three floor plans,
and 23 decisions with two batches instead of 35)."""

_BLOCK = 8
"""Grid nodes a side of a block whose wall distance a new tile measures once: a node's
membership test asks whether a wall passes within the map's length tolerance of it
(~1 us a node, most of a test) only in blocks a wall passes near."""


def _check_grid(world: Map, resolution: float, shape: tuple[int, int]) -> None:
    """Refuse a grid whose per-node arrays, were every tile looked up, would exceed the
    memory budget (``$SURVEIL_MEMORY_BUDGET`` or half the RAM, as the decompositions'),
    before allocating anything: at ``resolution = 1e-6`` the corridor's grid asked numpy
    for 582 TiB (a MemoryError traceback through the pursuer's reset).

    Raises:
        MemoryBudgetError: naming the estimate and the resolution that fits.
    """
    limit = memory_budget()
    need = _BYTES_PER_NODE * float(shape[0]) * float(shape[1])
    if need <= limit:
        return
    fit = resolution * math.sqrt(need / limit) * 1.01  # the nodes scale as 1 / resolution^2
    raise MemoryBudgetError(
        f"LazySafetyTable(map {world.name!r}, resolution = {resolution:g}): its grid of "
        f"{shape[0]:,} x {shape[1]:,} nodes would need about {need / 1e9:.3g} GB, more than "
        f"the memory budget of {limit / 1e9:.3g} GB; use {MemoryBudgetError.KNOB} >= "
        f"{fit:.3g}, or raise the budget with {MemoryBudgetError.BUDGET}",
        "resolution",
        budget=MemoryBudgetError.ENV_BUDGET,  # no memory_budget argument here
        size=f"{math.ceil(1.2 * need / 1e9)}GB",
    )


@functools.lru_cache(maxsize=4)
def _decomposition(world: Map, L: float) -> Any:
    """The decomposition of ``world`` at ``L`` a lazy table classifies with, its point
    location built, kept in memory for the map's later tables.

    A policy builds a new table each episode: each read the decomposition back from the
    disk cache and built its point location again (on a 200 m floor plan at L_min 2,
    0.6 s of the shooting evader's 0.72 s of CPU a reset after its first). The objects
    are the same (the disk cache's round trip is exact); what the tables memoise on it
    (the region grid, the cells' stop-code index) are functions of the decomposition.
    """
    from strategies.cspace import decompose

    dec = decompose(world, L, cache=True)
    # classify_points' point location (the region grid, the cells' stop-code index),
    # built here rather than in the first decision: the same objects, ~60 ms of the
    # first decision on a 300-vertex floor plan (its classification then takes ~5)
    dec.region_grid()
    _cell_keys(dec).use_cells()
    return dec


class LazySafetyTable:
    """The :class:`~strategies.policies.safety.SafetyTable` of a map, filled on demand.

    Attributes ``free``, ``safe``, ``guaranteed``, ``ccw``, ``cw`` and ``need`` hold the
    rows classified so far; :meth:`rows` and :meth:`row` classify what they touch first,
    so indexing those arrays with rows just returned is always valid.

    Args:
        world: the map.
        L: rod length.
        resolution: grid spacing (the eager table's grid: same origin, same nodes).
        n_bins: orientation bins.
    """

    bin_width = SafetyTable.bin_width
    bin_of = SafetyTable.bin_of
    bin_centre = SafetyTable.bin_centre
    _row_search = SafetyTable._row_search  # classifies through rows()
    grid_index = SafetyTable.grid_index

    def __init__(self, world: Map, L: float, resolution: float, n_bins: int) -> None:
        self.map = world
        self.L = float(L)
        self.resolution = float(resolution)
        self.n_bins = int(n_bins)
        check_grid_spacing(world, self.resolution, "LazySafetyTable")
        xmin, ymin, xmax, ymax = world.bounds
        self.shape = (
            grid_size(xmin, xmax, self.resolution),
            grid_size(ymin, ymax, self.resolution),
        )
        # before any allocation (a 1e9 m map's axes alone were 75 GiB) or the decomposition
        _check_grid(world, self.resolution, self.shape)
        self._xs = grid_axis(xmin, xmax, self.resolution)
        self._ys = grid_axis(ymin, ymax, self.resolution)
        self.origin = np.array([self._xs[0], self._ys[0]])
        self.decomposition = _decomposition(world, self.L)
        # node (i, j) is entry (i % _TILE, j % _TILE) of slab _tiles[i // _TILE, j // _TILE]
        # of _cell (its row, _UNKNOWN, or -1) and _member (0 unknown, 1 inside, 2 not)
        self._tiles = np.full(
            (-(-self.shape[0] // _TILE), -(-self.shape[1] // _TILE)), -1, dtype=np.int64
        )
        self._cell = np.full((1, _TILE, _TILE), _UNKNOWN, dtype=np.int32)
        self._member = np.zeros((1, _TILE, _TILE), dtype=np.int8)
        self._near = np.zeros((1, _TILE, _TILE), dtype=bool)
        self._n_tiles = 0
        self._centres = -math.pi + (np.arange(self.n_bins) + 0.5) * self.bin_width
        self._walls = shapely.boundary(world.free_region)
        shapely.prepare(self._walls)
        self._eps = REL_LENGTH_TOL * world.scale
        # a node within _eps of a wall lies in a block whose centre is within this of one
        # (its half diagonal, and a margin far above the distances' rounding)
        slack = REL_LENGTH_TOL * (world.scale + float(np.abs(world.bounds).max()))
        self._block_reach = (_BLOCK - 1) / 2 * math.sqrt(2) * self.resolution + self._eps + slack
        self._n = 0
        cap = 1024
        self._free = np.zeros((cap, self.n_bins), dtype=bool)
        self._safe = np.zeros_like(self._free)
        self._guaranteed = np.zeros(cap, dtype=bool)
        self._ccw = np.zeros((cap, self.n_bins), dtype=np.uint8)
        self._cw = np.zeros_like(self._ccw)
        self._need = np.zeros_like(self._ccw)

    # ------------------------------------------------------------- the classified rows
    free = property(lambda self: self._free[: self._n])
    safe = property(lambda self: self._safe[: self._n])
    guaranteed = property(lambda self: self._guaranteed[: self._n])
    ccw = property(lambda self: self._ccw[: self._n])
    cw = property(lambda self: self._cw[: self._n])
    need = property(lambda self: self._need[: self._n])

    def row(self, point: np.ndarray) -> int:
        """Table row of the grid point nearest to ``point``, or of the nearest in free
        space (``SafetyTable.row``'s scalar arithmetic for a node classified already, the
        pursuer's look-up of the evader's row each decision; else through :meth:`rows`).

        A node not classified yet is classified with the unknown nodes within
        ``_AROUND`` nodes of it, in one batch: the evader's next nodes, which it would
        otherwise meet one batch at a time (the same entries; the rows are numbered in
        the order the nodes were classified)."""
        i = round((float(point[0]) - float(self.origin[0])) / self.resolution)
        j = round((float(point[1]) - float(self.origin[1])) / self.resolution)
        if 0 <= i < self.shape[0] and 0 <= j < self.shape[1]:
            slab = int(self._tiles[i >> _TILE_BITS, j >> _TILE_BITS])
            r = _UNKNOWN if slab < 0 else int(self._cell[slab, i & (_TILE - 1), j & (_TILE - 1)])
            if r == _UNKNOWN:
                self._classify_around(i, j)
                slab = int(self._tiles[i >> _TILE_BITS, j >> _TILE_BITS])  # (allocated now)
                r = int(self._cell[slab, i & (_TILE - 1), j & (_TILE - 1)])
            if r >= 0:
                return r
        return self._row_search(point)

    def _classify_around(self, i: int, j: int) -> None:
        """Classify the unknown grid nodes within ``_AROUND`` nodes of node ``(i, j)`` (in
        each coordinate), in (i, j) order (as :meth:`rows`' batches)."""
        ii = np.repeat(np.arange(i - _AROUND, i + _AROUND + 1), 2 * _AROUND + 1)
        jj = np.tile(np.arange(j - _AROUND, j + _AROUND + 1), 2 * _AROUND + 1)
        ok = (ii >= 0) & (ii < self.shape[0]) & (jj >= 0) & (jj < self.shape[1])
        ii, jj = ii[ok], jj[ok]
        flat = self._slots(ii, jj)  # (first: it may allocate tiles)
        new = self._cell.reshape(-1)[flat] == _UNKNOWN
        self._classify(ii[new], jj[new])

    @property
    def classified(self) -> int:
        """Grid points classified so far (inside the free region)."""
        return self._n

    def inside(
        self,
        points: np.ndarray,
        step: np.ndarray | None = None,
        steps: int = 0,
        nodes: bool = False,
    ) -> np.ndarray | tuple[np.ndarray, tuple]:
        """Whether the grid points nearest to (k, 2) points lie in the free region.

        Membership only (a vectorised point-in-polygon test per new node, memoised):
        the orientations are classified when :meth:`rows` asks for them. ``step`` and
        ``steps``: as :meth:`rows` (the new nodes ahead tested in the same batch).
        ``nodes=True``: also the points' grid nodes, for :meth:`rows` of some of the
        points (:meth:`nodes_at`) without finding them again.
        """
        ix, iy, ok = self._nodes(points)
        out = np.zeros(len(ok), dtype=bool)
        flat = self._slots(ix, iy)
        member = self._member.reshape(-1)[flat]
        unknown = member == 0
        if unknown.any():
            ux, uy, uf = ix[unknown], iy[unknown], flat[unknown]
            if steps and step is not None:
                ax, ay, _ = self._nodes(_ahead(points, step, steps))
                at = self._slots(ax, ay)
                new = self._member.reshape(-1)[at] == 0
                ux, uy = np.concatenate([ux, ax[new]]), np.concatenate([uy, ay[new]])
                uf = np.concatenate([uf, at[new]])
            _, first = np.unique(uf, return_index=True)
            self._membership(ux[first], uy[first], uf[first])
            member = self._member.reshape(-1)[flat]
        out[ok] = member == 1
        return (out, (ix, iy, flat, ok)) if nodes else out

    @staticmethod
    def nodes_at(nodes: tuple, at: np.ndarray) -> tuple:
        """The grid nodes (``inside(points, nodes=True)``'s) of ``points[at]``."""
        ix, iy, flat, ok = nodes
        ok_at = ok[at]
        if len(ix) < len(ok):  # (a point off the grid: ix, iy, flat skip it)
            at = (np.cumsum(ok) - 1)[at[ok_at]]
        return ix[at], iy[at], flat[at], ok_at

    def _nodes(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Grid indices ``(i, j)`` of the nodes nearest to (k, 2) points that lie on the
        grid, and which do (``grid_index``'s nodes, as ``SafetyTable.rows`` tests them)."""
        idx = np.rint((np.asarray(points, dtype=float) - self.origin) / self.resolution).astype(
            np.int64, order="F"
        )
        ix, iy = idx[:, 0], idx[:, 1]  # (contiguous columns)
        ok = (ix.view(np.uint64) < self.shape[0]) & (iy.view(np.uint64) < self.shape[1])
        if not ok.all():
            ix, iy = ix[ok], iy[ok]
        return ix, iy, ok

    def _slots(self, ix: np.ndarray, iy: np.ndarray) -> np.ndarray:
        """Where grid nodes ``(ix, iy)`` are kept in ``_cell`` and ``_member`` (flat
        indices), their tiles allocated first (unknown nodes). (Shifts and masks: the
        indices are not negative.)"""
        ti, tj = ix >> _TILE_BITS, iy >> _TILE_BITS
        slab = self._tiles[ti, tj]
        if (slab < 0).any():
            new = np.unique(np.stack([ti[slab < 0], tj[slab < 0]], axis=1), axis=0)
            n = self._n_tiles + len(new)
            if n > len(self._cell):
                cap = max(n, 2 * len(self._cell))
                cell = np.full((cap, _TILE, _TILE), _UNKNOWN, dtype=np.int32)
                member = np.zeros((cap, _TILE, _TILE), dtype=np.int8)
                near = np.zeros((cap, _TILE, _TILE), dtype=bool)
                cell[: self._n_tiles] = self._cell[: self._n_tiles]
                member[: self._n_tiles] = self._member[: self._n_tiles]
                near[: self._n_tiles] = self._near[: self._n_tiles]
                self._cell, self._member, self._near = cell, member, near
            self._tiles[new[:, 0], new[:, 1]] = np.arange(self._n_tiles, n)
            self._near[self._n_tiles : n] = self._walls_near(new)
            self._n_tiles = n
            slab = self._tiles[ti, tj]
        mask = _TILE - 1
        return (slab << (2 * _TILE_BITS)) | ((ix & mask) << _TILE_BITS) | (iy & mask)

    def _walls_near(self, tiles: np.ndarray) -> np.ndarray:
        """Per node of (k, 2) tiles (``(k, _TILE, _TILE)``, bool), whether a wall may pass
        within the map's length tolerance of it: False for the nodes of a block of
        ``_BLOCK`` x ``_BLOCK`` whose centre is farther than ``_block_reach`` from every
        wall (then so is each of its nodes farther than the tolerance)."""
        per = _TILE // _BLOCK
        centre = np.arange(per) * _BLOCK + (_BLOCK - 1) / 2  # in nodes from a tile's corner
        cx = self.origin[0] + self.resolution * (tiles[:, 0, None] * _TILE + centre)
        cy = self.origin[1] + self.resolution * (tiles[:, 1, None] * _TILE + centre)
        x = np.broadcast_to(cx[:, :, None], (len(tiles), per, per))
        y = np.broadcast_to(cy[:, None, :], (len(tiles), per, per))
        near = shapely.dwithin(self._walls, shapely.points(x.ravel(), y.ravel()), self._block_reach)
        block = near.reshape(len(tiles), per, 1, per, 1)
        return np.broadcast_to(block, (len(tiles), per, _BLOCK, per, _BLOCK)).reshape(
            len(tiles), _TILE, _TILE
        )

    def _membership(self, ix: np.ndarray, iy: np.ndarray, flat: np.ndarray) -> np.ndarray:
        """Decide (and memoise) which grid nodes ``(ix, iy)`` (kept at ``flat``) lie in
        the free region: inside its polygon and not within the length tolerance of a
        wall (tested only where a wall passes near: :meth:`_walls_near`)."""
        x, y = self._xs[ix], self._ys[iy]
        inside = shapely.contains_xy(self.map.prepared_free_region, x, y)
        at = np.flatnonzero(inside & self._near.reshape(-1)[flat])
        if len(at):
            inside[at] = ~shapely.dwithin(self._walls, shapely.points(x[at], y[at]), self._eps)
        self._member.reshape(-1)[flat] = np.where(inside, 1, 2)
        return inside

    def rows(
        self,
        points: np.ndarray,
        step: np.ndarray | None = None,
        steps: int = 0,
        nodes: tuple | None = None,
    ) -> np.ndarray:
        """Table rows of the grid points nearest to (k, 2) points (-1 outside).

        ``step`` (2,) and ``steps``: where the caller looks next, ``points + k step`` for
        k = 1 .. ``steps`` (an evader's probes along its velocity). When ``points`` meet
        new nodes, the new nodes ahead are classified in the same batch: a batch costs
        ~0.2 ms however few its points and ~1 us a point more, so the next lookups find
        their nodes ready instead of paying for a batch a decision. Every node's entries
        are the same either way (its classification does not depend on its batch; the
        rows are numbered in the order the nodes were classified). ``nodes``: the
        points' grid nodes if known (:meth:`nodes_at`).
        """
        if nodes is None:
            ix, iy, ok = self._nodes(points)
            flat = self._slots(ix, iy)
        else:
            ix, iy, flat, ok = nodes
        out = np.full(len(ok), -1, dtype=np.int64)
        vals = self._cell.reshape(-1)[flat]
        unknown = vals == _UNKNOWN
        if unknown.any():
            ux, uy = ix[unknown], iy[unknown]
            if steps and step is not None:
                ax, ay, _ = self._nodes(_ahead(points, step, steps))
                at = self._slots(ax, ay)
                new = self._cell.reshape(-1)[at] == _UNKNOWN
                ux, uy = np.concatenate([ux, ax[new]]), np.concatenate([uy, ay[new]])
            # each node once, in (i, j) order (as np.unique of the (i, j) pairs)
            ny = np.int64(self.shape[1])
            key = np.unique(ux * ny + uy)
            self._classify(key // ny, key % ny)
            vals = self._cell.reshape(-1)[flat]
        out[ok] = vals
        return out

    def _classify(self, ix: np.ndarray, iy: np.ndarray) -> None:
        """Classify grid nodes ``(ix, iy)`` as the eager table's build does."""
        flat = self._slots(ix, iy)
        member = self._member.reshape(-1)[flat]
        inside = member == 1
        unknown = member == 0
        if unknown.any():
            inside[unknown] = self._membership(ix[unknown], iy[unknown], flat[unknown])
        cell = self._cell.reshape(-1)
        cell[flat[~inside]] = -1
        if not inside.all():
            ix, iy, flat = ix[inside], iy[inside], flat[inside]
        k = len(flat)
        if not k:
            return
        self._grow(self._n + k)
        pts = np.stack([self._xs[ix], self._ys[iy]], axis=1)
        # (the nodes tested inside the polygon: _membership)
        free, safe = classify_points(
            self.decomposition, pts, self.resolution, self._centres, interior=True
        )
        g = safe.any(axis=1)
        safe = np.where(g[:, None], safe, free)
        ccw, cw = _both_ways(safe)
        sl = slice(self._n, self._n + k)
        self._free[sl], self._safe[sl], self._guaranteed[sl] = free, safe, g
        self._ccw[sl], self._cw[sl] = ccw, cw
        np.minimum(ccw, cw, out=self._need[sl])
        cell[flat] = np.arange(self._n, self._n + k)
        self._n += k

    def _grow(self, n: int) -> None:
        cap = len(self._guaranteed)
        if n <= cap:
            return
        while cap < n:
            cap *= 2
        for name in ("_free", "_safe", "_guaranteed", "_ccw", "_cw", "_need"):
            old = getattr(self, name)
            new = np.zeros((cap, *old.shape[1:]), dtype=old.dtype)
            new[: self._n] = old[: self._n]
            setattr(self, name, new)


def _ahead(points: np.ndarray, step: np.ndarray, steps: int) -> np.ndarray:
    """``points + k step`` for k = 1 .. ``steps``, (steps k, 2)."""
    shift = np.arange(1, steps + 1)[:, None, None] * np.asarray(step, dtype=float)
    return (np.asarray(points, dtype=float).reshape(-1, 2) + shift).reshape(-1, 2)


def _both_ways(safe: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``safety._circular_distance(safe, +1)`` and ``(safe, -1)`` of a batch of rows at
    once: the same bins to the next safe bin at or after each bin and to the last at or
    before it (``NO_PATH`` where a row has none). A row safe all round is 0 both ways
    and one with no safe bin ``NO_PATH`` (most of a lazy table's rows, away from the
    walls, are one or the other). The others are laid end to end, each twice (its
    circle unrolled), and each bin's next and last safe bins read off the safe bins'
    running count: one cumulative sum and two gathers (numpy's running minimum, the
    scan this took before, costs ~6 ns an element, about four times as much)."""
    k, nb = safe.shape
    n_safe = np.count_nonzero(safe, axis=1)
    ccw = np.where(n_safe[:, None] == 0, np.uint8(NO_PATH), np.uint8(0))
    ccw = np.broadcast_to(ccw, (k, nb)).copy()
    mixed = np.flatnonzero((n_safe > 0) & (n_safe < nb))
    if not len(mixed):
        return ccw, ccw.copy()
    cw = ccw.copy()
    part = safe[mixed]
    m = len(mixed)
    flat = np.concatenate([part, part], axis=1).reshape(-1)
    dtype = np.int32 if len(flat) < np.iinfo(np.int32).max else np.int64  # (half the bytes)
    at = np.flatnonzero(flat).astype(dtype)  # the safe bins, in order
    count = np.cumsum(flat, dtype=dtype).reshape(m, 2 * nb)  # safe bins up to each bin
    idx = np.arange(m * 2 * nb, dtype=dtype).reshape(m, 2 * nb)
    # a row has a safe bin within nb - 1 bins either way: the next one at or after a bin
    # of its first copy and the last one at or before a bin of its second lie in the row
    ahead = at[count[:, :nb] - part] - idx[:, :nb]
    behind = idx[:, nb:] - at[count[:, nb:] - 1]
    if nb - 1 > NO_PATH:  # (distances past NO_PATH read as NO_PATH)
        ahead, behind = np.minimum(ahead, NO_PATH), np.minimum(behind, NO_PATH)
    ccw[mixed], cw[mixed] = ahead, behind
    return ccw, cw
