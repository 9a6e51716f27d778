"""Time of :func:`strategies.cspace.decompose` on the built-in worlds and on random maps.

Prints, for each world, the wall-clock time of one decomposition (best of ``--repeat``),
its size (curves, regions, cells) and its ratio to a reference measured in the same run
(the decomposition of ``open_room``); then the exponent ``k`` of ``time ~ n^k`` fitted by
least squares on the random maps with n = 8 ... 128 obstacle vertices, and the cost of
the per-step query :meth:`Decomposition.safe_arcs` (what the decomposition pursuer calls).

Goals (issue "Configuration-space theory"): the paper's worlds under 2 s each, k <= 2.5,
``safe_arcs`` under 1 ms.

Usage::

    python benchmarks/decomposition_scaling.py [--L 2.0] [--repeat 3] [--seeds 2]
        [--sizes 8 16 32 64 128]
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

from envs.maps import builtin_map, builtin_names, random_map
from strategies.cspace import decompose

PAPER_WORLDS = ("corridor", "two_rooms", "open_room", "corner")


def _time(world, L: float, repeat: int):
    best, dec = math.inf, None
    for _ in range(repeat):
        t = time.perf_counter()
        dec = decompose(world, L)
        best = min(best, time.perf_counter() - t)
    return best, dec


def _row(name: str, n: int, t: float, ref: float, dec) -> str:
    curves = sum(c.type > 0 for c in dec.curves)
    return (
        f"{name:<22} {n:>5} {t:>9.3f} {t / ref:>8.1f} {curves:>7} {len(dec.regions):>8} "
        f"{len(dec.cells):>7} {dec.unresolved:>6}  {'evader' if dec.evader_wins else 'pursuer'}"
    )


def _safe_arcs_time(dec, n_queries: int = 2000) -> float:
    rng = np.random.default_rng(0)
    xmin, ymin, xmax, ymax = dec.map.bounds
    pts = rng.uniform([xmin, ymin], [xmax, ymax], size=(4 * n_queries, 2))
    pts = pts[dec.map.contains(pts)][:n_queries]
    t = time.perf_counter()
    for p in pts:
        dec.safe_arcs(p)
    return (time.perf_counter() - t) / len(pts)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--L", type=float, default=2.0, help="rod length (default 2)")
    ap.add_argument("--repeat", type=int, default=3, help="timings per world, best kept")
    ap.add_argument("--seeds", type=int, default=2, help="random maps per size")
    ap.add_argument("--sizes", type=int, nargs="+", default=[8, 16, 32, 64, 128])
    args = ap.parse_args(argv)

    ref_t, ref_dec = _time(builtin_map("open_room"), args.L, max(args.repeat, 5))
    header = (
        f"{'world':<22} {'n':>5} {'time [s]':>9} {'x ref':>8} {'curves':>7} {'regions':>8} "
        f"{'cells':>7} {'unres':>6}  verdict"
    )
    print(f"decompose at L = {args.L:g}; reference: open_room {ref_t * 1e3:.1f} ms\n")
    print(header)
    print("-" * len(header))
    names = [n for n in PAPER_WORLDS if n in builtin_names()]
    names += [n for n in builtin_names() if n not in names]
    slow_paper = []
    for name in names:
        world = builtin_map(name)
        t, dec = _time(world, args.L, args.repeat)
        print(_row(name, world.n_vertices, t, ref_t, dec))
        if name in PAPER_WORLDS and t >= 2.0:
            slow_paper.append(name)
    ns, ts = [], []
    for n in args.sizes:
        for seed in range(args.seeds):
            world = random_map(seed, n_vertices=n)
            t, dec = _time(world, args.L, max(1, args.repeat // 2))
            print(_row(f"random n={n} seed={seed}", world.n_vertices, t, ref_t, dec))
            ns.append(n)
            ts.append(t)
    k, _ = np.polyfit(np.log(ns), np.log(ts), 1)
    print(
        f"\nfitted exponent: time ~ n^{k:.2f} over n = {min(ns)}..{max(ns)} "
        f"(goal <= 2.5: {'met' if k <= 2.5 else 'NOT met'})"
    )
    print("paper's worlds under 2 s each: " + ("yes" if not slow_paper else f"no {slow_paper}"))
    q = _safe_arcs_time(decompose(builtin_map("corridor"), args.L))
    qr = _safe_arcs_time(ref_dec)
    print(
        f"safe_arcs per query: corridor {q * 1e3:.3f} ms, open_room {qr * 1e3:.3f} ms "
        f"(ratio {q / qr:.2f}; goal < 1 ms)"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
