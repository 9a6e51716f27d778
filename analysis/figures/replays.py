"""Claims in motion: short GIF replays of seeded episodes with the analytic policies.

The episodes are :data:`analysis.figures.cases.MATCHES`, played with the shared episode
runner (:func:`strategies.runner.run_episode`) and drawn by the env's own renderer
(:func:`analysis.replay.frames_from_trajectory`), the decomposition's escapable regions
shaded under them where it helps (:func:`analysis.overlay.decomposition_shading`). The
GIFs are kept small: frames subsampled, a shared 64-colour palette, no dithering.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from analysis.figures import cases
from analysis.figures.registry import register

__all__ = ["episode_frames", "write_gif"]

BASE_SIZE = 300
"""Frame size in pixels (longer side of the map) at size factor 1."""

FPS = 10
MAX_FRAMES = 110
"""Episodes longer than this many frames are subsampled."""


def episode_frames(
    result,
    size: int,
    *,
    shading: bool = False,
    label: str = "",
    step: int | None = None,
    until: float | None = None,
) -> list:
    """RGB frames of a played episode with a one-line label on top.

    Args:
        result: the played episode.
        size: pixels along the map's longer side.
        shading: shade the regions with escapable cells (decomposition at L_min).
        label: text before the time stamp.
        step: keep every ``step``-th env step (default: at most :data:`MAX_FRAMES` frames).
        until: stop at this time (s); the outcome frame is kept when the episode ends
            before.
    """
    from PIL import Image, ImageDraw

    from analysis.overlay import decomposition_shading
    from analysis.replay import frames_from_trajectory

    shade = decomposition_shading(result.map_obj, result.config.l_min) if shading else ()
    frames = frames_from_trajectory(result, size=size, trail=40, shading=shade)
    last = len(frames) - 1
    if until is not None:
        last = min(last, round(until / result.dt))
    if step is None:
        step = max(1, int(np.ceil((last + 1) / MAX_FRAMES)))
    picks = list(range(0, last + 1, step))
    if picks[-1] != last:
        picks.append(last)  # always show the outcome (or the cut)
    out = []
    bar = 14
    for k in picks:
        f = frames[k]
        img = Image.new("RGB", (f.shape[1], f.shape[0] + bar), (255, 255, 255))
        img.paste(Image.fromarray(f), (0, bar))
        ImageDraw.Draw(img).text((3, 1), f"{label}  t = {k * result.dt:4.1f} s", fill=(30, 30, 30))
        out.append(np.asarray(img))
    return out


def write_gif(path: Path, panels: list[list], *, hold_ms: int = 1500) -> Path:
    """Write panels (lists of frames) side by side as one GIF; shorter panels hold their
    last frame."""
    from PIL import Image

    n = max(len(p) for p in panels)
    h = max(p[0].shape[0] for p in panels)
    rows = []
    for k in range(n):
        tiles = []
        for p in panels:
            f = p[min(k, len(p) - 1)]
            if f.shape[0] < h:
                f = np.vstack([f, np.full((h - f.shape[0], f.shape[1], 3), 255, np.uint8)])
            tiles += [f, np.full((h, 4, 3), 255, np.uint8)]
        rows.append(np.hstack(tiles[:-1]))
    palette = Image.fromarray(np.vstack([rows[0], rows[-1]])).quantize(
        colors=64, method=Image.Quantize.MEDIANCUT, dither=Image.Dither.NONE
    )
    images = [Image.fromarray(r).quantize(palette=palette, dither=Image.Dither.NONE) for r in rows]
    durations = [int(1000 / FPS)] * (len(images) - 1) + [hold_ms]
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    images[0].save(
        path,
        save_all=True,
        append_images=images[1:],
        duration=durations,
        loop=0,
        optimize=True,
        disposal=1,
    )
    return path


def _size(scale: float) -> int:
    return max(60, round(BASE_SIZE * scale))


def _outcome(result, until: float | None = None) -> str:
    if result.winner == "pursuer":
        if until is not None and until < result.steps * result.dt:
            return f"pursuer holds (all {result.steps * result.dt:g} s)"
        return "pursuer holds"
    return f"evader escapes ({result.cause})"


def _label(result) -> str:
    return f"{result.map}: {_outcome(result)}"


@register(
    "fig03-replay",
    paper="Fig. 3 (in motion)",
    kind="gif",
    title="the corridor: the pursuer holds",
    caption="""The decomposition pursuer (blue) against the shooting evader (red) in the
    corridor world from a safe start (seed 0), escapable regions shaded: the pursuer keeps
    the rod out of escapable cells (never on the dead-end side) and holds to the horizon,
    as Prop. 2's verdict allows.""",
)
def build_fig03_replay(path: Path, scale: float) -> None:
    """The corridor episode."""
    r = cases.play(cases.MATCHES["corridor"])
    write_gif(path, [episode_frames(r, _size(scale), shading=True, label=_label(r))])


@register(
    "fig06-replay",
    paper="Fig. 6 (in motion)",
    kind="gif",
    title="the two rooms: the evader escapes",
    caption="""The same policies between the two rooms (seed 1): every cell is escapable
    (Prop. 4), the shooting evader walks into the corridor with the pursuer behind it and
    turns the far mouth's corner; the rod hits the corner.""",
)
def build_fig06_replay(path: Path, scale: float) -> None:
    """The two-rooms episode."""
    r = cases.play(cases.MATCHES["two_rooms"])
    write_gif(path, [episode_frames(r, _size(scale), shading=True, label=_label(r))])


@register(
    "fig09-replay",
    paper="Fig. 9(b) (in motion)",
    kind="gif",
    title="rounding the corner, slow and fast evader",
    caption="""A wall-hugging evader leads round the convex corner of the Fig. 9(b) world
    against the decomposition pursuer. Left, ρ = 0.5 (seed 3): the pursuer keeps up and
    holds. Right, ρ = 1 (seed 1): it cannot turn the rod round the corner fast enough
    (Sec. 7.4: with the evader nearer the corner than L/2 the required speed
    V_e (L - l)/l exceeds V_p) and the rod is occluded by the corner.""",
)
def build_fig09_replay(path: Path, scale: float) -> None:
    """Two corner episodes side by side."""
    slow = cases.play(cases.MATCHES["corner_slow"])
    fast = cases.play(cases.MATCHES["corner_fast"])  # rho = 1
    size = _size(0.8 * scale)
    until = fast.steps * fast.dt + 3.0  # both panels until shortly after the fast escape
    panels = [
        episode_frames(
            slow, size, step=2, until=until, label="rho = 0.5: " + _outcome(slow, until)
        ),
        episode_frames(fast, size, step=2, until=until, label="rho = 1: " + _outcome(fast)),
    ]
    write_gif(path, panels)


@register(
    "fn4-replay",
    paper="Sec. 5, footnote 4 (in motion)",
    kind="gif",
    title="ρ > 1: charge, don't run",
    caption="""Footnote 4 says a faster evader (ρ > 1) escapes by running away. In a bounded
    world running away gets cornered (right: the pursuer holds); charging the pursuer always
    works, since L then shrinks at least at V_e - V_p > 0 and drops below L_min (left).
    Open room, ρ = 1.5, decomposition pursuer, seed 0.""",
)
def build_fn4_replay(path: Path, scale: float) -> None:
    """Charging and running away at rho = 1.5."""
    charge = cases.play(cases.MATCHES["charge"])
    away = cases.play(cases.MATCHES["run_away"])
    size = _size(0.8 * scale)
    panels = [
        episode_frames(charge, size, step=1, label="charge: " + _outcome(charge)),
        episode_frames(away, size, step=1, until=6.0, label="run away: " + _outcome(away, 6.0)),
    ]
    write_gif(path, panels)
