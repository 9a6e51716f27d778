"""Files written whole or not at all.

:func:`written_whole` yields a temporary path beside the file to write and moves it into
place (``os.replace``, atomic on one file system) only once the writing succeeded. A
write that fails part way (a full disk, a quota, a file-size limit) or is interrupted
(Ctrl-C) leaves the file as it was, and no temporary file behind; the failure is an
:class:`~envs.errors.OutputError` naming the file. Without it an export cut short by a full
disk replaced a complete CSV by a shorter one that still read as valid, and the error
named no file ("[Errno 28] No space left on device").

Lives in the bottom layer beside :mod:`envs.errors` because the map files, the pictures of
:mod:`strategies` and the exports and replays of :mod:`analysis` all use it.

Examples:
    >>> import tempfile, pathlib
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "rows.csv"
    >>> with written_whole(path) as tmp:
    ...     _ = tmp.write_text("a,b\\n")
    >>> path.read_text(), sorted(p.name for p in path.parent.iterdir())
    ('a,b\\n', ['rows.csv'])
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterator
from pathlib import Path

from envs.errors import OutputError

__all__ = ["output_error", "temporary_beside", "written_whole"]


def temporary_beside(path: Path) -> Path:
    """A temporary name in ``path``'s folder (same file system, so the final rename is
    atomic), hidden, unique to this process and ending in ``path``'s suffix (writers such
    as matplotlib's ``savefig`` read the format from it)."""
    return path.with_name(f".{path.stem}.{os.getpid()}.tmp{path.suffix}")


def output_error(name: str, path: str | os.PathLike[str], exc: OSError) -> OutputError:
    """The :class:`OutputError` for a write of ``path`` that failed with ``exc``;
    ``name`` is what the user called the file (a flag such as ``--out``)."""
    reason = exc.strerror or str(exc) or type(exc).__name__
    return OutputError(
        f"{name} = {os.fspath(path)!r}: could not write it ({reason}); nothing was written "
        "there (a file already there is kept as it was); expected a place with room for it"
    )


@contextlib.contextmanager
def written_whole(path: str | os.PathLike[str], name: str = "file") -> Iterator[Path]:
    """Yield a temporary path to write instead of ``path``; move it over ``path`` when
    the block ends without an error, else remove it.

    Args:
        path: the file to write.
        name: what the user called it, for the error message (``"--out"``).

    Raises:
        OutputError: the writing or the move failed with an ``OSError`` (its reason named).
    """
    path = Path(path)
    tmp = temporary_beside(path)
    try:
        yield tmp
        os.replace(tmp, path)
    except OSError as exc:
        raise output_error(name, path, exc) from exc
    finally:
        tmp.unlink(missing_ok=True)
