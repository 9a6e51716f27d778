"""Fixed starts: a world's default starts as the runner plays it, and referee-certified starts.

The other benchmarks draw their own safe starts. These episodes start where two other
judges look:

* ``--starts default``: a built-in world as the runner plays it given nothing but its
  name (its recommended L_min, L_max and speeds, the safe start the episode seed draws,
  the environment's horizon): the decomposition pursuer against ``--opponents`` (default:
  the charging toward-away evader and the wall-hugger the report tallies there, the
  shooting evader and the herder), seeds ``--seeds`` (0-39). These are the episodes the
  reproduction report tallies (``analysis/figures/cases/episodes.py``: the corner world
  at seeds 0-9; a regression of the pursuer once showed there and in no benchmark set).
* ``--starts certified --role pursuer``: starts the referee certifies for the pursuer
  (:mod:`strategies.referee`: some bounded-speed pursuer holds from them forever), the
  decomposition pursuer against every evader of ``unseen_worlds.py`` (the registered
  ones, the referee's included, and the unseen opponents). A loss from such a start is
  the policy's regret, and its row says so (``"regret": true``).
* ``--starts certified --role evader``: starts the referee certifies for the evader (no
  bounded-speed pursuer holds; ``"escape_bound"``: the certified time the evader needs),
  the shooting evader against every pursuer of ``unseen_worlds.py`` (the referee's
  included: the first run solves its game, about 2 minutes a world).
  A loss (the pursuer held to the horizon) is the evader's regret.

The certified starts ship in ``benchmarks/certified_starts.json`` (a solve takes 10-40 s
a world, uncached): the worlds of :data:`CERTIFY` (``unseen_worlds.py`` labels, at
(rho, L_max / L_min, L_min), V_p 1, body radius 0.1, scaled with a transformed world as
there), solved at ``CPL`` cells per L_min with ``referee_labels.py``'s fine evader
lattice, ``N_STARTS`` starts a world (4 of the pursuer's, 6 of the evader's) drawn by
``Referee.sample_starts`` from ``numpy.random.default_rng(SEED)``. ``--certify FILE``
writes that file again (a world on which the referee certifies nothing of the kind is
left out, and said); a test re-certifies some of the shipped starts, so the file cannot
drift from the referee.

Horizons: default starts, the environment's (500 steps); certified pursuer-win starts,
``--max-cycles`` (600: 60 s); certified evader-win starts, ``--k`` D / V_e (8, D the
bounding-box diagonal), as ``unseen_worlds.py``. The episode seed is the seed (default
starts) or the start's index in its world (certified starts: it seeds the opponents).

Rows (JSON lines, ``--results``; a rerun plays only what the file lacks, ``--play-again``
every selected episode) carry ``starts, role, world, combo, opponent, seed, start,
horizon``, the result (``winner, cause, t, steps``) and, from certified starts,
``certified`` (the referee's label) and ``regret`` (a loss). The report prints the
wins per world and opponent, and each loss with the command that replays it.

    python benchmarks/fixed_starts.py --starts default --world corner --seeds 0-39
    python benchmarks/fixed_starts.py --starts certified --role pursuer
    python benchmarks/fixed_starts.py --starts certified --role evader --worlds random:convex:7204
"""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import shlex
import time
from collections import Counter, defaultdict

import episode_rows
import numpy as np
import referee_labels
from bench_cli import ArgumentParser, integer, play_rows, real, results_file, run
from unseen_opponents import make_opponent
from unseen_worlds import EVADERS, MAX_CYCLES, PURSUERS, K, diameter, evader_world, pursuer_world

from envs.errors import InvalidConfigError
from envs.maps import load_map

HERE = os.path.dirname(os.path.abspath(__file__))
CERTIFIED = os.path.join(HERE, "certified_starts.json")
"""The shipped certified starts (:func:`certify` writes them)."""

CPL = 16.0
N_STARTS = {"pursuer": 4, "evader": 6}
SEED = 1330
CERTIFY = {
    "pursuer": [
        ("L_15x6.5", (0.2, 2.0, 2.0)),
        ("pillar_centre", (0.2, 2.0, 2.0)),
        ("plus_w6", (0.2, 2.0, 2.0)),
        ("open_room~x0.6rot0.3off(11,11)", (0.3, 2.0, 2.0)),
    ],
    "evader": [
        ("random:polygons:7202", (0.2, 3.0, 2.0)),
        ("random:convex:7204", (0.2, 3.0, 2.0)),
        ("random:rectangles:7203", (0.2, 3.0, 2.0)),
        ("plus_w1.6a4.5", (0.2, 3.0, 2.0)),
        ("random:polygons:7302", (0.2, 3.0, 2.0)),
        ("random:convex:7308", (0.2, 3.0, 2.0)),
    ],
}
"""The worlds certified, per role of the certified player: (label, (rho, L_max / L_min,
L_min)). The pursuer's: rooms where the referee's pursuer bound certifies starts at rho
0.2 or 0.3 (it certifies none at rho >= 0.35); the evader's: two worlds open only to a
point evader (no escape region a body can cross into; the shooting evader missed
certified escapes there in session 22), two open to a body, and two where it missed
certified escapes in session 23 (helper-139's: the referee's evader steps past the corner
of an obstacle the long rod grazes; random:polygons:7302 starts 3 and 5, random:convex:7308
start 5)."""

OPPONENTS = {"pursuer": EVADERS, "evader": PURSUERS}
"""Who plays against the certified player's policy: every opponent of ``unseen_worlds.py``
(the referee's own policies solve their world at reset and cache it on disk: the first
run of the evader-win starts spends about 2 minutes a world in the referee pursuer's
solve, later runs seconds)."""
POLICY = {"pursuer": "pursuer/decomposition", "evader": "evader/shooting"}
DEFAULT_OPPONENTS = ["evader/toward_away:toward", "evader/shooting", "evader/wall_hugging",
                     "herder"]  # fmt: skip
"""``--starts default``: the report's corner opponents (the charge, the wall-hugger) and
the shooting evader and the herder."""


# ------------------------------------------------------------------ the worlds


def world(role: str, label: str, combo) -> tuple[object, dict]:
    """(map, env overrides) of a certified world: ``role`` is the certified player's
    (the pursuer's worlds are ``unseen_worlds.pursuer_world``'s, the evader's
    ``evader_world``'s)."""
    rho, ratio, l_min = combo
    if role == "pursuer":
        return pursuer_world(label, (rho, ratio, l_min))
    return evader_world(label, l_min, rho, ratio)


def certify_world(role: str, label: str, combo) -> dict | None:
    """The entry of the certified starts file for one world of :data:`CERTIFY`: the
    referee solved (or loaded from its disk cache) and :data:`N_STARTS` starts it
    certifies for ``role`` drawn; None (said) when it certifies none or is not solved."""
    m, ov = world(role, label, combo)
    t0 = time.perf_counter()
    ref = referee_labels._referee(m, ov, CPL)
    if isinstance(ref, Exception):
        print(f"{label} {list(combo)}: left out, not solved ({ref})", flush=True)
        return None
    print(f"{label} {list(combo)}: solved in {time.perf_counter() - t0:.0f} s, lattice starts "
          f"{ref.lattice_starts().counts()}", flush=True)  # fmt: skip
    try:
        starts = ref.sample_starts(N_STARTS[role], np.random.default_rng(SEED), kind=role)
    except InvalidConfigError as exc:
        print(f"  left out: {exc}", flush=True)
        return None
    entry = {"role": role, "world": label, "combo": list(combo), "starts": []}
    for st in starts:
        st = {k: [float(x) for x in v] for k, v in st.items()}
        bound = ref.escape_time(st["pursuer"], st["evader"]) if role == "evader" else None
        entry["starts"].append({**st, "escape_bound": bound})
    return entry


def certify(path: str, roles=("pursuer", "evader")) -> dict:
    """Solve the referee on each world of :data:`CERTIFY` and write :data:`N_STARTS`
    certified starts of each to ``path`` (JSON); the document written."""
    doc = {"cpl": CPL, "solve": referee_labels.SOLVE, "seed": SEED, "worlds": []}
    for role in roles:
        for label, combo in CERTIFY[role]:
            entry = certify_world(role, label, combo)
            if entry is not None:
                doc["worlds"].append(entry)
    with open(path, "w") as f:  # a start a line: a re-certified file's diff reads by start
        f.write(json.dumps({**doc, "worlds": []})[:-3] + "[\n")
        for i, w in enumerate(doc["worlds"]):
            head = json.dumps({**w, "starts": []})[:-3]
            lines = ",\n  ".join(json.dumps(st) for st in w["starts"])
            f.write(f" {head}[\n  {lines}]}}{',' if i < len(doc['worlds']) - 1 else ''}\n")
        f.write("]}\n")
    return doc


def load_certified(path: str = CERTIFIED) -> list[dict]:
    """The certified worlds of ``path`` (:func:`certify`'s ``"worlds"``).

    Raises:
        InvalidConfigError: ``path`` is not such a file, naming it and what was expected.
    """
    expected = "expected the JSON document fixed_starts.py --certify writes"
    try:
        with open(path) as f:
            worlds = json.load(f)["worlds"]
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise InvalidConfigError(f"{path!r}: {exc!s}; {expected}") from None
    for w in worlds:
        missing = {"role", "world", "combo", "starts"} - set(w)
        if missing:
            raise InvalidConfigError(
                f"{path!r}: a world without {', '.join(sorted(missing))}; {expected}"
            )
    return worlds


# ------------------------------------------------------------------ the episodes


def _seeds(text: str) -> list[int]:
    """``--seeds`` items: ``N`` or ``A-B`` (inclusive)."""
    m = re.fullmatch(r"(\d+)(?:-(\d+))?", text)
    if m is None or (m[2] is not None and int(m[2]) < int(m[1])):
        raise argparse.ArgumentTypeError(f"{text!r}: expected a seed N or a range A-B (A <= B)")
    return list(range(int(m[1]), int(m[2] or m[1]) + 1))


def jobs(args) -> list[dict]:
    """The selected episodes, as the fields their rows start with."""
    if args.starts == "default":
        opponents = args.opponents or DEFAULT_OPPONENTS
        return [{"starts": "default", "role": "pursuer", "world": args.world, "combo": None,
                 "opponent": o, "seed": s, "start": None, "horizon": None}
                for o in opponents for s in args.seeds]  # fmt: skip
    out = []
    for w in load_certified(args.certified):
        if w["role"] != args.role or (args.worlds and w["world"] not in args.worlds):
            continue
        horizon = args.max_cycles if args.role == "pursuer" else args.k
        for i, st in enumerate(w["starts"]):
            if args.seeds and i not in args.seeds:
                continue
            for o in args.opponents or OPPONENTS[args.role]:
                out.append({"starts": "certified", "role": args.role, "world": w["world"],
                            "combo": w["combo"], "opponent": o, "seed": i,
                            "start": {k: st[k] for k in ("pursuer", "evader")},
                            "horizon": horizon,
                            "escape_bound": st.get("escape_bound")})  # fmt: skip
    return out


def row_key(row) -> str:
    """An episode's identity: its fields up to the horizon (the start itself included, so
    a re-certified file plays its new starts again)."""
    return episode_rows.key(row[k] for k in ("starts", "role", "world", "combo", "opponent",
                                             "seed", "start", "horizon"))  # fmt: skip


def play(job: dict) -> dict:
    """Play one job; its row."""
    from strategies.runner import run_episode

    row = dict(job)
    me, other = job["role"], "evader" if job["role"] == "pursuer" else "pursuer"
    t0 = time.perf_counter()
    try:
        players = {me: POLICY[me], other: make_opponent(job["opponent"])}
        if job["starts"] == "default":
            r = run_episode(job["world"], players["pursuer"], players["evader"], job["seed"])
        else:
            m, ov = world(me, job["world"], job["combo"])
            cycles = job["horizon"]
            if me == "evader":
                cycles = math.ceil(job["horizon"] * diameter(m) / ov["v_evader"] / 0.1)
            r = run_episode(m, players["pursuer"], players["evader"], job["seed"],
                            max_cycles=cycles, overrides=ov, start=job["start"])  # fmt: skip
        row.update(winner=r.winner, cause=r.cause, t=r.escape_time, steps=r.steps)
        if job["starts"] == "default":  # the key keeps None: the seed draws the start
            row["start_drawn"] = {k: [float(x) for x in v] for k, v in r.start.items()}
    except Exception as exc:  # a crash is a loss, kept with its message
        row["error"] = repr(exc)[:400]
    if job["starts"] == "certified":
        row["certified"] = me
        row["regret"] = not won(row)
    row["wall"] = round(time.perf_counter() - t0, 2)
    return row


def won(row) -> bool:
    """Whether the row's role won (an ``error`` row, a crash, is a loss)."""
    return "error" not in row and row.get("winner") == row["role"]


def replay_command(row, results: str = "replay.jsonl") -> str:
    """The command that plays this row's episode again, alone."""
    words = ["python", "benchmarks/fixed_starts.py", "--starts", row["starts"]]
    if row["starts"] == "default":
        words += ["--world", row["world"]]
    else:
        words += ["--role", row["role"], "--worlds", row["world"]]
        if row["horizon"] != (MAX_CYCLES if row["role"] == "pursuer" else K):
            flag = "--max-cycles" if row["role"] == "pursuer" else "--k"
            words += [flag, f"{row['horizon']:g}"]
    words += ["--opponents", row["opponent"], "--seeds", str(row["seed"]), "--results",
              results, "--play-again"]  # fmt: skip
    return shlex.join(words)


def report(rows: list[dict]) -> None:
    """Wins per world and opponent, the total, and each loss with its replay command."""
    by_world: dict[str, Counter] = defaultdict(Counter)
    by_opponent: dict[str, Counter] = defaultdict(Counter)
    for r in rows:
        w = r["world"] if r["combo"] is None else f"{r['world']} {r['combo']}"
        for table, k in ((by_world, w), (by_opponent, r["opponent"])):
            table[k]["won"] += won(r)
            table[k]["n"] += 1
    role = rows[0]["role"]
    for title, table in (("world", by_world), ("opponent", by_opponent)):
        print(f"{role} wins per {title}:")
        for k, c in table.items():
            print(f"  {k:<48} {c['won']:>4}/{c['n']}")
    print(f"total: {sum(won(r) for r in rows)}/{len(rows)} {role} wins "
          f"({rows[0]['starts']} starts)")  # fmt: skip
    for r in rows:
        if won(r):
            continue
        what = r.get("error") or (
            f"{r['cause']} at {r['t']:.2f} s" if r["t"] is not None else "held to the horizon"
        )
        note = ""
        if r.get("regret"):
            bound = r.get("escape_bound")
            within = f", escape certified within {bound:.1f} s" if bound else ""
            note = f"  REGRET (certified {r['certified']}-win start{within})"
        print(f"  lost: {r['world']} {r['opponent']} seed={r['seed']}: {what}{note}")
        print(f"    replay: {replay_command(r)}")


def main(argv=None) -> int:
    ap = ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--starts", choices=("default", "certified"), required=True)
    ap.add_argument("--role", choices=("pursuer", "evader"), default="pursuer",
                    help="certified starts: the certified player, whose policy plays")  # fmt: skip
    ap.add_argument("--world", default="corner", help="default starts: a map as 'surveil play "
                    "--map' takes it (a built-in name, ...)")  # fmt: skip
    ap.add_argument("--worlds", nargs="+", help="certified starts: these worlds of the file only")
    ap.add_argument("--opponents", nargs="+", help="opponent labels (as unseen_worlds.py's; "
                    "default: the starts' own list, module docstring)")  # fmt: skip
    ap.add_argument("--seeds", nargs="+", type=_seeds, help="default starts: the seeds (N or "
                    "A-B; default 0-39); certified starts: the starts' indices in their "
                    "world")  # fmt: skip
    ap.add_argument("--max-cycles", type=integer(1), default=MAX_CYCLES,
                    help="certified pursuer-win starts: horizon in steps")  # fmt: skip
    ap.add_argument("--k", type=real(0), default=K,
                    help="certified evader-win starts: horizon in D / V_e")  # fmt: skip
    ap.add_argument("--certified", default=CERTIFIED, help="the certified starts (JSON)")
    ap.add_argument("--certify", metavar="FILE", type=results_file, help="solve the referee on "
                    "the worlds of CERTIFY and write their certified starts to FILE; no "
                    "play")  # fmt: skip
    ap.add_argument("--results", type=results_file, help="JSON-lines file (default "
                    "out/fixed_starts_STARTS_ROLE.jsonl)")  # fmt: skip
    ap.add_argument("--play-again", action="store_true", help="play every selected episode, "
                    "also those the results file holds (the new row counts)")  # fmt: skip
    ap.add_argument("--workers", type=integer(1), default=1)
    args = ap.parse_args(argv)
    if args.certify:
        certify(args.certify)
        return 0
    args.seeds = sorted({s for group in args.seeds for s in group}) if args.seeds else None
    if args.starts == "default":
        args.seeds = args.seeds if args.seeds is not None else list(range(40))
        if args.role != "pursuer":
            ap.error("--starts default: the pursuer role only (the report's episodes)")
        try:
            load_map(args.world)
        except ValueError as exc:  # the project's errors subclass ValueError
            ap.error(f"--world: {exc}")
    for label in args.opponents or []:
        try:
            make_opponent(label)
        except ValueError as exc:  # the project's errors subclass ValueError
            ap.error(f"--opponents: {label!r} is no opponent ({exc})")
    selected = jobs(args)
    if not selected:
        ap.error("no episode selected (--worlds, --seeds: none in the certified starts file)")
    results = args.results or f"out/fixed_starts_{args.starts}_{args.role}.jsonl"
    done = episode_rows.read(results, row_key)
    todo = selected if args.play_again else [j for j in selected if row_key(j) not in done]
    print(f"{len(selected)} episodes selected, {len(todo)} to play, results in {results}")
    play_rows(todo, play, results, done, row_key, won, args.workers)
    report([done[row_key(j)] for j in selected])
    return 0


if __name__ == "__main__":
    raise SystemExit(run(main))
