"""A command's standard output whose reader has left (``surveil maps | head -1``).

Lives in the bottom layer beside :mod:`envs.pidlock` because the command lines of
:mod:`analysis` (``surveil``), :mod:`training` (``python -m training``, ``python -m
training.zoo``) and the benchmark scripts all stop the same way when it happens: silently,
with exit code 141 (128 + SIGPIPE, as a shell reports a command killed by it).
"""

from __future__ import annotations

import os
import sys

__all__ = ["EXIT_READER_GONE", "reader_gone"]

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
