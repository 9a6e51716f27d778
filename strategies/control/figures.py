"""Reconstructions of the paper's Figs. 11, 12 and 14 (the originals are lost, THEORY.md).

``draw_figure(name, path, **params)`` is the entry point of ``surveil figure <name>``;
matplotlib is imported lazily so the control package never needs it otherwise.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from envs.errors import SurveilValueError, UnknownNameError
from strategies.control.cooperative import tractrix
from strategies.control.evasion import ShootResult, shoot, solve_escape

__all__ = ["FIGURES", "draw_figure"]

FIGURES = ("shooting", "greedy", "tractrix")
"""Names accepted by :func:`draw_figure`."""


def _pyplot():
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as exc:  # pragma: no cover - matplotlib is in the analysis extra
        raise ImportError(
            "drawing figures needs matplotlib: pip install 'surveil[analysis]'"
        ) from exc
    return plt


def _draw_arc(ax, arc: ShootResult, title: str, rods: int = 6) -> None:
    ev, pu = arc.evader_path(), arc.pursuer_path()
    ax.plot(ev[:, 0], ev[:, 1], "b-", lw=2, label="evader E")
    ax.plot(pu[:, 0], pu[:, 1], "r--", lw=1.5, label="pursuer P")
    for i in np.linspace(0, len(ev) - 1, rods).astype(int):
        ax.plot([ev[i, 0], pu[i, 0]], [ev[i, 1], pu[i, 1]], color="0.6", lw=0.8)
    ax.plot(*ev[0], "bo")
    ax.plot(*pu[0], "ro")
    ax.axhline(0.0, color="k", lw=0.5)
    ax.set_aspect("equal")
    ax.set_title(title, fontsize=9)
    ax.legend(fontsize=8, loc="best")


def _shooting(
    ax, theta0=math.pi, x_e=1.0, L=1.0, rho=0.5, branch="+", lambda1=None, lambda2_0=None
) -> None:
    """Fig. 11: an optimal escape to (x_e, 0); with multipliers given, the plain shot."""
    if lambda1 is not None or lambda2_0 is not None:
        arc = shoot(
            theta0,
            0.0 if lambda1 is None else lambda1,
            0.0 if lambda2_0 is None else lambda2_0,
            L=L,
            rho=rho,
            branch=branch,
            x_max=x_e,
            stop_at_crossing=True,
        )
        title = (
            f"shot: θ0={theta0:.3f}, λ1={arc.lambda1:.3f}, λ2(0)={arc.lambda2_0:.3f}, "
            f"L={L}, ρ={rho}, x_c={arc.x_c}"
        )
    else:
        sol = solve_escape(theta0, x_e, L=L, rho=rho, branch=branch)
        if not sol.success:
            raise SurveilValueError(f"no optimal escape to draw: {sol.reason}")
        arc = sol.arc
        title = (
            f"optimal escape: θ0={theta0:.3f}, x_e={x_e}, L={L}, ρ={rho}\n"
            f"λ1={sol.lambda1:.4f}, λ2(0)={sol.lambda2_0:.4f}, J={sol.J:.4f}"
        )
    _draw_arc(ax, arc, title)


def _greedy(ax, theta0=math.pi, x_max=2.0, L=1.0, rho=0.5, branch="+") -> None:
    """Fig. 12: final y free, λ1 = 0, the evader minimises the instantaneous rotation."""
    arc = shoot(theta0, 0.0, 0.0, L=L, rho=rho, branch=branch, x_max=x_max)
    _draw_arc(ax, arc, f"greedy (λ1 = 0): θ0={theta0:.3f}, L={L}, ρ={rho}")


def _tractrix(ax, t_max=4.0, L=1.0, v_e=1.0, theta0=0.5 * math.pi) -> None:
    """Fig. 14: the follower's tractrix behind a leader on the x-axis (E4)."""
    tr = tractrix(np.linspace(0.0, t_max, 400), L=L, v_e=v_e, theta0=theta0)
    ax.plot(tr.leader[:, 0], tr.leader[:, 1], "b-", lw=2, label="leader (evader)")
    ax.plot(tr.follower[:, 0], tr.follower[:, 1], "r-", lw=2, label="follower (tractrix)")
    for i in np.linspace(0, len(tr.t) - 1, 7).astype(int):
        ax.plot(
            [tr.leader[i, 0], tr.follower[i, 0]],
            [tr.leader[i, 1], tr.follower[i, 1]],
            color="0.6",
            lw=0.8,
        )
    ax.set_aspect("equal")
    ax.set_title(f"tractrix: L={L}, V_e={v_e}, θ0={theta0:.3f}", fontsize=9)
    ax.legend(fontsize=8, loc="best")


_DRAWERS = {"shooting": _shooting, "greedy": _greedy, "tractrix": _tractrix}


def draw_figure(name: str, path: str | Path, **params: Any) -> Path:
    """Draw one figure to a PNG file.

    Args:
        name: ``"shooting"`` (Fig. 11; params ``theta0, x_e, L, rho, branch`` and
            optionally ``lambda1, lambda2_0`` to draw a plain shot), ``"greedy"``
            (Fig. 12; ``theta0, x_max, L, rho, branch``) or ``"tractrix"`` (Fig. 14;
            ``t_max, L, v_e, theta0``).
        path: output file.
        **params: figure parameters (unknown ones raise TypeError).

    Returns:
        The path written.
    """
    if name not in _DRAWERS:
        raise UnknownNameError(f"figure name {name!r}: expected one of {FIGURES}")
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(6, 4.5))
    try:
        _DRAWERS[name](ax, **params)
        out = Path(path)
        fig.savefig(out, dpi=120, bbox_inches="tight")
    finally:
        plt.close(fig)
    return out
