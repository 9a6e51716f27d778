"""Zoo models against analytic and baseline opponents, beside analytic-vs-analytic references.

Every row plays the same seeded starts (``analysis.evaluate.play_episode``: safe starts
at L_min where the map has them, the env settings the model was trained with), and
prints

* the pursuer's surveillance success rate with its Wilson 95% interval, the learner's
  own success rate (a pursuer model wins by holding, an evader model by escaping), the
  mean time to escape (Student t 95% interval) and the escape causes;
* for each model, reference rows measured in the same run: the analytic policy of the
  model's role (``pursuer/decomposition`` or ``evader/shooting``) in its place against
  the same opponents, so each learned row has an analytic row to compare against;
* per-step decision time of each learned policy against the analytic policy of its
  role (a ratio measured in the same run, plus absolute figures).

Usage::

    python benchmarks/learned_vs_analytic.py [--episodes 50] [--models NAME ...] [--seed 0]
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

from analysis.evaluate import play_episode, t_mean_interval, wilson_interval
from training import zoo

ANALYTIC = {"pursuer": "pursuer/decomposition", "evader": "evader/shooting"}
OPPONENTS = {
    "pursuer": ["evader/straight", "evader/random", "evader/toward_away", "evader/shooting"],
    "evader": ["pursuer/greedy", "pursuer/tractrix", "pursuer/decomposition"],
}


def play_row(map_name, pursuer, evader, seeds, overrides):
    """Play one matchup over ``seeds``; returns the aggregate dict of the row."""
    held, escapes, causes, decide = 0, [], {}, {"pursuer": [], "evader": []}
    t0 = time.perf_counter()
    for seed in seeds:
        r = play_episode(map_name, pursuer, evader, seed, overrides=overrides, start="safe")
        if r.winner == "pursuer":
            held += 1
        else:
            escapes.append(r.escape_time)
            causes[r.cause] = causes.get(r.cause, 0) + 1
        for role in decide:
            decide[role].append(r.decide_seconds[role])
    n = len(seeds)
    lo, hi = wilson_interval(held, n)
    mean, tlo, thi = t_mean_interval(escapes)
    return {
        "held": held,
        "n": n,
        "rate": held / n,
        "lo": lo,
        "hi": hi,
        "escape": (mean, tlo, thi),
        "causes": causes,
        "decide": {k: float(np.mean(v)) for k, v in decide.items()},
        "seconds": time.perf_counter() - t0,
    }


def _name(policy) -> str:
    return policy if isinstance(policy, str) else policy.name


def fmt_row(label_p, label_e, row, learner_role):
    mean, lo, hi = row["escape"]
    if math.isnan(mean):
        esc = "-"
    elif math.isinf(hi):
        esc = f"{mean:6.2f}"
    else:
        esc = f"{mean:6.2f} [{lo:5.2f}, {hi:5.2f}]"
    own = row["rate"] if learner_role == "pursuer" else 1.0 - row["rate"]
    causes = ", ".join(f"{k}:{v}" for k, v in sorted(row["causes"].items())) or "-"
    return (
        f"{label_p:<38} {label_e:<36} {row['held']:>3}/{row['n']:<3} "
        f"{row['rate']:5.2f} [{row['lo']:.2f}, {row['hi']:.2f}]  {own:5.2f}  "
        f"{esc:<22} {causes}"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--episodes", type=int, default=50)
    parser.add_argument("--seed", type=int, default=0, help="first episode seed")
    parser.add_argument("--models", nargs="*", default=None, help="zoo names (default: all)")
    args = parser.parse_args()
    names = args.models or zoo.list_models()
    seeds = list(range(args.seed, args.seed + args.episodes))
    header = (
        f"{'pursuer':<38} {'evader':<36} {'held':>7} {'rate [Wilson 95%]':<18}  "
        f"{'learner':>5}  {'escape time s [t 95%]':<22} causes"
    )
    timing = []
    for name in names:
        cfg = zoo.config(name)
        prov = zoo.info(name)
        role = cfg.role
        learned = zoo.load(name)
        label = f"zoo:{name}"
        print(
            f"\n== {name}: {cfg.algo.upper()} {role} trained vs {cfg.opponent} on {cfg.map}, "
            f"{prov['timesteps']} timesteps, env {cfg.env}; {args.episodes} seeded safe starts"
        )
        print(header)
        opponents = [cfg.opponent] + [o for o in OPPONENTS[role] if o != cfg.opponent]
        for opp in opponents:
            for me, tag in ((learned, label), (ANALYTIC[role], ANALYTIC[role] + " (ref)")):
                if role == "pursuer":
                    row = play_row(cfg.map, me, opp, seeds, cfg.env)
                    print(fmt_row(tag, opp, row, role), flush=True)
                else:
                    row = play_row(cfg.map, opp, me, seeds, cfg.env)
                    print(fmt_row(opp, tag, row, role), flush=True)
                if me is learned and opp == cfg.opponent:
                    t_learned = row["decide"][role]
                elif opp == cfg.opponent:
                    t_analytic = row["decide"][role]
        timing.append((name, role, t_learned, t_analytic))
    print("\nper-step decision time (same run): learned policy vs the analytic policy of its role")
    for name, role, tl, ta in timing:
        print(
            f"  {name:<40} {tl * 1e3:8.3f} ms vs {ANALYTIC[role]} {ta * 1e3:8.3f} ms "
            f"(ratio analytic/learned {ta / tl:6.2f}x)"
        )


if __name__ == "__main__":
    main()
