"""DAgger's learning curve: disagreement with the expert and hold rate per iteration.

Runs :func:`training.dagger.dagger` (expert/learner mixture rollouts through the shared
runner, expert labels, aggregation, supervised fit of an SB3 PPO policy network) and
prints, per iteration, the dataset size, the mean distance between the learner's and the
expert's actions on the states that iteration's rollouts visited (measured before the
refit: DAgger's on-policy disagreement), the fit error on the whole dataset after the
refit, and the share of that iteration's episodes the learner's role won (iteration 0 is
the expert alone; the expert's share falls as beta^i).

Usage::

    python benchmarks/dagger_curve.py [--expert pursuer/greedy] [--opponent evader/straight]
        [--maps open_room] [--iterations 6] [--episodes 25] [--epochs 100] [--lr 3e-4]
"""

from __future__ import annotations

import argparse
import os
import tempfile

from bench_cli import integer, real, run

from training.dagger import DaggerConfig, dagger


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--expert", default="pursuer/greedy")
    ap.add_argument("--opponent", default="evader/straight")
    ap.add_argument("--maps", nargs="+", default=["open_room"])
    ap.add_argument("--iterations", type=integer(1), default=6)
    ap.add_argument("--episodes", type=integer(1), default=25)
    ap.add_argument("--max-cycles", type=integer(1), default=150)
    ap.add_argument("--epochs", type=integer(1), default=100)
    ap.add_argument("--lr", type=real(0), default=3e-4)
    ap.add_argument("--seed", type=integer(0), default=0)
    args = ap.parse_args(argv)
    print(f"load average: {os.getloadavg()}")
    role = args.expert.partition("/")[0]
    with tempfile.TemporaryDirectory() as out:
        r = dagger(
            DaggerConfig(
                role=role,
                expert=args.expert,
                opponent=args.opponent,
                maps=tuple(args.maps),
                iterations=args.iterations,
                episodes=args.episodes,
                max_cycles=args.max_cycles,
                epochs=args.epochs,
                learning_rate=args.lr,
                seed=args.seed,
                output_dir=out,
            )
        )
    print(f"{'iteration':>9}{'samples':>9}{'disagreement':>14}{'fit error':>11}{'held':>7}")
    for i, (n, d, f, h) in enumerate(
        zip(r.samples, r.disagreement, r.fit_error, r.held, strict=True)
    ):
        print(f"{i:>9}{n:>9}{d:>14.3f}{f:>11.3f}{h:>7.2f}")
    print(f"{r.wall_seconds:.1f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(run(main))
