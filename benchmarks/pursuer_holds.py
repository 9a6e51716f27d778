"""Does the decomposition pursuer hold from safe starts? Variants of the paper's worlds.

Issue 13's goal: from safe starts on worlds where the pursuer wins (Prop. 2 false), at
rho <= 0.5, the decomposition pursuer holds every episode against every evader in the
registry, on rotated, rescaled and off-centre variants of the paper's worlds. This plays
seeded episodes through the shared runner (:func:`strategies.runner.run_episode`) on
each variant against each evader and prints the held rate per world and evader, every
loss (seed, cause, time, and the ``surveil play`` command that replays it with its GIF),
and the decomposition pursuer's decision time per step against the greedy pursuer's (a
reference measured in the same run).

Usage::

    python benchmarks/pursuer_holds.py [--seeds 10] [--rho 0.3 0.5] [--workers 2]
        [--max-cycles 600] [--worlds corridor corner ...] [--evaders E ...] [--no-greedy]
        [--results F.jsonl] [--referee CPL] [--hindsight CELL]

The evaders are every evader of the registry (:data:`EVADERS`; ``--evaders`` plays a
subset): the referee's evader solves its world once (cached on disk, seconds per world).

Each loss is printed as it happens, and a progress line every 25 episodes. With
``--results F.jsonl`` every episode is appended to F as it completes (JSON lines,
``benchmarks/episode_rows.py``); the same command with the same F after a stop plays only
the episodes missing from it and reports over all of them.

``--no-greedy`` skips the greedy reference (half the time; no decision-time ratio).

``--l-min X`` plays at L_min = X (times the variant's scale) instead of the world's own,
with the world's ratio L_max / L_min kept: a smaller rod on the same map, as on a larger
map with the same rod (the decomposition pursuer's grid is L_min / 20, so halving L_min
quadruples its points; issue 13's decision time on large worlds).

``--referee CPL`` asks the referee (:mod:`strategies.referee`, the bounded-speed ground
truth) about every start: each start, mapped back to the as-is world (a rotation and a
uniform scaling of lengths and speeds leave the game unchanged), is classified on the
as-is world's referee at CPL cells per L_min, with a fine evader lattice (2 cells, 1
spacing a step; ``benchmarks/referee_labels.py``, shared with ``unseen_worlds.py``), and
the counts are printed per world and variant, then beside each loss.
A certified *evader* start is one no pursuer can hold (on a world whose safe starts are
all such, "held" only measures the evaders' weakness); a loss from a certified *pursuer*
start is a weakness of the policy (its regret); "unknown" is the referee's resolution gap.
Solutions are cached on disk (minutes per world the first time).

``--hindsight CELL`` labels every loss to an *open-loop* evader (``evader/straight``,
``evader/wall_hugging``, ``evader/random``, ``evader/orbit``: their paths do not depend on
the pursuer) with :func:`strategies.referee.hindsight.hindsight` at cell side CELL,
against the evader's path recorded from the episode and extended alone to ``--max-cycles``
steps (the bodies' radius as played): ``evader`` (no pursuer of speed V_p holds to the
horizon: unavoidable), ``pursuer`` (some pursuer holds: the policy's regret) or
``unknown`` (``not solved``: the grid would exceed the memory budget); beside each such
loss, and over them (as ``unseen_worlds.py --hindsight``).
"""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import os
import shlex
import time
import warnings

import episode_rows
import numpy as np
import referee_labels
from bench_cli import integer, real, results_file, run, worker_pool
from referee_labels import similarity_back

from envs.errors import InfeasibleError, LongRunWarning, MemoryBudgetError
from envs.maps import builtin_info, builtin_names
from envs.maps.io import Similarity
from strategies.referee.hindsight import hindsight, record_evader_path
from strategies.runner import run_episode

EVADERS = [
    "evader/shooting",
    "evader/straight",
    "evader/toward_away",
    "evader/toward_away:away",
    "evader/wall_hugging",
    "evader/random",
    "evader/orbit",
    "evader/referee",
]
"""Every evader of the registry (checked by a test), with the toward-away evader in both
modes; ``--evaders`` plays a subset."""
OPEN_LOOP = ("evader/straight", "evader/wall_hugging", "evader/random", "evader/orbit")
"""The evaders of :data:`EVADERS` whose path does not depend on the pursuer."""
WORLDS = ["corridor", "corner", "l_hall", "open_room"]
PURSUERS = ("pursuer/decomposition", "pursuer/greedy")
# (label, rotation in radians, scale, offset)
VARIANTS = [
    ("as is", 0.0, 1.0, (0.0, 0.0)),
    ("rot 0.37", 0.37, 1.0, (0.0, 0.0)),
    ("x0.1", 0.0, 0.1, (0.0, 0.0)),
    ("x10 rot 1.1", 1.1, 10.0, (0.0, 0.0)),
    ("off-centre", 0.0, 1.0, (13.7, -4.2)),
]


def _world(name: str, rot: float, scale: float, offset):
    info = builtin_info(name)
    c, s = math.cos(rot), math.sin(rot)
    m = info.map.transformed(scale * np.array([[c, -s], [s, c]]), offset)
    params = dict(info.params())
    for k in ("l_min", "l_max", "v_pursuer", "v_evader"):
        if k in params:
            params[k] = params[k] * scale
    return m, params


def _evader(label: str):
    if label == "evader/toward_away:away":
        from strategies.policies import make_policy

        return make_policy("evader/toward_away", mode="away")
    return label


def _game(world: str, variant, rho: float, l_min: float | None) -> tuple:
    """The map and env overrides an episode of ``world``'s ``variant`` plays."""
    _, rot, scale, offset = variant
    m, params = _world(world, rot, scale, offset)
    if l_min is not None:  # the world's L_max / L_min kept
        params["l_max"] *= l_min * scale / params["l_min"]
        params["l_min"] = l_min * scale
    params["v_evader"] = rho * params["v_pursuer"]
    params["body_radius"] = 0.2 * scale
    return m, params


REPLAY_PARAMETERS = ("l_min", "l_max", "v_pursuer", "v_evader", "body_radius")


def replay_command(world: str, variant_label: str, rho: float, evader: str, seed: int,
                   max_cycles: int, l_min: float | None = None) -> str:  # fmt: skip
    """The ``surveil play`` command that plays this episode of the decomposition pursuer
    again, with its replay: the variant as a map name ``WORLD~[xS][rotR][off(X,Y)]``
    (:func:`envs.maps.load_map`) and the episode's lengths, speeds and bodies spelled out."""
    variant = next(v for v in VARIANTS if v[0] == variant_label)
    _, rot, scale, offset = variant
    _, params = _game(world, variant, rho, l_min)
    suffix = Similarity(scale, rot, offset).label()
    name, _, mode = evader.partition(":")
    words = ["surveil", "play", "--map", f"{world}~{suffix}" if suffix else world,
             "--pursuer", "pursuer/decomposition", "--evader", name]  # fmt: skip
    if mode:
        words += ["--evader-params", json.dumps({"mode": mode})]
    config = json.dumps({k: params[k] for k in REPLAY_PARAMETERS})
    words += ["--seed", str(seed), "--start", "safe", "--max-cycles", str(max_cycles)]
    words += ["--config", config, "--out", f"out/{world}_{name.split('/')[1]}_{seed}.gif"]
    return shlex.join(words)


def _play(job):
    world, variant, rho, evader, seed, max_cycles, pursuers, l_min = job
    m, params = _game(world, variant, rho, l_min)
    out = {}
    for pursuer in pursuers:
        r = run_episode(
            m, pursuer, _evader(evader), seed, max_cycles=max_cycles, overrides=params, start="safe"
        )
        out[pursuer] = [r.winner, r.cause, r.escape_time, r.decide_seconds["pursuer"], r.start]
    row = dict(zip(_KEY, _job_values(job), strict=True))
    return {**row, "out": out}


_KEY = ("world", "variant", "rho", "evader", "seed", "max_cycles", "pursuers", "l_min")
"""What identifies an episode (its row's fields): a rerun skips the rows it finds."""


def _job_values(job) -> list:
    world, variant, rho, evader, seed, max_cycles, pursuers, l_min = job
    return [world, variant[0], rho, evader, seed, max_cycles, list(pursuers), l_min]


def _row_key(row: dict) -> str:
    return episode_rows.key(row[k] for k in _KEY)


def hindsight_verdict(row: dict, cell: float):
    """The hindsight (cell side ``cell``) against the evader's path of an episode row,
    recorded from its episode and extended alone to the episode's horizon."""
    from envs.surveillance.config import EnvConfig

    variant = next(v for v in VARIANTS if v[0] == row["variant"])
    m, params = _game(row["world"], variant, row["rho"], row["l_min"])
    cycles = row["max_cycles"]
    path = record_evader_path(m, _evader(row["evader"]), row["seed"],
                              pursuers=("pursuer/decomposition",), overrides=params,
                              max_cycles=cycles, extend_to=cycles)  # fmt: skip
    return hindsight(EnvConfig(map=m, **params), path, path.pursuer_start, cell)


def _hindsight_label(row: dict, cell: float) -> str:
    """:func:`hindsight_verdict`'s verdict, printed with the grids' times and its cost;
    ``not solved`` over the memory budget (the reason printed)."""
    what = (f"  hindsight (cell {cell:g}) {row['world']} [{row['variant']}] rho={row['rho']} "
            f"{row['evader']} seed={row['seed']}: ")  # fmt: skip
    try:
        with MemoryBudgetError.naming("--hindsight CELL"), warnings.catch_warnings():
            # a long estimate is a line of the report, printed before the run
            warnings.simplefilter("always", LongRunWarning)
            warnings.showwarning = lambda message, *_: print(f"{what}{message}", flush=True)
            h = hindsight_verdict(row, cell)
    except InfeasibleError as exc:  # over the memory budget: the others still run
        print(f"{what}not solved ({exc})", flush=True)
        return "not solved"
    empty = "never" if h.optimistic_empty is None else f"{h.optimistic_empty:.1f} s"
    print(f"{what}{h.verdict} (optimistic empty {empty}, pessimistic until "
          f"{h.pessimistic_until:.1f} s of {h.horizon:.1f}; {h.seconds:.1f} s, estimated up "
          f"to {h.estimated_seconds:.1f} s)", flush=True)  # fmt: skip
    return h.verdict


def _referee_label(world: str, variant_label: str, rho: float, start, cpl: float) -> str:
    """The referee's label of a variant's start, on the as-is world (see the docstring)."""
    _, rot, scale, offset = next(v for v in VARIANTS if v[0] == variant_label)
    m, params = _world(world, 0.0, 1.0, (0.0, 0.0))
    ov = {"l_min": params["l_min"], "l_max": params["l_max"], "v_pursuer": params["v_pursuer"],
          "v_evader": rho * params["v_pursuer"], "body_radius": 0.2}  # fmt: skip
    return referee_labels.verdict(m, ov, start, cpl, similarity_back(rot, scale, offset))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=integer(1), default=3)
    ap.add_argument("--rho", type=real(0), nargs="+", default=[0.3, 0.5])
    ap.add_argument("--workers", type=integer(1), default=2)
    ap.add_argument("--max-cycles", type=integer(1), default=600)
    ap.add_argument("--worlds", nargs="+", choices=builtin_names(), default=WORLDS)
    ap.add_argument("--variants", nargs="+", choices=[v[0] for v in VARIANTS],
                    default=[v[0] for v in VARIANTS])  # fmt: skip
    ap.add_argument(
        "--evaders",
        nargs="+",
        choices=EVADERS,
        default=EVADERS,
        help="play these evaders only (default: every evader of the registry)",
    )
    ap.add_argument("--no-greedy", action="store_true", help="skip the greedy reference")
    ap.add_argument("--l-min", type=real(0), default=None, help="play at this L_min (see above)")
    ap.add_argument(
        "--referee",
        type=real(0),
        metavar="CPL",
        default=None,
        help="label every start with the referee at CPL cells per L_min",
    )
    ap.add_argument("--hindsight", type=real(0), metavar="CELL", default=None,
                    help="label every loss to an open-loop evader by hindsight at cell "
                    "side CELL (see above)")  # fmt: skip
    ap.add_argument("--results", metavar="FILE", default=None, type=results_file,
                    help="append each episode to FILE (JSON lines) as it completes; a rerun "
                    "with the same FILE plays only the episodes missing from it")  # fmt: skip
    args = ap.parse_args(argv)
    if args.l_min is not None and args.referee:  # the referee solves the world's own L_min
        ap.error("--l-min and --referee: the referee judges the world's own L_min only")
    pursuers = ("pursuer/decomposition",) if args.no_greedy else PURSUERS
    print(f"load average: {os.getloadavg()}")
    variants = [v for v in VARIANTS if v[0] in args.variants]
    jobs = [
        (w, v, rho, e, s, args.max_cycles, pursuers, args.l_min)
        for w in args.worlds
        for v in variants
        for rho in args.rho
        for e in args.evaders
        for s in range(args.seeds)
    ]
    done = episode_rows.read(args.results, _row_key) if args.results else {}
    todo = [j for j in jobs if episode_rows.key(_job_values(j)) not in done]
    if args.results:
        print(f"{len(jobs)} episodes selected, {len(todo)} to play, results in {args.results}")
    t0 = time.perf_counter()
    with contextlib.ExitStack() as stack:
        write = stack.enter_context(episode_rows.appending(args.results)) if args.results else None
        # no more workers than episodes (a resumed run with 3 left, or none, starts 3 or 1)
        pool = stack.enter_context(worker_pool(min(args.workers, max(1, len(todo)))))
        lost = 0
        for i, row in enumerate(pool.imap_unordered(_play, todo), 1):
            if write is not None:
                write(row)
            done[_row_key(row)] = row
            winner, cause, t = row["out"]["pursuer/decomposition"][:3]
            if winner != "pursuer":
                lost += 1
                where = f"{row['world']} [{row['variant']}] rho={row['rho']} {row['evader']}"
                print(f"  episode lost: {where} seed={row['seed']}: {cause} at {t}", flush=True)
            if i % 25 == 0 or i == len(todo):
                print(f"  {i}/{len(todo)} played, {lost} lost, {time.perf_counter() - t0:.0f} s",
                      flush=True)  # fmt: skip
    wall = time.perf_counter() - t0
    results = []
    hind: dict[tuple, str] = {}  # (world, variant, rho, evader, seed) -> the hindsight's label
    for j in jobs:
        r = done[episode_rows.key(_job_values(j))]
        results.append((r["world"], r["variant"], r["rho"], r["evader"], r["seed"], r["out"]))
        won = r["out"]["pursuer/decomposition"][0] == "pursuer"
        if args.hindsight and not won and r["evader"] in OPEN_LOOP:
            key = (r["world"], r["variant"], r["rho"], r["evader"], r["seed"])
            hind[key] = _hindsight_label(r, args.hindsight)
    held: dict[tuple, list[int]] = {}
    losses = []
    decide = {p: [] for p in pursuers}
    for world, label, rho, evader, seed, out in results:
        for p in decide:
            decide[p].append(out[p][3])
        winner, cause, t, _, start = out["pursuer/decomposition"]
        key = (world, evader)
        h = held.setdefault(key, [0, 0, 0])
        h[0] += winner == "pursuer"
        h[1] += 1
        h[2] += "pursuer/greedy" in out and out["pursuer/greedy"][0] == "pursuer"
        if winner != "pursuer":
            losses.append((world, label, rho, evader, seed, cause, t, start))
    print(f"{len(todo)} x {len(pursuers)} episodes played in {wall:.0f} s ({args.workers} "
          f"workers); the report is over all {len(jobs)}")  # fmt: skip
    print(f"{'world':<10}{'evader':<26}{'decomposition held':>20}{'greedy held':>14}")
    for (world, evader), (h, n, g) in sorted(held.items()):
        greedy = f"{g}/{n}" if len(pursuers) > 1 else "-"
        print(f"{world:<10}{evader:<26}{f'{h}/{n}':>20}{greedy:>14}")
    total = sum(v[0] for v in held.values()), sum(v[1] for v in held.values())
    print(f"decomposition pursuer held {total[0]}/{total[1]} from safe starts")
    d = float(np.mean(decide["pursuer/decomposition"]))
    if len(pursuers) > 1:
        g = float(np.mean(decide["pursuer/greedy"]))
        print(
            f"decision time per step: decomposition {1e3 * d:.3f} ms, greedy {1e3 * g:.3f} ms "
            f"(ratio {d / g:.1f}x)"
        )
    else:
        print(f"decision time per step: decomposition {1e3 * d:.3f} ms")
    labels: dict[tuple, str] = {}  # (world, variant, rho, seed) -> the referee's verdict
    if args.referee:
        # Every start, not only the lost ones: a world whose safe starts are all certified
        # evader wins is not a pursuer-win world with bounded speeds, whatever it holds.
        for world, label, rho, _, seed, out in results:
            key = (world, label, rho, seed)
            if key not in labels:
                labels[key] = _referee_label(world, label, rho, out[pursuers[0]][4], args.referee)
        per: dict[tuple, dict[str, int]] = {}
        for (world, label, rho, _), v in labels.items():
            c = per.setdefault((world, label, rho), {})
            c[v] = c.get(v, 0) + 1
        print(f"referee (cpl {args.referee:g}) on the starts (one per seed):")
        for (world, label, rho), c in sorted(per.items()):
            counts = ", ".join(f"{n} {v}" for v, n in sorted(c.items()))
            print(f"  {world} [{label}] rho={rho}: {counts}")
    verdicts_of_losses = []
    for loss in losses:
        world, label, rho, evader, seed, cause, t, start = loss
        ref = ""
        if args.referee:
            v = labels[(world, label, rho, seed)]
            verdicts_of_losses.append(v)
            ref = f"; referee: {v}"
        if (world, label, rho, evader, seed) in hind:
            ref += f"; hindsight: {hind[(world, label, rho, evader, seed)]}"
        print(f"  lost: {world} [{label}] rho={rho} {evader} seed={seed}: {cause} at {t}{ref}")
        again = replay_command(world, label, rho, evader, seed, args.max_cycles, args.l_min)
        print(f"    replay: {again}")
    if args.referee and losses:
        distinct = {(w, label, rho, seed) for w, label, rho, _, seed, *_ in losses}
        print(referee_labels.summary(args.referee, verdicts_of_losses, len(distinct)))
    if args.hindsight:
        print(referee_labels.hindsight_summary(args.hindsight, hind.values()))
    return 0


if __name__ == "__main__":
    raise SystemExit(run(main))
