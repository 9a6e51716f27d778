"""Playing matches where the executors put them: the same code in every backend.

The driver builds one :class:`Context` per run (maps, resolved env parameters, roster,
model files as bytes) and ships it to each worker once; tasks are small
:class:`~analysis.tournament.identity.Match` records naming labels. :func:`play` turns a
match into an *outcome* dict for :meth:`Store.record`:

* ``ok`` -- the episode was played out (the record of :func:`strategies.runner.run_episode`);
* ``forfeit`` -- a policy raised, returned an action the env refuses, or ran out of time:
  the other side wins, ``blame`` names the role at fault, ``error`` says what happened;
* ``error`` -- the match could not be played (no start exists, a bad env parameter, the
  env or the harness hung): nobody wins.

**The time limit is a chess clock per role** (:func:`strategies.runner.run_episode`):
each role may spend ``time_limit`` seconds deciding in a match, its policy's ``reset``
and ``act`` calls; building the env and the policy objects, drawing the start, the
observations and the env's steps are on no clock. A role whose clock runs out forfeits,
whichever side was slower overall. What a policy builds of a map once and caches is built
before its first match there in the process, on no clock (:func:`_set_up`). A stored row's
``decide_pursuer`` / ``decide_evader`` is the mean ``act`` call; the record's
``reset_seconds`` holds each reset.

A hang is cut short twice. A ``SIGALRM`` interrupts a call :data:`ALARM_GRACE` seconds
after the deciding role's clock ran out (where the platform allows it: the main thread of
a POSIX process), and that role forfeits. The worker also writes on a :class:`Board` who
is deciding and until when (a :class:`LocalBoard` in a Ray worker, read by its watchdog
thread), so a worker stuck where signals do not reach (C code, signals blocked) can be
killed and the role that was deciding still blamed. With
no policy deciding, each stretch of the env's and the harness's work gets the time limit
too (the same alarm, the same kill): past it the match is an ``error``, charged to nobody.
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import signal
import tempfile
import threading
import time
import traceback
import warnings
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from analysis.tournament.identity import Match
from analysis.tournament.spec import PolicyEntry, Spec
from envs.errors import NarrowBandWarning, RhoAboveOneWarning

__all__ = [
    "Board",
    "Context",
    "LocalBoard",
    "MatchTimeout",
    "context_for",
    "forfeit",
    "play",
    "warm_up",
]

ALARM_GRACE = 1.0
"""Seconds past the end of a clock before ``SIGALRM`` interrupts the call in progress."""
ALARM_MAX = 1e8
"""The longest alarm set (about three years): ``setitimer`` overflows near 1e12 s."""


class MatchTimeout(Exception):
    """Raised by the ``SIGALRM`` handler inside a hung call.

    Attributes:
        role: the role that was deciding (it forfeits), or ``None``: the env or the
            harness was working (the match is an error).
    """

    def __init__(self, message: str, role: str | None = None) -> None:
        super().__init__(message)
        self.role = role


IDLE, HARNESS = -1.0, 0.0
"""What a :class:`Board` says between matches, and while no policy is deciding."""
ROLE_CODES = {"pursuer": 1.0, "evader": 2.0}


class Board:
    """Who is deciding in one worker and until when, readable by the driver's process.

    Three shared doubles, ``[sequence, who, deadline]``, written by the worker only, as a
    seqlock: the sequence is odd while a write is under way, so a reader that sees it odd
    or changed across its read skips that read. ``who`` is :data:`IDLE`,
    :data:`HARNESS` or a :data:`ROLE_CODES` value; ``deadline`` is the
    ``time.monotonic()`` (one clock for every process of the machine) at which the
    deciding role's clock runs out, or the harness's stretch does.

    Args:
        mpctx: the multiprocessing context that starts the worker.
    """

    def __init__(self, mpctx: Any) -> None:
        self.values = mpctx.RawArray("d", 3)
        self.values[1] = IDLE

    def write(self, who: float, deadline: float) -> None:
        """Say who is deciding and until when (the worker)."""
        v = self.values
        v[0] += 1.0
        v[1] = who
        v[2] = deadline
        v[0] += 1.0

    def read(self) -> tuple[str | None, float] | None:
        """``(role or None for the harness, deadline)``; ``None`` when idle or mid-write."""
        v = self.values
        before, who, deadline, after = v[0], v[1], v[2], v[0]
        if before != after or before % 2 or who == IDLE:
            return None
        role = next((r for r, c in ROLE_CODES.items() if c == who), None)
        return role, deadline


class LocalBoard:
    """A :class:`Board` read by a thread of the same process (a Ray worker's watchdog)."""

    def __init__(self) -> None:
        self.seen: tuple[float, float] = (IDLE, 0.0)  # one object: read whole or not at all

    def write(self, who: float, deadline: float) -> None:
        """Say who is deciding and until when."""
        self.seen = (who, deadline)

    def read(self) -> tuple[str | None, float] | None:
        """``(role or None for the harness, deadline)``; ``None`` when idle."""
        who, deadline = self.seen
        if who == IDLE:
            return None
        return next((r for r, c in ROLE_CODES.items() if c == who), None), deadline


@dataclass
class Context:
    """Everything a worker needs to play any match of a run.

    Attributes:
        maps: ``{label: Map}``.
        envs: ``{(map label, variant label): resolved env parameters}``.
        policies: ``{"ROLE:label": PolicyEntry}``.
        models: ``{sha256: model file bytes}`` (shipped once, materialised per worker).
        time_limit: wall-clock seconds each role may spend deciding in a match (its
            reset and acts); also the longest stretch of the env's and the harness's work.
        starts: the run's start kinds (``"safe"``...), whose samplers :func:`warm_up`
            prepares.
    """

    maps: dict[str, Any]
    envs: dict[tuple[str, str], dict[str, Any]]
    policies: dict[str, PolicyEntry]
    models: dict[str, bytes] = field(default_factory=dict, repr=False)
    time_limit: float = 300.0
    starts: tuple[str, ...] = ()


def context_for(spec: Spec) -> Context:
    """The worker context of ``spec`` (reads each model file once)."""
    models = {}
    for p in spec.policies().values():
        if p.model is not None and p.model_sha256 not in models:
            data = Path(p.model).read_bytes()
            import hashlib

            if hashlib.sha256(data).hexdigest() != p.model_sha256:
                from envs.errors import InvalidConfigError

                raise InvalidConfigError(
                    f"model {p.model} changed on disk since the spec was loaded; reload the spec"
                )
            models[p.model_sha256] = data
    return Context(
        maps={m.label: m.map for m in spec.maps},
        envs={(m.label, v.label): spec.env_config(m, v) for m in spec.maps for v in spec.variants},
        policies=spec.policies(),
        models=models,
        time_limit=spec.time_limit,
        starts=tuple(spec.starts),
    )


# --------------------------------------------------------------------------- per process
_MODEL_DIR: str | None = None
_LEARNED: dict[str, Any] = {}


def _model_file(ctx: Context, sha: str) -> str:
    global _MODEL_DIR
    if _MODEL_DIR is None:
        _MODEL_DIR = tempfile.mkdtemp(prefix="surveil-models-")
    path = os.path.join(_MODEL_DIR, f"{sha}.zip")
    if not os.path.exists(path):
        tmp = path + f".{os.getpid()}.tmp"
        with open(tmp, "wb") as f:
            f.write(ctx.models[sha])
        os.replace(tmp, path)
    return path


def build_policy(ctx: Context, entry: PolicyEntry) -> Any:
    """A fresh policy for one match (learned models are loaded once per process)."""
    from strategies.policies import make_policy

    if entry.model is None:
        return make_policy(entry.name, **entry.params)
    # the label is part of the key: a process keeps its models across runs (the serial
    # backend's is the caller's), and the same file under another label is another name
    params = json.dumps(entry.params, sort_keys=True)
    key = f"{entry.role}:{entry.model_sha256}:{params}:{entry.label}"
    if key not in _LEARNED:
        path = _model_file(ctx, entry.model_sha256)
        policy = make_policy(f"{entry.role}/sb3:{path}", **entry.params)
        # named as the spec names it (its label: the model as written, by default), not by
        # this process's copy of the file ('pursuer/sb3:/tmp/surveil-models-.../SHA.zip')
        policy.name = entry.label
        _LEARNED[key] = policy
    return _LEARNED[key]


class _Watch:
    """One match's clocks as the worker's alarm and its :class:`Board` see them.

    Called by the runner (``on_clock``) as a policy starts deciding, with its role and the
    seconds left on its clock, and as it stops, with ``(None, None)``: from then on the env
    and the harness get a stretch of ``limit`` seconds. Each stretch is due
    :data:`ALARM_GRACE` after it runs out.

    The alarm is not set at every call (two system calls a decision, 3.3 us against
    0.66 us for the whole call now): it may ring early, and its handler then sets it again.
    It is set for the earliest moment any stretch still to come can be due: no stretch
    of a role with ``left`` seconds on its clock can be due before ``now + left + grace``,
    since a clock runs no faster than time. So it is set at the start, and after that
    only when it rings or a stretch is due before it.
    """

    def __init__(self, limit: float, board: Board | None) -> None:
        self.limit = limit
        self.board = board
        self.low = limit  # the least time left on either role's clock
        self.stretch: tuple[str | None, float] = (None, math.inf)  # (who, due), one object
        self.armed = math.inf  # when the alarm rings (time.monotonic)
        self.alarm = (
            hasattr(signal, "setitimer") and threading.current_thread() is threading.main_thread()
        )

    def __call__(self, role: str | None, left: float | None) -> None:
        now = time.monotonic()
        if role is None:  # a role stopped deciding: its clock ran until now
            low = self.stretch[1] - ALARM_GRACE - now  # (inf at the start)
            if low < self.low:
                self.low = low
            due = now + self.limit + ALARM_GRACE
        else:
            due = now + left + ALARM_GRACE
        self.stretch = (role, due)  # one object: a ring sees this stretch or the previous
        if due < self.armed and self.alarm:
            self._arm(due, now)
        if self.board is not None:
            self.board.write(HARNESS if role is None else ROLE_CODES[role], due - ALARM_GRACE)

    @contextlib.contextmanager
    def setting_up(self, role: str) -> Iterator[None]:
        """A policy's one-time set-up (:func:`_set_up`): watched as a call of ``role``
        with a whole time limit, on no clock (the least time left on a clock unchanged;
        an alarm it rang is spent)."""
        low = self.low
        self(role, self.limit)
        try:
            yield
        finally:
            self.armed = math.inf
            self(None, None)
            self.low = low

    def _arm(self, at: float, now: float) -> None:
        self.armed = at
        signal.setitimer(signal.ITIMER_REAL, min(max(at - now, 1e-3), ALARM_MAX))

    def _ring(self, signum: int, frame: Any) -> None:
        now = time.monotonic()
        role, due = self.stretch
        if now < due:  # early: set it for the current stretch or the next one due
            self._arm(min(due, now + self.low + ALARM_GRACE), now)
            return
        if role is None:
            raise MatchTimeout(
                f"the env or the harness gave no answer for {self.limit + ALARM_GRACE:g} s "
                f"(the time limit + {ALARM_GRACE:g} s) while no policy was deciding"
            )
        raise MatchTimeout(
            f"no answer {ALARM_GRACE:g} s after its clock ran out (time limit "
            f"{self.limit:g} s of decision time per role)",
            role,
        )

    def __enter__(self) -> _Watch:
        if self.alarm:
            self.previous = signal.signal(signal.SIGALRM, self._ring)
        self(None, None)
        return self

    def __exit__(self, *exc: Any) -> None:
        if self.alarm:
            signal.setitimer(signal.ITIMER_REAL, 0.0)
            signal.signal(signal.SIGALRM, self.previous)
        if self.board is not None:
            self.board.write(IDLE, 0.0)


def forfeit(match_id: str, role: str, error: str) -> dict[str, Any]:
    """The outcome of a match ``role`` forfeits (the other side wins)."""
    return {
        "match_id": match_id,
        "status": "forfeit",
        "winner": "evader" if role == "pursuer" else "pursuer",
        "blame": role,
        "error": error,
    }


def warm_up(ctx: Context | None = None) -> None:
    """Import what a match imports on first use, before a fresh worker's first match.

    Without it the first match of a worker process imported the env (PettingZoo), the
    start sampler and the observers on its own clock: 0.15 s on an idle machine, 1.2 s at
    load 6 on 2 cores (compiled from source where no bytecode is cached), against a time
    limit that a short tournament sets to 1 s, so a quick match could forfeit or be stored
    as a ``MatchTimeout`` error for time it never used.

    With ``ctx``, its models are loaded too (stable-baselines3, torch and the model file:
    2-3 s for the first at load 8), as building a policy is on no clock: a model loaded in
    its first reset, on its clock, and an alarm that interrupted the load past a short
    clock left torch half imported, so every later match of a model in that process
    failed to load it ('module 'sympy' has no attribute 'core''), an error charged to
    nobody. A model that fails to load here is left to its matches, which say why.

    With ``ctx``, each map's one-time set-up is done too, once per body radius its env
    variants set (:func:`_prepare_map`): a worker's first match on a map built it in the
    harness's first stretch, 0.38-0.48 s on a 1000-wall room at load 10, against a
    stretch of the time limit plus :data:`ALARM_GRACE`, so a short limit could store a
    ``MatchTimeout`` error for a match that never hung. That includes the run's start
    kinds: a first ``"safe"`` start on office built its judge's safety table there (1.0 s
    at load 7; then 0.012 s), and a spec with ``time_limit = 0.05`` stored that match as
    an error.
    """
    import envs.surveillance_v1  # noqa: F401
    import strategies.policies.observe
    import strategies.policies.starts
    import strategies.runner  # noqa: F401
    from strategies.policies.registry import policy_names

    policy_names()  # the catalog of built-in policies
    for entry in () if ctx is None else ctx.policies.values():
        if entry.model is not None:
            with contextlib.suppress(Exception):  # its matches report it
                build_policy(ctx, entry).load()
    done = set()  # the caches' keys: the map, and its body radius for the room check
    for (label, _), overrides in {} if ctx is None else ctx.envs.items():
        if (key := (label, repr(overrides.get("body_radius")))) in done:
            continue
        with contextlib.suppress(Exception), warnings.catch_warnings():  # its matches say why
            warnings.simplefilter("ignore")
            _prepare_map(ctx.maps[label], overrides, ctx.starts)
            done.add(key)  # (a variant whose start is refused leaves it to the next)


def _prepare_map(world: Any, overrides: dict[str, Any], starts: tuple[str, ...] = ()) -> None:
    """Build what a match's set-up builds once per map and caches: the env's geometry
    kernel, the start sampler's room check (:func:`envs.surveillance.placement.check_room`)
    and the map's lazy indexes, by drawing one valid start and resetting an env there, and
    the judge of each other start kind in ``starts`` (a decomposition pursuer's safety
    table), by drawing one such start.

    The caches hold no randomness (the draw's generator is its own), so no match plays
    differently; the draw uses the env's parameters, as ``run_episode``'s does.
    """
    import numpy as np

    from strategies.policies.starts import sample_start
    from strategies.runner import build_env

    env = build_env(world, {**overrides, "observation": "state"})
    try:
        placement = sample_start(env.config, np.random.default_rng(0), kind="valid")
        env.reset(seed=0, options=placement)
        for kind in sorted(set(starts) - {"valid"}):
            sample_start(env.config, np.random.default_rng(0), kind=kind)
    finally:
        env.close()


_SET_UP: set[tuple[str, ...]] = set()
"""The (policy, map, env parameters) whose one-time set-up this process has done."""


def _set_up(ctx: Context, match: Match, entries: tuple[PolicyEntry, ...], watch: _Watch) -> None:
    """Do each policy's one-time set-up of the match's map before its clock starts: the
    first time this process plays a policy on a map (and its parameters), a throwaway
    copy of the policy is reset there, as the match will reset its own.

    A policy caches what it builds from the map (the shooting evader's escape plan and
    safety table, the decomposition pursuer's table: 9 s of CPU, 72 s of wall time at load
    14, for the shooting evader on a 1000-wall room, then 0.03 s of CPU a reset), and its
    first match there built it in its reset, on its clock: a 30 s limit forfeited it. The
    set-up is on no clock, watched as a call of its role given a whole time limit (past
    it, interrupted or its worker killed, as a match's call is); one that fails or is
    interrupted is left to the match, whose reset says why on its clock. A learned model's
    set-up is its load (:func:`warm_up`).
    The caches are bounded (eight escape plans): a worker that plays more maps in turn
    than they hold builds an evicted map's again in a match, on its clock, as before.
    """
    from strategies.runner import build_env, observation_options

    world, overrides = ctx.maps[match.map], ctx.envs[(match.map, match.variant)]
    for entry in entries:
        params, game = (
            json.dumps(x, sort_keys=True, default=str) for x in (entry.params, overrides)
        )
        key = (entry.role, entry.name, params, world.digest, game)
        if entry.model is not None or key in _SET_UP:
            continue
        _SET_UP.add(key)
        with watch.setting_up(entry.role), contextlib.suppress(Exception):
            # a failure (a hang interrupted too) is left to the match's reset, which says why
            policy = build_policy(ctx, entry)
            if hasattr(policy, "select"):  # a mixture: its pick is the match's
                continue
            opts = entry.observation or observation_options(policy) or {}
            env = build_env(world, {**overrides, **opts})
            try:
                policy.reset(role=entry.role, map=env.config.map, config=env.config, seed=0)
            finally:
                env.close()


def play(match: Match, ctx: Context, board: Board | None = None) -> dict[str, Any]:
    """Play one match; never raises for a failure of the match itself (see the module).

    Args:
        match: the match.
        ctx: the run's worker context.
        board: where to say who is deciding (a process worker's; see :class:`Board`).
    """
    from strategies.runner import PolicyFailure, run_episode

    out: dict[str, Any] = {"match_id": match.match_id}
    try:
        p = ctx.policies[f"pursuer:{match.pursuer}"]
        e = ctx.policies[f"evader:{match.evader}"]
        env = ctx.envs[(match.map, match.variant)]
        observations = {"pursuer": p.observation, "evader": e.observation}
        with _Watch(ctx.time_limit, board) as watch, warnings.catch_warnings():
            warnings.simplefilter("ignore", RhoAboveOneWarning)  # said once, at spec load
            warnings.simplefilter("ignore", NarrowBandWarning)  # so is this
            _set_up(ctx, match, (p, e), watch)
            result = run_episode(
                ctx.maps[match.map],
                build_policy(ctx, p),
                build_policy(ctx, e),
                match.seed,
                overrides=env,
                start=match.start,
                observations=observations,
                time_limit=ctx.time_limit,
                on_clock=watch,
            )
    except PolicyFailure as exc:
        return forfeit(match.match_id, exc.role, str(exc))
    except MatchTimeout as exc:  # the alarm rang outside a policy's call
        if exc.role is not None:  # as the call returned, past its clock and the grace
            return forfeit(match.match_id, exc.role, f"{exc.role} MatchTimeout: {exc}")
        out.update(status="error", error=f"MatchTimeout: {exc}")
        return out
    except Exception as exc:
        tb = traceback.format_exception_only(type(exc), exc)[-1].strip()
        out.update(status="error", error=tb)
        return out
    rec = result.to_record()
    out.update(
        status="ok",
        winner=result.winner,
        cause=result.cause,
        feature=result.feature,
        escape_time=result.escape_time,
        steps=result.steps,
        dt=result.dt,
        decide_pursuer=result.decide_seconds["pursuer"],
        decide_evader=result.decide_seconds["evader"],
        wall_seconds=result.wall_seconds,
        record=json.dumps(rec, sort_keys=True, default=str),
    )
    return out
