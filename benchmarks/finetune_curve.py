"""Does PPO fine-tuning keep what DAgger taught? The win rate along the fine-tuning run.

Starts :class:`training.finetune.BCRegularisedPPO` from a DAgger zoo model (its weights,
its DAgger dataset for the decaying behaviour-cloning term when ``--dataset`` or
``out/training/NAME/dataset.npz`` holds one, else no BC term) and evaluates the policy
every ``--every`` env steps on the same seeded safe starts against ``--opponent`` (Wilson
95 % intervals): the pursuer's held rate, the evader's escape rate. A model trained with
analytic features is fine-tuned on the input it was fitted on (``SingleAgentEnv(inputs=)``).
Step 0 is the cloned model itself; a collapse shows as a drop after the critic warm-up.
Two arms are run from the same start: with the remedies (critic warm-up, BC term, small
initial action noise) and plain PPO from the same weights, so the remedies' effect is
measured in the same run.

Usage::

    python benchmarks/finetune_curve.py [--model dagger_pursuer_generalist]
        [--steps 40000] [--every 10000] [--episodes 24] [--opponent evader/shooting ...]
        [--maps two_rooms office] [--dataset PATH] [--arms remedies plain] [--save DIR]
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import numpy as np
from bench_cli import integer, path_text, real, run

from analysis.evaluate import wilson_interval
from strategies.runner import run_episode
from training import zoo
from training.pool import OpponentPool


def _wins(model_zip: Path, prov_dir: Path, role: str, maps, opponents, episodes: int,
          tmp: str) -> dict[str, int]:  # fmt: skip
    """Wins against each opponent over ``episodes`` seeded safe starts (maps in turn)."""
    import shutil

    d = Path(tmp) / "eval"  # the model beside the zoo's provenance (its observation, features)
    d.mkdir(exist_ok=True)
    shutil.copyfile(model_zip, d / "model.zip")
    shutil.copyfile(prov_dir / "provenance.json", d / "provenance.json")
    me = f"{role}/sb3:{d / 'model.zip'}"
    wins = {}
    for opponent in opponents:
        wins[opponent] = 0
        for s in range(episodes):
            players = (me, opponent) if role == "pursuer" else (opponent, me)
            r = run_episode(maps[s % len(maps)], *players, 70_000 + s, start="safe",
                            max_cycles=300)  # fmt: skip
            wins[opponent] += r.winner == role
    return wins


def _line(step: int, wins: dict[str, int], episodes: int, verb: str, extra: str = "") -> str:
    parts = []
    for opponent, w in wins.items():
        lo, hi = wilson_interval(w, episodes)
        parts.append(f"{opponent} {w:>3}/{episodes} [{lo:.2f}, {hi:.2f}]")
    return f"  step {step:>7}: {verb} " + "; ".join(parts) + extra


ARMS = {
    # critic warm-up, a decaying BC term and a small initial action noise (log_std -1.6)
    "remedies": dict(critic_warmup=3, bc_coef=1.0, bc_decay=0.95),
    "plain": dict(critic_warmup=0, bc_coef=0.0, bc_decay=1.0),  # plain PPO, same weights
}


def main(argv=None) -> int:
    import tempfile

    import torch

    from training.finetune import from_cloned, model_inputs
    from training.single_agent import SingleAgentEnv

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--model", default="dagger_pursuer_generalist")
    ap.add_argument("--steps", type=integer(1), default=40_000)
    ap.add_argument("--every", type=integer(1), default=10_000)
    ap.add_argument("--episodes", type=integer(1), default=24)
    ap.add_argument("--opponent", nargs="+", default=None,
                    help="fine-tune against these (a uniform pool) and evaluate against each "
                    "(default: evader/shooting for a pursuer, pursuer/decomposition for an "
                    "evader)")  # fmt: skip
    ap.add_argument("--maps", nargs="+", default=None,
                    help="fine-tune and evaluate on these (default: the recipe's)")  # fmt: skip
    ap.add_argument("--dataset", default=None,
                    help="the DAgger dataset.npz for the BC term (default: the recipe's "
                    "output_dir)")  # fmt: skip
    ap.add_argument("--arms", nargs="+", choices=sorted(ARMS), default=sorted(ARMS))
    ap.add_argument("--learning-rate", type=real(0), default=1e-4)
    ap.add_argument(
        "--save",
        default=None,
        type=path_text("a directory"),
        help="directory to keep each arm's last model in",
    )
    args = ap.parse_args(argv)
    if args.every > args.steps:
        ap.error(f"--every {args.every} > --steps {args.steps}: no model would be evaluated "
                 "after step 0; expected --every <= --steps")  # fmt: skip
    torch.set_num_threads(1)
    try:
        cfg = zoo.config(args.model)
    except ValueError as exc:  # UnknownNameError: say it without a traceback
        ap.error(str(exc))
    role = cfg.role
    opponents = args.opponent or [
        "evader/shooting" if role == "pursuer" else "pursuer/decomposition"
    ]
    prov_dir = zoo.MODELS_DIR / args.model
    maps = list(args.maps or cfg.maps)
    obs = dict(cfg.observation)
    inputs = model_inputs(zoo.model_path(args.model), role)
    data = Path(args.dataset) if args.dataset else Path(cfg.output_dir) / "dataset.npz"
    verb = "held" if role == "pursuer" else "escaped"
    print(f"load average: {os.getloadavg()}; {args.model} ({role}) on {maps} vs {opponents}; "
          f"features: {list(inputs.features) if inputs else 'none'}; "
          f"BC dataset: {data if data.is_file() else 'none'}")  # fmt: skip
    n = args.episodes
    with tempfile.TemporaryDirectory() as tmp:
        base = _wins(zoo.model_path(args.model), prov_dir, role, maps, opponents, n, tmp)
        for arm in args.arms:
            kw = ARMS[arm]
            print(f"\n== {arm}: {kw}, learning rate {args.learning_rate}")
            print(_line(0, base, n, verb))
            pool = OpponentPool(opponents) if len(opponents) > 1 else opponents[0]
            env = SingleAgentEnv(role, pool, map=maps, start="safe", max_cycles=300,
                                 inputs=inputs, **obs)  # fmt: skip
            extra = {}
            if data.is_file() and kw["bc_coef"] > 0:
                with np.load(data) as z:
                    extra = {"bc_obs": z["obs"], "bc_act": z["act"]}
            model = from_cloned(zoo.model_path(args.model), env, n_steps=1024, batch_size=256,
                                learning_rate=args.learning_rate, n_epochs=5, seed=0, **kw,
                                **extra)  # fmt: skip
            if kw["critic_warmup"]:
                with torch.no_grad():
                    model.policy.log_std.fill_(-1.6)
            t0 = time.perf_counter()
            for done in range(args.every, args.steps + 1, args.every):
                model.learn(args.every, reset_num_timesteps=False)
                path = Path(tmp) / f"{arm}_{done}.zip"
                model.save(str(path))
                wins = _wins(path, prov_dir, role, maps, opponents, n, tmp)
                print(_line(done, wins, n, verb, f" ({time.perf_counter() - t0:.0f} s)"),
                      flush=True)  # fmt: skip
            if args.save:
                Path(args.save).mkdir(parents=True, exist_ok=True)
                model.save(str(Path(args.save) / f"{arm}.zip"))
            env.close()
    return 0


if __name__ == "__main__":
    raise SystemExit(run(main))
