"""Shared helpers of the map tests."""

from __future__ import annotations

import numpy as np

from envs.maps import Map


def box(x0: float, y0: float, x1: float, y1: float) -> list[tuple[float, float]]:
    return [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]


def regular(cx: float, cy: float, r: float, n: int, phase: float = 0.0) -> np.ndarray:
    a = phase + 2 * np.pi * np.arange(n) / n
    return np.stack([cx + r * np.cos(a), cy + r * np.sin(a)], axis=1)


def rings_equal_up_to_rotation(a: np.ndarray, b: np.ndarray, tol: float = 1e-9) -> bool:
    if a.shape != b.shape:
        return False
    return any(np.allclose(np.roll(a, k, axis=0), b, atol=tol) for k in range(len(a)))


def walls_equal(m1: Map, m2: Map, tol: float = 1e-9) -> bool:
    """Same outer ring and the same set of holes, each up to where the ring starts."""
    if len(m1.rings) != len(m2.rings):
        return False
    if not rings_equal_up_to_rotation(m1.rings[0], m2.rings[0], tol):
        return False
    unmatched = list(m2.rings[1:])
    for r in m1.rings[1:]:
        hit = next(
            (k for k, s in enumerate(unmatched) if rings_equal_up_to_rotation(r, s, tol)), None
        )
        if hit is None:
            return False
        unmatched.pop(hit)
    return True
