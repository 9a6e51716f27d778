"""PettingZoo's own test suites over a matrix of configurations (STYLE.md convention 12)."""

from __future__ import annotations

import functools
import types
import warnings

import numpy as np
import pytest

with warnings.catch_warnings():
    # pettingzoo.test imports PettingZoo's own deprecated env modules, which warn
    warnings.filterwarnings("ignore", "The old environment creation API", DeprecationWarning)
    from pettingzoo.test import (
        api_test,
        max_cycles_test,
        parallel_api_test,
        parallel_seed_test,
        render_test,
        seed_test,
    )
    from pettingzoo.test.state_test import state_test

from envs import surveillance_v1
from tests.envs.surveillance._worlds import l_room, pillar_room

CONFIGS = {
    "state-zero_sum-corridor": dict(map="corridor", max_cycles=60),
    "lidar-sparse-pillar": dict(
        map=pillar_room(), observation="lidar", n_rays=16, reward="sparse", max_cycles=60
    ),
    "state-sparse-two_rooms-fast_evader": dict(
        map="two_rooms", reward="sparse", v_pursuer=1.5, v_evader=1.2, max_cycles=60
    ),
    "lidar-zero_sum-l_room-slow": dict(
        map=l_room(),
        observation="lidar",
        v_pursuer=0.6,
        v_evader=0.2,
        l_min=1.0,
        l_max=3.0,
        dt=0.2,
        max_cycles=60,
    ),
}
IDS = list(CONFIGS)


def _module(cfg: dict) -> types.SimpleNamespace:
    """A stand-in for an env module, with the config baked into its factories."""
    return types.SimpleNamespace(
        env=functools.partial(surveillance_v1.env, **cfg),
        parallel_env=functools.partial(surveillance_v1.parallel_env, **cfg),
        raw_env=functools.partial(surveillance_v1.raw_env, **cfg),
    )


@pytest.fixture(autouse=True)
def _no_warnings():
    # PettingZoo's checkers report problems as warnings: a clean env raises none
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        yield


@pytest.mark.parametrize("name", IDS)
def test_api(name: str) -> None:
    api_test(surveillance_v1.env(**CONFIGS[name]), num_cycles=200)


@pytest.mark.parametrize("name", IDS)
def test_parallel_api(name: str) -> None:
    parallel_api_test(surveillance_v1.parallel_env(**CONFIGS[name]), num_cycles=200)


@pytest.mark.parametrize("name", IDS[:2])
def test_the_retired_v0_passes_the_suites(name: str) -> None:
    from envs import surveillance_v0

    cfg = CONFIGS[name]
    api_test(surveillance_v0.env(**cfg), num_cycles=100)
    parallel_api_test(surveillance_v0.parallel_env(**cfg), num_cycles=100)
    parallel_seed_test(functools.partial(surveillance_v0.parallel_env, **cfg), num_cycles=50)


@pytest.mark.parametrize("name", IDS)
def test_seed(name: str) -> None:
    mod = _module(CONFIGS[name])
    seed_test(mod.env, num_cycles=100)
    parallel_seed_test(mod.parallel_env, num_cycles=100)


@pytest.mark.parametrize("name", IDS)
def test_max_cycles(name: str) -> None:
    cfg = {k: v for k, v in CONFIGS[name].items() if k != "max_cycles"}
    max_cycles_test(_module(cfg))


@pytest.mark.parametrize("name", IDS[:2])
def test_render(name: str) -> None:
    render_test(_module(CONFIGS[name]).raw_env)


@pytest.mark.parametrize("name", IDS)
def test_state(name: str) -> None:
    mod = _module(CONFIGS[name])
    state_test(mod.env(), mod.parallel_env(), num_cycles=30)


@pytest.mark.parametrize("name", IDS)
def test_declared_spaces_match_data(name: str) -> None:
    """Shape, dtype and bounds of every observation and state match the declared spaces."""
    env = surveillance_v1.parallel_env(**CONFIGS[name])
    rng = np.random.default_rng(0)
    for episode in range(3):
        obs, _ = env.reset(seed=episode)
        seen = [obs]
        while env.agents:
            actions = {a: rng.uniform(-1.5, 1.5, 2).astype(np.float32) for a in env.agents}
            obs, *_ = env.step(actions)
            seen.append(obs)
            state = env.state()
            assert state.shape == env.state_space.shape and state.dtype == env.state_space.dtype
            assert env.state_space.contains(state), state
        for o in seen:
            for agent, x in o.items():
                space = env.observation_space(agent)
                assert x.shape == space.shape, (x.shape, space.shape)
                assert x.dtype == space.dtype == np.float32
                assert space.contains(x), (agent, x, space)
    for agent in env.possible_agents:
        space = env.observation_space(agent)
        assert np.all(np.isfinite(space.low)) and np.all(np.isfinite(space.high))
        act = env.action_space(agent)
        assert act.shape == (2,) and act.dtype == np.float32
        assert np.all(act.low == -1.0) and np.all(act.high == 1.0)


def test_sb3_check_env_on_a_single_agent_view() -> None:
    """SB3's checker accepts the pursuer's view with a fixed random evader."""
    gymnasium = pytest.importorskip("gymnasium")
    env_checker = pytest.importorskip("stable_baselines3.common.env_checker")

    class PursuerView(gymnasium.Env):
        def __init__(self) -> None:
            self.env = surveillance_v1.parallel_env(map=pillar_room(), max_cycles=50)
            self.observation_space = self.env.observation_space("pursuer_0")
            self.action_space = self.env.action_space("pursuer_0")
            self._rng = np.random.default_rng(0)

        def reset(self, *, seed=None, options=None):
            super().reset(seed=seed)
            if seed is not None:
                self._rng = np.random.default_rng(seed)
            obs, infos = self.env.reset(seed=seed, options=options)
            return obs["pursuer_0"], infos["pursuer_0"]

        def step(self, action):
            evader = self._rng.uniform(-1, 1, 2).astype(np.float32)
            obs, rew, term, trunc, info = self.env.step({"pursuer_0": action, "evader_0": evader})
            return (
                obs["pursuer_0"],
                rew["pursuer_0"],
                term["pursuer_0"],
                trunc["pursuer_0"],
                info["pursuer_0"],
            )

    with warnings.catch_warnings():
        warnings.simplefilter("default")  # SB3 may advise on things outside our control
        env_checker.check_env(PursuerView(), warn=True)
