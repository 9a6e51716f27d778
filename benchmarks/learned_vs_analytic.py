"""Learned vs analytic policies, through the tournament runner, with issue 9's targets.

One tournament (``analysis.tournament``: a SQLite store that resumes, common random starts
per map, a process pool) plays every zoo model beside the analytic policies and baselines of
its role against the other role's roster, on the maps the models trained on (*seen*) and on
maps no model saw (*held out*: seeded random maps with seeds outside any training set, and
the built-ins left out of training). Then it prints, per map group and pairing, the held
rate with its Wilson 95 % interval, and each target of issue 9 as a ratio measured in
this run:

* learned pursuer vs ``evader/shooting``: held rate / the decomposition pursuer's, on
  corridor, open_room and l_hall (target >= 0.9); on held-out maps, minus greedy's (>= 0);
* learned evader vs ``pursuer/decomposition``: escape rate minus ``evader/shooting``'s on
  two_rooms and office (>= 0); on held-out maps minus ``evader/straight``'s (>= 0);
* the per-step decision time of each model against the analytic policy of its role.

The report (``report.html``: tables, heat maps, ratings, replays) is written beside the
store.

Usage::

    python benchmarks/learned_vs_analytic.py [--seeds 20] [--models NAME ...]
        [--store out/bench/learned.sqlite] [--workers 2]
"""

from __future__ import annotations

import argparse
import os
from collections import defaultdict
from pathlib import Path

from analysis.tournament import run_tournament, spec_from_dict
from analysis.tournament.report import analyse, write_report
from analysis.tournament.statistics import wilson_interval
from training import zoo

SEEN_PURSUER = ["corridor", "open_room", "l_hall"]
SEEN_EVADER = ["two_rooms", "office"]
HELD_OUT = ["pillars", "random:9001", "random:9002", "random:rectangles:9003"]
PURSUERS = ["pursuer/decomposition", "pursuer/greedy", "pursuer/tractrix"]
EVADERS = ["evader/shooting", "evader/straight", "evader/toward_away", "evader/random"]


def _rate(rows, pursuer, evader, maps):
    got = [r for r in rows if r["pursuer"] == pursuer and r["evader"] == evader
           and r["map"] in maps and r["winner"] is not None]  # fmt: skip
    held = sum(r["winner"] == "pursuer" for r in got)
    lo, hi = wilson_interval(held, len(got)) if got else (float("nan"), float("nan"))
    return (held / len(got) if got else float("nan")), lo, hi, len(got)


def _fmt(rate, lo, hi, n):
    return f"{rate:5.2f} [{lo:.2f}, {hi:.2f}] n={n}"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=20, help="seeded safe starts per map")
    ap.add_argument("--models", nargs="*", default=None, help="zoo names (default: all)")
    ap.add_argument("--store", default="out/bench/learned.sqlite")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--max-cycles", type=int, default=300)
    args = ap.parse_args(argv)
    names = args.models or zoo.list_models()
    learned = {"pursuer": [], "evader": []}
    for name in names:
        learned[zoo.info(name)["role"]].append(name)
    print(f"load average: {os.getloadavg()}; models: {names}")
    spec = spec_from_dict(
        {
            "name": "learned_vs_analytic",
            "maps": sorted(set(SEEN_PURSUER + SEEN_EVADER + HELD_OUT), key=str),
            "seeds": args.seeds,
            "start": "safe",
            "time_limit": 300,
            "pursuers": PURSUERS + [{"model": f"zoo:{n}", "label": n} for n in learned["pursuer"]],
            "evaders": EVADERS + [{"model": f"zoo:{n}", "label": n} for n in learned["evader"]],
            "env": {"max_cycles": args.max_cycles},
        }
    )
    summary = run_tournament(spec, args.store, workers=args.workers)
    print(f"{summary.played} played, {summary.reused} reused, {summary.seconds:.0f} s")
    a = analyse(args.store)
    rows = a.rows
    groups = {"seen (pursuer maps)": SEEN_PURSUER, "seen (evader maps)": SEEN_EVADER,
              "held out": HELD_OUT}  # fmt: skip
    print("\nheld rate of the pursuer [Wilson 95%], per map group")
    for gname, maps in groups.items():
        print(f"\n== {gname}: {', '.join(maps)}")
        for p in PURSUERS + learned["pursuer"]:
            for e in EVADERS + learned["evader"]:
                if (
                    p in PURSUERS
                    and e in EVADERS
                    and not (p == "pursuer/decomposition" or e == "evader/shooting")
                ):
                    continue  # baseline vs baseline: in the report
                print(f"  {p:<44} {e:<40} {_fmt(*_rate(rows, p, e, maps))}")
    print("\ntargets (ratios measured in this run)")
    for m in learned["pursuer"]:
        r_l = _rate(rows, m, "evader/shooting", SEEN_PURSUER)[0]
        r_d = _rate(rows, "pursuer/decomposition", "evader/shooting", SEEN_PURSUER)[0]
        h_l = _rate(rows, m, "evader/shooting", HELD_OUT)[0]
        h_g = _rate(rows, "pursuer/greedy", "evader/shooting", HELD_OUT)[0]
        ratio = r_l / r_d if r_d else float("nan")
        print(f"  {m}: seen held {r_l:.2f} / decomposition {r_d:.2f} = {ratio:.2f} (target >= 0.9: "
              f"{'met' if ratio >= 0.9 else 'NOT met'}); held out {h_l:.2f} vs greedy {h_g:.2f} "
              f"({'met' if h_l >= h_g else 'NOT met'})")  # fmt: skip
    for m in learned["evader"]:
        e_l = 1 - _rate(rows, "pursuer/decomposition", m, SEEN_EVADER)[0]
        e_s = 1 - _rate(rows, "pursuer/decomposition", "evader/shooting", SEEN_EVADER)[0]
        h_l = 1 - _rate(rows, "pursuer/decomposition", m, HELD_OUT)[0]
        h_s = 1 - _rate(rows, "pursuer/decomposition", "evader/straight", HELD_OUT)[0]
        print(f"  {m}: seen escape {e_l:.2f} vs shooting {e_s:.2f} "
              f"({'met' if e_l >= e_s else 'NOT met'}); held out {h_l:.2f} vs straight "
              f"{h_s:.2f} ({'met' if h_l >= h_s else 'NOT met'})")  # fmt: skip
    decide = defaultdict(list)
    for r in rows:
        for role in ("pursuer", "evader"):
            t = r.get(f"decide_{role}")
            if t is not None:
                decide[(role, r[role])].append(t)
    print("\nper-step decision time (mean over matches, same run)")
    for role, ref in (("pursuer", "pursuer/decomposition"), ("evader", "evader/shooting")):
        t_ref = decide.get((role, ref))
        for m in learned[role]:
            t_m = decide.get((role, m))
            if t_ref and t_m:
                a_ms, b_ms = 1e3 * sum(t_m) / len(t_m), 1e3 * sum(t_ref) / len(t_ref)
                print(f"  {m:<44} {a_ms:7.3f} ms vs {ref} {b_ms:7.3f} ms ({b_ms / a_ms:5.2f}x)")
    out = write_report(args.store, Path(args.store).with_suffix("") / "report", replays=False)
    print(f"\nreport: {out.get('html', out)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
