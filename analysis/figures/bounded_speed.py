"""Fig. 9: the two ways a bounded-speed pursuer loses where a fast one would not (Sec. 5).

(a) The evader charges the pursuer, which must turn the rod before it is pushed into the
corridor: eq. (6) integrated (:func:`strategies.control.theta_dot`) and Sec. 7.2's closed
form for the time (:func:`strategies.control.straight_leader_time`).
(b) The evader pulls the rod against a convex corner: the pursuer's required velocity
(:func:`strategies.control.corner_pursuer_velocity`, Sec. 7.4) exceeds V_p when the evader
is within ``rho L / (1 + rho)`` of the corner (:func:`strategies.control.corner_min_distance`).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from analysis.figures import cases, style
from analysis.figures.registry import register
from envs.maps import builtin_info
from strategies.control import corner_feasible, corner_min_distance, corner_pursuer_velocity

__all__ = ["CORNER_LENGTHS"]

CORNER_LENGTHS = (0.35, 0.667, 1.1, 1.6)
"""Evader-corner distances l drawn in Fig. 9(b) (L = 2)."""


@register(
    "fig09-corner-cases",
    paper="Fig. 9",
    title="bounded speed: charged, or pulled against a corner",
    caption="""(a) The rod at θ = π in front of the corridor (the paper's Fig. 9a): the evader
    charges straight at the pursuer (α = π) and the pursuer turns the rod at its extreme
    rate θ̇⁻ of eq. (6). Turning by π/2 takes T = L/(V_p(1 - ρ²)) [ρ(cos(α - θ1) - cos(α - θ0))
    - (E(φ1|ρ²) - E(φ0|ρ²))] (Sec. 7.2 with errata E5, E5b), and meanwhile the pursuer is
    pushed back a distance d: started closer than d to the wall line it is forced into the
    corridor (an escapable cell) or against the wall. (b) The rod on the convex corner of
    the Fig. 9(b) world: to keep the contact the pursuer must move at
    ṗ = (I - (L/l) n nᵀ) ė (Sec. 7.4, the velocity formula, correct as printed); against
    an evader moving across the rod this is
    V_e (L - l)/l, more than V_p when l < ρL/(1 + ρ) (the shaded disc): there the evader
    breaks the line of sight on the corner. Arrows: the evader's velocity across the rod
    (red) and the pursuer's required velocity (blue, at 0.6 scale). L = 2, ρ = 0.5,
    V_p = 1.""",
)
def build_fig09(path: Path, scale: float) -> None:
    """Fig. 9 (a) and (b)."""
    rot = cases.charge_rotation()
    fig, axes = style.new_figure(9.4, 4.2, 1, 2)
    ax = axes[0, 0]
    style.draw_map(ax, builtin_info("corridor").map)
    e, p = rot.positions((rot.recoil + rot.L, 0.0))
    ax.plot(*e.T, color=style.EVADER, lw=1.2, zorder=5)
    ax.plot(*p.T, color=style.PURSUER, lw=1.2, zorder=5)
    for k in np.linspace(0, len(rot.t) - 1, 6).astype(int):
        a = 0.35 + 0.65 * k / (len(rot.t) - 1)
        style.draw_rod(ax, e[k], p[k], alpha=a, lw=1.2, size=3.5)
    k = int(np.argmin(p[:, 0]))
    ax.plot(*p[k], "x", color="black", ms=6, zorder=9)
    ax.annotate(
        f"pushed back d = {rot.recoil:.3f}",
        p[k],
        xytext=(6, -16),
        textcoords="offset points",
        fontsize=7.5,
    )
    style.arrow(ax, e[0] + np.array([0.0, -0.35]), [-0.8, 0.0], colour=style.EVADER, lw=1.0)
    ax.annotate("α = π", e[0] + np.array([-0.4, -0.65]), color=style.EVADER, fontsize=8)
    style.zoom(ax, -2.2, 3.6, -1.6, 2.8)
    ax.set_title(f"(a) charged at θ = π: turning by π/2 takes T = {rot.T:.3f} s", fontsize=8.5)

    ax = axes[0, 1]
    info = builtin_info("corner")
    L, rho, v_e = info.l_min, info.rho, info.v_evader
    v = np.array([5.0, 5.0])
    style.draw_map(ax, info.map)
    from matplotlib.patches import Circle

    l_star = corner_min_distance(L=L, rho=rho)
    ax.add_patch(
        Circle(v, l_star, facecolor=style.ESCAPABLE, alpha=0.25, edgecolor="none", zorder=2)
    )
    for i, ell in enumerate(CORNER_LENGTHS):
        ang = math.radians(112.0 + 20.0 * i)  # evader in the upper arm, rod to the lower one
        u = np.array([math.cos(ang), math.sin(ang)])
        ev_pos = v + ell * u
        pu = ev_pos + L * (-u)
        ok = bool(corner_feasible(ell, L=L, rho=rho))
        style.draw_rod(ax, ev_pos, pu, colour=style.ROD if ok else style.ESCAPABLE, size=3.5)
        n = np.array([u[1], -u[0]])  # across the rod
        ve = v_e * n
        vp = corner_pursuer_velocity(ev_pos, v, ve, L=L)
        style.arrow(ax, ev_pos, ve, colour=style.EVADER, lw=1.0)
        style.arrow(ax, pu, 0.6 * vp, colour=style.PURSUER, lw=1.0)
        ax.annotate(
            f"l = {ell:g}: |ṗ| = {np.hypot(*vp):.2f}",
            pu,
            xytext=(5, -3),
            textcoords="offset points",
            fontsize=7,
            color="black" if ok else style.ESCAPABLE,
        )
    style.zoom(ax, 2.4, 9.2, 1.8, 7.4)
    ax.set_title(
        f"(b) pulled against the corner: needs |ṗ| > $V_p$ = 1 for l < {l_star:.3f}", fontsize=8.5
    )
    style.save_png(fig, path, scale)
