"""Could any pursuer have held against the maze's wall hugger? Hindsight reachable sets.

The decomposition pursuer's maze loss against ``evader/wall_hugging`` (episode seed 2 of
``benchmarks/pursuer_holds.py --worlds maze --variants "as is" --rho 0.5``: body radius
0.2, safe start; occluded at 4.29 s). The wall hugger is open-loop (its path does not
depend on the pursuer), so :func:`strategies.referee.hindsight.hindsight` brackets the
truth against its path: the path is recorded from the episode (checked identical against
the decomposition and greedy pursuers) and extended past the break by replaying the
evader alone (``--steps`` env steps in all); then, for each cell side, the optimistic
set (empty: no pursuer could hold) and the pessimistic one (non-empty: a pursuer held,
its witness path) are computed, with their wall-clock cost. ``--witness`` replays the
pessimistic witness of each cell in the env as a scripted pursuer (when the pessimistic
step is the env's). ``--v-pursuer`` asks the question of a slower (or faster) pursuer
against the same path.

Usage::

    python benchmarks/hindsight_maze.py [--cells 0.04 0.02 0.01] [--steps 60]
        [--substeps N] [--moves 10] [--pieces 4] [--clearance R] [--v-pursuer 1] [--witness]
"""

from __future__ import annotations

import argparse
import os

import numpy as np
from bench_cli import integer, real, run

from envs.errors import MemoryBudgetError
from envs.maps import builtin_info
from envs.surveillance.config import EnvConfig
from strategies.policies.base import BasePolicy
from strategies.referee.hindsight import hindsight, record_evader_path
from strategies.runner import run_episode


class _Scripted(BasePolicy):
    """Follows a path given one position per env step (straight moves in between)."""

    def __init__(self, path: np.ndarray, name: str = "pursuer/witness") -> None:
        super().__init__(name=name)
        self.path = path

    def _decide(self, snap):
        k = self._steps
        if k + 1 >= len(self.path):
            return np.zeros(2)
        return (self.path[k + 1] - self.path[k]) / self.config.dt


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cells", type=real(0), nargs="+", default=[0.04, 0.02, 0.01])
    ap.add_argument("--steps", type=integer(1), default=60, help="env steps of evader path")
    ap.add_argument("--substeps", type=integer(1), default=None, help="optimistic steps a frame")
    ap.add_argument("--moves", type=real(1), default=10.0)
    ap.add_argument("--pieces", type=integer(1), default=4)
    ap.add_argument("--clearance", type=real(0), default=None)
    ap.add_argument("--v-pursuer", type=real(0), default=None, help="the pursuer's speed bound")
    ap.add_argument("--witness", action="store_true", help="replay the witnesses in the env")
    args = ap.parse_args(argv)
    print(f"load average: {os.getloadavg()}")
    info = builtin_info("maze")
    params = {**info.params(), "v_evader": 0.5, "body_radius": 0.2}
    path = record_evader_path(
        info.map,
        "evader/wall_hugging",
        2,
        overrides=params,
        max_cycles=600,
        extend_to=args.steps,
    )
    print(f"evader path: {path.lengths} frames (the same on their common frames)")
    cfg = EnvConfig(map=info.map, **params)
    if args.v_pursuer is not None:  # the question of another pursuer; the path stays
        cfg = EnvConfig(map=info.map, **{**params, "v_pursuer": args.v_pursuer})
        print(f"V_p = {args.v_pursuer:g} (the path was recorded at V_p = {params['v_pursuer']:g})")
    for h in args.cells:
        with MemoryBudgetError.naming("--cells"):  # this script's flag
            r = hindsight(
                cfg,
                path,
                path.pursuer_start,
                h,
                substeps=args.substeps,
                moves=args.moves,
                pieces=args.pieces,
                clearance=args.clearance,
            )
        print(
            f"cell {h:g}: {r.verdict:8s} optimistic empty at {r.optimistic_empty}, "
            f"pessimistic until {r.pessimistic_until:.2f} s of {r.horizon:.2f} "
            f"(tau {r.tau:.4f}, {r.pessimistic_tau:.4f}); "
            f"largest sets {r.optimistic_cells.max()} / {r.pessimistic_cells.max()} cells; "
            f"{r.seconds:.1f} s (estimated up to {r.estimated_seconds:.1f} s)",
            flush=True,
        )
        replayable = args.v_pursuer is None and abs(r.pessimistic_tau - cfg.dt) < 1e-12
        if args.witness and replayable and len(r.witness) > 1:
            ep = run_episode(
                info.map,
                _Scripted(r.witness),
                "evader/wall_hugging",
                2,
                overrides=params,
                max_cycles=len(r.witness) - 1,
            )
            held = "held" if ep.winner == "pursuer" else f"lost ({ep.cause} at {ep.escape_time})"
            print(f"  witness replayed in the env for {ep.steps * ep.dt:.2f} s: {held}")
    return 0


if __name__ == "__main__":
    raise SystemExit(run(main))
