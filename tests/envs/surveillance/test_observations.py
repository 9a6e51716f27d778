"""Observation layouts, the state encoder/decoder round trip, lidar against shapely."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
import shapely
from shapely.geometry import LineString

from envs import surveillance_v1
from envs.surveillance.config import EnvConfig
from envs.surveillance.observations import (
    STATE_LAYOUT,
    STATE_SIZE,
    StateEncoder,
    decode_state,
    lidar_layout,
    state_space,
)
from tests.envs.surveillance._worlds import l_room, pillar_room

P, E = "pursuer_0", "evader_0"


def _tiles(layout: dict[str, slice], size: int) -> bool:
    covered = sorted((s.start, s.stop) for s in layout.values())
    return (
        covered[0][0] == 0
        and covered[-1][1] == size
        and all(a[1] == b[0] for a, b in itertools.pairwise(covered))
    )


def test_layouts_tile_the_vector_without_gaps() -> None:
    assert _tiles(STATE_LAYOUT, STATE_SIZE)
    for n in (1, 8, 32):
        layout = lidar_layout(n)
        assert _tiles(layout, n + 6) and layout["rays"] == slice(0, n)


@pytest.mark.parametrize("seed", range(5))
def test_encode_decode_round_trip(seed: int) -> None:
    rng = np.random.default_rng(seed)
    cfg = EnvConfig(
        map=l_room(),
        v_pursuer=rng.uniform(0.5, 2),
        v_evader=rng.uniform(0.1, 1),
        l_min=1.0,
        l_max=rng.uniform(2, 6),
        max_cycles=int(rng.integers(10, 1000)),
    )
    enc = StateEncoder(cfg)
    p = tuple(rng.uniform(0, 10, 2))
    e = tuple(rng.uniform(0, 10, 2))
    vp = tuple(rng.uniform(-1, 1, 2) * cfg.v_pursuer / math.sqrt(2))
    ve = tuple(rng.uniform(-1, 1, 2) * cfg.v_evader / math.sqrt(2))
    step = int(rng.integers(0, cfg.max_cycles + 1))
    visible = bool(rng.integers(0, 2))
    obs = enc.encode(p, vp, e, ve, visible, step)
    assert obs.dtype == np.float32 and obs.shape == (STATE_SIZE,)
    assert state_space(cfg).contains(obs)
    view = decode_state(obs, cfg)
    tol = 1e-6 * 10  # float32 relative precision times the map extent
    assert np.allclose(view.pursuer_pos, p, atol=tol) and np.allclose(view.evader_pos, e, atol=tol)
    assert np.allclose(view.pursuer_vel, vp, atol=1e-6) and np.allclose(
        view.evader_vel, ve, atol=1e-6
    )
    assert view.distance == pytest.approx(math.dist(p, e), abs=1e-5)
    assert view.theta == pytest.approx(math.atan2(p[1] - e[1], p[0] - e[0]), abs=1e-6)
    assert view.visible is visible and view.step == step
    assert view.time == pytest.approx(step * cfg.dt)


def test_decode_rejects_a_wrong_shape() -> None:
    cfg = EnvConfig(map=pillar_room())
    with pytest.raises(ValueError, match=r"shape \(13,\)"):
        decode_state(np.zeros(12), cfg)


def test_env_state_observation_decodes_to_the_world() -> None:
    env = surveillance_v1.parallel_env(map=pillar_room(), max_cycles=50)
    rng = np.random.default_rng(2)
    obs, infos = env.reset(seed=9)
    while env.agents:
        p_prev, _ = env.world.positions()
        obs, _, _, _, infos = env.step({a: rng.uniform(-1, 1, 2) for a in env.agents})
        view = decode_state(obs[P], env.config)
        p, e = env.world.positions()
        assert np.allclose(view.pursuer_pos, p, atol=1e-5) and np.allclose(
            view.evader_pos, e, atol=1e-5
        )
        assert np.allclose(view.pursuer_vel, (np.array(p) - p_prev) / 0.1, atol=1e-5)
        assert view.distance == pytest.approx(infos[P]["distance"], abs=1e-5)
        assert np.array_equal(obs[P], obs[E]) and np.array_equal(obs[P], env.state())
        assert obs[P] is not obs[E]  # separate arrays: mutating one leaves the other


def _ray_oracle(world, origin, angle, max_range) -> float:
    """Distance along a ray to the walls with shapely (independent of the kernel)."""
    far = (origin[0] + max_range * math.cos(angle), origin[1] + max_range * math.sin(angle))
    hit = LineString([origin, far]).intersection(world.free_region.boundary)
    if hit.is_empty:
        return max_range
    return min(max_range, shapely.Point(origin).distance(hit))


def test_lidar_observation_against_shapely() -> None:
    world = pillar_room()
    env = surveillance_v1.parallel_env(map=world, observation="lidar", n_rays=12, l_max=4.0)
    obs, _ = env.reset(options={"pursuer": (2.0, 1.0), "evader": (2.0, 3.5)})
    layout = lidar_layout(12)
    for agent, me, other in ((P, (2.0, 1.0), (2.0, 3.5)), (E, (2.0, 3.5), (2.0, 1.0))):
        o = obs[agent]
        assert env.observation_space(agent).contains(o)
        for k, ray in enumerate(o[layout["rays"]]):
            expected = _ray_oracle(world, me, 2 * math.pi * k / 12, 4.0) / 4.0
            assert ray == pytest.approx(expected, abs=1e-6)
        rel = o[layout["other_rel"]]
        assert rel == pytest.approx(((other[0] - me[0]) / 4.0, (other[1] - me[1]) / 4.0), abs=1e-7)
        assert o[layout["visible"]][0] == 1.0 and o[layout["time"]][0] == 0.0
        assert np.all(o[layout["self_vel"]] == 0.0)


def test_lidar_masks_the_other_agent_when_surveillance_breaks() -> None:
    env = surveillance_v1.parallel_env(
        map=l_room(),
        observation="lidar",
        n_rays=8,
        l_min=1.0,
        l_max=5.0,
        v_evader=2.0,
        v_pursuer=2.0,
    )
    env.reset(options={"pursuer": (6.2, 2.0), "evader": (4.5, 6.0)})
    # the evader slips behind the corner (5, 5) and stays there at the end of the step
    obs, _, term, _, infos = env.step({P: np.zeros(2), E: np.array([1.0, 1.0])})
    assert term[P] and infos[P]["cause"] == "occluded"
    layout = lidar_layout(8)
    for agent in (P, E):
        assert obs[agent][layout["visible"]][0] == 0.0
        assert np.all(obs[agent][layout["other_rel"]] == 0.0)
        assert env.observation_space(agent).contains(obs[agent])


# ------------------------------------------------------------------ "lidar_track"
def test_lidar_track_layout_tiles_and_keeps_the_lidar_fields_in_order() -> None:
    for n in (1, 8, 32):
        layout = lidar_layout(n, track=True)
        assert _tiles(layout, n + 8)
        plain = lidar_layout(n)
        assert [k for k in layout if k != "other_vel"] == list(plain)


def test_lidar_track_reports_the_other_agents_realised_velocity() -> None:
    """After one step in open space each agent moved at its command: the tracker reports
    the other's velocity over the other's speed bound; the rest equals the plain lidar."""
    kw = dict(map=pillar_room(), n_rays=12, l_min=1.0, l_max=4.0, v_pursuer=2.0, v_evader=0.5)
    place = {"pursuer": (2.0, 1.0), "evader": (2.0, 3.0)}
    act = {P: np.array([0.6, 0.0]), E: np.array([-0.5, 0.4])}
    out = {}
    for kind in ("lidar", "lidar_track"):
        env = surveillance_v1.parallel_env(observation=kind, **kw)
        env.reset(options=place)
        out[kind], *_ = env.step(act)
        assert all(env.observation_space(a).contains(out[kind][a]) for a in (P, E))
    t, plain = lidar_layout(12, track=True), lidar_layout(12)
    for agent, other in ((P, E), (E, P)):
        o = out["lidar_track"][agent]
        assert o[t["visible"]][0] == 1.0
        # realised velocity / own bound = the command (in open space, no wall contact)
        assert o[t["other_vel"]] == pytest.approx(act[other], abs=1e-4)
        for name, s in plain.items():
            assert np.array_equal(o[t[name]], out["lidar"][agent][s]), name


def test_lidar_track_masks_the_velocity_when_surveillance_breaks() -> None:
    kw = dict(l_min=1.0, l_max=5.0, v_evader=2.0, v_pursuer=2.0)
    env = surveillance_v1.parallel_env(map=l_room(), observation="lidar_track", n_rays=8, **kw)
    env.reset(options={"pursuer": (6.2, 2.0), "evader": (4.5, 6.0)})
    obs, _, term, _, _ = env.step({P: np.zeros(2), E: np.array([1.0, 1.0])})
    assert term[P]
    t = lidar_layout(8, track=True)
    for agent in (P, E):
        assert np.all(obs[agent][t["other_vel"]] == 0.0) and obs[agent][t["visible"]][0] == 0.0


@pytest.mark.parametrize("kind", ["lidar", "lidar_track"])
def test_encode_state_rebuilds_the_envs_lidar_from_the_state_vector(kind: str) -> None:
    """What a lidar learner is shown while an expert reads the state (DAgger labels)."""
    import dataclasses

    from envs.surveillance.observations import LidarEncoder

    env = surveillance_v1.parallel_env(map="l_hall", observation=kind, n_rays=16, max_cycles=80)
    obs, _ = env.reset(seed=5)
    state_cfg = dataclasses.replace(env.config, observation="state")
    enc = {r: LidarEncoder(env.config, r, env.kernel) for r in ("pursuer", "evader")}
    rng = np.random.default_rng(0)
    steps = 0
    while env.agents:
        s = env.state()
        for role, agent in (("pursuer", P), ("evader", E)):
            got = enc[role].encode_state(s, state_cfg, role)
            assert got.shape == obs[agent].shape
            assert np.max(np.abs(got - obs[agent])) < 1e-5  # float32 rounding of positions
        obs, *_ = env.step({a: rng.uniform(-1, 1, 2) for a in env.agents})
        steps += 1
    assert steps > 5
