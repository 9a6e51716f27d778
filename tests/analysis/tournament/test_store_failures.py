"""A store that cannot be written, runs out of room or is damaged: one line that says so
(never SQLite's traceback), nothing lost that was stored, and readers that still read.

Real files and real SQLite throughout: a store made unwritable by its permissions (as
another user, when the tests run as root), a write limit on the driver's process
(``RLIMIT_FSIZE``: its writes fail as on a full disk), a page of the store overwritten.
"""

from __future__ import annotations

import contextlib
import csv
import io
import os
import pickle
import resource
import shutil
import sqlite3
import subprocess
import sys
import tempfile
import textwrap
from pathlib import Path

import pytest

from analysis.cli import main
from analysis.tournament import Store, StoreError, run_tournament, spec_from_dict
from analysis.tournament.report import write_report

from .conftest import comparable

ROOT = Path(__file__).resolve().parents[3]

SPEC = textwrap.dedent(
    """
    name = "small"
    maps = ["open_room", "corridor"]
    pursuers = ["pursuer/greedy", "pursuer/tractrix"]
    evaders = ["evader/straight", "evader/random"]
    seeds = 10
    start = "valid"
    [env]
    max_cycles = 60
    """
)


def _as_a_user_who_cannot_write(path: Path, work):
    """``work()``'s result, computed by a process that cannot write ``path`` or its folder:
    another user when this one is root (root writes anything), else this one after a
    chmod. The folder must be readable by others (``tmp_path`` is not)."""
    if os.geteuid() != 0:
        path.chmod(0o444)
        path.parent.chmod(0o555)
        try:
            return work()
        finally:
            path.parent.chmod(0o755)
            path.chmod(0o644)
    read, write = os.pipe()
    pid = os.fork()
    if pid == 0:  # pragma: no cover - the child reports through the pipe
        code = 0
        try:
            os.close(read)
            os.setgid(65534)
            os.setuid(65534)  # nobody
            try:
                result = ("ok", work())
            except BaseException as exc:
                result = ("raised", f"{type(exc).__name__}: {exc}")
            with os.fdopen(write, "wb") as f:
                pickle.dump(result, f)
        except BaseException:
            code = 1
        os._exit(code)
    os.close(write)
    with os.fdopen(read, "rb") as f:
        data = f.read()
    _, status = os.waitpid(pid, 0)
    assert status == 0 and data, "the child running as another user failed"
    kind, value = pickle.loads(data)
    if kind == "raised":
        raise AssertionError(value)
    return value


@pytest.fixture
def shared_dir():
    """A folder other users can read (``tmp_path`` is private to its owner)."""
    path = Path(tempfile.mkdtemp(prefix="surveil-store-test-"))
    path.chmod(0o755)
    out = path / "out"
    out.mkdir()
    out.chmod(0o777)
    yield path
    shutil.rmtree(path, ignore_errors=True)


def test_a_store_its_reader_cannot_write_is_reported_and_exported(shared_dir, small_spec):
    """Another user's store (or one on a read-only file system): a report and an export
    read it; a run is refused in one line saying why. Before, each of them was refused
    with "store ... is not a tournament store (SQLite): attempt to write a readonly
    database": the reader wrote the schema and WAL mode into the file as it opened it."""
    store = shared_dir / "theirs.sqlite"
    summary = run_tournament(spec_from_dict(small_spec), store, backend="serial", progress=False)
    with Store(store) as db:
        want = comparable(db.rows(summary.run_id))
    before = store.read_bytes()
    out = shared_dir / "out"

    def read_it():
        with Store(store, create=False) as db:
            rows = comparable(db.rows(db.run()["run_id"]))
            db.export(db.run()["run_id"], out / "theirs.csv")
        try:
            Store(store).close()
        except StoreError as exc:
            refused = str(exc)
        else:
            refused = None
        return rows, refused

    rows, refused = _as_a_user_who_cannot_write(store, read_it)
    assert rows == want
    with (out / "theirs.csv").open() as f:
        assert len(list(csv.DictReader(f))) == len(want) == 24
    assert refused is not None and "cannot be written here" in refused
    assert "give --store a file in a place you can write" in refused
    assert store.read_bytes() == before


def test_a_report_folder_its_user_cannot_write_is_refused_before_any_work(shared_dir, small_spec):
    """``surveil report --out DIR`` (and ``tournament --report DIR``) where DIR cannot be
    made: refused in one line naming the flag, before the announcement of the work. Before,
    the report announced its regret table, solved it and drew the replays (minutes to
    hours), and only then failed on the folder: "DIR: Permission denied"."""
    store = shared_dir / "theirs.sqlite"
    run_tournament(spec_from_dict(small_spec), store, backend="serial", progress=False)
    # its owner can (and so the other user's process has every module it needs loaded)
    write_report(store, shared_dir / "out" / "mine", regret=False, replays=False)
    spec = shared_dir / "out" / "small.toml"
    spec.write_text(SPEC)
    spec.chmod(0o644)
    rep = shared_dir / "rep"

    def report_there():
        said = []
        run = ["tournament", str(spec), "--store", str(shared_dir / "out" / "t.sqlite")]
        for argv in (
            ["report", str(store), "--out", str(rep), "--no-regret", "--no-replays"],
            [*run, "--report", str(rep), "--backend", "serial"],
        ):
            err = io.StringIO()
            with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
                code = main(argv)
            said.append((code, err.getvalue()))
        return said

    (report, report_err), (run, run_err) = _as_a_user_who_cannot_write(store, report_there)
    assert report == 2 and report_err.startswith("surveil: error: --out = ")
    assert run == 2 and run_err.startswith("surveil: error: --report = ")
    for err in (report_err, run_err):
        assert len(err.splitlines()) == 1, err
        assert f"cannot write in {str(shared_dir)!r}" in err and "writing the report" not in err
    assert not rep.exists() and not (shared_dir / "out" / "t.sqlite").exists()


def _limited(limit: int):
    def cap() -> None:  # in the driver's process only: its writes past `limit` fail
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))

    return cap


def test_a_run_whose_store_stops_taking_writes_says_so_and_resumes(tmp_path):
    """The store's writes fail mid-run (as on a full disk: a file-size limit on the
    driver): one line naming the store, how many matches are kept and the command that
    resumes, exit code 2; the resumed run stores what an uninterrupted one does. Before:
    a traceback ending in "sqlite3.OperationalError: disk I/O error"."""
    spec = tmp_path / "small.toml"
    spec.write_text(SPEC)
    store = tmp_path / "full.sqlite"
    command = [sys.executable, "-m", "analysis.cli", "tournament", str(spec)]
    command += ["--store", str(store), "--backend", "serial", "--no-progress", "--no-report"]
    env = {**os.environ, "PYTHONPATH": str(ROOT), "SDL_VIDEODRIVER": "dummy", "MPLBACKEND": "Agg"}
    proc = subprocess.run(
        command,
        env=env,
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=300,
        preexec_fn=_limited(400_000),  # the plan fits, not every match
    )
    assert "Traceback" not in proc.stderr, proc.stderr
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"surveil: error: store {str(store)!r}")
    with Store(store, create=False) as db:
        run = db.run()
        kept = run["done"]
        assert run["status"] == "interrupted"  # not 'running': nothing runs it
    assert 0 < kept < 80
    assert f"({kept} of 80 matches are stored" in lines[0]
    assert f"to resume: surveil tournament {spec} --store {store} --backend serial" in lines[0]
    resumed = run_tournament(spec, store, backend="serial", progress=False)
    assert (resumed.reused, resumed.played) == (kept, 80 - kept)
    whole = run_tournament(spec, tmp_path / "whole.sqlite", backend="serial", progress=False)
    with Store(store) as a, Store(tmp_path / "whole.sqlite") as b:
        assert comparable(a.rows(resumed.run_id)) == comparable(b.rows(whole.run_id))
        assert a.conn.execute("SELECT COUNT(*) FROM results").fetchone()[0] == 80


def test_an_export_cut_short_by_a_full_disk_keeps_the_file_as_it_was(tmp_path):
    """An export whose writes fail part way (a file-size limit on its process, as on a
    full disk) says so in one line naming the file, and leaves a complete export written
    before as it was, with no temporary file beside it. Before: the complete file was
    replaced by its first 36,000 bytes (74 of the 80 rows whole, the 75th cut mid-line; a
    CSV cut at a row's end reads as a valid export) and the error named no file
    ("surveil: error: [Errno 27] File too large")."""
    spec = tmp_path / "small.toml"
    spec.write_text(SPEC)
    store = tmp_path / "small.sqlite"
    run_tournament(spec, store, backend="serial", progress=False)
    out = tmp_path / "rows.jsonl"
    assert main(["export", str(store), str(out)]) == 0
    whole = out.read_bytes()
    assert len(whole) > 36_000, len(whole)  # the limit below cuts it (SQLite's 32 kB fit)
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    proc = subprocess.run(
        [sys.executable, "-m", "analysis.cli", "export", str(store), str(out)],
        env=env,
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=120,
        preexec_fn=_limited(36_000),
    )
    assert "Traceback" not in proc.stderr, proc.stderr
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1, proc.stderr
    assert lines[0].startswith(f"surveil: error: export file = {str(out)!r}: could not write")
    assert "File too large" in lines[0]
    assert out.read_bytes() == whole
    assert sorted(p.name for p in tmp_path.iterdir() if "rows" in p.name) == ["rows.jsonl"]


def test_a_reader_sees_one_moment_of_a_store_a_run_is_writing(tmp_path):
    """While a tournament writes, a reader's counts and rows come from one snapshot:
    ``surveil export`` of a running run wrote 582 rows and said "580 of its 640 planned
    matches stored", and then counted the rows again for its line. Here a match is
    stored between the reader's reads (by a real second connection, as a driver would)."""
    spec = tmp_path / "small.toml"
    spec.write_text(SPEC)
    store = tmp_path / "s.sqlite"
    run_id = run_tournament(spec, store, backend="serial", progress=False).run_id
    with Store(store) as db:
        last = db.rows(run_id)[-1]
        db.conn.execute("DELETE FROM results WHERE match_id = ?", (last["match_id"],))
    with Store(store, create=False) as reader, reader.snapshot():
        done = reader.run(run_id)["done"]
        with Store(store) as writer:  # the driver stores the last match meanwhile
            writer.record(run_id, last)
        assert done == len(reader.rows(run_id)) == 79
        reader.export(run_id, tmp_path / "rows.csv")
    with (tmp_path / "rows.csv").open() as f:
        assert len(list(csv.DictReader(f))) == 79
    with Store(store, create=False) as reader:  # after the snapshot: the store as it is now
        assert reader.run(run_id)["done"] == len(reader.rows(run_id)) == 80


def _damage_table(store: Path, table: str) -> None:
    """Overwrite the root page of ``table`` with bytes no page holds."""
    con = sqlite3.connect(store)
    con.execute("PRAGMA wal_checkpoint(TRUNCATE)")
    page_size = con.execute("PRAGMA page_size").fetchone()[0]
    root = con.execute("SELECT rootpage FROM sqlite_master WHERE name = ?", (table,)).fetchone()
    con.close()
    with store.open("r+b") as f:
        f.seek((root[0] - 1) * page_size)
        f.write(b"\xff" * page_size)


def test_a_damaged_store_is_named_as_damaged_in_one_line(tmp_path, small_spec, capsys):
    """A store whose table of match identities is damaged: resuming its run said
    "sqlite3.DatabaseError: database disk image is malformed" with a traceback, a store
    cut short was called "not a tournament store". Both now say it is damaged and how
    to save its rows; its results, undamaged, still export."""
    spec = tmp_path / "small.toml"
    spec.write_text(SPEC)
    store = tmp_path / "damaged.sqlite"
    run_tournament(spec, store, backend="serial", progress=False)
    _damage_table(store, "matches")
    capsys.readouterr()
    argv = ["tournament", str(spec), "--store", str(store), "--backend", "serial"]
    assert main([*argv, "--no-progress", "--no-report"]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"surveil: error: store {str(store)!r} is damaged (SQLite: ")
    assert f"sqlite3 {store} .recover" in err and len(err.strip().splitlines()) == 1
    assert main(["export", str(store), str(tmp_path / "rows.csv")]) == 0
    with (tmp_path / "rows.csv").open() as f:
        assert len(list(csv.DictReader(f))) == 80
    cut = tmp_path / "cut.sqlite"
    cut.write_bytes(store.read_bytes()[: 3 * 4096])
    with pytest.raises(StoreError, match=r"is damaged \(SQLite: database disk image"):
        Store(cut, create=False)
