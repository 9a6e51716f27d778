"""Wall distances on the safety table's grid, for the decomposition pursuer's orbit and wall checks.

An eager table's whole-grid wall distances and geodesic distance to room (an orbit
circle's centre with room, :mod:`strategies.policies.decomposition.orbit`), cached per
map (:func:`_clearance_grid`, :func:`_room_field`); and :class:`_Clearances`, the lookups
at a point's nearest grid node, memoised block by block on a lazy table (which has no
whole-map grid).
"""

from __future__ import annotations

import functools
import math

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra

from strategies.policies.safety import SafetyTable


@functools.lru_cache(maxsize=16)
def _clearance_grid(world, table: SafetyTable) -> np.ndarray:
    """(nx, ny) wall distance of each node ``origin + resolution (i, j)`` of an eager
    table's grid (0 off the free region), for the orbit test of
    :meth:`DecompositionPursuer._orbit_margins` (a lazy table fills the same values in
    as they are needed)."""
    nodes = np.argwhere(table.cell >= 0)
    clear = np.zeros(table.shape)
    for k in range(0, len(nodes), 4096):  # bounded memory: points x edges per chunk
        chunk = nodes[k : k + 4096]
        clear[chunk[:, 0], chunk[:, 1]] = world.distance_to_walls(
            table.origin + table.resolution * chunk
        )
    return clear


@functools.lru_cache(maxsize=16)
def _room_field(world, table: SafetyTable, need: float) -> np.ndarray:
    """(nx, ny) geodesic distance from each node of an eager table's grid to the nearest
    node whose wall distance is at least ``need`` (a centre of an orbit circle with
    room, :meth:`DecompositionPursuer._orbit_margins`); ``inf`` off the free region and
    where no such node is reachable.

    Paths run through the grid's 8 neighbours; a step of length ``s`` is taken only
    between nodes both at least ``s / 2`` from the walls, so the straight step between
    them is free (each half lies in its end's free disc).
    """
    clear = _clearance_grid(world, table)
    nx, ny = clear.shape
    idx = np.arange(nx * ny).reshape(nx, ny)
    h = table.resolution
    rows, cols, weights = [], [], []
    for di, dj in ((1, 0), (0, 1), (1, 1), (1, -1)):
        s = h * math.hypot(di, dj)
        a = (slice(0, nx - di), slice(max(0, -dj), ny - max(0, dj)))
        b = (slice(di, nx), slice(max(0, dj), ny - max(0, -dj)))
        ok = np.minimum(clear[a], clear[b]) > 0.5 * s
        rows.append(idx[a][ok])
        cols.append(idx[b][ok])
        weights.append(np.full(int(ok.sum()), s))
    graph = coo_matrix(
        (np.concatenate(weights), (np.concatenate(rows), np.concatenate(cols))),
        shape=(nx * ny, nx * ny),
    ).tocsr()
    sources = np.flatnonzero(clear.reshape(-1) >= need)
    if not sources.size:
        return np.full((nx, ny), np.inf)
    dist = dijkstra(graph, directed=False, indices=sources, min_only=True)
    return np.asarray(dist, dtype=np.float64).reshape(nx, ny)


@functools.cache
def _block_nodes(bits: int) -> np.ndarray:
    """The (i, j) offsets of the nodes of a block of ``2^bits`` x ``2^bits`` grid nodes,
    ((2^bits)^2, 2) int64 (:meth:`DecompositionPursuer._measure_blocks`)."""
    side = np.arange(1 << bits, dtype=np.int64)
    out = np.stack(np.meshgrid(side, side, indexing="ij"), -1).reshape(-1, 2)
    out.setflags(write=False)
    return out


class _Clearances:
    """Wall distance and way to room at the table's grid node nearest a point.

    A part of :class:`~strategies.policies.decomposition.pursuer.DecompositionPursuer`:
    it reads the pursuer's constants and the state its ``_reset`` sets.
    """

    def _node_at(self, x: float, y: float) -> tuple[int, int] | None:
        """The table's grid node nearest ``(x, y)``, None off the grid."""
        tab = self.table
        i = round((x - float(tab.origin[0])) / tab.resolution)
        j = round((y - float(tab.origin[1])) / tab.resolution)
        if not (0 <= i < tab.shape[0] and 0 <= j < tab.shape[1]):
            return None
        return i, j

    def _clearance_at(self, x: float, y: float) -> float:
        """Wall distance at the table's grid node nearest ``(x, y)`` (0 off the grid)."""
        node = self._node_at(x, y)
        if node is None:
            return 0.0
        i, j = node
        if self._clear is not None:
            return float(self._clear[i, j])
        return self._memo_clearance(i, j)

    def _memo_clearance(self, i: int, j: int) -> float:
        """Wall distance of grid node (i, j) of a lazy table (the eager grid's value: same
        node, same arithmetic), memoised (:meth:`_measure_blocks`)."""
        d = self._clear_memo.get((i, j))
        if d is None:
            self._measure_blocks([(i, j)])
            d = self._clear_memo[(i, j)]
        return d

    def _memo_clearances(self, i: np.ndarray, j: np.ndarray) -> np.ndarray:
        """:meth:`_memo_clearance` of grid nodes ``(i[k], j[k])``, the ones not memoised yet
        measured in one batch (:meth:`_measure_blocks`)."""
        memo = self._clear_memo
        keys = list(zip(i.tolist(), j.tolist(), strict=True))
        todo = [k for k in keys if k not in memo]
        if todo:
            self._measure_blocks(todo)
        return np.array([memo[k] for k in keys])

    def _measure_blocks(self, nodes: list[tuple[int, int]]) -> None:
        """Memoise the wall distances of every grid node of the blocks of
        ``2^CLEAR_BLOCK_BITS`` x ``2^CLEAR_BLOCK_BITS`` nodes that hold ``nodes`` (0 for a
        node outside the free region), in one batch: the same values (membership and the
        wall distance are each a function of the node alone). The clearances asked for
        (the pursuer's path ahead, the orbits' centres) move on by a node or two a step,
        and a batch costs mostly per call (one call per node was most of a decision on a
        lazy table, ~1-3 ms on a 300-vertex floor plan): blocks of 4 x 4 nodes take a
        third of the batches of the nodes alone on floor_plan:1:110."""
        tab = self.table
        b = self.CLEAR_BLOCK_BITS
        blocks = np.array(list(dict.fromkeys((i >> b, j >> b) for i, j in nodes)))
        ij = ((blocks[:, None, :] << b) + _block_nodes(b)).reshape(-1, 2)
        ij = ij[(ij[:, 0] < tab.shape[0]) & (ij[:, 1] < tab.shape[1])]
        points = tab.origin + tab.resolution * ij
        inside = tab.inside(points)
        d = np.zeros(len(ij))
        if inside.any():
            d[inside] = self.config.map.distance_to_walls(points[inside])
        self._clear_memo.update(zip(map(tuple, ij.tolist()), d.tolist(), strict=True))

    def _field_at(self, x: float, y: float) -> float:
        """Geodesic distance to room (:func:`_room_field`) at the grid node nearest
        ``(x, y)`` (``inf`` off the grid)."""
        tab = self.table
        i = round((x - float(tab.origin[0])) / tab.resolution)
        j = round((y - float(tab.origin[1])) / tab.resolution)
        if not (0 <= i < tab.shape[0] and 0 <= j < tab.shape[1]):
            return math.inf
        return float(self._field[i, j])
