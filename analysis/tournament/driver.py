"""The driver: plan a spec's matches, skip those already stored, play the rest, store each.

:func:`run_tournament` is the Python API behind ``surveil tournament``. It takes the
store's write lock, records the run and its plan, hands the unplayed matches to an
executor and commits every outcome as it arrives (one transaction per match). Ctrl-C
or SIGTERM stops it within a second or two: workers are stopped, the matches in flight
are dropped (they are replayed on resume), and the summary says how to resume. A rerun
of the same spec on the same store resumes; nothing stored is played again.

A store may hold a run of the same spec played by an older surveil whose time limit meant
something else (:data:`~analysis.tournament.spec.TIME_LIMIT_RULE`): its matches have
other identities and are not reused, the run is a new one, and the summary says so.
When an older surveil identified the matches of the very same run otherwise (the spec,
so the run id, unchanged), those matches are set aside as a run of their own
(:meth:`~analysis.tournament.store.Store.set_aside`) before the run plays its own.

A spec with an ``[sprt]`` table stops as soon as Wald's sequential test on the
candidate's and the baseline's paired starts is decided (run status ``decided``); the
matches left are not played. Matches are planned seed-major, so pairs complete as the
run goes.
"""

from __future__ import annotations

import contextlib
import dataclasses
import os
import signal
import sys
import threading
import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from analysis.tournament.executors import Executor, SerialExecutor, check_backend, make_executor
from analysis.tournament.identity import plan
from analysis.tournament.spec import Spec, load_spec, unseen_games
from analysis.tournament.store import Store, StoreError
from analysis.tournament.worker import context_for

__all__ = ["RunSummary", "Sequential", "default_store", "run_tournament"]


def default_store(spec: Spec) -> Path:
    """Where a spec's results go unless told: ``out/tournaments/<name>.sqlite``."""
    return Path("out") / "tournaments" / f"{spec.name}.sqlite"


@dataclass
class RunSummary:
    """What one invocation of :func:`run_tournament` did.

    Attributes:
        run_id, name: the run (the spec's hash and name).
        store: the store file.
        planned: distinct matches the spec plans.
        reused: of those, already in the store when the run started.
        played: matches finished by this invocation.
        forfeits, errors: of ``played``, how many ended so.
        interrupted: ``None``, or the signal that stopped the run (``"SIGINT"``...).
        decided: with an ``[sprt]`` table, the test's decision once it stopped the run.
        seconds: wall-clock time of this invocation.
        backend: the executor's description.
    """

    run_id: str
    name: str
    store: Path
    planned: int
    reused: int
    played: int = 0
    forfeits: int = 0
    errors: int = 0
    interrupted: str | None = None
    decided: str | None = None
    seconds: float = 0.0
    backend: str = ""
    messages: list[str] = field(default_factory=list)

    @property
    def complete(self) -> bool:
        """Every planned match has a result."""
        if self.interrupted is not None:
            return False
        return self.decided is not None or self.reused + self.played >= self.planned

    def describe(self) -> str:
        """A few lines for the terminal."""
        rate = self.played / self.seconds if self.seconds > 0 else 0.0
        head = (
            f"run {self.run_id} ({self.name}) in {self.store}: {self.reused + self.played} of "
            f"{self.planned} matches stored ({self.reused} reused, {self.played} played now "
            f"in {self.seconds:.1f} s, {rate:.2f}/s, {self.backend})"
        )
        if self.forfeits or self.errors:
            head += f"; {self.forfeits} forfeits, {self.errors} errors (see the report)"
        return "\n".join([head, *self.messages])


def run_tournament(
    spec: Spec | str | os.PathLike[str],
    store: str | os.PathLike[str] | None = None,
    *,
    backend: str = "process",
    workers: int | None = None,
    address: str | None = None,
    executor: Executor | None = None,
    retry_errors: bool = False,
    progress: bool = True,
    resume_hint: str | None = None,
) -> RunSummary:
    """Play a tournament into a store, resuming what is already there.

    Args:
        spec: a :class:`Spec` or the path of a TOML spec.
        store: the SQLite store (default: :func:`default_store`).
        backend: ``"serial"``, ``"process"`` or ``"ray"``.
        workers: processes (process backend) or CPUs of a local Ray instance.
        address: a Ray cluster address (ray backend).
        executor: an executor to use instead of ``backend``/``workers``/``address``.
        retry_errors: replay matches stored as ``error`` (e.g. after fixing a map).
        progress: show a progress bar (matches done, rate, ETA) on stderr.
        resume_hint: the command that resumes, printed when interrupted.

    Returns:
        The :class:`RunSummary` (``interrupted`` set if a signal stopped it).

    Raises:
        InvalidConfigError: a bad spec, store or backend (or ``workers`` not an integer
            >= 1).
        StoreBusyError: another driver is writing to the store.
    """
    t0 = time.monotonic()
    if executor is None:
        # before the store: a refused backend left the run marked 'running'
        check_backend(backend, workers=workers, address=address)
    if not isinstance(spec, Spec):
        spec = load_spec(spec)
    path = Path(store) if store is not None else default_store(spec)
    db = Store(path)
    ex: Executor | None = None
    summary: RunSummary | None = None
    began = False
    try:
        db.lock()
        matches = list(plan(spec))
        unique = list({m.match_id: (m, d) for m, d in matches}.values())
        from envs.maps.io import map_to_dict

        geometry = {m.digest: (m.map.name, map_to_dict(m.map)) for m in spec.maps}
        older = _older_runs(db, spec)  # before this run is in the store
        aside = db.set_aside(spec.run_id, (m.match_id for m, _ in unique))
        if aside is not None:
            older.append(
                f"run {spec.run_id} in {path} held {aside[1]} matches an older surveil "
                "identified otherwise (the same spec, other match identities): they are set "
                f"aside as run {aside[0]} (surveil report {path} --run {aside[0]}), so that "
                f"run {spec.run_id} counts each of its starts once"
            )
        done = db.begin_run(spec.run_id, spec.name, spec.to_dict(), unique, geometry)
        began = True
        if retry_errors:
            done = db.finished(spec.run_id, include_errors=False)
        todo = [m for m, _ in unique if m.match_id not in done]
        summary = RunSummary(spec.run_id, spec.name, path, len(unique), len(unique) - len(todo))
        summary.messages += older
        test = Sequential(spec.sprt, db.rows(spec.run_id)) if spec.sprt else None
        if test is not None and test.decision is not None:
            todo = []
            summary.decided = test.decision
            summary.messages.append(test.describe())
        if todo:  # once per run, here: a worker's copy of a model says nothing
            for category, message in unseen_games(spec):
                warnings.warn(message, category, stacklevel=2)
        if not todo:
            summary.backend = "nothing to play"
            db.end_run(spec.run_id, "decided" if summary.decided else "finished")
            return summary
        ctx = context_for(spec)
        ex = executor or make_executor(backend, workers=workers, address=address)
        summary.backend = ex.describe()
        try:
            _play(db, spec, todo, ctx, ex, summary, progress, test)
        except StoreError as exc:  # a full disk: say what is kept and how to go on
            with contextlib.suppress(StoreError):  # not 'running' when nothing runs it
                db.end_run(spec.run_id, "interrupted")
            hint = resume_hint or "run the same spec on the same store again"
            raise StoreError(
                f"{exc} ({summary.reused + summary.played} of {summary.planned} matches "
                f"are stored; the matches in play were lost; to resume: {hint})"
            ) from exc
        status = "interrupted" if summary.interrupted else "finished"
        if summary.decided and not summary.interrupted:
            status = "decided"
            summary.messages.append(test.describe())
        db.end_run(spec.run_id, status)
        if summary.interrupted:
            hint = resume_hint or "run the same spec on the same store again"
            summary.messages.append(
                f"stopped by {summary.interrupted}: {summary.reused + summary.played} of "
                f"{summary.planned} matches are stored in {path}; to resume: {hint}"
            )
        return summary
    except KeyboardInterrupt:  # before _play's handler: a Ctrl-C while Ray or the pool
        if began:  # started left the run 'running' (the store said so to report/export)
            with contextlib.suppress(StoreError):
                db.end_run(spec.run_id, "interrupted")
        raise
    finally:
        if ex is not None:
            ex.close()
        db.close()
        if summary is not None:
            summary.seconds = time.monotonic() - t0


def _older_runs(db: Store, spec: Spec) -> list[str]:
    """A line for each run of ``spec`` in ``db`` an older surveil played (not reused),
    said when this run begins: none when ``db`` holds it already (a resume; the lines
    were repeated on every one)."""
    from analysis.tournament.spec import TIME_LIMIT_RULE

    runs = db.runs()
    if any(r["run_id"] == spec.run_id for r in runs):
        return []
    bare = _placeless({k: v for k, v in spec.to_dict().items() if k != "time_limit_rule"})
    return [
        f"run {r['run_id']} in {db.path} is this spec played by an older surveil, whose time "
        "limit counted the whole match (the env's set-up included) and blamed the side "
        f"that had decided slower: none of its {r['done']} stored matches is reused, and "
        f"this run ({spec.run_id}) plays them with a clock per role ({TIME_LIMIT_RULE}); "
        f"the old run stays in the store (surveil report {db.path} --run {r['run_id']})"
        for r in runs
        if _placeless(r["spec"]) == bare
    ]


def _placeless(spec: dict[str, Any]) -> dict[str, Any]:
    """A normalised spec without where its files lie (a model's path, a map file's),
    whose contents it identifies by hash: the same spec run from another checkout (a
    zoo model under another root) is the same game. The run id keeps the paths."""
    out = dict(spec)
    for key, place in (("pursuers", "model_path"), ("evaders", "model_path"), ("maps", "source")):
        if isinstance(spec.get(key), list):  # any spec a store holds, whatever wrote it
            out[key] = [
                {k: v for k, v in e.items() if k != place} if isinstance(e, dict) else e
                for e in spec[key]
            ]
    return out


class Sequential:
    """Wald's SPRT of an ``[sprt]`` table, fed one finished match at a time.

    A start (map, variant, opponent, seed, start kind) counts once both the candidate and
    the baseline have a result on it; it is discordant when exactly one of them won.

    Args:
        cfg: the spec's validated ``[sprt]`` table.
        rows: matches already stored (flat dicts as :meth:`Store.rows` returns).
    """

    def __init__(self, cfg: dict[str, Any], rows: list[dict[str, Any]] = ()) -> None:
        self.cfg = cfg
        self.role = cfg["role"]
        self.other = "evader" if self.role == "pursuer" else "pursuer"
        self.wins: dict[tuple, dict[str, bool]] = {}
        self.a_only = self.b_only = 0
        self.decision: str | None = None
        for r in rows:
            self.add(r)

    def add(self, row: dict[str, Any]) -> str | None:
        """Count one finished match (a row with labels, ``status`` and ``winner``)."""
        label = row[self.role]
        if label not in (self.cfg["candidate"], self.cfg["baseline"]):
            return self.decision
        if row.get("status") == "error" or not row.get("winner"):
            return self.decision
        key = (row["map"], row["variant"], row[self.other], row["seed"], row["start"])
        pair = self.wins.setdefault(key, {})
        pair[label] = row["winner"] == self.role
        if len(pair) == 2:
            a, b = pair[self.cfg["candidate"]], pair[self.cfg["baseline"]]
            self.a_only += a and not b
            self.b_only += b and not a
            if self.decision is None:
                from analysis.tournament.statistics import sprt

                verdict = sprt(
                    self.a_only,
                    self.b_only,
                    p1=self.cfg["p1"],
                    alpha=self.cfg["alpha"],
                    beta=self.cfg["beta"],
                )
                self.decision = None if verdict == "undecided" else verdict
        return self.decision

    def describe(self) -> str:
        """One line: the comparison, the counts and the decision."""
        c = self.cfg
        verdict = {"a better": "better", "not better": "not better"}.get(self.decision or "")
        head = (
            f"sprt ({c['role']}s, p1 = {c['p1']:g}, alpha = {c['alpha']:g}, beta = {c['beta']:g})"
        )
        counts = (
            f"discordant starts: {self.a_only} won by the candidate only, "
            f"{self.b_only} by the baseline only"
        )
        if verdict is None:
            return f"{head}: undecided ({counts})"
        who = f"{c['candidate']!r} is {verdict} than {c['baseline']!r}"
        return f"{head}: {who} ({counts}); the run stopped"


class _ProgressLines:
    """Progress for a log: a line on stderr each time another tenth of the planned
    matches is stored (matches stored, forfeits and errors so far, elapsed time)."""

    def __init__(self, name: str, summary: RunSummary) -> None:
        self.name = name
        self.summary = summary
        self.tenth = 10 * summary.reused // max(summary.planned, 1)  # said by a resumed run
        self.t0 = time.monotonic()

    def update(self) -> None:
        s = self.summary
        done = s.reused + s.played
        if 10 * done // max(s.planned, 1) <= self.tenth:
            return
        self.tenth = 10 * done // max(s.planned, 1)
        print(
            f"{self.name}: {done:,} of {s.planned:,} matches stored ({s.played:,} played in "
            f"{time.monotonic() - self.t0:.0f} s; {s.forfeits} forfeits, {s.errors} errors)",
            file=sys.stderr,
            flush=True,
        )


def _play(
    db: Store,
    spec: Spec,
    todo: list,
    ctx: Any,
    ex: Executor,
    summary: RunSummary,
    progress: bool,
    test: Sequential | None = None,
) -> None:
    from tqdm import tqdm

    tqdm.monitor_interval = 0  # no monitor thread: the process backend forks workers
    stop = threading.Event()
    caught: list[str] = []

    def on_signal(signum: int, frame: Any) -> None:
        name = signal.Signals(signum).name
        first = not caught
        caught.append(name)
        stop.set()
        # the serial backend plays in this thread: abandon the match in progress
        if not first or (isinstance(ex, SerialExecutor) and ex.in_match):
            raise KeyboardInterrupt(name)

    handlers = {}
    if threading.current_thread() is threading.main_thread():
        for sig in (signal.SIGINT, signal.SIGTERM):
            handlers[sig] = signal.signal(sig, on_signal)
    # a bar on a terminal; a log (nohup, a cluster's job output) gets a line per tenth of
    # the matches, as training's progress does: the bar's redraws made one line of ~100
    # bytes a match that tail showed as a single line
    terminal = sys.stderr.isatty()
    bar = tqdm(
        total=summary.planned,
        initial=summary.reused,
        desc=spec.name,
        unit="match",
        disable=not (progress and terminal),
        file=sys.stderr,
        dynamic_ncols=True,
        smoothing=0.05,
    )
    lines = _ProgressLines(spec.name, summary) if progress and not terminal else None
    by_id = {m.match_id: m for m in todo} if test is not None else {}
    try:
        for out in ex.run(todo, ctx, stop):
            db.record(spec.run_id, out)
            if test is not None and out["match_id"] in by_id:
                m = by_id[out["match_id"]]
                if test.add({**dataclasses.asdict(m), **out}) and not summary.decided:
                    summary.decided = test.decision
                    stop.set()
            summary.played += 1
            summary.forfeits += out.get("status") == "forfeit"
            summary.errors += out.get("status") == "error"
            bar.update(1)
            if lines is not None:
                lines.update()
            if summary.forfeits or summary.errors:
                bar.set_postfix(forfeits=summary.forfeits, errors=summary.errors, refresh=False)
    except KeyboardInterrupt as exc:
        if not caught:
            caught.append(str(exc) or "SIGINT")
    finally:
        bar.close()
        for sig, h in handlers.items():
            signal.signal(sig, h)
    if caught:
        summary.interrupted = caught[0]
