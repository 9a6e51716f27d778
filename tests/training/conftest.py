"""Shared tiny training configs (a few hundred timesteps: smoke tests, not learning)."""

from __future__ import annotations

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
