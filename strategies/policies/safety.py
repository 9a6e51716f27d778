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
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from envs.errors import InvalidConfigError
from envs.maps import Map
from strategies.cspace.cache import resolve_cache_dir
from strategies.cspace.grids import grid_points

__all__ = ["NO_PATH", "SOURCE", "SafetyTable", "grid_points", "safety_table"]

NO_PATH = 255
"""Entry of the rotation tables meaning "no safe orientation at this point"."""

TABLE_VERSION = 2

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

    def rows(self, points: np.ndarray) -> np.ndarray:
        """Table rows of the grid points nearest to (k, 2) points (-1 outside)."""
        idx = np.rint((np.asarray(points, dtype=float) - self.origin) / self.resolution).astype(
            np.int64
        )
        ok = (idx[:, 0] >= 0) & (idx[:, 0] < self.shape[0]) & (idx[:, 1] >= 0)
        ok &= idx[:, 1] < self.shape[1]
        out = np.full(len(idx), -1, dtype=np.int64)
        out[ok] = self.cell[idx[ok, 0], idx[ok, 1]]
        return out

    def row(self, point: np.ndarray) -> int:
        """Table row of the grid point nearest to ``point``, or of the nearest in free space."""
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
    """Bins to move (by ``step`` = +1 ccw or -1 cw) from each bin to the next safe bin."""
    _n, nb = safe.shape
    dist = np.where(safe, 0, NO_PATH).astype(np.int32)
    for _ in range(nb):
        nxt = np.roll(dist, -step, axis=1) + 1
        new = np.minimum(dist, nxt)
        if np.array_equal(new, dist):
            break
        dist = new
    return np.minimum(dist, NO_PATH).astype(np.uint8)


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


def _build(world: Map, L: float, resolution: float, n_bins: int) -> SafetyTable:
    from strategies.cspace import decompose

    dec = decompose(world, L, cache=True)
    origin, cell, pts = grid_points(world, resolution)
    centres = -math.pi + (np.arange(n_bins) + 0.5) * (2.0 * math.pi / n_bins)
    free = np.zeros((len(pts), n_bins), dtype=bool)
    safe = np.zeros_like(free)
    for i, p in enumerate(pts):
        arcs, safe_arcs = _classified(dec, p, resolution)
        free[i] = _arc_bins(arcs, centres)
        if safe_arcs is not None:  # unresolved: no guarantee claimed, the free bins stand in
            safe[i] = free[i] & _arc_bins(safe_arcs, centres)
    guaranteed = safe.any(axis=1)
    safe = np.where(guaranteed[:, None], safe, free)  # Prop. 2: nothing safe, keep it free
    return SafetyTable(
        L=float(L),
        resolution=float(resolution),
        origin=origin,
        shape=(int(cell.shape[0]), int(cell.shape[1])),
        n_bins=n_bins,
        cell=cell,
        free=free,
        safe=safe,
        guaranteed=guaranteed,
        ccw=_circular_distance(safe, +1),
        cw=_circular_distance(safe, -1),
    )


@functools.lru_cache(maxsize=16)
def safety_table(
    world: Map, L: float, resolution: float = 0.1, n_bins: int = 144, *, disk_cache: bool = True
) -> SafetyTable:
    """The :class:`SafetyTable` of ``world`` at rod length ``L`` (cached).

    Args:
        world: the map.
        L: rod length, normally L_min.
        resolution: grid spacing.
        n_bins: orientation bins (< 255).
        disk_cache: read and write ``$SURVEIL_CACHE_DIR``.

    Raises:
        InvalidConfigError: non-positive L or resolution, or a bad bin count.
    """
    if not (math.isfinite(L) and L > 0 and math.isfinite(resolution) and resolution > 0):
        raise InvalidConfigError(
            f"L and resolution must be > 0, got L={L!r}, resolution={resolution!r}"
        )
    if not 8 <= int(n_bins) < NO_PATH:
        raise InvalidConfigError(f"n_bins must be in [8, {NO_PATH}), got {n_bins!r}")
    key = hashlib.sha256(
        f"{TABLE_VERSION}|{SOURCE}|{world.digest}|{L!r}|{resolution!r}|{n_bins}".encode()
    ).hexdigest()[:24]
    path = cache_dir() / f"safety_{key}.npz"
    if disk_cache and path.exists():
        try:
            with np.load(path) as z:
                return SafetyTable(
                    L=float(L),
                    resolution=float(resolution),
                    origin=z["origin"],
                    shape=tuple(int(v) for v in z["cell"].shape),
                    n_bins=int(n_bins),
                    cell=z["cell"],
                    free=z["free"],
                    safe=z["safe"],
                    guaranteed=z["guaranteed"],
                    ccw=z["ccw"],
                    cw=z["cw"],
                )
        except (OSError, KeyError, ValueError):
            pass  # a damaged cache file: rebuild it
    table = _build(world, float(L), float(resolution), int(n_bins))
    if disk_cache:
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            tmp = path.with_suffix(f".{os.getpid()}.tmp.npz")
            np.savez_compressed(
                tmp,
                origin=table.origin,
                cell=table.cell,
                free=table.free,
                safe=table.safe,
                guaranteed=table.guaranteed,
                ccw=table.ccw,
                cw=table.cw,
            )
            os.replace(tmp, path)
        except OSError:
            pass  # a read-only home: keep the table in memory only
    return table
