"""DAgger's mechanics: labels, aggregation, the fit, and an ordinary SB3 model at the end."""

from __future__ import annotations

import json

import numpy as np
import pytest

from envs import surveillance_v0
from envs.errors import InvalidConfigError
from strategies.policies import make_policy
from training.dagger import DaggerConfig, _Rollout, dagger


def _cfg(tmp_path, **kw):
    base = dict(role="pursuer", expert="pursuer/greedy", opponent="evader/straight",
                maps=("open_room",), iterations=2, episodes=2, max_cycles=60, epochs=300,
                output_dir=str(tmp_path / "dagger"))  # fmt: skip
    return DaggerConfig(**{**base, **kw})


def test_dagger_aggregates_expert_labels_and_fits_them(tmp_path):
    r = dagger(_cfg(tmp_path))
    assert len(r.disagreement) == len(r.samples) == len(r.fit_error) == 2
    assert r.samples[0] > 0 and r.samples[1] > r.samples[0]  # aggregated, not replaced
    # the network reproduces what it was shown (actions in [-1, 1]^2, so 0.1 is small)
    assert r.fit_error[-1] < 0.1
    prov = json.loads((r.model_path.parent / "provenance.json").read_text())
    assert prov["role"] == "pursuer" and prov["method"] == "dagger"
    # an ordinary SB3 model: it loads by name, declares its observation and plays
    p = make_policy(f"pursuer/sb3:{r.model_path}")
    assert p.observation_options == {"observation": "state"}
    env = surveillance_v0.parallel_env(map="open_room")
    obs, _ = env.reset(seed=0)
    p.reset(role="pursuer", map=env.config.map, config=env.config, seed=0)
    assert p.act(obs["pursuer_0"]).shape == (2,)
    env.close()


def test_rollout_labels_every_visited_observation_with_the_expert():
    from stable_baselines3 import PPO

    from training.single_agent import SingleAgentEnv

    env = SingleAgentEnv("pursuer", "evader/straight", map="open_room", observation="state")
    model = PPO("MlpPolicy", env, seed=0, device="cpu")
    expert = make_policy("pursuer/greedy")
    twin = make_policy("pursuer/greedy")
    roll = _Rollout(expert, model, beta=0.0, seed=0)  # the learner acts, the expert labels
    penv = surveillance_v0.parallel_env(map="open_room", max_cycles=20)
    obs, _ = penv.reset(seed=3)
    for pol in (roll, twin):
        pol.reset(role="pursuer", map=penv.config.map, config=penv.config, seed=0)
    evader = make_policy("evader/straight")
    evader.reset(role="evader", map=penv.config.map, config=penv.config, seed=0)
    while penv.agents:
        a = roll.act(obs["pursuer_0"])
        assert np.allclose(roll.labels[-1], twin.act(obs["pursuer_0"]))
        assert np.allclose(a, roll.learned[-1])  # beta = 0: the learner's action is played
        obs, *_ = penv.step({"pursuer_0": a, "evader_0": evader.act(obs["evader_0"])})
    assert len(roll.obs) == len(roll.labels) == 20


@pytest.mark.parametrize(
    "bad",
    [
        {"expert": "evader/shooting"},
        {"iterations": 0},
        {"beta": 1.5},
        {"maps": ()},
        {"learning_rate": -1.0},
    ],
)
def test_bad_dagger_configs_name_the_field(tmp_path, bad):
    with pytest.raises(InvalidConfigError):
        _cfg(tmp_path, **bad)
