"""Single-writer lock files that name their holder.

A long run that writes into a place (a tournament store, a training ``output_dir``) holds an
exclusive POSIX record lock (``lockf``) on a lock file there and writes who holds it into
that file; a second run is refused with that text. The kernel releases the lock however the
holder dies, and forked workers do not inherit it. Callers word the refusal: this module
only takes and releases the lock.

Lives in the bottom layer beside :mod:`envs.errors` and :mod:`envs.validation` because
:mod:`training` and :mod:`analysis` both use it.

Examples:
    >>> import tempfile, pathlib
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "run.lock"
    >>> f = acquire(path)
    >>> path.read_text().startswith("pid ")
    True
    >>> acquire(path)
    Traceback (most recent call last):
    ...
    envs.pidlock.LockHeldError: pid ...
    >>> release(f)
    >>> path.read_text()
    ''
"""

from __future__ import annotations

import contextlib
import os
import socket
import time
from pathlib import Path
from typing import TextIO

__all__ = ["LockHeldError", "acquire", "release"]

# Record locks belong to a process: it would take its own lock again. The lock files this
# process holds (resolved paths) play that part within it.
_HELD: dict[int, str] = {}


class LockHeldError(OSError):
    """The lock is held by another process (or another holder in this one).

    Attributes:
        holder: the text the holder wrote (``pid N on HOST since TIME``), or
            ``"another process"`` when it wrote nothing yet.
    """

    def __init__(self, holder: str) -> None:
        super().__init__(holder)
        self.holder = holder


def acquire(lock_path: Path | str) -> TextIO:
    """Take the exclusive lock on ``lock_path`` (created if missing) without waiting.

    Returns:
        The open lock file: keep it and pass it to :func:`release`.

    Raises:
        LockHeldError: another process, or another holder in this one, holds it (its
            ``holder`` names who).
    """
    import fcntl

    key = str(Path(lock_path).resolve())
    f = open(lock_path, "a+", encoding="utf-8")
    try:
        if key in _HELD.values():
            raise BlockingIOError
        fcntl.lockf(f.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        f.seek(0)
        holder = f.read().strip() or "another process"
        f.close()
        raise LockHeldError(holder) from None
    f.seek(0)
    f.truncate()
    f.write(
        f"pid {os.getpid()} on {socket.gethostname()} since {time.strftime('%Y-%m-%d %H:%M:%S')}"
    )
    f.flush()
    _HELD[id(f)] = key
    return f


def release(f: TextIO) -> None:
    """Empty the lock file, release the lock and close the file (errors ignored: the
    kernel releases the lock on close anyway)."""
    import fcntl

    with contextlib.suppress(OSError, ValueError):
        f.truncate(0)
        f.flush()
        fcntl.lockf(f.fileno(), fcntl.LOCK_UN)
    f.close()
    _HELD.pop(id(f), None)
