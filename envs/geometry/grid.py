"""A uniform bucket grid over a map: which wall edges / vertices lie near a query.

Segments are ``p-q`` (lower case: any two ends; capital P is the pursuer project-wide).
Built once per kernel. Each edge is registered in every cell that it, grown by the
kernel's tolerance ``pad``, overlaps; so any point within ``pad`` of an edge lies in a
cell that lists it. A segment query visits, row by row, exactly the cells that the
segment (grown by ``pad``) overlaps, so a query costs the number of nearby edges, not the
size of the map. Pure Python on purpose: per-call numpy overhead dominates at this size.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["Grid"]


class Grid:
    """Buckets of item indices over the box ``[x0, x0 + nx h] x [y0, y0 + ny h]``.

    Args:
        lo: (x0, y0), lower-left corner.
        hi: upper-right corner of the region to cover.
        n_items_hint: number of items, to size the cells (about two cells per item).
        pad: tolerance by which item boxes and query shapes are grown.
        max_cells: cap on cells per axis.
    """

    def __init__(
        self,
        lo: tuple[float, float],
        hi: tuple[float, float],
        n_items_hint: int,
        pad: float,
        max_cells: int = 256,
    ) -> None:
        w = max(hi[0] - lo[0], pad)
        h = max(hi[1] - lo[1], pad)
        size = math.sqrt(w * h / max(2 * n_items_hint, 1))
        size = max(size, w / max_cells, h / max_cells)
        self.x0 = float(lo[0]) - pad
        self.y0 = float(lo[1]) - pad
        self.h = float(size)
        self.inv_h = 1.0 / self.h
        self.nx = max(1, math.ceil((w + 2 * pad) / size))
        self.ny = max(1, math.ceil((h + 2 * pad) / size))
        self.pad = float(pad)
        self._cells: list[list[int]] = [[] for _ in range(self.nx * self.ny)]
        self.cells: list[tuple[int, ...]] = []

    # ------------------------------------------------------------------ building
    def ix(self, x: float) -> int:
        """Column of the cell containing x (clamped to the grid)."""
        i = math.floor((x - self.x0) * self.inv_h)
        return 0 if i < 0 else (self.nx - 1 if i >= self.nx else i)

    def iy(self, y: float) -> int:
        """Row of the cell containing y (clamped to the grid)."""
        j = math.floor((y - self.y0) * self.inv_h)
        return 0 if j < 0 else (self.ny - 1 if j >= self.ny else j)

    def insert_segment(self, item: int, px: float, py: float, qx: float, qy: float) -> None:
        """Register ``item`` in every cell the segment p-q (grown by ``pad``) overlaps."""
        for c in self.segment_cells(px, py, qx, qy):
            self._cells[c].append(item)

    def insert_box(self, item: int, xmin: float, ymin: float, xmax: float, ymax: float) -> None:
        """Register ``item`` in every cell its box (grown by ``pad``) overlaps."""
        p = self.pad
        for j in range(self.iy(ymin - p), self.iy(ymax + p) + 1):
            row = j * self.nx
            for i in range(self.ix(xmin - p), self.ix(xmax + p) + 1):
                self._cells[row + i].append(item)

    def freeze(self) -> None:
        """Finish building: cells become tuples."""
        self.cells = [tuple(c) for c in self._cells]
        del self._cells

    def cell_centers(self) -> np.ndarray:
        """(ny * nx, 2) centres of the cells, in cell-index order."""
        ii, jj = np.meshgrid(np.arange(self.nx), np.arange(self.ny))
        return np.stack(
            [self.x0 + (ii.ravel() + 0.5) * self.h, self.y0 + (jj.ravel() + 0.5) * self.h], axis=1
        )

    # ------------------------------------------------------------------ queries
    def cell_of(self, x: float, y: float) -> int:
        """Index of the cell containing (x, y) (clamped to the grid)."""
        return self.iy(y) * self.nx + self.ix(x)

    def query_box(self, xmin: float, ymin: float, xmax: float, ymax: float):
        """Items registered in the cells the box overlaps (a tuple or a set)."""
        j0, j1 = self.iy(ymin), self.iy(ymax)
        i0, i1 = self.ix(xmin), self.ix(xmax)
        cells = self.cells
        if j0 == j1 and i0 == i1:
            return cells[j0 * self.nx + i0]
        out: set[int] = set()
        for j in range(j0, j1 + 1):
            row = j * self.nx
            for i in range(i0, i1 + 1):
                out.update(cells[row + i])
        return out

    def segment_cells(self, px: float, py: float, qx: float, qy: float) -> list[int]:
        """Indices of the cells that segment p-q, grown by ``pad``, overlaps (row by row)."""
        p = self.pad
        nx = self.nx
        j0 = self.iy(min(py, qy) - p)
        j1 = self.iy(max(py, qy) + p)
        dy = qy - py
        dx = qx - px
        inv = 1.0 / dy if abs(dy) > p else 0.0
        out: list[int] = []
        for j in range(j0, j1 + 1):
            if inv == 0.0:
                xa, xb = (px, qx) if px <= qx else (qx, px)
            else:
                # the part of the segment inside this row's band (grown by pad)
                ta = (self.y0 + j * self.h - p - py) * inv
                tb = (self.y0 + (j + 1) * self.h + p - py) * inv
                if ta > tb:
                    ta, tb = tb, ta
                ta = 0.0 if ta < 0.0 else ta
                tb = 1.0 if tb > 1.0 else tb
                if ta > tb:
                    continue
                xa = px + ta * dx
                xb = px + tb * dx
                if xa > xb:
                    xa, xb = xb, xa
            row = j * nx
            out.extend(range(row + self.ix(xa - p), row + self.ix(xb + p) + 1))
        return out

    def query_segment(self, px: float, py: float, qx: float, qy: float):
        """Items in the cells that segment p-q, grown by ``pad``, overlaps."""
        p = self.pad
        cells = self.cells
        j0 = self.iy(min(py, qy) - p)
        if j0 == self.iy(max(py, qy) + p):
            i0 = self.ix(min(px, qx) - p)
            if i0 == self.ix(max(px, qx) + p):
                return cells[j0 * self.nx + i0]
        out: set[int] = set()
        for c in self.segment_cells(px, py, qx, qy):
            out.update(cells[c])
        return out
