"""Benchmarks keep each episode as it completes (``--results``) and resume from it."""

from __future__ import annotations

import importlib
import json
import re
import signal
from pathlib import Path

import pytest

from envs.errors import InvalidConfigError

BENCHMARKS = Path(__file__).resolve().parents[1] / "benchmarks"


@pytest.fixture
def bench(monkeypatch):
    """Import a benchmark module (they import their helpers from beside them)."""
    monkeypatch.syspath_prepend(str(BENCHMARKS))
    return importlib.import_module


def _lines(path: Path) -> list[str]:
    return path.read_text().splitlines()


def test_a_row_cut_short_by_a_kill_is_dropped_and_not_glued_to_the_next(bench, tmp_path):
    rows = bench("episode_rows")
    path = tmp_path / "r.jsonl"
    path.write_text('{"id": 1}\n{"id": 2}\n{"id"')  # killed while writing row 3
    key = lambda r: str(r["id"])
    assert set(rows.read(path, key)) == {"1", "2"}
    with rows.appending(path) as write:
        write({"id": 3})
    assert [json.loads(line)["id"] for line in _lines(path)] == [1, 2, 3]


def test_rows_record_their_code_and_a_rerun_says_which_were_played_by_other_code(
    bench, tmp_path, monkeypatch, capsys
):
    """A row is written with the code that played it; reading rows back notes how many
    were played by other code (a changed policy must not be measured by old rows
    unnoticed), and says nothing when all are this code's."""
    rows = bench("episode_rows")
    path = tmp_path / "r.jsonl"
    monkeypatch.setattr(rows, "code_version", lambda: "aaaaaaaaaaaa")
    with rows.appending(path) as write:
        write({"id": 1})
        write({"id": 2})
    assert [json.loads(line)["code"] for line in _lines(path)] == ["aaaaaaaaaaaa"] * 2
    capsys.readouterr()
    assert set(rows.read(path, lambda r: str(r["id"]))) == {"1", "2"}
    assert capsys.readouterr().out == ""
    monkeypatch.setattr(rows, "code_version", lambda: "bbbbbbbbbbbb+0123abcd")
    with rows.appending(path) as write:
        write({"id": 3})
    path.write_text(path.read_text() + '{"id": 4}\n')  # a row of a file older than the field
    rows.read(path, lambda r: str(r["id"]))
    out = capsys.readouterr().out
    assert "3 of the 4 rows in" in out
    assert "other code (aaaaaaaaaaaa, not recorded; this is bbbbbbbbbbbb+0123abcd)" in out, out


def test_the_code_version_is_the_commit_and_a_digest_of_changes(bench):
    rows = bench("episode_rows")
    version = rows.code_version()
    assert version is None or re.fullmatch(r"[0-9a-f]{12}(\+[0-9a-f]{8})?", version), version


def test_scripts_of_another_checkout_record_the_code_that_plays(bench, tmp_path, capsys):
    """Scripts run from a second checkout play the policies Python imports (an editable
    install's checkout): the rows name that code and the scripts' apart, and a note says
    how to play the scripts' own (they named the scripts' commit, which did not play)."""
    import importlib.util

    here = bench("episode_rows")
    (tmp_path / "benchmarks").mkdir()
    copy = tmp_path / "benchmarks" / "episode_rows.py"
    copy.write_text((BENCHMARKS / "episode_rows.py").read_text())
    spec = importlib.util.spec_from_file_location("episode_rows_elsewhere", copy)
    other = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(other)
    assert other.playing_root() == here.SCRIPTS_ROOT != other.SCRIPTS_ROOT == str(tmp_path)
    assert other.code_version() == f"{here.code_version()} (scripts: None)"  # not a checkout
    err = capsys.readouterr().err
    assert f"scripts are in {tmp_path} but the policies that play are imported from" in err
    assert f"PYTHONPATH={tmp_path} python" in err
    assert here.code_version() is None or " " not in here.code_version()  # one checkout


def test_a_file_that_is_not_json_lines_is_refused_naming_the_line(bench, tmp_path):
    rows = bench("episode_rows")
    path = tmp_path / "notes.txt"
    path.write_text("some notes\nmore\n")
    with pytest.raises(ValueError, match=r"notes.txt, line 1: 'some notes' is not a JSON"):
        rows.read(path, str)


def test_a_last_line_that_is_no_row_but_ends_its_line_is_refused(bench, tmp_path):
    """Only a line without its newline was cut short by a kill: a whole bad last line (a
    one-line file of notes, a row edited by hand) is refused, not silently kept under the
    rows appended after it (which made the next rerun fail on it)."""
    rows = bench("episode_rows")
    for text in ("garbage\n", '{"id": 1}\n{"id"\n'):
        path = tmp_path / "r.jsonl"
        path.write_text(text)
        with pytest.raises(InvalidConfigError, match=r"r.jsonl, line \d: .* is not a JSON object"):
            rows.read(path, lambda r: str(r["id"]))


def test_a_results_file_of_another_script_is_refused_naming_the_field(bench, tmp_path):
    rows = bench("episode_rows")
    path = tmp_path / "escapes.jsonl"
    path.write_text('{"world": "tee", "pursuer": "still", "seed": 0}\n')
    with pytest.raises(
        InvalidConfigError, match=r"escapes.jsonl, line 1: the row has no field 'rho'"
    ):
        rows.read(path, lambda r: str((r["world"], r["rho"])))


def test_a_bad_results_file_is_one_line_and_exit_2_and_left_as_it_was(bench, tmp_path, capsys):
    holds = bench("pursuer_holds")
    bench_cli = bench("bench_cli")
    out = tmp_path / "other.jsonl"
    text = '{"world": "tee", "pursuer": "still", "seed": 0}\n'
    out.write_text(text)
    argv = ["--worlds", "open_room", "--variants", "as is", "--rho", "0.3", "--seeds", "1",
            "--no-greedy", "--workers", "1", "--results", str(out)]  # fmt: skip
    old = signal.getsignal(signal.SIGTERM)
    try:
        assert bench_cli.run(lambda: holds.main(argv)) == 2
    finally:
        signal.signal(signal.SIGTERM, old)  # run() answers SIGTERM: not in pytest's process
    err = capsys.readouterr().err
    assert "other.jsonl, line 1: the row has no field 'variant'" in err
    assert "Traceback" not in err
    assert out.read_text() == text


def test_pursuer_holds_writes_each_episode_and_resumes(bench, tmp_path, capsys):
    """Eight episodes (one per evader) are written as rows; after losing two (and a row cut
    short), the same command plays only those two and reports over all eight."""
    holds = bench("pursuer_holds")
    out = tmp_path / "holds.jsonl"
    argv = ["--worlds", "open_room", "--variants", "as is", "--rho", "0.3", "--seeds", "1",
            "--no-greedy", "--workers", "1", "--max-cycles", "30",
            "--results", str(out)]  # fmt: skip
    assert holds.main(argv) == 0
    first = capsys.readouterr().out
    rows = [json.loads(line) for line in _lines(out)]
    assert len(rows) == 8
    assert {r["evader"] for r in rows} == set(holds.EVADERS)
    assert all(r["out"]["pursuer/decomposition"][0] in ("pursuer", "evader") for r in rows)
    out.write_text("\n".join(_lines(out)[:6]) + '\n{"world": "open_')
    assert holds.main(argv) == 0
    second = capsys.readouterr().out
    assert "8 episodes selected, 2 to play" in second
    assert len(_lines(out)) == 8
    summary = [line for line in first.splitlines() if "held" in line and "/8" in line]
    assert summary and summary[0] in second  # the same report over all eight


def test_the_pursuer_benchmarks_play_every_evader_of_the_registry_by_default(bench):
    """Issue 13's goal is against every evader of the registry: the default roster holds
    each (the toward-away evader in both modes), so a policy added to the registry is
    benchmarked without anyone remembering to add it here."""
    holds = bench("pursuer_holds")
    from strategies.policies import policy_names

    assert {e.split(":")[0] for e in holds.EVADERS} == set(policy_names("evader"))
    assert "evader/toward_away:away" in holds.EVADERS
    unseen = bench("unseen_worlds")  # the pursuer role of the unseen-worlds benchmark too
    registered = {e.split(":")[0] for e in unseen.EVADERS if e.startswith("evader/")}
    assert registered == set(policy_names("evader"))


def test_pursuer_holds_hindsight_labels_the_losses_to_open_loop_evaders(bench, tmp_path, capsys):
    """``--hindsight CELL``: a loss to an open-loop evader gets the hindsight's verdict
    against its recorded path (bodies 0.2 as played); a closed-loop evader's loss gets
    none. The episodes are in fact held over the horizon (played here), so no verdict but
    ``pursuer`` is right; two rows are rewritten as losses to be labelled."""
    holds = bench("pursuer_holds")
    out = tmp_path / "holds.jsonl"
    argv = ["--worlds", "open_room", "--variants", "as is", "--rho", "0.3", "--seeds", "1",
            "--no-greedy", "--workers", "1", "--max-cycles", "30",
            "--results", str(out)]  # fmt: skip
    assert holds.main(argv) == 0
    rows = [json.loads(line) for line in _lines(out)]
    assert all(r["out"]["pursuer/decomposition"][0] == "pursuer" for r in rows)  # the oracle
    for r in rows:
        if r["evader"] in ("evader/straight", "evader/toward_away"):
            r["out"]["pursuer/decomposition"][:3] = ["evader", "too_close", 2.0]
    out.write_text("".join(json.dumps(r) + "\n" for r in rows))
    capsys.readouterr()
    assert holds.main([*argv, "--hindsight", "0.1"]) == 0
    text = capsys.readouterr().out
    assert "hindsight (cell 0.1) open_room [as is] rho=0.3 evader/straight seed=0: pursuer" in text
    assert "of 3.0; " in text  # the path extended to the horizon, 30 steps
    assert "evader/straight seed=0: too_close at 2.0; hindsight: pursuer" in text
    assert "evader/toward_away seed=0: too_close at 2.0\n" in text  # closed loop: no label
    assert (
        "hindsight (cell 0.1) on the 1 losses to open-loop evaders: 0 evader (unavoidable), "
        "1 pursuer (the policy's regret), 0 unknown (the hindsight's resolution gap)" in text
    )


def test_evader_escapes_writes_each_job_and_resumes(bench, tmp_path, capsys):
    escapes = bench("evader_escapes")
    out = tmp_path / "escapes.jsonl"
    argv = ["--worlds", "tee", "--pursuers", "still", "--seeds", "2", "--simple-seeds", "0",
            "--k", "1", "--workers", "1", "--results", str(out)]  # fmt: skip
    assert escapes.main(argv) == 0
    capsys.readouterr()
    rows = [json.loads(line) for line in _lines(out)]
    assert sorted(r["seed"] for r in rows) == [0, 1]
    assert all(r["pursuer"] == "still" and r["out"]["shooting"][0] for r in rows)
    out.write_text(_lines(out)[0] + "\n")
    assert escapes.main(argv) == 0
    assert "2 jobs selected, 1 to play" in capsys.readouterr().out
    assert len(_lines(out)) == 2


def test_referee_scaling_prints_each_resolution_with_the_budget_s_estimate():
    """Each row as its resolution completes, with the memory the referee's budget estimated
    before solving (est MB) beside the measured peak."""
    import subprocess
    import sys

    out = subprocess.run(
        [sys.executable, "referee_scaling.py", "--world", "open", "--cpl", "4", "6"],
        cwd=BENCHMARKS, capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert out.returncode == 0, out.stderr
    lines = out.stdout.splitlines()
    head = next(i for i, line in enumerate(lines) if line.split()[:2] == ["cpl", "cell"])
    assert "peak MB  x ref  est MB" in lines[head]
    rows = [line.split() for line in lines[head + 1 : head + 3]]
    assert [r[0] for r in rows] == ["4", "6"]
    for r in rows:  # est MB (the 11th column) within a factor of 2 of the peak (the 9th)
        assert 0.5 < float(r[10]) / float(r[8]) < 2.0


def test_pursuer_holds_prints_a_surveil_play_command_that_replays_a_variant_loss(
    bench, tmp_path, capsys
):
    """A loss on a rotated corner (toward_away seed 2: too_close at 3.18 s) is printed with
    a ``surveil play`` command; that command, run, plays the same episode (the same
    outcome, cause and time to the step) on the map it names (``corner~rot0.37``) and
    writes its GIF."""
    import shlex

    from analysis.cli import main as surveil

    holds = bench("pursuer_holds")
    row = holds._play(("corner", holds.VARIANTS[1], 0.5, "evader/toward_away", 2, 600,
                       ("pursuer/decomposition",), None))  # fmt: skip
    winner, cause, t = row["out"]["pursuer/decomposition"][:3]
    assert (winner, cause) == ("evader", "too_close")
    command = holds.replay_command("corner", "rot 0.37", 0.5, "evader/toward_away", 2, 600)
    words = shlex.split(command)
    assert words[:3] == ["surveil", "play", "--map"] and words[3] == "corner~rot0.37"
    gif = tmp_path / "loss.gif"
    words[words.index("--out") + 1] = str(gif)
    capsys.readouterr()
    assert surveil(words[1:]) == 0
    printed = capsys.readouterr().out
    assert f"evader escaped at t = {t:.3f} s ({cause})" in printed, printed
    assert gif.stat().st_size > 0


@pytest.fixture
def appending_elsewhere():
    """Another process appends to a results file (holds its lock) until the block ends;
    the block gets its pid. The file holds that run's row in flight (no newline yet)."""
    import contextlib
    import subprocess
    import sys

    @contextlib.contextmanager
    def hold(path: Path):
        code = (
            f"import sys; sys.path[:0] = [{str(BENCHMARKS)!r}, {str(BENCHMARKS.parent)!r}]\n"
            "import episode_rows, time\n"
            f"with episode_rows.appending({str(path)!r}):\n"
            f"    open({str(path)!r}, 'a').write('{{\"world\": \"open')\n"
            "    print('holding', flush=True)\n"
            "    time.sleep(60)\n"
        )
        holder = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True)
        try:
            assert holder.stdout.readline().strip() == "holding"
            yield holder.pid
        finally:
            holder.kill()
            holder.wait()

    return hold


def test_a_second_run_on_a_results_file_in_use_is_refused_and_changes_nothing(
    bench, tmp_path, capsys, appending_elsewhere
):
    """Two runs on one --results file interleaved their rows, and the second truncated the
    first's row in flight as if a kill had cut it short; now the second is refused at once
    (exit 2, one line naming the file and the holder), before it plays anything."""
    holds = bench("pursuer_holds")
    rows = bench("episode_rows")
    bench_cli = bench("bench_cli")
    out = tmp_path / "holds.jsonl"
    argv = ["--worlds", "open_room", "--variants", "as is", "--rho", "0.3", "--seeds", "1",
            "--no-greedy", "--workers", "1", "--max-cycles", "30",
            "--results", str(out)]  # fmt: skip
    with appending_elsewhere(out) as pid:
        before = out.read_text()
        old = signal.getsignal(signal.SIGTERM)
        try:
            assert bench_cli.run(lambda: holds.main(argv)) == 2
        finally:
            signal.signal(signal.SIGTERM, old)
        err = capsys.readouterr().err
        assert f"holds.jsonl: another run (pid {pid}) is appending to this results file" in err
        assert "Traceback" not in err and len(err.strip().splitlines()) == 1
        with pytest.raises(rows.ResultsBusyError, match="another --results file"):
            with rows.appending(out):  # the row in flight is kept
                pass
        assert rows.read(out, lambda r: r["world"]) == {}  # a report may read it meanwhile
        assert out.read_text() == before == '{"world": "open'
    with rows.appending(out) as write:  # the holder gone, the file is free again
        write({"id": 2})
    assert _lines(out) == ['{"id": 2, "code": ' + json.dumps(rows.code_version()) + "}"]


def test_play_rows_starts_no_more_workers_than_jobs(bench, tmp_path, monkeypatch):
    """A resumed run with nothing (or one job) left starts no pool of --workers processes:
    with 8 workers asked, none is spawned for 0 or 1 job, 2 for 2 jobs."""
    bench_cli = bench("bench_cli")
    started = []
    real = bench_cli.worker_pool

    def counting(processes, *args):
        started.append(processes)
        return real(processes, *args)

    monkeypatch.setattr(bench_cli, "worker_pool", counting)
    for jobs in ([], [1], [1, 2]):
        done = {}
        bench_cli.play_rows(
            jobs, _square, tmp_path / f"rows{len(jobs)}.jsonl", done, _key, _always, 8
        )
        assert sorted(done) == [str(j) for j in jobs]
    assert started == [2]


def _square(j):  # module level: the spawned workers import it
    return {"job": j, "value": j * j}


def _key(row):
    return str(row["job"])


def _always(row):
    return True
