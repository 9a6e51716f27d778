"""The referee's estimate evader against the decomposition pursuer: how often it escapes.

``EstimateEvader`` (:mod:`strategies.referee.estimate_policy`, not registered) plays the
plain discrete game's evader strategy (the referee section of README). It is the strongest
evader the project has where the registered ones lose: on the corner world at rho 0.5 the
referee certifies every safe start an evader win, yet the decomposition pursuer holds all
64 of ``pursuer_holds.py``'s episodes there. This plays it from the same starts and with the
same settings as ``pursuer_holds.py`` (the world's own parameters, rho * V_p, body radius
0.2, 600 steps, the safe start of each seed)::

    python benchmarks/estimate_evader.py --worlds corner pillars --rho 0.5 --cpl 6 8

and prints, per world, rho and resolution, the seeds it escapes from.
"""

from __future__ import annotations

import argparse
import os

from bench_cli import integer, real

from envs.maps import builtin_info, builtin_names, load_map
from strategies.referee import EstimateEvader
from strategies.runner import run_episode


def escapes(world: str, rho: float, cpl: float, seeds: int, max_cycles: int) -> list[int]:
    """The seeds from whose safe start the estimate evader at ``cpl`` cells per L_min
    escapes the decomposition pursuer on ``world`` (a built-in name, or one with a
    ``~`` transform of it) at ``rho``."""
    info = builtin_info(world.split("~")[0])
    params = {**info.params(), "v_evader": rho, "body_radius": 0.2}
    won = []
    for seed in range(seeds):
        ev = EstimateEvader(cells_per_lmin=cpl)
        r = run_episode(load_map(world), "pursuer/decomposition", ev, seed,
                        max_cycles=max_cycles, overrides=params)  # fmt: skip
        if r.winner == "evader":
            won.append(seed)
    return won


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--worlds", nargs="+", default=["corner"],
                    help=f"built-in worlds ({', '.join(builtin_names())}), each may carry a "
                    "~transform (corner~rot0.37)")  # fmt: skip
    ap.add_argument("--rho", type=real(0), nargs="+", default=[0.5])
    ap.add_argument("--cpl", type=real(0), nargs="+", default=[6.0, 8.0],
                    help="the estimate's cells per L_min")  # fmt: skip
    ap.add_argument("--seeds", type=integer(1), default=8)
    ap.add_argument("--max-cycles", type=integer(1), default=600)
    args = ap.parse_args(argv)
    print(f"load average: {os.getloadavg()}")
    for world in args.worlds:
        if world.split("~")[0] not in builtin_names():
            ap.error(f"--worlds: {world!r}: expected a built-in world, optionally ~transformed")
        for rho in args.rho:
            for cpl in args.cpl:
                won = escapes(world, rho, cpl, args.seeds, args.max_cycles)
                print(f"{world} rho={rho:g} cpl={cpl:g}: the estimate evader escapes "
                      f"{len(won)}/{args.seeds} (seeds {won})", flush=True)  # fmt: skip
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
