"""Array kernels of the two fixed points: stencil erosion and shifted gathers.

Per-state arrays have shape ``(n_points, W, W)``: a certified lattice point and the
window of opponent cells around it (see :mod:`strategies.referee.lattice`).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.ndimage import minimum_filter1d

__all__ = ["Worklist", "erode", "reach_rectangles", "shifted"]


MAX_RECTANGLES = 8
"""Rectangles per stencil: a larger exact stencil is covered by this many (a superset)."""


def reach_rectangles(
    reach: float, h: float, max_rects: int | None = MAX_RECTANGLES
) -> list[tuple[int, int]]:
    """The opponent's one-step cell stencil as a union of centred rectangles.

    From a cell, the opponent (anywhere in it, moving at most ``reach``) can end in the
    cells within ``reach`` of the cell in the Euclidean distance between squares: offsets
    ``(i, j)`` with ``max(|i| - 1, 0)^2 + max(|j| - 1, 0)^2 <= (reach / h)^2``. That set is
    the union over ``k = 0 .. floor(reach / h)`` of the rectangles with half-sides
    ``(k + 1, floor(sqrt((reach / h)^2 - k^2)) + 1)`` (fewer: nested ones are dropped).

    A large stencil costs one pass per rectangle, so beyond ``max_rects`` it is covered by
    ``max_rects`` rectangles whose corners lie evenly in angle on the staircase: a
    superset, which over-approximates the opponent a little more (sound for both bounds,
    whose opponents must be over-approximated).

    Returns:
        ``[(half_x, half_y), ...]``.

    Examples:
        Within one cell's width of a cell: the 3 x 3 block and the four cells two away
        along the axes (a plus-shaped 5 x 5 without its corners' neighbours):

        >>> reach_rectangles(1.0, 1.0)
        [(1, 2), (2, 1)]
    """
    # a reach beyond any window (whose side the memory budget keeps far below 1e15 cells)
    # covers it whatever its length: capped, so r * r stays finite (rho = 2e-301 overflowed)
    r = min(reach / h, 1e15)
    K = math.floor(r + 1e-9)

    def width(k: int) -> int:
        return math.floor(math.sqrt(max(r * r - k * k, 0.0)) + 1e-9)

    # For k >= r / sqrt(2) the width falls by at least 1 a row, so the exact union has
    # more than K (1 - 1/sqrt(2)) - 1 rectangles: from K = 4 (max_rects + 1) on, more than
    # max_rects, and its K + 1 rows (4e9 for a step of 2e9 s at rho 1e-9) are not listed.
    if max_rects is None or K < 4 * (max_rects + 1):
        exact: list[tuple[int, int]] = []
        for k in range(K + 1):
            w = width(k)
            if exact and exact[-1][1] == w + 1:
                exact[-1] = (k + 1, w + 1)  # the previous rectangle lies inside this one
            else:
                exact.append((k + 1, w + 1))
        if max_rects is None or len(exact) <= max_rects:
            return exact
    # rows k_1 < ... < k_m = K spread in angle; rectangle j reaches row k_j with the width
    # of the first row after k_{j-1}, so it covers every exact rectangle in between
    rows = sorted(
        {
            min(K, round(r * math.sin(0.5 * math.pi * j / max_rects)))
            for j in range(1, max_rects + 1)
        }
        | {K}
    )
    out, prev = [], -1
    for k in rows:
        out.append((k + 1, width(prev + 1) + 1))
        prev = k
    return out


def erode(X: np.ndarray, rects: list[tuple[int, int]], border: bool) -> np.ndarray:
    """For all stencil offsets s: ``X[o + s]`` (per slice), cells off the window = ``border``.

    The stencil is the union of the centred rectangles ``rects``, so the erosion is the
    AND of one separable min-filter per rectangle.

    Args:
        X: (n, W, W) bool.
        rects: ``[(half_x, half_y), ...]`` from :func:`reach_rectangles`.
        border: value of cells outside the window.

    Returns:
        (n, W, W) bool.
    """
    u = X.view(np.uint8)
    cval = int(bool(border))
    out = None
    for hx, hy in rects:
        # a half-side of the window's width or more covers the whole axis and the border
        # from every cell: the same minimum, without a filter as long as the stencil
        hx, hy = min(hx, X.shape[1]), min(hy, X.shape[2])
        y = minimum_filter1d(u, 2 * hx + 1, axis=1, mode="constant", cval=cval)
        y = minimum_filter1d(y, 2 * hy + 1, axis=2, mode="constant", cval=cval)
        out = y if out is None else np.minimum(out, y, out=out)
    if out is None:
        return X.copy()
    return out.view(bool)


def shifted(Y: np.ndarray, dx: int, dy: int, fill: bool) -> np.ndarray:
    """``out[:, a, b] = Y[:, a - dx, b - dy]``, ``fill`` where that falls off the window."""
    W = Y.shape[1]
    out = np.full(Y.shape, fill, dtype=bool)
    if abs(dx) >= W or abs(dy) >= W:
        return out
    out[:, max(0, dx) : W + min(0, dx), max(0, dy) : W + min(0, dy)] = Y[
        :, max(0, -dx) : W - max(0, dx), max(0, -dy) : W - max(0, dy)
    ]
    return out


class Worklist:
    """Which certified points a fixed-point sweep must revisit.

    A point's states change only when the states its moves lead to have changed, so after
    the first sweep only the predecessors of the points that changed are recomputed.

    Args:
        targets: (n_points, n_moves) the point each move reaches, -1 if none.
    """

    def __init__(self, targets: np.ndarray) -> None:
        n = len(targets)
        preds: list[set[int]] = [set() for _ in range(n)]
        for k, row in enumerate(targets):
            for q in row[row >= 0].tolist():
                preds[q].add(k)
        self._preds = [np.fromiter(sorted(p), dtype=np.int64) for p in preds]
        self.dirty = np.ones(n, dtype=bool)

    def todo(self) -> np.ndarray:
        """The points whose states may change in the next sweep."""
        mark = np.zeros(len(self.dirty), dtype=bool)
        for q in np.flatnonzero(self.dirty):
            mark[self._preds[q]] = True
        return np.flatnonzero(mark)

    def changed(self, points: np.ndarray) -> None:
        """Record the points whose states changed in this sweep."""
        self.dirty = np.zeros(len(self.dirty), dtype=bool)
        self.dirty[points] = True
