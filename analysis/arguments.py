"""Checked command-line arguments, shared by every ``surveil`` subcommand.

Every user error becomes one line, ``surveil: error: WHAT = VALUE: expected ...``, exit
code 2, no traceback, and is found before any long work starts:

* :class:`Parser` is an ``argparse.ArgumentParser`` whose errors are that one line (no
  usage dump); subparsers inherit it. An argument no command takes is refused by the
  command it was given to (:class:`CommandParser`, also for the benchmark scripts).
* :func:`integer` and :func:`real` are argparse ``type=`` functions with ranges.
* :func:`json_object` parses a JSON option (``--config``, ``--params``) and says which
  flag failed and where its JSON breaks.
* :func:`output_file` and :func:`output_dir` check an output path (not a directory where
  a file is meant, a known suffix, a parent that can be created and written) before the
  run whose result it will hold.
* :func:`why_not_a_file` says what a path that should be a regular file is instead
  (missing, a directory, a device such as ``/dev/null``, a broken link).
* :func:`user_error` tells a project error or a file error (reported as one line) from
  a bug (which keeps its traceback).
* :func:`warnings_held` and :func:`say_warnings` hold the warnings of a legal input (an
  env config no pursuer can be sure to win) until every check has passed: a refused run
  says its error alone.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import re
import signal
import stat
import tempfile
import threading
import warnings
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import Any, NoReturn

from envs.console import CommandParser, RecordedInterrupt, interrupts_recorded, reader_gone
from envs.errors import InvalidConfigError, MemoryBudgetError, SurveilValueError
from envs.validation import DuplicateKeyError, json_pairs_once

__all__ = [
    "CommandParser",
    "Parser",
    "RecordedInterrupt",
    "integer",
    "interrupts_recorded",
    "json_object",
    "output_dir",
    "output_file",
    "path_text",
    "reader_gone",
    "real",
    "say_warnings",
    "sigterm_as_interrupt",
    "user_error",
    "warnings_held",
    "why_not_a_file",
]

PROG = "surveil"


class Parser(CommandParser):
    """``argparse.ArgumentParser`` whose errors are one line: ``surveil: error: ...``."""

    def error(self, message: str) -> NoReturn:
        """Print ``surveil: error: MESSAGE`` (flag and value first) and exit with code 2."""
        m = re.fullmatch(r"argument (\S+?)(?:/\S+)?: ('.*?'): (.*)", message, flags=re.S)
        if m:  # a type= check: "--seed = '-1': expected an integer >= 0"
            message = f"{m[1]} = {m[2]}: {m[3]}"
        else:
            message = re.sub(r"^argument (\S+?)(?:/\S+)?: ", r"\1: ", message)
        self.exit(2, f"{PROG}: error: {message} (see '{self.prog} --help')\n")


MAP_HELP = (
    "a built-in name (surveil maps), a map file (.json, .geojson or .wkt: see "
    "envs/maps/io.py) or a seeded random map, random:SEED or random:KIND:SEED; any of "
    "these + ~[xS][rotR][off(X,Y)] is it scaled by S, rotated R rad, shifted (e.g. "
    "corner~x10rot1.1)"
)
"""What a map argument takes (every command reads it with :func:`envs.maps.load_map`)."""


def integer(minimum: int, maximum: int | None = None) -> Callable[[str], int]:
    """An argparse ``type=``: an integer in [minimum, maximum]."""
    expected = (
        f"an integer >= {minimum}" if maximum is None else f"an integer in [{minimum}, {maximum}]"
    )

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r}: expected {expected}") from None
        if value < minimum or (maximum is not None and value > maximum):
            raise argparse.ArgumentTypeError(f"{text!r}: expected {expected}")
        return value

    parse.__name__ = "integer"
    return parse


def real(minimum: float, *, strict: bool = True) -> Callable[[str], float]:
    """An argparse ``type=``: a finite number > ``minimum`` (``strict``) or >= it."""
    expected = f"a finite number {'>' if strict else '>='} {minimum:g}"

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r}: expected {expected}") from None
        ok = value > minimum if strict else value >= minimum
        if not (ok and value < float("inf")):
            raise argparse.ArgumentTypeError(f"{text!r}: expected {expected}")
        return value

    parse.__name__ = "real"
    return parse


def path_text(what: str) -> Callable[[str], str]:
    """An argparse ``type=``: a file or directory name, not empty or blank (an empty one
    was taken as the flag's absence wherever the code tested its truth: ``--out ''`` drew
    nothing, or to the default path, and exited 0)."""

    def parse(text: str) -> str:
        if not text.strip():
            raise argparse.ArgumentTypeError(f"{text!r}: expected {what}")
        return text

    parse.__name__ = "path"
    return parse


_SPECIAL_FILES = (
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISFIFO, "a named pipe"),
    (stat.S_ISSOCK, "a socket"),
)


def why_not_a_file(path: str | os.PathLike[str]) -> str | None:
    """None when ``path`` is a regular file (or a link to one), else what it is instead,
    as the end of a message: ``"no such file"``, ``"is a directory, not a file"``, ``"is
    a character device, not a regular file"`` (``/dev/null`` was "no such file").

    Examples:
        >>> why_not_a_file("/dev/null")
        'is a character device, not a regular file'
        >>> why_not_a_file("/")
        'is a directory, not a file'
    """
    p = Path(path)
    try:
        mode = p.stat().st_mode
    except FileNotFoundError:
        return "is a broken symbolic link" if p.is_symlink() else "no such file"
    except OSError as exc:
        return f"cannot be read ({exc.strerror or exc})"
    if stat.S_ISREG(mode):
        return None
    if stat.S_ISDIR(mode):
        return "is a directory, not a file"
    kind = next((name for test, name in _SPECIAL_FILES if test(mode)), "a special file")
    return f"is {kind}, not a regular file"


def json_object(flag: str, text: str | None, *, example: str) -> dict[str, Any]:
    """The JSON object given to ``flag`` (``{}`` when the flag is absent).

    Raises:
        InvalidConfigError: not JSON (naming the flag and where the JSON breaks), JSON
            that is not an object, or a key given twice in an object.
    """
    if text is None:
        return {}
    try:
        obj = json.loads(text, object_pairs_hook=json_pairs_once)
    except DuplicateKeyError as dup:
        raise InvalidConfigError(
            f"{flag} = {text!r}: key {dup.key!r} given twice (JSON keeps only the last); "
            f"expected each key once, as in {example}"
        ) from None
    except json.JSONDecodeError as exc:
        near = text[max(0, exc.pos - 10) : exc.pos + 10]
        raise InvalidConfigError(
            f"{flag} = {text!r}: not valid JSON: {exc.msg} at column {exc.colno} "
            f"(near {near!r}); expected an object such as {example}"
        ) from None
    except RecursionError:  # the decoder recurses once per nested [ or {
        raise InvalidConfigError(
            f"{flag} = {text[:40]!r}...: JSON nested too deeply to read; expected an object "
            f"such as {example}"
        ) from None
    if not isinstance(obj, dict):
        raise InvalidConfigError(
            f"{flag} = {text!r}: expected a JSON object such as {example}, "
            f"got a JSON {_json_kind(obj)}"
        )
    return obj


def check_env_options(overrides: dict[str, Any], where: str) -> None:
    """Refuse env overrides (``--config``) that name no env parameter, listing them.

    Raises:
        InvalidConfigError: ``"WHERE: unknown env option(s) ['bogus']; options are ..."``.
    """
    from envs.surveillance.config import env_parameters

    allowed = [k for k in env_parameters() if k not in ("map", "render_mode")]
    unknown = sorted(set(overrides) - set(allowed))
    if unknown:
        raise InvalidConfigError(
            f"{where}: unknown env option(s) {unknown}; options are {', '.join(allowed)}"
        )


def _json_kind(obj: Any) -> str:
    names = {list: "array", str: "string", bool: "boolean", int: "number", float: "number"}
    return "null" if obj is None else names.get(type(obj), type(obj).__name__)


def output_file(
    flag: str, value: str | os.PathLike[str], *, suffixes: Sequence[str], default_name: str
) -> Path:
    """The file an option names, checked before the run that will fill it.

    A directory (existing, or written with a trailing slash) means ``DIR/default_name``.
    The parent directory is created if needed and must accept a new file.

    Raises:
        InvalidConfigError: a suffix not in ``suffixes``, or a parent that cannot be
            created or written (naming the flag, the path and the reason).
    """
    text = os.fspath(value)
    path = Path(text)
    if path.is_dir() or text.endswith(("/", os.sep)):
        path = path / default_name
    if path.suffix.lower() not in suffixes:
        listed = (
            " or ".join(suffixes)
            if len(suffixes) < 3
            else (f"{', '.join(suffixes[:-1])} or {suffixes[-1]}")
        )
        hint = ""
        if not path.suffix:  # 'replays', meant as a directory that does not exist yet
            hint = f", or a directory: an existing one, or {text.rstrip('/') + '/'!r} to create it"
        raise InvalidConfigError(f"{flag} = {text!r}: expected a file ending in {listed}{hint}")
    _writable_dir(flag, text, path.parent)
    return path


def output_dir(flag: str, value: str | os.PathLike[str]) -> Path:
    """A directory an option names, created if needed and checked for writing.

    Raises:
        InvalidConfigError: an empty name, an existing file, or a directory that cannot be
            created or written.
    """
    text = os.fspath(value)
    if not text.strip():  # Path("") is "." (the figures landed in the working directory)
        raise InvalidConfigError(
            f"{flag} = {text!r}: expected a directory name ('.' for the current directory)"
        )
    path = Path(text)
    if path.exists() and not path.is_dir():
        raise InvalidConfigError(f"{flag} = {text!r}: is a file, expected a directory")
    _writable_dir(flag, text, path)
    return path


def _writable_dir(flag: str, text: str, directory: Path) -> None:
    try:
        directory.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=directory):
            pass  # a file can be created there (os.access lies to root and on some mounts)
    except (FileExistsError, NotADirectoryError):
        blocker = next((p for p in (directory, *directory.parents) if p.is_file()), directory)
        raise InvalidConfigError(
            f"{flag} = {text!r}: cannot write in {str(directory)!r}: {str(blocker)!r} is a "
            "file, not a directory"
        ) from None
    except OSError as exc:
        reason = exc.strerror or type(exc).__name__
        raise InvalidConfigError(
            f"{flag} = {text!r}: cannot write in {str(directory) or '.'!r} ({reason})"
        ) from None


def user_error(exc: BaseException) -> str | None:
    """The one-line message for an error a user caused, or ``None`` for a bug.

    User errors are the project's (:class:`~envs.errors.SurveilValueError`), file errors
    (``OSError``: missing, unreadable, unwritable) and a policy failure caused by one of
    those (a model fed the wrong observation). Anything else is a bug and keeps its
    traceback.
    """
    if isinstance(exc, MemoryBudgetError):  # a command line has no memory_budget= argument
        return str(exc.named(budget=MemoryBudgetError.ENV_BUDGET))
    if isinstance(exc, SurveilValueError):
        return str(exc)
    if isinstance(exc, OSError):
        if exc.filename is not None and exc.strerror:
            return f"{exc.filename}: {exc.strerror}"
        return str(exc) or type(exc).__name__
    from strategies.runner import PolicyFailure

    cause = exc.__cause__
    if isinstance(exc, PolicyFailure) and cause is not None and user_error(cause) is not None:
        return str(exc)
    return None


@contextlib.contextmanager
def warnings_held() -> Iterator[list[warnings.WarningMessage]]:
    """Record the warnings the block raises instead of saying them; :func:`say_warnings`
    says them once the command's checks have all passed. A warning about a legal input
    (``NarrowBandWarning``, ``RhoAboveOneWarning``) said before a refusal of the same run
    read as one more problem to fix, and came before the error line that scripts and
    tests read first. The user's filters apply as ever (an ignored warning is not held)."""
    with warnings.catch_warnings(record=True) as held:
        yield held


def say_warnings(held: Sequence[warnings.WarningMessage]) -> None:
    """Say the warnings :func:`warnings_held` recorded, each from where it was raised."""
    for w in held:
        warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)


def set_from_flag(config: dict[str, Any], key: str, flag: str, value: Any) -> None:
    """``config[key] = value`` for a flag given beside ``--config``; a ``--config`` that
    sets ``key`` to something else is refused (which one the user meant is unknown).

    Raises:
        InvalidConfigError: both set ``key``, to different values (naming both).
    """
    if value is None:
        return
    if key in config and config[key] != value:
        raise InvalidConfigError(
            f"{flag} {value!r} and --config {key} = {config[key]!r}: give {key} once"
        )
    config[key] = value


def _raise_sigterm(signum: int, frame: object) -> None:
    raise KeyboardInterrupt("SIGTERM")


@contextlib.contextmanager
def sigterm_as_interrupt() -> Iterator[None]:
    """Within the block, SIGTERM (``kill``, ``timeout``) raises ``KeyboardInterrupt("SIGTERM")``
    in the main thread, so a command stops as on Ctrl-C: its cleanup runs (a replay's
    temporary file removed, a training run's resume note printed). It was the default
    action: ``surveil play`` killed so left ``.NAME.gif.PID.tmp`` beside its output. The
    previous handler is restored on leaving (tournaments install their own inside)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGTERM, _raise_sigterm)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)
