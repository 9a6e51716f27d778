"""What the benchmark scripts share on the command line: checked values, a clean stop.

* :func:`integer` and :func:`real` (from :mod:`analysis.arguments`) are argparse
  ``type=`` functions with ranges: ``--seeds 0`` or ``--rho nan`` is a usage error naming
  the value and what was expected (exit code 2) before any long work.
* :class:`ArgumentParser` reads ``@FILE`` arguments (one argument a line) and refuses
  one whose file cannot be read by naming it: ``--worlds @nosuch.txt`` was argparse's
  bare ``error: [Errno 2] No such file or directory: 'nosuch.txt'``.
* :func:`run` calls a script's ``main`` and turns SIGINT (Ctrl-C) and SIGTERM (``timeout``,
  ``kill``) into one line on stderr and exit code 130 / 143, no traceback. What a script
  wrote before the signal is kept (results files are appended and flushed row by row; rerun
  the same command to resume where a script resumes). A user error found later than
  argparse can (an unknown map or zoo model named by a flag: the project's
  ``SurveilValueError``, or a file error) is one line and exit code 2, as in the ``surveil``
  CLI (:func:`analysis.arguments.user_error`); a bug keeps its traceback.
* :func:`worker_pool` is a ``multiprocessing`` pool whose workers ignore SIGINT (Ctrl-C
  reaches the whole process group; only the parent answers it) from their first
  instruction (a Ctrl-C while they are still importing is no traceback either), closed
  when its ``with`` block ends and terminated when a stop leaves it.
* :func:`play_rows` plays a script's episodes (in this process, or on such a pool), hands
  each row to the results file as it completes and prints the progress.
"""

from __future__ import annotations

import argparse
import contextlib
import multiprocessing as mp
import os
import signal
import sys
import threading
import time
from collections.abc import Callable, Iterator, Sequence
from multiprocessing.pool import Pool
from typing import Any

import episode_rows

from analysis.arguments import (
    integer,
    path_text,
    reader_gone,
    real,
    user_error,
    why_not_a_file,
)

__all__ = [
    "ArgumentParser",
    "integer",
    "path_text",
    "play_rows",
    "real",
    "results_file",
    "run",
    "worker_pool",
]

EXIT_CODE = {"SIGINT": 130, "SIGTERM": 143}


class ArgumentParser(argparse.ArgumentParser):
    """``argparse.ArgumentParser`` that takes ``@FILE`` for the arguments in FILE, one a
    line, and refuses an ``@FILE`` it cannot read as a usage error
    naming it, also one named inside another such file."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        kwargs.setdefault("fromfile_prefix_chars", "@")
        super().__init__(*args, **kwargs)

    def parse_known_args(
        self, args: Sequence[str] | None = None, namespace: argparse.Namespace | None = None
    ) -> tuple[argparse.Namespace, list[str]]:
        """argparse's, once every ``@FILE`` named (directly or in such a file) is readable."""
        self._check_argument_files(sys.argv[1:] if args is None else args, "", set())
        return super().parse_known_args(args, namespace)

    def _check_argument_files(self, args: Sequence[str], named_in: str, seen: set[str]) -> None:
        prefix = self.fromfile_prefix_chars or ""
        for arg in args:
            if not (isinstance(arg, str) and arg[:1] and arg[0] in prefix):
                continue
            name = arg[1:]
            why = why_not_a_file(name) if name else "names no file"
            if why is not None and (not name or not os.path.exists(name) or os.path.isdir(name)):
                where = "" if os.path.isabs(name) else f" (in {os.getcwd()})"
                self.error(
                    f"{arg}{named_in}: {why}{where}; {arg[0]}FILE reads arguments from FILE, "
                    "one a line"
                )
            key = os.path.realpath(name)
            if why is not None or key in seen:
                continue  # a device or a pipe (@/dev/stdin, @<(...)): argparse reads it once
            seen.add(key)
            try:
                with open(name, encoding="utf-8") as f:
                    lines = f.read().splitlines()
            except (OSError, UnicodeDecodeError) as exc:
                self.error(f"{arg}{named_in}: cannot be read ({exc})")
            inner = [a for line in lines for a in self.convert_arg_line_to_args(line)]
            self._check_argument_files(inner, f" (named in {arg})", seen)


def results_file(text: str) -> str:
    """An argparse ``type=`` for ``--results FILE`` (JSON lines, :mod:`episode_rows`): a
    file name, not a directory and not under a file, refused before any work (a directory
    was the bare "error: /tmp: Is a directory" once the run had started, and a file where
    a folder should be "error: /etc/passwd: File exists")."""
    text = path_text("a file")(text)
    if os.path.isdir(text):
        raise argparse.ArgumentTypeError(f"{text!r}: is a directory, expected a file")
    parent = os.path.dirname(os.path.abspath(text))
    while not os.path.exists(parent):
        parent = os.path.dirname(parent)
    if not os.path.isdir(parent):
        raise argparse.ArgumentTypeError(
            f"{text!r}: cannot be created: {parent!r} is a file, not a directory"
        )
    return text


def _raise_interrupt(signum: int, frame: object) -> None:
    raise KeyboardInterrupt(signal.Signals(signum).name)


def run(main: Callable[[], int | None]) -> int:
    """``main()``'s exit code; 130 (SIGINT) or 143 (SIGTERM) if stopped, 2 for a user error,
    141 (128 + SIGPIPE, silently) when the reader of its output left (``| head``)."""
    signal.signal(signal.SIGTERM, _raise_interrupt)
    prog = os.path.basename(sys.argv[0])
    try:
        code = int(main() or 0)
        if sys.stdout is not None:  # a reader gone (`| head`) is met here, not at exit
            sys.stdout.flush()
        return code
    except KeyboardInterrupt as exc:
        name = str(exc) if str(exc) in EXIT_CODE else "SIGINT"
        print(f"{prog}: stopped by {name}", file=sys.stderr)
        return EXIT_CODE[name]
    except Exception as exc:
        if isinstance(exc, BrokenPipeError) and reader_gone():
            return 141
        message = user_error(exc)
        if message is None:
            raise  # a bug: keep the traceback
        print(f"{prog}: error: {message}", file=sys.stderr)
        return 2


def _start_worker(initializer: Callable[..., object] | None, initargs: tuple) -> None:
    """A pool worker's start: tqdm's lock for this process is a thread lock, not its
    default ``multiprocessing`` one (a named semaphore that a terminated worker leaves
    behind: "resource_tracker: There appear to be 2 leaked semaphore objects" after a stop,
    once the workers had built a table behind a progress bar), then ``initializer``."""
    from tqdm import tqdm

    tqdm.set_lock(threading.RLock())
    if initializer is not None:
        initializer(*initargs)


@contextlib.contextmanager
def worker_pool(
    processes: int, initializer: Callable[..., object] | None = None, initargs: tuple = ()
) -> Iterator[Pool]:
    """A ``spawn`` pool of ``processes`` workers that leave Ctrl-C to the parent.

    The workers are started with SIGINT ignored (an ignored signal stays ignored across
    ``exec``, and Python then installs no KeyboardInterrupt handler), so a Ctrl-C at any
    moment, their start-up included, prints no worker traceback. Leaving the block closes
    the pool and waits for its workers; leaving it by an exception (a stop included), or a
    stop during that wait, terminates them first. The workers' progress bars lock within
    each worker (:func:`_start_worker`), so a terminated worker leaks no semaphore.
    """
    from analysis.tournament.executors import warn_if_oversubscribed

    warn_if_oversubscribed(processes, stacklevel=2)  # --workers 1000: said, then played
    old = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        pool = mp.get_context("spawn").Pool(processes, _start_worker, (initializer, initargs))
    finally:
        signal.signal(signal.SIGINT, old)
    try:
        yield pool
    except BaseException:
        pool.terminate()
        raise
    else:
        pool.close()
    finally:
        try:
            pool.join()
        except BaseException:  # a stop while the closed pool finishes its last jobs
            pool.terminate()
            pool.join()
            raise


def play_rows(
    todo: Sequence,
    play: Callable[[Any], dict],
    results: str | os.PathLike,
    done: dict,
    row_key: Callable[[dict], str],
    won: Callable[[dict], bool],
    workers: int,
    initializer: Callable[..., object] | None = None,
    initargs: tuple = (),
) -> None:
    """Play the jobs ``todo`` with ``play``, appending each row to ``results`` as it
    completes and keeping it in ``done`` under ``row_key(row)``.

    One worker plays in this process; more play on a :func:`worker_pool` (``initializer``
    runs in each worker), in completion order. Every 25 rows and at the end, one line:
    rows played, how many ``won`` says were lost, seconds since the start. A stop leaves
    the rows written so far (and terminates the pool).
    """
    t0 = time.perf_counter()
    with episode_rows.appending(results) as write, contextlib.ExitStack() as stack:
        if min(workers, len(todo)) > 1:  # no more workers than jobs (a resumed run: none)
            pool = stack.enter_context(worker_pool(min(workers, len(todo)), initializer, initargs))
            rows = pool.imap_unordered(play, todo)
        else:
            rows = map(play, todo)
        lost = 0
        for i, row in enumerate(rows, 1):
            write(row)
            done[row_key(row)] = row
            lost += not won(row)
            if i % 25 == 0 or i == len(todo):
                print(f"  {i}/{len(todo)} played, {lost} lost, {time.perf_counter() - t0:.0f} s",
                      flush=True)  # fmt: skip
