"""Pictures of evaluation tables: one heat map of surveillance success per map.

Rows are pursuers, columns evaders; each cell shows the success rate with its Wilson
interval and the mean time to escape. matplotlib is imported lazily (``surveil[analysis]``).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from envs.errors import InvalidConfigError
from envs.files import written_whole

__all__ = ["plot_matchups"]


def _short(name: str) -> str:
    return name.split("/", 1)[-1]


def plot_matchups(rows: Sequence[Any], path: str | Path, *, dpi: int = 150) -> Path:
    """Draw :class:`analysis.evaluate.MatchupRow` rows as one heat map per (map, overrides).

    Args:
        rows: the rows returned by :func:`analysis.evaluate.evaluate`.
        path: PNG file to write.
        dpi: resolution.

    Returns:
        The path written.
    """
    if not rows:
        raise InvalidConfigError("plot_matchups: no rows to draw")
    from matplotlib.figure import Figure

    groups: dict[tuple[str, str], list[Any]] = {}
    for r in rows:
        groups.setdefault((r.map, r.overrides), []).append(r)
    n = len(groups)
    cols = min(n, 3)
    nrows = math.ceil(n / cols)
    pursuers = list(dict.fromkeys(r.pursuer for r in rows))
    evaders = list(dict.fromkeys(r.evader for r in rows))
    w = 1.6 + 1.25 * len(evaders)
    h = 1.2 + 0.62 * len(pursuers)
    fig = Figure(figsize=(cols * w, nrows * h), layout="constrained")
    axes = np.atleast_1d(fig.subplots(nrows, cols, squeeze=False)).ravel()
    image = None
    for ax, ((map_name, overrides), group) in zip(axes, groups.items(), strict=False):
        grid = np.full((len(pursuers), len(evaders)), np.nan)
        for r in group:
            i, j = pursuers.index(r.pursuer), evaders.index(r.evader)
            grid[i, j] = r.rate
            escape = "" if math.isnan(r.escape_mean) else f"\n{r.escape_mean:.1f} s"
            text = f"{r.rate:.2f}\n[{r.rate_lo:.2f}, {r.rate_hi:.2f}]{escape}"
            colour = "white" if r.rate < 0.35 or r.rate > 0.8 else "black"
            ax.text(j, i, text, ha="center", va="center", fontsize=6.5, color=colour)
        image = ax.imshow(grid, cmap="RdYlBu", vmin=0.0, vmax=1.0, aspect="auto")
        ax.set_xticks(
            range(len(evaders)), [_short(e) for e in evaders], rotation=30, ha="right", fontsize=7
        )
        ax.set_yticks(range(len(pursuers)), [_short(p) for p in pursuers], fontsize=7)
        extra = "" if overrides in ("{}", "") else f"\n{overrides}"
        ax.set_title(f"{map_name} (n = {group[0].n} per cell){extra}", fontsize=8)
    for ax in axes[n:]:
        ax.set_visible(False)
    if image is not None:
        bar = fig.colorbar(image, ax=axes[:n].tolist(), shrink=0.8)
        bar.set_label("surveillance held to the horizon (rate)", fontsize=8)
    fig.suptitle(
        "pursuer (rows) vs evader (columns): success rate, 95% CI, mean escape time", fontsize=9
    )
    path = Path(path)
    with written_whole(path, "picture") as tmp:  # a full disk leaves no cut picture
        fig.savefig(tmp, dpi=dpi)
    return path
