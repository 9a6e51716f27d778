"""Tournament throughput: serial vs processes vs Ray on this machine, in one run.

One spec (analytic policies and baselines on two built-in worlds, short episodes) is played
into a fresh SQLite store by each backend in turn, with the decomposition caches warmed
first so every backend plays the same work. Printed per backend: matches, wall time,
matches per second and the ratio to the serial backend measured in the same run (the
issue's goals: 2 processes >= 1.8x serial; Ray within 15% of the processes), Ray both
cold (starting a local instance, counted in the time) and warm (its workers up), plus the
driver's own cost per match: wall time of the serial run minus the time spent inside
the matches, divided by the matches (spec expansion, identity hashing, one SQLite
transaction per match, progress).

Usage::

    python benchmarks/tournament_scaling.py [--seeds 12] [--max-cycles 300] [--workers 2]
        [--no-ray]

The first line prints the load average: ratios are only meaningful on a quiet machine.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

from bench_cli import integer, run

from analysis.tournament import Store, run_tournament, spec_from_dict


def _spec(seeds: int, max_cycles: int) -> dict:
    return {
        "name": "scaling",
        "maps": ["corridor", "open_room"],
        "pursuers": ["pursuer/decomposition", "pursuer/greedy", "pursuer/tractrix"],
        "evaders": ["evader/straight", "evader/toward_away", "evader/random"],
        "seeds": seeds,
        "start": "valid",
        "env": {"max_cycles": max_cycles},
    }


def _play(spec: dict, store: Path, backend: str, workers: int | None) -> tuple[float, int, float]:
    t0 = time.perf_counter()
    summary = run_tournament(
        spec_from_dict(spec), store, backend=backend, workers=workers, progress=False
    )
    wall = time.perf_counter() - t0
    if summary.interrupted:  # a timing of part of the run would be wrong: stop
        raise KeyboardInterrupt(summary.interrupted)
    with Store(store, create=False) as db:
        rows = db.rows(summary.run_id)
    inside = sum(r["wall_seconds"] or 0.0 for r in rows)
    return wall, summary.played, inside


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=integer(1), default=12)
    ap.add_argument("--max-cycles", type=integer(1), default=300)
    ap.add_argument("--workers", type=integer(1), default=2)
    ap.add_argument("--no-ray", action="store_true", help="skip the Ray backend")
    args = ap.parse_args(argv)
    print(f"load average: {os.getloadavg()}; cpus: {os.cpu_count()}")
    spec = _spec(args.seeds, args.max_cycles)
    with tempfile.TemporaryDirectory() as tmp:
        # warm the decomposition caches (shared on disk by every backend)
        warm = dict(spec, seeds=1, name="warm")
        _play(warm, Path(tmp) / "warm.sqlite", "serial", None)

        backends = [("serial", None), ("process", args.workers)]
        if not args.no_ray:
            try:
                import ray

                backends.append(("ray", args.workers))
            except ImportError:
                print("ray not installed (pip install 'surveil[ray]'): skipped")
        results = {}
        ray_start = None
        for backend, workers in backends:
            if backend == "ray":
                # cold: the run starts a local Ray instance and its workers import the
                # project; then warm: the same instance, workers up (a week-long run's
                # steady state)
                import ray

                t0 = time.perf_counter()
                ray.init(num_cpus=workers, include_dashboard=False, log_to_driver=False)
                ray_start = time.perf_counter() - t0
                cold = _play(spec, Path(tmp) / "ray_cold.sqlite", backend, workers)
                results["ray(cold)"] = (cold[0] + ray_start, *cold[1:])
                results["ray"] = _play(spec, Path(tmp) / "ray.sqlite", backend, workers)
                ray.shutdown()
                continue
            wall, n, inside = _play(spec, Path(tmp) / f"{backend}.sqlite", backend, workers)
            results[backend] = (wall, n, inside)
        ref_rate = results["serial"][1] / results["serial"][0]
        print(f"{'backend':<15}{'matches':>8}{'wall s':>9}{'matches/s':>11}{'x serial':>10}")
        for backend, (wall, n, _) in results.items():
            name = backend
            if backend != "serial":
                name = backend.replace("(cold)", "") + f"({args.workers})"
                name += " cold" if "cold" in backend else (" warm" if backend == "ray" else "")
            rate = n / wall
            print(f"{name:<15}{n:>8}{wall:>9.2f}{rate:>11.2f}{rate / ref_rate:>10.2f}")
        if "ray" in results:
            p = results["process"][1] / results["process"][0]
            r = results["ray"][1] / results["ray"][0]
            print(f"ray (warm) / process: {r / p:.2f}; starting Ray took {ray_start:.1f} s")
        wall, n, inside = results["serial"]
        print(
            f"driver + store overhead (serial): {1e3 * (wall - inside) / n:.2f} ms per match "
            f"({100 * (wall - inside) / wall:.1f}% of the run; a match takes "
            f"{1e3 * inside / n:.1f} ms on average)"
        )
    return 0


if __name__ == "__main__":
    sys.exit(run(main))
