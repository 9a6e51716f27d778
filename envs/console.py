"""What every command line of the project shares.

* :func:`reader_gone`: a command's standard output whose reader has left (``surveil maps
  | head -1``); the command stops silently, with exit code 141 (128 + SIGPIPE, as a
  shell reports a command killed by it).
* :class:`CommandParser`: an argument no parser took is refused by the subcommand it was
  given to (``surveil maps extra``, ``python -m training.zoo list extra``), with that
  subcommand's usage.
* :class:`OneLineWarnings`: each distinct warning once, as one line ``PROG: warning: ...``.
* :func:`interrupts_recorded`: a Ctrl-C that CPython discards during imports (in a
  weakref callback) is recorded, to be honoured once the imports are done.

Lives in the bottom layer beside :mod:`envs.pidlock` because the command lines of
:mod:`analysis` (``surveil``), :mod:`training` (``python -m training``, ``python -m
training.zoo``) and the benchmark scripts all use it, and :mod:`training` may not import
:mod:`analysis`.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import signal
import sys
import threading
from collections.abc import Iterator, Sequence

__all__ = [
    "EXIT_READER_GONE",
    "CommandParser",
    "OneLineWarnings",
    "RecordedInterrupt",
    "interrupts_recorded",
    "reader_gone",
]

EXIT_READER_GONE = 141  # 128 + SIGPIPE


def reader_gone() -> bool:
    """Whether stdout's reader has left (``| head``), not some other pipe: its pending
    output cannot be flushed, or (unbuffered) polling its pipe reports an error. Then
    stdout is pointed at the null device, so that the interpreter's own flush at exit
    does not print "Exception ignored ... BrokenPipeError" either."""
    import select

    try:
        sys.stdout.flush()
        poll = select.poll()  # no poll (Windows): only a failed flush tells
        poll.register(sys.stdout.fileno(), select.POLLOUT)
        gone = any(event & select.POLLERR for _, event in poll.poll(0))
    except BrokenPipeError:
        gone = True
    except (AttributeError, OSError, ValueError):  # no poll, no file descriptor
        gone = False
    if gone:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)
    return gone


def progress_flags(parser: argparse.ArgumentParser, help: str) -> None:
    """``--no-progress`` (described by ``help``) and the hidden ``--progress``, accepted for
    the runs that showed progress only when asked (progress is the default now)."""
    parser.add_argument("--no-progress", action="store_true", help=help)
    parser.add_argument("--progress", action="store_true", help=argparse.SUPPRESS)


class CommandParser(argparse.ArgumentParser):
    """``argparse.ArgumentParser`` whose arguments that no parser took are refused by the
    subcommand they were given to (its usage and help), not by the top-level parser."""

    def parse_args(  # type: ignore[override]
        self, args: Sequence[str] | None = None, namespace: argparse.Namespace | None = None
    ) -> argparse.Namespace:
        """argparse's, but arguments no parser took are refused by the subcommand they
        were given to: ``surveil policies extra`` points at ``surveil policies --help``
        (it pointed at ``surveil --help``, whose usage does not show them)."""
        parsed, extras = self.parse_known_args(args, namespace)
        if extras:
            self._chosen(parsed).error(f"unrecognized arguments: {' '.join(extras)}")
        return parsed

    def _chosen(self, parsed: argparse.Namespace) -> argparse.ArgumentParser:
        """The (sub)command parser ``parsed`` was read by: the deepest chosen subparser."""
        parser: argparse.ArgumentParser = self
        while True:
            sub = next(
                (
                    a
                    for a in parser._actions  # argparse keeps its subparsers only here
                    if isinstance(a, argparse._SubParsersAction)
                ),
                None,
            )
            name = None if sub is None else getattr(parsed, sub.dest or "", None)
            if sub is None or name not in sub.choices:
                return parser
            parser = sub.choices[name]


class OneLineWarnings:
    """A ``warnings.showwarning`` that shows each distinct warning once, as one line:
    ``PROG: warning: ...`` (Python's own shows the file, the line number and the source
    line, and repeats a warning whose text it has shown from another place).

    Deprecation warnings (a library's business, not the user's) go to the handler that
    was installed before.
    """

    def __init__(self, previous, prog: str) -> None:
        self.previous = previous
        self.prog = prog
        self.seen: set[str] = set()

    def __call__(self, message, category, filename, lineno, file=None, line=None) -> None:
        if issubclass(category, (DeprecationWarning, PendingDeprecationWarning)):
            self.previous(message, category, filename, lineno, file, line)
            return
        text = str(message)
        if text not in self.seen:
            self.seen.add(text)
            print(f"{self.prog}: warning: {text}", file=sys.stderr if file is None else file)


class RecordedInterrupt:
    """A SIGINT handler that raises ``KeyboardInterrupt`` as Python's own does, and
    records that it did (:attr:`seen`)."""

    def __init__(self) -> None:
        self.seen = False

    def __call__(self, signum: int, frame: object) -> None:
        self.seen = True
        raise KeyboardInterrupt


@contextlib.contextmanager
def interrupts_recorded() -> Iterator[RecordedInterrupt]:
    """Within the block, Ctrl-C raises ``KeyboardInterrupt`` as usual and is recorded too:
    check :attr:`RecordedInterrupt.seen` where the block's work is done. CPython discards
    an exception raised where none can propagate (a weakref callback of importlib's
    module locks, a ``__del__``: "Exception ignored in ...") and goes on: 2 of 20 Ctrl-Cs
    1.5-4 s after ``surveil tournament`` started, in its parser's imports under load, were
    lost so and the run played on. A SIGINT that Python does not turn into
    ``KeyboardInterrupt`` (ignored in a background job, or a handler of the caller's)
    is left as it is, as off the main thread."""
    record = RecordedInterrupt()
    if (
        threading.current_thread() is not threading.main_thread()
        or signal.getsignal(signal.SIGINT) is not signal.default_int_handler
    ):
        yield record
        return
    previous = signal.signal(signal.SIGINT, record)
    try:
        yield record
    finally:
        signal.signal(signal.SIGINT, previous)
