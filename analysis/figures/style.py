"""Shared drawing helpers of the figures: one look for every panel, small files.

matplotlib is imported lazily (``pip install 'surveil[analysis]'``); figures are made with
``matplotlib.figure.Figure`` directly, never through pyplot's global state. PNGs are
written at :data:`BASE_DPI` times the size factor and re-encoded with a 256-colour
palette, which keeps each file at a few tens of kilobytes.

Colours follow the env's renderer (pursuer blue, evader red) and the decomposition
pictures (:data:`strategies.cspace.draw.TYPE_COLOURS` for the critical-curve types).
"""

from __future__ import annotations

import io
import math
from pathlib import Path
from typing import Any

import numpy as np

from envs.maps import Map
from envs.maps.plot import DependencyNotInstalled, plot_map
from strategies.cspace.draw import TYPE_COLOURS

__all__ = [
    "BASE_DPI",
    "ESCAPABLE",
    "EVADER",
    "PURSUER",
    "SAFE",
    "TYPE_COLOURS",
    "arrow",
    "context",
    "draw_curves",
    "draw_map",
    "draw_rod",
    "new_figure",
    "save_png",
    "zoom",
]

BASE_DPI = 100
"""Resolution of the documentation figures (at size factor 1)."""

PURSUER = "#2f5bd3"
EVADER = "#d43a3a"
ESCAPABLE = "#e4572e"
SAFE = "#3a7ca5"
ROD = "#2e9e4f"
GUIDE = "#8a8a8a"

_RC = {
    "font.family": "DejaVu Sans",
    "font.size": 8.5,
    "axes.titlesize": 9.5,
    "axes.labelsize": 8.5,
    "legend.fontsize": 7.5,
    "xtick.labelsize": 7.5,
    "ytick.labelsize": 7.5,
    "hatch.linewidth": 0.5,
    "axes.spines.top": False,
    "axes.spines.right": False,
}


def _matplotlib():
    try:
        import matplotlib
        from matplotlib.figure import Figure
    except ImportError as exc:  # pragma: no cover - matplotlib is in the analysis extra
        raise DependencyNotInstalled(
            "drawing the paper's figures needs matplotlib: pip install 'surveil[analysis]'"
        ) from exc
    return matplotlib, Figure


def context():
    """The figures' matplotlib style as a context manager (fonts, sizes); builders run in it."""
    matplotlib, _ = _matplotlib()
    return matplotlib.rc_context(_RC)


def new_figure(width: float, height: float, nrows: int = 1, ncols: int = 1, **kw: Any):
    """A ``Figure`` of ``width`` x ``height`` inches with a grid of axes (constrained layout).

    Returns:
        ``(fig, axes)`` with ``axes`` a 2-D array (``squeeze=False``).
    """
    _, figure_cls = _matplotlib()
    fig = figure_cls(figsize=(width, height), layout="constrained")
    axes = fig.subplots(nrows, ncols, squeeze=False, **kw)
    return fig, axes


def save_png(fig: Any, path: str | Path, scale: float) -> Path:
    """Write ``fig`` as a palette PNG at ``BASE_DPI * scale`` and return the path."""
    from PIL import Image

    buf = io.BytesIO()
    fig.savefig(
        buf, format="png", dpi=max(20, round(BASE_DPI * scale)), metadata={"Software": None}
    )
    img = Image.open(buf).convert("RGB")
    pal = img.quantize(colors=256, method=Image.Quantize.MEDIANCUT, dither=Image.Dither.NONE)
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    pal.save(out, format="PNG", optimize=True)
    return out


def draw_map(ax: Any, world: Map, *, convex: bool = False, title: str | None = "") -> Any:
    """The world: free space light, obstacles grey, walls black (``envs.maps.plot``)."""
    plot_map(
        world,
        ax,
        title=title,
        show_convex=convex,
        free_color="#ffffff",
        obstacle_color="#c9c5bd",
        wall_color="#222222",
        wall_width=1.3,
        convex_color="#222222",
        convex_size=10.0,
    )
    ax.set_xticks([])
    ax.set_yticks([])
    for s in ax.spines.values():
        s.set_visible(False)
    return ax


def zoom(ax: Any, xmin: float, xmax: float, ymin: float, ymax: float) -> None:
    """Show only the window ``[xmin, xmax] x [ymin, ymax]`` (equal aspect)."""
    ax.set_xlim(xmin, xmax)
    ax.set_ylim(ymin, ymax)
    ax.set_aspect("equal")


def draw_curves(ax: Any, curves, *, lw: float = 1.1, alpha: float = 1.0, types=None) -> None:
    """Critical curves (not the walls) coloured by type."""
    for c in sorted(curves, key=lambda c: c.type):
        if c.type == 0 or (types is not None and c.type not in types):
            continue
        ax.plot(*c.points.T, color=TYPE_COLOURS[c.type], lw=lw, alpha=alpha, zorder=3)


def draw_rod(
    ax: Any,
    evader,
    pursuer,
    *,
    colour: str = ROD,
    lw: float = 1.6,
    alpha: float = 1.0,
    labels: bool = False,
    size: float = 4.5,
    zorder: int = 6,
) -> None:
    """The rod from the evader E (red) to the pursuer P (blue)."""
    e = np.asarray(evader, dtype=float)
    p = np.asarray(pursuer, dtype=float)
    ax.plot([e[0], p[0]], [e[1], p[1]], color=colour, lw=lw, alpha=alpha, zorder=zorder)
    ax.plot(*e, "o", color=EVADER, ms=size, alpha=alpha, zorder=zorder + 1, mec="white", mew=0.5)
    ax.plot(*p, "o", color=PURSUER, ms=size, alpha=alpha, zorder=zorder + 1, mec="white", mew=0.5)
    if labels:
        d = p - e
        n = np.array([-d[1], d[0]]) / max(math.hypot(*d), 1e-12)
        off = 0.06 * math.hypot(*d)
        ax.annotate(
            "E",
            e - off * (d / max(math.hypot(*d), 1e-12)) - off * n,
            ha="center",
            va="center",
            color=EVADER,
            fontsize=9,
            fontweight="bold",
            zorder=zorder + 2,
        )
        ax.annotate(
            "P",
            p + off * (d / max(math.hypot(*d), 1e-12)) + off * n,
            ha="center",
            va="center",
            color=PURSUER,
            fontsize=9,
            fontweight="bold",
            zorder=zorder + 2,
        )


def arrow(
    ax: Any,
    start,
    vector,
    *,
    colour: str,
    lw: float = 1.4,
    label: str | None = None,
    ls: str = "-",
    zorder: int = 7,
    **kw: Any,
) -> None:
    """An arrow from ``start`` along ``vector`` (data units)."""
    s = np.asarray(start, dtype=float)
    v = np.asarray(vector, dtype=float)
    ax.annotate(
        "",
        xy=s + v,
        xytext=s,
        arrowprops={
            "arrowstyle": "-|>",
            "color": colour,
            "lw": lw,
            "ls": ls,
            "shrinkA": 0,
            "shrinkB": 0,
            "mutation_scale": 9,
        },
        zorder=zorder,
    )
    if label:
        ax.annotate(label, s + v, color=colour, zorder=zorder, **({"fontsize": 8.5} | kw))
