"""Regular grids of evader positions over a map's free region (product code).

Tables that policies look up (the safety table, the escape plan's walks) and test
oracles sample the free region on a grid; this module is the one place that makes it.
The grid is centred in the map's bounding box, and a point belongs to it when it lies
strictly inside the free region (farther than the geometry kernel's length tolerance
from every wall). Membership is decided by shapely's prepared predicates, vectorised,
so a grid of millions of points over a map of thousands of walls takes seconds, not the
``points x walls`` work of a brute-force distance.

Example:
    >>> from envs.maps import Map
    >>> room = Map([(0, 0), (4, 0), (4, 2), (0, 2)], [[(1, 0.5), (2, 0.5), (2, 1.5), (1, 1.5)]])
    >>> origin, cell, pts = grid_points(room, 0.5)
    >>> origin.tolist(), cell.shape, len(pts)
    ([0.25, 0.25], (8, 4), 28)
"""

from __future__ import annotations

import math

import numpy as np
import shapely

from envs.errors import InvalidConfigError
from envs.maps.map import Map
from envs.tolerances import REL_LENGTH_TOL

__all__ = ["check_grid_spacing", "grid_axis", "grid_bytes", "grid_points", "grid_size", "points_at"]

_CHUNK = 1 << 20  # points per vectorised membership test
_CHUNK_BYTES = 58
"""Bytes a node of one chunk of :func:`grid_points`' membership test holds at once: the
two divmod indices (16; its int64 index, 8, is freed after the divmod), its coordinates
(16) and flag (1), and a node inside the free region its index (8), coordinates (16) and
a flag (1, :func:`_near_boxes`): 58 at most (42-44 measured with tracemalloc on
corner~x3). Only the few nodes near a wall are made shapely points (before, every free
node was: 90 bytes, 76-86 measured)."""


def check_grid_spacing(world: Map, resolution: float, where: str) -> None:
    """Refuse a grid spacing so fine that the grid's node count is no finite float (the
    memory estimates then overflowed: ``resolution = 1e-300`` ended in an OverflowError
    or ZeroDivisionError instead of a message). Such a spacing lies far below the map's
    length tolerance (``REL_LENGTH_TOL`` x its scale), which the message names; coarser
    ones go on to the memory budget's checks, which name a spacing that fits.

    Raises:
        InvalidConfigError: naming the value, the map and its length tolerance.
    """
    try:
        nodes = (world.scale / resolution) ** 2
    except (OverflowError, ZeroDivisionError):
        nodes = math.inf
    if math.isfinite(nodes):
        return
    raise InvalidConfigError(
        f"{where}(map {world.name!r}): resolution = {resolution:g}: expected a grid spacing "
        f"no finer than the map's length tolerance {REL_LENGTH_TOL * world.scale:.3g} "
        f"(REL_LENGTH_TOL x its scale {world.scale:g}); this grid's node count overflows"
    )


def grid_size(lo: float, hi: float, resolution: float) -> int:
    """How many abscissae :func:`grid_axis` has, without making them (a caller checks a
    grid's memory before allocating it)."""
    return max(1, math.floor((hi - lo) / resolution))


def grid_axis(lo: float, hi: float, resolution: float) -> np.ndarray:
    """Grid abscissae with spacing ``resolution``, centred in ``[lo, hi]`` (at least one)."""
    n = grid_size(lo, hi, resolution)
    return lo + 0.5 * ((hi - lo) - (n - 1) * resolution) + resolution * np.arange(n)


def points_at(area: float, resolution: float) -> float:
    """``area / resolution**2``, the grid points of a free region, also where the square
    overflows (resolution 1e155: OverflowError) or underflows to 0 (1e-300:
    ZeroDivisionError); ``**`` kept, not ``*``: they differ in the last bit for some
    spacings, and the tables' kind is chosen by this count."""
    try:
        sq = resolution**2
    except OverflowError:
        return 0.0
    return area / sq if sq > 0.0 else math.inf


def grid_bytes(world: Map, resolution: float) -> float:
    """Peak memory of :func:`grid_points` (bytes, estimated before building it): 5 bytes
    a node of the bounding box (its membership flag and int32 row index), 24 a point of
    the free region (its float64 coordinates and int64 index) and one chunk's
    temporaries (``_CHUNK_BYTES`` a node of a chunk); the points counted as
    :func:`points_at`."""
    x0, y0, x1, y1 = world.bounds
    nodes = max(1.0, (x1 - x0) / resolution) * max(1.0, (y1 - y0) / resolution)
    points = points_at(world.free_region.area, resolution)
    return 5.0 * nodes + 24.0 * points + _CHUNK_BYTES * min(nodes, _CHUNK)


def grid_points(world: Map, resolution: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The grid points strictly inside the free region.

    Args:
        world: the map.
        resolution: grid spacing (> 0).

    Returns:
        ``(origin, cell, points)``: the position of grid index (0, 0); an (nx, ny) int32
        array giving each grid node's row in ``points`` (-1 outside the free region);
        the (k, 2) free points in row order (x index major).
    """
    xmin, ymin, xmax, ymax = world.bounds
    xs, ys = grid_axis(xmin, xmax, resolution), grid_axis(ymin, ymax, resolution)
    free = world.prepared_free_region
    walls = shapely.boundary(world.free_region)
    shapely.prepare(walls)
    eps = REL_LENGTH_TOL * world.scale
    lo, hi = _wall_boxes(walls, 2.0 * eps)
    keep = np.zeros(len(xs) * len(ys), dtype=bool)
    # node k is (k // ny, k % ny), x index major: computed a chunk at a time, not held as
    # two int64 arrays over the grid (16 bytes a node: 3.1 GB on a 196-million-node grid;
    # corner~x100 at L_min 2 reached 7 GB here, in the shooting evader's reset)
    ny = len(ys)
    for s in range(0, len(keep), _CHUNK):
        gi, gj = np.divmod(np.arange(s, min(s + _CHUNK, len(keep))), ny)
        x, y = xs[gi], ys[gj]
        ok = shapely.contains_xy(free, x, y)
        idx = np.flatnonzero(ok)
        # only the free nodes near a wall segment's box can lie within eps of a wall
        idx = idx[_near_boxes(x[idx], y[idx], lo, hi)]
        ok[idx] = ~shapely.dwithin(walls, shapely.points(x[idx], y[idx]), eps)
        keep[s : s + _CHUNK] = ok
    idx = np.flatnonzero(keep)
    cell = np.full(len(keep), -1, dtype=np.int32)
    cell[idx] = np.arange(len(idx), dtype=np.int32)
    pts = np.empty((len(idx), 2))
    for s in range(0, len(idx), _CHUNK):
        gi, gj = np.divmod(idx[s : s + _CHUNK], ny)
        pts[s : s + _CHUNK, 0], pts[s : s + _CHUNK, 1] = xs[gi], ys[gj]
    return np.array([xs[0], ys[0]]), cell.reshape(len(xs), len(ys)), pts


def _wall_boxes(walls, margin: float) -> tuple[np.ndarray, np.ndarray]:
    """The corners ``(lo, hi)``, (m, 2) each, of the bounding boxes of the segments of
    ``walls`` (a line geometry), grown by ``margin``."""
    parts = shapely.get_parts(walls)
    lo, hi = [np.zeros((0, 2))], [np.zeros((0, 2))]
    for line in parts:
        c = shapely.get_coordinates(line)
        lo.append(np.minimum(c[:-1], c[1:]) - margin)
        hi.append(np.maximum(c[:-1], c[1:]) + margin)
    return np.concatenate(lo), np.concatenate(hi)


def _near_boxes(x: np.ndarray, y: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """(n,) bool: the point ``(x[k], y[k])`` lies in one of the boxes ``[lo, hi]``; ``x``
    sorted (a chunk of an x-major grid). A point outside every box grown by twice the
    wall tolerance is farther than it from every wall: :func:`grid_points` tests only the
    others (making a shapely point of every free node and testing it against the walls
    was 4.8 of the shooting evader's 21 s reset on a 200 m floor plan at L_min 3)."""
    near = np.zeros(len(x), dtype=bool)
    if not len(x):
        return near
    first = np.searchsorted(x, lo[:, 0], "left")
    last = np.searchsorted(x, hi[:, 0], "right")
    for k in np.flatnonzero(last > first).tolist():
        a, b = first[k], last[k]
        yk = y[a:b]
        near[a:b] |= (yk >= lo[k, 1]) & (yk <= hi[k, 1])
    return near
