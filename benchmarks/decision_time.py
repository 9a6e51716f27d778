"""Decision time of the analytic policies (issue 13: under 1 ms per decision).

For each map, seeded episodes of ``pursuer/decomposition`` against ``evader/shooting``
from safe starts are played through the shared runner, recording what each side
observed. Each policy is then replayed over those observations (a fresh policy, reset as
in the episode, so it takes the same decisions): ``pursuer/decomposition`` and the
reference ``pursuer/greedy`` on the pursuer's, ``evader/shooting`` on the evader's (and
each of ``--others``, registered names, on its role's: a policy other than the two
players does not take the decisions it would in its own episodes, only decisions of the
same kind). Each replay is repeated ``--reps`` times and the time of a step is the least
over the repeats, which filters out the other processes' interference on a shared
machine; the first decision of an episode (it may finish lazy set-up) is left out of
those figures and reported on its own.

Printed per policy and map: mean, 99th and 99.9th percentile and max of the time per
``act`` call in ms (wall clock, or with ``--clock cpu`` the thread's CPU time, which
leaves out the time slices of other processes on a loaded machine, not their cache
pressure), the slowest first decision of an episode (least over the repeats; the map's
caches are warm by then: the episode was just played), and the mean and p99 as
multiples of the greedy pursuer's mean in the same run (the machine-independent
figures). The verdict (issue 13: "under 1 ms per decision") is on the mean, the time a
decision costs over an episode; the tail line after it gives each policy's worst p99
and max over the maps, the single decisions past 1 ms.

Usage::

    python benchmarks/decision_time.py [--maps corridor two_rooms ...] [--seeds 2]
        [--max-cycles 300] [--reps 3] [--clock wall|cpu] [--l-min 1] [--ratio 4]
        [--table lazy] [--rho 0.99] [--others evader/straight pursuer/tractrix ...]

``--maps`` takes built-in names, ``NAME*S`` (the built-in map scaled by S, its L_min, L_max
and speeds kept: a larger world, S^2 times the table's points), ``floor_plan:SEED:W``
(:func:`envs.maps.floor_plan`, a W x W building, 1000 (W / 200)^2 wall vertices, at least
40; the env's default ranges unless ``--l-min``) and ``random:SEED`` /
``random:KIND:SEED`` (:func:`envs.maps.load_map`'s seeded random maps).

``--l-min X`` plays the maps at L_min = X, L_max = 2 X instead of their own ranges (the
decomposition pursuer's grid is L_min / 20: halving L_min quadruples its points);
``--ratio R`` plays them at L_max = R L_min (the map's own L_min, or ``--l-min``'s): the
pursuer's probes reach over the band up to L_max, so a wide band classifies more of the
table's nodes a decision (floor_plan:1:110 at rho 0.95, L_min 0.5, R = 4: a mean of
~1.5 ms of thread CPU against a random evader, helper-195's probe in session 30);
``--table`` forces the decomposition pursuer's safety table (``auto``: distinct rows up
to ``DecompositionPursuer.DISTINCT_TABLE_POINTS`` grid points, else filled lazily), so the
kinds can be compared on the same episodes.

``--rho R`` plays the evader at R times the pursuer's speed (the map's V_p kept) instead
of the map's ratio: the shooting evader's arcs near rho = 1 (issue 13).
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np
from bench_cli import integer, real, run

from envs.errors import InvalidConfigError
from envs.maps import builtin_info, builtin_names, floor_plan, load_map
from envs.surveillance.config import map_recommendations
from strategies.policies import make_policy, policy_names
from strategies.runner import episode_seeds, run_episode

MAPS = ["corridor", "two_rooms", "office", "l_hall", "maze"]
REFERENCE = "pursuer/greedy"
CLOCKS = {"wall": time.perf_counter, "cpu": time.thread_time}
POLICIES = [("pursuer/decomposition", "pursuer"), ("evader/shooting", "evader")]


def world(spec: str):
    """The map and config overrides of a ``--maps`` entry (see the module docstring)."""
    if spec.startswith("floor_plan:"):
        _, seed, w = spec.split(":")
        n = max(40, round(1000 * (float(w) / 200.0) ** 2))
        return floor_plan(int(seed), n_vertices=n, size=(float(w), float(w))), {}
    if spec.startswith("random:"):
        return load_map(spec), {}
    if "*" in spec:
        name, scale = spec.split("*")
        info = builtin_info(name)
        m = info.map.transformed(float(scale) * np.eye(2), (0.0, 0.0))
        return m, dict(info.params())
    return spec, {}


def map_spec(text: str) -> str:
    """An argparse ``type=`` for ``--maps``: a ``world()`` spec, checked without building it."""
    names = builtin_names()
    expected = (
        f"expected a built-in map {names}, NAME*S (S > 0), floor_plan:SEED:W (W > 0) or "
        "random:[KIND:]SEED"
    )
    try:
        if text.startswith("random:"):
            load_map(text)  # (a seeded random map builds in milliseconds)
            ok = True
        elif text.startswith("floor_plan:"):
            _, seed, w = text.split(":")
            ok = int(seed) >= 0 and 0 < float(w) < float("inf")
        elif "*" in text:
            name, scale = text.split("*")
            ok = name in names and 0 < float(scale) < float("inf")
        else:
            ok = text in names
    except (ValueError, InvalidConfigError):
        ok = False
    if not ok:
        raise argparse.ArgumentTypeError(f"{text!r}: {expected}")
    return text


def analytic_name(text: str) -> str:
    """An argparse ``type=`` for ``--others``: a registered policy name."""
    if text not in policy_names():
        raise argparse.ArgumentTypeError(f"{text!r}: expected a registered policy {policy_names()}")
    return text


def _replay(
    name: str,
    role: str,
    result,
    observations,
    seed: int,
    reps: int,
    clock=time.perf_counter,
    params: dict | None = None,
) -> np.ndarray:
    """Seconds per decision (least over ``reps`` replays, each by a fresh policy), the
    first decision first."""
    runs = []
    for _ in range(reps):
        policy = make_policy(name, **(params or {}))
        policy.reset(role=role, map=result.config.map, config=result.config, seed=seed)
        times = []
        for obs in observations:
            t0 = clock()
            policy.act(obs[role])
            times.append(clock() - t0)
        runs.append(times)
    return np.min(np.asarray(runs), axis=0)


def measure(
    map_name: str,
    seeds: int,
    max_cycles: int,
    reps: int,
    clock=time.perf_counter,
    overrides: dict | None = None,
    table: str = "auto",
    rho: float | None = None,
    others: tuple[str, ...] = (),
    ratio: float | None = None,
) -> tuple[dict[str, np.ndarray], dict[str, float]]:
    """Per-decision seconds of each policy (the two players, ``others`` and the
    reference) on ``map_name``, first decisions left out, and the slowest first decision
    of each."""
    out: dict[str, list[np.ndarray]] = {}
    first: dict[str, float] = {}
    m, params = world(map_name)
    overrides = {**params, **(overrides or {})}
    if rho is not None:
        v_pursuer = {**map_recommendations(m), **overrides}["v_pursuer"]
        overrides["v_evader"] = rho * v_pursuer
    if ratio is not None:
        overrides["l_max"] = ratio * {**map_recommendations(m), **overrides}["l_min"]
    overrides = overrides or None
    for seed in range(seeds):
        observations = []
        result = run_episode(
            m,
            POLICIES[0][0],
            POLICIES[1][0],
            seed,
            start="safe",
            max_cycles=max_cycles,
            overrides=overrides,
            on_step=lambda t, seen=observations: seen.append(t.observations),
        )
        _, _, s_pursuer, s_evader = episode_seeds(seed)
        role_seed = {"pursuer": s_pursuer, "evader": s_evader}
        replayed = [*POLICIES, *((n, n.split("/")[0]) for n in others), (REFERENCE, "pursuer")]
        for name, role in replayed:
            params = {"table": table} if name == "pursuer/decomposition" else None
            t = _replay(name, role, result, observations, role_seed[role], reps, clock, params)
            out.setdefault(name, []).append(t[1:])
            first[name] = max(first.get(name, 0.0), float(t[0]))
    return {name: np.concatenate(v) for name, v in out.items()}, first


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--maps", nargs="+", type=map_spec, default=MAPS)
    ap.add_argument("--seeds", type=integer(1), default=2)
    ap.add_argument("--max-cycles", type=integer(1), default=300)
    ap.add_argument("--reps", type=integer(1), default=3)
    ap.add_argument("--clock", choices=sorted(CLOCKS), default="wall")
    ap.add_argument("--l-min", type=real(0), default=None)
    ap.add_argument("--table", choices=["auto", "eager", "distinct", "lazy"], default="auto")
    ap.add_argument("--rho", type=real(0), default=None)
    ap.add_argument("--ratio", type=real(1), default=None, help="L_max / L_min (> 1)")
    ap.add_argument("--others", nargs="*", type=analytic_name, default=[])
    args = ap.parse_args(argv)
    others = tuple(n for n in dict.fromkeys(args.others) if n not in (*dict(POLICIES), REFERENCE))
    r = 2.0 if args.ratio is None else args.ratio
    overrides = None if args.l_min is None else {"l_min": args.l_min, "l_max": r * args.l_min}
    print(
        f"load average: {os.getloadavg()}; clock: {args.clock}; table: {args.table}"
        + ("" if overrides is None else f"; L in [{args.l_min:g}, {r * args.l_min:g}]")
        + ("" if args.rho is None else f"; rho {args.rho:g}")
        + ("" if args.ratio is None else f"; L_max / L_min {args.ratio:g}")
    )
    # the map column fits the longest label (floor_plan:0:200 ran into the policy's name)
    w = max(16, *(len(m) + 1 for m in args.maps))
    pw = max(24, *(len(n) + 1 for n in others), 0)
    print(
        f"{'map':<{w}}{'policy':<{pw}}{'steps':>6}{'mean ms':>9}{'p99 ms':>8}{'p99.9 ms':>9}"
        f"{'max ms':>8}{'first ms':>9}{'mean/ref':>10}{'p99/ref':>9}"
    )
    worst = {name: 0.0 for name, _ in POLICIES}
    tails = {name: (0.0, 0.0) for name in [*(n for n, _ in POLICIES), *others]}
    for map_name in args.maps:
        times, first = measure(
            map_name,
            args.seeds,
            args.max_cycles,
            args.reps,
            CLOCKS[args.clock],
            overrides,
            args.table,
            args.rho,
            others,
            args.ratio,
        )
        ref = float(times[REFERENCE].mean())
        for name in [*(n for n, _ in POLICIES), *others, REFERENCE]:
            t = times[name] * 1e3
            mean, p99 = float(t.mean()), float(np.percentile(t, 99))
            p999 = float(np.percentile(t, 99.9))
            if name in worst:
                worst[name] = max(worst[name], mean)
            if name in tails:
                tails[name] = (max(tails[name][0], p99), max(tails[name][1], float(t.max())))
            print(
                f"{map_name:<{w}}{name:<{pw}}{len(t):>6}{mean:>9.3f}{p99:>8.3f}{p999:>9.3f}"
                f"{t.max():>8.3f}{1e3 * first[name]:>9.3f}{mean / (1e3 * ref):>10.1f}"
                f"{p99 / (1e3 * ref):>9.1f}"
            )
    for name, mean in worst.items():
        verdict = "PASS" if mean < 1.0 else "FAIL"
        print(f"{verdict} {name}: mean decision time <= {mean:.3f} ms on every map (< 1 ms)")
    for name, (p99, top) in tails.items():
        print(f"tail {name}: p99 <= {p99:.3f} ms, max {top:.3f} ms on every map")
    return 0


if __name__ == "__main__":
    raise SystemExit(run(main))
