"""SingleAgentEnv: API checkers, determinism, reward and termination pass-through."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env
from stable_baselines3.common.env_checker import check_env as sb3_check_env

from envs import surveillance_v1
from envs.errors import InvalidConfigError, InvalidPlacementError
from strategies.policies import make_policy
from training.single_agent import SingleAgentEnv

CASES = [("pursuer", "evader/straight"), ("evader", "pursuer/greedy")]


@pytest.mark.parametrize("observation", ["state", "lidar"])
@pytest.mark.parametrize(("role", "opponent"), CASES)
def test_checkers_pass(role, opponent, observation):
    env = SingleAgentEnv(
        role, opponent, map="pillars", observation=observation, n_rays=8, max_cycles=30
    )
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the checkers warn on every soft API violation
        check_env(env, skip_render_check=True)
        sb3_check_env(env, warn=True)
    agent = "pursuer_0" if role == "pursuer" else "evader_0"
    raw = surveillance_v1.parallel_env(map="pillars", observation=observation, n_rays=8)
    assert env.observation_space == raw.observation_space(agent)
    assert env.action_space == raw.action_space(agent)


def _rollout(env, seed, n_steps=120, action_seed=7):
    rng = np.random.default_rng(action_seed)
    out = []
    obs, info = env.reset(seed=seed)
    out.append(("reset", obs.tobytes(), info["distance"]))
    for _ in range(n_steps):
        obs, r, term, trunc, info = env.step(rng.uniform(-1, 1, 2).astype(np.float32))
        out.append((obs.tobytes(), r, term, trunc, info["distance"]))
        if term or trunc:
            obs, info = env.reset()
            out.append(("reset", obs.tobytes(), info["distance"]))
    return out


@pytest.mark.parametrize("start", ["env", "valid"])
def test_same_seed_same_episodes(start):
    make = lambda: SingleAgentEnv(
        "pursuer", "evader/random", map="corridor", start=start, max_cycles=25
    )
    a, b = _rollout(make(), seed=3), _rollout(make(), seed=3)
    assert a == b
    assert sum(1 for x in a if x[0] == "reset") >= 2  # several episodes, resets unseeded
    assert _rollout(make(), seed=4) != a
    env = make()  # reseeding the same env replays the stream
    assert _rollout(env, seed=3) == _rollout(env, seed=3)


def test_rewards_and_ends_pass_through():
    # the learner alternates between the greedy pursuer (which holds the straight-line
    # evader) and standing still (which loses it), so both kinds of episode end occur
    env = SingleAgentEnv("pursuer", "evader/straight", map="open_room", max_cycles=60)
    greedy = make_policy("pursuer/greedy")
    ends = {"terminated": 0, "truncated": 0}
    for episode in range(6):
        obs, _ = env.reset(seed=100 + episode)
        greedy.reset(role="pursuer", map=env.config.map, config=env.config, seed=episode)
        done = False
        while not done:
            action = greedy.act(obs) if episode % 2 == 0 else np.zeros(2, np.float32)
            obs, r, term, trunc, info = env.step(action)
            parts = info["reward_surveillance"] + info["reward_escape"] + info["reward_horizon"]
            assert r == pytest.approx(parts)
            assert term == (not info["surveillance"])
            if term:
                assert r == pytest.approx(-1.0)  # zero-sum: escape costs the pursuer 1
                assert "cause" in info and 0.0 <= info["break_time"] <= 1.0
            else:
                assert r == pytest.approx(1.0 / 60)
            if trunc:
                assert info["step"] == 60
            done = term or trunc
        ends["terminated" if term else "truncated"] += 1
    assert ends["terminated"] > 0 and ends["truncated"] > 0


def test_lidar_learner_against_analytic_opponent():
    # the analytic opponent reads env.state(), so it plays as well as in a "state" env:
    # the greedy pursuer holds a passive evader (zero action) to the horizon
    env = SingleAgentEnv(
        "evader",
        "pursuer/greedy",
        map="open_room",
        observation="lidar",
        n_rays=8,
        max_cycles=50,
        start="valid",
    )
    for seed in range(3):
        obs, _ = env.reset(seed=seed)
        assert obs.shape == (14,)
        done = False
        while not done:
            obs, _, term, trunc, _ = env.step(np.zeros(2, np.float32))
            done = term or trunc
        assert trunc and not term


def test_explicit_placement_and_policy_object():
    opp = make_policy("evader/straight")
    env = SingleAgentEnv("pursuer", opp, map="open_room")
    _, info = env.reset(seed=0, options={"pursuer": (5.0, 5.0), "evader": (2.0, 5.0)})
    assert info["distance"] == pytest.approx(3.0)
    assert env.opponent is opp and opp.role == "evader"


@pytest.mark.parametrize("maps", ["corridor", ["corridor", "open_room"]])
def test_a_refused_reset_leaves_the_env_as_it_was(maps):
    """reset(seed=7, options=bad) reseeded the generator (and drew the map, the start and
    the opponent's seed from it) before the env refused the placement: the next reset()
    played seed 7's stream. Now it plays the one under way, and the episode under way
    keeps its opponent (reset only once the env accepts a start)."""

    def made():
        env = SingleAgentEnv("pursuer", make_policy("evader/straight"), map=maps)
        env.reset(seed=0)
        return env

    env, untouched = made(), made()
    opponent = env.opponent
    with pytest.raises(InvalidPlacementError, match="outside the free space"):
        env.reset(seed=7, options={"pursuer": (1e9, 0.0), "evader": (1.0, 1.0)})
    assert env.opponent is opponent and env.config.map.name == untouched.config.map.name
    for _ in range(3):
        assert np.array_equal(env.reset()[0], untouched.reset()[0])


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"role": "bishop", "opponent": "evader/straight"}, "bishop"),
        ({"role": "pursuer", "opponent": "pursuer/greedy"}, "opponent"),
        ({"role": "pursuer", "opponent": "evader/straight", "start": "anywhere"}, "start"),
        ({"role": "pursuer", "opponent": "evader/straight", "max_cycle": 3}, "max_cycle"),
        ({"role": "pursuer", "opponent": 42}, "opponent"),
    ],
)
def test_bad_arguments(kwargs, match):
    with pytest.raises(InvalidConfigError, match=match):
        SingleAgentEnv(**kwargs)


def test_step_before_reset_raises():
    env = SingleAgentEnv("pursuer", "evader/straight", map="open_room")
    with pytest.raises(InvalidConfigError, match="reset"):
        env.step(np.zeros(2))


def test_a_list_of_maps_plays_each_episode_on_one_of_them() -> None:
    """Each reset draws a world; a built-in keeps its recommended ranges; the lidar
    observation has one shape everywhere; the same seed replays the same sequence."""
    from envs.maps import builtin_info

    maps = ["corridor", "l_hall", "random:2"]
    env = SingleAgentEnv("pursuer", "evader/straight", map=maps, observation="lidar_track",
                         n_rays=16, max_cycles=5)  # fmt: skip
    names = []
    env.reset(seed=1)
    for _ in range(20):
        names.append(env.config.map.name)
        obs, _ = env.reset()
        assert env.observation_space.contains(obs)
    assert set(names) == {"corridor", "l_hall", "random_polygons_2"}
    env.reset(seed=1)
    again = [env.config.map.name]
    for _ in range(19):
        env.reset()
        again.append(env.config.map.name)
    assert again == names
    while env.config.map.name != "corridor":
        env.reset()
    assert env.config.l_min == builtin_info("corridor").l_min
    env.close()


def test_an_empty_list_of_maps_is_refused() -> None:
    with pytest.raises(InvalidConfigError, match="map"):
        SingleAgentEnv("pursuer", "evader/straight", map=[])


@pytest.mark.parametrize("start", ["safe", "valid"])
def test_sampled_starts_work_for_a_lidar_learner(start) -> None:
    """The start sampler judges with the state; the learner still sees its lidar."""
    env = SingleAgentEnv("pursuer", "evader/straight", map="corridor", start=start,
                         observation="lidar_track", n_rays=8, max_cycles=5)  # fmt: skip
    obs, info = env.reset(seed=0)
    assert obs.shape == (16,) and info["surveillance"]
    env.close()
