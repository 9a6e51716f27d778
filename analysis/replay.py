"""Episode replays: GIF files (and PNG strips) from a played episode.

Frames come from the env's own renderer (``render_mode="rgb_array"``) when the episode was
recorded, or are redrawn from the recorded trajectory with
:func:`envs.surveillance.render.render_frame`; rendering only reads positions.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from envs.errors import InvalidConfigError

__all__ = ["frames_from_trajectory", "write_replay", "write_strip"]


def frames_from_trajectory(
    result: Any, *, size: int = 600, trail: int = 60, shading: tuple = ()
) -> list[np.ndarray]:
    """Redraw every step of a played episode from its recorded positions.

    Args:
        result: an :class:`analysis.evaluate.EpisodeResult` with ``trajectory``,
            ``map_obj`` and ``config``.
        size: pixels along the map's longer side.
        trail: how many past positions to draw behind each agent.
        shading: ``Snapshot.shading`` polygons drawn under the agents.
    """
    from envs.surveillance.render import Snapshot, render_frame

    traj = np.asarray(result.trajectory)
    config = result.config
    frames = []
    for k, (p, e) in enumerate(traj):
        last = k == len(traj) - 1
        broken = last and result.winner == "evader"
        lo = max(0, k - trail)
        frames.append(
            render_frame(
                Snapshot(
                    map=result.map_obj,
                    pursuer=(float(p[0]), float(p[1])),
                    evader=(float(e[0]), float(e[1])),
                    l_min=config.l_min,
                    l_max=config.l_max,
                    body_radius=config.body_radius,
                    surveillance=not broken,
                    cause=result.cause if broken else None,
                    step=k,
                    time=k * result.dt,
                    trail_pursuer=tuple(map(tuple, traj[lo : k + 1, 0])),
                    trail_evader=tuple(map(tuple, traj[lo : k + 1, 1])),
                    shading=shading,
                ),
                size=size,
            )
        )
    return frames


def _frames(result: Any) -> list[np.ndarray]:
    frames = result.frames if result.frames else frames_from_trajectory(result)
    if not frames:
        raise InvalidConfigError("the episode has no frames and no trajectory to draw")
    return list(frames)


def write_replay(
    result: Any, path: str | Path, *, decomposition: bool = False, fps: int = 20
) -> Path:
    """Write an episode replay as a GIF (or a PNG strip if ``path`` ends in ``.png``).

    Args:
        result: the played episode (recorded or with a trajectory).
        path: output file, ``.gif`` or ``.png``.
        decomposition: tint free space by the configuration-space decomposition at L_min.
        fps: frames per second of the GIF.

    Returns:
        The path written.
    """
    from PIL import Image

    path = Path(path)
    if fps <= 0:
        raise InvalidConfigError(f"fps must be a positive integer, got {fps!r}")
    if decomposition:
        from analysis.overlay import decomposition_shading

        shading = decomposition_shading(result.map_obj, result.config.l_min)
        frames = frames_from_trajectory(result, shading=shading)
    else:
        frames = _frames(result)
    if path.suffix.lower() == ".png":
        return write_strip(frames, path)
    if path.suffix.lower() != ".gif":
        raise InvalidConfigError(f"replay path must end in .gif or .png, got {str(path)!r}")
    images = [Image.fromarray(f) for f in frames]
    hold = [int(1000 / fps)] * (len(images) - 1) + [1500]  # linger on the outcome
    images[0].save(
        path, save_all=True, append_images=images[1:], duration=hold, loop=0, optimize=False
    )
    return path


def write_strip(frames: Sequence[np.ndarray], path: str | Path, *, panels: int = 6) -> Path:
    """Write ``panels`` evenly spaced frames side by side as one PNG."""
    from PIL import Image

    if not frames:
        raise InvalidConfigError("no frames to write")
    k = min(panels, len(frames))
    picks = [frames[round(i * (len(frames) - 1) / max(k - 1, 1))] for i in range(k)]
    strip = np.concatenate(picks, axis=1)
    Image.fromarray(strip).save(path)
    return Path(path)
