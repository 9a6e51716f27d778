"""The safety table's classification of many grid points at once (issue 13).

:func:`strategies.policies.safety._classified` classifies one point: the kernel's free
arcs, the region under the point, its arcs' cells by their stop pairs, about 0.2 ms in
Python. A lazy table meets ~100 new points a decision on the built-in maps at L_min =
0.5, and a table of the whole map there has 400,000, so :func:`classify_points` does
the same for a batch (about ten times faster a point): the free arcs by the
decomposition build's vectorised kernel
(:func:`~strategies.cspace._batch_arcs.free_arcs_batch`, the kernel's stops, arcs
within 1e-12 rad), the regions by the decomposition's locate grid (vectorised; the rare
point it cannot answer asks ``Decomposition.locate``), the cells by the same stop-pair
match as ``Decomposition._match``, and the bins by the same comparison as
``safety._arc_bins``. A point with an arc it cannot match (on a critical curve) is
handed to ``_classified`` itself, which nudges it off the curve. A lazy table's batches
(a few dozen to a few hundred points) take
:func:`~strategies.cspace._batch_arcs.free_arcs_few`, the same arrays in fewer numpy
calls: a batch's cost there is mostly per call, not per point.

:func:`distinct_rows` classifies a whole grid in chunks and keeps each distinct row once
(``safety_table(..., distinct=True)``).
"""

from __future__ import annotations

import math

import numpy as np
import shapely

from envs.geometry import kernel_for
from strategies.cspace._batch_arcs import WallCells, free_arcs_batch, free_arcs_few, stop_code
from strategies.cspace._candidates import wall_index

__all__ = ["classify_points", "distinct_rows"]

_TWO_PI = 2.0 * math.pi
FEW = 4096  # batches up to this size (a lazy table's) take free_arcs_few


def _regions(dec, pts: np.ndarray) -> np.ndarray:
    """``Decomposition.locate`` of (k, 2) points, vectorised (-1 for ``None``)."""
    grid = dec.region_grid()
    k = len(pts)
    out = np.full(k, -1, dtype=np.int64)
    nx, ny = grid.labels.shape
    if nx == 0 or ny == 0:
        ask = np.arange(k)
    else:
        # _RegionGrid.region's arithmetic, elementwise
        i = np.floor((pts[:, 0] - grid.origin[0]) / grid.h).astype(np.int64)
        j = np.floor((pts[:, 1] - grid.origin[1]) / grid.h).astype(np.int64)
        inr = (i >= 0) & (i < nx) & (j >= 0) & (j < ny)
        lab = np.full(k, -2, dtype=np.int64)
        lab[inr] = grid.labels[i[inr], j[inr]]
        out[lab >= 0] = lab[lab >= 0]
        if (lab >= 0).all():  # (most batches)
            return out
        # unlabelled squares: the one candidate polygon holding the point, if one does
        und = np.flatnonzero(lab == -1)
        sq = i[und] * ny + j[und]
        s, e = grid.start[sq], grid.start[sq + 1]
        n = e - s
        who = np.repeat(np.arange(len(und)), n)
        # each square's candidates laid end to end: the m-th of square u at s[u] + m
        cand = grid.cand[np.arange(len(who)) + np.repeat(s - (np.cumsum(n) - n), n)]
        p = und[who]
        hit = shapely.intersects_xy(grid.polygons[cand], pts[p, 0], pts[p, 1])
        whom = who[hit]
        one = np.bincount(whom, minlength=len(und)) == 1
        out[und[whom[one[whom]]]] = cand[hit][one[whom]]
        ask = np.concatenate([np.flatnonzero(lab == -2), und[~one]])
    for a in ask:  # the region tree (Decomposition._locate_tree)
        r = dec.locate(pts[a])
        out[a] = -1 if r is None else r
    return out


class _CellKeys:
    """Each region's cells keyed by stop-code pairs (``Decomposition._cell_of`` in codes)."""

    def __init__(self, dec) -> None:
        self.dec = dec
        self._of: dict[int, dict[tuple[int, int], int]] = {}
        self.neighbours = dec.neighbours
        # the same keys as sorted integers: (region, lo, hi) with the codes numbered
        cells = dec.cells
        lo = np.array([stop_code(c.stops[0]) for c in cells], dtype=np.int64)
        hi = np.array([stop_code(c.stops[1]) for c in cells], dtype=np.int64)
        reg = np.array([c.region for c in cells], dtype=np.int64)
        self.codes = np.unique(np.concatenate([lo, hi]))
        key = self._key(reg, lo, hi)
        order = np.argsort(key, kind="stable")
        self.sorted_keys, self.key_cell = key[order], order
        self.n_cells = np.array([len(r.cells) for r in dec.regions] + [-1], dtype=np.int64)
        self.escapable = np.array([c.escapable for c in cells], dtype=bool)
        # the map's wall index and kernel tolerance (free_arcs_few's; their look-ups
        # hash the map's vertices, ~0.1 ms a call on a 300-vertex floor plan)
        self.tree = wall_index(dec.map).tree
        self.eps = kernel_for(dec.map).eps
        self.cells: WallCells | None = None  # (use_cells)

    def use_cells(self) -> None:
        """Have :func:`classify_points`' small batches find their (point, edge) pairs by
        the map's :class:`~strategies.cspace._batch_arcs.WallCells` (the same pairs as the
        wall index's query; a lazy table's batches, whose per-point query was a sixth of
        their cost on a 280-edge floor plan)."""
        if self.cells is None:
            self.cells = WallCells(self.dec.map, self.tree, self.dec.L + self.eps)

    def _key(self, reg: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        """Integer keys of (region, code, code) triples (-1 where a code is no cell's)."""
        n = len(self.codes)
        if not n:
            return np.full(len(reg), -1, dtype=np.int64)
        a = np.minimum(np.searchsorted(self.codes, lo), n - 1)
        b = np.minimum(np.searchsorted(self.codes, hi), n - 1)
        ok = (self.codes[a] == lo) & (self.codes[b] == hi) & (reg >= 0)
        return np.where(ok, (reg * n + a) * n + b, -1)

    def cells_in_own_region(self, reg: np.ndarray, lo: np.ndarray, hi: np.ndarray):
        """The cell of each arc among its point's region's cells (-1: none)."""
        key = self._key(reg, lo, hi)
        if not len(self.sorted_keys):
            return np.full(len(key), -1, dtype=np.int64)
        at = np.minimum(np.searchsorted(self.sorted_keys, key), len(self.sorted_keys) - 1)
        return np.where((self.sorted_keys[at] == key) & (key >= 0), self.key_cell[at], -1)

    def of(self, r: int) -> dict[tuple[int, int], int]:
        d = self._of.get(r)
        if d is None:
            cells = self.dec.cells
            d = {
                (stop_code(cells[c].stops[0]), stop_code(cells[c].stops[1])): c
                for c in self.dec.regions[r].cells
            }
            self._of[r] = d
        return d

    def match(self, region: int, keys: list[tuple[int, int]]) -> list[int | None]:
        """``Decomposition._match`` of one point's stop-code pairs."""
        cands = (region, *self.neighbours[region])
        for r in cands:
            table = self.of(r)
            if len(table) == len(keys) and all(k in table for k in keys):
                return [table[k] for k in keys]
        return [next((self.of(r)[k] for r in cands if k in self.of(r)), None) for k in keys]


def _cell_keys(dec) -> _CellKeys:
    """The stop-code index of ``dec`` (cached on it)."""
    keys = dec.__dict__.get("_batch_cell_keys")
    if keys is None:
        keys = _CellKeys(dec)
        dec.__dict__["_batch_cell_keys"] = keys
    return keys


def classify_points(
    dec, pts: np.ndarray, step: float, centres: np.ndarray, interior: bool = False
) -> tuple[np.ndarray, np.ndarray]:
    """The free and safe bins at (k, 2) points of the free region, as the eager build.

    ``interior=True``: every point is known to lie in the free region's polygon (a lazy
    table's nodes, tested when first looked up), which a batch then does not test again.

    Returns ``(free, safe)``, (k, n_bins) bool: the bin centres inside the free arcs,
    and inside the non-escapable ones (all False where no point nearby resolves the
    cells: the caller then falls back to ``free``, as ``safety._build`` does).
    """
    from strategies.policies.safety import _arc_bins, _classified

    pts = np.asarray(pts, dtype=float).reshape(-1, 2)
    k, nb = len(pts), len(centres)
    free = np.zeros((k, nb), dtype=bool)
    safe = np.zeros((k, nb), dtype=bool)
    if not k:
        return free, safe
    index = _cell_keys(dec)
    if k <= FEW:  # (a lazy table's lookups)
        batch = free_arcs_few(dec.map, pts, dec.L, index.tree, index.eps, interior, index.cells)
    else:
        batch = free_arcs_batch(dec.map, pts, dec.L)
    counts = np.diff(batch.offsets)
    regions = _regions(dec, pts)
    # Decomposition._match: a point whose arcs are exactly its region's cells (most),
    # vectorised; the others through the neighbours, point by point
    owner = np.repeat(np.arange(k), counts)
    cell = index.cells_in_own_region(regions[owner], batch.code_lo, batch.code_hi)
    found = np.bincount(owner[cell >= 0], minlength=k)
    fast = (found == counts) & (index.n_cells[regions] == counts)
    # per arc: 0 safe (not escapable), 1 escapable, 2 unmatched
    state = np.full(len(batch.lo), 2, dtype=np.int8)
    at = fast[owner]
    state[at] = index.escapable[cell[at]]
    nudge = []
    slow = np.flatnonzero(~fast)
    if len(slow):
        code_lo, code_hi = batch.code_lo.tolist(), batch.code_hi.tolist()
        offs = batch.offsets.tolist()
        cells = dec.cells
    for i in slow.tolist():
        s, e = offs[i], offs[i + 1]
        r = int(regions[i])
        if s == e:
            continue
        if r < 0:
            nudge.append(i)
            continue
        ids = index.match(r, list(zip(code_lo[s:e], code_hi[s:e], strict=True)))
        if any(c is None for c in ids):
            nudge.append(i)
            continue
        state[s:e] = [1 if cells[c].escapable else 0 for c in ids]
    # bins in the arcs (safety._arc_bins' comparison, every arc at once)
    lo, hi = batch.lo[:, None], batch.hi[:, None]
    d = centres[None, :] - lo
    if len(d) and -math.pi <= batch.lo.min() and batch.lo.max() < math.pi:
        # |d| < 2 pi: d % 2 pi is fmod (d itself) plus 2 pi where d < 0, as numpy does
        np.add(d, _TWO_PI, out=d, where=d < 0)
    else:
        d %= _TWO_PI
    inarc = d <= (hi - lo)
    inarc_safe = inarc & (state == 0)[:, None]
    # each point's arcs or-ed together: its n-th arc is at offsets[i] + n
    has = np.flatnonzero(counts)
    at = batch.offsets[has]
    free[has] = inarc[at]
    safe[has] = inarc_safe[at]
    for n in range(1, int(counts.max()) if k else 0):
        has = has[counts[has] > n]
        at = batch.offsets[has] + n
        free[has] |= inarc[at]
        safe[has] |= inarc_safe[at]
    for i in nudge:  # as the eager build, point by point
        arcs, safe_arcs = _classified(dec, pts[i], step)
        free[i] = _arc_bins(arcs, centres)
        safe[i] = free[i] & _arc_bins(safe_arcs, centres) if safe_arcs is not None else False
    safe &= free
    return free, safe


CHUNK = 20_000  # grid points classified per batch of a distinct-row build
_MIX = np.random.default_rng(0).integers(1, 2**63, size=64, dtype=np.uint64) | np.uint64(1)


def _unique_rows(key: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``np.unique(key, axis=0, return_inverse=True)`` of (k, 8 w) uint8 rows, sorted by a
    64-bit hash instead (a sort of k words, not of k rows); exact: rows that share a hash
    are compared, and a collision falls back to ``np.unique``."""
    words = key.view(np.uint64)
    h = (words * _MIX[: words.shape[1]]).sum(axis=1, dtype=np.uint64)  # wraps mod 2^64
    _, first, inv = np.unique(h, return_index=True, return_inverse=True)
    inv = inv.reshape(-1)
    if not np.array_equal(key[first[inv]], key):  # a collision (never seen)
        uniq, inv = np.unique(key, axis=0, return_inverse=True)
        return uniq, inv.reshape(-1)
    return key[first], inv


def distinct_rows(
    dec, pts: np.ndarray, step: float, centres: np.ndarray, progress=None
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Classify (k, 2) points in chunks and keep each distinct row once.

    Returns ``(ids, free, safe, guaranteed)``: the row of each point, and the distinct
    rows (after ``safety._build``'s fallback: ``safe`` is ``free`` where nothing is
    guaranteed). Most points share their row with many others (35x on the pillar room
    at L_min 0.5), so memory grows with the distinct rows, not with the points.
    """
    nb = len(centres)
    ids = np.empty(len(pts), dtype=np.int32)
    seen: dict[bytes, int] = {}
    keep: list[np.ndarray] = []
    for s in range(0, len(pts), CHUNK):
        free, safe = classify_points(dec, pts[s : s + CHUNK], step, centres)
        g = safe.any(axis=1)
        safe = np.where(g[:, None], safe, free)
        key = np.packbits(np.concatenate([free, safe, g[:, None]], axis=1), axis=1)
        key = np.pad(key, ((0, 0), (0, -key.shape[1] % 8)))
        uniq, inv = _unique_rows(key)
        glob = np.empty(len(uniq), dtype=np.int32)
        for u, row in enumerate(uniq):
            b = row.tobytes()
            j = seen.get(b)
            if j is None:
                j = seen[b] = len(seen)
                keep.append(row)
            glob[u] = j
        ids[s : s + CHUNK] = glob[inv.reshape(-1)]
        if progress is not None:
            progress(len(free))
    width = -(-(2 * nb + 1) // 64) * 8
    bits = np.unpackbits(np.array(keep, dtype=np.uint8).reshape(-1, width), axis=1)
    return ids, bits[:, :nb].astype(bool), bits[:, nb : 2 * nb].astype(bool), bits[:, 2 * nb] == 1
