"""Every pursuer against every evader on the built-in worlds: surveillance rates and escape times.

Plays seeded episodes from safe starts (a non-escapable cell at L_min, admissible, where
one exists; any valid start otherwise) with :func:`analysis.evaluate.evaluate`, stores
them in a SQLite tournament store as they finish (rerun the same command to resume), and
prints

* the matchup table: surveillance success rate with its Wilson 95% interval, mean time to
  escape with its Student t 95% interval, escape causes;
* the theory's predictions (Secs. 4-6) checked against the table;
* the decomposition pursuer's per-step decision time, against the greedy pursuer's
  (a reference measured in the same run).

Usage::

    python benchmarks/analytic_matchups.py [--seeds 10] [--maps corridor two_rooms ...]
        [--max-cycles 1000] [--results out/analytic_matchups.sqlite] [--workers 2]
"""

from __future__ import annotations

import argparse
import json
import math
import time

import numpy as np
from bench_cli import integer, path_text, run

from analysis.evaluate import evaluate, format_table
from analysis.tournament import spec_from_dict
from envs.maps import builtin_names
from strategies.policies import make_policy, policy_names
from strategies.policies.starts import sample_start
from strategies.runner import build_env

FAST_RHO = {"v_evader": 1.5}  # rho = 1.5 with the built-ins' V_p = 1


def _rows(rows, **match):
    return [r for r in rows if all(getattr(r, k) == v for k, v in match.items())]


def check_theory(rows, fast_rows) -> list[str]:
    """The predictions of the issue, one line each: PASS/FAIL and the numbers."""
    out = []
    held = {(r.map, r.pursuer, r.evader): r for r in rows}
    corridor = _rows(rows, map="corridor", pursuer="pursuer/decomposition")
    if corridor:
        bad = [r.evader for r in corridor if r.held != r.n]
        out.append(
            f"{'PASS' if not bad else 'FAIL'} corridor, rho=0.5, safe start: decomposition "
            f"pursuer holds against every evader" + (f" (not against {bad})" if bad else "")
        )
    two = _rows(rows, map="two_rooms", evader="evader/shooting")
    if two:
        bad = [r.pursuer for r in two if r.held > 0]
        out.append(
            f"{'PASS' if not bad else 'FAIL'} two_rooms: shooting evader escapes from every "
            f"pursuer" + (f" (not from {bad})" if bad else "")
        )
    if fast_rows:
        bad = [(r.map, r.pursuer, r.evader) for r in fast_rows if r.held > 0]
        out.append(
            f"{'PASS' if not bad else 'FAIL'} rho=1.5: the evader escapes everywhere"
            + (f" (not in {bad})" if bad else "")
        )
    worse = []
    for (m, p, e), r in held.items():
        if p == "pursuer/decomposition" and (m, "pursuer/greedy", e) in held:
            g = held[(m, "pursuer/greedy", e)]
            if r.rate < g.rate:
                worse.append((m, e, r.rate, g.rate))
    out.append(
        f"{'PASS' if not worse else 'FAIL'} decomposition pursuer >= greedy pursuer in every "
        f"matchup" + (f" (worse in {worse})" if worse else "")
    )
    slower = []
    for (m, p, e), r in held.items():
        if e == "evader/shooting" and (m, p, "evader/straight") in held:
            s = held[(m, p, "evader/straight")]
            if r.escape_mean > s.escape_mean or (r.held > s.held):
                slower.append((m, p, round(r.escape_mean, 2), round(s.escape_mean, 2)))
    out.append(
        f"{'PASS' if not slower else 'NOTE'} shooting evader escapes sooner (and at least as "
        "often) than the straight-line evader" + (f" (not in {slower})" if slower else "")
    )
    return out


def decision_times(map_name: str = "corridor", steps: int = 2000, seed: int = 0) -> str:
    """Per-step decision time of the decomposition pursuer vs the greedy pursuer."""
    env = build_env(map_name)
    cfg = env.config
    start = sample_start(cfg, np.random.default_rng(seed))
    obs, _ = env.reset(seed=seed, options=start)
    rng = np.random.default_rng(seed)
    observations = []
    while len(observations) < steps:
        observations.append(obs["pursuer_0"])
        a = rng.uniform(-1, 1, size=2)
        p = np.zeros(2, dtype=np.float32)
        obs, _, term, trunc, _ = env.step({"pursuer_0": p, "evader_0": a})
        if term["pursuer_0"] or trunc["pursuer_0"]:
            obs, _ = env.reset(seed=seed + len(observations), options=start)
    res = {}
    for name in ("pursuer/greedy", "pursuer/decomposition"):
        pol = make_policy(name)
        pol.reset(role="pursuer", map=cfg.map, config=cfg, seed=seed)
        t0 = time.perf_counter()
        for o in observations:
            pol.act(o)
        res[name] = (time.perf_counter() - t0) / len(observations)
    d, g = res["pursuer/decomposition"], res["pursuer/greedy"]
    return (
        f"decision time on {map_name} ({steps} steps): decomposition {d * 1e6:.0f} us/step, "
        f"greedy {g * 1e6:.0f} us/step, ratio {d / g:.1f}x"
    )


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--maps", nargs="+", default=builtin_names())
    ap.add_argument("--pursuers", nargs="+", default=policy_names("pursuer"))
    ap.add_argument("--evaders", nargs="+", default=policy_names("evader"))
    ap.add_argument("--seeds", type=integer(1), default=10)
    ap.add_argument("--fast-seeds", type=integer(0), default=3, help="seeds of the rho > 1 rows")
    ap.add_argument("--max-cycles", type=integer(1), default=1000)
    ap.add_argument(
        "--results",
        type=path_text("a results database file"),
        default="out/analytic_matchups.sqlite",
    )
    ap.add_argument("--workers", type=integer(1), default=2)
    args = ap.parse_args(argv)
    roster = {"maps": args.maps, "pursuers": args.pursuers, "evaders": args.evaders}
    try:  # the names, checked as the tournament will (before any episode)
        spec_from_dict({"name": "evaluate", **roster, "seeds": [0]}, source="arguments")
    except ValueError as exc:  # the project's errors subclass ValueError
        ap.error(str(exc))
    common = dict(max_cycles=args.max_cycles, results_path=args.results, workers=args.workers)
    rows = evaluate(args.maps, args.pursuers, args.evaders, range(args.seeds), **common)
    fast = []  # --fast-seeds 0: no rho > 1 rows
    if args.fast_seeds > 0:
        fast = evaluate(
            args.maps,
            args.pursuers,
            ["evader/shooting", "evader/straight"],
            range(args.fast_seeds),
            overrides=FAST_RHO,
            **common,
        )
    print(format_table(rows + fast))
    print()
    for line in check_theory(rows, fast):
        print(line)
    print()
    print(decision_times())
    summary = {
        "episodes": sum(r.n for r in rows + fast),
        "mean_rate": float(np.mean([r.rate for r in rows if not math.isnan(r.rate)])),
    }
    print(json.dumps(summary))
    return 0


if __name__ == "__main__":
    raise SystemExit(run(main))
