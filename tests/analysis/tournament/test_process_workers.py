"""Process workers never run the driver's signal handlers, however early a signal comes."""

from __future__ import annotations

import multiprocessing as mp
import signal

import pytest

from analysis.tournament import spec_from_dict
from analysis.tournament.executors import _Worker
from analysis.tournament.worker import context_for


@pytest.mark.parametrize("raises", [False, True], ids=["first-signal", "second-signal"])
def test_a_worker_stopped_as_it_starts_dies_by_sigterm(small_spec, raises):
    """The driver's handler sets its stop event on a first signal and raises on a second
    (driver._play). A worker forked with it in place ran it when close() terminated the
    pool as it started (a Ctrl-C then): it lived on (exit code None after 2 s: killed a
    second later by close()) or died of "KeyboardInterrupt: SIGTERM" with a traceback
    (exit code 1); of 20 workers terminated as they started, 15 did so before the fix."""
    ctx = context_for(spec_from_dict(small_spec))
    caught = []

    def drivers_handler(signum, frame):
        caught.append(signum)
        if raises:
            raise KeyboardInterrupt(signal.Signals(signum).name)

    previous = signal.signal(signal.SIGTERM, drivers_handler)
    codes = []
    try:
        for _ in range(10):
            w = _Worker(mp.get_context("fork"), ctx)
            w.proc.terminate()
            w.proc.join(2.0)
            codes.append(w.proc.exitcode)
            w.kill()
    finally:
        signal.signal(signal.SIGTERM, previous)
    assert codes == [-signal.SIGTERM] * 10
    assert caught == []  # and the driver's own handler saw nothing of it
