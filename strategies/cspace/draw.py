"""A picture of a decomposition: critical curves by type, regions, escapable cells, G_L.

:func:`draw_decomposition` writes a PNG in the style of the paper's Figs. 3, 5, 6, 7, 8:
on the left the world with the noncritical regions (regions with escapable cells shaded,
darker the larger their share of escapable cells, a region whose cells are all escapable
hatched: Prop. 2's witnesses), the semi-free critical curves coloured by type; on the
right the connectivity graph G_L laid out over the regions' sample points, escapable
cells in red. matplotlib is imported lazily.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from envs.errors import InvalidConfigError
from envs.files import written_whole

if TYPE_CHECKING:
    from strategies.cspace.decomposition import Decomposition

__all__ = ["TYPE_COLOURS", "cell_positions", "draw_decomposition", "fill_polygon"]

TYPE_COLOURS = {
    0: "#222222",
    1: "#1f77b4",
    2: "#2ca02c",
    3: "#d62728",
    4: "#9467bd",
    5: "#ff7f0e",
}
"""Colour of each critical-curve type (0 = walls)."""

_ESC = "#e4572e"
_ESC_DARK = "#9c2a10"
_SAFE = "#3a7ca5"
_OBSTACLE = "#b9b4ab"


def _pyplot():
    try:
        import matplotlib

        matplotlib.use("Agg", force=False)
        import matplotlib.pyplot as plt
    except ImportError as exc:  # pragma: no cover - optional dependency
        raise InvalidConfigError(
            "draw_decomposition needs matplotlib: pip install 'surveil[analysis]'"
        ) from exc
    return plt


def fill_polygon(ax: Any, poly: Any, **kw: Any) -> None:
    """Fill a shapely polygon or multipolygon, holes left open, as one matplotlib
    ``PathPatch`` per part (``kw`` to the patch: colours, zorder, hatch)."""
    from matplotlib.patches import PathPatch
    from matplotlib.path import Path as MPath

    for g in getattr(poly, "geoms", [poly]):
        verts, codes = [], []
        for ring in (g.exterior, *g.interiors):
            c = np.asarray(ring.coords)
            verts.append(c)
            codes += [MPath.MOVETO] + [MPath.LINETO] * (len(c) - 2) + [MPath.CLOSEPOLY]
        ax.add_patch(PathPatch(MPath(np.concatenate(verts), codes), **kw))


def _frame(ax, world) -> None:
    xmin, ymin, xmax, ymax = world.bounds
    pad = 0.03 * max(xmax - xmin, ymax - ymin)
    ax.set_xlim(xmin - pad, xmax + pad)
    ax.set_ylim(ymin - pad, ymax + pad)
    ax.set_aspect("equal")
    ax.set_xticks([])
    ax.set_yticks([])
    for s in ax.spines.values():
        s.set_visible(False)


def _draw_world(ax, dec: Decomposition, label_regions: bool) -> None:
    from matplotlib.colors import to_rgba
    from matplotlib.patches import Rectangle

    world = dec.map
    xmin, ymin, xmax, ymax = world.bounds
    pad = 0.03 * max(xmax - xmin, ymax - ymin)
    ax.add_patch(
        Rectangle(
            (xmin - pad, ymin - pad),
            xmax - xmin + 2 * pad,
            ymax - ymin + 2 * pad,
            facecolor=_OBSTACLE,
            edgecolor="none",
            zorder=0,
        )
    )
    fill_polygon(ax, world.free_region, facecolor="white", edgecolor="none", zorder=1)
    witnesses = set(dec.witness_regions)
    for r in dec.regions:
        cells = [dec.cells[c] for c in r.cells]
        share = (sum(c.escapable for c in cells) / len(cells)) if cells else 1.0
        if share <= 0:
            continue
        fill_polygon(
            ax,
            r.polygon,
            facecolor=to_rgba(_ESC, 0.12 + 0.30 * share),
            edgecolor=to_rgba(_ESC_DARK, 0.55) if r.id in witnesses else "none",
            linewidth=0.0,
            hatch="////" if r.id in witnesses else None,
            zorder=2,
        )
    for c in sorted(dec.curves, key=lambda c: c.type):
        if c.type == 0:
            continue
        ax.plot(
            *c.points.T,
            color=TYPE_COLOURS[c.type],
            lw=1.15,
            solid_capstyle="round",
            solid_joinstyle="round",
            zorder=3,
        )
    for ring in world.rings:
        closed = np.vstack([ring, ring[:1]])
        ax.plot(*closed.T, color=TYPE_COLOURS[0], lw=1.8, solid_joinstyle="miter", zorder=4)
    if label_regions:
        for r in dec.regions:
            ax.annotate(
                str(r.id),
                r.point,
                fontsize=5.5,
                ha="center",
                va="center",
                color="#444444",
                zorder=5,
            )
    w = dec.witness_region
    if w is not None:
        ax.plot(*w.point, marker="*", ms=13, color="#ffd23f", mec="#3d3d3d", mew=0.8, zorder=6)
    _frame(ax, world)


def cell_positions(dec: Decomposition, nudge: float = 0.012) -> dict[int, np.ndarray]:
    """Where to draw each cell of G_L: at its region's sample point, moved ``nudge`` times
    the map's larger side along its arc's middle direction when the region has several
    cells (so they do not overlap)."""
    xmin, ymin, xmax, ymax = dec.map.bounds
    off = nudge * max(xmax - xmin, ymax - ymin)
    pos = {}
    for r in dec.regions:
        k = 0.0 if len(r.cells) == 1 else off
        for c in r.cells:
            th = dec.cells[c].arc.mid
            pos[c] = r.point + k * np.array([math.cos(th), math.sin(th)])
    return pos


def _draw_graph(ax, dec: Decomposition) -> None:
    world = dec.map
    fill_polygon(ax, world.free_region, facecolor="#f7f7f5", edgecolor="none", zorder=0)
    for c in dec.curves:
        if c.type != 0:
            ax.plot(*c.points.T, color=TYPE_COLOURS[c.type], lw=0.6, alpha=0.18, zorder=0)
    for ring in world.rings:
        closed = np.vstack([ring, ring[:1]])
        ax.plot(*closed.T, color="#9a9a9a", lw=1.0, zorder=0)
    pos = cell_positions(dec)
    for i, j in dec.graph.edges:
        a, b = pos[i], pos[j]
        both = dec.cells[i].escapable and dec.cells[j].escapable
        ax.plot(
            [a[0], b[0]],
            [a[1], b[1]],
            color=_ESC if both else "#7a7a7a",
            lw=0.5,
            alpha=0.7,
            zorder=1,
        )
    if pos:
        ids = sorted(pos)
        xy = np.array([pos[i] for i in ids])
        col = [_ESC if dec.cells[i].escapable else _SAFE for i in ids]
        size = 14 if len(ids) < 150 else 7
        ax.scatter(xy[:, 0], xy[:, 1], s=size, c=col, edgecolors="white", linewidths=0.4, zorder=2)
    _frame(ax, world)


def draw_decomposition(
    decomposition: Decomposition,
    path: str | Path,
    *,
    show_graph: bool = True,
    label_regions: bool | None = None,
    dpi: int = 200,
) -> Path:
    """Write a PNG of a decomposition (the paper's Figs. 3, 5-8 for our worlds).

    Args:
        decomposition: from :func:`strategies.cspace.decompose`.
        path: output file (``.png``).
        show_graph: draw the connectivity graph G_L in a second panel.
        label_regions: write region ids (default: when there are at most 80 regions).
        dpi: resolution.

    Returns:
        The path written.
    """
    from matplotlib.colors import to_rgb
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    from strategies.cspace.curves import TYPE_NAMES

    plt = _pyplot()
    dec = decomposition
    out = Path(path)
    if label_regions is None:
        label_regions = len(dec.regions) <= 80
    xmin, ymin, xmax, ymax = dec.map.bounds
    aspect = (ymax - ymin) / max(xmax - xmin, 1e-12)
    ncol = 2 if show_graph else 1
    panel = 6.0
    height = min(9.0, max(2.6, panel * aspect) + 1.3)
    rc = {"hatch.linewidth": 0.5, "font.family": "DejaVu Sans", "axes.titlesize": 10}
    with plt.rc_context(rc):
        fig, axes = plt.subplots(
            1, ncol, figsize=(panel * ncol, height), squeeze=False, layout="constrained"
        )
        _draw_world(axes[0, 0], dec, label_regions)
        n_esc = sum(c.escapable for c in dec.cells)
        axes[0, 0].set_title(
            f"{dec.map.name}: critical curves and {len(dec.regions)} regions, L = {dec.L:g}"
        )
        present = sorted({c.type for c in dec.curves})
        handles = [
            Line2D([], [], color=TYPE_COLOURS[t], lw=1.8, label=f"type {t}: {TYPE_NAMES[t]}")
            for t in present
        ]
        handles.append(Patch(facecolor=_ESC, alpha=0.35, label="region with escapable cells"))
        handles.append(
            Patch(
                facecolor=(*to_rgb(_ESC), 0.42),
                edgecolor=(*to_rgb(_ESC_DARK), 0.55),
                lw=0.0,
                hatch="////",
                label="only escapable cells (Prop. 2)",
            )
        )
        if dec.evader_wins:
            handles.append(
                Line2D(
                    [],
                    [],
                    marker="*",
                    ls="",
                    ms=10,
                    color="#ffd23f",
                    mec="#3d3d3d",
                    label="witness region",
                )
            )
        if show_graph:
            _draw_graph(axes[0, 1], dec)
            verdict = "the evader wins" if dec.evader_wins else "the pursuer holds"
            axes[0, 1].set_title(
                f"$G_L$: {len(dec.cells)} cells ({n_esc} escapable), "
                f"{dec.graph.number_of_edges()} adjacencies: {verdict}"
            )
            handles.append(Line2D([], [], marker="o", ls="", color=_SAFE, label="cell"))
            handles.append(Line2D([], [], marker="o", ls="", color=_ESC, label="escapable cell"))
        fig.legend(
            handles=handles,
            loc="outside lower center",
            ncol=min(4 if show_graph else 2, len(handles)),
            fontsize=7.5,
            frameon=False,
        )
        out.parent.mkdir(parents=True, exist_ok=True)
        with written_whole(out, "picture") as tmp:  # a full disk leaves no cut picture
            fig.savefig(tmp, dpi=dpi)
        plt.close(fig)
    return out
