"""Decomposition overlays for replays: regions shaded by how escapable their cells are."""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["ONLY_ESCAPABLE", "SOME_ESCAPABLE", "decomposition_shading"]

ONLY_ESCAPABLE = (238, 160, 150)
"""Regions whose cells are all escapable (Prop. 2 witnesses): the evader wins there."""

SOME_ESCAPABLE = (248, 218, 200)
"""Regions with at least one escapable cell (the pursuer must pick its side)."""

_SAFE = (236, 236, 228)  # the renderer's free-space colour


def decomposition_shading(world: Any, length: float) -> tuple[tuple[np.ndarray, tuple], ...]:
    """``Snapshot.shading`` for the decomposition of ``world`` at rod length ``length``.

    Every region is listed, largest first, so that a region nested in another's hole is
    painted after it; regions without escapable cells keep the free-space colour.
    """
    from strategies.cspace import decompose

    dec = decompose(world, float(length))
    escapable = dec.escapable
    shading = []
    for region in sorted(dec.regions, key=lambda r: -r.area):
        flags = [c in escapable for c in region.cells]
        if flags and all(flags):
            colour = ONLY_ESCAPABLE
        elif any(flags):
            colour = SOME_ESCAPABLE
        else:
            colour = _SAFE
        ring = np.asarray(region.polygon.exterior.coords)[:-1]
        shading.append((ring, colour))
    return tuple(shading)
