"""Figs. 1 and 2: the configuration of the pursuer-evader rod and the critical-curve catalog.

Fig. 1 draws eq. (1) and the velocity geometry of eqs. (4)-(6) with
:func:`strategies.control.theta_dot` and :func:`strategies.control.pursuer_velocity`.
Fig. 2 draws each critical-curve type of THEORY.md 1.2 from
:func:`strategies.cspace.critical_curves` on a small world, with the rod drawn in its
contact configuration at points of the curve (:meth:`CriticalCurve.evaluate`).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from analysis.figures import style, worlds
from analysis.figures.registry import register
from strategies.control import pursuer_velocity, theta_dot
from strategies.cspace import critical_curves

__all__ = ["FIG1_PARAMS", "FIG2_LENGTH", "catalog_curves"]

FIG1_PARAMS = {"theta": math.radians(38.0), "alpha": math.radians(-20.0), "L": 3.0, "rho": 0.5}
"""The configuration drawn in Fig. 1 (V_p = 1)."""

FIG2_LENGTH = 2.0
"""Rod length L of the catalog panels."""


def _angle_arc(ax, centre, radius, a0, a1, colour, label, label_r=1.25):
    from matplotlib.patches import Arc

    ax.add_patch(
        Arc(
            centre,
            2 * radius,
            2 * radius,
            theta1=math.degrees(min(a0, a1)),
            theta2=math.degrees(max(a0, a1)),
            color=colour,
            lw=1.0,
            zorder=5,
        )
    )
    mid = 0.5 * (a0 + a1)
    ax.annotate(
        label,
        centre + label_r * radius * np.array([math.cos(mid), math.sin(mid)]),
        ha="center",
        va="center",
        color=colour,
        fontsize=9,
    )


@register(
    "fig01-configuration",
    paper="Fig. 1",
    title="configuration variables",
    caption="""The configuration q = (x, y, θ, L): the evader E at (x, y), the pursuer
    P = E + L (cos θ, sin θ) (eq. 1). The evader moves at speed V_e in direction α (eq. 4).
    Right: eq. (5) says ṗ = ė + L θ̇ (−sin θ, cos θ), a point of the dotted line through
    P + ė perpendicular to the rod; |ṗ| = V_p (the dotted circle) cuts it at the two
    rates θ̇⁺ and θ̇⁻ of eq. (6). Drawn for L = 3, ρ = 0.5, θ = 38°, α = −20°.""",
)
def build_fig01(path: Path, scale: float) -> None:
    """Fig. 1 and the geometry of eq. (6)."""
    th, al, L, rho = (FIG1_PARAMS[k] for k in ("theta", "alpha", "L", "rho"))
    v_p, k = 1.0, 1.6  # k: data units per unit of speed in the velocity panel
    E = np.array([1.0, 1.0])
    u = np.array([math.cos(th), math.sin(th)])
    P = E + L * u
    ev = rho * v_p * np.array([math.cos(al), math.sin(al)])
    fig, axes = style.new_figure(8.4, 4.3, 1, 2, width_ratios=[1.0, 1.05])
    ax = axes[0, 0]
    ax.axhline(E[1], color=style.GUIDE, lw=0.6, ls=":")
    style.draw_rod(ax, E, P, size=6)
    ax.annotate(
        "E = (x, y)", E + np.array([-0.1, 0.18]), ha="right", color=style.EVADER, fontsize=9
    )
    ax.annotate(
        "P = ($x_p$, $y_p$)",
        P + np.array([0.1, 0.12]),
        ha="center",
        color=style.PURSUER,
        fontsize=9,
    )
    ax.annotate(
        "L",
        0.5 * (E + P) + 0.25 * np.array([-u[1], u[0]]),
        color=style.ROD,
        fontsize=10,
        ha="center",
        va="center",
    )
    _angle_arc(ax, E, 1.0, 0.0, th, style.ROD, "θ")
    style.arrow(ax, E, k * ev, colour=style.EVADER)
    ax.annotate("$V_e$", E + k * ev + np.array([0.08, -0.12]), color=style.EVADER, fontsize=9)
    _angle_arc(ax, E, 0.55, al, 0.0, style.EVADER, "α", label_r=1.55)
    ax.set_xlim(0.0, 4.6)
    ax.set_ylim(0.0, 3.6)
    ax.set_aspect("equal")
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    ax.set_title("eq. (1): P = E + L (cos θ, sin θ)")

    ax = axes[0, 1]
    tp, tm = theta_dot(al, th, L=L, v_p=v_p, rho=rho)
    n = np.array([-math.sin(th), math.cos(th)])
    from matplotlib.patches import Circle

    ax.add_patch(Circle(P, k * v_p, fill=False, ls=":", color=style.PURSUER, lw=1.0))
    line = np.array([P + k * (ev + s * n) for s in (-2.2, 2.2)])
    ax.plot(*line.T, ls=":", color=style.GUIDE, lw=1.0)
    ax.plot(*np.array([E + (P - E) * 0.45, P]).T, color=style.ROD, lw=1.4)
    ax.annotate("rod", E + (P - E) * 0.52, color=style.ROD, fontsize=8, ha="right")
    ax.plot(*P, "o", color=style.PURSUER, ms=6)
    style.arrow(ax, P, k * ev, colour=style.EVADER, ls="--", label=" ė")
    box = {"fc": "white", "ec": "none", "alpha": 0.85, "pad": 0.6}
    for rate, name, off, ha in (
        (tp, "θ̇⁺", (0.12, 0.1), "left"),
        (tm, "θ̇⁻", (-0.15, -0.25), "right"),
    ):
        vel = pursuer_velocity(ev, th, rate, L=L)
        style.arrow(ax, P, k * vel, colour=style.PURSUER)
        style.arrow(ax, P + k * ev, k * L * rate * n, colour=style.ROD, lw=1.0)
        tip = P + k * vel
        ax.annotate(
            f"ṗ with {name} = {rate:+.3f}",
            tip + np.array(off),
            color=style.PURSUER,
            fontsize=8,
            ha=ha,
            bbox=box,
            zorder=9,
        )
    ax.annotate(
        "|ṗ| = $V_p$",
        P + k * v_p * np.array([math.cos(2.6), math.sin(2.6)]),
        xytext=(-4, 0),
        textcoords="offset points",
        color=style.PURSUER,
        fontsize=8,
        ha="right",
        bbox=box,
        zorder=9,
    )
    ax.annotate("P", P + np.array([-0.3, 0.05]), color=style.PURSUER, fontsize=9, fontweight="bold")
    ax.set_aspect("equal")
    ax.set_xlim(P[0] - 2.4, P[0] + 2.4)
    ax.set_ylim(P[1] - 2.1, P[1] + 2.1)
    ax.set_xticks([])
    ax.set_yticks([])
    ax.set_title("eqs. (5)-(6): the two rates θ̇± at |ṗ| = $V_p$")
    style.save_png(fig, path, scale)


# ----------------------------------------------------------------------------- Fig. 2
def catalog_curves():
    """The curve of each type 1-5 drawn in Fig. 2, with its world and zoom window.

    Returns:
        A list of ``(type, world, curves, window)`` with ``curves`` the semi-free pieces
        of that type on the chosen features and ``window = (xmin, xmax, ymin, ymax)``.
    """
    L = FIG2_LENGTH
    out = []
    room = worlds.pillar_room()
    all_room = critical_curves(room, L)
    top = worlds.edge_near(room, (4, 5), (6, 5))
    corner = worlds.vertex_near(room, (6, 5))
    right = worlds.edge_near(room, (6, 3), (6, 5))
    out.append(
        (
            1,
            room,
            [c for c in all_room if c.type == 1 and c.features == (top,)],
            (2.2, 7.8, 2.0, 7.6),
        )
    )
    out.append(
        (
            2,
            room,
            [c for c in all_room if c.type == 2 and c.features == (corner,)],
            (3.0, 8.6, 2.0, 7.6),
        )
    )
    pair = worlds.staggered_pillars()
    v1, v2 = worlds.vertex_near(pair, (5, 5)), worlds.vertex_near(pair, (6, 4))
    out.append(
        (
            3,
            pair,
            [c for c in critical_curves(pair, L) if c.type == 3 and set(c.features) == {v1, v2}],
            (2.4, 8.6, 1.8, 7.2),
        )
    )
    out.append(
        (
            4,
            room,
            [c for c in all_room if c.type == 4 and c.features == (corner, right)],
            (3.0, 8.6, 2.0, 7.6),
        )
    )
    tri = worlds.vertex_above_floor(1.2)
    v = worlds.vertex_near(tri, (6, 1.2))
    floor = worlds.edge_near(tri, (0, 0), (12, 0))
    out.append(
        (
            5,
            tri,
            [c for c in critical_curves(tri, L) if c.type == 5 and c.features == (v, floor)],
            (3.2, 8.8, -0.3, 5.1),
        )
    )
    return out


_SHORT = {
    1: "tip on an edge, rod normal to it",
    2: "tip at a vertex",
    3: "body on two convex vertices",
    4: "along an edge, body on its end",
    5: "body on a vertex, tip on an edge",
}


def _contact_rods(ax, curve, count: int) -> None:
    L = curve.L
    ts = np.linspace(curve.t0, curve.t1, count + 2)[1:-1]
    P, theta = curve.evaluate(ts)
    Q = P + L * np.column_stack([np.cos(theta), np.sin(theta)])
    for p, q in zip(P, Q, strict=True):
        style.draw_rod(ax, p, q, lw=1.0, alpha=0.75, size=3.2)


@register(
    "fig02-critical-curves",
    paper="Fig. 2",
    title="the critical-curve catalog",
    caption="""The five types of critical curves (THEORY.md 1.2; the numbering is fixed by
    the paper's proof of Prop. 1 and Sec. 6), each for L = 2 with the rod drawn in its
    contact configuration at points of the curve (evader red, pursuer blue): type 1, tip on
    an edge with the rod perpendicular (a segment parallel to the edge at distance L);
    type 2, tip at a vertex (an arc of radius L); type 3, the rod on two convex vertices
    (exists once L exceeds their distance); type 4, the rod along an edge with its body on
    the convex end (the edge's extension, length L); type 5, body on a convex vertex and
    tip on an edge (a conchoid of Nicomedes, exists once L exceeds the vertex-edge
    distance). Last panel: every semi-free curve of the pillar room at L = 2.""",
)
def build_fig02(path: Path, scale: float) -> None:
    """Fig. 2 from the library's critical curves."""
    fig, axes = style.new_figure(9.0, 6.4, 2, 3)
    for ax, (t, world, curves, window) in zip(axes.flat, catalog_curves(), strict=False):
        style.draw_map(ax, world, convex=True)
        for c in curves:
            ax.plot(*c.points.T, color=style.TYPE_COLOURS[t], lw=2.2, zorder=4)
            _contact_rods(ax, c, {1: 3, 2: 4, 3: 2, 4: 1, 5: 3}[t])
        style.zoom(ax, *window)
        ax.set_title(f"type {t}: {_SHORT[t]}", fontsize=8)
    ax = axes[1, 2]
    room = worlds.pillar_room()
    style.draw_map(ax, room, convex=True)
    style.draw_curves(ax, critical_curves(room, FIG2_LENGTH), lw=1.2)
    style.zoom(ax, 0.0, 10.0, 0.0, 8.0)
    ax.set_title("all curves of the pillar room, L = 2", fontsize=8)
    from matplotlib.lines import Line2D

    handles = [
        Line2D([], [], color=style.TYPE_COLOURS[t], lw=2, label=f"type {t}") for t in range(1, 6)
    ]
    fig.legend(handles=handles, loc="outside lower center", ncol=5, frameon=False)
    style.save_png(fig, path, scale)
