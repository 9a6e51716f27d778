"""Time the geometry kernel's hot paths on a small and a large (>= 500-edge) map.

Prints microseconds per call of ``line_of_sight``, ``sweep``, ``free_arcs`` and
``ray_distances``, and the ratio of ``line_of_sight`` to shapely's equivalent measured in
the same run: ``LineString([p, q]).intersects`` on the prepared wall boundary (segment
construction included, as a caller would pay it). Run from the repository root::

    python benchmarks/geometry_kernel.py [--quick]
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np
import shapely
from bench_cli import run
from shapely.geometry import LineString

from envs.geometry import Kernel
from envs.maps.map import Map


def small_map() -> Map:
    """A 12-edge world: a room with two obstacles."""
    return Map(
        [(0, 0), (10, 0), (10, 10), (0, 10)],
        [[(2, 2), (4, 2), (4, 4), (2, 4)], [(6, 5), (8, 5), (7.5, 7.5), (5.5, 6.5)]],
        name="small",
    )


def large_map(seed: int = 0, n: int = 12) -> Map:
    """An n x n grid of random non-touching convex polygons in a square room."""
    rng = np.random.default_rng(seed)
    cell = 4.0
    obstacles = []
    for i in range(n):
        for j in range(n):
            k = int(rng.integers(3, 6))
            ang = np.sort(rng.uniform(0, 2 * math.pi, k))
            r = cell * rng.uniform(0.2, 0.35)
            c = ((i + 0.5) * cell, (j + 0.5) * cell)
            pts = np.stack([c[0] + r * np.cos(ang), c[1] + r * np.sin(ang)], axis=1)
            hull = shapely.convex_hull(shapely.multipoints(pts))
            obstacles.append(np.asarray(hull.exterior.coords)[:-1])
    side = n * cell
    return Map([(0, 0), (side, 0), (side, side), (0, side)], obstacles, name="large")


def free_points(world: Map, rng: np.random.Generator, k: int) -> np.ndarray:
    lo, hi = np.array(world.bounds[:2]), np.array(world.bounds[2:])
    out = np.empty((0, 2))
    while len(out) < k:
        p = lo + (hi - lo) * rng.uniform(size=(4 * k, 2))
        p = p[world.contains(p) & (world.distance_to_walls(p) > 1e-3)]
        out = np.concatenate([out, p])
    return out[:k]


def per_call(fn, args: list[tuple], repeat: int) -> float:
    """Best-of-``repeat`` mean seconds per call of ``fn(*a)`` over the argument list."""
    best = math.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        for a in args:
            fn(*a)
        best = min(best, (time.perf_counter() - t0) / len(args))
    return best


def bench(world: Map, n: int, repeat: int) -> dict[str, float]:
    rng = np.random.default_rng(1)
    kern = Kernel(world)
    E = free_points(world, rng, n)
    ang = rng.uniform(-math.pi, math.pi, n)
    L = rng.uniform(1.0, 3.0, n)
    P = E + L[:, None] * np.stack([np.cos(ang), np.sin(ang)], axis=1)
    keep = world.contains(P)
    E, P = E[keep], P[keep]
    seg_args = [(e, p) for e, p in zip(E, P, strict=True)]
    step = rng.uniform(-0.3, 0.3, (len(E), 2, 2))
    sweep_args = [(p, e, p + s[0], e + s[1], 0.5, 3.5) for e, p, s in zip(E, P, step, strict=True)]
    arc_args = [(e, 2.0) for e in E]
    rays = np.linspace(-math.pi, math.pi, 32, endpoint=False)
    ray_args = [(e, rays, 5.0) for e in E]
    boundary = world.free_region.boundary
    shapely.prepare(boundary)
    lines = [LineString([e, p]) for e, p in seg_args]
    out = {
        "line_of_sight": per_call(kern.line_of_sight, seg_args, repeat),
        "shapely intersects (with LineString)": per_call(
            lambda e, p: boundary.intersects(LineString([e, p])), seg_args, repeat
        ),
        "shapely intersects (prebuilt LineString)": per_call(
            boundary.intersects, [(g,) for g in lines], repeat
        ),
        "sweep": per_call(kern.sweep, sweep_args, repeat),
        "free_arcs (L=2)": per_call(kern.free_arcs, arc_args, repeat),
        "ray_distances (32 rays)": per_call(kern.ray_distances, ray_args, repeat),
    }
    out["line_of_sight_many (per segment)"] = per_call(
        kern.line_of_sight_many, [(E, P)], repeat
    ) / len(E)
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer calls, for a smoke run")
    args = ap.parse_args()
    n, repeat = (200, 2) if args.quick else (2000, 5)
    results = {}
    for world in (small_map(), large_map()):
        res = bench(world, n, repeat)
        results[world.name] = res
        print(f"\n{world.name}: {world.n_edges} edges, {int(world.vertex_convex.sum())} convex")
        for name, sec in res.items():
            print(f"  {name:42s} {sec * 1e6:9.2f} us/call")
        ratio = res["line_of_sight"] / res["shapely intersects (with LineString)"]
        print(f"  line_of_sight / shapely (with LineString)  {ratio:9.2f}x")
    s, b = results["small"], results["large"]
    print("\nlarge / small map cost:")
    for name in ("line_of_sight", "sweep", "free_arcs (L=2)", "ray_distances (32 rays)"):
        print(f"  {name:42s} {b[name] / s[name]:9.2f}x")


if __name__ == "__main__":
    raise SystemExit(run(main))
