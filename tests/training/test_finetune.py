"""PPO fine-tuning after cloning: the critic warms up with the actor frozen, the BC term decays."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from envs.errors import InvalidConfigError
from strategies.policies import make_policy
from strategies.runner import run_episode
from training.dagger import DaggerConfig, _Rollout, dagger
from training.finetune import BCRegularisedPPO, from_cloned
from training.single_agent import SingleAgentEnv


def _actor(model):
    p = model.policy
    params = [*p.mlp_extractor.policy_net.parameters(), *p.action_net.parameters(), p.log_std]
    return [t.detach().clone() for t in params]


def _critic(model):
    p = model.policy
    params = [*p.mlp_extractor.value_net.parameters(), *p.value_net.parameters()]
    return [t.detach().clone() for t in params]


def test_finetune_warms_the_critic_then_decays_the_bc_term(tmp_path):
    torch.set_num_threads(1)
    cfg = DaggerConfig(role="pursuer", expert="pursuer/greedy", opponent="evader/straight",
                       iterations=1, episodes=2, max_cycles=60, epochs=200,
                       output_dir=str(tmp_path / "d"))  # fmt: skip
    r = dagger(cfg)
    # the cloning dataset: one expert-played episode, labelled by the expert
    learner = from_cloned(r.model_path, SingleAgentEnv("pursuer", "evader/straight",
                          map="open_room", observation="state"))  # fmt: skip
    roll = _Rollout(make_policy("pursuer/greedy"), learner, beta=1.0, seed=1)
    run_episode("open_room", roll, "evader/straight", 1, max_cycles=60, start="valid")
    X, Y = np.asarray(roll.obs), np.clip(np.asarray(roll.labels), -1, 1)

    def tuned(bc_coef):
        env = SingleAgentEnv("pursuer", "evader/straight", map="open_room", observation="state")
        return from_cloned(r.model_path, env, bc_obs=X, bc_act=Y, bc_coef=bc_coef, bc_decay=0.5,
                           critic_warmup=1, n_steps=64, batch_size=32, n_epochs=2, seed=0,
                           learning_rate=3e-3)  # fmt: skip

    def distance(m):
        return np.linalg.norm(
            np.clip(m.predict(X, deterministic=True)[0], -1, 1) - Y, axis=1
        ).mean()

    model, plain = tuned(2.0), tuned(0.0)
    before = model.predict(X, deterministic=True)[0]
    actor0, critic0 = _actor(model), _critic(model)
    model.learn(total_timesteps=64)  # one rollout: the warm-up
    assert all(torch.equal(a, b) for a, b in zip(actor0, _actor(model), strict=True))
    assert not all(torch.equal(a, b) for a, b in zip(critic0, _critic(model), strict=True))
    assert np.array_equal(model.predict(X, deterministic=True)[0], before)
    model.learn(total_timesteps=3 * 64, reset_num_timesteps=False)
    plain.learn(total_timesteps=4 * 64)
    assert model.bc_weights == [0.0, 2.0, 1.0, 0.5]
    # measured: cloned 0.023; after 3 PPO updates at lr 3e-3, 0.039 with BC, 0.091 without
    assert distance(model) < 0.06 < distance(plain)
    path = tmp_path / "ft.zip"
    model.save(str(path))
    from stable_baselines3 import PPO

    assert np.array_equal(
        PPO.load(str(path)).predict(X, deterministic=True)[0],
        model.predict(X, deterministic=True)[0],
    )  # an ordinary PPO zip


@pytest.mark.parametrize("bad", [{"bc_decay": 1.5}, {"bc_coef": -1.0}, {"critic_warmup": -1}])
def test_bad_finetune_arguments_name_the_field(bad):
    env = SingleAgentEnv("pursuer", "evader/straight", map="open_room", observation="state")
    with pytest.raises(InvalidConfigError, match=next(iter(bad))):
        BCRegularisedPPO("MlpPolicy", env, **bad)


def test_a_model_that_reads_another_observation_is_refused_naming_both_shapes():
    from training import zoo

    env = SingleAgentEnv("pursuer", "evader/straight", map="corridor", observation="lidar_track")
    # the table-feature generalist reads lidar_track (40) plus 5 analytic features
    with pytest.raises(InvalidConfigError, match=r"shape \(45,\).*\(40,\)"):
        from_cloned(zoo.model_path("dagger_pursuer_table"), env)


def test_a_feature_model_fine_tunes_on_the_input_it_plays_with():
    from training import zoo
    from training.finetune import model_inputs

    torch.set_num_threads(1)
    path = zoo.model_path("dagger_pursuer_table")
    inputs = model_inputs(path, "pursuer")
    assert inputs is not None and inputs.features == ("safety_table",)
    env = SingleAgentEnv("pursuer", "evader/straight", map=["corridor", "l_hall"], start="safe",
                         max_cycles=40, observation="lidar_track", n_rays=32,
                         inputs=inputs)  # fmt: skip
    assert env.observation_space.shape == (45,)
    model = from_cloned(path, env, n_steps=32, batch_size=32, n_epochs=1, seed=0)
    player = make_policy(f"pursuer/sb3:{path}")
    for seed in (5, 6):
        obs, _ = env.reset(seed=seed)
        player.reset(role="pursuer", map=env.config.map, config=env.config, seed=0)
        for _ in range(25):  # the same action as the model playing from the state
            action = np.clip(model.predict(obs, deterministic=True)[0], -1, 1)
            np.testing.assert_allclose(action, player.act(env.env.state()), atol=1e-6)
            obs, _, term, trunc, _ = env.step(action)
            if term or trunc:
                break
    model.learn(total_timesteps=32)  # and PPO trains on it


def test_bad_inputs_are_refused_naming_the_value():
    with pytest.raises(InvalidConfigError, match="inputs: expected a LearnerInputs"):
        SingleAgentEnv("pursuer", "evader/straight", map="corridor", inputs=["safety_table"])
