"""Properties of whole episodes on seeded random worlds, against independent checks.

The other env tests play fixed worlds; these draw the world (``random:KIND:SEED`` of every
kind, transformed built-ins), the observation kind, dt and the actions (every form a
policy may return: float32 / float64 arrays, lists, numpy scalars, overshooting, zero),
and check each step against shapely and against the AEC conversion.
"""

from __future__ import annotations

import math

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from shapely.geometry import LineString, Point

from envs import surveillance_v1

P, E = "pursuer_0", "evader_0"

WORLDS = [
    "random:convex:11",
    "random:star:12",
    "random:polygons:13",
    "random:rectangles:14",
    "pillars~x0.01rot0.7",
    "maze~x100rot2off(-3000,500)",
]

_number = st.floats(-1.5, 1.5, allow_nan=False, width=64)
_actions = st.one_of(
    st.tuples(_number, _number).map(lambda v: np.array(v, dtype=np.float32)),
    st.tuples(_number, _number).map(lambda v: np.array(v)),
    st.tuples(_number, _number).map(list),
    st.tuples(_number, _number).map(lambda v: (np.float32(v[0]), np.float64(v[1]))),
    st.tuples(_number, _number).map(lambda v: [1e300 * v[0], 1e300 * v[1]]),
    st.integers(-1, 1).map(lambda k: np.array([k, -k])),
    st.just(np.zeros(2)),
)
_episode = st.fixed_dictionaries(
    {
        "world": st.sampled_from(WORLDS),
        "observation": st.sampled_from(["state", "lidar", "lidar_track"]),
        "dt": st.sampled_from([0.1, 0.37, 1.0]),
        "seed": st.integers(0, 2**31),
        # each drawn pair of actions is held for a few steps, so that bodies reach the walls
        "plan": st.lists(
            st.tuples(_actions, _actions, st.integers(2, 10)), min_size=4, max_size=15
        ),
    }
)


def _config(ep: dict) -> dict:
    # the transformed built-ins bring their scaled lengths; dt scales with them
    scale = 0.01 if "x0.01" in ep["world"] else (100.0 if "x100" in ep["world"] else 1.0)
    return dict(
        map=ep["world"],
        observation=ep["observation"],
        dt=ep["dt"] * scale if scale < 1 else ep["dt"],
        n_rays=12,
        max_cycles=80,
    )


def _actions_of(ep: dict):
    for a_p, a_e, k in ep["plan"]:
        for _ in range(k):
            yield {P: a_p, E: a_e}


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(ep=_episode)
def test_every_step_keeps_the_env_card_s_promises(ep) -> None:
    """Observations in their space (float32), disc centres in free space at least half a
    radius from the walls (physics.MAX_SUBSTEP_TRAVEL), a step reported held ends with a
    clear rod in range by shapely, and zero-sum rewards with matching flags."""
    env = surveillance_v1.parallel_env(**_config(ep))
    obs, _ = env.reset(seed=ep["seed"])
    cfg, world = env.config, env.map
    free = world.prepared_free_region
    walls = world.free_region.boundary
    tol = 1e-7 * world.scale
    for actions in _actions_of(ep):
        for a in (P, E):
            assert obs[a].dtype == np.float32
            assert env.observation_space(a).contains(obs[a]), (a, obs[a])
        if not env.agents:
            break
        obs, rew, term, trunc, infos = env.step(actions)
        p, e = env._pursuer, env._evader
        for x in (p, e):
            assert free.contains(Point(x)), x
            assert walls.distance(Point(x)) >= 0.5 * cfg.body_radius * (1 - 1e-9), x
        assert rew[P] == -rew[E] and term[P] == term[E] and trunc[P] == trunc[E]
        assert infos[P]["surveillance"] is not term[P]
        if not term[P]:  # held throughout the step, so at its end too
            assert cfg.l_min - tol <= math.dist(p, e) <= cfg.l_max + tol
            assert LineString([p, e]).difference(world.free_region).length <= tol
        else:
            assert 0.0 <= infos[P]["break_time"] <= 1.0


@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(ep=_episode)
def test_the_aec_env_plays_the_parallel_episode_bit_for_bit(ep) -> None:
    """The AEC conversion, stepped agent by agent with the same actions, gives each agent
    the parallel env's observations, rewards, flags and infos."""
    cfg = _config(ep)
    par = surveillance_v1.parallel_env(**cfg)
    aec = surveillance_v1.env(**cfg)
    obs, infos = par.reset(seed=ep["seed"])
    aec.reset(seed=ep["seed"])
    for a in (P, E):
        np.testing.assert_array_equal(aec.observe(a), obs[a])
    for actions in _actions_of(ep):
        if not par.agents:
            break
        obs, rew, term, trunc, infos = par.step(actions)
        for a in (P, E):
            assert aec.agent_selection == a
            aec.step(actions[a])
        for a in (P, E):
            np.testing.assert_array_equal(aec.observe(a), obs[a])
            assert aec.rewards[a] == rew[a]
            assert (aec.terminations[a], aec.truncations[a]) == (term[a], trunc[a])
            assert aec.infos[a] == infos[a]
    while aec.agents and not par.agents:  # ended: each agent is stepped out with None
        aec.step(None)
    assert aec.agents == par.agents
