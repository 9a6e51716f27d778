"""Decision time of the analytic policies (issue 13: under 1 ms per decision).

For each map, seeded episodes of ``pursuer/decomposition`` against ``evader/shooting``
from safe starts are played through the shared runner, recording what each side
observed. Each policy is then replayed over those observations (a fresh policy, reset as
in the episode, so it takes the same decisions): ``pursuer/decomposition`` and the
reference ``pursuer/greedy`` on the pursuer's, ``evader/shooting`` on the evader's. Each
replay is repeated ``--reps`` times and the time of a step is the least over the
repeats, which filters out the other processes' interference on a shared machine; the
first decision of an episode (it may finish lazy set-up) is left out.

Printed per policy and map: mean, 99th percentile and max of the wall-clock time per
``act`` call in ms, and the mean and p99 as multiples of the greedy pursuer's mean in
the same run (the machine-independent figures).

Usage::

    python benchmarks/decision_time.py [--maps corridor two_rooms ...] [--seeds 2]
        [--max-cycles 300] [--reps 3]
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

from strategies.policies import make_policy
from strategies.runner import episode_seeds, run_episode

MAPS = ["corridor", "two_rooms", "office", "l_hall", "maze"]
REFERENCE = "pursuer/greedy"
POLICIES = [("pursuer/decomposition", "pursuer"), ("evader/shooting", "evader")]


def _replay(name: str, role: str, result, observations, seed: int, reps: int) -> np.ndarray:
    """Seconds per decision (least over ``reps`` replays), first decision left out."""
    runs = []
    for _ in range(reps):
        policy = make_policy(name)
        policy.reset(role=role, map=result.config.map, config=result.config, seed=seed)
        times = []
        for obs in observations:
            t0 = time.perf_counter()
            policy.act(obs[role])
            times.append(time.perf_counter() - t0)
        runs.append(times[1:])
    return np.min(np.asarray(runs), axis=0)


def measure(map_name: str, seeds: int, max_cycles: int, reps: int) -> dict[str, np.ndarray]:
    """Per-decision seconds of each policy (and the reference) on ``map_name``."""
    out: dict[str, list[np.ndarray]] = {}
    for seed in range(seeds):
        observations = []
        result = run_episode(
            map_name,
            POLICIES[0][0],
            POLICIES[1][0],
            seed,
            start="safe",
            max_cycles=max_cycles,
            on_step=lambda t, seen=observations: seen.append(t.observations),
        )
        _, _, s_pursuer, s_evader = episode_seeds(seed)
        role_seed = {"pursuer": s_pursuer, "evader": s_evader}
        for name, role in [*POLICIES, (REFERENCE, "pursuer")]:
            out.setdefault(name, []).append(
                _replay(name, role, result, observations, role_seed[role], reps)
            )
    return {name: np.concatenate(v) for name, v in out.items()}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--maps", nargs="+", default=MAPS)
    ap.add_argument("--seeds", type=int, default=2)
    ap.add_argument("--max-cycles", type=int, default=300)
    ap.add_argument("--reps", type=int, default=3)
    args = ap.parse_args(argv)
    print(f"load average: {os.getloadavg()}")
    print(
        f"{'map':<11}{'policy':<24}{'steps':>6}{'mean ms':>9}{'p99 ms':>8}{'max ms':>8}"
        f"{'mean/ref':>10}{'p99/ref':>9}"
    )
    worst = {name: 0.0 for name, _ in POLICIES}
    for map_name in args.maps:
        times = measure(map_name, args.seeds, args.max_cycles, args.reps)
        ref = float(times[REFERENCE].mean())
        for name in [*(n for n, _ in POLICIES), REFERENCE]:
            t = times[name] * 1e3
            mean, p99 = float(t.mean()), float(np.percentile(t, 99))
            if name in worst:
                worst[name] = max(worst[name], mean)
            print(
                f"{map_name:<11}{name:<24}{len(t):>6}{mean:>9.3f}{p99:>8.3f}{t.max():>8.3f}"
                f"{mean / (1e3 * ref):>10.1f}{p99 / (1e3 * ref):>9.1f}"
            )
    for name, mean in worst.items():
        verdict = "PASS" if mean < 1.0 else "FAIL"
        print(f"{verdict} {name}: mean decision time <= {mean:.3f} ms on every map (< 1 ms)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
