"""Episode replays: GIF files (and PNG strips) from a played episode, in flat memory.

Frames come from the env's own renderer (``render_mode="rgb_array"``), streamed one at a
time into a :class:`GifStream` while the episode plays (``run_episode(on_frame=...)``), or
are redrawn from the recorded trajectory with :func:`envs.surveillance.render.render_frame`
(:func:`iter_trajectory_frames`, a generator); rendering only reads positions. Neither
path keeps more than one frame in memory, so a replay of any length costs the same
memory (an RGB frame is about 2.75 MB).

A replay is written to a temporary file beside its target and renamed into place when
complete, so an interrupted or failed run never leaves a truncated GIF behind.
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterable, Iterator, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from envs import validation
from envs.errors import InvalidConfigError
from envs.files import output_error, written_whole

__all__ = [
    "MAX_FPS",
    "REPLAY_SUFFIXES",
    "GifStream",
    "frames_from_trajectory",
    "iter_trajectory_frames",
    "strip_indices",
    "write_replay",
    "write_strip",
]

REPLAY_SUFFIXES = (".gif", ".png")
"""A replay is an animated GIF or a PNG strip of a few frames."""

MAX_FPS = 100
"""GIF frame delays are whole hundredths of a second: faster than 100 fps cannot be stored."""

DEFAULT_FPS = 20
"""A replay's frame rate unless told otherwise."""

LINGER_MS = 1500
"""How long the GIF shows its last frame (the outcome) before looping."""


def _fps(fps: Any) -> int:
    return validation.integer("fps", fps, minimum=1, maximum=MAX_FPS)


# ----------------------------------------------------------------------------- frames
def iter_trajectory_frames(
    result: Any,
    *,
    size: int = 600,
    trail: int = 60,
    shading: tuple = (),
    indices: Iterable[int] | None = None,
) -> Iterator[np.ndarray]:
    """Redraw the steps of a played episode from its recorded positions, one at a time.

    Args:
        result: an :class:`strategies.runner.EpisodeResult` with ``trajectory``,
            ``map_obj`` and ``config``.
        size: pixels along the map's longer side.
        trail: how many past positions to draw behind each agent.
        shading: ``Snapshot.shading`` polygons drawn under the agents.
        indices: the steps to draw (default: all of them, in order).
    """
    from envs.surveillance.render import Snapshot, render_frame

    traj = np.asarray(result.trajectory)
    config = result.config
    last = len(traj) - 1
    for k in range(len(traj)) if indices is None else indices:
        p, e = traj[k]
        broken = k == last and result.winner == "evader"
        lo = max(0, k - trail)
        yield render_frame(
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


def frames_from_trajectory(
    result: Any, *, size: int = 600, trail: int = 60, shading: tuple = ()
) -> list[np.ndarray]:
    """Every frame of :func:`iter_trajectory_frames` as a list (memory grows with the
    episode: prefer the generator for long episodes)."""
    return list(iter_trajectory_frames(result, size=size, trail=trail, shading=shading))


def strip_indices(n_frames: int, panels: int = 6) -> list[int]:
    """The ``panels`` evenly spaced frame indices of a strip, first and last included."""
    k = min(panels, n_frames)
    return [round(i * (n_frames - 1) / max(k - 1, 1)) for i in range(k)]


# ----------------------------------------------------------------------------- writers
def _temporary(path: Path) -> Path:
    return path.with_name(f".{path.name}.{os.getpid()}.tmp")


class GifStream:
    """An animated GIF written frame by frame: memory stays flat for any length.

    Each frame's changed rectangle is quantised to its own 256-colour palette and encoded
    at once with Pillow's GIF encoder (``GifImagePlugin.getheader``/``getdata``, the
    frame-level API that imageio's streaming GIF writer also uses); two frames are held
    (the newest, so that the last one can linger :data:`LINGER_MS`, and the one written
    before it, to find what changed). The file is written to a temporary
    name beside ``path`` and renamed when :meth:`close` completes; :meth:`abort` (or an
    exception inside a ``with`` block) removes it.

    Opening the stream creates the temporary file, so an unwritable target fails at once,
    before any episode is played.

    Args:
        path: the ``.gif`` file to write.
        fps: frames per second, an integer in [1, :data:`MAX_FPS`].

    Raises:
        InvalidConfigError: a bad ``fps`` or a path not ending in ``.gif``.
        OSError: the file cannot be created.
    """

    def __init__(self, path: str | os.PathLike[str], fps: int = DEFAULT_FPS) -> None:
        self.path = Path(path)
        if self.path.suffix.lower() != ".gif":
            raise InvalidConfigError(f"GIF path must end in .gif, got {str(self.path)!r}")
        self.delay_ms = round(1000 / _fps(fps))
        self._tmp = _temporary(self.path)
        self._fp = open(self._tmp, "wb")
        self._pending: np.ndarray | None = None
        self._previous: np.ndarray | None = None  # the last frame written
        self.frames = 0

    def add(self, frame: np.ndarray) -> None:
        """Append one HxWx3 uint8 frame.

        Raises:
            OutputError: the file could not be written (a full disk); the partial file is
                removed.
        """
        if self._pending is not None:
            with self._aborted_on_failure():
                self._write(self._pending, self.delay_ms)
        self._pending = frame

    @contextlib.contextmanager
    def _aborted_on_failure(self) -> Iterator[None]:
        """A write that fails (a full disk) removes the partial file and names the GIF."""
        try:
            yield
        except OSError as exc:
            self.abort()
            raise output_error("GIF file", self.path, exc) from exc

    __call__ = add  # usable as run_episode(on_frame=stream)

    def _write(self, frame: np.ndarray, duration_ms: int) -> None:
        from PIL import GifImagePlugin, Image

        frame = np.asarray(frame, dtype=np.uint8)
        top, left, bottom, right = 0, 0, frame.shape[0], frame.shape[1]
        if self._previous is not None and self._previous.shape == frame.shape:
            # only the rectangle that changed (the rest of the previous frame stays:
            # disposal 1), as Pillow's own encoder does when it holds every frame
            changed = (frame != self._previous).reshape(frame.shape[0], -1)  # (H, 3W)
            rows = np.flatnonzero(changed.any(axis=1))
            if len(rows):
                top, bottom = int(rows[0]), int(rows[-1]) + 1
                cols = np.flatnonzero(changed[top:bottom].any(axis=0)) // frame.shape[2]
                left, right = int(cols[0]), int(cols[-1]) + 1
            else:  # nothing moved: one pixel keeps the frame (and its delay)
                bottom, right = 1, 1
        im = Image.fromarray(frame[top:bottom, left:right]).convert(
            "P", palette=Image.Palette.ADAPTIVE, colors=256
        )
        if self.frames == 0:
            header, _ = GifImagePlugin.getheader(im, info={"loop": 0, "duration": duration_ms})
            for chunk in header:
                self._fp.write(chunk)
        for chunk in GifImagePlugin.getdata(
            im,
            offset=(int(left), int(top)),
            duration=duration_ms,
            disposal=1,
            include_color_table=True,
        ):
            self._fp.write(chunk)
        self._previous = frame
        self.frames += 1

    def close(self) -> Path:
        """Write the last frame (it lingers), finish the file and move it into place.

        Raises:
            InvalidConfigError: no frame was added.
            OutputError: the file could not be written (a full disk); the partial file is
                removed and a file already at ``path`` kept.
        """
        if self._fp.closed:
            return self.path
        if self._pending is None:
            self.abort()
            raise InvalidConfigError(f"{self.path}: no frames to write")
        with self._aborted_on_failure():
            self._write(self._pending, max(LINGER_MS, self.delay_ms))
            self._pending = self._previous = None
            self._fp.write(b";")  # GIF trailer
            self._fp.close()
            os.replace(self._tmp, self.path)
        return self.path

    def abort(self) -> None:
        """Discard the partial file (idempotent)."""
        self._pending = self._previous = None
        if not self._fp.closed:
            # closing flushes the buffer, which fails again on a full disk: the file is
            # closed all the same, and the partial file must still go (it was left behind)
            with contextlib.suppress(OSError):
                self._fp.close()
        self._tmp.unlink(missing_ok=True)

    def __enter__(self) -> GifStream:
        return self

    def __exit__(self, kind, exc, tb) -> None:
        if kind is None:
            self.close()
        else:
            self.abort()


def write_strip(frames: Sequence[np.ndarray], path: str | Path, *, panels: int = 6) -> Path:
    """Write ``panels`` evenly spaced frames side by side as one PNG."""
    if not frames:
        raise InvalidConfigError("no frames to write")
    picks = [frames[i] for i in strip_indices(len(frames), panels)]
    return _save_png(np.concatenate(picks, axis=1), Path(path))


def _save_png(image: np.ndarray, path: Path) -> Path:
    from PIL import Image

    with written_whole(path, "PNG file") as tmp:
        Image.fromarray(image).save(tmp, format="PNG")
    return path


def write_replay(
    result: Any,
    path: str | Path,
    *,
    decomposition: bool = False,
    fps: int = DEFAULT_FPS,
    panels: int = 6,
) -> Path:
    """Write an episode replay as a GIF (or a PNG strip if ``path`` ends in ``.png``).

    Frames are the recorded ones (``result.frames``) if any, else redrawn from the
    trajectory one at a time, so memory does not grow with the episode's length.

    Args:
        result: the played episode (recorded or with a trajectory).
        path: output file, ``.gif`` or ``.png``.
        decomposition: tint free space by the configuration-space decomposition at L_min
            (frames are then redrawn from the trajectory).
        fps: frames per second of the GIF, an integer in [1, :data:`MAX_FPS`].
        panels: frames in a PNG strip.

    Returns:
        The path written.

    Raises:
        InvalidConfigError: a bad ``fps`` or suffix, or an episode without frames.
    """
    path = Path(path)
    fps = _fps(fps)
    suffix = path.suffix.lower()
    if suffix not in REPLAY_SUFFIXES:
        raise InvalidConfigError(f"replay path must end in .gif or .png, got {str(path)!r}")
    shading: tuple = ()
    if decomposition:
        from analysis.overlay import decomposition_shading

        shading = decomposition_shading(result.map_obj, result.config.l_min)
    recorded = result.frames if (result.frames and not decomposition) else None
    if recorded is None and result.trajectory is None:
        raise InvalidConfigError("the episode has no frames and no trajectory to draw")
    n = len(recorded) if recorded is not None else len(result.trajectory)
    if suffix == ".png":
        picks = strip_indices(n, panels)
        if recorded is not None:
            frames = [recorded[i] for i in picks]
        else:
            frames = list(iter_trajectory_frames(result, shading=shading, indices=picks))
        return _save_png(np.concatenate(frames, axis=1), path)
    source = recorded if recorded is not None else iter_trajectory_frames(result, shading=shading)
    with GifStream(path, fps) as gif:
        for frame in source:
            gif.add(frame)
    return path
