"""Peak memory and time of writing a replay GIF: streamed frames against a list of frames.

``surveil play`` used to keep every rendered frame (about 2.75 MB each at the default
size) and hand the list to Pillow's ``save_all`` at the end: memory grew by 2.75 MB per
step (5.8 GB at 2,000 steps). It now streams each frame into
:class:`analysis.replay.GifStream` as the runner draws it (``run_episode(on_frame=...)``).

Both ways play the same seeded episode (``pursuer/greedy`` against ``evader/random`` on
``open_room``, which holds surveillance to the horizon, so every run has ``--steps``
frames), each in its own fresh process so that the peak resident set size
(``ru_maxrss``) belongs to that variant alone. The processes run one after the other in
this run; the time ratio and the memory ratio are the figures, the absolute values are
printed beside them.

Usage::

    python benchmarks/replay_memory.py [--steps 500] [--variant list|stream]
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from bench_cli import integer, run

EPISODE = dict(map="open_room", pursuer="pursuer/greedy", evader="evader/random", seed=0)


def _child(variant: str, steps: int, out: Path) -> dict:
    from analysis.replay import GifStream
    from strategies.runner import run_episode

    t0 = time.perf_counter()
    if variant == "stream":
        with GifStream(out, fps=20) as gif:
            result = run_episode(**EPISODE, max_cycles=steps, on_frame=gif)
    else:  # the former way: every frame in a list, then Pillow's save_all
        from PIL import Image

        result = run_episode(**EPISODE, max_cycles=steps, record=True)
        images = [Image.fromarray(f) for f in result.frames]
        hold = [50] * (len(images) - 1) + [1500]
        images[0].save(out, save_all=True, append_images=images[1:], duration=hold, loop=0)
    seconds = time.perf_counter() - t0
    peak_kb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss  # KiB on Linux
    return {
        "variant": variant,
        "steps": result.steps,
        "seconds": seconds,
        "peak_mb": peak_kb / 1024,
        "file_mb": out.stat().st_size / 2**20,
    }


def _run(variant: str, steps: int) -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        cmd = [
            sys.executable,
            __file__,
            "--variant",
            variant,
            "--steps",
            str(steps),
            "--out",
            str(Path(tmp) / f"{variant}.gif"),
        ]
        env = {**os.environ, "SDL_VIDEODRIVER": "dummy", "MPLBACKEND": "Agg"}
        done = subprocess.run(cmd, check=True, capture_output=True, text=True, env=env)
    return json.loads(done.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--steps", type=integer(1), default=500, help="episode length (frames - 1)")
    parser.add_argument("--variant", choices=["list", "stream"], help=argparse.SUPPRESS)
    parser.add_argument("--out", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.variant:  # a child process: one variant, one JSON line
        print(json.dumps(_child(args.variant, args.steps, Path(args.out))))
        return
    print(f"load average: {os.getloadavg()[0]:.2f} (2 cores shared)")
    rows = [_run("stream", args.steps), _run("list", args.steps)]
    for r in rows:
        print(
            f"{r['variant']:<7} {r['steps']:>6} steps  {r['seconds']:7.1f} s  "
            f"peak {r['peak_mb']:8.0f} MB  file {r['file_mb']:6.2f} MB"
        )
    s, ref = rows
    print(
        f"stream / list: time {s['seconds'] / ref['seconds']:.2f}x, "
        f"peak memory {s['peak_mb'] / ref['peak_mb']:.3f}x, "
        f"file size {s['file_mb'] / ref['file_mb']:.2f}x"
    )


if __name__ == "__main__":
    raise SystemExit(run(main))
