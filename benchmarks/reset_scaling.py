"""The shooting evader's set-up on large maps: reset time and peak memory (issue 13).

Each policy is reset in a fresh process with an empty cache directory (the decomposition
and the tables are built, not read), and the process's peak memory is read after the
reset. The reference, measured in the same run on the same map, is the decomposition
pursuer's reset (its own decomposition at its rod length and its safety table, filled
lazily above ``DecompositionPursuer.DISTINCT_TABLE_POINTS`` grid points); the ratios
are machine independent. Each reset's CPU time (the process's, all threads) is given
too, with its ratio: on a loaded machine the wall-clock ratios scatter (the shooting
evader on floor_plan:0:200 at one commit: 2.9x and 6.5x in two runs at load ~5), its CPU
time less (16.6 s in both of two other runs).

Worlds (``--worlds``, default all): ``corner~x100`` (the corner world scaled x100 at its
L_min 2: 115 million grid points at L_min / 20, which the evader's distinct table used to
tabulate), ``floor_plan:0:60`` and ``floor_plan:0:200`` (generated buildings, 60 m at
L_min 2 and 200 m at L_min 3), ``pillars*3`` and ``pillar_room`` (a 60 x 56 room with
210 square pillars 0.8 wide).

``--table distinct`` forces the shooting evader's whole-map table (the behaviour before
its lazy table: on corner~x100 that takes tens of minutes and gigabytes).

Usage::

    python benchmarks/reset_scaling.py [--worlds corner~x100 pillars*3 ...]
        [--table auto|distinct|lazy] [--timeout 1800]
"""

from __future__ import annotations

import argparse
import multiprocessing as mp
import os
import queue
import resource
import tempfile
import time

from bench_cli import real, run

WORLDS = ["corner~x100", "floor_plan:0:60", "pillars*3", "pillar_room", "floor_plan:0:200"]
POLICIES = ["pursuer/decomposition", "evader/shooting"]


def _world(spec: str):
    """The map and env overrides of a ``--worlds`` entry."""
    from decision_time import world

    from envs.maps import Map
    from envs.surveillance.config import resolve_map

    if spec == "pillar_room":

        def square(x, y, r):
            return [(x - r, y - r), (x + r, y - r), (x + r, y + r), (x - r, y + r)]

        pillars = [square(2 + 4 * i, 2 + 4 * j, 0.4) for i in range(15) for j in range(14)]
        return Map([(0, 0), (60, 0), (60, 56), (0, 56)], pillars, name="pillar_room"), {}
    if spec == "floor_plan:0:200":
        m, _ = world(spec)
        return m, {"l_min": 3.0, "l_max": 6.0}
    if "~" in spec:
        return resolve_map(spec), {}
    m, params = world(spec)
    return (resolve_map(m) if isinstance(m, str) else m), params


def _measure(spec: str, name: str, table: str, q) -> None:
    with tempfile.TemporaryDirectory() as cache:
        os.environ["SURVEIL_CACHE_DIR"] = cache
        from envs.surveillance.config import EnvConfig
        from strategies.policies import make_policy

        m, params = _world(spec)
        config = EnvConfig(map=m, **params)
        # (the default unnamed: the script runs on commits before the evader's option)
        kw = {"table": table} if name == "evader/shooting" and table != "auto" else {}
        policy = make_policy(name, **kw)
        t0, c0 = time.perf_counter(), time.process_time()
        policy.reset(role=name.split("/")[0], map=m, config=config, seed=0)
        seconds, cpu = time.perf_counter() - t0, time.process_time() - c0
        peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1e6
        points = m.free_region.area / (config.l_min / 20.0) ** 2
        q.put((seconds, cpu, peak, type(policy.table).__name__, points))


def _run(spec: str, name: str, table: str, timeout: float):
    ctx = mp.get_context("spawn")
    q = ctx.Queue()
    proc = ctx.Process(target=_measure, args=(spec, name, table, q))
    proc.start()
    try:
        return q.get(timeout=timeout)
    except queue.Empty:
        proc.kill()
        return None
    finally:
        proc.join()


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--worlds", nargs="+", choices=WORLDS, default=WORLDS, metavar="WORLD")
    ap.add_argument("--table", choices=["auto", "distinct", "lazy"], default="auto")
    ap.add_argument("--timeout", type=real(0), default=1800.0, help="seconds per reset")
    args = ap.parse_args(argv)
    print(f"load average: {os.getloadavg()}; shooting evader's table: {args.table}")
    print(
        f"{'world':<18}{'points':>10}{'policy':>23}{'reset s':>9}{'cpu s':>8}{'peak GB':>9}"
        f"{'s/ref':>7}{'cpu/ref':>8}{'GB/ref':>8}  table"
    )
    for spec in args.worlds:
        ref = None
        for name in POLICIES:
            got = _run(spec, name, args.table, args.timeout)
            if got is None:
                print(f"{spec:<18}{'':>10}{name:>23}  over {args.timeout:g} s (killed)")
                continue
            seconds, cpu, peak, kind, points = got
            ref = ref or (seconds, max(cpu, 1e-9), peak)
            print(
                f"{spec:<18}{points:>10.3g}{name:>23}{seconds:>9.2f}{cpu:>8.2f}{peak:>9.2f}"
                f"{seconds / ref[0]:>7.2f}{cpu / ref[1]:>8.2f}{peak / ref[2]:>8.2f}  {kind}",
                flush=True,
            )
    print("(peak: the resetting process's maximum resident set, imports included)")
    return 0


if __name__ == "__main__":
    raise SystemExit(run(main))
