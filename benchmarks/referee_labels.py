"""The referee's verdict on a benchmark's starts (``pursuer_holds.py`` and
``unseen_worlds.py``, ``--referee CPL``).

A start is classified by the referee (:mod:`strategies.referee`, the bounded-speed
ground truth) at ``CPL`` cells per L_min, with a fine evader lattice (2 cells a spacing,
1 spacing a step): ``"evader"`` (certified: no bounded-speed pursuer holds it, a loss
from it is unavoidable), ``"pursuer"`` (certified: some pursuer holds it, a loss is the
policy's regret), ``"unknown"`` (the referee's resolution gap; at rho >= 0.35 the pursuer
bound certifies nothing, so there every verdict is ``"evader"`` or ``"unknown"``),
``"not a start"`` (surveillance does not hold there) or ``"not solved"`` (the solve would
exceed the referee's memory budget, ``$SURVEIL_MEMORY_BUDGET``; the message, printed once
per world, names the CPL that fits).

A world that is a similarity (rotation, uniform scaling, shift) of another is judged on
the other: scaling lengths and speeds by one factor and moving the plane leave the game
unchanged (time is not scaled), so :func:`verdict` maps the start back with
:func:`similarity_back` and the variants of one world share one solve (cached on disk:
minutes per world the first time, ``SURVEIL_CACHE_DIR``).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Mapping

import numpy as np

from envs.errors import InfeasibleError, InvalidPlacementError, MemoryBudgetError
from envs.maps import Map

__all__ = [
    "MEANING",
    "hindsight_summary",
    "judge",
    "similarity_back",
    "summary",
    "tally",
    "unknown_why",
    "verdict",
]

# the referee's resolution besides CPL: a fine evader lattice (as pursuer_holds.py always had)
SOLVE = {"evader_coarse": 2, "evader_steps": 1}
MEANING = {
    "evader": "unavoidable",
    "pursuer": "the policy's regret",
    "unknown": "the referee's resolution gap",
}

_last: tuple[object, object] | None = None  # (cache key, Referee): one world at a time


def similarity_back(
    rot: float, scale: float, offset: Iterable[float]
) -> Callable[[object], np.ndarray]:
    """The inverse of ``x -> scale R(rot) x + offset`` (how a variant was made)."""
    c, s = math.cos(rot), math.sin(rot)
    r = np.array([[c, -s], [s, c]])
    off = np.asarray(tuple(offset), float)
    return lambda q: (np.asarray(q, float) - off) / scale @ r


def _referee(m: Map, overrides: Mapping[str, float], cpl: float):
    """The world's referee, or the InfeasibleError that refused its solve (the memory
    budget, ``$SURVEIL_MEMORY_BUDGET``): one world at a time."""
    from envs.surveillance.config import EnvConfig
    from strategies.referee import referee_for

    global _last
    cfg = EnvConfig(map=m, **overrides)
    key = (m.digest, tuple(sorted(overrides.items())), float(cpl), cfg.dt)
    if _last is None or _last[0] != key:
        try:
            with MemoryBudgetError.naming("--referee CPL"):  # the scripts' flag
                _last = (key, referee_for(cfg, cpl, **SOLVE))
        except InfeasibleError as exc:
            print(f"  referee (cpl {cpl:g}) not solved on map {m.name!r}: {exc}", flush=True)
            _last = (key, exc)
    return _last[1]


def verdict(
    m: Map,
    overrides: Mapping[str, float],
    start: Mapping[str, object],
    cpl: float,
    back: Callable[[object], np.ndarray] | None = None,
) -> str:
    """The referee's label of ``start`` (``{"pursuer": (x, y), "evader": (x, y)}``) in the
    game on ``m`` with env ``overrides`` (``l_min, l_max, v_pursuer, v_evader,
    body_radius``), at ``cpl`` cells per L_min; ``back`` maps the start's points into
    ``m`` when the start was played on a similar world. ``"not solved"`` when the solve
    would exceed the memory budget (the reason is printed once per world): the other
    worlds are still labelled."""
    return judge(m, overrides, start, cpl, back)[0]


def judge(
    m: Map,
    overrides: Mapping[str, float],
    start: Mapping[str, object],
    cpl: float,
    back: Callable[[object], np.ndarray] | None = None,
) -> tuple[str, float | None]:
    """(:func:`verdict`'s label, the certified escape time): for a start certified for
    the evader, a bound on the time the evader needs to break surveillance against any
    pursuer (:meth:`Referee.escape_time`, seconds of the game), else None."""
    back = back or (lambda q: np.asarray(q, float))
    ref = _referee(m, overrides, cpl)
    if isinstance(ref, InfeasibleError):
        return "not solved", None
    p, e = back(start["pursuer"]), back(start["evader"])
    try:
        label = ref.classify(p, e)
    except InvalidPlacementError:
        return "not a start", None
    return label, ref.escape_time(p, e) if label == "evader" else None


def unknown_why(m: Map, overrides: Mapping[str, float], cpl: float) -> str | None:
    """Why a start of this game can be ``"unknown"`` whatever it is, or None.

    An ``"unknown"`` start is the referee's resolution gap only where the bounds certify
    something of the game. Where the pursuer bound certifies no state of it (issue 13's
    blind spot: from rho ~ 0.3, a range band narrow against the evader's step, passages
    the bound's pursuer cannot pass the evader in; ``strategies.referee.pursuer_bound``),
    every start the evader bound leaves is unknown, so an unknown says nothing about that
    start; likewise where the evader bound certifies no state. The same solve as
    :func:`judge`'s (one world at a time, so right after it no solve is repeated)."""
    ref = _referee(m, overrides, cpl)
    if isinstance(ref, InfeasibleError):
        return None
    # the evader bound's rank 0 is a state broken already (out of range, occluded)
    pursuer, evader = bool(ref.pursuer.win.any()), bool((ref.evader.rank > 0).any())
    if pursuer and evader:
        return None
    if not (pursuer or evader):
        return "neither bound certified a state of this game"
    return ("the pursuer bound certified no state of this game" if evader else
            "the evader bound certified no escape from a state of this game")  # fmt: skip


def tally(verdicts: Iterable[str], gap: str = MEANING["unknown"]) -> tuple[int, str]:
    """(n, ``a evader (unavoidable), b pursuer (the policy's regret), c unknown (GAP)``)
    (and any other label, e.g. ``not a start``, with its count): one verdict per loss;
    ``gap`` says what an ``unknown`` is (the referee's resolution gap by default)."""
    meaning = {**MEANING, "unknown": gap}
    counts = {v: 0 for v in meaning}
    n = 0
    for v in verdicts:
        counts[v] = counts.get(v, 0) + 1
        n += 1
    parts = [f"{k} {v} ({meaning[v]})" if v in meaning else f"{k} {v}" for v, k in counts.items()]
    return n, ", ".join(parts)


def summary(cpl: float, verdicts: Iterable[str], distinct: int | None = None) -> str:
    """``referee (cpl X) on the N lost starts (K distinct): a evader (unavoidable), b
    pursuer (the policy's regret), c unknown (...)`` (and any ``not a start``): one verdict
    per lost episode; ``distinct`` says how many starts they are (opponents share them)."""
    n, parts = tally(verdicts)
    of = "" if distinct is None else f" ({distinct} distinct)"
    return f"referee (cpl {cpl:g}) on the {n} lost starts{of}: " + parts


def hindsight_summary(cell: float, verdicts: Iterable[str]) -> str:
    """``hindsight (cell H) on the N losses to open-loop evaders: a evader (unavoidable), b
    pursuer (the policy's regret), c unknown (the hindsight's resolution gap)``: one
    verdict per lost episode (:mod:`strategies.referee.hindsight`, against the evader's
    recorded path to the episode's horizon)."""
    n, parts = tally(verdicts, "the hindsight's resolution gap")
    return f"hindsight (cell {cell:g}) on the {n} losses to open-loop evaders: " + parts


def rotation_bound_summary(verdicts: Iterable[str]) -> str:
    """``rotation bound on the N losses to open-loop evaders: a certain (unavoidable: no
    pursuer holds past the time given), b not proven``: one verdict (``certain by T s`` or
    ``not proven``) per lost episode (:mod:`strategies.referee.rotation_bound`, against the
    evader's recorded path to the episode's horizon)."""
    verdicts = list(verdicts)
    certain = sum(v.startswith("certain") for v in verdicts)
    return (
        f"rotation bound on the {len(verdicts)} losses to open-loop evaders: {certain} certain "
        f"(unavoidable: no pursuer holds past the time given), {len(verdicts) - certain} not "
        "proven"
    )
