"""Play registered policies against each other: one episode, or a seeded matchup table.

:func:`play_episode` runs one episode of ``surveillance_v0`` between two policies from
a start drawn by :func:`strategies.policies.starts.sample_start` (valid surveillance
configurations, optionally in a safe cell at ``L_min``) and returns an
:class:`EpisodeResult`. :func:`evaluate` plays every pursuer against every evader on
every map for many seeds, appends one JSON line per episode as it goes (an interrupted
run resumes where it stopped) and aggregates a table of surveillance success rates
(Wilson intervals) and mean times to escape (Student t intervals).
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from scipy import stats

from envs.errors import InvalidConfigError
from strategies.runner import EpisodeResult

__all__ = [
    "EpisodeResult",
    "MatchupRow",
    "bootstrap_mean_interval",
    "evaluate",
    "format_table",
    "make_env",
    "play_episode",
    "t_mean_interval",
    "wilson_interval",
]

PURSUER, EVADER = "pursuer_0", "evader_0"


# --------------------------------------------------------------------------- statistics
def _check_confidence(confidence: float) -> float:
    c = float(confidence)
    if not 0.0 < c < 1.0:
        raise InvalidConfigError(f"confidence must be in (0, 1), got {confidence!r}")
    return c


def wilson_interval(successes: int, n: int, confidence: float = 0.95) -> tuple[float, float]:
    """Wilson score interval of a binomial proportion (``n = 0`` gives ``(0, 1)``).

    Examples:
        >>> lo, hi = wilson_interval(8, 10)
        >>> round(lo, 4), round(hi, 4)
        (0.4902, 0.9433)
    """
    c = _check_confidence(confidence)
    if n < 0 or not 0 <= successes <= n:
        raise InvalidConfigError(f"need 0 <= successes <= n, got successes={successes}, n={n}")
    if n == 0:
        return (0.0, 1.0)
    z = float(stats.norm.ppf(0.5 + c / 2))
    if successes in (0, n):  # exact ends: 0 (resp. 1) without rounding residue
        edge = z * z / (n + z * z)
        return (0.0, edge) if successes == 0 else (1.0 - edge, 1.0)
    p = successes / n
    denom = 1 + z * z / n
    centre = (p + z * z / (2 * n)) / denom
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / denom
    return (max(0.0, centre - half), min(1.0, centre + half))


def t_mean_interval(
    values: Sequence[float], confidence: float = 0.95
) -> tuple[float, float, float]:
    """``(mean, lo, hi)`` with a Student t interval; NaNs when empty, infinite for one value."""
    c = _check_confidence(confidence)
    x = np.asarray(values, dtype=float)
    if x.size == 0:
        return (math.nan, math.nan, math.nan)
    m = float(x.mean())
    if x.size == 1:
        return (m, -math.inf, math.inf)
    h = float(stats.t.ppf(0.5 + c / 2, x.size - 1)) * float(x.std(ddof=1)) / math.sqrt(x.size)
    return (m, m - h, m + h)


def bootstrap_mean_interval(
    values: Sequence[float], confidence: float = 0.95, *, n_resamples: int = 2000, seed: int = 0
) -> tuple[float, float, float]:
    """``(mean, lo, hi)`` with a percentile bootstrap interval; NaNs when empty."""
    c = _check_confidence(confidence)
    x = np.asarray(values, dtype=float)
    if x.size == 0:
        return (math.nan, math.nan, math.nan)
    rng = np.random.default_rng(seed)
    means = x[rng.integers(0, x.size, size=(n_resamples, x.size))].mean(axis=1)
    lo, hi = np.quantile(means, [0.5 - c / 2, 0.5 + c / 2])
    return (float(x.mean()), float(lo), float(hi))


# --------------------------------------------------------------------------- one episode
def make_env(map_: Any, overrides: Mapping[str, Any] | None = None, *, record: bool = False):
    """A ``surveillance_v0`` parallel env with the state observation (see
    :func:`strategies.runner.build_env`)."""
    from strategies.runner import build_env

    return build_env(
        map_,
        {**dict(overrides or {}), "observation": "state"},
        render_mode="rgb_array" if record else None,
    )


def play_episode(
    map: Any,
    pursuer: Any,
    evader: Any,
    seed: int = 0,
    *,
    max_cycles: int | None = None,
    overrides: Mapping[str, Any] | None = None,
    options: Mapping[str, Any] | None = None,
    start: str = "safe",
    record: bool = False,
) -> EpisodeResult:
    """One episode: a thin alias of :func:`strategies.runner.run_episode`.

    ``options`` (an explicit start ``{"pursuer": (x, y), "evader": (x, y)}``) wins over
    ``start``; ``record`` keeps the rendered frames in ``result.frames``.
    """
    from strategies.runner import run_episode

    return run_episode(
        map,
        pursuer,
        evader,
        seed,
        max_cycles=max_cycles,
        overrides=overrides,
        start=dict(options) if options is not None else start,
        record=record,
    )


# --------------------------------------------------------------------------- many episodes
@dataclass(frozen=True)
class MatchupRow:
    """Aggregate of one (map, pursuer, evader, overrides) cell of the table.

    Attributes:
        map, pursuer, evader: names.
        overrides: the env overrides of this row (JSON text, ``"{}"`` if none).
        n: episodes played.
        held: episodes in which the pursuer kept surveillance to the horizon.
        rate, rate_lo, rate_hi: surveillance success rate and its Wilson interval.
        escape_mean, escape_lo, escape_hi: mean time to escape over the escapes, with a
            Student t interval (NaN when nobody escaped).
        causes: escape causes and their counts.
    """

    map: str
    pursuer: str
    evader: str
    overrides: str
    n: int
    held: int
    rate: float
    rate_lo: float
    rate_hi: float
    escape_mean: float
    escape_lo: float
    escape_hi: float
    causes: dict[str, int]


def _key(rec: Mapping[str, Any]) -> str:
    return json.dumps(
        [
            rec["map"],
            rec["pursuer"],
            rec["evader"],
            int(rec["seed"]),
            rec["overrides"],
            rec.get("start_kind", "safe"),
        ],
        sort_keys=True,
    )


def _play_record(job: tuple) -> dict[str, Any]:
    map_, pursuer, evader, seed, overrides, start = job
    res = play_episode(map_, pursuer, evader, seed, overrides=overrides, start=start)
    rec = res.to_record()
    rec["map"] = map_ if isinstance(map_, str) else res.map
    rec["overrides"] = dict(overrides)
    rec["start_kind"] = start
    return rec


def evaluate(
    maps: Iterable[Any],
    pursuers: Iterable[str],
    evaders: Iterable[str],
    seeds: Iterable[int],
    *,
    max_cycles: int | None = None,
    overrides: Mapping[str, Any] | Sequence[Mapping[str, Any]] | None = None,
    start: str = "safe",
    results_path: str | Path | None = None,
    workers: int = 1,
    progress: bool = True,
    confidence: float = 0.95,
) -> list[MatchupRow]:
    """Play every pursuer against every evader on every map for every seed.

    Args:
        maps: built-in names (or map files / Maps).
        pursuers, evaders: registered policy names.
        seeds: episode seeds.
        max_cycles: horizon in steps (``None``: the env default).
        overrides: one env override dict, or a list of them (each becomes its own rows).
        start: ``"safe"`` or ``"valid"`` drawn starts (see :func:`play_episode`).
        results_path: JSON-lines file; episodes already in it are not replayed, new
            ones are appended as soon as they finish.
        workers: processes to play in (1 = in this process).
        progress: show a tqdm progress bar.
        confidence: level of the intervals.

    Returns:
        One :class:`MatchupRow` per (map, pursuer, evader, overrides), in input order.
    """
    from tqdm import tqdm

    if overrides is None or isinstance(overrides, Mapping):
        variants = [dict(overrides or {})]
    else:
        variants = [dict(o) for o in overrides]
    if max_cycles is not None:
        variants = [{**v, "max_cycles": int(max_cycles)} for v in variants]
    maps, pursuers, evaders, seeds = list(maps), list(pursuers), list(evaders), list(seeds)
    jobs = [
        (m, p, e, int(s), v, start)
        for v in variants
        for m in maps
        for p in pursuers
        for e in evaders
        for s in seeds
    ]
    done: dict[str, dict[str, Any]] = {}
    path = Path(results_path) if results_path is not None else None
    if path is not None and path.exists():
        for line in path.read_text(encoding="utf-8").splitlines():
            if line.strip():
                try:
                    rec = json.loads(line)
                except json.JSONDecodeError:
                    continue  # a line cut short by an interruption
                done[_key(rec)] = rec
    todo = [j for j in jobs if _key(_job_record_key(j)) not in done]
    if path is not None:
        path.parent.mkdir(parents=True, exist_ok=True)
    out = path.open("a", encoding="utf-8") if path is not None else None
    if out is not None and path.stat().st_size and not path.read_bytes().endswith(b"\n"):
        out.write("\n")  # an interrupted write left half a line: start a fresh one
    try:
        bar = tqdm(
            total=len(jobs), initial=len(jobs) - len(todo), disable=not progress, desc="episodes"
        )
        results = _run(todo, workers)
        for rec in results:
            done[_key(rec)] = rec
            if out is not None:
                out.write(json.dumps(rec) + "\n")
                out.flush()
            bar.update(1)
        bar.close()
    finally:
        if out is not None:
            out.close()
    return _aggregate(jobs, done, variants, maps, pursuers, evaders, confidence)


def _job_record_key(job: tuple) -> dict[str, Any]:
    m, p, e, s, v, start = job
    return {
        "map": m if isinstance(m, str) else m.name,
        "pursuer": p,
        "evader": e,
        "seed": s,
        "overrides": v,
        "start_kind": start,
    }


def _run(todo: list[tuple], workers: int) -> Iterable[dict[str, Any]]:
    if workers <= 1 or len(todo) <= 1:
        for job in todo:
            yield _play_record(job)
        return
    from concurrent.futures import ProcessPoolExecutor, as_completed

    with ProcessPoolExecutor(max_workers=workers) as pool:
        futures = [pool.submit(_play_record, job) for job in todo]
        for fut in as_completed(futures):
            yield fut.result()


def _aggregate(jobs, done, variants, maps, pursuers, evaders, confidence) -> list[MatchupRow]:
    rows = []
    for v in variants:
        for m in maps:
            for p in pursuers:
                for e in evaders:
                    recs = [
                        done[_key(_job_record_key(j))]
                        for j in jobs
                        if j[0] is m and j[1] == p and j[2] == e and j[4] == v
                    ]
                    held = sum(r["winner"] == "pursuer" for r in recs)
                    lo, hi = wilson_interval(held, len(recs), confidence)
                    times = [r["escape_time"] for r in recs if r["winner"] == "evader"]
                    mean, tlo, thi = t_mean_interval(times, confidence)
                    causes: dict[str, int] = {}
                    for r in recs:
                        if r["cause"]:
                            causes[r["cause"]] = causes.get(r["cause"], 0) + 1
                    rows.append(
                        MatchupRow(
                            map=m if isinstance(m, str) else m.name,
                            pursuer=p,
                            evader=e,
                            overrides=json.dumps(v, sort_keys=True),
                            n=len(recs),
                            held=held,
                            rate=held / len(recs) if recs else math.nan,
                            rate_lo=lo,
                            rate_hi=hi,
                            escape_mean=mean,
                            escape_lo=tlo,
                            escape_hi=thi,
                            causes=causes,
                        )
                    )
    return rows


def _fmt_time(mean: float, lo: float, hi: float) -> str:
    if math.isnan(mean):
        return "-"
    if not math.isfinite(lo):
        return f"{mean:.2f}"
    return f"{mean:.2f} [{max(lo, 0.0):.2f}, {hi:.2f}]"


def format_table(rows: Sequence[MatchupRow]) -> str:
    """Plain-text table: map, pursuer, evader, overrides, n, success rate [Wilson], escape time."""
    head = (
        "map",
        "overrides",
        "pursuer",
        "evader",
        "n",
        "surveillance held [95% CI]",
        "mean escape s [95% CI]",
        "causes",
    )
    body = [
        (
            r.map,
            "" if r.overrides == "{}" else r.overrides,
            r.pursuer,
            r.evader,
            str(r.n),
            f"{r.rate:.2f} [{r.rate_lo:.2f}, {r.rate_hi:.2f}]",
            _fmt_time(r.escape_mean, r.escape_lo, r.escape_hi),
            ",".join(f"{k}:{c}" for k, c in sorted(r.causes.items())),
        )
        for r in rows
    ]
    widths = [max(len(x[i]) for x in [head, *body]) for i in range(len(head))]
    line = lambda cells: "  ".join(c.ljust(w) for c, w in zip(cells, widths, strict=False))
    return "\n".join([line(head), line(["-" * w for w in widths]), *map(line, body)])
