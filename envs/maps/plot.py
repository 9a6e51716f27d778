"""A picture of a map with matplotlib (imported lazily: ``pip install surveil[analysis]``).

Free space is drawn light, everything outside it (obstacles and the area beyond the
boundary) dark, the walls as lines, and the convex obstacle vertices (the corners a rod
can wrap around, the paper's "reflex vertices") as dots.
"""

from __future__ import annotations

import os
from typing import Any

import numpy as np

from envs.files import written_whole
from envs.maps.map import Map

__all__ = ["DependencyNotInstalled", "plot_map"]


class DependencyNotInstalled(ImportError):
    """An optional dependency is missing; the message says which extra installs it."""


def _matplotlib() -> tuple[Any, Any, Any]:
    try:
        from matplotlib.figure import Figure
        from matplotlib.patches import PathPatch
        from matplotlib.path import Path
    except ImportError as exc:
        raise DependencyNotInstalled(
            "plotting maps needs matplotlib: install it with `pip install surveil[analysis]`"
        ) from exc
    return Figure, PathPatch, Path


def _ring_path(rings: tuple[np.ndarray, ...], path_cls: Any) -> Any:
    """One compound path of closed rings (outer CCW, holes CW: the holes stay empty)."""
    verts, codes = [], []
    for r in rings:
        verts += [*r.tolist(), r[0].tolist()]
        codes += [path_cls.MOVETO] + [path_cls.LINETO] * (len(r) - 1) + [path_cls.CLOSEPOLY]
    return path_cls(np.asarray(verts), codes)


def plot_map(
    map: Map,
    ax: Any = None,
    *,
    path: str | os.PathLike[str] | None = None,
    title: str | None = None,
    show_convex: bool = True,
    show_indices: bool = False,
    free_color: str = "#f7f7f2",
    obstacle_color: str = "#5b5b5b",
    wall_color: str = "#111111",
    wall_width: float = 1.5,
    convex_color: str = "#d62728",
    convex_size: float = 30.0,
    figsize: tuple[float, float] = (6.0, 6.0),
    dpi: int = 120,
) -> Any:
    """Draw ``map``: free space, walls, and (optionally) convex obstacle vertices.

    Args:
        map: the map.
        ax: a matplotlib ``Axes`` to draw into; by default a new ``Figure`` is made
            (without pyplot, so no global state and no display is needed).
        path: also save the figure to this file (PNG, SVG, PDF... by suffix).
        title: the axes title (default: the map's name and size).
        show_convex: mark the convex obstacle vertices.
        show_indices: label every wall vertex with its index in ``map.vertices``.
        free_color, obstacle_color, wall_color, wall_width, convex_color, convex_size:
            the style.
        figsize, dpi: of the new figure when ``ax`` is None.

    Returns:
        The ``Axes`` drawn into (its figure is ``ax.figure``).

    Raises:
        DependencyNotInstalled: if matplotlib is not installed.
    """
    figure_cls, patch_cls, path_cls = _matplotlib()
    if ax is None:
        ax = figure_cls(figsize=figsize, dpi=dpi).add_subplot()
    xmin, ymin, xmax, ymax = map.bounds
    pad = 0.04 * max(xmax - xmin, ymax - ymin)
    ax.set_facecolor(obstacle_color)
    ax.add_patch(
        patch_cls(_ring_path(map.rings, path_cls), facecolor=free_color, edgecolor="none", zorder=1)
    )
    for r in map.rings:
        closed = np.vstack([r, r[:1]])
        ax.plot(closed[:, 0], closed[:, 1], color=wall_color, lw=wall_width, zorder=2)
    if show_convex and map.vertex_convex.any():
        v = map.vertices[map.vertex_convex]
        ax.scatter(
            v[:, 0], v[:, 1], s=convex_size, color=convex_color, zorder=3, label="convex vertex"
        )
    if show_indices:
        for i, (x, y) in enumerate(map.vertices):
            ax.annotate(str(i), (x, y), fontsize=7, xytext=(3, 3), textcoords="offset points")
    ax.set_xlim(xmin - pad, xmax + pad)
    ax.set_ylim(ymin - pad, ymax + pad)
    ax.set_aspect("equal")
    if title is None:
        n_obs, n_convex = len(map.rings) - 1, int(map.vertex_convex.sum())
        title = (
            f"{map.name}: {map.n_vertices} walls, {n_obs} obstacle{'s' * (n_obs != 1)}, "
            f"{n_convex} convex {'vertex' if n_convex == 1 else 'vertices'}"
        )
    ax.set_title(title)
    if path is not None:
        with written_whole(path, "picture") as tmp:  # a full disk leaves no cut picture
            ax.figure.savefig(tmp, bbox_inches="tight")
    return ax
