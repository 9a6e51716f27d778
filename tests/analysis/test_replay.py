"""Replays are streamed: frames round-trip through the GIF, memory does not grow with length."""

from __future__ import annotations

import tracemalloc

import numpy as np
import pytest
from PIL import Image, ImageSequence

from analysis.replay import GifStream, iter_trajectory_frames, strip_indices, write_replay
from envs.errors import InvalidConfigError
from strategies.runner import run_episode


def _frames(n: int) -> list[np.ndarray]:
    rng = np.random.default_rng(0)
    frames = []
    for i in range(n):
        f = np.full((48, 64, 3), 236, np.uint8)
        y, x = rng.integers(0, 40), rng.integers(0, 56)
        f[y : y + 8, x : x + 8] = (220, 50, 50)
        f[40:44, (3 * i) % 60 : (3 * i) % 60 + 4] = (40, 90, 220)
        frames.append(f)
    frames.append(frames[-1].copy())  # a frame where nothing moved
    return frames


def test_every_frame_round_trips_exactly_with_its_delay(tmp_path) -> None:
    frames = _frames(12)
    path = tmp_path / "r.gif"
    with GifStream(path, fps=25) as gif:
        for f in frames:
            gif.add(f)
    with Image.open(path) as im:
        assert im.n_frames == len(frames) and im.info["loop"] == 0
        for k, frame in enumerate(ImageSequence.Iterator(im)):
            assert np.array_equal(np.asarray(frame.convert("RGB")), frames[k]), k
            assert frame.info["duration"] == (1500 if k == len(frames) - 1 else 40)


def test_a_failed_run_leaves_no_file(tmp_path) -> None:
    path = tmp_path / "r.gif"
    with pytest.raises(RuntimeError), GifStream(path) as gif:
        gif.add(_frames(1)[0])
        raise RuntimeError("the episode failed")
    assert list(tmp_path.iterdir()) == []
    with pytest.raises(InvalidConfigError, match="no frames"):
        GifStream(path).close()
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("fps", [0, 101, 2.5, True])
def test_fps_is_checked(tmp_path, fps) -> None:
    with pytest.raises(InvalidConfigError, match="fps = "):
        GifStream(tmp_path / "r.gif", fps=fps)


def test_strip_indices_cover_the_episode() -> None:
    assert strip_indices(11, 6) == [0, 2, 4, 6, 8, 10]
    assert strip_indices(3, 6) == [0, 1, 2]
    assert strip_indices(1, 6) == [0]


def _peak_while_streaming(tmp_path, steps: int) -> tuple[int, int]:
    frame_bytes = []

    with GifStream(tmp_path / f"{steps}.gif") as gif:

        def sink(frame: np.ndarray) -> None:
            frame_bytes.append(frame.nbytes)
            gif.add(frame)

        tracemalloc.start()
        try:
            run_episode(
                "open_room",
                "pursuer/greedy",
                "evader/random",
                seed=0,
                max_cycles=steps,
                on_frame=sink,
            )
            peak = tracemalloc.get_traced_memory()[1]
        finally:
            tracemalloc.stop()
    return peak, frame_bytes[0]


def test_memory_stays_flat_for_any_episode_length(tmp_path) -> None:
    """Four times the steps, the same peak: frames are not kept (numpy is traced)."""
    _peak_while_streaming(tmp_path, 2)  # warm-up: first-call caches (kernel, tables, fonts)
    short, frame = _peak_while_streaming(tmp_path, 6)
    long, _ = _peak_while_streaming(tmp_path, 24)
    assert long - short < 2 * frame, (short, long, frame)  # a list would add 18 frames


def test_write_replay_redraws_a_png_strip_from_the_trajectory(tmp_path) -> None:
    result = run_episode("open_room", "pursuer/greedy", "evader/random", seed=1, max_cycles=9)
    out = write_replay(result, tmp_path / "strip.png")
    panels = list(iter_trajectory_frames(result, indices=strip_indices(result.steps + 1)))
    with Image.open(out) as img:
        strip = np.asarray(img.convert("RGB"))
    assert len(panels) == 6
    assert np.array_equal(strip, np.concatenate(panels, axis=1))  # first to last, in order
    gif = write_replay(result, tmp_path / "redrawn.gif", fps=10)
    with Image.open(gif) as im:
        assert im.n_frames == result.steps + 1
