"""The benchmark scripts refuse bad arguments up front and stop cleanly on SIGTERM."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

BENCHMARKS = Path(__file__).resolve().parents[1] / "benchmarks"


def _run(script: str, *args: str, **kwargs) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, script, *args],
        cwd=BENCHMARKS,
        capture_output=True,
        text=True,
        timeout=120,
        **kwargs,
    )


@pytest.mark.parametrize(
    ("script", "args", "message"),
    [
        ("pursuer_holds.py", ["--worlds", "nope"], "--worlds: invalid choice: 'nope'"),
        ("pursuer_holds.py", ["--rho", "nan"], "'nan': expected a finite number > 0"),
        ("pursuer_holds.py", ["--hindsight", "0"], "'0': expected a finite number > 0"),
        ("decision_time.py", ["--maps", "nope"], "'nope': expected a built-in map"),
        ("decision_time.py", ["--seeds", "0"], "'0': expected an integer >= 1"),
        ("decision_time.py", ["--rho", "0"], "'0': expected a finite number > 0"),
        ("decision_time.py", ["--ratio", "1"], "'1': expected a finite number > 1"),
        ("decision_time.py", ["--maps", "random:x:1"], "'random:x:1': expected a built-in map"),
        ("decision_time.py", ["--others", "nope"], "'nope': expected a registered policy"),
        ("evader_escapes.py", ["--seeds", "0"], "'0': expected an integer >= 1"),
        ("faster_evaders.py", ["--rhos", "1"], "'1': expected a finite number > 1"),
        ("referee_scaling.py", ["--cpl", "0"], "'0': expected a finite number > 0"),
        ("reset_scaling.py", ["--worlds", "nope"], "--worlds: invalid choice: 'nope'"),
        ("reset_scaling.py", ["--timeout", "0"], "'0': expected a finite number > 0"),
        ("analytic_matchups.py", ["--workers", "0"], "'0': expected an integer >= 1"),
        ("hindsight_maze.py", ["--cells", "0"], "'0': expected a finite number > 0"),
        ("finetune_curve.py", ["--steps", "100", "--every", "1000"], "--every 1000 > --steps 100"),
        # an empty name (an unset shell variable) was the flag's absence: results not kept
        # (pursuer_holds, evader_escapes) or written to the default path (unseen_worlds)
        ("pursuer_holds.py", ["--results", ""], "--results: '': expected a file"),
        ("evader_escapes.py", ["--results", " "], "--results: ' ': expected a file"),
        ("unseen_worlds.py", ["--results", ""], "--results: '': expected a file"),
        ("analytic_matchups.py", ["--results", ""], "'': expected a results database file"),
        ("finetune_curve.py", ["--save", ""], "--save: '': expected a directory"),
        # an @FILE that cannot be read was argparse's bare "[Errno 2] No such file or
        # directory: 'nosuch.txt'", naming neither the @ argument nor where it was looked for
        (
            "unseen_worlds.py",
            ["--role", "pursuer", "--worlds", "@nosuch.txt"],
            f"error: @nosuch.txt: no such file (in {BENCHMARKS}); @FILE reads arguments",
        ),
        ("unseen_worlds.py", ["--role", "evader", "--worlds", "@."], "@.: is a directory"),
        # a directory, or a path under a file, as the results file: "error: /tmp: Is a
        # directory" and "error: /etc/passwd: File exists" once the run had started
        (
            "unseen_worlds.py",
            ["--role", "pursuer", "--results", "."],
            "--results: '.': is a directory, expected a file",
        ),
        ("pursuer_holds.py", ["--results", "."], "--results: '.': is a directory"),
        (
            "evader_escapes.py",
            ["--results", "bench_cli.py/x.jsonl"],
            "cannot be created: '" + str(BENCHMARKS / "bench_cli.py") + "' is a file",
        ),
        # a file as the output directory: "error: policy_sets.py: File exists"
        (
            "policy_sets.py",
            ["run", "b1", "--out", "policy_sets.py"],
            "error: --out = 'policy_sets.py': is a file, expected a directory",
        ),
        # a subcommand's extra argument: refused with the top-level usage, not the command's
        (
            "policy_sets.py",
            ["totals", ".", "extra"],
            "usage: policy_sets.py totals [-h] DIR\npolicy_sets.py totals: error: unrecognized",
        ),
    ],
)
def test_a_bad_argument_is_a_usage_error(script, args, message) -> None:
    """Exit code 2 and one line naming the value, no traceback, nothing run."""
    out = _run(script, *args)
    assert out.returncode == 2, out.stderr
    assert message in out.stderr
    assert "Traceback" not in out.stderr
    assert out.stdout == ""  # no work started (the scripts print the load average first)


def test_an_argument_file_names_the_one_it_cannot_read(tmp_path) -> None:
    """An @FILE named inside another is checked too, and said to be named there; a file
    that reads is expanded as argparse does (one argument a line)."""
    outer = tmp_path / "worlds.txt"
    outer.write_text("corridor~rot2.3\n@inner.txt\n")
    out = _run("unseen_worlds.py", "--role", "pursuer", "--worlds", f"@{outer}")
    assert out.returncode == 2 and out.stdout == ""
    assert f"@inner.txt (named in @{outer}): no such file (in {BENCHMARKS})" in out.stderr
    outer.write_text("corridor~rot2.3\nnowhere\n")
    out = _run("unseen_worlds.py", "--role", "pursuer", "--worlds", f"@{outer}")
    assert out.returncode == 2 and "unknown pursuer-role world 'nowhere'" in out.stderr


def test_a_name_found_unknown_after_parsing_is_one_line() -> None:
    """A project error (here an unknown zoo model) is one line and exit code 2."""
    out = _run("exploitability.py", "--models", "nope")
    assert out.returncode == 2, out.stderr
    assert out.stderr.startswith("exploitability.py: error: unknown zoo model 'nope'")
    assert "Traceback" not in out.stderr


def test_sigterm_stops_a_run_with_one_line() -> None:
    """SIGTERM (``timeout``) stops the run: exit code 143, no traceback from any process."""
    env = {**os.environ, "PYTHONUNBUFFERED": "1"}
    args = ["--seeds", "50", "--worlds", "maze", "--no-greedy", "--workers", "1"]
    proc = subprocess.Popen(
        [sys.executable, "pursuer_holds.py", *args],
        cwd=BENCHMARKS,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
    )
    assert proc.stdout.readline().startswith("load average")  # the episodes are starting
    time.sleep(1.0)
    proc.send_signal(signal.SIGTERM)
    try:
        _, err = proc.communicate(timeout=30)
    except subprocess.TimeoutExpired:  # pragma: no cover - the bug this test is for
        proc.kill()
        raise
    assert proc.returncode == 143, err
    assert "stopped by SIGTERM" in err
    assert "Traceback" not in err


def _ctrl_c_as_in_a_terminal() -> None:
    # A foreground job takes SIGINT; a test run started in the background (`nohup pytest
    # ... &` from a script) ignores it, its children inherit that, and Python then installs
    # no KeyboardInterrupt handler: the Ctrl-C below would go unseen
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def test_ctrl_c_stops_a_pool_run_with_one_line(tmp_path) -> None:
    """Ctrl-C (SIGINT to the whole process group) stops ``unseen_worlds.py --workers 2``
    with exit code 130 and one line: no worker traceback, no leaked-semaphore warning. An
    empty cache: the workers build their tables behind progress bars (tqdm's lock was a
    semaphore per worker, left behind by the terminated workers)."""
    env = {**os.environ, "PYTHONUNBUFFERED": "1", "SURVEIL_CACHE_DIR": str(tmp_path / "cache")}
    rows = str(tmp_path / "rows.jsonl")
    args = ["--role", "pursuer", "--worlds", "maze~x0.7rot-2.6", "--combos", "0",
            "--seeds", *map(str, range(8)), "--workers", "2", "--results", rows]  # fmt: skip
    proc = subprocess.Popen(
        [sys.executable, "unseen_worlds.py", *args],
        cwd=BENCHMARKS,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
        start_new_session=True,  # its own process group, as a terminal's job
        preexec_fn=_ctrl_c_as_in_a_terminal,
    )
    for line in proc.stdout:  # the pool starts after this line
        if "to play" in line:
            break
    time.sleep(5.0)  # the workers are playing (before, they may still be importing)
    os.killpg(proc.pid, signal.SIGINT)
    try:
        _, err = proc.communicate(timeout=30)
    except subprocess.TimeoutExpired:  # pragma: no cover - the bug this test is for
        os.killpg(proc.pid, signal.SIGKILL)
        raise
    assert proc.returncode == 130, err
    assert err.strip() == "unseen_worlds.py: stopped by SIGINT"


@pytest.mark.parametrize("unbuffered", ["1", ""])
def test_a_reader_that_leaves_stops_a_run_silently(unbuffered) -> None:
    # `policy_sets.py compare A B | head -1` said "policy_sets.py: error: [Errno 32] Broken
    # pipe" (exit 2; unbuffered output) or "Exception ignored ... BrokenPipeError" (exit 120)
    args = ["--maps", "open_room", "--seeds", "1", "--max-cycles", "3", "--reps", "1"]
    proc = subprocess.Popen(
        [sys.executable, "decision_time.py", *args],
        cwd=BENCHMARKS,
        env={**os.environ, "PYTHONUNBUFFERED": unbuffered},
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    proc.stdout.close()  # the reader leaves before the first line (imports take longer)
    err = proc.stderr.read().decode()
    assert proc.wait(timeout=120) == 141, err  # 128 + SIGPIPE, as a shell reports it
    assert err == ""
