"""A lookup table of safe rod orientations at L_min, built once per map from the exact cells.

The analytic policies decide in microseconds by looking up, at the grid point nearest to
an evader position, which orientation bins are *free* (the rod of length L_min touches
no wall) and which are *safe* (free and in a non-escapable cell, Sec. 4), and how far
the rod must turn, counter-clockwise or clockwise, to reach a safe orientation.

The source is the exact decomposition K_L (:func:`strategies.cspace.decompose`, cached on
disk): at each grid point the free bins are the bin centres inside the kernel's exact
free arcs and the safe bins those inside ``Decomposition.safe_arcs`` (the arcs of
non-escapable cells). Where a grid point sits on a critical curve and its arcs cannot be
matched to cells, the classification is borrowed from a point nudged off the curve (a
quarter grid step at most); if that fails too, no guarantee is claimed there. Where a
grid point carries no safe arc at all (Prop. 2: every cell above it escapable, or
unclassified) the table falls back to its free bins, so a pursuer still keeps the rod
clear of walls where no guarantee exists; ``guaranteed`` marks the other points.

Tables are cached in memory and on disk (``$SURVEIL_CACHE_DIR``, default
``~/.cache/surveil``), keyed by the version, the source, the map digest and the
parameters.
"""

from __future__ import annotations

import functools
import hashlib
import math
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from envs import validation
from envs.errors import InvalidConfigError, MemoryBudgetError
from envs.maps import Map
from strategies.cspace.cache import (
    CacheWarning,
    constants_digest,
    resolve_cache_dir,
    write_cache_file,
)
from strategies.cspace.grids import check_grid_spacing, grid_bytes, grid_points
from strategies.cspace.grids import points_at as _points_at
from strategies.memory import memory_budget as _memory_budget

__all__ = [
    "NO_PATH",
    "SOURCE",
    "CacheWarning",
    "SafetyTable",
    "default_resolution",
    "grid_points",
    "safety_table",
    "table_bytes",
]

NO_PATH = 255
"""Entry of the rotation tables meaning "no safe orientation at this point"."""

TABLE_VERSION = 18  # follows the decomposition cache (FORMAT_VERSION 18)

SOURCE = "decomposition"
"""What the table is built from (part of the cache key): the exact cells of K_L."""


@dataclass(frozen=True, eq=False)
class SafetyTable:
    """Safe and free orientation bins on a grid, at rod length ``L``.

    Attributes:
        L: rod length (L_min).
        resolution: grid spacing h.
        origin: (2,) position of grid index (0, 0).
        shape: (nx, ny) grid size.
        n_bins: orientation bins; bin b is centred on ``-pi + (b + 0.5) 2 pi / n_bins``.
        cell: (nx, ny) int32 row of each grid point in the tables, -1 outside free space.
        free: (n, n_bins) bool, the bin centre is a free orientation.
        safe: (n, n_bins) bool, free and not escapable (or free, where nothing is safe).
        guaranteed: (n,) bool, the point has a non-escapable arc (``safe`` is exact there).
        ccw, cw: (n, n_bins) uint8, bins to turn counter-clockwise / clockwise from a bin
            to the nearest safe bin (any orientation on the way; ``NO_PATH`` if none).
        need: (n, n_bins) uint8, ``min(ccw, cw)``.
    """

    L: float
    resolution: float
    origin: np.ndarray
    shape: tuple[int, int]
    n_bins: int
    cell: np.ndarray
    free: np.ndarray
    safe: np.ndarray
    guaranteed: np.ndarray
    ccw: np.ndarray
    cw: np.ndarray

    @functools.cached_property
    def need(self) -> np.ndarray:
        """(n, n_bins) uint8: bins to turn, the shorter way, to the nearest safe bin."""
        return np.minimum(self.ccw, self.cw)

    @property
    def bin_width(self) -> float:
        """Width of an orientation bin (radians)."""
        return 2.0 * math.pi / self.n_bins

    def bin_of(self, theta: float) -> int:
        """The bin containing orientation ``theta``."""
        return int(((theta + math.pi) % (2.0 * math.pi)) / self.bin_width) % self.n_bins

    def bin_centre(self, b: int | np.ndarray) -> float | np.ndarray:
        """Centre orientation of bin(s) ``b``."""
        return -math.pi + (np.asarray(b) + 0.5) * self.bin_width

    def grid_index(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Grid indices (k, 2) of the nodes nearest to (k, 2) points, and which lie on it."""
        idx = np.rint((np.asarray(points, dtype=float) - self.origin) / self.resolution).astype(
            np.int64
        )
        ok = (idx[:, 0] >= 0) & (idx[:, 0] < self.shape[0]) & (idx[:, 1] >= 0)
        ok &= idx[:, 1] < self.shape[1]
        return idx, ok

    def rows(self, points: np.ndarray) -> np.ndarray:
        """Table rows of the grid points nearest to (k, 2) points (-1 outside)."""
        # grid_index's nodes, looked up flat (the policies call this every step)
        idx = np.rint((np.asarray(points, dtype=float) - self.origin) / self.resolution).astype(
            np.int64
        )
        ix, iy = idx[:, 0], idx[:, 1]
        nx, ny = self.shape
        ok = (ix.view(np.uint64) < nx) & (iy.view(np.uint64) < ny)  # negatives wrap high
        flat = self.cell.reshape(-1).take(np.where(ok, ix * ny + iy, 0))
        return np.where(ok, flat, -1).astype(np.int64)

    def inside(self, points: np.ndarray) -> np.ndarray:
        """Whether the grid points nearest to (k, 2) points lie in the free region."""
        return self.rows(points) >= 0

    def row(self, point: np.ndarray) -> int:
        """Table row of the grid point nearest to ``point``, or of the nearest in free space."""
        # rows() of one point in scalar arithmetic (the same IEEE operations; Python's
        # round, like np.rint, rounds half to even)
        i = round((float(point[0]) - float(self.origin[0])) / self.resolution)
        j = round((float(point[1]) - float(self.origin[1])) / self.resolution)
        if 0 <= i < self.shape[0] and 0 <= j < self.shape[1]:
            r = int(self.cell[i, j])
            if r >= 0:
                return r
        return self._row_search(point)

    def _row_search(self, point: np.ndarray) -> int:
        """:meth:`row` through :meth:`rows`, looking around when ``point`` is just outside."""
        r = int(self.rows(np.asarray(point, dtype=float)[None])[0])
        if r >= 0:
            return r
        # just outside the grid's free points (the evader's disc touches a wall): look around
        for k in (1, 2, 3):
            offs = self.resolution * np.array(
                [(i, j) for i in range(-k, k + 1) for j in range(-k, k + 1)], dtype=float
            )
            cand = self.rows(point + offs)
            ok = cand >= 0
            if ok.any():
                d = np.linalg.norm(offs[ok], axis=1)
                return int(cand[ok][np.argmin(d)])
        return -1


def _circular_distance(safe: np.ndarray, step: int) -> np.ndarray:
    """Bins to move (by ``step`` = +1 ccw or -1 cw) from each bin to the next safe bin.

    Vectorised over a doubled circle: the next safe bin at or after ``b`` is a running
    minimum of safe indices taken from the right (``NO_PATH`` where a row has none).
    """
    if len(safe) > _DISTANCE_ROWS:  # in chunks: the int64 temporaries stay small
        return np.concatenate(
            [
                _circular_distance(safe[k : k + _DISTANCE_ROWS], step)
                for k in range(0, len(safe), _DISTANCE_ROWS)
            ]
        )
    nb = safe.shape[1]
    s = safe if step > 0 else safe[:, ::-1]
    doubled = np.concatenate([s, s], axis=1)
    idx = np.where(doubled, np.arange(2 * nb), 4 * nb)
    nxt = np.minimum.accumulate(idx[:, ::-1], axis=1)[:, ::-1][:, :nb]
    dist = nxt - np.arange(nb)
    dist = np.where(dist >= 2 * nb, NO_PATH, np.minimum(dist, NO_PATH)).astype(np.uint8)
    return dist if step > 0 else dist[:, ::-1]


_DISTANCE_ROWS = 16_384  # rows per chunk of _circular_distance (~40 MB of temporaries)


def cache_dir() -> Path:
    """Directory of the on-disk table cache: the decompositions' (``$SURVEIL_CACHE_DIR``)."""
    return resolve_cache_dir()


def _arc_bins(arcs, centres: np.ndarray) -> np.ndarray:
    """Which bin centres lie in the union of closed arcs."""
    out = np.zeros(len(centres), dtype=bool)
    for a in arcs:
        out |= ((centres - a.lo) % (2.0 * math.pi)) <= (a.hi - a.lo)
    return out


def _classified(dec, p: np.ndarray, step: float):
    """The free arcs at ``p`` and the safe ones (``None`` if they cannot be classified).

    ``Decomposition.free_arcs`` leaves an arc unclassified (``escapable is None``) when
    ``p`` cannot be matched to a region's cells by its stops, which happens on (or within
    the polyline tolerance of) a critical curve. The classification is then borrowed
    from a point nudged off the curve by at most ``step / 4`` (it is constant inside a
    region, and the arcs move by a negligible angle); ``None`` if no nudge resolves every
    arc, and the caller claims no guarantee there.
    """
    cas = dec.free_arcs(p)
    arcs = [ca.arc for ca in cas]
    if all(ca.escapable is not None for ca in cas):
        return arcs, [ca.arc for ca in cas if not ca.escapable]
    for r in (1e-3, 1e-2, 0.1, 0.25):
        for k in range(8):
            q = p + r * step * np.array([math.cos(k * math.pi / 4), math.sin(k * math.pi / 4)])
            if not dec.map.contains(q[None])[0]:
                continue
            near = dec.free_arcs(q)
            if all(ca.escapable is not None for ca in near):
                return arcs, [ca.arc for ca in near if not ca.escapable]
    return arcs, None


_PROGRESS_POINTS = 20_000  # tables with more grid points show a bar (on a terminal)


def _build(
    world: Map, L: float, resolution: float, n_bins: int, progress: bool | None = None
) -> SafetyTable:
    from tqdm import tqdm

    from strategies.cspace import decompose

    origin, cell, pts = _free_grid(world, L, resolution)
    dec = decompose(world, L, cache=True)
    centres = -math.pi + (np.arange(n_bins) + 0.5) * (2.0 * math.pi / n_bins)
    free = np.zeros((len(pts), n_bins), dtype=bool)
    safe = np.zeros_like(free)
    show = progress if progress is not None else (None if len(pts) > _PROGRESS_POINTS else False)
    bar = tqdm(
        pts,
        desc=f"safety table {world.name} L={L:g}",
        unit="pt",
        disable=None if show is None else not show,
        leave=False,
    )
    for i, p in enumerate(bar):
        arcs, safe_arcs = _classified(dec, p, resolution)
        free[i] = _arc_bins(arcs, centres)
        if safe_arcs is not None:  # unresolved: no guarantee claimed, the free bins stand in
            safe[i] = free[i] & _arc_bins(safe_arcs, centres)
    guaranteed = safe.any(axis=1)
    safe = np.where(guaranteed[:, None], safe, free)  # Prop. 2: nothing safe, keep it free
    return _table(origin, cell, L, resolution, free, safe, guaranteed)


def _build_distinct(
    world: Map, L: float, resolution: float, n_bins: int, progress: bool | None = None
) -> SafetyTable:
    """:func:`_build`'s table with each distinct row stored once (``cell`` points the
    grid nodes at them), classified in vectorised chunks."""
    from tqdm import tqdm

    from strategies.cspace import decompose
    from strategies.policies._batch_classify import distinct_rows

    origin, cell, pts = _free_grid(world, L, resolution)
    dec = decompose(world, L, cache=True)
    centres = -math.pi + (np.arange(n_bins) + 0.5) * (2.0 * math.pi / n_bins)
    show = progress if progress is not None else (None if len(pts) > _PROGRESS_POINTS else False)
    with tqdm(
        total=len(pts),
        desc=f"safety table {world.name} L={L:g}",
        unit="pt",
        disable=None if show is None else not show,
        leave=False,
    ) as bar:
        ids, free, safe, guaranteed = distinct_rows(dec, pts, resolution, centres, bar.update)
    # the nodes pointed at their distinct rows in place, a chunk at a time: the whole
    # grid's temporaries (mask, clipped index, gathered rows, np.where's result and its
    # int32 copy) took 13 bytes a node, 2.5 GB on corner~x100's 196-million-node grid
    flat = cell.reshape(-1)
    for s in range(0, len(flat), _REMAP_NODES):
        part = flat[s : s + _REMAP_NODES]
        free_at = part >= 0
        part[free_at] = ids[part[free_at]]
    return _table(origin, cell, L, resolution, free, safe, guaranteed)


_REMAP_NODES = 1 << 20  # grid nodes per chunk of _build_distinct's remap


def _free_grid(world: Map, L: float, resolution: float):
    """:func:`grid_points`, refusing a grid with no node in the free region (a resolution
    wider than the map's rooms: at 8 on the corner world the build failed with numpy's
    IndexError, the policies' reset with it)."""
    origin, cell, pts = grid_points(world, resolution)
    if len(pts) == 0:
        raise InvalidConfigError(
            f"safety_table(map {world.name!r}, L = {L:g}): resolution = {resolution:g} leaves "
            f"no node of its {cell.shape[0]} x {cell.shape[1]} grid inside the free region; "
            f"expected a grid spacing well below the width of the map's free space (the "
            f"default is L / 20 = {default_resolution(L):g})"
        )
    return origin, cell, pts


def _table(origin, cell, L, resolution, free, safe, guaranteed) -> SafetyTable:
    return SafetyTable(
        L=float(L),
        resolution=float(resolution),
        origin=origin,
        shape=(int(cell.shape[0]), int(cell.shape[1])),
        n_bins=free.shape[1],
        cell=cell,
        free=free,
        safe=safe,
        guaranteed=guaranteed,
        ccw=_circular_distance(safe, +1),
        cw=_circular_distance(safe, -1),
    )


_ARRAYS = ("origin", "cell", "free", "safe", "guaranteed", "ccw", "cw")


def default_resolution(L: float) -> float:
    """The grid spacing a table uses unless told otherwise: ``L / 20``.

    Relative to the rod, so a map drawn in centimetres or kilometres gets the same table
    as the same map in metres (0.1 on the built-in worlds, where L_min = 2).
    """
    return float(L) / 20.0


def table_bytes(world: Map, resolution: float, n_bins: int, distinct: bool = False) -> float:
    """Estimated memory of building a table: its grid's arrays
    (:func:`~strategies.cspace.grids.grid_bytes`: 5 bytes a node of the bounding box, 24
    a free point, one chunk's temporaries) and its rows, free-region grid points x (4
    bytes per bin + 9).

    Each row holds ``free``, ``safe`` (bool), ``ccw``, ``cw`` (uint8) per bin, a row
    index and a flag. A ``distinct`` table holds its distinct rows only (bounded here by
    a chunk of classification, ``_batch_classify.CHUNK`` points, which its build holds
    at once). (The grid was left out but for a 4-byte index a node: on corner~x100 at
    L_min 2, 196 million nodes, a distinct table was estimated at 0.8 GB and its build
    took 4-7 GB.)
    """
    from strategies.policies._batch_classify import CHUNK

    points = _points_at(world.free_region.area, resolution)
    if distinct:
        points = min(points, CHUNK)
    return grid_bytes(world, resolution) + points * (4 * n_bins + 9)


@functools.lru_cache(maxsize=16)
def safety_table(
    world: Map,
    L: float,
    resolution: float | None = None,
    n_bins: int = 144,
    *,
    disk_cache: bool = True,
    memory_budget: object = None,
    progress: bool | None = None,
    distinct: bool = False,
) -> SafetyTable:
    """The :class:`SafetyTable` of ``world`` at rod length ``L`` (cached).

    Args:
        world: the map.
        L: rod length, normally L_min.
        resolution: grid spacing (default :func:`default_resolution`: ``L / 20``).
        n_bins: orientation bins (< 255).
        disk_cache: read and write ``$SURVEIL_CACHE_DIR``. A file carries its key and a
            SHA-256 of its arrays, is read without pickle, and is verified on load; a
            damaged or mismatched one (truncated, a flipped bit, empty, another table
            copied over it) is rebuilt with a one-line :class:`CacheWarning` naming it.
        memory_budget: bytes (or ``"2GB"``) the table may take; default
            ``$SURVEIL_MEMORY_BUDGET`` or half the RAM, as for decompositions.
        progress: a progress bar over the grid points (``None``: on a terminal, for
            large tables).
        distinct: store each distinct row once, the grid nodes' ``cell`` pointing at
            them (rows are then not the grid points of :func:`grid_points`), classified
            in vectorised batches: the same lookups for a fraction of the memory (1/35 on
            the pillar room at L = 0.8, h = 0.025) and about a fifth of the build time,
            for the decomposition pursuer on large grids (issue 13). The bins come from
            the vectorised kernel's arcs, within 1e-12 rad of the kernel's.

    Raises:
        InvalidConfigError: non-positive L or resolution, or a bad bin count.
        MemoryBudgetError: the table's estimated memory exceeds the budget (the message
            gives the estimate and the resolution that would fit).
    """
    where = "safety_table"
    L = validation.positive("L", L, where=where)
    if resolution is None:
        resolution = default_resolution(L)
    resolution = validation.positive("resolution", resolution, where=where)
    check_grid_spacing(world, resolution, where)
    n_bins = validation.integer("n_bins", n_bins, minimum=8, maximum=NO_PATH - 1, where=where)
    budget = _memory_budget(memory_budget)
    need = table_bytes(world, resolution, n_bins, distinct)
    if need > budget:
        fit = resolution * math.sqrt(need / budget) * 1.05
        for _ in range(100):  # the chunks' terms do not shrink as 1 / resolution^2
            if table_bytes(world, fit, n_bins, distinct) <= budget:
                break
            fit *= 1.05
        raise MemoryBudgetError(  # its knobs named late: a policy's caller has others
            f"safety_table(map {world.name!r}, L = {L:g}, resolution = {resolution:g}): the "
            f"table would need about {need / 1e9:.3g} GB, more than the memory budget of "
            f"{budget / 1e9:.3g} GB; use {MemoryBudgetError.KNOB} >= {fit:.3g} or raise the "
            f"budget with {MemoryBudgetError.BUDGET}",
            "resolution",
            size=f"{math.ceil(1.2 * need / 1e9)}GB",
        )
    key = (  # the decomposition's constants too: a changed tolerance is another table
        f"{TABLE_VERSION}|{SOURCE}|{world.digest}|{float(L).hex()}|{float(resolution).hex()}"
        f"|{n_bins}" + ("|distinct" if distinct else "") + f"|{constants_digest()}"
    )
    path = cache_dir() / f"safety_{hashlib.sha256(key.encode()).hexdigest()[:24]}.npz"
    if disk_cache:
        table = _read(path, key, float(L), float(resolution), n_bins)
        if table is not None:
            return table
    build = _build_distinct if distinct else _build
    table = build(world, float(L), float(resolution), n_bins, progress)
    if disk_cache:
        _write(path, key, table)
    return table


def _checksum(arrays: dict[str, np.ndarray]) -> str:
    h = hashlib.sha256()
    for name in _ARRAYS:
        a = np.ascontiguousarray(arrays[name])
        h.update(f"{name}|{a.dtype.str}|{a.shape}|".encode())
        h.update(a.tobytes())
    return h.hexdigest()


def _read(path: Path, key: str, L: float, resolution: float, n_bins: int) -> SafetyTable | None:
    """The table stored at ``path`` if it is intact and is the one asked for, else None."""
    if not path.exists():
        return None
    try:
        with open(path, "rb") as fh, np.load(fh, allow_pickle=False) as z:
            arrays = {name: z[name] for name in _ARRAYS}
            stored_key, stored_sum = str(z["key"]), str(z["sha256"])
        if stored_key != key:
            raise ValueError("it holds another table (key mismatch)")
        if stored_sum != _checksum(arrays):
            raise ValueError("its checksum does not match its content")
        cell = arrays["cell"]
        n = int(cell.max()) + 1 if cell.size else 0
        shapes_ok = arrays["free"].shape == (n, n_bins) == arrays["ccw"].shape
        if not shapes_ok or cell.ndim != 2:
            raise ValueError("its arrays have inconsistent shapes")
        return SafetyTable(
            L=L,
            resolution=resolution,
            origin=arrays["origin"],
            shape=(int(cell.shape[0]), int(cell.shape[1])),
            n_bins=n_bins,
            cell=cell,
            free=arrays["free"],
            safe=arrays["safe"],
            guaranteed=arrays["guaranteed"],
            ccw=arrays["ccw"],
            cw=arrays["cw"],
        )
    except Exception as exc:
        why = str(exc) or type(exc).__name__
        warnings.warn(
            f"safety table cache {path}: unusable ({why}); rebuilding it",
            CacheWarning,
            stacklevel=4,
        )
        return None


def _write(path: Path, key: str, table: SafetyTable) -> None:
    arrays = {name: getattr(table, name) for name in _ARRAYS}

    def write(fh) -> None:
        np.savez_compressed(fh, key=np.array(key), sha256=np.array(_checksum(arrays)), **arrays)

    write_cache_file(path, write, "safety table")
