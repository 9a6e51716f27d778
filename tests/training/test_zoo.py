"""The shipped model zoo: present, small, documented, loadable, and acting in range."""

from __future__ import annotations

import numpy as np
import pytest

from envs import surveillance_v0
from envs.errors import UnknownNameError
from training import zoo
from training.config import TrainConfig

SHIPPED = ["ppo_evader_vs_greedy_open_room", "ppo_pursuer_vs_straight_open_room"]


def test_list_models():
    assert set(SHIPPED) <= set(zoo.list_models())


@pytest.mark.parametrize("name", SHIPPED)
def test_model_files_and_provenance(name):
    assert zoo.model_path(name).stat().st_size < 1_000_000
    prov = zoo.info(name)
    cfg = zoo.config(name)
    assert isinstance(cfg, TrainConfig)
    assert prov["config"] == cfg.to_dict() and prov["role"] == cfg.role
    assert prov["env_id"] == "surveillance_v0" and prov["timesteps"] >= cfg.total_timesteps
    assert prov["evaluation"]["episodes"] == cfg.eval_episodes
    assert zoo.policy_name(name) == f"{cfg.role}/sb3:{zoo.model_path(name)}"


@pytest.mark.parametrize("name", SHIPPED)
@pytest.mark.parametrize("observation_seed", [0, 1])
def test_loads_and_acts(name, observation_seed):
    cfg = zoo.config(name)
    policy = zoo.load(name)
    env = surveillance_v0.parallel_env(map=cfg.map, **cfg.env)
    agent = f"{cfg.role}_0"
    obs, _ = env.reset(seed=observation_seed)
    policy.reset(role=cfg.role, map=env.config.map, config=env.config, seed=0)
    for _ in range(5):
        a = policy.act(obs[agent])
        assert a.shape == env.action_space(agent).shape and a.dtype == np.float32
        assert np.all(np.abs(a) <= 1.0)
        other = "evader_0" if cfg.role == "pursuer" else "pursuer_0"
        obs, *_ = env.step({agent: a, other: np.zeros(2, np.float32)})
        if not env.agents:
            break


def test_unknown_model():
    with pytest.raises(UnknownNameError, match="ppo_pursuer_vs_straight_open_room"):
        zoo.load("no_such_model")


def test_cli_list(capsys):
    from training.zoo.__main__ import main

    assert main(["list"]) == 0
    out = capsys.readouterr().out
    assert all(name in out for name in SHIPPED)
