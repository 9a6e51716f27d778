"""Figs. 14-16 and Sec. 7.2: the leader-follower motions (the evader leads).

From :mod:`strategies.control.cooperative`: the tractrix (7.1, erratum E4), the
straight-line leader's time (7.2, E5/E5b), wall following (7.3, E6) and rounding a corner
(7.4, E7).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from analysis.figures import style
from analysis.figures.evasion import draw_tractrix
from analysis.figures.registry import register
from strategies.control import (
    corner_min_distance,
    corner_pursuer_position,
    corner_pursuer_velocity,
    corner_required_speed,
    straight_leader_time,
    tractrix,
    tractrix_numeric,
    wall_follow_max_speed,
    wall_follow_speed,
)

__all__ = ["COOP"]

COOP = {"L": 1.0, "v_e": 1.0, "rho": 0.5}
"""Parameters of Figs. 14-16 (V_p = V_e / rho)."""


@register(
    "fig14-tractrix",
    paper="Fig. 14 (Sec. 7.1)",
    title="the tractrix",
    caption="""Sec. 7.1: the follower dragged by a taut rod behind a leader moving along the
    x-axis traces the tractrix; it is the follower's path, not the evader's (erratum E4).
    Left: the closed form (L = V_e = 1, θ0 = π/2) is the printed (t - tanh t, sech t); the
    dots are an independent RK4 integration of the dragged follower. Right: Sec. 7.2's
    straight-line leader: the least time for the follower to turn the rod from θ0 to θ1
    while the leader goes straight, from the closed form with the incomplete elliptic
    integral of the second kind (errata E5 and E5b: the printed dt/dθ has a typo and the
    printed T is only the second integral), for three ρ.""",
)
def build_fig14(path: Path, scale: float) -> None:
    """Fig. 14 and the Sec. 7.2 times."""
    fig, axes = style.new_figure(9.4, 3.6, 1, 2, width_ratios=[1.35, 1.0])
    ax = axes[0, 0]
    draw_tractrix(ax, t_max=4.0, L=COOP["L"], v_e=COOP["v_e"])
    t = np.linspace(0.0, 4.0, 17)
    num = tractrix_numeric(t, L=COOP["L"], v_e=COOP["v_e"])
    ax.plot(*num.follower.T, "o", ms=3, color="black", label="RK4 check")
    ax.legend(loc="upper right", frameon=False)
    ax = axes[0, 1]
    th1 = np.linspace(0.5 * math.pi, 1.5 * math.pi, 61)
    for rho in (0.25, 0.5, 0.75):
        T = [
            straight_leader_time(0.5 * math.pi, x, alpha=0.0, L=COOP["L"], v_p=1.0, rho=rho)
            for x in th1
        ]
        ax.plot(np.degrees(th1), T, label=f"ρ = {rho}")
    ax.set_xlabel("θ1 (deg), from θ0 = 90°, leader heading α = 0")
    ax.set_ylabel("T (L = V_p = 1)")
    ax.legend(frameon=False)
    ax.set_title("Sec. 7.2: least time to turn the rod")
    style.save_png(fig, path, scale)


@register(
    "fig15-wall-following",
    paper="Fig. 15 (Sec. 7.3)",
    title="wall following",
    caption="""Sec. 7.3: the follower slides along a wall (the x-axis) while the leader moves at
    speed V_e in direction α. Left: the required follower speed ẋ_p = V_e cos(α - θ)/cos θ
    over the leader's headings, for three rod angles θ; its extremes V_e/|cos θ| are at
    α = θ + kπ for every integer k (erratum E6: the paper lists k = 1, 2, ...). Right: the
    worst case V_e/|cos θ| against the follower's bound V_p = V_e/ρ (ρ = 0.5): the follower
    can hold the wall for every heading iff |cos θ| ≥ ρ (shaded); the printed condition
    cos θ ≥ ρ is right only for cos θ > 0 (E6).""",
)
def build_fig15(path: Path, scale: float) -> None:
    """Fig. 15: the wall-following speed."""
    v_e, rho = COOP["v_e"], COOP["rho"]
    fig, axes = style.new_figure(9.0, 3.5, 1, 2)
    ax = axes[0, 0]
    alpha = np.linspace(-math.pi, math.pi, 721)
    for th in (math.radians(20), math.radians(60), math.radians(140)):
        ax.plot(
            np.degrees(alpha),
            wall_follow_speed(alpha, th, v_e=v_e),
            label=f"θ = {math.degrees(th):.0f}°",
        )
        for k in (-1, 0, 1):
            a = th + k * math.pi
            if -math.pi <= a <= math.pi:
                ax.plot(math.degrees(a), wall_follow_speed(a, th, v_e=v_e), "k.", ms=4)
    ax.set_xlabel("leader heading α (deg)")
    ax.set_ylabel("$\\dot x_p$ / $V_e$")
    ax.legend(frameon=False, loc="lower left")
    ax.set_title("required speed along the wall (dots: α = θ + kπ)")
    ax = axes[0, 1]
    th = np.linspace(0.0, math.pi, 721)
    with np.errstate(divide="ignore"):
        worst = wall_follow_max_speed(th, v_e=v_e)
    ax.plot(np.degrees(th), np.minimum(worst, 6.0), color=style.PURSUER, label="V_e / |cos θ|")
    ax.axhline(v_e / rho, color=style.GUIDE, ls="--", label="$V_p$ = V_e / ρ")
    ok = np.abs(np.cos(th)) >= rho
    ax.fill_between(
        np.degrees(th), 0, 6, where=ok, color=style.SAFE, alpha=0.15, label="|cos θ| ≥ ρ"
    )
    ax.set_ylim(0, 6)
    ax.set_xlabel("rod angle θ (deg)")
    ax.legend(frameon=False, loc="upper left")
    ax.set_title("feasible for every heading iff |cos θ| ≥ ρ")
    style.save_png(fig, path, scale)


@register(
    "fig16-corner-rounding",
    paper="Fig. 16 (Sec. 7.4)",
    title="rounding a corner",
    caption="""Sec. 7.4: the rod keeps contact with a corner v while the leader walks round it.
    The follower's position is p = e + (L/l)(v - e) (a position relation; the paper prints
    it as a velocity, erratum E7) and its velocity ṗ = (I - (L/l) n nᵀ) ė, n = (sin θ, -cos θ)
    (correct as printed): the leader's velocity along the rod passes through, the part across
    it is scaled by 1 - L/l (a lever about v). Left: the leader on a quarter circle of radius
    0.5 L about v, follower positions and velocities (blue arrows). Right: the worst-case
    follower speed V_e max(1, (L - l)/l) against V_p = V_e/ρ: the contact can be held for
    every heading iff l ≥ ρL/(1 + ρ).""",
)
def build_fig16(path: Path, scale: float) -> None:
    """Fig. 16: the follower's velocity round a corner."""
    L, v_e, rho = COOP["L"], COOP["v_e"], COOP["rho"]
    v = np.array([0.0, 0.0])
    fig, axes = style.new_figure(9.0, 3.9, 1, 2)
    ax = axes[0, 0]
    from matplotlib.patches import Polygon as MPolygon

    ax.add_patch(
        MPolygon(
            [(0, 0), (1.6, 0), (1.6, 1.6), (0, 1.6)],
            facecolor="#c9c5bd",
            edgecolor="#222222",
            lw=1.3,
        )
    )
    r = 0.5 * L
    phi = np.linspace(math.radians(95), math.radians(175), 5)  # leader goes round clockwise
    for k, a in enumerate(phi):
        e = v + r * np.array([math.cos(a), math.sin(a)])
        p = corner_pursuer_position(e, v, L=L)
        ev = v_e * np.array([math.sin(a), -math.cos(a)])  # along the circle, clockwise
        pv = corner_pursuer_velocity(e, v, ev, L=L)
        style.draw_rod(ax, e, p, size=3.5, alpha=0.45 + 0.55 * k / (len(phi) - 1))
        style.arrow(ax, e, 0.25 * ev, colour=style.EVADER, lw=1.0)
        style.arrow(ax, p, 0.25 * pv, colour=style.PURSUER, lw=1.0)
    ax.plot(*v, "ko", ms=4)
    ax.annotate("v", v, xytext=(4, 4), textcoords="offset points")
    style.zoom(ax, -0.9, 0.9, -0.7, 0.8)
    ax.set_xticks([])
    ax.set_yticks([])
    ax.set_title(f"leader at l = {r:g} from v, L = {L:g}: ṗ = (I - (L/l) n nᵀ) ė", fontsize=8.5)
    ax = axes[0, 1]
    ell = np.linspace(0.05, L, 400)
    ax.plot(
        ell,
        corner_required_speed(ell, L=L, v_e=v_e),
        color=style.PURSUER,
        label="V_e max(1, (L - l)/l)",
    )
    ax.axhline(v_e / rho, color=style.GUIDE, ls="--", label="$V_p$ = V_e / ρ")
    ls = corner_min_distance(L=L, rho=rho)
    ax.axvline(ls, color=style.ESCAPABLE, lw=0.8)
    ax.annotate(
        f"ρL/(1+ρ) = {ls:.3f}",
        (ls, 6.0),
        xytext=(4, 0),
        textcoords="offset points",
        color=style.ESCAPABLE,
        fontsize=8,
    )
    ax.set_ylim(0, 8)
    ax.set_xlabel("leader-corner distance l (L = 1)")
    ax.set_ylabel("worst-case follower speed")
    ax.legend(frameon=False)
    ax.set_title("holding the contact for every heading")
    style.save_png(fig, path, scale)


def _tractrix_point() -> tuple[float, float, float]:
    """THEORY.md section 7's check: the follower and theta at t = 1 (L = V_e = 1)."""
    tr = tractrix([1.0])
    return float(tr.follower[0, 0]), float(tr.follower[0, 1]), float(tr.theta[0])
