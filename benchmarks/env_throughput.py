"""Parallel-API step throughput of surveillance_v1 against MPE2's simple_tag_v3 (1 v 1).

Measured in one run, so the ratios do not depend on the machine:

* surveillance_v1 (state observations, render off) on a small map (``open_room``, 4
  walls) and on a large seeded random map (>= 500 walls);
* ``mpe2.simple_tag_v3`` with one adversary, one good agent, no obstacles, continuous
  actions: the reference;
* the retired surveillance_v0 on the small map (it sweeps a step in which a wall bent a
  body's path along the chord; v1 sweeps it substep by substep): what v1 costs.

Actions are pre-sampled (uniform in each agent's Box) so the loop times only
``env.step``. Episodes of surveillance_v1 end when the evader escapes; the env is then
reset outside the timed region. The four envs run in interleaved chunks, so that load
from other processes affects them alike. Goals: ours >= 6x simple_tag, and the large map
no more than 1.5x slower than the small one.

A breakdown per step follows: physics (``World.step``) and the kernel's continuous-time
``sweep``, each replayed on its own over the first 2000 recorded steps, and the rest of
``step`` (actions, observations, infos) as the difference (so it absorbs timing noise).

Usage::

    python benchmarks/env_throughput.py [--steps N] [--profile]
"""

from __future__ import annotations

import argparse
import cProfile
import pstats
import time

import numpy as np
from bench_cli import integer, run

from envs import surveillance_v0, surveillance_v1
from envs.maps import load_map, random_map

N_ACTIONS = 4096


def _presampled(env, agents, rng: np.random.Generator) -> dict[str, np.ndarray]:
    return {
        a: rng.uniform(
            env.action_space(a).low,
            env.action_space(a).high,
            (N_ACTIONS, *env.action_space(a).shape),
        ).astype(np.float32)
        for a in agents
    }


class OurRunner:
    """Steps surveillance_v1 on one map with pre-sampled actions; times ``step`` only."""

    def __init__(self, world_map, seed: int = 0, module=surveillance_v1) -> None:
        self.env = module.parallel_env(map=world_map, max_cycles=10**9)
        self.acts = _presampled(self.env, self.env.possible_agents, np.random.default_rng(seed))
        self.env.reset(seed=seed)
        self.i = 0
        self.resets = 0
        self.record: list = []

    def run(self, steps: int) -> float:
        env, acts = self.env, self.acts
        agents = env.possible_agents
        elapsed = 0.0
        for _ in range(steps):
            if not env.agents:
                env.reset()
                self.resets += 1
            k = self.i % N_ACTIONS
            self.i += 1
            actions = {a: acts[a][k] for a in agents}
            if len(self.record) < 2000:
                p0, e0 = env.world.positions()
            t0 = time.perf_counter()
            env.step(actions)
            elapsed += time.perf_counter() - t0
            if len(self.record) < 2000:
                cmd = (env._command(a, actions[a]) for a in agents)
                self.record.append((*cmd, p0, e0, *env.world.positions()))
        return elapsed


class TagRunner:
    """Steps mpe2 simple_tag_v3 (1 adversary, 1 good agent, no obstacles, continuous)."""

    def __init__(self, seed: int = 0) -> None:
        from mpe2 import simple_tag_v3

        self.env = simple_tag_v3.parallel_env(
            num_good=1,
            num_adversaries=1,
            num_obstacles=0,
            continuous_actions=True,
            max_cycles=10**9,
        )
        self.env.reset(seed=seed)
        self.acts = _presampled(self.env, self.env.agents, np.random.default_rng(seed))
        self.i = 0

    def run(self, steps: int) -> float:
        env, acts = self.env, self.acts
        agents = list(env.agents)
        t0 = time.perf_counter()
        for _ in range(steps):
            k = self.i % N_ACTIONS
            self.i += 1
            env.step({a: acts[a][k] for a in agents})
        return time.perf_counter() - t0


def breakdown(env, record) -> dict[str, float]:
    """Microseconds per step spent in physics, in the kernel sweep, and in the rest."""
    cfg = env.config
    n = len(record)
    env.world.reset(np.array(record[0][2]), np.array(record[0][3]))
    t0 = time.perf_counter()
    for vp, ve, *_ in record:
        env.world.step(vp, ve)
    physics = (time.perf_counter() - t0) / n
    kernel = env.kernel
    t0 = time.perf_counter()
    for _, _, p0, e0, p1, e1 in record:
        kernel.sweep(p0, e0, p1, e1, cfg.l_min, cfg.l_max)
    sweep = (time.perf_counter() - t0) / n
    return {"physics_us": physics * 1e6, "sweep_us": sweep * 1e6}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--steps", type=integer(1), default=20000, help="timed steps per env")
    parser.add_argument("--profile", action="store_true", help="cProfile the large-map run")
    args = parser.parse_args()

    small = load_map("open_room")
    large = random_map(0, n_vertices=600)
    print(
        f"small map: {small.name}, {small.n_edges} walls; "
        f"large map: {large.name}, {large.n_edges} walls"
    )

    # interleave short chunks so that load from other processes hits all four alike
    runners = {
        "tag": TagRunner(),
        "small": OurRunner(small),
        "large": OurRunner(large),
        "v0": OurRunner(small, module=surveillance_v0),
    }
    elapsed = dict.fromkeys(runners, 0.0)
    rounds = 10
    chunk = max(1, args.steps // rounds)
    for _ in range(rounds):
        for key, runner in runners.items():
            elapsed[key] += runner.run(chunk)
    rate = {key: rounds * chunk / t for key, t in elapsed.items()}
    ref, ours_small, ours_large = rate["tag"], rate["small"], rate["large"]
    resets_small, resets_large = runners["small"].resets, runners["large"].resets
    print(f"simple_tag_v3 (1v1, continuous): {ref:10.0f} steps/s")
    print(
        f"surveillance_v1 small map:       {ours_small:10.0f} steps/s"
        f"  ({resets_small} resets, untimed)"
    )
    print(
        f"surveillance_v1 large map:       {ours_large:10.0f} steps/s"
        f"  ({resets_large} resets, untimed)"
    )
    print(f"ratio ours(small) / simple_tag:  {ours_small / ref:6.2f}   (goal >= 6)")
    print(f"ratio ours(large) / simple_tag:  {ours_large / ref:6.2f}")
    print(f"slowdown large / small map:      {ours_small / ours_large:6.2f}   (goal <= 1.5)")
    print(f"surveillance_v0 small map:       {rate['v0']:10.0f} steps/s")
    print(f"ratio v1 / v0 (small map):       {ours_small / rate['v0']:6.2f}")
    for label in ("small", "large"):
        runner = runners[label]
        b = breakdown(runner.env, runner.record)
        total = 1e6 / rate[label]
        rest = total - b["physics_us"] - b["sweep_us"]
        print(
            f"per step on the {label} map: total {total:7.1f} us"
            f" = physics {b['physics_us']:6.1f} us"
            f" + kernel.sweep {b['sweep_us']:6.1f} us + env rest {rest:6.1f} us"
        )
    if args.profile:
        prof = cProfile.Profile()
        prof.enable()
        OurRunner(large).run(min(args.steps, 5000))
        prof.disable()
        pstats.Stats(prof).sort_stats("tottime").print_stats(20)


if __name__ == "__main__":
    raise SystemExit(run(main))
