"""Figs. 3-8 and erratum E10: regions, cells, G_L, the stratified graph, escapable cells.

Everything is drawn from :mod:`strategies.cspace` objects (regions and their polygons,
cells and their free arcs, the graph G_L, the stratified graph) computed in
:mod:`analysis.figures.cases`.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from analysis.figures import cases, style
from analysis.figures.registry import register
from strategies.cspace import critical_curves
from strategies.cspace.draw import cell_positions, fill_polygon

__all__ = ["draw_graph", "draw_regions"]

_ESC_DARK = "#9c2a10"


def draw_regions(
    ax,
    dec,
    *,
    labels: bool = False,
    curves: bool = True,
    lw: float = 1.0,
    highlight: int | None = None,
) -> None:
    """The world, the critical curves by type and the regions: shaded by their share of
    escapable cells, hatched where every cell is escapable (Prop. 2's witnesses)."""
    from matplotlib.colors import to_rgba

    style.draw_map(ax, dec.map)
    witnesses = set(dec.witness_regions)
    for r in dec.regions:
        cells = [dec.cells[c] for c in r.cells]
        share = sum(c.escapable for c in cells) / len(cells) if cells else 1.0
        if r.id == highlight:
            fill_polygon(
                ax, r.polygon, facecolor=to_rgba("#ffd23f", 0.55), edgecolor="none", zorder=2
            )
        if share <= 0:
            continue
        fill_polygon(
            ax,
            r.polygon,
            facecolor=to_rgba(style.ESCAPABLE, 0.12 + 0.3 * share),
            edgecolor=to_rgba(_ESC_DARK, 0.5) if r.id in witnesses else "none",
            lw=0.0,
            hatch="////" if r.id in witnesses else None,
            zorder=2,
        )
    if curves:
        style.draw_curves(ax, dec.curves, lw=lw)
    if labels:
        for r in dec.regions:
            ax.annotate(
                str(r.id),
                r.point,
                fontsize=5.5,
                ha="center",
                va="center",
                color="#333333",
                zorder=8,
            )


def draw_graph(ax, dec, *, chain: tuple[int, ...] = (), size: float = 12.0) -> None:
    """G_L laid over the world: a node per cell at its region, escapable cells red, an
    edge per adjacency; ``chain`` (cell ids) drawn as a thick path."""
    fill_polygon(ax, dec.map.free_region, facecolor="#f6f6f3", edgecolor="none", zorder=0)
    for ring in dec.map.rings:
        closed = np.vstack([ring, ring[:1]])
        ax.plot(*closed.T, color="#9a9a9a", lw=0.8, zorder=0)
    style.draw_curves(ax, dec.curves, lw=0.5, alpha=0.2)
    pos = cell_positions(dec, nudge=0.013)
    for i, j in dec.graph.edges:
        both = dec.cells[i].escapable and dec.cells[j].escapable
        ax.plot(
            *np.array([pos[i], pos[j]]).T,
            color=style.ESCAPABLE if both else "#8a8a8a",
            lw=0.5,
            alpha=0.7,
            zorder=1,
        )
    if len(chain) > 1:
        ax.plot(
            *np.array([pos[c] for c in chain]).T,
            color="#ffb000",
            lw=2.4,
            zorder=2,
            solid_capstyle="round",
        )
    ids = sorted(pos)
    xy = np.array([pos[i] for i in ids])
    col = [style.ESCAPABLE if dec.cells[i].escapable else style.SAFE for i in ids]
    ax.scatter(xy[:, 0], xy[:, 1], s=size, c=col, edgecolors="white", linewidths=0.4, zorder=3)
    xmin, ymin, xmax, ymax = dec.map.bounds
    pad = 0.03 * max(xmax - xmin, ymax - ymin)
    style.zoom(ax, xmin - pad, xmax + pad, ymin - pad, ymax + pad)
    ax.set_xticks([])
    ax.set_yticks([])
    for s in ax.spines.values():
        s.set_visible(False)


def _legend(fig, *, witness: bool = False, graph: bool = False, ncol: int = 4) -> None:
    from matplotlib.colors import to_rgb
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    h = [
        Line2D([], [], color=style.TYPE_COLOURS[t], lw=1.8, label=f"type {t}") for t in range(1, 6)
    ]
    h.append(Patch(facecolor=style.ESCAPABLE, alpha=0.3, label="region with escapable cells"))
    if witness:
        h.append(
            Patch(
                facecolor=(*to_rgb(style.ESCAPABLE), 0.42),
                edgecolor=(*to_rgb(_ESC_DARK), 0.5),
                hatch="////",
                label="only escapable cells (Prop. 2)",
            )
        )
    if graph:
        h.append(Line2D([], [], marker="o", ls="", color=style.SAFE, label="cell"))
        h.append(Line2D([], [], marker="o", ls="", color=style.ESCAPABLE, label="escapable cell"))
    fig.legend(handles=h, loc="outside lower center", ncol=ncol, frameon=False)


# ----------------------------------------------------------------------------- Fig. 3
@register(
    "fig03-corridor",
    paper="Fig. 3",
    title="the corridor world and its regions",
    caption="""The corridor world (a 10 x 10 room with a dead-end corridor 6 long and 1
    wide, THEORY.md section 3) at L = L_min = 2: the semi-free critical curves by type
    and the noncritical regions they bound, numbered by the library. Shaded: regions
    with escapable cells (Sec. 4), the darker the larger their share; no region has only
    escapable cells, so by Prop. 2 the evader cannot force an escape: the pursuer holds
    by never being on the dead-end side.""",
)
def build_fig03(path: Path, scale: float) -> None:
    """Fig. 3 from the corridor's decomposition."""
    dec = cases.corridor()
    fig, axes = style.new_figure(8.6, 5.6)
    ax = axes[0, 0]
    draw_regions(ax, dec, labels=True)
    ax.set_title(
        f"corridor, L = {dec.L:g}: {len(dec.regions)} regions, {len(dec.cells)} cells, "
        f"{len(dec.escapable)} escapable, no region only escapable"
    )
    _legend(fig, witness=False, ncol=6)
    style.save_png(fig, path, scale)


# ----------------------------------------------------------------------------- Fig. 4
def _arc_wedge(ax, centre, radius, arc, colour, alpha=0.25):
    from matplotlib.patches import Wedge

    ax.add_patch(
        Wedge(
            centre,
            radius,
            math.degrees(arc.lo),
            math.degrees(arc.hi),
            facecolor=colour,
            alpha=alpha,
            edgecolor="none",
            zorder=4,
        )
    )


@register(
    "fig04-cells",
    paper="Fig. 4",
    title="the two cells above the mouth region",
    caption="""The region just outside the corridor's mouth (the paper's R5, yellow)
    carries two cells: kappa_5L (left), whose rod points into the corridor, and kappa_5R
    (right), whose rod points into the room; the wedge is the cell's range of free
    orientations at the region's sample point, bounded by its stops. kappa_5L is escapable
    (the evader leaves the mouth and turns a corner, Sec. 4), kappa_5R is not.""",
)
def build_fig04(path: Path, scale: float) -> None:
    """Fig. 4: one configuration in each cell of the mouth region."""
    dec = cases.corridor()
    region = dec.regions[cases.corridor_mouth_region(dec)]
    cells = sorted((dec.cells[c] for c in region.cells), key=lambda c: math.cos(c.arc.mid))
    fig, axes = style.new_figure(8.0, 3.8, 1, len(cells))
    for ax, cell, side in zip(axes[0], cells, ("L", "R"), strict=False):
        draw_regions(ax, dec, highlight=region.id, lw=0.8)
        e = region.point
        p = e + dec.L * np.array([math.cos(cell.arc.mid), math.sin(cell.arc.mid)])
        _arc_wedge(ax, e, 0.9 * dec.L, cell.arc, style.ESCAPABLE if cell.escapable else style.SAFE)
        style.draw_rod(ax, e, p, size=5)
        style.zoom(ax, -3.2, 3.6, -2.6, 2.6)
        stops = ", ".join(str(s) for s in cell.stops)
        verdict = "escapable" if cell.escapable else "not escapable"
        ax.set_title(
            f"κ5{side}: cell {cell.id} of region {region.id} ({verdict})\nstops {stops}", fontsize=8
        )
    style.save_png(fig, path, scale)


# ----------------------------------------------------------------------------- Fig. 5
@register(
    "fig05-graph",
    paper="Fig. 5",
    title="the connectivity graph G_L of the corridor",
    caption="""The connectivity graph G_L of the corridor world at L = 2 (Sec. 3): a node
    per cell, placed in its region and nudged toward its rod's direction; an edge joins
    cells whose free arcs overlap across a shared boundary (footnote 3). Red: escapable
    cells (the least fixed point of Sec. 4's recursive definition). Thick yellow: the
    guaranteed escape from kappa_5L (the mouth cell pointing into the corridor) into
    kappa_6L, which has no continuation across the next boundary (condition (a)).""",
)
def build_fig05(path: Path, scale: float) -> None:
    """Fig. 5: G_L over the corridor world, with the kappa_5L escape."""
    dec = cases.corridor()
    chain = cases.mouth_chain()
    fig, axes = style.new_figure(8.6, 5.6)
    draw_graph(axes[0, 0], dec, chain=chain.cells, size=16)
    axes[0, 0].set_title(
        f"G_L of the corridor, L = {dec.L:g}: {len(dec.cells)} cells, "
        f"{dec.graph.number_of_edges()} adjacencies, "
        f"{len(dec.escapable)} escapable"
    )
    _legend(fig, graph=True, ncol=6)
    style.save_png(fig, path, scale)


# ----------------------------------------------------------------------------- Fig. 6
@register(
    "fig06-two-rooms",
    paper="Fig. 6",
    title="two rooms joined by the corridor: the evader wins",
    caption="""The corridor joining two rooms (THEORY.md section 3) at L = 2: every cell is
    escapable, so every region is a witness of Prop. 2 (hatched) and, L_min being the
    smallest length, Prop. 4 says no pursuer, however fast, keeps surveillance. Black: the
    evader's shortest path from (5, 0) into the largest witness region (star); there
    whatever the pursuer does the configuration lies in an escapable cell, and the evader
    walks the corridor and turns a corner at its far mouth.""",
)
def build_fig06(path: Path, scale: float) -> None:
    """Fig. 6 and Prop. 4's verdict with the evader's path."""
    v = cases.paper_verdict("two_rooms")
    dec = v.decomposition
    fig, axes = style.new_figure(9.4, 3.9)
    ax = axes[0, 0]
    draw_regions(ax, dec, lw=0.8)
    if v.evader_path is not None:
        ax.plot(*v.evader_path.T, color="black", lw=1.4, zorder=7)
        ax.plot(*v.evader_path[0], "o", color=style.EVADER, ms=5, zorder=8)
        ax.plot(*v.witness_point, marker="*", ms=13, color="#ffd23f", mec="#3d3d3d", zorder=8)
    ax.set_title(
        f"two rooms, L = {dec.L:g}: {len(dec.escapable)} of {len(dec.cells)} cells "
        f"escapable; Prop. 4: {'the evader wins' if v.evader_wins else 'pursuer holds'}"
    )
    _legend(fig, witness=True, ncol=4)
    style.save_png(fig, path, scale)


# ----------------------------------------------------------------------------- Fig. 7
def _stratified_layout(sg):
    """x = the stratum's index; y = rank of the cell by its region's position along the
    corridor and its arc, so that a column reads like the corridor seen edge-on."""
    pos = {}
    for i, dec in enumerate(sg.strata):
        order = sorted(
            dec.cells,
            key=lambda c: (
                dec.regions[c.region].point[0],
                dec.regions[c.region].point[1],
                c.arc.mid,
            ),
        )
        n = len(order)
        for k, c in enumerate(order):
            pos[(i, c.id)] = (float(i), (k + 0.5) / n)
    return pos


@register(
    "fig07-graphs",
    paper="Fig. 7",
    title="G_L of the two rooms, and the stratified graph G over L",
    caption="""Left: the paper's Fig. 7, the connectivity graph G_L of the two-rooms world at
    L = 2; every cell is escapable (red). Right: Sec. 3's graph G for the corridor over
    L in [L_min, L_max] = [2, 4]: one column per stratum, at its sample length L_i^q between
    consecutive critical lengths (ticks below); grey edges join adjacent cells of one G_i,
    blue edges join a cell of G_i to a cell of G_(i+1) whose region overlaps it and whose
    free arc lies in the shorter rod's (lengthening the rod in place stays free; Prop. 3's
    monotonicity makes every cell of G_(i+1) linked).""",
)
def build_fig07(path: Path, scale: float) -> None:
    """Fig. 7 (G_L of Fig. 6) and the stratified graph of Sec. 3."""
    two = cases.paper_verdict("two_rooms").decomposition
    sg = cases.corridor_stratified()
    fig, axes = style.new_figure(10.0, 4.4, 1, 2, width_ratios=[1.5, 1.0])
    draw_graph(axes[0, 0], two, size=9)
    axes[0, 0].set_title(
        f"G_L of the two rooms, L = {two.L:g}: {len(two.cells)} cells, "
        f"{two.graph.number_of_edges()} adjacencies"
    )
    ax = axes[0, 1]
    pos = _stratified_layout(sg)
    segs_cell, segs_len = [], []
    for a, b, kind in sg.graph.edges(data="kind"):
        (segs_cell if kind == "cell" else segs_len).append([pos[a], pos[b]])
    from matplotlib.collections import LineCollection

    ax.add_collection(LineCollection(segs_cell, colors="#9a9a9a", lw=0.3, alpha=0.6))
    ax.add_collection(LineCollection(segs_len, colors=style.SAFE, lw=0.3, alpha=0.5))
    nodes = list(pos)
    xy = np.array([pos[n] for n in nodes])
    col = [style.ESCAPABLE if sg.graph.nodes[n]["escapable"] else style.SAFE for n in nodes]
    ax.scatter(xy[:, 0], xy[:, 1], s=5, c=col, zorder=3, linewidths=0)
    for k, c in enumerate(sg.critical):
        ax.axvline(k + 0.5, color="#cccccc", lw=0.6, zorder=0)
        ax.annotate(
            f"{c:.4g}",
            (k + 0.5, 1.0),
            xytext=(0, 2),
            textcoords="offset points",
            ha="center",
            va="bottom",
            fontsize=6.5,
            rotation=60,
            color="#777777",
        )
    ax.set_xlim(-0.5, len(sg.samples) - 0.5)
    ax.set_ylim(0, 1)
    ax.set_yticks([])
    ax.set_xticks(range(len(sg.samples)), [f"{x:.3f}" for x in sg.samples], rotation=60)
    ax.set_xlabel("stratum: sample length $L_i^q$ (critical lengths between, grey)")
    n_len = sum(1 for *_, k in sg.graph.edges(data="kind") if k == "length")
    ax.set_title(
        f"G of the corridor over L in [{sg.l_min:g}, {sg.l_max:g}]: "
        f"{len(sg.samples)} strata,\n{sg.graph.number_of_nodes()} cells, "
        f"{n_len} links between strata"
    )
    style.save_png(fig, path, scale)


# ----------------------------------------------------------------------------- Fig. 8
@register(
    "fig08-escapable-growth",
    paper="Fig. 8",
    title="escapable cells appear as L grows",
    caption="""Escapable cells appear when L crosses a critical value (Prop. 1), one row per
    curve type, each world just below (left) and just above (right) it. Top: two wedges
    with tips sqrt 2 apart: the type-3 curve through both tips appears at L = sqrt 2 and
    the rod threading between them is an escapable cell (condition (a)); by condition (b)
    every other cell of this small world becomes escapable too. Middle: an apex under a
    triangle's base: the type-5 curves appear at the vertex-edge distance and escapable
    cells appear around them. Bottom: the type-2 pockets at a room's corners (forcing the
    pursuer into a corner) are escapable at every L; once L exceeds half the room's width
    no region lets the rod turn freely and every cell becomes escapable. By Prop. 3 an
    escapable configuration stays escapable for larger L.""",
)
def build_fig08(path: Path, scale: float) -> None:
    """Fig. 8: the births of escapable cells."""
    rows = cases.growth_cases()
    fig, axes = style.new_figure(7.6, 10.6, len(rows), 2)
    for row, case in zip(axes, rows, strict=True):
        for ax, dec, side in ((row[0], case.before, "below"), (row[1], case.after, "above")):
            draw_regions(ax, dec, lw=0.9)
            style.zoom(ax, *case.window)
            n = len(dec.escapable)
            ax.set_title(
                f"{case.label}: L = {dec.L:.3f} ({side} {case.birth:.3f})\n"
                f"{n} of {len(dec.cells)} cells escapable",
                fontsize=8,
            )
    _legend(fig, witness=True, ncol=4)
    style.save_png(fig, path, scale)


# ----------------------------------------------------------------------------- E10
@register(
    "e10-l-hall",
    paper="Prop. 1 (erratum E10)",
    title="a critical length Prop. 1's list misses",
    caption="""An L-shaped hall with arms 4 wide. The type-1 lines x = L and y = L (tip on the
    outer walls) always cross at (L, L); that point lies on the type-2 arc of radius L about
    the convex corner (4, 4) when sqrt 2 (4 - L) = L, i.e. L = 8 - 4 sqrt 2: three curves
    through one point, where G_L changes although no vertex-vertex or vertex-edge distance
    (nor half of one) equals L. critical_lengths finds it by bisection (E10); the panels show
    the corner just below, at and above it.""",
)
def build_e10(path: Path, scale: float) -> None:
    """The L-hall triple point of erratum E10."""
    ev = cases.l_hall_event()
    world = ev.world
    fig, axes = style.new_figure(9.0, 3.4, 1, 3)
    for ax, L, tag in zip(
        axes[0], (ev.event - 0.12, ev.event, ev.event + 0.12), ("below", "at", "above"), strict=True
    ):
        style.draw_map(ax, world)
        style.draw_curves(ax, critical_curves(world, L), lw=1.3)
        ax.plot(L, L, "o", ms=4, color="black", zorder=6)
        style.zoom(ax, 0.0, 4.6, 0.0, 4.6)
        ax.set_title(f"L = {L:.4f} ({tag} the event)", fontsize=8)
    style.save_png(fig, path, scale)
