"""Issue 13's question: in the pillar room, is the chargers' win a weakness of the pursuers
or a loss no pursuer can avoid?

The pillar room is the one the policies' tests use (``tests/strategies/policies/
conftest.py``): a 12 x 8 room with a 2 x 2 pillar at (8..10, 5..7), L in [2, 4], rho = 0.5,
body radius 0.1. For each resolution the script prints:

* the referee's labels over all lattice starts (pursuer / evader / unknown);
* the decomposition's verdict for an infinitely fast pursuer (Prop. 2 at L_min and
  Prop. 4 over [L_min, L_max]);
* the label of each of the decomposition's own safe starts (the starts issue 13's
  episodes use: ``strategies.policies.starts.sample_start``, seeds 0..n-1), with the
  certified time within which the evader breaks surveillance;
* and, from those starts, every registered pursuer against the referee's own certified
  evader (``RefereeEvader``) through the shared runner: who won, and when;
* then the *estimate* (``strategies.referee.estimates``: the plain discrete game at the
  ``--estimate-cpl`` resolutions, both information orders; not a certificate): its shares
  over the lattice starts, its contested share (the resolution error), and the estimated
  label of each safe start.

``--world centered`` moves the pillar to the middle of the room (5..7, 3..5), where the
gaps are wider than L_max and Prop. 2 no longer decides.

Usage::

    python benchmarks/referee_pillar.py [--cpl 24 32] [--starts 6] [--world box|centered]
        [--estimate-cpl 6 8]
"""

from __future__ import annotations

import argparse
import os
import time
import warnings

import numpy as np
from bench_cli import integer, real, run


def _world(name: str):
    from envs.maps import Map

    pillar = {"box": [(8, 5), (10, 5), (10, 7), (8, 7)],
              "centered": [(5, 3), (7, 3), (7, 5), (5, 5)]}[name]  # fmt: skip
    return Map([(0, 0), (12, 0), (12, 8), (0, 8)], [pillar], name=f"pillar_{name}")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cpl", type=real(0), nargs="+", default=[24.0, 32.0])
    parser.add_argument("--starts", type=integer(1), default=6)
    parser.add_argument("--world", choices=["box", "centered"], default="box")
    parser.add_argument("--rho", type=real(0), default=0.5)
    parser.add_argument("--estimate-cpl", type=real(0), nargs="*", default=[6.0, 8.0],
                        help="resolutions of the estimate (none: skip it)")  # fmt: skip
    args = parser.parse_args(argv)

    from envs.errors import MemoryBudgetError, VacuousBoundWarning
    from envs.surveillance.config import EnvConfig
    from strategies.cspace import decompose, surveillance_verdict
    from strategies.policies.registry import policy_names
    from strategies.policies.starts import sample_start
    from strategies.referee import RefereeEvader, referee_for
    from strategies.runner import episode_seeds, run_episode

    world = _world(args.world)
    cfg = EnvConfig(map=world, l_min=2.0, l_max=4.0, v_pursuer=1.0, v_evader=args.rho)
    load = os.getloadavg()
    print(f"load average {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}; {world.name}: 12 x 8 room, "
          f"pillar {world.obstacles[0].min(axis=0)}..{world.obstacles[0].max(axis=0)}, "
          f"L in [2, 4], rho = {args.rho:g}")  # fmt: skip
    dec = decompose(world, 2.0)
    print(f"infinitely fast pursuer: Prop. 2 at L_min says evader wins = {dec.evader_wins}; "
          f"Prop. 4 over [2, 4] says evader wins = "
          f"{surveillance_verdict(world, 2.0, 4.0).evader_wins}")  # fmt: skip
    starts = []
    for s in range(args.starts):
        _, s_start, _, _ = episode_seeds(s)
        starts.append(sample_start(cfg, np.random.default_rng(s_start), kind="safe"))
    ref = None
    for cpl in args.cpl:
        t = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", VacuousBoundWarning)  # printed below
            with MemoryBudgetError.naming("--cpl"):  # this script's flag
                ref = referee_for(cfg, cpl)
        s = ref.summary()
        print(f"\ncells per L_min {cpl:g} ({time.perf_counter() - t:.0f} s): {s['starts']} "
              f"lattice starts, pursuer {s['pursuer']:.1%}, evader {s['evader']:.1%}, "
              f"unknown {s['gap']:.1%}")  # fmt: skip
        if s["pursuer_bound"]["vacuous"] is not None:
            print(f"  the pursuer share says nothing: {s['pursuer_bound']['vacuous']}")
        for i, st in enumerate(starts):
            label = ref.classify(st["pursuer"], st["evader"])
            extra = ""
            if label == "evader":
                extra = f", surveillance breaks within {ref.escape_time(**st):.1f} s"
            print(f"  safe start {i} P={np.round(st['pursuer'], 2).tolist()} "
                  f"E={np.round(st['evader'], 2).tolist()}: {label}{extra}")  # fmt: skip
    overrides = {"l_min": 2.0, "l_max": 4.0, "v_pursuer": 1.0, "v_evader": args.rho}
    print(
        "\nthe referee's certified evader from each safe start it certifies, against every "
        "registered pursuer (winner, time of the break):"
    )
    for i, st in enumerate(starts):
        if ref.classify(st["pursuer"], st["evader"]) != "evader":
            continue
        bound = ref.escape_time(**st)
        cycles = int(np.ceil(bound / cfg.dt)) + 20
        row = []
        for name in policy_names("pursuer"):
            r = run_episode(world, name, RefereeEvader(ref.evader), i, max_cycles=cycles,
                            overrides=overrides, start=st)  # fmt: skip
            t = "-" if r.escape_time is None else f"{r.escape_time:.1f}"
            row.append(f"{name.split('/')[1]} {r.winner} {t}")
        print(f"  start {i} (bound {bound:.1f} s): " + "; ".join(row))
    if len(set(args.estimate_cpl)) >= 2:
        _print_estimate(cfg, starts, args.estimate_cpl)
    return 0


def _print_estimate(cfg, starts, cpls) -> None:
    from envs.errors import MemoryBudgetError
    from strategies.referee import GameSpec, estimate

    t = time.perf_counter()
    with MemoryBudgetError.naming("the largest --estimate-cpl (the others in proportion)"):
        est = estimate(GameSpec.from_config(cfg), cpls)
    s = est.summary()
    print(f"\nthe estimate (the plain discrete game at {', '.join(f'{c:g}' for c in est.cpls)} "
          f"cells per L_min, both information orders; not a certificate; "
          f"{time.perf_counter() - t:.0f} s): {s['starts']} lattice starts, pursuer "
          f"{s['pursuer']:.1%}, evader {s['evader']:.1%}, contested {s['contested']:.1%} "
          "(the resolution error)")  # fmt: skip
    for sol in s["solutions"]:
        print(f"  {sol['cells_per_lmin']:g} cells per L_min ({sol['steps']:.3g} cells a step of "
              f"{sol['tau']:.3g} s, "
              f"{sol['states']} states, {sol['seconds']['build'] + sol['seconds']['solve']:.0f}"
              f" s): pursuer wins {sol['evader_first']:.1%} when the evader moves first, "
              f"{sol['pursuer_first']:.1%} when the pursuer does")  # fmt: skip
    for i, st in enumerate(starts):
        print(f"  safe start {i}: estimated {est.classify(st['pursuer'], st['evader'])}")


if __name__ == "__main__":
    raise SystemExit(run(main))
