"""Backends that play matches: serial, a process pool, Ray. One small interface.

An executor's :meth:`Executor.run` takes the matches still to play, the worker
:class:`~analysis.tournament.worker.Context` and a ``stop`` event, and yields one outcome
dict per finished match, as it finishes. The driver stores each one at once. When
``stop`` is set the executor returns within a fraction of a second, and :meth:`close`
leaves no process behind. A new backend is one class.

* :class:`SerialExecutor` -- in the driver's process (tests, debugging, profiling).
* :class:`ProcessExecutor` -- N worker processes fed batches through pipes (default).
  Workers die with the driver even on SIGKILL (``PR_SET_PDEATHSIG`` on Linux, a
  parent-watching thread elsewhere), ignore Ctrl-C (the driver handles it), and a worker
  still busy :data:`KILL_GRACE` seconds after the deciding role's clock ran out (or the
  harness's stretch did: see :mod:`~analysis.tournament.worker`) is killed and replaced:
  the role that was deciding forfeits; with none deciding the match is an error.
* :class:`RayExecutor` -- Ray core tasks (``ray.init(address=...)`` for a cluster, a local
  instance otherwise), the context put in the object store once, batches of about
  :data:`TARGET_BATCH_SECONDS` each. A worker's watchdog thread ends a hang the alarm
  cannot interrupt :data:`KILL_GRACE` past its deadline and posts the match's outcome
  (the deciding role forfeits) to a mailbox actor the driver reads.
"""

from __future__ import annotations

import collections
import contextlib
import math
import multiprocessing as mp
import os
import signal
import sys
import threading
import time
from collections.abc import Iterator, Sequence
from multiprocessing.connection import Connection, wait
from pathlib import Path
from typing import Any

from analysis.tournament.identity import Match
from analysis.tournament.worker import (
    ALARM_GRACE,
    Board,
    Context,
    LocalBoard,
    forfeit,
    play,
    warm_up,
)

__all__ = [
    "BACKENDS",
    "KILL_GRACE",
    "TARGET_BATCH_SECONDS",
    "Executor",
    "ProcessExecutor",
    "RayExecutor",
    "SerialExecutor",
    "available_cpus",
    "check_backend",
    "make_executor",
    "warn_if_oversubscribed",
]

BACKENDS = ("serial", "process", "ray")
TARGET_BATCH_SECONDS = 1.0
"""Aim for tasks of about this long (fewer messages; Ray's per-task cost is ~ms)."""
KILL_GRACE = 5.0
"""Seconds past the end of the deciding role's clock (or of the harness's stretch) before
a process worker is killed."""
POLL = 0.1
"""Seconds between checks of the stop event and the deadlines."""


class Executor:
    """The interface: ``run`` yields outcomes; ``close`` releases every resource."""

    name = "executor"

    def run(self, matches: Sequence[Match], ctx: Context, stop: threading.Event) -> Iterator[dict]:
        """Play ``matches``; yield one outcome dict per finished match."""
        raise NotImplementedError

    def close(self) -> None:
        """Stop all work and release processes (idempotent)."""

    def describe(self) -> str:
        """One line for logs: the backend and its parallelism."""
        return self.name


class _Batcher:
    """Batch sizes aiming at :data:`TARGET_BATCH_SECONDS` from measured match times."""

    def __init__(self, workers: int) -> None:
        self.workers = max(1, workers)
        self.total = 0.0
        self.count = 0

    def observe(self, outcome: dict) -> None:
        seconds = outcome.get("wall_seconds")
        if seconds is not None:
            self.total += float(seconds)
            self.count += 1

    def size(self, remaining: int) -> int:
        if self.count == 0:
            return 1  # measure first
        per_match = max(self.total / self.count, 1e-4)
        size = max(1, int(TARGET_BATCH_SECONDS / per_match))
        fair = max(1, math.ceil(remaining / (2 * self.workers)))  # keep every worker fed
        return min(size, fair)


# --------------------------------------------------------------------------- serial
class SerialExecutor(Executor):
    """Plays in the driver's process, one match at a time.

    A policy that hangs inside C code with signals blocked cannot be interrupted here;
    use the process backend for untrusted policies.
    """

    name = "serial"

    def __init__(self) -> None:
        self.in_match = False

    def run(self, matches: Sequence[Match], ctx: Context, stop: threading.Event) -> Iterator[dict]:
        warm_up(ctx)  # as a process or Ray worker does: the imports are on no match's time
        for m in matches:
            if stop.is_set():
                return
            self.in_match = True
            try:
                out = play(m, ctx)
            finally:
                self.in_match = False
            yield out


# --------------------------------------------------------------------------- processes
def _die_with_parent(parent: int) -> None:
    """Make this worker die when the driver dies, however it dies."""
    if sys.platform.startswith("linux"):
        try:
            import ctypes

            libc = ctypes.CDLL(None, use_errno=True)
            libc.prctl(1, signal.SIGKILL, 0, 0, 0)  # PR_SET_PDEATHSIG
        except (OSError, AttributeError):  # pragma: no cover
            pass
    if os.getppid() != parent:  # the parent died before prctl took effect
        os._exit(1)

    def watch() -> None:  # portable fallback
        while True:
            time.sleep(0.5)
            if os.getppid() != parent:
                os._exit(1)

    threading.Thread(target=watch, daemon=True).start()


_STOP_SIGNALS = {signal.SIGINT, signal.SIGTERM}


def _one_torch_thread_after_fork() -> None:
    """Keep torch to one thread in a worker forked from a driver that had used it.

    A driver that had run torch on its OpenMP threads (a notebook, a suite, any caller
    that trained or evaluated a model first) forks workers holding that thread team's
    state without its threads: the worker's first parallel region (loading a model: its
    weights' orthogonal init) waited for them for ever. A suite hung so in warm_up (no
    time limit: no watch). One thread takes no team. A worker whose torch is imported
    after the fork (a driver that never imported it, a spawned worker) keeps torch's own
    default.
    """
    torch = sys.modules.get("torch")
    if torch is not None and hasattr(torch, "set_num_threads"):
        torch.set_num_threads(1)


def _worker_main(conn: Connection, ctx: Context, parent: int, board: Board) -> None:
    # born with these blocked (see _Worker): the driver's handlers, which a forked worker
    # inherits, must never run here
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the driver's business
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, _STOP_SIGNALS)
    _die_with_parent(parent)
    _one_torch_thread_after_fork()
    warm_up(ctx)  # before the first match's clock starts, as a Ray worker does
    while True:
        try:
            batch = conn.recv()
        except (EOFError, OSError):
            break
        if batch is None:
            break
        for m in batch:
            conn.send(("start", m.match_id, time.monotonic()))
            conn.send(("done", play(m, ctx, board)))
    conn.close()


class _Worker:
    def __init__(self, mpctx: Any, ctx: Context) -> None:
        self.conn, child = mpctx.Pipe()
        self.board = Board(mpctx)
        self.proc = mpctx.Process(
            target=_worker_main,
            args=(child, ctx, os.getpid(), self.board),
            daemon=True,
            name="surveil-tournament-worker",
        )
        # A forked worker inherits the driver's SIGINT and SIGTERM handlers until
        # _worker_main replaces them: a SIGTERM from close() (a Ctrl-C as the pool
        # starts) ran the driver's handler there, so the worker lived on until killed a
        # second later, or printed "KeyboardInterrupt: SIGTERM" with a traceback. Born with
        # both blocked, it takes them only once its own dispositions are in place.
        masked = hasattr(signal, "pthread_sigmask")
        if masked:
            before = signal.pthread_sigmask(signal.SIG_BLOCK, _STOP_SIGNALS)
        try:
            self.proc.start()
        finally:
            if masked:
                signal.pthread_sigmask(signal.SIG_SETMASK, before)
        child.close()
        self.batch: collections.deque[Match] = collections.deque()
        self.current: Match | None = None

    def overrun(self, now: float, grace: float) -> dict | None:
        """The outcome to store if the match in play is ``grace`` past its board's deadline."""
        seen = self.board.read() if self.current is not None else None
        if seen is None or now <= seen[1] + grace:
            return None
        return _killed(self.current.match_id, seen[0], grace)

    def kill(self) -> None:
        if self.proc.is_alive():
            self.proc.kill()
        self.proc.join(timeout=2.0)
        self.conn.close()


def _killed(match_id: str, role: str | None, grace: float) -> dict:
    """The outcome of a match whose worker is killed ``grace`` past its deadline."""
    if role is None:
        return {
            "match_id": match_id,
            "status": "error",
            "error": f"killed: the env or the harness gave no answer for the time limit + "
            f"{grace:g} s while no policy was deciding (a hang the alarm could not interrupt)",
        }
    return forfeit(
        match_id,
        role,
        f"{role} killed: no answer {grace:g} s after its clock ran out (a hang the alarm "
        "could not interrupt)",
    )


class ProcessExecutor(Executor):
    """N worker processes fed batches of matches through pipes.

    Args:
        workers: processes (default: the CPUs available to this process).
        kill_grace: seconds past the end of the deciding role's clock (or of the
            harness's stretch) before a silent worker is killed.
        start_method: multiprocessing start method (default ``"fork"`` where available:
            workers start in milliseconds and see everything the driver registered).
    """

    name = "process"

    def __init__(
        self,
        workers: int | None = None,
        *,
        start_method: str | None = None,
        kill_grace: float = KILL_GRACE,
    ) -> None:
        if workers is None:
            workers = available_cpus()
        from envs.validation import integer

        self.workers = integer("workers", workers, minimum=1)
        warn_if_oversubscribed(self.workers)
        if start_method is None:
            start_method = "fork" if "fork" in mp.get_all_start_methods() else "spawn"
        self.mpctx = mp.get_context(start_method)
        self.kill_grace = float(kill_grace)
        self.pool: list[_Worker] = []

    def describe(self) -> str:
        return f"process ({self.workers} workers)"

    def run(self, matches: Sequence[Match], ctx: Context, stop: threading.Event) -> Iterator[dict]:
        todo = collections.deque(matches)
        batcher = _Batcher(self.workers)
        self.pool = [_Worker(self.mpctx, ctx) for _ in range(min(self.workers, len(todo)))]
        while (todo or any(w.batch or w.current for w in self.pool)) and not stop.is_set():
            for w in self.pool:
                if not w.batch and w.current is None and todo:
                    n = batcher.size(len(todo))
                    batch = [todo.popleft() for _ in range(min(n, len(todo)))]
                    w.batch.extend(batch)
                    w.conn.send(batch)
            ready = wait([w.conn for w in self.pool if w.batch or w.current], timeout=POLL)
            for w in list(self.pool):
                if w.conn not in ready:
                    continue
                try:
                    while w.conn.poll():
                        msg = w.conn.recv()
                        if msg[0] == "start":
                            w.current = w.batch.popleft()
                        else:
                            w.current = None
                            batcher.observe(msg[1])
                            yield msg[1]
                            if stop.is_set():
                                return
                except (EOFError, OSError):
                    # the worker died (killed by the OOM killer, a segfault in a policy...)
                    lost = w.current
                    why = {"status": "error", "error": "worker process died"}
                    yield from self._replace(
                        w, ctx, todo, None if lost is None else {"match_id": lost.match_id, **why}
                    )
            now = time.monotonic()
            for w in list(self.pool):
                outcome = w.overrun(now, self.kill_grace)
                if outcome is not None:
                    yield from self._replace(w, ctx, todo, outcome)

    def _replace(
        self, w: _Worker, ctx: Context, todo: collections.deque, lost: dict | None
    ) -> Iterator[dict]:
        """Kill ``w``, queue its unplayed batch again, yield ``lost`` (its match's outcome)."""
        w.kill()
        todo.extendleft(reversed(w.batch))  # the unplayed rest goes back to the queue
        self.pool.remove(w)
        if lost is not None:
            yield lost
        if todo:
            self.pool.append(_Worker(self.mpctx, ctx))

    def close(self) -> None:
        for w in self.pool:
            if w.proc.is_alive():
                w.proc.terminate()
        deadline = time.monotonic() + 1.0
        for w in self.pool:
            w.proc.join(timeout=max(0.0, deadline - time.monotonic()))
            w.kill()
        self.pool = []


# --------------------------------------------------------------------------- ray
_RAY_CONTEXTS: dict[str, Context] = {}


class _Mailbox:
    """A Ray actor of a run: the outcome a Ray worker posts before it ends itself."""

    def __init__(self) -> None:
        self.box: dict[str, dict] = {}

    def post(self, match_id: str, outcome: dict) -> None:
        self.box[match_id] = outcome

    def take(self, match_id: str) -> dict | None:
        return self.box.pop(match_id, None)


class _RayWatch:
    """A Ray worker process's watchdog: a thread reading the board of the match in play.

    A hang the alarm cannot interrupt (C code, signals blocked) outlives its deadline by
    :data:`KILL_GRACE`: the thread posts the match's outcome (a forfeit of the role that
    was deciding, or an error) to the run's mailbox and ends the process, and the driver
    stores what it finds there when it sees the task fail.
    """

    def __init__(self) -> None:
        self.board = LocalBoard()
        self.match: Match | None = None
        self.mailbox: Any = None
        threading.Thread(target=self._watch, daemon=True, name="surveil-ray-watch").start()

    def _watch(self) -> None:
        import ray

        while True:
            time.sleep(POLL)
            match, seen = self.match, self.board.read()
            if match is None or seen is None or time.monotonic() <= seen[1] + KILL_GRACE:
                continue
            try:
                outcome = _killed(match.match_id, seen[0], KILL_GRACE)
                ray.get(self.mailbox.post.remote(match.match_id, outcome), timeout=60)
            finally:
                os._exit(1)


_RAY_WATCH: list[_RayWatch] = []


def _ray_play(batch: list[Match], ctx_box: list[Any], mailbox: Any) -> Iterator[tuple[str, Any]]:
    """A Ray task (a generator): fetch the run's context once per worker process, play.

    Yields ``("start", match_id)`` and ``("done", outcome)`` for each match, so that the
    driver times each match from its own start, as the process backend does (not the wait
    in Ray's queue, the worker's start or the context's fetching before it). The worker's
    :class:`_RayWatch` posts to ``mailbox`` the outcome of a match it ends.
    """
    import ray

    if not _RAY_WATCH:
        _RAY_WATCH.append(_RayWatch())
    watch = _RAY_WATCH[0]
    watch.mailbox = mailbox
    ref = ctx_box[0]
    key = ref.hex()
    if key not in _RAY_CONTEXTS:
        _RAY_CONTEXTS.clear()
        ctx, registrations = ray.get(ref)
        _register_missing(registrations)
        warm_up(ctx)
        _RAY_CONTEXTS[key] = ctx
    for m in batch:
        yield ("start", m.match_id)
        watch.match = m
        try:
            out = play(m, _RAY_CONTEXTS[key], watch.board)
        finally:
            watch.match = None
        yield ("done", out)


def _roster_registrations(ctx: Context) -> dict[str, tuple[Any, str]]:
    """``{name: (factory, description)}`` of the roster's registered policies.

    A Ray worker is a fresh process: it knows the built-in policies but not one the driver
    registered at run time (a forked process worker inherits those), so these travel with
    the context and :func:`_register_missing` registers them there.
    """
    from strategies.policies.registry import policy_spec

    out = {}
    for entry in ctx.policies.values():
        if entry.model is None:
            spec = policy_spec(entry.name)
            out[entry.name] = (spec.factory, spec.description)
    return out


def _register_missing(registrations: dict[str, tuple[Any, str]]) -> None:
    """Register in this process the policies of ``registrations`` it does not know."""
    from strategies.policies.registry import policy_names, register_policy

    known = set(policy_names())
    for name, (factory, description) in registrations.items():
        if name not in known:
            register_policy(name, factory, description)


def _ray_allowance(time_limit: float) -> float:
    """Seconds from a match's start before the Ray driver kills its task."""
    return 3 * (time_limit + ALARM_GRACE) + KILL_GRACE


class _RayTask:
    """The driver's view of one Ray task: its batch and what it has reported."""

    def __init__(self, batch: list[Match]) -> None:
        self.batch = batch
        self.pending = collections.deque(batch)  # not started yet
        self.current: Match | None = None  # in play
        self.played = 0
        self.since: float | None = None  # the driver's clock at its last match report

    def deadline(self, time_limit: float) -> float | None:
        """When to kill it: ``None`` until it starts a match (queued, or its worker starting).

        The driver cannot see which role a Ray worker's match is deciding, so it allows
        the match both clocks and as long again for the env and the harness, each with the
        alarm's grace, and :data:`KILL_GRACE` more.
        """
        if self.since is None:
            return None
        return self.since + _ray_allowance(time_limit)


class RayExecutor(Executor):
    """Ray core tasks, each a batch of matches.

    Args:
        address: a running cluster (``"auto"``, ``"ray://host:10001"``...); ``None``
            starts a local instance with ``num_cpus`` CPUs (shut down by :meth:`close`).
        num_cpus: CPUs of a local instance (default: all); with ``address``, or when Ray
            is already initialised, the most CPUs this run's tasks occupy at once.

    Up to two tasks per CPU are in flight, so a task may wait in Ray's queue. A task
    reports when it starts each match (it is a generator, see :func:`_ray_play`). Within a
    match the worker's own alarm blames the role whose clock ran out, as in the other
    backends, and a hang the alarm cannot interrupt is ended by the worker's watchdog
    thread :data:`KILL_GRACE` past its deadline, which posts the outcome (a forfeit of the
    role that was deciding, or an error with none deciding) to the run's mailbox actor
    (:class:`_Mailbox`, no CPU) before it ends the process. Where the watchdog cannot run
    either (C code holding the GIL), the driver kills the task three times the time limit
    plus the alarm's grace, plus :data:`KILL_GRACE`, after that report: an error, charged
    to nobody. A wait in Ray's queue, a worker's start and its fetching of the context
    are no match's time and are not timed: timed from the submission, with a guessed
    allowance (30 s), they outran it at load 14 on 2 cores (a worker's start 23 s, the
    context 14 s more) and matches that never overran were stored as overruns. A hang
    there (a policy whose unpickling hangs with signals blocked) is not killed; ``stop``
    still ends the run.
    """

    name = "ray"

    def __init__(
        self,
        address: str | None = None,
        num_cpus: int | None = None,
    ) -> None:
        if num_cpus is not None:
            from envs.validation import integer

            # 0 CPUs: no task was ever scheduled, and each batch was stored as an error
            # ("overran the time limit") after time_limit + 6 s
            num_cpus = integer("workers", num_cpus, minimum=1)
            if address is None:  # a local instance runs up to num_cpus worker processes
                warn_if_oversubscribed(num_cpus)
        try:
            import ray
        except ModuleNotFoundError as exc:
            from envs.errors import InvalidConfigError

            raise InvalidConfigError("--backend ray needs Ray: pip install 'surveil[ray]'") from exc
        self.ray = ray
        self.started = False
        self.owner: str | None = None  # the mark of the processes a local start begat
        self.inflight: dict[Any, _RayTask] = {}  # task (an ObjectRefGenerator): its state
        self.mailbox: Any = None
        if not ray.is_initialized():
            kwargs: dict[str, Any] = {
                "include_dashboard": False,
                "log_to_driver": False,
                "configure_logging": False,
            }
            if address is None:
                kwargs["num_cpus"] = num_cpus
            # no address: a new local instance, as documented. ray.init(address=None)
            # joins the cluster named by $RAY_ADDRESS or /tmp/ray/ray_current_cluster (a
            # `ray start --head` running, or a stale file one left behind), and with
            # num_cpus raised "When connecting to an existing cluster, num_cpus and
            # num_gpus must not be provided": a traceback for --backend ray --workers 2
            self._init("local" if address is None else address, kwargs)
        try:
            self.cluster_cpus = max(1, int(ray.cluster_resources().get("CPU", 1)))
        except BaseException:  # a Ctrl-C here too: the caller has no executor to close
            self.close()
            raise
        # num_cpus also caps the work in flight on a cluster (--address) or on an instance
        # this process had started: it was ignored there, and every CPU was used
        self.cpus = self.cluster_cpus if num_cpus is None else min(num_cpus, self.cluster_cpus)
        # two tasks a CPU keep every CPU fed; under a cap, as many as it allows (a queued
        # second task would run on a CPU of the cluster's beyond it)
        self.max_inflight = 2 * self.cpus if self.cpus == self.cluster_cpus else self.cpus
        self.task = ray.remote(num_cpus=1, max_retries=0)(_ray_play)

    def _init(self, address: str | None, kwargs: dict[str, Any]) -> None:
        """``ray.init``, stopped cleanly by Ctrl-C or SIGTERM (it takes seconds).

        ``ray.init`` sets a SIGTERM handler of its own (``sys.exit(15)``): a SIGTERM while
        Ray started, or before the run's own handler was in place, ended ``surveil`` with
        exit code 15, no message, and Ray's dashboard and runtime-env agents alive after
        it (a Ctrl-C then left them too). The handler that was there is put back, and an
        interrupted start shuts down what it started.
        """
        main = threading.current_thread() is threading.main_thread()
        previous = signal.getsignal(signal.SIGTERM) if main else None
        if address == "local":  # every process the instance starts inherits the mark
            self.owner = f"{os.getpid()}-{os.urandom(8).hex()}"
            os.environ[RAY_OWNER] = self.owner
        try:
            self.started = True  # from the first process it starts: close() shuts it down
            self.ray.init(address=address, **kwargs)
        except BaseException as exc:
            self.close()
            if isinstance(exc, SystemExit) and exc.code == signal.SIGTERM:  # Ray's handler
                raise KeyboardInterrupt("SIGTERM") from None
            raise
        finally:
            os.environ.pop(RAY_OWNER, None)  # not for this process's other children
            if previous is not None:
                signal.signal(signal.SIGTERM, previous)

    def describe(self) -> str:
        if self.cpus < self.cluster_cpus:
            return f"ray ({self.cpus} of {self.cluster_cpus} CPUs)"
        return f"ray ({self.cpus} CPUs)"

    def run(self, matches: Sequence[Match], ctx: Context, stop: threading.Event) -> Iterator[dict]:
        ray = self.ray
        try:  # shipped once; models and the roster's registrations travel inside it
            box = [ray.put((ctx, _roster_registrations(ctx)))]
        except Exception as exc:  # e.g. a policy class that cannot be pickled
            from envs.errors import InvalidConfigError

            raise InvalidConfigError(
                f"the run's context (maps, policies, models) cannot be sent to Ray workers: "
                f"{type(exc).__name__}: {exc}; use --backend process"
            ) from exc
        if self.mailbox is None:
            self.mailbox = ray.remote(num_cpus=0)(_Mailbox).remote()
        todo = collections.deque(matches)
        batcher = _Batcher(self.cpus)
        solo: set[str] = set()  # matches of a task that died before it started one
        while (todo or self.inflight) and not stop.is_set():
            while todo and len(self.inflight) < self.max_inflight:
                n = 1 if todo[0].match_id in solo else batcher.size(len(todo))
                batch = [todo.popleft() for _ in range(min(n, len(todo)))]
                self.inflight[self.task.remote(batch, box, self.mailbox)] = _RayTask(batch)
            ready, _ = ray.wait(list(self.inflight), num_returns=1, timeout=POLL)
            for gen in ready:
                yield from self._drain(gen, todo, solo, batcher)
                if stop.is_set():
                    return
            now = time.monotonic()
            for gen, task in list(self.inflight.items()):
                deadline = task.deadline(ctx.time_limit)
                if deadline is not None and now > deadline:
                    ray.cancel(gen, force=True)
                    del self.inflight[gen]
                    why = (
                        f"killed: no answer {_ray_allowance(ctx.time_limit):g} s into "
                        "the match (a hang neither the alarm nor the worker's watchdog "
                        "could end)"
                    )
                    yield from self._lost(task, todo, solo, why)

    def _drain(
        self, gen: Any, todo: collections.deque, solo: set[str], batcher: _Batcher
    ) -> Iterator[dict]:
        """Consume what task ``gen`` has yielded so far; yield its outcomes."""
        ray = self.ray
        task = self.inflight[gen]
        while True:
            try:
                kind, value = ray.get(next(gen))
            except StopIteration:
                del self.inflight[gen]
                return
            except Exception as exc:  # the task's worker died
                del self.inflight[gen]
                yield from self._lost(
                    task, todo, solo, f"Ray task failed: {type(exc).__name__}: {exc}"
                )
                return
            task.since = time.monotonic()
            if kind == "start":
                task.current = task.pending.popleft()
            elif kind == "done":
                task.current = None
                task.played += 1
                batcher.observe(value)
                yield value
            if not ray.wait([gen], num_returns=1, timeout=0)[0]:
                return

    def _lost(
        self, task: _RayTask, todo: collections.deque, solo: set[str], why: str
    ) -> Iterator[dict]:
        """A task killed or dead: its match in play is what its worker posted before it
        ended itself (see :class:`_RayWatch`), or an error; the rest is replayed."""
        rest = list(task.pending)
        if task.current is not None:
            mid = task.current.match_id
            try:
                posted = self.ray.get(self.mailbox.take.remote(mid), timeout=60)
            except Exception:  # pragma: no cover - the mailbox died with the cluster
                posted = None
            yield posted or {"match_id": mid, "status": "error", "error": why}
        elif task.played == 0 and len(task.batch) == 1 and task.batch[0].match_id in solo:
            # a worker that never started this match, already alone in its task: give up
            yield {"match_id": rest[0].match_id, "status": "error", "error": why}
            return
        elif task.played == 0:  # the start failed: retry these one by one
            solo.update(m.match_id for m in rest)
        todo.extendleft(reversed(rest))

    def close(self) -> None:
        for ref in list(self.inflight):
            try:
                self.ray.cancel(ref, force=True)
            except Exception:  # pragma: no cover - already finished
                pass
        self.inflight.clear()
        if self.mailbox is not None:
            with contextlib.suppress(Exception):
                self.ray.kill(self.mailbox)
            self.mailbox = None
        if self.started:  # (even half started: an interrupted ray.init)
            with contextlib.suppress(Exception):
                self.ray.shutdown()
            self.started = False
        if self.owner is not None:  # what the raylet started outlives it
            end_marked_processes(self.owner)
            self.owner = None


RAY_OWNER = "SURVEIL_RAY_OWNER"
"""An environment variable set while a :class:`RayExecutor` starts a local instance: its
GCS, raylet, agents and workers inherit it, so :meth:`RayExecutor.close` finds them all."""


def _marked_processes(owner: str) -> list[int]:
    """The processes whose environment holds ``RAY_OWNER=owner`` (Linux's /proc; none
    elsewhere), this one aside."""
    proc = Path("/proc")
    if not proc.is_dir():  # pragma: no cover - not Linux: ray.shutdown's own cleanup only
        return []
    mark = f"{RAY_OWNER}={owner}".encode()
    me = str(os.getpid())
    found = []
    for entry in proc.iterdir():
        if entry.name.isdigit() and entry.name != me:
            with contextlib.suppress(OSError):
                if mark in (entry / "environ").read_bytes().split(b"\0"):
                    found.append(int(entry.name))
    return found


def end_marked_processes(owner: str, grace: float = 3.0) -> None:
    """End what a local Ray instance started and ``ray.shutdown`` left: SIGTERM, then
    SIGKILL after ``grace`` seconds.

    ``ray.shutdown`` stops the GCS and the raylet it started, but not what the raylet
    started: after a Ctrl-C while Ray started (``ray.init`` or an actor's creation) its
    dashboard and runtime-env agents (``ray::DashboardAgent``, ``ray::RuntimeEnvAgent``)
    lived on, reparented to init, for about a minute; workers likewise. They are found by
    the :data:`RAY_OWNER` mark they inherited, so no other process (another run's Ray
    included) is touched.
    """
    pids = _marked_processes(owner)
    for sig in (signal.SIGTERM, signal.SIGKILL):
        for pid in pids:
            with contextlib.suppress(ProcessLookupError, PermissionError):
                os.kill(pid, sig)
        deadline = time.monotonic() + (grace if sig == signal.SIGTERM else 1.0)
        while pids and time.monotonic() < deadline:
            time.sleep(0.05)
            pids = _marked_processes(owner)
        if not pids:
            return


OVERSUBSCRIBED = 2
"""Workers above this many times :func:`available_cpus` are said to be too many."""


def available_cpus() -> int:
    """The CPUs this process may run on (its affinity), else ``os.cpu_count()``."""
    affinity = getattr(os, "sched_getaffinity", None)
    return len(affinity(0)) if affinity else (os.cpu_count() or 1)


def warn_if_oversubscribed(workers: int, name: str = "workers", stacklevel: int = 3) -> None:
    """Warn (:class:`~envs.errors.OversubscribedWarning`) when ``workers`` processes are
    more than :data:`OVERSUBSCRIBED` times :func:`available_cpus`: ``--workers 1000`` on
    two cores started 1000 interpreters without a word. Not refused: it plays as asked."""
    import warnings

    from envs.errors import OversubscribedWarning

    cpus = available_cpus()
    if workers > OVERSUBSCRIBED * cpus:
        warnings.warn(
            f"{name} = {workers}: far above the {cpus} CPUs this process may use "
            f"(os.cpu_count() = {os.cpu_count()}): up to {workers} worker processes take "
            "turns on them, each with its own interpreter and copies of the maps and "
            f"policies, no faster than {cpus} and heavier; played as asked",
            OversubscribedWarning,
            stacklevel=stacklevel,
        )


def check_backend(backend: str, *, workers: int | None = None, address: str | None = None) -> None:
    """Refuse a backend, worker count or address :func:`make_executor` cannot use.

    Raises:
        InvalidConfigError: an unknown backend, ``address`` without Ray, ``workers``
            not an integer >= 1, or more than one worker for the serial backend.
    """
    from envs.errors import InvalidConfigError
    from envs.validation import integer

    if backend not in BACKENDS:
        raise InvalidConfigError(f"backend = {backend!r}: expected one of {list(BACKENDS)}")
    if address is not None and backend != "ray":
        raise InvalidConfigError(f"--address applies to the ray backend, not {backend!r}")
    if workers is not None:
        integer("workers", workers, minimum=1)
        if backend == "serial" and workers != 1:  # it was ignored without a word
            raise InvalidConfigError(
                f"workers = {workers}: the serial backend plays one match at a time in this "
                "process; use the process or ray backend for more"
            )


def make_executor(
    backend: str, *, workers: int | None = None, address: str | None = None
) -> Executor:
    """The executor of ``backend`` (``"serial"``, ``"process"``, ``"ray"``).

    Raises:
        InvalidConfigError: an unknown backend, or ``address`` without Ray.
    """

    check_backend(backend, workers=workers, address=address)
    if backend == "serial":
        return SerialExecutor()
    if backend == "process":
        return ProcessExecutor(workers)
    return RayExecutor(address, workers)
