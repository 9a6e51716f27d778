"""Cost of :func:`strategies.cspace.decompose` from the paper's worlds to floor plans.

Each world is decomposed in a fresh process, which reports its wall time, its peak
memory (the process's maximum resident set), the decomposition's size (pairs of
meeting curves estimated, regions, cells), whether every exactness check passed, the
time to write and then read it back from the on-disk cache, and the per-query cost of
``Decomposition.safe_arcs`` (what the decomposition pursuer asks each step). Times and
memory are printed beside their ratio to a reference measured in the same run (the
empty 10 x 10 room at L = 2), and the exponent ``k`` of ``time ~ n^k`` is fitted over
every unscaled ring and floor plan (n = wall vertices), with ``time ~ K^k`` against the
output size K (regions) beside it.

Worlds: the paper's (corridor, two rooms, open room, corner) at L = 2; ring rooms (a
regular polygon of radius 10 with a ring pillar of radius 4, n/2 vertices each) with
64, 256 and 1024 vertices at L = 2; generated floor plans (envs.maps.floor_plan: rooms
along corridors, 60 m, 100 m and 200 m square) of about 100, 300 and 1000 vertices at
L = 3; and the rings and plans again scaled by 1e-2 and 1e3 (with L): the same
decomposition must cost the same.

Goals (issue 10): the 1024-vertex ring and the 1000-vertex floor plan well under 60 s
and 2 GB on two cores, scaled maps costing what the originals cost, safe_arcs under
1 ms.

Usage::

    python benchmarks/decomposition_scaling.py [--quick] [--no-scaled]
"""

from __future__ import annotations

import argparse
import math
import multiprocessing as mp
import os
import resource
import tempfile
import time

import numpy as np
from bench_cli import run

from envs.maps import Map, builtin_map, floor_plan

PAPER = ("corridor", "two_rooms", "open_room", "corner")


def ring_room(n: int, R: float = 10.0, r: float = 4.0) -> Map:
    """A round room (n/2-gon of radius R) around a round pillar (n/2-gon of radius r)."""
    k = n // 2
    a = 2 * math.pi * (np.arange(k) + 0.5) / k
    return Map(
        np.c_[R * np.cos(a), R * np.sin(a)], [np.c_[r * np.cos(a), r * np.sin(a)]], name=f"ring{n}"
    )


def _world(spec: tuple) -> tuple[Map, float]:
    kind, n, scale = spec
    if kind == "paper":
        world, L = builtin_map(n), 2.0
    elif kind == "room":
        world, L = Map([(0, 0), (10, 0), (10, 10), (0, 10)], name="room10"), 2.0
    elif kind == "ring":
        world, L = ring_room(n), 2.0
    else:
        side = {100: 60.0, 300: 100.0, 1000: 200.0}[n]
        world, L = floor_plan(0, n_vertices=n, size=(side, side), name=f"plan{n}"), 3.0
    if scale != 1.0:
        world = world.transformed([[scale, 0.0], [0.0, scale]])
    return world, L * scale


def _measure(spec: tuple) -> dict:
    """Run in a fresh process: build (with the cache), read back, query."""
    from strategies.cspace import decompose
    from strategies.cspace._budget import estimate
    from strategies.cspace.cache import cached_decomposition

    world, L = _world(spec)
    with tempfile.TemporaryDirectory() as tmp:
        t = time.perf_counter()
        dec = decompose(world, L, progress=False)
        build = time.perf_counter() - t
        peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
        t = time.perf_counter()
        cached_decomposition(world, L, cache_dir=tmp, build=lambda: dec)  # a miss: write
        t_write = time.perf_counter() - t
        t = time.perf_counter()
        again = decompose(world, L, cache=True, cache_dir=tmp, progress=False)
        t_read = time.perf_counter() - t
    rng = np.random.default_rng(0)
    xmin, ymin, xmax, ymax = world.bounds
    pts = rng.uniform([xmin, ymin], [xmax, ymax], size=(4000, 2))
    pts = pts[world.contains(pts)][:1000]
    t = time.perf_counter()
    for p in pts:
        again.safe_arcs(p)
    query = (time.perf_counter() - t) / max(1, len(pts))
    return {
        "name": world.name + ("" if spec[2] == 1.0 else f" x{spec[2]:g}"),
        "n": world.n_vertices,
        "pairs": estimate(world, L).pairs,
        "time": build,
        "peak": peak,
        "regions": len(dec.regions),
        "cells": len(dec.cells),
        "exact": dec.exact,
        "verdict": "evader" if dec.evader_wins else "pursuer",
        "write": t_write,
        "read": t_read,
        "query": query,
        "same": len(again.regions) == len(dec.regions) and again.escapable == dec.escapable,
    }


def _run(spec: tuple) -> dict:
    ctx = mp.get_context("spawn")
    with ctx.Pool(1) as pool:
        return pool.apply(_measure, (spec,))


def _fit(x, y) -> float:
    return float(np.polyfit(np.log(x), np.log(y), 1)[0])


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="skip the 1024 ring and 1000 plan")
    ap.add_argument("--no-scaled", action="store_true", help="skip the scaled copies")
    args = ap.parse_args(argv)

    rings = (64, 256) if args.quick else (64, 256, 1024)
    plans = (100, 300) if args.quick else (100, 300, 1000)
    specs = [("paper", name, 1.0) for name in PAPER]
    specs += [("ring", n, 1.0) for n in rings] + [("plan", n, 1.0) for n in plans]
    if not args.no_scaled:
        specs += [(k, n, s) for s in (1e-2, 1e3) for k, ns in (("ring", rings), ("plan", plans))
                  for n in ns]  # fmt: skip
    load = os.getloadavg()
    print(f"load average {load[0]:.2f} {load[1]:.2f} {load[2]:.2f} on {os.cpu_count()} cores")
    ref = _run(("room", 0, 1.0))
    print(
        f"reference: empty 10 x 10 room at L = 2: {ref['time'] * 1e3:.1f} ms, "
        f"peak {ref['peak'] / 1e6:.0f} MB, safe_arcs {ref['query'] * 1e6:.0f} us\n"
    )
    head = (
        f"{'world':<20} {'n':>5} {'pairs':>8} {'regions':>8} {'cells':>7} {'time [s]':>9} "
        f"{'x ref':>7} {'peak MB':>8} {'x ref':>6} {'write s':>7} {'read s':>7} "
        f"{'query us':>8}  exact verdict"
    )
    print(head)
    print("-" * len(head))
    rows = []
    for spec in specs:
        r = _run(spec)
        rows.append((spec, r))
        print(
            f"{r['name']:<20} {r['n']:>5} {r['pairs']:>8} {r['regions']:>8} {r['cells']:>7} "
            f"{r['time']:>9.2f} {r['time'] / ref['time']:>7.0f} {r['peak'] / 1e6:>8.0f} "
            f"{r['peak'] / ref['peak']:>6.1f} {r['write']:>7.2f} {r['read']:>7.2f} "
            f"{r['query'] * 1e6:>8.0f}  {'yes' if r['exact'] and r['same'] else 'NO':<5} "
            f"{r['verdict']}",
            flush=True,
        )
    base = [(s, r) for s, r in rows if s[0] in ("ring", "plan") and s[2] == 1.0]
    n = [r["n"] for _, r in base]
    t = [r["time"] for _, r in base]
    K = [r["regions"] for _, r in base]
    print(
        f"\nfitted over {len(base)} rings and floor plans, n = {min(n)}..{max(n)}: "
        f"time ~ n^{_fit(n, t):.2f}, time ~ K^{_fit(K, t):.2f} (K = regions, the output)"
    )
    for s, r in rows:
        if s[2] != 1.0:
            orig = next(r0 for s0, r0 in base if s0[:2] == s[:2])
            same = (r["regions"], r["cells"], r["verdict"]) == (
                orig["regions"], orig["cells"], orig["verdict"])  # fmt: skip
            print(
                f"{r['name']:<20} time {r['time'] / orig['time']:.2f} x the original's, "
                f"same regions, cells and verdict: {'yes' if same else 'NO'}"
            )
    big = [r for s, r in base if (s[0], s[1]) in (("ring", 1024), ("plan", 1000))]
    for r in big:
        ok = r["time"] < 60 and r["peak"] < 2e9
        print(f"goal {r['name']}: {r['time']:.1f} s, {r['peak'] / 1e9:.2f} GB: "
              f"{'met' if ok else 'NOT met'} (< 60 s, < 2 GB)")  # fmt: skip
    return 0


if __name__ == "__main__":
    raise SystemExit(run(main))
