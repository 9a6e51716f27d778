"""What the benchmark scripts share on the command line: checked values, a clean stop.

* :func:`integer` and :func:`real` (from :mod:`analysis.arguments`) are argparse
  ``type=`` functions with ranges: ``--seeds 0`` or ``--rho nan`` is a usage error naming
  the value and what was expected (exit code 2) before any long work.
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
"""

from __future__ import annotations

import contextlib
import multiprocessing as mp
import os
import signal
import sys
import threading
from collections.abc import Callable, Iterator
from multiprocessing.pool import Pool

from analysis.arguments import integer, path_text, real, user_error

__all__ = ["integer", "path_text", "real", "run", "worker_pool"]

EXIT_CODE = {"SIGINT": 130, "SIGTERM": 143}


def _raise_interrupt(signum: int, frame: object) -> None:
    raise KeyboardInterrupt(signal.Signals(signum).name)


def run(main: Callable[[], int | None]) -> int:
    """``main()``'s exit code; 130 (SIGINT) or 143 (SIGTERM) if stopped, 2 for a user error."""
    signal.signal(signal.SIGTERM, _raise_interrupt)
    prog = os.path.basename(sys.argv[0])
    try:
        return int(main() or 0)
    except KeyboardInterrupt as exc:
        name = str(exc) if str(exc) in EXIT_CODE else "SIGINT"
        print(f"{prog}: stopped by {name}", file=sys.stderr)
        return EXIT_CODE[name]
    except Exception as exc:
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
