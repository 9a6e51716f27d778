"""A lookup table of safe rod orientations at L_min, built once per map from the cspace graph.

The analytic policies decide in microseconds by looking up, at the grid point nearest to
an evader position, which orientation bins are *free* (the rod of length L_min touches
no wall) and which are *safe* (free and in a non-escapable cell, Sec. 4), and how far
the rod must turn, counter-clockwise or clockwise, to reach a safe orientation.

The source is the configuration-space graph of :mod:`strategies.cspace.grid_oracle`
(grid points, the exact free arcs at each, overlap edges, and the least fixed point of
the escapable-cell definition). Where a grid point carries no safe arc at all (Prop. 2:
every cell above it escapable) the table falls back to its free bins, so a pursuer still
keeps the rod clear of walls where no guarantee exists.

Tables are cached in memory and on disk (``$SURVEIL_CACHE_DIR``, default
``~/.cache/surveil``), keyed by the map digest and the parameters.
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

__all__ = ["NO_PATH", "SafetyTable", "cspace_graph", "safety_table"]

NO_PATH = 255
"""Entry of the rotation tables meaning "no safe orientation at this point"."""

TABLE_VERSION = 1


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
    """Directory of the on-disk table cache (``$SURVEIL_CACHE_DIR`` or ``~/.cache/surveil``)."""
    return Path(os.environ.get("SURVEIL_CACHE_DIR", Path.home() / ".cache" / "surveil"))


@functools.lru_cache(maxsize=4)
def cspace_graph(world: Map, L: float, resolution: float):
    """The cspace grid graph of ``world`` at rod length ``L`` (shared, cached in memory)."""
    from strategies.cspace.grid_oracle import grid_graph

    return grid_graph(world, L, resolution=resolution)


def _build(world: Map, L: float, resolution: float, n_bins: int) -> SafetyTable:
    g = cspace_graph(world, L, resolution)
    pts = g.points
    origin = pts.min(axis=0)
    idx = np.rint((pts - origin) / resolution).astype(np.int64)
    shape = (int(idx[:, 0].max()) + 1, int(idx[:, 1].max()) + 1)
    cell = np.full(shape, -1, dtype=np.int32)
    cell[idx[:, 0], idx[:, 1]] = np.arange(len(pts), dtype=np.int32)
    centres = -math.pi + (np.arange(n_bins) + 0.5) * (2.0 * math.pi / n_bins)
    free = np.zeros((len(pts), n_bins), dtype=bool)
    safe = np.zeros_like(free)
    esc = g.escapable
    for node in range(g.n_nodes):
        p = g.node_point[node]
        lo, hi = g.node_lo[node], g.node_hi[node]
        inside = ((centres - lo) % (2.0 * math.pi)) <= (hi - lo)
        free[p] |= inside
        if not esc[node]:
            safe[p] |= inside
    guaranteed = safe.any(axis=1)
    safe = np.where(guaranteed[:, None], safe, free)
    return SafetyTable(
        L=float(L),
        resolution=float(resolution),
        origin=origin,
        shape=shape,
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
        f"{TABLE_VERSION}|{world.digest}|{L!r}|{resolution!r}|{n_bins}".encode()
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
