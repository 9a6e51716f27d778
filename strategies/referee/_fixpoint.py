"""Array kernels of the two fixed points: stencil erosion and shifted gathers.

Per-state arrays have shape ``(n_points, W, W)``: a certified lattice point and the
window of opponent cells around it (see :mod:`strategies.referee.lattice`).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.ndimage import minimum_filter1d

__all__ = ["erode", "reach_rectangles", "shifted"]


def reach_rectangles(reach: float, h: float) -> list[tuple[int, int]]:
    """The opponent's one-step cell stencil as a union of centred rectangles.

    From a cell, the opponent (anywhere in it, moving at most ``reach``) can end in the
    cells within ``reach`` of the cell in the Euclidean distance between squares: offsets
    ``(i, j)`` with ``max(|i| - 1, 0)^2 + max(|j| - 1, 0)^2 <= (reach / h)^2``. That set is
    the union over ``k = 0 .. floor(reach / h)`` of the rectangles with half-sides
    ``(k + 1, floor(sqrt((reach / h)^2 - k^2)) + 1)``.

    Returns:
        ``[(half_x, half_y), ...]``.
    """
    r = reach / h
    out: list[tuple[int, int]] = []
    for k in range(math.floor(r + 1e-9) + 1):
        w = math.floor(math.sqrt(max(r * r - k * k, 0.0)) + 1e-9)
        if out and out[-1][1] == w + 1:
            out[-1] = (k + 1, w + 1)  # the previous rectangle lies inside this one
        else:
            out.append((k + 1, w + 1))
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
