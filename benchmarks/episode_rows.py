"""Episode rows kept as they complete (JSON lines), and read back to resume a run.

The format of ``unseen_worlds.py --results`` (also ``pursuer_holds.py`` and
``evader_escapes.py``): one JSON object per line, one line per episode, appended and
flushed as each episode completes, so a stop (Ctrl-C, ``timeout``, a crash) loses at most
the episodes in flight. A rerun with the same file skips the episodes whose key is already
in it and reports over all of them. A last line cut short by a hard kill (no newline after
it: every row is written with its newline) is dropped (that episode is played again) and
never glued to the next row; any other line that is not a row of this script (not JSON, or
a row of another script, without the fields of its key) is refused before anything is
played or appended.

One run appends to a results file at a time: :func:`appending` holds an exclusive
``flock`` on it for the whole run (the kernel releases it however the run ends), and a
second run on the same file is refused as it starts to append, before it plays anything,
naming the holder where the system says (:class:`ResultsBusyError`); two runs' rows
interleaved, and each truncated the other's row in flight as a row cut short by a kill.
Reading needs no lock (a report may read a file in use).

Each row records the code that played it (``"code"``: the commit, and a digest of the
uncommitted changes to the package's sources when there are any; :func:`code_version`).
A rerun reuses rows whatever code played them, since an episode's key does not name the
code; :func:`read` says how many of the rows it found were played by other code, so a
changed policy is not measured by yesterday's rows unnoticed (a new ``--results`` file
plays them with this code).
"""

from __future__ import annotations

import contextlib
import fcntl
import functools
import hashlib
import json
import os
import subprocess
import sys
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager
from typing import IO, Any

from envs.errors import InvalidConfigError

__all__ = ["ResultsBusyError", "appending", "code_version", "key", "read"]

SOURCES = ("envs", "strategies", "analysis", "training", "benchmarks")
"""The folders whose code plays an episode (their uncommitted changes count too)."""


class ResultsBusyError(InvalidConfigError):
    """Another run is appending to the results file (it holds the file's lock)."""


def _lock(f: IO, path: str | os.PathLike) -> None:
    """``flock`` the open file ``f`` exclusively, without waiting.

    Raises:
        ResultsBusyError: another run holds the lock, naming the file and, where
            ``/proc/locks`` says, its holder.
    """
    try:
        fcntl.flock(f.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        holder = _holder(f.fileno())
        raise ResultsBusyError(
            f"{os.fspath(path)}: another run{f' ({holder})' if holder else ''} is appending "
            "to this results file; wait for it to finish, or give this run another --results "
            "file (two runs on one file interleave their rows)"
        ) from None


def _holder(fd: int) -> str | None:
    """``pid N`` of the process holding a ``flock`` on ``fd``'s file, from ``/proc/locks``
    (Linux), or None."""
    st = os.fstat(fd)
    device = f"{os.major(st.st_dev):02x}:{os.minor(st.st_dev):02x}:{st.st_ino}"
    with contextlib.suppress(OSError):
        with open("/proc/locks") as f:
            for line in f:
                fields = line.split()  # "1: FLOCK ADVISORY WRITE 4242 08:01:1234 0 EOF"
                if len(fields) >= 6 and fields[1] == "FLOCK" and fields[5] == device:
                    if fields[4] != str(os.getpid()):
                        return f"pid {fields[4]}"
    return None


SCRIPTS_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
"""The checkout these scripts are in."""


def playing_root() -> str:
    """The checkout whose policies play: where Python imports the package from. Not the
    scripts' own when another checkout is installed in editable mode and this one is not
    on the import path (``python benchmarks/X.py`` puts ``benchmarks/`` there, not the root;
    ``PYTHONPATH=ROOT`` does)."""
    import strategies

    return os.path.dirname(os.path.dirname(os.path.abspath(strategies.__file__)))


def _git(*args: str, root: str = SCRIPTS_ROOT) -> str | None:
    try:
        out = subprocess.run(["git", *args], cwd=root, capture_output=True, text=True, timeout=20)
    except (OSError, subprocess.SubprocessError):
        return None
    return out.stdout if out.returncode == 0 else None


def _version(root: str) -> str | None:
    sha = _git("rev-parse", "HEAD", root=root)
    if not sha:
        return None
    diff = _git("diff", "HEAD", "--", *SOURCES, root=root) or ""
    untracked = (
        _git("ls-files", "--others", "--exclude-standard", "--", *SOURCES, root=root) or ""
    ).split()
    if not diff and not untracked:
        return sha.strip()[:12]
    h = hashlib.sha256(diff.encode())
    for name in sorted(untracked):
        h.update(name.encode())
        with open(os.path.join(root, name), "rb") as f:
            h.update(f.read())
    return f"{sha.strip()[:12]}+{h.hexdigest()[:8]}"


@functools.cache
def code_version() -> str | None:
    """``SHA`` of HEAD (12 digits), ``SHA+DIGEST`` when :data:`SOURCES` differ from it
    (DIGEST: 8 hex digits of the diff and of the untracked files' names and contents),
    ``None`` outside a git checkout: the version of the checkout whose policies play
    (:func:`playing_root`). When that is not the scripts' own checkout, the rows say so,
    ``VERSION (scripts: VERSION)``, and a note on stderr tells how to play the scripts'
    own code: the rows would otherwise name a commit that did not play them."""
    playing = os.path.realpath(playing_root())
    version = _version(playing)
    if playing == os.path.realpath(SCRIPTS_ROOT):
        return version
    scripts = _version(SCRIPTS_ROOT)
    print(
        f"note: these benchmark scripts are in {SCRIPTS_ROOT} but the policies that play are "
        f"imported from {playing} (an editable install of that checkout); rows record "
        f"{version} (scripts: {scripts}). To play this checkout's code: "
        f"PYTHONPATH={SCRIPTS_ROOT} python ...",
        file=sys.stderr,
    )
    return f"{version} (scripts: {scripts})"


def key(values: Iterable[Any]) -> str:
    """A job's identity as text: the JSON list of its values."""
    return json.dumps(list(values))


def read(
    path: str | os.PathLike, key_of: Callable[[dict], str], *, note_other_code: bool = True
) -> dict[str, dict]:
    """The rows already in ``path`` by ``key_of(row)``; empty when there is no file.
    ``note_other_code=False`` leaves out the note on rows played by other code (a reader
    that compares code versions itself, ``policy_sets.py``).

    Reading takes no lock: a report may read a file another run is appending to (its
    row in flight, cut short, is dropped as above).

    Raises:
        InvalidConfigError: a line is not a JSON object (the file is not such a results
            file), the last one included unless it was cut short (no newline after it), or
            a row lacks a field of ``key_of`` (a results file of another script); the
            message names the file and the line.
    """
    rows: dict[str, dict] = {}
    if not os.path.exists(path):
        return rows
    with open(path) as f:
        text = f.read()
    lines = text.split("\n")  # a row cut short is the last item (text ends without "\n")
    expected = "expected a results file of JSON lines (one episode a line) of this script"
    for i, line in enumerate(lines):
        if not line.strip():
            continue
        try:
            row = json.loads(line)
        except json.JSONDecodeError:
            row = None
        if not isinstance(row, dict):
            if i == len(lines) - 1:  # cut short by a hard kill: play that episode again
                break
            raise InvalidConfigError(
                f"{os.fspath(path)}, line {i + 1}: {line[:60]!r} is not a JSON object; " + expected
            )
        try:
            rows[key_of(row)] = row
        except KeyError as exc:
            raise InvalidConfigError(
                f"{os.fspath(path)}, line {i + 1}: the row has no field {exc}; {expected}"
            ) from None
    if not note_other_code:  # nor code_version(): its note on whose code plays is for players
        return rows
    other = [r.get("code") for r in rows.values() if r.get("code") != code_version()]
    if other and code_version() is not None:
        seen = sorted({str(c) for c in other if c}) + ["not recorded"] * (None in other)
        print(f"note: {len(other)} of the {len(rows)} rows in {os.fspath(path)} were played by "
              f"other code ({', '.join(seen[:3])}{', ...' if len(seen) > 3 else ''}; this is "
              f"{code_version()}) and are reused as they are; a new --results file plays them "
              "with this code", flush=True)  # fmt: skip
    return rows


@contextmanager
def appending(path: str | os.PathLike) -> Iterator[Callable[[dict], None]]:
    """``write(row)``: append one row to ``path`` and flush it, holding the file's
    exclusive lock until the block ends. The directory is made, and a last line cut short
    by a hard kill (no newline after it) is removed first: it is no row (:func:`read`
    drops it), and the next row must start a line of its own.

    Raises:
        ResultsBusyError: another run is appending to ``path``; nothing is changed.
    """
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    with open(path, "a") as f:
        _lock(f, path)  # before the truncation: another run's row in flight
        with open(path, "rb+") as g:
            data = g.read()
            end = data.rfind(b"\n") + 1
            if end < len(data):
                g.truncate(end)

        def write(row: dict) -> None:
            _write(f, row if "code" in row else {**row, "code": code_version()})

        yield write


def _write(f: IO[str], row: dict) -> None:
    f.write(json.dumps(row) + "\n")
    f.flush()
