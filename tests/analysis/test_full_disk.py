"""Outputs written on a full disk: one line naming the file, and nothing cut short left.

A real write failure, not a stand-in: each command runs in a process whose files may not
grow past a size (``RLIMIT_FSIZE``; its writes then fail as on a full disk, with "File too
large"). Before :func:`envs.files.written_whole`, each said only "surveil: error: [Errno
27] File too large", naming no file, and left a picture cut short over a whole one
(``surveil maps --plot``) or a hidden temporary GIF behind (``surveil play``).
"""

from __future__ import annotations

import os
import resource
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
LIMIT = 12_000  # bytes: the corner world's picture (~18 kB) and a 60-step GIF do not fit


def _limited() -> None:  # in the command's process only
    resource.setrlimit(resource.RLIMIT_FSIZE, (LIMIT, LIMIT))


def _surveil(cwd: Path, *argv: str, limited: bool) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": str(ROOT), "SDL_VIDEODRIVER": "dummy", "MPLBACKEND": "Agg"}
    return subprocess.run(
        [sys.executable, "-m", "analysis.cli", *argv],
        env=env,
        cwd=cwd,
        capture_output=True,
        text=True,
        timeout=300,
        preexec_fn=_limited if limited else None,
    )


def _one_line_naming(proc: subprocess.CompletedProcess, what: str) -> None:
    assert "Traceback" not in proc.stderr, proc.stderr
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1, proc.stderr
    assert lines[0].startswith(f"surveil: error: {what}: could not write it (File too large)")


def test_a_picture_that_does_not_fit_leaves_the_one_there_whole(tmp_path):
    pictures = tmp_path / "maps"
    assert _surveil(tmp_path, "maps", "--plot", str(pictures), limited=False).returncode == 0
    whole = (pictures / "corner.png").read_bytes()
    assert len(whole) > LIMIT
    proc = _surveil(tmp_path, "maps", "--plot", str(pictures), limited=True)
    _one_line_naming(proc, f"picture = {str(pictures / 'corner.png')!r}")
    assert (pictures / "corner.png").read_bytes() == whole  # before: its first 12,000 bytes
    assert sorted(p.name for p in pictures.iterdir() if p.name.startswith(".")) == []


def test_a_replay_that_does_not_fit_leaves_no_temporary_file(tmp_path):
    gif = tmp_path / "play.gif"
    argv = ["play", "--map", "open_room", "--pursuer", "pursuer/greedy", "--evader"]
    argv += ["evader/straight", "--start", "valid", "--max-cycles", "60", "--out", str(gif)]
    proc = _surveil(tmp_path, *argv, limited=True)
    _one_line_naming(proc, f"GIF file = {str(gif)!r}")
    assert sorted(p.name for p in tmp_path.iterdir()) == []  # before: .play.gif.PID.tmp
