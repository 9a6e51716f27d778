"""How the referee's cost and its resolution error scale with resolution.

For each resolution (``--cpl``: opponent cells per L_min) the referee of one small world is
solved in a fresh subprocess (so its peak memory is its own), uncached. Printed per
resolution, as each completes: the cell size, the state counts of both bounds, the wall
time of each bound (build + fixed point), the peak resident memory and beside it the
estimate the referee's memory budget made of it before solving (``est MB``,
:mod:`strategies.referee._budget`), the fractions of lattice starts each
bound certifies and the gap between them (the resolution error), and the time and memory
as ratios to the first (reference) resolution, measured in the same run. Then the
exponents k of ``time ~ cpl^k`` and ``memory ~ cpl^k`` fitted by least squares (the
state count grows as cpl^4: cells per axis squared times window cells squared).

Usage::

    python benchmarks/referee_scaling.py [--world dead_end|open|pillar] [--rho 0.2]
        [--cpl 8 12 16 20 24]

Run it on a quiet machine (the first line prints the load average): the ratios are
measured in one run, the absolute figures beside them depend on the machine.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import resource
import subprocess
import sys
import time

from bench_cli import real, run

WORLDS = ("dead_end", "open", "pillar")


def _world(name: str):
    from envs.maps import Map

    if name == "open":
        return Map([(0, 0), (5, 0), (5, 5), (0, 5)], name="open5")
    if name == "pillar":
        return Map(
            [(0, 0), (8, 0), (8, 8), (0, 8)],
            [[(3.5, 3.5), (4.5, 3.5), (4.5, 4.5), (3.5, 4.5)]],
            name="pillar8",
        )
    return Map(
        [(0, -2.5), (5, -2.5), (5, 2.5), (0, 2.5), (0, 0.25), (-2.5, 0.25), (-2.5, -0.25),
         (0, -0.25)],
        name="dead_end",
    )  # fmt: skip


def _child(world: str, rho: float, cpl: float) -> dict:
    """Solve once (in this process) and report."""
    from envs.errors import MemoryBudgetError
    from strategies.referee import GameSpec, solve

    spec = GameSpec(_world(world), 1.0, 2.0, 1.0, rho, body_radius=0.05)
    t = time.perf_counter()
    with MemoryBudgetError.naming("--cpl"):  # this script's flag
        ref = solve(spec, cpl, cache=False)
    total = time.perf_counter() - t
    s = ref.summary()
    peak_kb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    from strategies.referee._budget import bound_size, peak

    sizes = [
        bound_size(spec, ref.pursuer.res, "pursuer"),
        bound_size(spec, ref.evader.res, "evader"),
    ]
    return {
        "est_mb": peak(sizes)[0] / 2**20,
        "cpl": cpl,
        "cell": ref.pursuer.res.cell,
        "states_p": s["pursuer_bound"]["states"],
        "states_e": s["evader_bound"]["states"],
        "time_p": sum(s["pursuer_bound"]["seconds"].values()),
        "time_e": sum(s["evader_bound"]["seconds"].values()),
        "time": total,
        "peak_mb": peak_kb / 1024.0,
        "pursuer": s["pursuer"],
        "evader": s["evader"],
        "gap": s["gap"],
        "starts": s["starts"],
    }


def _fit(xs, ys) -> float:
    lx = [math.log(x) for x in xs]
    ly = [math.log(max(y, 1e-12)) for y in ys]
    mx, my = sum(lx) / len(lx), sum(ly) / len(ly)
    den = sum((a - mx) ** 2 for a in lx)
    return sum((a - mx) * (b - my) for a, b in zip(lx, ly, strict=True)) / den if den else 0.0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--world", choices=WORLDS, default="dead_end")
    parser.add_argument("--rho", type=real(0), default=0.2)
    parser.add_argument("--cpl", type=real(0), nargs="+", default=[8, 12, 16, 20, 24])
    parser.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.child:
        print(json.dumps(_child(args.world, args.rho, args.cpl[0])))
        return 0
    print(f"load average {os.getloadavg()[0]:.2f} {os.getloadavg()[1]:.2f} "
          f"{os.getloadavg()[2]:.2f} on {os.cpu_count()} cores; world {args.world}, "
          f"rho = {args.rho:g}, L in [1, 2]")  # fmt: skip
    rows = []
    head = (f"{'cpl':>5} {'cell':>7} {'states P':>10} {'states E':>10} {'time P':>8} "
            f"{'time E':>8} {'time':>8} {'x ref':>7} {'peak MB':>8} {'x ref':>6} "
            f"{'est MB':>7} {'pursuer':>8} {'evader':>7} {'gap':>6}")  # fmt: skip
    for cpl in args.cpl:
        out = subprocess.run(
            [sys.executable, __file__, "--child", "--world", args.world, "--rho",
             str(args.rho), "--cpl", str(cpl)],
            capture_output=True, text=True,
        )  # fmt: skip
        if out.returncode != 0:  # the child's last line says why (e.g. out of memory)
            last = (out.stderr.strip().splitlines() or ["no message"])[-1]
            print(f"cpl {cpl:g}: the solve failed (exit code {out.returncode}): {last}",
                  file=sys.stderr)  # fmt: skip
            return 1
        r = json.loads(out.stdout.strip().splitlines()[-1])
        rows.append(r)
        ref = rows[0]
        if len(rows) == 1:
            print(head)
        print(  # each row as its resolution completes (a stop keeps the rows printed)
            f"{r['cpl']:>5g} {r['cell']:>7.4f} {r['states_p']:>10d} {r['states_e']:>10d} "
            f"{r['time_p']:>7.2f}s {r['time_e']:>7.2f}s {r['time']:>7.2f}s "
            f"{r['time'] / ref['time']:>7.1f} {r['peak_mb']:>8.0f} "
            f"{r['peak_mb'] / ref['peak_mb']:>6.1f} {r['est_mb']:>7.0f} {r['pursuer']:>8.3f} "
            f"{r['evader']:>7.3f} {r['gap']:>6.3f}",
            flush=True,
        )
    if len(rows) > 1:
        cpl = [r["cpl"] for r in rows]
        print(
            f"fitted exponents: time ~ cpl^{_fit(cpl, [r['time'] for r in rows]):.2f}, "
            f"states ~ cpl^{_fit(cpl, [r['states_p'] + r['states_e'] for r in rows]):.2f}, "
            f"peak memory ~ cpl^{_fit(cpl, [r['peak_mb'] for r in rows]):.2f}"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(run(main))
