"""The referee's discretisation of a map: opponent cells, the certified lattice, moves.

* **Cells.** Squares of side ``h`` centred on ``anchor + h (i, j)``, where ``anchor`` is
  the centre of the map's bounding box (so a rotation by a quarter turn or a reflection
  about the centre maps the cells onto themselves). A cell is *open to the opponent* when
  it meets the opponent's region F_c' (free space eroded by the opponent clearance); the
  opponent's real position is anywhere in its cell.
* **Certified lattice.** The cell centres whose indices are multiples of ``coarse``, kept
  when they lie in free space at least ``body_radius`` from every wall. The certified
  player sits *exactly* on these points (it steers itself there), so its position carries
  no discretisation error.
* **Moves.** Lattice vectors of length <= V tau (standing still included) whose straight
  path keeps the body radius from every wall.
* **Windows.** The opponent's cell is stored relative to the certified player: a state is
  (certified point k, window offset (a, b)), the opponent's cell being the fine cell at
  the point's index plus ``(a - hw, b - hw)``. Only offsets within range can matter, so
  every per-state array has shape ``(n_points, W, W)`` with ``W = 2 hw + 1``.

Everything here is set-up work done once per (map, parameters); shapely is used for the
eroded free region and for the few cells that meet a wall.
"""

from __future__ import annotations

import math

import numpy as np
import shapely
from numpy.lib.stride_tricks import sliding_window_view

from envs.errors import InvalidConfigError, NoStartError
from envs.geometry.segments import segment_distance
from strategies.referee.spec import GameSpec, Resolution

__all__ = [
    "Lattice",
    "count_lattice_vectors",
    "grid_shape",
    "lattice_vectors",
    "segment_wall_distance",
    "window_half_width",
]

_QUAD_SEGS = 32
"""Arc segments per quarter circle of the eroded region (its polygon lies *outside* the
true eroded region, see :meth:`Lattice._opponent_cells`)."""


def segment_wall_distance(A: np.ndarray, B: np.ndarray, world) -> np.ndarray:
    """Distance from each segment A[i]-B[i] to the nearest wall edge (0 if they meet).

    Args:
        A: (k, 2) segment starts.
        B: (k, 2) segment ends.
        world: the :class:`~envs.maps.Map`.

    Returns:
        (k,) distances.
    """
    a = world.edge_start[None]
    b = world.edge_end[None]
    out = np.empty(len(A))
    chunk = max(1, 2_000_000 // max(1, a.shape[1]))
    for s in range(0, len(A), chunk):
        d = segment_distance(A[s : s + chunk, None, :], B[s : s + chunk, None, :], a, b)
        out[s : s + chunk] = d.min(axis=1)
    return out


def grid_shape(bounds: tuple[float, float, float, float], h: float) -> tuple[int, int, int, int]:
    """``(i0, j0, nx, ny)``: the cells of side ``h`` covering ``bounds``, centred on the
    bounding box's centre (the first cell's indices and the counts along x and y)."""
    x0, y0, x1, y1 = bounds
    cx, cy = 0.5 * (x0 + x1), 0.5 * (y0 + y1)
    eps = 1e-9
    i0 = math.ceil((x0 - cx) / h - 0.5 - eps)
    j0 = math.ceil((y0 - cy) / h - 0.5 - eps)
    i1 = math.floor((x1 - cx) / h + 0.5 + eps)
    j1 = math.floor((y1 - cy) / h + 0.5 + eps)
    return i0, j0, i1 - i0 + 1, j1 - j0 + 1


def window_half_width(reach: float, h: float) -> int:
    """Half-width in cells of a window that holds every cell whose disc (radius
    ``h / sqrt(2)``) comes within ``reach`` of the window's centre, plus one cell."""
    return math.ceil((reach + h / math.sqrt(2.0)) / h) + 1


def lattice_vectors(length: float, spacing: float) -> list[tuple[int, int]]:
    """The integer vectors (in spacings) of length <= ``length``: standing still first,
    then by length and angle (a fixed, symmetric order)."""
    r = math.floor(length / spacing + 1e-9)
    cand = [
        (a, b)
        for a in range(-r, r + 1)
        for b in range(-r, r + 1)
        if math.hypot(a, b) * spacing <= length * (1.0 + 1e-12)
    ]
    cand.sort(key=lambda v: (v != (0, 0), math.hypot(*v), math.atan2(v[1], v[0])))
    return cand


EXACT_COUNT_RADIUS = 100_000
"""Up to this radius in spacings :func:`count_lattice_vectors` counts exactly (a column
of the disc at a time, vectorised: about 10 ms at this radius); beyond, the area of the
disc (Gauss's circle problem: the error, O(r^(2/3)), is about 1e-7 of the count there)."""


def count_lattice_vectors(length: float, spacing: float) -> int:
    """``len(lattice_vectors(length, spacing))`` without listing them: the memory
    estimate of a solve needs the count only, and at a huge resolution the list (millions
    of vectors, sorted) took most of a refusal's time (26 s at 100,000 cells per L_min).

    Examples:
        >>> [count_lattice_vectors(x, 1.0) for x in (0.5, 1.0, 1.5, 2.0)]
        [1, 5, 9, 13]
        >>> count_lattice_vectors(7.3, 0.7) == len(lattice_vectors(7.3, 0.7))
        True
    """
    r = math.floor(length / spacing + 1e-9)
    if r > EXACT_COUNT_RADIUS:
        return round(math.pi * (length * (1.0 + 1e-12) / spacing) ** 2)
    a = np.arange(0, r + 1, dtype=np.float64)
    # the largest b with hypot(a, b) * spacing <= length * (1 + 1e-12), as lattice_vectors
    # tests it: from the square root, then corrected by the test itself at the boundary
    limit = length * (1.0 + 1e-12)
    b = np.floor(np.sqrt(np.maximum((limit / spacing) ** 2 - a * a, 0.0)))
    fits = lambda b: (np.hypot(a, b) * spacing <= limit) & (b <= r)
    b = np.where(fits(b + 1.0), b + 1.0, b)
    b = np.where(fits(b), b, b - 1.0)  # -1: no vector in this column (only past a = r)
    per_column = np.where(b >= 0.0, 2.0 * b + 1.0, 0.0)  # b from -b to b
    return int(per_column[0] + 2.0 * per_column[1:].sum())


class Lattice:
    """Cells, certified points and moves of one game at one resolution.

    Args:
        spec: the game.
        res: the resolution.
        role: the certified player, ``"pursuer"`` or ``"evader"``.
        reach: largest distance, beyond ``l_max``, at which an opponent cell must still be
            represented (the window's half-width is ``l_max + reach`` plus one cell).

    Attributes:
        h: cell side.
        spacing: certified lattice spacing (``coarse * h``).
        delta: ``h / sqrt(2)``, the radius of a cell about its centre.
        anchor: (2,) the centre of the map's bounding box.
        i0, j0: fine index of the first row/column of :attr:`cell_open`.
        cell_open: (nx, ny) cells open to the opponent.
        points: (n, 2) certified lattice points.
        point_cells: (n, 2) their fine indices (multiples of ``coarse``).
        hw: window half-width in cells; ``W = 2 hw + 1``.
        offsets: (W, W, 2) the vector from a certified point to each window cell's centre.
    """

    def __init__(self, spec: GameSpec, res: Resolution, role: str, reach: float = 0.0) -> None:
        if role not in ("pursuer", "evader"):
            raise InvalidConfigError(f"role = {role!r}: expected 'pursuer' or 'evader'")
        self.spec = spec
        self.res = res
        self.role = role
        world = spec.map
        self.h = h = res.cell
        self.coarse = res.coarse
        self.spacing = res.spacing
        self.delta = res.cell_radius
        x0, y0, x1, y1 = world.bounds
        self.anchor = np.array([0.5 * (x0 + x1), 0.5 * (y0 + y1)])
        self.i0, self.j0, self.nx, self.ny = grid_shape(world.bounds, h)
        i1, j1 = self.i0 + self.nx - 1, self.j0 + self.ny - 1
        n_cells = self.nx * self.ny
        if n_cells > 50_000_000:
            raise InvalidConfigError(
                f"cell = {h!r}: {self.nx} x {self.ny} cells on map {world.name!r} is too fine"
            )
        ii, jj = np.meshgrid(np.arange(self.i0, i1 + 1), np.arange(self.j0, j1 + 1), indexing="ij")
        self.centers = self.anchor + h * np.stack([ii, jj], axis=-1).astype(float)
        self.cell_open = self._opponent_cells()
        self._certified_points()
        self.hw = window_half_width(spec.l_max + reach, h)
        w = np.arange(-self.hw, self.hw + 1) * h
        self.offsets = np.stack(np.meshgrid(w, w, indexing="ij"), axis=-1)

    # ------------------------------------------------------------------ cells
    def _opponent_cells(self) -> np.ndarray:
        """Cells meeting F_c'. The eroded region's polygon has its vertices on the true
        arcs, so its chords cut *into* the obstacles' rounded corners: it contains the
        true region, and no cell the opponent can reach is missed."""
        free = self.spec.map.free_region
        region = free.buffer(-self.spec.opponent_clearance, quad_segs=_QUAD_SEGS)
        self.opponent_region = region
        if region.is_empty:
            raise InvalidConfigError(
                f"opponent_clearance = {self.spec.opponent_clearance!r}: no point of map "
                f"{self.spec.map.name!r} is that far from the walls"
            )
        shapely.prepare(region)
        c = self.centers.reshape(-1, 2)
        r = 0.5 * self.h
        boxes = shapely.box(c[:, 0] - r, c[:, 1] - r, c[:, 0] + r, c[:, 1] + r)
        self._boxes = boxes.reshape(self.nx, self.ny)
        return shapely.intersects(region, boxes).reshape(self.nx, self.ny)

    def cell_of(self, points: np.ndarray) -> np.ndarray:
        """Fine (i, j) indices of the cells containing ``points`` (k, 2) (ties go up)."""
        p = np.atleast_2d(np.asarray(points, dtype=float))
        return np.floor((p - self.anchor) / self.h + 0.5).astype(np.int64)

    def cell_open_at(self, ij: np.ndarray) -> np.ndarray:
        """Whether fine cells ``ij`` (k, 2) are open to the opponent (False off the grid)."""
        ij = np.atleast_2d(ij)
        a = ij[:, 0] - self.i0
        b = ij[:, 1] - self.j0
        inside = (a >= 0) & (a < self.nx) & (b >= 0) & (b < self.ny)
        out = np.zeros(len(ij), dtype=bool)
        out[inside] = self.cell_open[a[inside], b[inside]]
        return out

    def open_cells_within(self, x: np.ndarray, r: float) -> np.ndarray:
        """Fine (i, j) indices of the open cells within distance ``r`` of the point ``x``
        (the cells a player at ``x`` can end in after moving at most ``r``)."""
        x = np.asarray(x, dtype=float)
        lo = np.floor((x - r - self.anchor) / self.h - 0.5).astype(int)
        hi = np.ceil((x + r - self.anchor) / self.h + 0.5).astype(int)
        ii, jj = np.meshgrid(
            np.arange(lo[0], hi[0] + 1), np.arange(lo[1], hi[1] + 1), indexing="ij"
        )
        ij = np.stack([ii.ravel(), jj.ravel()], axis=1)
        c = self.anchor + self.h * ij
        dx = np.maximum(np.abs(c[:, 0] - x[0]) - 0.5 * self.h, 0.0)
        dy = np.maximum(np.abs(c[:, 1] - x[1]) - 0.5 * self.h, 0.0)
        ij = ij[np.hypot(dx, dy) <= r]
        return ij[self.cell_open_at(ij)]

    def convex_cells(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """For each open cell: whether cell ∩ F is convex, a point of cell ∩ F_c', and
        whether the whole cell lies in free space (its centre as that point).

        Used by the evader bound's robust occlusion test. A cell whose centre is at least
        ``max(delta, c')`` inside free space is convex with its centre as the point; the
        others (cells meeting a wall) are clipped with shapely.

        Returns:
            ``(convex, rep, interior)``: (nx, ny) bool, (nx, ny, 2) float (NaN where not
            open) and (nx, ny) bool.
        """
        world = self.spec.map
        c = self.centers.reshape(-1, 2)
        clear = world.distance_to_walls(c)
        inside = world.contains(c) & (clear >= max(self.delta, self.spec.opponent_clearance))
        convex = inside.copy()
        rep = np.where(inside[:, None], c, np.nan)
        open_ = self.cell_open.reshape(-1)
        todo = np.flatnonzero(open_ & ~inside)
        if len(todo):
            boxes = self._boxes.reshape(-1)[todo]
            piece = shapely.intersection(boxes, world.free_region)
            hull = shapely.convex_hull(piece)
            a_piece = shapely.area(piece)
            a_hull = shapely.area(hull)
            single = shapely.get_type_id(piece) == 3  # Polygon, not MultiPolygon
            convex[todo] = single & (a_hull <= a_piece * (1.0 + 1e-9) + 1e-15)
            sub = shapely.intersection(boxes, self.opponent_region)
            ok = ~shapely.is_empty(sub)
            got = np.full((len(todo), 2), np.nan)
            got[ok] = shapely.get_coordinates(shapely.point_on_surface(sub[ok]))
            rep[todo] = got
        shape = (self.nx, self.ny)
        return convex.reshape(shape), rep.reshape(*shape, 2), inside.reshape(shape)

    # ------------------------------------------------------------------ certified lattice
    def _certified_points(self) -> None:
        world = self.spec.map
        m = self.coarse
        lo_i = -((-self.i0) // m) * m  # the smallest multiple of m >= i0
        lo_j = -((-self.j0) // m) * m
        ci = np.arange(lo_i, self.i0 + self.nx, m)
        cj = np.arange(lo_j, self.j0 + self.ny, m)
        gi, gj = np.meshgrid(ci, cj, indexing="ij")
        idx = np.stack([gi.ravel(), gj.ravel()], axis=1)
        pts = self.anchor + self.h * idx.astype(float)
        keep = world.contains(pts) & (world.distance_to_walls(pts) >= self.spec.body_radius)
        self.points = pts[keep]
        self.point_cells = idx[keep]
        if len(self.points) == 0:
            raise NoStartError(
                f"no lattice point of spacing {self.spacing:g} lies {self.spec.body_radius:g} "
                f"from the walls of map {self.spec.map.name!r}; try another resolution (the "
                "lattices are not nested: where passages are about as narrow as the agents, "
                "a finer one can miss them too)"
            )
        self._lookup = {(int(i), int(j)): k for k, (i, j) in enumerate(self.point_cells)}

    @property
    def n_points(self) -> int:
        """Number of certified lattice points."""
        return len(self.points)

    def points_within(self, x: np.ndarray, radius: float) -> np.ndarray:
        """Indices of the certified points within ``radius`` of the real position ``x``,
        nearest first. A tenth of the robust margin is allowed beyond ``radius``: a
        policy reads its position from a float32 observation, a few 1e-7 off its lattice
        point, and must keep its full-length moves (the robust tests absorb the overshoot).
        """
        d = np.hypot(*(self.points - np.asarray(x, dtype=float)).T)
        idx = np.flatnonzero(d <= radius + 0.1 * self.spec.margin)
        return idx[np.argsort(d[idx], kind="stable")]

    def point_index(self, ij: np.ndarray) -> np.ndarray:
        """Index of the certified point at fine indices ``ij`` (k, 2), or -1."""
        ij = np.atleast_2d(ij)
        return np.array([self._lookup.get((int(i), int(j)), -1) for i, j in ij], dtype=np.int64)

    def moves(self, length: float) -> tuple[np.ndarray, np.ndarray]:
        """The certified player's moves of at most ``length`` and where each one leads.

        Returns:
            ``(vectors, targets)``: (n_moves, 2) integer vectors in cells (multiples of
            ``coarse``; the first is (0, 0)), and (n_points, n_moves) the index of the
            point each move reaches, -1 where it leaves the lattice or its path comes
            closer than the body radius to a wall.
        """
        m = self.coarse
        vec = np.array(lattice_vectors(length, self.spacing), dtype=np.int64) * m
        n, k = self.n_points, len(vec)
        dest = self.point_cells[:, None, :] + vec[None, :, :]
        targets = self.point_index(dest.reshape(-1, 2)).reshape(n, k)
        ok = targets >= 0
        ok[:, 0] = True
        rows, cols = np.nonzero(ok[:, 1:])
        if len(rows):
            A = self.points[rows]
            B = A + self.h * vec[1:][cols].astype(float)
            clear = segment_wall_distance(A, B, self.spec.map)
            bad = clear < self.spec.body_radius * (1.0 - 1e-9)
            ok[rows[bad], cols[bad] + 1] = False
        targets = np.where(ok, targets, -1)
        targets[:, 0] = np.arange(n)
        return vec, targets

    # ------------------------------------------------------------------ windows
    @property
    def W(self) -> int:
        """Window side, ``2 hw + 1``."""
        return 2 * self.hw + 1

    def windows(self, grid: np.ndarray, fill) -> np.ndarray:
        """Gather a per-cell (nx, ny) array into per-point windows (n_points, W, W)."""
        hw = self.hw
        pad = [(hw, hw), (hw, hw)] + [(0, 0)] * (grid.ndim - 2)
        g = np.pad(grid, pad, constant_values=fill)
        view = sliding_window_view(g, (self.W, self.W), axis=(0, 1))
        a = self.point_cells[:, 0] - self.i0
        b = self.point_cells[:, 1] - self.j0
        out = view[a, b]
        if grid.ndim > 2:  # sliding_window_view puts the window axes last
            out = np.moveaxis(out, (-2, -1), (1, 2))
        return np.ascontiguousarray(out)

    def window_cell(self, k: np.ndarray, ij: np.ndarray) -> np.ndarray:
        """Window offsets (a, b) of fine cells ``ij`` seen from certified points ``k``."""
        return np.atleast_2d(ij) - self.point_cells[k] + self.hw
