"""rho > 1: does every evader escape a slower pursuer? (issue 13's third goal)

A faster evader always escapes by running at the pursuer: L closes at least ``V_e - V_p``
a second whatever the pursuer does, down to L_min (footnote 4 of the paper). This plays
every registered evader with its default parameters, plus the toward-away evader's
``away`` and ``alternate`` modes and a random walk that holds each velocity 10 steps,
against every registered pursuer but the referee's (its solve at reset takes minutes a
world), on the built-in worlds and four transformed ones, from the runner's safe start
and from a valid one (the env's own default draw), at each ``--rhos`` (V_e = rho V_p,
the world's other parameters as recommended), and prints the escapes per evader and
rho, then every episode the pursuer held with the command that replays it.

Horizon: ``K ((L_max - L_min) / (V_e - V_p) + D / V_e)`` with K = 2 (``--k``), D the
map's diameter: the time a charge takes to close the whole band, plus a crossing of the
map, twice.

Usage::

    python benchmarks/faster_evaders.py [--rhos 1.05 1.1 1.25 1.5 2] [--seeds 0]
        [--worlds corner ...] [--evaders evader/orbit ...] [--pursuers ...]
        [--starts safe valid] [--k 2] [--results F.jsonl]

``--results F.jsonl``: one JSON line per episode (:mod:`episode_rows`), appended as it
completes; the same command resumes where a stop left it. The full default matrix
(5 rhos x 12 worlds x 2 starts x 6 pursuers x 10 evaders, 7200 episodes) took 25 minutes
on two cores shared by a dozen processes; most of it is the episodes the pursuer holds to
the horizon.
"""

from __future__ import annotations

import json
import math
import shlex
import warnings
from collections import Counter

import episode_rows
from bench_cli import ArgumentParser, integer, real, results_file, run

from envs.errors import RhoAboveOneWarning
from strategies.policies import make_policy, policy_names
from strategies.runner import map_parameters, run_episode

WORLDS = [
    "corridor",
    "corner",
    "pillars",
    "open_room",
    "l_hall",
    "two_rooms",
    "maze",
    "office",
    "corner~x1.5rot0.7",
    "l_hall~rot0.37off(3,-2)",
    "pillars~x1.15rot-1.35off(2,-6)",
    "two_rooms~x0.8rot2.1",
]
VARIANTS = ["evader/toward_away:away", "evader/toward_away:alternate", "evader/random:10"]
EVADERS = [*policy_names("evader"), *VARIANTS]
PURSUERS = [p for p in policy_names("pursuer") if p != "pursuer/referee"]
RHOS = [1.05, 1.1, 1.25, 1.5, 2.0]
FIELDS = ("world", "pursuer", "evader", "rho", "seed", "start_kind", "k")


def make_evader(label: str):
    """A registered evader, or ``evader/toward_away:MODE`` / ``evader/random:HOLD``."""
    if label.startswith("evader/toward_away:"):
        return make_policy("evader/toward_away", mode=label.split(":", 1)[1])
    if label.startswith("evader/random:"):
        return make_policy("evader/random", hold=int(label.split(":", 1)[1]))
    return label


def game(world: str, rho: float, k: float) -> tuple[dict, int]:
    """The env overrides of ``world`` at ``rho`` and the horizon in steps (dt 0.1)."""
    m, p = map_parameters(world)
    p = {"l_min": 2.0, "l_max": 4.0, "v_pursuer": 1.0, **p}
    v_p = p["v_pursuer"]
    v_e = rho * v_p
    seconds = k * ((p["l_max"] - p["l_min"]) / (v_e - v_p) + float(m.diameter) / v_e)
    return dict(p, v_evader=v_e), math.ceil(seconds / 0.1)


def play(world: str, pursuer: str, evader: str, rho: float, seed: int, start: str, k: float):
    overrides, steps = game(world, rho, k)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RhoAboveOneWarning)  # rho > 1 on purpose
        r = run_episode(
            world, pursuer, make_evader(evader), seed,
            max_cycles=steps, overrides=overrides, start=start,
        )  # fmt: skip
    return {
        "winner": r.winner, "cause": r.cause, "t": r.escape_time, "steps": r.steps,
        "horizon": steps, "start": r.start,
    }  # fmt: skip


def replay(row: dict) -> str:
    """The ``surveil play`` command that plays ``row``'s episode again."""
    overrides, steps = game(row["world"], row["rho"], row["k"])
    config = {k: overrides[k] for k in ("l_min", "l_max", "v_pursuer", "v_evader")}
    name, _, arg = row["evader"].partition(":")
    words = [
        "surveil",
        "play",
        "--map",
        row["world"],
        "--pursuer",
        row["pursuer"],
        "--evader",
        name,
    ]
    if arg:
        params = {"mode": arg} if name == "evader/toward_away" else {"hold": int(arg)}
        words += ["--evader-params", json.dumps(params)]
    words += ["--seed", str(row["seed"]), "--start", row["start_kind"], "--max-cycles", str(steps)]
    return shlex.join([*words, "--config", json.dumps(config)])


def main(argv=None) -> int:
    ap = ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rhos", type=real(minimum=1.0, strict=True), nargs="+", default=RHOS)
    ap.add_argument("--worlds", nargs="+", default=WORLDS)
    ap.add_argument("--evaders", nargs="+", default=EVADERS)
    ap.add_argument("--pursuers", nargs="+", default=PURSUERS)
    ap.add_argument("--seeds", type=integer(minimum=0), nargs="+", default=[0])
    ap.add_argument("--starts", nargs="+", choices=["safe", "valid"], default=["safe", "valid"])
    ap.add_argument("--k", type=real(minimum=0.0, strict=True), default=2.0)
    ap.add_argument("--results", type=results_file, help="JSON-lines file (resumable)")
    args = ap.parse_args(argv)

    def row_key(row: dict) -> str:
        return episode_rows.key(row[f] for f in FIELDS)

    done = episode_rows.read(args.results, row_key) if args.results else {}
    jobs = [
        (w, p, e, rho, s, st, args.k)
        for rho in args.rhos
        for w in args.worlds
        for st in args.starts
        for s in args.seeds
        for p in args.pursuers
        for e in args.evaders
    ]
    rows = []
    with episode_rows.appending(args.results) if args.results else _no_file() as write:
        for job in jobs:
            k = episode_rows.key(job)
            if k in done:
                rows.append(done[k])
                continue
            row = dict(zip(FIELDS, job, strict=True)) | play(*job)
            write(row)
            rows.append(row)
            if row["winner"] != "evader":
                print(f"held: {replay(row)}", flush=True)
    tally: dict[tuple[str, float], Counter] = {}
    for row in rows:
        c = tally.setdefault((row["evader"], row["rho"]), Counter())
        c["n"] += 1
        c["escaped"] += row["winner"] == "evader"
    rhos = sorted({rho for _, rho in tally})
    print(f"{'evader':32s}" + "".join(f"  rho {rho:<9g}" for rho in rhos))
    for evader in dict.fromkeys(e for e, _ in tally):
        cells = [tally.get((evader, rho), Counter()) for rho in rhos]
        print(f"{evader:32s}" + "".join(f"  {c['escaped']:>5d}/{c['n']:<7d}" for c in cells))
    return 0


class _no_file:
    def __enter__(self):
        return lambda row: None

    def __exit__(self, *exc):
        return False


if __name__ == "__main__":
    raise SystemExit(run(main))
