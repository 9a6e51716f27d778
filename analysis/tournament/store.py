"""The tournament store: one SQLite file in WAL mode, written only by the driver.

Tables:

* ``runs`` -- one row per spec (``run_id`` = the spec's content hash): name, the
  normalised spec, when it was created and last updated, its status.
* ``run_matches`` -- the matches a run plans, with the labels its reports use.
* ``matches`` -- one row per match identity (primary key), with the identity document.
* ``maps`` -- the geometry of every map by digest, so reports re-simulate replays even
  after a map file changed.
* ``results`` -- one row per finished match: ``ok`` (played out), ``forfeit`` (a policy
  raised or overran its time: the other side wins) or ``error`` (the match could not be
  played, e.g. no start exists; nobody wins).
* ``errors`` -- every failure, including worker crashes that left no result.

Each finished match is one transaction, so killing the driver at any moment (SIGKILL
included) loses at most the matches in flight and never leaves a half-written result.
Results are shared between runs by identity: a different spec on the same store reuses
every match it has in common and never sees the others.

One writer at a time: :meth:`Store.lock` takes an exclusive POSIX lock on ``STORE.lock``
(released by the kernel if the driver dies, not inherited by its workers); a second
driver is refused with a message naming the holder. Readers (reports, exports) need no
lock: WAL lets them read while a run writes. A reader writes no schema and no row, and
reads a store it cannot write (another user's, on a read-only file system) as it is.

A store that cannot be written (read-only, a full disk), is damaged or cannot be read
raises :class:`StoreError` naming the file, what SQLite said and what to do, wherever
it happens (opening it, or the thousandth match of a run), never SQLite's bare error.
"""

from __future__ import annotations

import contextlib
import csv
import functools
import hashlib
import json
import os
import sqlite3
import time
import urllib.parse
from collections.abc import Iterable, Iterator, Mapping
from pathlib import Path
from typing import Any

from analysis.arguments import why_not_a_file
from envs import pidlock
from envs.errors import InvalidConfigError, SurveilValueError
from envs.files import written_whole

__all__ = ["RESULT_FIELDS", "SCHEMA_VERSION", "Store", "StoreBusyError", "StoreError"]

SCHEMA_VERSION = 1

_SCHEMA = """
CREATE TABLE IF NOT EXISTS meta (key TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE IF NOT EXISTS runs (
    run_id TEXT PRIMARY KEY, name TEXT NOT NULL, spec TEXT NOT NULL,
    created REAL NOT NULL, updated REAL NOT NULL, status TEXT NOT NULL);
CREATE TABLE IF NOT EXISTS maps (digest TEXT PRIMARY KEY, name TEXT, geometry TEXT NOT NULL);
CREATE TABLE IF NOT EXISTS matches (match_id TEXT PRIMARY KEY, identity TEXT NOT NULL);
CREATE TABLE IF NOT EXISTS run_matches (
    run_id TEXT NOT NULL REFERENCES runs, match_id TEXT NOT NULL REFERENCES matches,
    seq INTEGER NOT NULL, map TEXT NOT NULL, variant TEXT NOT NULL, pursuer TEXT NOT NULL,
    evader TEXT NOT NULL, start TEXT NOT NULL, seed INTEGER NOT NULL,
    PRIMARY KEY (run_id, match_id));
CREATE TABLE IF NOT EXISTS results (
    match_id TEXT PRIMARY KEY REFERENCES matches,
    status TEXT NOT NULL CHECK (status IN ('ok', 'forfeit', 'error')),
    winner TEXT CHECK (winner IN ('pursuer', 'evader')), cause TEXT, feature TEXT,
    escape_time REAL, steps INTEGER, dt REAL, blame TEXT, error TEXT,
    decide_pursuer REAL, decide_evader REAL, wall_seconds REAL, record TEXT,
    finished REAL NOT NULL);
CREATE TABLE IF NOT EXISTS errors (
    id INTEGER PRIMARY KEY AUTOINCREMENT, run_id TEXT, match_id TEXT, kind TEXT NOT NULL,
    message TEXT NOT NULL, at REAL NOT NULL);
CREATE INDEX IF NOT EXISTS run_matches_seq ON run_matches (run_id, seq);
"""

RESULT_FIELDS = (
    "status",
    "winner",
    "cause",
    "feature",
    "escape_time",
    "steps",
    "dt",
    "blame",
    "error",
    "decide_pursuer",
    "decide_evader",
    "wall_seconds",
    "record",
)
"""Columns of ``results`` an outcome dict fills (besides ``match_id``)."""

ROW_FIELDS = (
    "seq",
    "match_id",
    "map",
    "variant",
    "pursuer",
    "evader",
    "start",
    "seed",
    *RESULT_FIELDS[:-1],
)


class StoreBusyError(SurveilValueError):
    """Another driver holds the store's write lock."""


class StoreError(InvalidConfigError):
    """The store file cannot be written or read: read-only, a full disk, damaged.

    The message names the file, what SQLite (or the system) said and what to do.
    """


# SQLite's primary result codes (https://sqlite.org/rescode.html) a store can meet:
# 3 PERM, 8 READONLY, 10 IOERR, 11 CORRUPT, 13 FULL, 14 CANTOPEN, 26 NOTADB. Python 3.10
# has no ``sqlite_errorcode``: its message text is matched
_SQLITE_TEXT = (
    ("readonly", 8),
    ("read-only", 8),
    ("disk or database is full", 13),
    ("database or disk is full", 13),
    ("malformed", 11),
    ("not a database", 26),
    ("unable to open", 14),
    ("disk i/o error", 10),
)


_OS_ERRNO = {1: 3, 13: 3, 28: 13, 30: 8}
"""The SQLite code of an ``OSError``'s errno: EPERM, EACCES, ENOSPC, EROFS."""


def _sqlite_code(exc: BaseException) -> int | None:
    """SQLite's primary result code of ``exc`` (``None`` if it has none we know)."""
    code = getattr(exc, "sqlite_errorcode", None)
    if code is not None:
        return code & 0xFF
    text = str(exc).lower()
    return next((c for t, c in _SQLITE_TEXT if t in text), None)


def _problem(
    path: Path, exc: BaseException, *, writing: bool, errno: int | None = None
) -> str | None:
    """The message of a store that cannot be used (``None``: not such an error); an
    ``OSError`` is read by its ``errno`` (the disk full, no permission, read-only)."""
    code = _OS_ERRNO.get(errno) if errno is not None else _sqlite_code(exc)
    if code is None and errno is not None:
        return f"store {str(path)!r}: cannot write {exc}"
    said = "SQLite" if errno is None else "the system"
    if code == 26:
        return f"store {str(path)!r} is not a tournament store (SQLite): {exc}"
    if code == 11:
        return (
            f"store {str(path)!r} is damaged ({said}: {exc}); the rows still readable can "
            f"be saved with: sqlite3 {path} .recover > recovered.sql; play into a new --store"
        )
    if code == 13:
        return (
            f"store {str(path)!r}: the disk is full ({said}: {exc}); what was stored before "
            "is kept: free some space, then run the same command again"
        )
    if code in (3, 8, 14):
        if writing:
            return (
                f"store {str(path)!r} cannot be written here ({said}: {exc}); a tournament "
                "writes its store: give --store a file in a place you can write"
                + (" (surveil report and export read this one as it is)" if path.exists() else "")
            )
        return f"store {str(path)!r} cannot be read ({said}: {exc})"
    if code == 10:
        return f"store {str(path)!r}: the disk failed to read or write it ({said}: {exc})"
    return None


def _guarded(method: Any) -> Any:
    """Raise :class:`StoreError` for a SQLite error that means the file cannot be used."""

    @functools.wraps(method)
    def guarded(self: Store, *args: Any, **kwargs: Any) -> Any:
        try:
            return method(self, *args, **kwargs)
        except sqlite3.DatabaseError as exc:
            message = _problem(self.path, exc, writing=self.writer)
            if message is None:
                raise  # another error: a bug, keep its traceback
            raise StoreError(message) from exc

    return guarded


class Store:
    """A tournament store at ``path`` (created on first use).

    Args:
        path: the SQLite file.
        create: create it if missing and write to it (a run); ``False``, a reader
            (reports, exports), writes no schema and no row, and reads a store it
            cannot write.

    Raises:
        InvalidConfigError: the file is not a tournament store, or of another schema.
        StoreError: it cannot be written (a writer) or read, or is damaged.
    """

    def __init__(self, path: str | os.PathLike[str], *, create: bool = True) -> None:
        self.path = Path(path)
        problem = why_not_a_file(self.path)
        if problem is not None and (not create or problem != "no such file"):
            # a device (/dev/null) was "no such file" to readers, an SQLite I/O error to
            # writers; a writer creates a missing file
            raise InvalidConfigError(f"store {str(self.path)!r}: {problem}")
        self.writer = create
        self._lock_file = None
        self.conn: sqlite3.Connection | None = None
        try:
            if create:
                self.path.parent.mkdir(parents=True, exist_ok=True)
            self.conn = self._connect()
            self.conn.row_factory = sqlite3.Row
            self._check_foreign(create)
            if create:
                mode = self.conn.execute("PRAGMA journal_mode=WAL").fetchone()[0]
                if mode.lower() != "wal":  # pragma: no cover - e.g. a network file system
                    raise InvalidConfigError(f"store {self.path}: cannot use WAL mode (got {mode})")
                # NORMAL in WAL mode: a committed match survives any crash of this process
                self.conn.execute("PRAGMA synchronous=NORMAL")
            self.conn.execute("PRAGMA foreign_keys=ON")
            self._init_schema()
        except (sqlite3.DatabaseError, OSError) as exc:
            if self.conn is not None:
                self.conn.close()
            if isinstance(exc, OSError):  # making its folder
                if exc.errno not in _OS_ERRNO:
                    raise  # said with the folder's name
                raise StoreError(_problem(self.path, exc, writing=create, errno=exc.errno)) from exc
            message = _problem(self.path, exc, writing=create) or (
                f"store {str(self.path)!r} is not a tournament store (SQLite): {exc}"
            )
            raise StoreError(message) from exc

    def _connect(self) -> sqlite3.Connection:
        """A connection: a writer's, or a reader's, which writes nothing (and still reads a
        store it cannot write: another user's, on a read-only file system)."""
        plain = sqlite3.connect(self.path, timeout=30.0, isolation_level=None)
        if self.writer:
            return plain
        try:  # as a writer's (it tidies the -wal and -shm files away on closing)
            plain.execute("SELECT COUNT(*) FROM sqlite_master").fetchone()
            return plain
        except sqlite3.OperationalError as exc:
            plain.close()
            if _sqlite_code(exc) not in (8, 14):
                raise
        uri = "file:" + urllib.parse.quote(str(self.path.resolve())) + "?mode=ro"
        if not os.path.exists(f"{self.path}-shm"):
            # a WAL file nobody has open in a place this user cannot write
            # (SQLITE_READONLY_DIRECTORY, or CANTOPEN on a read-only file system): SQLite
            # cannot make the -shm a reader needs, and no writer has it open (its -shm
            # would be there), so read the file as it is
            uri += "&immutable=1"
        return sqlite3.connect(uri, uri=True, timeout=30.0, isolation_level=None)

    def _check_foreign(self, create: bool) -> None:
        """Refuse, before writing anything (the schema, WAL mode), a SQLite file that is
        not a store: one with other tables, or an empty one for a reader."""
        tables = sorted(
            r[0] for r in self.conn.execute("SELECT name FROM sqlite_master WHERE type = 'table'")
        )
        if "meta" in tables or (create and not tables):
            return
        self.conn.close()
        what = f"a SQLite database with other tables {tables}" if tables else "an empty file"
        raise InvalidConfigError(
            f"store {str(self.path)!r} is not a tournament store: it is {what}; left "
            "unchanged (give a new path, or a store a tournament wrote)"
        )

    def _init_schema(self) -> None:
        if not self.writer:  # _check_foreign saw its tables
            row = self.conn.execute("SELECT value FROM meta WHERE key = 'schema'").fetchone()
            row = row or ("none",)
        else:
            with self.transaction() as c:
                for stmt in _SCHEMA.strip().split(";"):
                    if stmt.strip():
                        c.execute(stmt)
                c.execute("INSERT OR IGNORE INTO meta VALUES ('schema', ?)", (str(SCHEMA_VERSION),))
                row = c.execute("SELECT value FROM meta WHERE key = 'schema'").fetchone()
        if str(row[0]) != str(SCHEMA_VERSION):
            raise InvalidConfigError(
                f"store {self.path} has schema version {row[0]}, this surveil reads "
                f"{SCHEMA_VERSION}; use a new store or export the old one with its version"
            )

    # ---------------------------------------------------------------- transactions
    @contextlib.contextmanager
    def transaction(self) -> Iterator[sqlite3.Connection]:
        """``BEGIN IMMEDIATE`` ... ``COMMIT`` (``ROLLBACK`` on any exception)."""
        self.conn.execute("BEGIN IMMEDIATE")
        try:
            yield self.conn
        except BaseException:
            self.conn.execute("ROLLBACK")
            raise
        self.conn.execute("COMMIT")

    @contextlib.contextmanager
    def snapshot(self) -> Iterator[None]:
        """Reads within it see the store as it was at their first read (one read
        transaction; WAL lets a run go on writing meanwhile), so that counts and rows read
        one after the other agree. Reentrant.

        Without it, ``surveil export`` of a running tournament wrote 582 rows and said
        "580 of its 640 planned matches stored": each query saw a later store.
        """
        if self.conn.in_transaction:
            yield
            return
        self.conn.execute("BEGIN")
        try:
            yield
        finally:
            with contextlib.suppress(sqlite3.Error):
                self.conn.execute("COMMIT")

    def close(self) -> None:
        """Release the lock (if held) and close the connection (idempotent)."""
        self.unlock()
        with contextlib.suppress(sqlite3.Error):
            self.conn.close()

    def __enter__(self) -> Store:
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    # ---------------------------------------------------------------- the write lock
    def lock(self) -> None:
        """Take the single-writer lock, or raise :class:`StoreBusyError` naming the holder.

        A POSIX record lock (``lockf``) on ``STORE.lock`` beside the file the store's path
        resolves to (so a symlink to the store takes the same lock): the kernel releases it
        when the driver dies, however it dies, and forked workers do not inherit it. Within one
        process a registry of held stores plays the same part.
        """
        # beside the file the path resolves to: a symlink to the store (or another
        # spelling of its path) takes the same lock, not one of its own
        real = self.path.resolve()
        lock = real.with_name(real.name + ".lock")
        try:
            self._lock_file = pidlock.acquire(lock)
        except pidlock.LockHeldError as e:
            raise StoreBusyError(
                f"store {self.path} is being written by {e.holder}; wait for that run to "
                "finish (or stop it) before starting another on this store, or use --store "
                "with another file"
            ) from None
        except OSError as exc:  # was a bare "[Errno 28] No space left on device"
            why = f"its lock file {lock}: {exc.strerror or exc}"
            raise StoreError(
                _problem(self.path, OSError(why), writing=True, errno=exc.errno)
            ) from exc

    def unlock(self) -> None:
        """Release the write lock (idempotent)."""
        if self._lock_file is not None:
            pidlock.release(self._lock_file)
            self._lock_file = None

    # ---------------------------------------------------------------- runs
    @_guarded
    def begin_run(
        self,
        run_id: str,
        name: str,
        spec: Mapping[str, Any],
        matches: Iterable[tuple[Any, Mapping[str, Any]]],
        maps: Mapping[str, tuple[str, dict[str, Any]]],
    ) -> set[str]:
        """Record a run and its planned matches; return the ids already finished.

        Args:
            run_id: the spec's content hash.
            name: the run's name.
            spec: the normalised spec.
            matches: ``(Match, identity document)`` pairs in play order.
            maps: ``{digest: (name, geometry dict)}``.
        """
        now = time.time()
        with self.transaction() as c:
            c.execute(
                "INSERT INTO runs VALUES (?, ?, ?, ?, ?, 'running') ON CONFLICT(run_id) "
                "DO UPDATE SET updated = excluded.updated, status = 'running'",
                (run_id, name, json.dumps(spec, sort_keys=True), now, now),
            )
            c.executemany(
                "INSERT OR IGNORE INTO maps VALUES (?, ?, ?)",
                [(d, n, json.dumps(g)) for d, (n, g) in maps.items()],
            )
            rows, idents = [], []
            for seq, (m, doc) in enumerate(matches):
                idents.append((m.match_id, json.dumps(doc, sort_keys=True)))
                rows.append(
                    (
                        run_id,
                        m.match_id,
                        seq,
                        m.map,
                        m.variant,
                        m.pursuer,
                        m.evader,
                        m.start,
                        m.seed,
                    )
                )
            c.executemany("INSERT OR IGNORE INTO matches VALUES (?, ?)", idents)
            c.executemany("INSERT OR IGNORE INTO run_matches VALUES (?,?,?,?,?,?,?,?,?)", rows)
        return self.finished(run_id)

    @_guarded
    def set_aside(self, run_id: str, planned: Iterable[str]) -> tuple[str, int] | None:
        """Move the matches ``run_id`` holds but no longer plans into a run of their own.

        The same spec plans other matches when the code that identifies them changed
        (a store an older surveil wrote: another identity version, another env default)
        while the spec, and so the run id, did not. :meth:`begin_run` added the new
        matches beside the old ones: the run then held every start twice and its report
        counted each cell's matches twice (n doubled, intervals too narrow).

        Args:
            run_id: the run about to begin.
            planned: the match ids its spec plans now.

        Returns:
            ``(the new run's id, how many matches moved)``, or ``None`` when the run is
            not in the store or holds only planned matches. The new run keeps the old
            run's name, spec, dates and status (``interrupted`` if it was ``running``),
            so ``surveil report --run ID`` shows what the old run showed.
        """
        keep = set(planned)
        held = self.conn.execute("SELECT match_id FROM run_matches WHERE run_id = ?", (run_id,))
        stale = sorted(m for (m,) in held if m not in keep)  # streamed: a run may be huge
        if not stale:
            return None
        aside = hashlib.sha256(f"{run_id}:{','.join(stale)}".encode()).hexdigest()[:16]
        with self.transaction() as c:
            name, spec, created, updated, status = c.execute(
                "SELECT name, spec, created, updated, status FROM runs WHERE run_id = ?",
                (run_id,),
            ).fetchone()
            status = "interrupted" if status == "running" else status
            c.execute(
                "INSERT OR IGNORE INTO runs VALUES (?, ?, ?, ?, ?, ?)",
                (aside, name, spec, created, updated, status),
            )
            c.executemany(
                "UPDATE run_matches SET run_id = ? WHERE run_id = ? AND match_id = ?",
                [(aside, run_id, m) for m in stale],
            )
        return aside, len(stale)

    @_guarded
    def finished(self, run_id: str, *, include_errors: bool = True) -> set[str]:
        """Match ids of ``run_id`` that have a result (``error`` ones unless excluded)."""
        sql = (
            "SELECT r.match_id FROM run_matches r JOIN results s ON s.match_id = r.match_id "
            "WHERE r.run_id = ?"
        )
        if not include_errors:
            sql += " AND s.status != 'error'"
        return {row[0] for row in self.conn.execute(sql, (run_id,))}

    @_guarded
    def end_run(self, run_id: str, status: str) -> None:
        """Mark a run ``finished``, ``interrupted`` or ``decided``."""
        with self.transaction() as c:
            c.execute(
                "UPDATE runs SET status = ?, updated = ? WHERE run_id = ?",
                (status, time.time(), run_id),
            )

    @_guarded
    def runs(self) -> list[dict[str, Any]]:
        """Every run, newest first, with its counts of planned and finished matches."""
        out = []
        for r in self.conn.execute("SELECT * FROM runs ORDER BY updated DESC"):
            planned, done = self.conn.execute(
                "SELECT COUNT(*), COUNT(s.match_id) FROM run_matches m LEFT JOIN results s "
                "ON s.match_id = m.match_id WHERE m.run_id = ?",
                (r["run_id"],),
            ).fetchone()
            out.append({**dict(r), "spec": json.loads(r["spec"]), "planned": planned, "done": done})
        return out

    def run(self, run_id: str | None = None) -> dict[str, Any]:
        """One run (default: the most recently updated); ``run_id`` may be a prefix.

        Raises:
            InvalidConfigError: no such run (listing the known ones).
        """
        runs = self.runs()
        if not runs:
            raise InvalidConfigError(f"store {self.path} has no runs yet")
        if run_id is None:
            return runs[0]
        hits = [r for r in runs if r["run_id"].startswith(run_id) or r["name"] == run_id]
        if len(hits) != 1:
            known = ", ".join(f"{r['run_id']} ({r['name']})" for r in runs)
            what = "no run" if not hits else "more than one run"
            raise InvalidConfigError(f"store {self.path}: {what} matches {run_id!r}; runs: {known}")
        return hits[0]

    # ---------------------------------------------------------------- results
    @_guarded
    def record(self, run_id: str, outcome: Mapping[str, Any]) -> None:
        """Store one finished match (one transaction); errors also go to ``errors``."""
        values = [outcome.get(k) for k in RESULT_FIELDS]
        with self.transaction() as c:
            c.execute(
                f"INSERT OR REPLACE INTO results (match_id, {', '.join(RESULT_FIELDS)}, finished) "
                f"VALUES ({', '.join('?' * (len(RESULT_FIELDS) + 2))})",
                (outcome["match_id"], *values, time.time()),
            )
            if outcome.get("status") != "ok":
                c.execute(
                    "INSERT INTO errors (run_id, match_id, kind, message, at) VALUES (?,?,?,?,?)",
                    (
                        run_id,
                        outcome["match_id"],
                        outcome["status"],
                        outcome.get("error") or "",
                        time.time(),
                    ),
                )

    @_guarded
    def log_error(self, run_id: str, match_id: str | None, kind: str, message: str) -> None:
        """Record a failure that left no result (a crashed or killed worker)."""
        with self.transaction() as c:
            c.execute(
                "INSERT INTO errors (run_id, match_id, kind, message, at) VALUES (?,?,?,?,?)",
                (run_id, match_id, kind, message, time.time()),
            )

    @_guarded
    def rows(self, run_id: str) -> list[dict[str, Any]]:
        """The finished matches of ``run_id`` (in plan order) as flat dicts."""
        cols = ", ".join(
            f"m.{k}"
            if k in ("seq", "match_id", "map", "variant", "pursuer", "evader", "start", "seed")
            else f"s.{k}"
            for k in ROW_FIELDS
        )
        sql = (
            f"SELECT {cols} FROM run_matches m JOIN results s ON s.match_id = m.match_id "
            "WHERE m.run_id = ? ORDER BY m.seq"
        )
        return [dict(r) for r in self.conn.execute(sql, (run_id,))]

    @_guarded
    def doubled(self, run_id: str) -> int:
        """How many starts (map, variant, pairing, start kind, seed) ``run_id`` holds more
        than one match of: a store whose run an older surveil extended with matches it
        identified otherwise (every start then counted twice, until the spec's next
        ``surveil tournament`` sets the old ones aside, :meth:`set_aside`)."""
        sql = (
            "SELECT COUNT(*) FROM (SELECT 1 FROM run_matches WHERE run_id = ? "
            "GROUP BY map, variant, pursuer, evader, start, seed HAVING COUNT(*) > 1)"
        )
        return int(self.conn.execute(sql, (run_id,)).fetchone()[0])

    @_guarded
    def errors(self, run_id: str) -> list[dict[str, Any]]:
        """The failures logged by ``run_id``, oldest first."""
        sql = "SELECT * FROM errors WHERE run_id = ? ORDER BY id"
        return [dict(r) for r in self.conn.execute(sql, (run_id,))]

    @_guarded
    def record_of(self, match_id: str) -> dict[str, Any] | None:
        """The stored episode record of one match (``None`` if not played)."""
        row = self.conn.execute(
            "SELECT record FROM results WHERE match_id = ?", (match_id,)
        ).fetchone()
        return None if row is None or row[0] is None else json.loads(row[0])

    @_guarded
    def identity(self, match_id: str) -> dict[str, Any] | None:
        """The identity document of one match (``None`` if the store has none)."""
        row = self.conn.execute(
            "SELECT identity FROM matches WHERE match_id = ?", (match_id,)
        ).fetchone()
        return None if row is None else json.loads(row[0])

    @_guarded
    def map_geometry(self, digest: str) -> dict[str, Any] | None:
        """The stored geometry (``envs.maps.io.map_to_dict`` form) of a map digest."""
        row = self.conn.execute("SELECT geometry FROM maps WHERE digest = ?", (digest,)).fetchone()
        return None if row is None else json.loads(row[0])

    # ---------------------------------------------------------------- export
    @_guarded
    def export(self, run_id: str, path: str | os.PathLike[str]) -> Path:
        """Write a run's results as CSV (``.csv``) or JSON lines (``.jsonl``/``.ndjson``).

        Raises:
            InvalidConfigError: another suffix.
            OutputError: the file could not be written whole (a full disk); a file
                already at ``path`` is kept as it was.
        """
        path = Path(path)
        suffix = path.suffix.lower()
        if suffix not in (".csv", ".jsonl", ".ndjson"):
            raise InvalidConfigError(
                f"export path {str(path)!r}: expected a .csv, .jsonl or .ndjson file"
            )
        rows = self.rows(run_id)
        path.parent.mkdir(parents=True, exist_ok=True)
        # whole or not at all: a full disk cut a CSV short, and the shorter file still read
        # as a valid export (over a complete one written before)
        with (
            written_whole(path, "export file") as tmp,
            tmp.open("w", encoding="utf-8", newline="") as f,
        ):
            if suffix == ".csv":
                writer = csv.DictWriter(f, fieldnames=list(ROW_FIELDS))
                writer.writeheader()
                writer.writerows(rows)
            else:
                for r in rows:
                    f.write(json.dumps(r, sort_keys=True) + "\n")
        return path
