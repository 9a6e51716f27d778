"""Pictures of the referee's winning sets (matplotlib, imported lazily).

* :func:`draw_starts`: for one fixed evader position, the pursuer positions from which
  the pursuer provably holds (blue), the evader provably escapes (red), or neither
  (grey: the resolution error), over the lattice starts where surveillance holds.
* :func:`draw_fractions`: for every evader lattice point, the share of its valid pursuer
  positions of each kind, as a colour (blue = pursuer, red = evader, grey = unknown).
* :func:`draw_referee`: a figure with a few evader positions and the fraction map.
"""

from __future__ import annotations

import os
from typing import Any

import numpy as np

from envs import validation as V
from envs.files import written_whole
from envs.maps.plot import plot_map
from strategies.referee.referee import Referee, StartSet

__all__ = ["COLORS", "draw_fractions", "draw_referee", "draw_starts", "evader_fractions"]

COLORS = {"pursuer": "#1f5fbf", "evader": "#d62728", "unknown": "#9a9a9a"}
"""The colour of each label in every referee picture."""


def _figure(nrows: int, ncols: int, size: float):
    from matplotlib.figure import Figure

    return Figure(figsize=(size * ncols, size * nrows), dpi=110)


def draw_starts(
    referee: Referee,
    evader,
    ax: Any = None,
    *,
    starts: StartSet | None = None,
    marker_size: float | None = None,
) -> Any:
    """Draw, for the evader lattice point nearest ``evader``, each valid pursuer start by
    its label.

    Args:
        referee: the solved referee.
        evader: an (x, y) position (snapped to the nearest evader lattice point).
        ax: axes to draw into (default: a new figure).
        starts: precomputed :meth:`Referee.lattice_starts` (saves recomputing them).
        marker_size: scatter marker size (default from the lattice spacing).

    Returns:
        The axes.
    """
    e = V.point("evader", evader)
    starts = referee.lattice_starts() if starts is None else starts
    E = referee.evader.lattice.points
    e_snap = E[int(np.argmin(np.hypot(*(E - e).T)))]
    sel = np.all(np.isclose(starts.evader, e_snap), axis=1)
    ax = plot_map(referee.spec.map, ax, title="")
    s = marker_size or _marker(ax, referee.pursuer.lattice.spacing)
    for label, color in COLORS.items():
        m = sel & (starts.label == label)
        n = int(m.sum())
        ax.scatter(
            *starts.pursuer[m].T,
            s=s,
            color=color,
            marker="s",
            lw=0,
            zorder=4,
            label=f"{label} ({n})",
        )
    ax.scatter([e_snap[0]], [e_snap[1]], s=60, color="black", marker="*", zorder=5, label="evader")
    ax.set_title(f"evader at ({e_snap[0]:.3g}, {e_snap[1]:.3g})", fontsize=9)
    ax.legend(loc="upper right", fontsize=6, framealpha=0.8)
    return ax


def evader_fractions(referee: Referee, starts: StartSet | None = None):
    """Per evader lattice point: the shares of its valid starts labelled pursuer, evader
    and unknown.

    Returns:
        ``(points (m, 2), fractions (m, 3), counts (m,))`` in the order of
        :data:`~strategies.referee.referee.LABELS`.
    """
    starts = referee.lattice_starts() if starts is None else starts
    pts, inv = np.unique(starts.evader, axis=0, return_inverse=True)
    inv = np.asarray(inv).reshape(-1)
    counts = np.bincount(inv, minlength=len(pts))
    fr = np.zeros((len(pts), 3))
    for c, label in enumerate(("pursuer", "evader", "unknown")):
        fr[:, c] = np.bincount(inv, weights=(starts.label == label), minlength=len(pts))
    fr /= np.maximum(counts, 1)[:, None]
    return pts, fr, counts


def draw_fractions(
    referee: Referee, ax: Any = None, *, starts: StartSet | None = None, marker_size=None
) -> Any:
    """Colour each evader lattice point by the shares of its valid pursuer starts: blue
    as the pursuer's share, red as the evader's, grey for the unknown rest."""
    pts, fr, _ = evader_fractions(referee, starts)
    blue = np.array([0x1F, 0x5F, 0xBF]) / 255.0
    red = np.array([0xD6, 0x27, 0x28]) / 255.0
    grey = np.array([0x9A, 0x9A, 0x9A]) / 255.0
    rgb = fr[:, :1] * blue + fr[:, 1:2] * red + fr[:, 2:3] * grey
    ax = plot_map(referee.spec.map, ax, title="")
    s = marker_size or _marker(ax, referee.evader.lattice.spacing)
    ax.scatter(*pts.T, c=np.clip(rgb, 0, 1), s=s, marker="s", lw=0, zorder=4)
    ax.set_title(
        "per evader position: share of pursuer starts won by\n"
        "pursuer (blue), evader (red), unknown (grey)",
        fontsize=8,
    )
    return ax


def _marker(ax, spacing: float) -> float:
    """Marker area (points^2) that roughly tiles the lattice."""
    fig = ax.figure
    x0, x1 = ax.get_xlim()
    width_pt = fig.get_figwidth() * 72.0 * ax.get_position().width
    return max(1.0, (spacing / max(x1 - x0, 1e-12) * width_pt) ** 2)


def draw_referee(
    referee: Referee,
    evaders=None,
    *,
    path: str | os.PathLike[str] | None = None,
    size: float = 3.6,
) -> Any:
    """A figure: the winning sets for a few evader positions and the fraction map.

    Args:
        referee: the solved referee.
        evaders: (k, 2) evader positions (default: three evader lattice points, where
            the evader wins the largest share of starts, where the pursuer does, and far
            from those).
        path: also save the figure there.
        size: panel size in inches.

    Returns:
        The matplotlib ``Figure``.
    """
    starts = referee.lattice_starts()
    if evaders is None:
        pts, fr, counts = evader_fractions(referee, starts)
        evaders = _spread(pts, fr, counts)
    evaders = np.atleast_2d(V.finite_array("evaders", evaders))
    n = len(evaders) + 1
    cols = min(n, 4)
    rows = -(-n // cols)
    fig = _figure(rows, cols, size)
    axes = [fig.add_subplot(rows, cols, i + 1) for i in range(n)]
    for ax, e in zip(axes, evaders, strict=False):
        draw_starts(referee, e, ax, starts=starts)
    draw_fractions(referee, axes[-1], starts=starts)
    s = referee.summary()
    fig.suptitle(
        f"{referee.spec.map.name}: rho = {referee.spec.rho:g}, L in [{referee.spec.l_min:g}, "
        f"{referee.spec.l_max:g}]; lattice starts: pursuer {s['pursuer']:.0%}, "
        f"evader {s['evader']:.0%}, unknown {s['gap']:.0%}",
        fontsize=9,
    )
    if path is not None:
        with written_whole(path, "picture") as tmp:  # a full disk leaves no cut picture
            fig.savefig(tmp, bbox_inches="tight")
    return fig


def _spread(pts: np.ndarray, fr: np.ndarray, counts: np.ndarray, k: int = 3) -> np.ndarray:
    """``k`` informative evader points: the one where the evader wins the largest share,
    the one where the pursuer does, then the farthest from those chosen."""
    ok = counts > 0
    if not ok.any():
        return pts[:1]
    pts, fr = pts[ok], fr[ok]
    chosen: list[int] = []
    for col in (1, 0):  # evader's share, then pursuer's share
        if fr[:, col].max() > 0:
            chosen.append(int(np.argmax(fr[:, col] + 1e-3 * np.minimum(fr[:, 0], fr[:, 1]))))
    if not chosen:
        chosen.append(0)
    d = np.min([np.hypot(*(pts - pts[c]).T) for c in chosen], axis=0)
    while len(chosen) < min(k, len(pts)):
        nxt = int(np.argmax(d))
        chosen.append(nxt)
        d = np.minimum(d, np.hypot(*(pts - pts[nxt]).T))
    return pts[chosen]
