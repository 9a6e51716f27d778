"""Playing matches where the executors put them: the same code in every backend.

The driver builds one :class:`Context` per run (maps, resolved env parameters, roster,
model files as bytes) and ships it to each worker once; tasks are small
:class:`~analysis.tournament.identity.Match` records naming labels. :func:`play` turns a
match into an *outcome* dict for :meth:`Store.record`:

* ``ok`` -- the episode was played out (the record of :func:`strategies.runner.run_episode`);
* ``forfeit`` -- a policy raised, or overran the match's time limit: the other side wins,
  ``blame`` names the role at fault, ``error`` says what happened;
* ``error`` -- the match could not be played (no start exists, a bad env parameter):
  nobody wins.

A hang is cut short twice: the runner checks the time limit between steps, and a
``SIGALRM`` one second later interrupts a policy stuck inside one call (where the
platform allows it: the main thread of a POSIX process). The process backend also kills
a worker whose match runs past the limit plus a grace period (a hang in C code).
"""

from __future__ import annotations

import contextlib
import json
import os
import signal
import tempfile
import threading
import traceback
import warnings
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from analysis.tournament.identity import Match
from analysis.tournament.spec import PolicyEntry, Spec
from envs.errors import RhoAboveOneWarning

__all__ = ["Context", "MatchTimeout", "context_for", "play", "warm_up"]

ALARM_GRACE = 1.0
"""Seconds past the time limit before ``SIGALRM`` interrupts a policy inside one call."""


class MatchTimeout(Exception):
    """Raised inside a hung call by the ``SIGALRM`` handler (the runner blames its role)."""


@dataclass
class Context:
    """Everything a worker needs to play any match of a run.

    Attributes:
        maps: ``{label: Map}``.
        envs: ``{(map label, variant label): resolved env parameters}``.
        policies: ``{"ROLE:label": PolicyEntry}``.
        models: ``{sha256: model file bytes}`` (shipped once, materialised per worker).
        time_limit: wall-clock seconds per match.
    """

    maps: dict[str, Any]
    envs: dict[tuple[str, str], dict[str, Any]]
    policies: dict[str, PolicyEntry]
    models: dict[str, bytes] = field(default_factory=dict, repr=False)
    time_limit: float = 300.0


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
    key = f"{entry.role}:{entry.model_sha256}:{json.dumps(entry.params, sort_keys=True)}"
    if key not in _LEARNED:
        path = _model_file(ctx, entry.model_sha256)
        _LEARNED[key] = make_policy(f"{entry.role}/sb3:{path}", **entry.params)
    return _LEARNED[key]


@contextlib.contextmanager
def _alarm(seconds: float) -> Iterator[None]:
    """Raise :class:`MatchTimeout` in the main thread after ``seconds`` (where possible)."""
    usable = hasattr(signal, "setitimer") and threading.current_thread() is threading.main_thread()
    if not usable:
        yield
        return

    def _ring(signum: int, frame: Any) -> None:
        raise MatchTimeout(f"no answer within the time limit (+{ALARM_GRACE:g} s)")

    previous = signal.signal(signal.SIGALRM, _ring)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0.0)
        signal.signal(signal.SIGALRM, previous)


def warm_up() -> None:
    """Import what a match imports on first use, before a fresh worker's first match.

    Without it the first match of a worker process imported the env (PettingZoo), the
    start sampler and the observers on its own clock: 0.15 s on an idle machine, 1.2 s at
    load 6 on 2 cores (compiled from source where no bytecode is cached), against a time
    limit that a short tournament sets to 1 s, so a quick match could forfeit or be stored
    as a ``MatchTimeout`` error for time it never used.
    """
    import envs.surveillance_v1  # noqa: F401
    import strategies.policies.observe
    import strategies.policies.starts
    import strategies.runner  # noqa: F401
    from strategies.policies.registry import policy_names

    policy_names()  # the catalog of built-in policies


def play(match: Match, ctx: Context) -> dict[str, Any]:
    """Play one match; never raises for a failure of the match itself (see the module)."""
    from strategies.runner import PolicyFailure, run_episode

    out: dict[str, Any] = {"match_id": match.match_id}
    try:
        p = ctx.policies[f"pursuer:{match.pursuer}"]
        e = ctx.policies[f"evader:{match.evader}"]
        env = ctx.envs[(match.map, match.variant)]
        observations = {"pursuer": p.observation, "evader": e.observation}
        with _alarm(ctx.time_limit + ALARM_GRACE), warnings.catch_warnings():
            warnings.simplefilter("ignore", RhoAboveOneWarning)  # said once, at spec load
            result = run_episode(
                ctx.maps[match.map],
                build_policy(ctx, p),
                build_policy(ctx, e),
                match.seed,
                overrides=env,
                start=match.start,
                observations=observations,
                time_limit=ctx.time_limit,
            )
    except PolicyFailure as exc:
        out.update(
            status="forfeit",
            winner="evader" if exc.role == "pursuer" else "pursuer",
            blame=exc.role,
            error=str(exc),
        )
        return out
    except MatchTimeout as exc:  # the alarm rang outside policy code
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
