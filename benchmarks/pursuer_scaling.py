"""The decomposition pursuer on large maps: set-up time, peak memory and decision time.

Each world is played in a fresh process with an empty cache directory (so the
decomposition is built, not read): the pursuer's set-up (``reset``: decomposition plus
safety table), the process's peak memory, and the mean and largest decision time over
an episode against ``evader/straight`` from a valid start. Worlds: the corridor of the
paper's Fig. 3 (the reference, eager table), generated floor plans of about 300 and
1000 vertices (60 m and 200 m square, L_min = 3; the table is filled lazily around the
evader) and the 1000-vertex plan scaled by 1e3 (nothing may depend on the units).
Issue 10's goals: ready in under 60 s and 2 GB, under 1 ms per decision.

Usage::

    python benchmarks/pursuer_scaling.py [--steps 300] [--quick]
"""

from __future__ import annotations

import argparse
import multiprocessing as mp
import os
import resource
import tempfile
import time

import numpy as np
from bench_cli import integer, run


def _world(spec):
    from envs.maps import builtin_map, floor_plan

    kind, n, size, scale = spec
    if kind == "builtin":
        return builtin_map(n), {}
    m = floor_plan(0, n_vertices=n, size=size)
    if scale != 1.0:
        m = m.transformed(np.eye(2) * scale)
    p = {"l_min": 3.0 * scale, "l_max": 6.0 * scale, "v_pursuer": 1.0 * scale}
    p.update(v_evader=0.5 * scale, body_radius=0.2 * scale)
    return m, p


def _measure(spec, steps, q):
    with tempfile.TemporaryDirectory() as cache:
        os.environ["SURVEIL_CACHE_DIR"] = cache
        from envs import surveillance_v1
        from strategies.policies import make_policy
        from strategies.policies.starts import sample_start

        world, params = _world(spec)
        env = surveillance_v1.parallel_env(map=world, max_cycles=steps, **params)
        c = env.config
        p = make_policy("pursuer/decomposition")
        t0 = time.perf_counter()
        p.reset(role="pursuer", map=c.map, config=c, seed=0)
        setup = time.perf_counter() - t0
        e = make_policy("evader/straight")
        e.reset(role="evader", map=c.map, config=c, seed=0)
        start = sample_start(c, np.random.default_rng(0), kind="valid")
        obs, _ = env.reset(seed=0, options=start)
        p.reset(role="pursuer", map=c.map, config=c, seed=0)  # the same table, in memory
        times = []
        while env.agents:
            t = time.perf_counter()
            a = p.act(obs["pursuer_0"])
            times.append(time.perf_counter() - t)
            obs, *_ = env.step({"pursuer_0": a, "evader_0": e.act(obs["evader_0"])})
        peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1e6
        kind = type(p.table).__name__
        q.put((len(world.vertices), setup, peak, np.mean(times), np.max(times), kind))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=integer(1), default=300)
    ap.add_argument("--quick", action="store_true", help="skip the 1000-vertex plans")
    args = ap.parse_args(argv)
    print(f"load average: {os.getloadavg()}")
    worlds = [
        ("corridor (ref)", ("builtin", "corridor", None, 1.0)),
        ("plan ~300 v, 60 m", ("plan", 300, 60.0, 1.0)),
    ]
    if not args.quick:
        worlds += [
            ("plan ~1000 v, 200 m", ("plan", 1000, 200.0, 1.0)),
            ("same x1e3", ("plan", 1000, 200.0, 1e3)),
        ]
    ctx = mp.get_context("spawn")
    print(
        f"{'world':<22}{'vertices':>9}{'set-up s':>10}{'x ref':>8}{'peak GB':>9}"
        f"{'decide ms':>11}{'max ms':>9}{'x ref':>7}  table"
    )
    ref = None
    for label, spec in worlds:
        q = ctx.Queue()
        proc = ctx.Process(target=_measure, args=(spec, args.steps, q))
        proc.start()
        n, setup, peak, mean, worst, kind = q.get()
        proc.join()
        if ref is None:
            ref = (setup, mean)
        print(
            f"{label:<22}{n:>9}{setup:>10.1f}{setup / ref[0]:>8.1f}{peak:>9.2f}"
            f"{1e3 * mean:>11.3f}{1e3 * worst:>9.1f}{mean / ref[1]:>7.1f}  {kind}"
        )
    print(f"(peak memory of the whole process; {resource.getpagesize()} B pages)")
    return 0


if __name__ == "__main__":
    raise SystemExit(run(main))
