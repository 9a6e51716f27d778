"""Compatibility names for the old evaluation module.

The episode loop lives in :mod:`strategies.runner` (``run_episode``), tournaments in
:mod:`analysis.tournament` (``surveil tournament``); this module keeps the old names:
:func:`play_episode`, :func:`make_env`, the interval functions and :func:`evaluate`
(a one-off tournament, returning :class:`MatchupRow` rows).
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from analysis.tournament.statistics import (
    bootstrap_mean_interval,
    t_mean_interval,
    wilson_interval,
)
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


def make_env(map_: Any, overrides: Mapping[str, Any] | None = None, *, record: bool = False):
    """A ``surveillance_v1`` parallel env with the state observation (see
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

    A one-off tournament (:func:`analysis.tournament.run_tournament`): results go to the
    SQLite store ``results_path`` (default: a temporary one), which resumes. Duplicate
    names are played once. Returns one :class:`MatchupRow` per (overrides, map, pursuer,
    evader).

    Raises:
        KeyboardInterrupt: SIGINT or SIGTERM stopped the tournament (its name is the
            message); the matches played so far are in the store.
    """
    import tempfile

    from analysis.tournament import run_tournament, spec_from_dict
    from analysis.tournament import statistics as st
    from analysis.tournament.store import Store

    if overrides is None or isinstance(overrides, Mapping):
        variants = [dict(overrides or {})]
    else:
        variants = [dict(o) for o in overrides]
    if max_cycles is not None:
        variants = [{**v, "max_cycles": int(max_cycles)} for v in variants]
    maps, pursuers, evaders = (
        list(maps),
        list(dict.fromkeys(pursuers)),
        list(dict.fromkeys(evaders)),
    )
    seeds = list(seeds)
    rows: list[MatchupRow] = []
    with tempfile.TemporaryDirectory() as tmp:
        store = Path(results_path) if results_path is not None else Path(tmp) / "evaluate.sqlite"
        for v in variants:
            spec = spec_from_dict(
                {
                    "name": "evaluate",
                    "maps": maps,
                    "pursuers": pursuers,
                    "evaders": evaders,
                    "seeds": seeds,
                    "start": start,
                    "env": v,
                },
                source="evaluate()",
            )
            summary = run_tournament(
                spec,
                store,
                backend="serial" if workers <= 1 else "process",
                workers=max(workers, 1),
                progress=progress,
            )
            if summary.interrupted:  # the store keeps what was played: the same call resumes
                raise KeyboardInterrupt(summary.interrupted)
            with Store(store, create=False) as db:
                cells = st.cells(db.rows(summary.run_id), confidence=confidence, overall=False)
            for c in cells:
                rows.append(
                    MatchupRow(
                        c.scope,
                        c.pursuer,
                        c.evader,
                        json.dumps(v, sort_keys=True),
                        c.n,
                        c.held,
                        c.rate,
                        c.lo,
                        c.hi,
                        c.escape_mean,
                        c.escape_lo,
                        c.escape_hi,
                        {k: n for k, n in c.causes.items()},
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
