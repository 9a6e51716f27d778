"""Does PPO fine-tuning keep what DAgger taught? The held rate along the fine-tuning run.

Starts :class:`training.finetune.BCRegularisedPPO` from a DAgger zoo model (its weights,
its DAgger dataset for the decaying behaviour-cloning term when ``out/training/NAME``
still holds ``dataset.npz``, else no BC term) and evaluates the policy every ``--every``
env steps on the same seeded safe starts against ``--opponent`` (Wilson 95 % intervals).
Step 0 is the cloned model itself; a collapse shows as a drop after the critic warm-up.
Two arms are run from the same start: with the remedies (critic warm-up, BC term, small
initial action noise) and plain PPO from the same weights, so the remedies' effect is
measured in the same run.

Usage::

    python benchmarks/finetune_curve.py [--model dagger_pursuer_generalist]
        [--steps 40000] [--every 10000] [--episodes 24] [--opponent evader/shooting]
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import numpy as np

from analysis.evaluate import wilson_interval
from strategies.runner import run_episode
from training import zoo


def _held(model_zip: Path, prov_dir: Path, maps, opponent: str, episodes: int, tmp: str) -> int:
    import shutil

    d = Path(tmp) / "eval"  # the model beside the zoo's provenance (its observation)
    d.mkdir(exist_ok=True)
    shutil.copyfile(model_zip, d / "model.zip")
    shutil.copyfile(prov_dir / "provenance.json", d / "provenance.json")
    wins = 0
    for s in range(episodes):
        r = run_episode(maps[s % len(maps)], f"pursuer/sb3:{d / 'model.zip'}", opponent,
                        70_000 + s, start="safe", max_cycles=300)  # fmt: skip
        wins += r.winner == "pursuer"
    return wins


def main(argv=None) -> int:
    import tempfile

    import torch

    from training.finetune import from_cloned
    from training.single_agent import SingleAgentEnv

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--model", default="dagger_pursuer_generalist")
    ap.add_argument("--steps", type=int, default=40_000)
    ap.add_argument("--every", type=int, default=10_000)
    ap.add_argument("--episodes", type=int, default=24)
    ap.add_argument("--opponent", default="evader/shooting")
    args = ap.parse_args(argv)
    torch.set_num_threads(1)
    cfg = zoo.config(args.model)
    prov_dir = zoo.MODELS_DIR / args.model
    maps = list(cfg.maps)
    obs = dict(cfg.observation)
    data = Path(cfg.output_dir) / "dataset.npz"
    print(f"load average: {os.getloadavg()}; {args.model} on {maps} vs {args.opponent}; "
          f"BC dataset: {data if data.is_file() else 'none'}")  # fmt: skip
    arms = {
        "warm-up + BC + log_std -1.6": dict(critic_warmup=3, bc_coef=1.0, bc_decay=0.95),
        "plain PPO (same weights)": dict(critic_warmup=0, bc_coef=0.0, bc_decay=1.0),
    }
    with tempfile.TemporaryDirectory() as tmp:
        base = _held(zoo.model_path(args.model), prov_dir, maps, args.opponent, args.episodes, tmp)
        for arm, kw in arms.items():
            print(f"\n== {arm}")
            blo, bhi = wilson_interval(base, args.episodes)
            print(f"  step {0:>7}: held {base:>3}/{args.episodes} [{blo:.2f}, {bhi:.2f}]")
            env = SingleAgentEnv("pursuer", args.opponent, map=maps, start="safe",
                                 max_cycles=300, **obs)  # fmt: skip
            extra = {}
            if data.is_file() and kw["bc_coef"] > 0:
                with np.load(data) as z:
                    extra = {"bc_obs": z["obs"], "bc_act": z["act"]}
            model = from_cloned(zoo.model_path(args.model), env, n_steps=1024, batch_size=256,
                                learning_rate=1e-4, n_epochs=5, seed=0, **kw, **extra)  # fmt: skip
            if kw["critic_warmup"]:
                with torch.no_grad():
                    model.policy.log_std.fill_(-1.6)
            t0 = time.perf_counter()
            for done in range(args.every, args.steps + 1, args.every):
                model.learn(args.every, reset_num_timesteps=False)
                path = Path(tmp) / f"{len(arm)}_{done}.zip"
                model.save(str(path))
                w = _held(path, prov_dir, maps, args.opponent, args.episodes, tmp)
                lo, hi = wilson_interval(w, args.episodes)
                print(f"  step {done:>7}: held {w:>3}/{args.episodes} [{lo:.2f}, {hi:.2f}] "
                      f"({time.perf_counter() - t0:.0f} s)", flush=True)  # fmt: skip
            env.close()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
