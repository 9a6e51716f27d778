"""Shared tiny training configs (a few hundred timesteps: smoke tests, not learning)."""

from __future__ import annotations

import contextlib
import subprocess
import sys
from pathlib import Path

import pytest

from training.config import TrainConfig


def tiny_config(tmp_path, **changes) -> TrainConfig:
    """A PPO pursuer run of 256 timesteps in 4 rollouts of 64 steps, checkpoint each one."""
    base = dict(
        role="pursuer",
        opponent="evader/straight",
        map="open_room",
        env={"max_cycles": 40},
        total_timesteps=256,
        n_steps=64,
        batch_size=32,
        checkpoint_freq=64,
        eval_episodes=2,
        eval_start="valid",
        algo_kwargs={"n_epochs": 2},
        output_dir=str(tmp_path / "run"),
    )
    base.update(changes)
    return TrainConfig(**base)


@pytest.fixture
def tiny(tmp_path):
    """Factory of tiny configs writing under this test's tmp dir."""
    return lambda **changes: tiny_config(tmp_path, **changes)


@contextlib.contextmanager
def lock_held_elsewhere(lock_path: Path):
    """Another process holds ``lock_path``'s record lock (as a run training there would),
    having written ``pid 4242 on elsewhere since 2026-01-01 00:00:00`` into it, until the
    block ends."""
    holder = subprocess.Popen(
        [sys.executable, "-c", (
            "import fcntl, sys\n"
            f"f = open({str(lock_path)!r}, 'a+')\n"
            "fcntl.lockf(f.fileno(), fcntl.LOCK_EX)\n"
            "f.write('pid 4242 on elsewhere since 2026-01-01 00:00:00'); f.flush()\n"
            "print('locked', flush=True)\n"
            "sys.stdin.read()\n"
        )],
        stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True,
    )  # fmt: skip
    try:
        assert holder.stdout.readline().strip() == "locked"
        yield
    finally:
        holder.stdin.close()
        holder.wait(timeout=30)
