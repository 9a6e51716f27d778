"""Training throughput: env steps per second inside PPO, and the env's share of the wall time.

Trains SB3 PPO (``MlpPolicy`` [64, 64], ``n_steps`` 256 per env, one epoch pass per
rollout as configured below) for a fixed number of env steps against a fixed opponent, in
several layouts, and prints steps/s with the share of the wall time spent inside the env
(the learner's ``step``, the opponent's decision included) as measured by a timing wrapper:

* ``dummy xN``: N envs in the learner's process (``DummyVecEnv``), torch on 1 thread;
* ``subproc xN``: N worker processes, one env each (``SubprocVecEnv``), torch on 1 thread;
* ``dummy x1, torch 2 threads``: the same as ``dummy x1`` with torch free to use both cores.

The first row is the reference; the others are printed as ratios to it, measured in the
same run. On 2 cores the env dominates, so moving envs into worker processes is what pays.

Usage::

    python benchmarks/training_throughput.py [--steps 8192] [--opponent evader/straight]
        [--observation lidar_track]
"""

from __future__ import annotations

import argparse
import os
import time

import gymnasium as gym
import numpy as np
from bench_cli import integer
from bench_cli import run as run_main

from envs.surveillance.config import OBSERVATION_KINDS


class Timed(gym.Wrapper):
    """Accumulates the wall time spent in ``step`` and ``reset``."""

    def __init__(self, env):
        super().__init__(env)
        self.seconds = 0.0
        self.steps = 0

    def step(self, action):
        t = time.perf_counter()
        out = self.env.step(action)
        self.seconds += time.perf_counter() - t
        self.steps += 1
        return out

    def reset(self, **kw):
        t = time.perf_counter()
        out = self.env.reset(**kw)
        self.seconds += time.perf_counter() - t
        return out

    def timing(self):
        return self.seconds, self.steps


def _factory(args, i):
    def make():
        from training.single_agent import SingleAgentEnv

        obs = {} if args.observation == "state" else {"observation": args.observation, "n_rays": 32}
        env = SingleAgentEnv("pursuer", args.opponent, map=args.map, max_cycles=300, **obs)
        env.reset(seed=i)
        return Timed(env)

    return make


def run(args, layout: str, n: int, threads: int) -> tuple[float, float]:
    import torch
    from stable_baselines3 import PPO
    from stable_baselines3.common.vec_env import DummyVecEnv, SubprocVecEnv

    torch.set_num_threads(threads)
    fns = [_factory(args, i) for i in range(n)]
    venv = DummyVecEnv(fns) if layout == "dummy" else SubprocVecEnv(fns, start_method="fork")
    model = PPO("MlpPolicy", venv, n_steps=256, batch_size=256, n_epochs=4, seed=0,
                device="cpu", verbose=0)  # fmt: skip
    t0 = time.perf_counter()
    model.learn(args.steps)
    wall = time.perf_counter() - t0
    env_seconds = sum(s for s, _ in venv.env_method("timing"))
    venv.close()
    # with N worker processes the env time runs in parallel: its share is per process
    share = env_seconds / (wall * (n if layout == "subproc" else 1))
    return args.steps / wall, share


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=integer(1), default=8192)
    ap.add_argument("--opponent", default="evader/straight")
    ap.add_argument("--map", default="corridor")
    ap.add_argument("--observation", default="lidar_track", choices=OBSERVATION_KINDS)
    args = ap.parse_args(argv)
    print(f"load average: {os.getloadavg()}; cores: {os.cpu_count()}; {args.steps} env steps "
          f"vs {args.opponent} on {args.map}, observation {args.observation}")  # fmt: skip
    rows = [("dummy", 1, 1), ("dummy", 4, 1), ("subproc", 2, 1), ("subproc", 4, 1), ("dummy", 1, 2)]
    ref = None
    for layout, n, threads in rows:
        sps, share = run(args, layout, n, threads)
        ref = ref or sps
        print(f"  {layout:>8} x{n}, torch {threads} thread(s): {sps:8.0f} steps/s "
              f"({sps / ref:4.2f}x the first row), env share {share:5.1%}", flush=True)  # fmt: skip
    return 0


if __name__ == "__main__":
    np.set_printoptions(precision=3)
    raise SystemExit(run_main(main))
