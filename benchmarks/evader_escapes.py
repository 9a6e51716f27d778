"""Does the shooting evader escape on evader-win worlds? Every pursuer, every variant.

Issue 13's goal: on worlds where the evader wins (Prop. 2: every cell escapable,
``strategies.cspace.decompose(world, L).evader_wins``) the shooting evader escapes in
every episode against every pursuer in the registry, within a horizon proportional to
the map's diameter D (its bounding-box diagonal) over V_e. This plays seeded episodes
through the shared runner (:func:`strategies.runner.run_episode`) from the project's
start sampler on

* the evader-win built-ins (``two_rooms``, ``office``) as is, rotated, rescaled and
  off-centre (like ``benchmarks/pursuer_holds.py``, ``Map.transformed``),
* a plus-shaped crossroads and a T-junction (corridors 1.6 wide, L_min = 2),
* seeded random maps of each kind on which Prop. 2 holds,

against every registered pursuer plus one that stands still, and prints the escape
rate per world and pursuer, the escape time in units of D / V_e (quantiles), every
failure (seed, world, pursuer, the evader's modes over the episode and where it ended),
the same starts played by the simple evaders (straight, toward/away, wall hugging) for
comparison, and the shooting evader's decision time per step against the straight
evader's in the same run.

Horizon: ``K * D / V_e`` with K = 8 by default. A guaranteed plan (Sec. 4) walks the
evader through at most a few regions, each walk no longer than a path across the map
(about D, up to ~2 D round obstacles); K = 8 leaves room for a plan of a few ranks
plus the pressure fallback at the start, and is still short enough that a freeze or a
loop shows as a failure rather than as a late escape. The printed quantiles show how
much of it is used.

Usage::

    python benchmarks/evader_escapes.py [--seeds 4] [--simple-seeds 2] [--k 8]
        [--workers 2] [--worlds two_rooms plus ...] [--pursuers pursuer/greedy ...]
        [--start safe] [--progress] [--results F.jsonl]

Each failure (the pursuer held) is printed as it happens, and a progress line every 20
jobs (``--progress``: a line per job). With ``--results F.jsonl`` every job (the shooting
evader's episode and the simple evaders' from the same start) is appended to F as it
completes (JSON lines, ``benchmarks/episode_rows.py``; ``start_drawn``: the start the
seed drew, which ``policy_sets.py label`` judges); the same command with the same F
after a stop plays only the jobs missing from it and reports over all of them.

The simple evaders play only the first ``--simple-seeds`` seeds (they lose often, and a
lost episode runs the whole horizon). The full default run takes about an hour on two
busy cores; ``--simple-seeds 0`` about a quarter of that. ``start="safe"`` falls back
to a valid start at L_min on these worlds (no safe cell exists).
"""

from __future__ import annotations

import argparse
import collections
import contextlib
import math
import os
import time

import episode_rows
import numpy as np
from bench_cli import integer, real, results_file, run, worker_pool

from envs.maps import Map, builtin_info, load_map
from envs.maps.junctions import crossroads, t_junction
from strategies.policies.base import BasePolicy
from strategies.runner import run_episode

BASE = {"l_min": 2.0, "l_max": 4.0, "v_pursuer": 1.0, "v_evader": 0.5}
SIMPLE = ["evader/straight", "evader/toward_away", "evader/toward_away:away", "evader/wall_hugging"]
# (label, rotation in radians, scale, offset)
VARIANTS = {
    "as is": (0.0, 1.0, (0.0, 0.0)),
    "rot 0.37": (0.37, 1.0, (0.0, 0.0)),
    "x0.1": (0.0, 0.1, (0.0, 0.0)),
    "x10 rot 1.1": (1.1, 10.0, (0.0, 0.0)),
    "off-centre": (0.0, 1.0, (13.7, -4.2)),
}
# random maps of each kind on which Prop. 2 holds at L_min + body radius = 2.1
RANDOM = ["random:polygons:0", "random:convex:1", "random:star:2", "random:rectangles:0"]
WORLDS = ["two_rooms", "office", "plus", "tee", *RANDOM]


class StandStill(BasePolicy):
    """A pursuer that does not move."""

    roles = ("pursuer",)

    def _decide(self, snap):
        return np.zeros(2)


def world(name: str, variant: str = "as is") -> tuple[Map, dict]:
    """The map and env overrides of a world variant (lengths and speeds scaled with it)."""
    rot, scale, offset = VARIANTS[variant]
    if name == "plus":
        m, params = crossroads(), dict(BASE)
    elif name == "tee":
        m, params = t_junction(), dict(BASE)
    elif name.startswith("random:"):
        m, params = load_map(name), dict(BASE)
    else:
        info = builtin_info(name)
        m, params = info.map, dict(info.params())
    c, s = math.cos(rot), math.sin(rot)
    m = m.transformed(scale * np.array([[c, -s], [s, c]]), offset)
    for k in ("l_min", "l_max", "v_pursuer", "v_evader"):
        params[k] = params[k] * scale
    params["body_radius"] = 0.1 * scale
    return m, params


def diameter(m: Map) -> float:
    x0, y0, x1, y1 = m.bounds
    return math.hypot(x1 - x0, y1 - y0)


def _policy(label: str):
    from strategies.policies import make_policy

    if label == "still":
        return StandStill()
    if label == "evader/toward_away:away":
        return make_policy("evader/toward_away", mode="away")
    if label == "evader/shooting":
        return make_policy(label)
    return label


def _play(job):
    name, variant, pursuer, seed, k, start, simple = job
    m, params = world(name, variant)
    unit_t = diameter(m) / params["v_evader"]
    max_cycles = math.ceil(k * unit_t / 0.1)
    ev = _policy("evader/shooting")
    modes: collections.Counter = collections.Counter()

    def on_step(tr):
        modes[ev.mode] += 1

    r = run_episode(m, _policy(pursuer), ev, seed, max_cycles=max_cycles, overrides=params,
                    start=start, on_step=on_step)  # fmt: skip
    end = r.trajectory[-1].tolist()
    out = {
        "shooting": [r.winner, r.escape_time, r.decide_seconds["evader"], dict(modes), end],
        "steps": r.steps,
        "unit": unit_t,
    }
    for e in simple:
        s = run_episode(m, _policy(pursuer), _policy(e), seed, max_cycles=max_cycles,
                        overrides=params, start=start)  # fmt: skip
        out[e] = [s.winner, s.escape_time, s.decide_seconds["evader"], s.steps]
    start_drawn = {k: [float(x) for x in v] for k, v in r.start.items()}  # the referee's labels
    return {**dict(zip(_KEY, job, strict=True)), "out": out, "start_drawn": start_drawn}


_KEY = ("world", "variant", "pursuer", "seed", "k", "start", "simple")
"""What identifies an episode (its row's fields): a rerun skips the rows it finds."""


def _row_key(row: dict) -> str:
    return episode_rows.key(row[k] for k in _KEY)


def main(argv=None) -> int:
    from strategies.cspace import decompose
    from strategies.policies import policy_names
    from strategies.policies.starts import START_KINDS

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    pursuers = [*policy_names("pursuer"), "still"]
    ap.add_argument("--seeds", type=integer(1), default=4)
    ap.add_argument("--k", type=real(0), default=8.0, help="horizon in units of D / V_e")
    ap.add_argument("--workers", type=integer(1), default=2)
    ap.add_argument("--worlds", nargs="+", default=WORLDS, help="built-in names, plus, tee, "
                    "random:KIND:SEED (default: %(default)s)")  # fmt: skip
    ap.add_argument("--variants", nargs="+", choices=list(VARIANTS), default=list(VARIANTS))
    ap.add_argument("--pursuers", nargs="+", choices=pursuers, default=pursuers)
    ap.add_argument("--start", choices=START_KINDS, default="safe",
                    help="start kind of the start sampler")  # fmt: skip
    ap.add_argument(
        "--simple-seeds",
        type=integer(0),
        default=2,
        help="seeds (the first ones) also played by the "
        "simple evaders, from the same starts (0: none)",
    )
    ap.add_argument("--progress", action="store_true",
                    help="a line per job (default: every 20 jobs, and each failure)")  # fmt: skip
    ap.add_argument("--results", metavar="FILE", default=None, type=results_file,
                    help="append each episode to FILE (JSON lines) as it completes; a rerun "
                    "with the same FILE plays only the episodes missing from it")  # fmt: skip
    args = ap.parse_args(argv)
    for w in args.worlds:
        try:
            world(w)
        except (ValueError, KeyError) as exc:  # the project's errors subclass ValueError
            ap.error(f"--worlds: {w!r} is no world ({exc}; the default set: {WORLDS})")
    print(f"load average: {os.getloadavg()}")
    simple = SIMPLE if args.simple_seeds > 0 else []
    jobs = []
    for w in args.worlds:
        # transformed variants of the built-ins only (plus, tee and random maps as is)
        variants = args.variants if w in ("two_rooms", "office") else ["as is"]
        for v in variants:
            m, params = world(w, v)
            if not decompose(m, round(params["l_min"] + params["body_radius"], 6)).evader_wins:
                print(f"skipped: {w} [{v}]: Prop. 2 does not hold (the pursuer wins)")
                continue
            for p in args.pursuers:
                for s in range(args.seeds):
                    jobs.append(
                        (w, v, p, s, args.k, args.start, simple if s < args.simple_seeds else [])
                    )
    done = episode_rows.read(args.results, _row_key) if args.results else {}
    todo = [j for j in jobs if episode_rows.key(j) not in done]
    if args.results:
        print(f"{len(jobs)} jobs selected, {len(todo)} to play, results in {args.results}")
    t0 = time.perf_counter()
    with contextlib.ExitStack() as stack:
        write = stack.enter_context(episode_rows.appending(args.results)) if args.results else None
        # no more workers than episodes (a resumed run with 3 left, or none, starts 3 or 1)
        pool = stack.enter_context(worker_pool(min(args.workers, max(1, len(todo)))))
        held = 0
        for i, row in enumerate(pool.imap_unordered(_play, todo), 1):
            if write is not None:
                write(row)
            done[_row_key(row)] = row
            winner, t = row["out"]["shooting"][:2]
            what = f"{row['world']} [{row['variant']}] {row['pursuer']} seed={row['seed']}"
            held += winner != "evader"
            if winner != "evader" or args.progress:
                print(f"  {'escaped' if winner == 'evader' else 'held'}: {what}", flush=True)
            if i % 20 == 0 or i == len(todo):
                print(f"  {i}/{len(todo)} jobs, {held} held, {time.perf_counter() - t0:.0f} s",
                      flush=True)  # fmt: skip
    results = []
    for j in jobs:
        r = done[episode_rows.key(j)]
        results.append((r["world"], r["variant"], r["pursuer"], r["seed"], r["out"]))
    results.sort(key=lambda r: (r[0], list(VARIANTS).index(r[1]), r[2], r[3]))
    wall = time.perf_counter() - t0
    print(f"{len(todo)} x {1 + len(simple)} episodes played in {wall:.0f} s ({args.workers} "
          f"workers; the report is over all {len(jobs)} jobs), horizon {args.k:g} D / V_e, "
          f"start {args.start!r}")  # fmt: skip
    rows: dict[tuple, list] = {}
    failures, times = [], []
    # decision time: the shooting evader's over all its episodes, and the same-run pair
    # (shooting, straight) over the episodes both played from the same start
    decide, pair = [], []
    simple_rate = {e: [0, 0] for e in simple}
    for name, variant, pursuer, seed, out in results:
        winner, t, dec, modes, end = out["shooting"]
        decide.append((dec * out["steps"], out["steps"]))
        row = rows.setdefault((name, pursuer), [0, 0, [], {e: [0, 0] for e in simple}])
        row[0] += winner == "evader"
        row[1] += 1
        if winner == "evader":
            row[2].append(t / out["unit"])
            times.append(t / out["unit"])
        else:
            failures.append((name, variant, pursuer, seed, modes, end))
        for e in simple:
            if e not in out:
                continue
            w, _, d, n_steps = out[e]
            if e == "evader/straight":  # seconds and steps of each, weighted by steps
                pair.append((dec * out["steps"], out["steps"], d * n_steps, n_steps))
            for acc in (row[3][e], simple_rate[e]):
                acc[0] += w == "evader"
                acc[1] += 1
    short = {e: e.split("/")[1].replace("toward_away", "t/a") for e in simple}
    head = f"{'world':<20}{'pursuer':<26}{'shooting':>9}{'t/(D/Ve) med':>14}{'max':>7}"
    print(head + "".join(f"{short[e]:>13}" for e in simple))
    for (name, pursuer), (ok, n, ts, srow) in sorted(rows.items()):
        med = f"{np.median(ts):.2f}" if ts else "-"
        mx = f"{max(ts):.2f}" if ts else "-"
        line = f"{name:<20}{pursuer:<26}{f'{ok}/{n}':>9}{med:>14}{mx:>7}"
        print(line + "".join(f"{f'{srow[e][0]}/{srow[e][1]}':>13}" for e in simple))
    total = sum(r[0] for r in rows.values()), sum(r[1] for r in rows.values())
    print(f"shooting evader escaped {total[0]}/{total[1]}")
    for e in simple:
        print(f"  {e:<26} escaped {simple_rate[e][0]}/{simple_rate[e][1]} (first seeds)")
    if times:
        q = np.quantile(times, [0.5, 0.9, 0.99, 1.0])
        print(
            "escape time / (D / V_e): median {:.2f}, 90% {:.2f}, 99% {:.2f}, max {:.2f}".format(*q)
        )
    spent, steps = np.sum(decide, axis=0)
    line = f"decision time per step: shooting {1e3 * spent / steps:.3f} ms (all steps)"
    if pair:
        a, na, b, nb = np.sum(pair, axis=0)
        d, s = a / na, b / nb
        line += f"; same starts: shooting {1e3 * d:.3f} ms, straight {1e3 * s:.4f} ms"
        line += f" (ratio {d / s:.0f}x)"
    print(line)
    for name, variant, pursuer, seed, modes, end in failures:
        total_steps = sum(modes.values())
        share = ", ".join(f"{k} {v / total_steps:.0%}" for k, v in sorted(modes.items()))
        print(f"  held: {name} [{variant}] {pursuer} seed={seed}: modes {share}; "
              f"end P={np.round(end[0], 2).tolist()} E={np.round(end[1], 2).tolist()}")  # fmt: skip
    return 0


if __name__ == "__main__":
    raise SystemExit(run(main))
