"""Figs. 10-13: the shooting method, optimal escape arcs, greedy evasion, escape endpoints.

The arcs come from :func:`strategies.control.shoot` and
:func:`strategies.control.solve_escape` (Sec. 6.2 with THEORY.md 4.2-4.3), the endpoints
from :func:`strategies.control.vertex_escape_target` and
:func:`strategies.control.critical_curve_escape_target`.

:func:`draw_figure` is the parametric entry point of ``surveil figure shooting|greedy|
tractrix`` (it used to live in ``strategies/control/figures.py``): one panel with the
user's parameters, drawn by the same functions as the paper's figures.
"""

from __future__ import annotations

import inspect
import math
from pathlib import Path
from typing import Any

import numpy as np

from analysis.figures import cases, style
from analysis.figures.registry import register
from envs import validation
from envs.errors import InfeasibleError, InvalidConfigError, SurveilValueError, UnknownNameError
from envs.files import written_whole
from strategies.control import greedy_heading, shoot, solve_escape, tractrix

__all__ = [
    "FIGURES",
    "draw_arc",
    "draw_figure",
    "draw_greedy",
    "draw_shooting",
    "draw_tractrix",
    "figure_parameters",
]


def draw_arc(ax, arc, title: str, rods: int = 6, legend: bool = True) -> None:
    """An extremal (evader frame): the evader's path, the pursuer's, and a few rods; the
    title says where an unbounded arc stops (THEORY §4.3).

    Raises:
        InfeasibleError: the arc is unbounded from its start (nothing to draw).
    """
    ev, pu = arc.evader_path(), arc.pursuer_path()
    if len(ev) < 2:
        raise InfeasibleError(
            f"nothing to draw: H has no minimiser at the start (THEORY §4.3) with theta0 = "
            f"{arc.theta0!r}, lambda1 = {arc.lambda1!r}, lambda2_0 = {arc.lambda2_0!r}, "
            f"L = {arc.L!r}, rho = {arc.rho!r}: the arc is unbounded from x = 0"
        )
    if arc.unbounded:
        title += f"\nunbounded (H has no minimiser, THEORY §4.3) from x = {arc.x[-1]:.4g}"
    ax.plot(ev[:, 0], ev[:, 1], "-", color=style.EVADER, lw=2, label="evader E")
    ax.plot(pu[:, 0], pu[:, 1], "--", color=style.PURSUER, lw=1.5, label="pursuer P")
    for i in np.linspace(0, len(ev) - 1, rods).astype(int):
        ax.plot([ev[i, 0], pu[i, 0]], [ev[i, 1], pu[i, 1]], color=style.ROD, lw=0.8, alpha=0.7)
    ax.plot(*ev[0], "o", color=style.EVADER)
    ax.plot(*pu[0], "o", color=style.PURSUER)
    ax.axhline(0.0, color="k", lw=0.5)
    ax.set_aspect("equal")
    ax.set_title(title, fontsize=8.5)
    if legend:
        ax.legend(loc="best", frameon=False)


def draw_shooting(
    ax,
    theta0=math.pi,
    x_e=1.0,
    L=1.0,
    rho=0.5,
    branch="+",
    lambda1=None,
    lambda2_0=None,
    step=None,
) -> None:
    """Fig. 11 style: the optimal escape to (x_e, 0); with multipliers, the plain shot.
    ``step``: the RK4 step (None: :func:`strategies.control.default_step`)."""
    if lambda1 is not None or lambda2_0 is not None:
        arc = shoot(
            theta0,
            0.0 if lambda1 is None else lambda1,
            0.0 if lambda2_0 is None else lambda2_0,
            L=L,
            rho=rho,
            branch=branch,
            x_max=x_e,
            step=step,
            stop_at_crossing=True,
        )
        title = (
            f"shot: θ0={theta0:.3f}, λ1={arc.lambda1:.3f}, λ2(0)={arc.lambda2_0:.3f}, "
            f"L={L}, ρ={rho}, x_c={arc.x_c}"
        )
    else:
        sol = solve_escape(theta0, x_e, L=L, rho=rho, branch=branch, step=step)
        if not sol.success:
            raise SurveilValueError(f"no optimal escape to draw: {sol.reason}")
        arc = sol.arc
        title = (
            f"optimal escape: θ0={theta0:.3f}, x_e={x_e}, L={L}, ρ={rho}\n"
            f"λ1={sol.lambda1:.4f}, λ2(0)={sol.lambda2_0:.4f}, J={sol.J:.4f}"
        )
    draw_arc(ax, arc, title)


def draw_greedy(ax, theta0=math.pi, x_max=2.0, L=1.0, rho=0.5, branch="+", step=None) -> None:
    """Fig. 12 style: final y free, λ1 = 0, the evader minimises the instantaneous rotation.
    ``step``: the RK4 step (None: :func:`strategies.control.default_step`)."""
    arc = shoot(theta0, 0.0, 0.0, L=L, rho=rho, branch=branch, x_max=x_max, step=step)
    a0 = greedy_heading(theta0, L=L, rho=rho, branch=branch).alpha
    draw_arc(ax, arc, f"greedy (λ1 = 0): θ0={theta0:.3f}, L={L}, ρ={rho}, α*(0)={a0:.4f}")


def draw_tractrix(ax, t_max=4.0, L=1.0, v_e=1.0, theta0=0.5 * math.pi) -> None:
    """Fig. 14 style: the follower's tractrix behind a leader on the x-axis (E4), over
    the leader's times [0, t_max] (t_max > 0 and v_e > 0: else the figure is a single rod)."""
    t_max = validation.positive("t_max", t_max)
    if validation.nonnegative("v_e", v_e) == 0.0:
        raise InvalidConfigError(
            f"v_e = {v_e!r}: expected > 0 (a leader at rest: the figure would be a single rod)"
        )
    tr = tractrix(np.linspace(0.0, t_max, 400), L=L, v_e=v_e, theta0=theta0)
    ax.plot(
        tr.leader[:, 0], tr.leader[:, 1], "-", color=style.EVADER, lw=2, label="leader (evader)"
    )
    ax.plot(
        tr.follower[:, 0],
        tr.follower[:, 1],
        "-",
        color=style.PURSUER,
        lw=2,
        label="follower (tractrix)",
    )
    for i in np.linspace(0, len(tr.t) - 1, 7).astype(int):
        ax.plot(*np.array([tr.leader[i], tr.follower[i]]).T, color=style.ROD, lw=0.8)
    ax.set_aspect("equal")
    ax.set_title(f"tractrix: L={L}, V_e={v_e}, θ0={theta0:.3f}", fontsize=8.5)
    ax.legend(loc="best", frameon=False)


_DRAWERS = {"shooting": draw_shooting, "greedy": draw_greedy, "tractrix": draw_tractrix}
FIGURES = tuple(_DRAWERS)
"""Names accepted by :func:`draw_figure` (``surveil figure NAME``)."""


def figure_parameters(name: str) -> dict[str, Any]:
    """The parameters of figure ``name`` (``surveil figure NAME``) with their defaults.

    Raises:
        UnknownNameError: unknown ``name``.
    """
    if name not in _DRAWERS:
        raise UnknownNameError(f"figure name {name!r}: expected one of {FIGURES}")
    sig = inspect.signature(_DRAWERS[name])
    return {k: p.default for k, p in list(sig.parameters.items())[1:]}  # after ``ax``


def draw_figure(name: str, path: str | Path, **params: Any) -> Path:
    """Draw one parametric figure to a PNG file (``surveil figure NAME --params JSON``).

    Args:
        name: ``"shooting"`` (Fig. 11; params ``theta0, x_e, L, rho, branch, step`` and
            optionally ``lambda1, lambda2_0`` to draw a plain shot), ``"greedy"``
            (Fig. 12; ``theta0, x_max, L, rho, branch, step``) or ``"tractrix"`` (Fig. 14;
            ``t_max, L, v_e, theta0``).
        path: output file.
        **params: figure parameters (see :func:`figure_parameters`).

    Returns:
        The path written.

    Raises:
        UnknownNameError: unknown ``name``.
        InvalidConfigError: an unknown parameter (or a bad value, from the theory).
    """
    known = figure_parameters(name)
    unknown = sorted(set(params) - set(known))
    if unknown:
        raise InvalidConfigError(
            f"figure {name!r}: unknown parameter(s) {unknown}; its parameters are "
            + ", ".join(f"{k} (default {v!r})" for k, v in known.items())
        )
    with style.context():
        fig, axes = style.new_figure(6.0, 4.5)
        _DRAWERS[name](axes[0, 0], **params)
        out = Path(path)
        out.parent.mkdir(parents=True, exist_ok=True)
        with written_whole(out, "picture") as tmp:  # a full disk leaves no cut picture
            fig.savefig(tmp, dpi=120)
    return out


# ----------------------------------------------------------------------------- Fig. 10
@register(
    "fig10-shooting",
    paper="Fig. 10",
    title="the shooting method",
    caption="""The algorithm of Fig. 10 (with RK4 steps, THEORY.md 4.3) at θ0 = π, L = 1 and
    the ρ that fits Fig. 11(a). Left: extremals of the Hamiltonian from the origin for a fan
    of initial multipliers (λ1 with λ2(0) = 0; only k = λ1/(1 + λ2(0)) matters, THEORY.md 4.2
    fact 1), each run until it returns to the x-axis (step 7); the solved one (thick) returns
    at x_e = 1. Right: the return abscissa x_c as a function of k, the function whose root
    step 8 searches; solve_escape brackets and refines it.""",
)
def build_fig10(path: Path, scale: float) -> None:
    """Fig. 10: a fan of shots and the shooting function."""
    p = cases.PAPER_SHOTS["a"]
    rho, L = cases.paper_shot_rho("a"), cases.SHOT_L
    sol = solve_escape(p["theta0"], p["x_e"], L=L, rho=rho)
    ks = np.linspace(-1.3, -0.25, 12)
    fig, axes = style.new_figure(9.0, 3.8, 1, 2, width_ratios=[1.3, 1.0])
    ax = axes[0, 0]
    import matplotlib

    cmap = matplotlib.colormaps["viridis"]
    for i, k in enumerate(ks):
        arc = shoot(p["theta0"], k, 0.0, L=L, rho=rho, x_max=3.0, stop_at_crossing=True)
        ax.plot(arc.x, arc.y, color=cmap(i / (len(ks) - 1)), lw=1.0)
    ax.plot(sol.arc.x, sol.arc.y, color=style.EVADER, lw=2.6, label=f"solved: k = {sol.k:.4f}")
    ax.plot([p["x_e"]], [0.0], "k*", ms=9)
    ax.axhline(0.0, color="k", lw=0.5)
    ax.set_aspect("equal")
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    ax.legend(loc="lower left", frameon=False)
    ax.set_title(f"evader paths for k in [{ks[0]}, {ks[-1]}] (ρ = {rho:.4f}, L = {L:g})")
    ax = axes[0, 1]
    kk = np.linspace(-1.6, -0.15, 60)
    xc = []
    for k in kk:
        arc = shoot(p["theta0"], k, 0.0, L=L, rho=rho, x_max=4.0)
        xc.append(math.nan if arc.x_c is None else arc.x_c)
    ax.plot(kk, xc, color=style.SAFE)
    ax.axhline(p["x_e"], color=style.GUIDE, lw=0.8, ls="--")
    ax.plot([sol.k], [p["x_e"]], "o", color=style.EVADER)
    ax.set_xlabel("k = λ1 / (1 + λ2(0))")
    ax.set_ylabel("return abscissa $x_c$")
    ax.set_title("the shooting function: $x_c$(k) = $x_e$")
    style.save_png(fig, path, scale)


# ----------------------------------------------------------------------------- Fig. 11
@register(
    "fig11-optimal-escape",
    paper="Fig. 11",
    title="optimal escape trajectories with the printed multipliers",
    caption="""Fig. 11's printed initial values shot at L = 1 (the paper gives neither L nor ρ;
    each panel's ρ is the one at which the shot returns to the x-axis exactly at the
    printed x_e, a one-parameter fit): (a) θ0 = π, λ1 = -1, λ2 = 0.41, x_e = 1, pursuer and
    evader moving the same way; (b) θ0 = π/6, λ1 = 1, λ2 = 0.608, x_e = 0.5, moving
    opposite ways. The Hamiltonian is constant along each arc (the system is autonomous in
    x), and solve_escape finds the same k = λ1/(1 + λ2(0)) independently.""",
)
def build_fig11(path: Path, scale: float) -> None:
    """Fig. 11 (a) and (b)."""
    fig, axes = style.new_figure(9.0, 3.8, 1, 2)
    for ax, which in zip(axes[0], "ab", strict=True):
        arc, _ = cases.paper_shot(which)
        p = cases.PAPER_SHOTS[which]
        title = (
            f"({which}) θ0 = {p['theta0']:.4f}, λ1 = {p['lambda1']:g}, "
            f"λ2 = {p['lambda2_0']:g}: ρ = {arc.rho:.4f}\n"
            f"$x_c$ = {arc.x_c:.4f}, J = {arc.J:.4f}, H in "
            f"[{arc.H.min():.6f}, {arc.H.max():.6f}]"
        )
        draw_arc(ax, arc, title, rods=7, legend=which == "a")
    style.save_png(fig, path, scale)


# ----------------------------------------------------------------------------- Fig. 12
@register(
    "fig12-greedy",
    paper="Fig. 12",
    title="no fixed escape point: greedy evasion",
    caption="""Fig. 12: with no fixed escape point the final y is free, transversality gives
    λ1 = 0 and the evader picks the heading that minimises the instantaneous rotation rate
    (THEORY.md 4.2 fact 4): at θ = π it is α* = -arctan ρ with dθ/dx = (1 - ρ²)/(Lρ).
    Drawn from θ0 = π at L = 1, ρ = 0.5.""",
)
def build_fig12(path: Path, scale: float) -> None:
    """Fig. 12: the greedy extremal."""
    fig, axes = style.new_figure(6.4, 3.6)
    draw_greedy(axes[0, 0], theta0=math.pi, x_max=2.5, L=cases.SHOT_L, rho=0.5)
    style.save_png(fig, path, scale)


# ----------------------------------------------------------------------------- Fig. 13
def _draw_escape(ax, case, title: str) -> None:
    style.draw_map(ax, cases.corridor().map)
    for c in case.curves:
        ax.plot(
            *np.asarray(c).T,
            ls="--",
            color=style.TYPE_COLOURS[4 if case.kind == "vertex" else 1],
            lw=1.4,
            zorder=4,
        )
    ax.plot(*case.evader_path.T, color=style.EVADER, lw=1.8, zorder=5)
    ax.plot(*case.pursuer_path.T, color=style.PURSUER, lw=1.2, ls="--", zorder=5)
    n = len(case.evader_path)
    for k in np.linspace(0, n - 1, 5).astype(int):
        style.draw_rod(
            ax,
            case.evader_path[k],
            case.pursuer_path[k],
            lw=1.0,
            size=3.2,
            alpha=0.4 + 0.6 * k / (n - 1),
        )
    ax.annotate(
        "E",
        case.evader,
        xytext=(4, -10),
        textcoords="offset points",
        color=style.EVADER,
        fontweight="bold",
    )
    ax.annotate(
        "P",
        case.pursuer,
        xytext=(4, 2),
        textcoords="offset points",
        color=style.PURSUER,
        fontweight="bold",
    )
    ax.plot(*case.target.position, "k*", ms=9, zorder=9)
    verdict = "the evader escapes" if case.evader_escapes else "the pursuer turns in time"
    ax.set_title(
        f"{title}\nneeds {case.needed:.3f} rad ({case.branch}), can turn "
        f"{case.achieved:.3f}: {verdict}",
        fontsize=8,
    )


@register(
    "fig13-endpoints",
    paper="Fig. 13",
    title="endpoints of optimal escape trajectories",
    caption="""The two kinds of escape endpoints (Sec. 6) in the corridor world, L = 2,
    ρ = 0.5, with the optimal escape arc of solve_escape mapped back to the world. Left:
    the mouth's corner v (a convex obstacle vertex, the paper's "reflex vertex"); the two
    type-4 curves leaving it (dashed) bound the admissible orientations there, and the
    pursuer must turn the rod between them before the evader arrives. Right: the type-1
    curve bounding the region of the room-corner pocket cell (escapable by condition (a));
    the evader runs perpendicular to the curve and the pursuer must turn out of the
    pocket's orientations. Each title compares the rotation needed with the rotation |J|
    the pursuer can effect while the evader runs the optimal arc.""",
)
def build_fig13(path: Path, scale: float) -> None:
    """Fig. 13: vertex and critical-curve endpoints."""
    fig, axes = style.new_figure(9.0, 4.4, 1, 2)
    _draw_escape(axes[0, 0], cases.vertex_escape(), "reflex (convex obstacle) vertex")
    style.zoom(axes[0, 0], -2.0, 4.0, -1.5, 4.5)
    _draw_escape(axes[0, 1], cases.curve_escape(), "critical curve of an escapable cell")
    style.zoom(axes[0, 1], -0.5, 5.0, -5.3, -0.3)
    style.save_png(fig, path, scale)
