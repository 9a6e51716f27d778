"""Behaviour of the env beyond the PettingZoo suites: determinism, placements, actions,
the continuous-time surveillance check, rewards in info, registry, rendering, pickling."""

from __future__ import annotations

import hashlib
import json
import math
import pickle

import numpy as np
import pettingzoo
import pytest
import shapely
from shapely.geometry import LineString, Polygon

from envs import surveillance_v1
from envs.errors import EpisodeStateError, InvalidActionError, InvalidPlacementError
from envs.maps import Feature
from envs.surveillance.observations import STATE_LAYOUT, decode_state
from tests.envs.surveillance._worlds import l_room, open_room, pillar_room, thin_pillar_room

P, E = "pursuer_0", "evader_0"


def _digest(env, seed: int, actions: np.ndarray) -> str:
    """SHA-256 of every observation, reward, flag and info of one seeded rollout."""
    h = hashlib.sha256()
    obs, infos = env.reset(seed=seed)
    h.update(json.dumps(infos, sort_keys=True).encode())
    for agent in env.possible_agents:
        h.update(obs[agent].tobytes())
    for a in actions:
        if not env.agents:
            break
        obs, rew, term, trunc, infos = env.step({P: a[0], E: a[1]})
        for agent in env.possible_agents:
            h.update(obs[agent].tobytes())
        h.update(json.dumps([rew, term, trunc, infos], sort_keys=True).encode())
    return h.hexdigest()


@pytest.mark.parametrize("observation", ["state", "lidar"])
def test_episode_digest_replays_from_seed_and_actions(observation: str) -> None:
    actions = np.random.default_rng(7).uniform(-1.2, 1.2, (300, 2, 2)).astype(np.float32)
    env = surveillance_v1.parallel_env(map=pillar_room(), observation=observation, max_cycles=300)
    other = surveillance_v1.parallel_env(map=pillar_room(), observation=observation, max_cycles=300)
    first = _digest(env, 3, actions)
    assert _digest(env, 3, actions) == first  # same env object, reset again
    assert _digest(other, 3, actions) == first  # a fresh env
    assert _digest(env, 4, actions) != first  # another seed, another start


def test_reset_without_seed_continues_the_generator() -> None:
    env = surveillance_v1.parallel_env(map=pillar_room())
    a, _ = env.reset(seed=11)
    b, _ = env.reset()
    c, _ = env.reset(seed=11)
    assert np.array_equal(a[P], c[P]) and not np.array_equal(a[P], b[P])


def test_random_starts_are_valid_surveillance_configurations() -> None:
    world = pillar_room()
    env = surveillance_v1.parallel_env(map=world, l_min=1.0, l_max=4.0, spawn_margin_steps=2)
    poly = world.free_region
    for seed in range(40):
        _, infos = env.reset(seed=seed)
        p, e = np.array(env.world.positions()[0]), np.array(env.world.positions()[1])
        assert infos[P]["surveillance"] is True
        # independent oracle: shapely sees a clear rod, both discs fit, range respected
        assert poly.buffer(1e-9).contains(LineString([p, e]))
        for q in (p, e):
            assert shapely.Point(q).distance(poly.exterior) >= 0.1 - 1e-12
        margin = min((1.0 + 0.5) * 0.2, 0.25 * 3.0)
        assert 1.0 + margin - 1e-12 <= np.linalg.norm(p - e) <= 4.0 - margin + 1e-12
        rod = LineString([p, e])
        for v in world.vertices[world.vertex_convex]:
            assert rod.distance(shapely.Point(v)) >= 1.0 * 0.2 - 1e-12


def test_options_place_the_agents_exactly() -> None:
    env = surveillance_v1.parallel_env(map=pillar_room())
    obs, infos = env.reset(options={"pursuer": (2.0, 1.0), "evader": (2.0, 3.5)})
    view = decode_state(obs[P], env.config)
    assert np.allclose(view.pursuer_pos, (2.0, 1.0), atol=1e-5)
    assert np.allclose(view.evader_pos, (2.0, 3.5), atol=1e-5)
    assert infos[P]["distance"] == pytest.approx(2.5)
    assert infos[P]["theta"] == pytest.approx(-math.pi / 2)


@pytest.mark.parametrize(
    ("pursuer", "evader", "pattern"),
    [
        ((5.0, 5.0), (5.0, 2.0), r"pursuer position \(5, 5\) is outside the free space"),
        ((2.0, 1.0), (11.0, 1.0), r"evader position \(11, 1\) is outside the free space"),
        ((0.05, 2.0), (3.0, 2.0), r"pursuer position \(0.05, 2\) is 0.05 from the nearest wall"),
        ((2.0, 1.0), (2.0, 2.5), r"out of range: distance 1.5 .*\[2, 4\] \(too_close\)"),
        ((1.0, 1.0), (8.0, 1.0), r"out of range: distance 7 .*\(too_far\)"),
        ((3.0, 5.0), (7.0, 5.0), r"occluded by .*(vertex|edge) \d+"),
        ((2.0, 1.0), None, r"must give both 'pursuer' and 'evader'"),
        ((2.0, float("nan")), (2.0, 3.5), r"pursuer = \(2.0, nan\): expected finite values"),
        ((1.0, 2.0, 3.0), (2.0, 3.5), r"pursuer: expected shape \(2,\), got shape \(3,\)"),
    ],
)
def test_bad_placements_raise_naming_positions_and_reason(pursuer, evader, pattern) -> None:
    env = surveillance_v1.parallel_env(map=pillar_room())
    with pytest.raises(InvalidPlacementError, match=pattern):
        env.reset(options={"pursuer": pursuer, "evader": evader})


def test_occluded_placement_names_the_blocking_feature() -> None:
    world = pillar_room()
    env = surveillance_v1.parallel_env(map=world)
    with pytest.raises(InvalidPlacementError) as err:
        env.reset(options={"pursuer": (3.0, 4.5), "evader": (6.5, 4.5)})
    # the rod crosses the pillar's left edge x = 4 first, from the pursuer's side
    feature_text = str(err.value).split("occluded by ")[1]
    assert "(4, 4)-(4, 6)" in feature_text or "(4, 6)-(4, 4)" in feature_text


def test_open_space_step_moves_exactly_v_dt() -> None:
    env = surveillance_v1.parallel_env(map=open_room(), v_pursuer=1.3, v_evader=0.7, dt=0.1)
    env.reset(options={"pursuer": (3.0, 5.0), "evader": (6.0, 5.0)})
    a_p = np.array([0.6, -0.8], dtype=np.float32)  # unit length (up to float32): full speed
    a_e = np.array([0.3, 0.4], dtype=np.float32)
    obs, *_ = env.step({P: a_p, E: a_e})
    p, e = env.world.positions()
    # the command is the action projected onto the unit disc, times the speed bound
    u_p = a_p.astype(float) / max(1.0, float(np.hypot(*a_p.astype(float))))
    u_e = a_e.astype(float)
    assert p == pytest.approx((3.0 + 1.3 * 0.1 * u_p[0], 5.0 + 1.3 * 0.1 * u_p[1]), abs=1e-12)
    assert e == pytest.approx((6.0 + 0.7 * 0.1 * u_e[0], 5.0 + 0.7 * 0.1 * u_e[1]), abs=1e-12)
    view = decode_state(obs[P], env.config)
    assert np.allclose(view.pursuer_vel, 1.3 * a_p, atol=1e-6)
    assert np.allclose(view.evader_vel, 0.7 * a_e, atol=1e-6)


def test_out_of_box_actions_are_clipped_to_box_then_unit_disc() -> None:
    env = surveillance_v1.parallel_env(map=open_room(), v_pursuer=1.0, v_evader=0.5)
    env.reset(options={"pursuer": (3.0, 5.0), "evader": (6.0, 5.0)})
    env.step({P: np.array([5.0, 0.0]), E: [-3.0, 7.0]})  # lists are accepted too
    p, e = env.world.positions()
    assert p == pytest.approx((3.1, 5.0), abs=1e-12)  # clipped to 1, full speed
    # (-3, 7) -> (-1, 1) -> (-1, 1) / sqrt(2): never faster than the bound
    s = 0.5 * 0.1 / math.sqrt(2.0)
    assert e == pytest.approx((6.0 - s, 5.0 + s), abs=1e-12)


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_non_finite_actions_raise_naming_the_agent(bad: float) -> None:
    env = surveillance_v1.parallel_env(map=open_room())
    env.reset(seed=0)
    with pytest.raises(InvalidActionError, match="evader_0: action must be finite"):
        env.step({P: np.zeros(2), E: np.array([0.0, bad])})


def test_wrong_shape_and_missing_actions_raise() -> None:
    env = surveillance_v1.parallel_env(map=open_room())
    env.reset(seed=0)
    with pytest.raises(
        InvalidActionError, match=r"pursuer_0: expected an action of shape \(2,\), got shape \(3,\)"
    ):
        env.step({P: np.zeros(3), E: np.zeros(2)})
    with pytest.raises(InvalidActionError, match=r"missing actions for \['evader_0'\]"):
        env.step({P: np.zeros(2)})
    with pytest.raises(InvalidActionError, match="pursuer_0"):
        env.step({P: "fast", E: np.zeros(2)})


def _first_contact_oracle(world, p0, e0, p1, e1, n=20001):
    """Brute force: first sampled t where the rod meets an obstacle (shapely)."""
    obstacles = [Polygon(o) for o in world.obstacles] or [Polygon(world.boundary).exterior]
    for t in np.linspace(0.0, 1.0, n):
        rod = LineString([p0 + t * (p1 - p0), e0 + t * (e1 - e0)])
        if any(rod.intersects(o) for o in obstacles):
            return t
    return None


def test_rod_sweeping_a_corner_within_one_step_breaks_surveillance() -> None:
    """Both frames are clear, yet the rod passes over a tiny pillar during the step."""
    world = thin_pillar_room()
    env = surveillance_v1.parallel_env(
        map=world, l_min=1.0, l_max=5.0, v_pursuer=3.0, v_evader=3.0, body_radius=0.05
    )
    p0, e0 = np.array([7.0, 4.88]), np.array([3.0, 4.9])
    env.reset(options={"pursuer": tuple(p0), "evader": tuple(e0)})
    obs, rew, term, trunc, infos = env.step({P: np.array([0.0, 1.0]), E: np.array([0.0, 1.0])})
    p1, e1 = p0 + np.array([0.0, 0.3]), e0 + np.array([0.0, 0.3])
    assert np.allclose(env.world.positions(), [p1, e1], atol=1e-12)
    # the end frame alone shows nothing wrong: a frame-by-frame check would miss this
    assert LineString([p1, e1]).disjoint(Polygon(world.obstacles[0]))
    assert obs[P][STATE_LAYOUT["visible"]][0] == 1.0
    info = infos[P]
    assert term == {P: True, E: True} and trunc == {P: False, E: False}
    assert info["surveillance"] is False and info["cause"] == "occluded"
    # the rod translates up by 0.3 t; its height at x is 4.9 - 0.005 (x - 3): the corner
    # (4.95, 5.0) is met first, at t = (5.0 - 4.890250) / 0.3
    t_exact = (5.0 - (4.9 - 0.005 * 1.95)) / 0.3
    assert 0.0 < info["break_time"] < 1.0
    assert info["break_time"] == pytest.approx(t_exact, abs=1e-9)
    assert info["break_time"] == pytest.approx(
        _first_contact_oracle(world, p0, e0, p1, e1), abs=1e-4
    )
    assert "vertex" in info["feature"] and "(4.95, 5)" in info["feature"]
    assert info["break_at"] == pytest.approx(0.1 * t_exact)
    assert infos[E]["cause"] == "occluded" and infos[E]["feature"] == info["feature"]
    assert rew == {P: -1.0, E: 1.0}
    assert info["reward_escape"] == -1.0 and infos[E]["reward_escape"] == 1.0
    assert env.agents == []


def test_evader_rounding_a_corner_is_reported_with_that_corner() -> None:
    world = l_room()
    corner = int(np.flatnonzero(world.vertex_convex)[0])
    assert np.allclose(world.vertices[corner], (5.0, 5.0))
    env = surveillance_v1.parallel_env(map=world, l_min=1.0, l_max=5.0, v_evader=2.0, v_pursuer=2.0)
    # the rod passes 0.075 left of the corner; the evader moves 0.2 right in open space
    p0, e0 = np.array([6.2, 2.0]), np.array([4.5, 6.0])
    env.reset(options={"pursuer": tuple(p0), "evader": tuple(e0)})
    *_, infos = env.step({P: np.array([0.0, 0.0]), E: np.array([1.0, 0.0])})
    e1 = e0 + np.array([0.2, 0.0])
    assert np.allclose(env.world.positions(), [p0, e1], atol=1e-12)
    info = infos[P]
    assert info["cause"] == "occluded"
    assert info["feature"] == world.describe(Feature("vertex", corner))
    # closed form: the corner lies on the rod when cross(P - v, E(t) - v) = 0
    a = p0 - (5.0, 5.0)
    c0 = e0 - (5.0, 5.0)
    t_exact = (a[0] * c0[1] - a[1] * c0[0]) / (a[1] * (e1 - e0)[0] - a[0] * (e1 - e0)[1])
    assert 0.0 < t_exact < 1.0
    assert info["break_time"] == pytest.approx(t_exact, abs=1e-9)
    assert info["break_time"] == pytest.approx(
        _first_contact_oracle(world, p0, e0, p0, e1), abs=1e-4
    )


@pytest.mark.parametrize(
    ("evader_action", "cause", "t_exact"),
    [
        # rod along x, length 3; evader moves away at 1.0: |P - E| = 3 + 0.1 t ... reaches 3.05
        (np.array([-1.0, 0.0]), "too_far", 0.5),
        # moves toward the pursuer: 3 - 0.1 t reaches 2.95 at t = 0.5
        (np.array([1.0, 0.0]), "too_close", 0.5),
    ],
)
@pytest.mark.filterwarnings("ignore::envs.errors.NarrowBandWarning")  # a 0.1 band on purpose
def test_range_breaks_report_cause_and_time(evader_action, cause, t_exact) -> None:
    env = surveillance_v1.parallel_env(
        map=open_room(), l_min=2.95, l_max=3.05, v_evader=1.0, body_radius=0.1
    )
    env.reset(options={"pursuer": (6.0, 5.0), "evader": (3.0, 5.0)})
    *_, infos = env.step({P: np.zeros(2), E: evader_action})
    assert infos[P]["cause"] == cause and infos[P]["feature"] is None
    assert infos[P]["break_time"] == pytest.approx(t_exact, abs=1e-9)


@pytest.mark.parametrize("reward", ["zero_sum", "sparse"])
def test_rewards_are_zero_sum_and_components_add_up(reward: str) -> None:
    env = surveillance_v1.parallel_env(map=pillar_room(), reward=reward, max_cycles=40)
    rng = np.random.default_rng(1)
    for seed in range(6):
        env.reset(seed=seed)
        total = 0.0
        while env.agents:
            _, rew, term, trunc, infos = env.step({a: rng.uniform(-1, 1, 2) for a in env.agents})
            assert rew[P] == -rew[E]
            for agent in (P, E):
                parts = sum(
                    infos[agent][k]
                    for k in ("reward_surveillance", "reward_escape", "reward_horizon")
                )
                assert parts == pytest.approx(rew[agent])
            total += rew[P]
        escaped = term[P]
        steps = infos[P]["step"]
        if reward == "zero_sum":
            expected = (steps - 1) / 40 - 1.0 if escaped else 1.0
        else:
            expected = -1.0 if escaped else 1.0
        assert total == pytest.approx(expected)
        assert trunc[P] == (not escaped) and steps <= 40


def test_agents_emptied_after_the_end_and_further_steps_raise() -> None:
    env = surveillance_v1.parallel_env(map=open_room(), max_cycles=3)
    with pytest.raises(EpisodeStateError, match=r"^step\(\) before reset\(\)"):
        env.step({P: np.zeros(2), E: np.zeros(2)})
    env.reset(seed=0)
    for _ in range(3):
        out = env.step({P: np.zeros(2), E: np.zeros(2)})
    assert out[3] == {P: True, E: True} and env.agents == []
    with pytest.raises(EpisodeStateError, match=r"ended at step 3 \(max_cycles reached\)"):
        env.step({})
    with pytest.raises(RuntimeError):  # also the conventional type of a call out of order
        env.step({P: np.zeros(2), E: np.zeros(2)})
    env.reset(seed=1)  # a new episode steps again
    assert env.step({P: np.zeros(2), E: np.zeros(2)})[0].keys() == {P, E}


def test_step_after_an_escape_names_the_cause() -> None:
    env = surveillance_v1.parallel_env(map=open_room(), max_cycles=200)
    env.reset(seed=0)
    while env.agents:  # the evader runs straight at the pursuer: too close
        d = np.subtract(env._pursuer, env._evader)
        env.step({P: np.zeros(2), E: d / np.linalg.norm(d)})
    with pytest.raises(EpisodeStateError, match=r"the evader escaped: too_close"):
        env.step({P: np.zeros(2), E: np.zeros(2)})


def test_registry_and_versioned_name() -> None:
    from envs import surveillance_v0

    for version, module in enumerate((surveillance_v0, surveillance_v1)):
        name = f"surveillance_v{version}"
        assert module.parallel_env.metadata["name"] == name
        par = pettingzoo.make("parallel", f"surveil/{name}", map=open_room(), max_cycles=7)
        assert type(par) is module.parallel_env and par.config.max_cycles == 7
        assert par.metadata["name"] == name
        assert type(module.env(map=open_room()).unwrapped) is module.parallel_env
        assert module.ENV_ID == f"surveil/surveillance-v{version}"
    aec = pettingzoo.make("aec", "surveil/surveillance", map=open_room())  # unversioned: latest
    assert type(aec.unwrapped) is surveillance_v1.parallel_env
    assert type(pettingzoo.make("parallel", "surveil/surveillance")) is surveillance_v1.parallel_env


def test_v0_is_v1_with_the_chord_sweep() -> None:
    """v0 differs from v1 only in how a step where a wall bent a body's path is swept: in
    the open room (no wall between the agents), both agents at the same speed and
    heading, held until they slide along a wall and the range breaks, the episodes agree
    step for step, a break's time aside when its step had a contact; and the pickled v0
    env comes back as v0."""
    from envs import surveillance_v0

    contacts = 0
    for seed in range(4):
        runs = []
        touched: list[bool] = []  # v1's record of the steps with a wall contact
        for module in (surveillance_v1, surveillance_v0):
            env = module.parallel_env(map=open_room(), max_cycles=150, v_evader=1.0)
            obs, _ = env.reset(seed=seed)
            rng = np.random.default_rng(seed)
            rows = [obs[P].tolist()]
            k = 0
            while env.agents:
                if k % 30 == 0:
                    heading = dict.fromkeys(env.agents, rng.uniform(-1, 1, 2))
                obs, rew, term, _, infos = env.step(heading)
                if env.sweep_path:
                    touched.append(bool(env.world._carry))
                when = None if touched[k] else infos[P].get("break_time")
                rows.append((obs[P].tolist(), rew[P], term[P], infos[P].get("cause"), when))
                k += 1
            runs.append(rows)
        assert runs[0] == runs[1], seed
        contacts += sum(touched)
    assert contacts > 50  # the walls were met
    v0 = pickle.loads(pickle.dumps(surveillance_v0.parallel_env(map=open_room())))
    assert type(v0) is surveillance_v0.parallel_env and not v0.sweep_path


def test_env_wrappers_and_aec_conversion() -> None:
    from pettingzoo.utils.wrappers import OrderEnforcingWrapper

    aec = surveillance_v1.env(map=open_room())
    assert isinstance(aec, OrderEnforcingWrapper)
    with pytest.raises(Exception, match="reset"):
        aec.step(np.zeros(2, dtype=np.float32))


def test_rgb_array_frames_show_the_state() -> None:
    env = surveillance_v1.parallel_env(
        map=thin_pillar_room(),
        render_mode="rgb_array",
        l_min=1.0,
        l_max=5.0,
        v_pursuer=3.0,
        v_evader=3.0,
        body_radius=0.05,
    )
    env.reset(options={"pursuer": (7.0, 4.88), "evader": (3.0, 4.9)})
    frame = env.render()
    assert frame.dtype == np.uint8 and frame.ndim == 3 and frame.shape[2] == 3
    h, w, _ = frame.shape
    assert abs(h - w) <= 1  # the square map keeps its aspect

    def colours(img):
        return {tuple(int(v) for v in c) for c in img.reshape(-1, 3)}

    before = colours(frame)
    assert {(40, 90, 220), (220, 50, 50), (30, 170, 60)} <= before  # pursuer, evader, green rod
    assert (220, 30, 30) not in before and (255, 140, 0) not in before
    env.step({P: np.array([0.0, 1.0]), E: np.array([0.0, 1.0])})  # sweeps over the pillar
    after = colours(env.render())
    assert (220, 30, 30) in after and (30, 170, 60) not in after  # the rod turns red
    assert (255, 140, 0) in after  # the occluding corner is highlighted
    env.close()
    env.close()  # idempotent


def test_render_before_reset_is_an_error() -> None:
    """As step() before reset(), and as the AEC env (PettingZoo's OrderEnforcingWrapper):
    it drew a frame with both agents at (0, 0)."""
    env = surveillance_v1.parallel_env(map="corridor", render_mode="rgb_array")
    with pytest.raises(EpisodeStateError, match=r"^render\(\) before reset\(\)"):
        env.render()
    env.reset(seed=0)
    assert env.render().ndim == 3
    with pytest.warns(UserWarning, match=r"render_mode=None draws nothing.*'rgb_array'"):
        assert surveillance_v1.parallel_env(map="corridor").render() is None  # no render_mode
    env.close()


def test_state_before_reset_is_an_error() -> None:
    """As step() and render() before reset(), and as the AEC env: it returned a state
    vector of both agents at (0, 0) (in the corridor's wall) without a word."""
    env = surveillance_v1.parallel_env(map="corridor", max_cycles=3)
    with pytest.raises(EpisodeStateError, match=r"^state\(\) before reset\(\)"):
        env.state()
    obs, _ = env.reset(seed=0)
    assert np.array_equal(env.state(), obs[P])
    while env.agents:
        obs, *_ = env.step({P: np.zeros(2), E: np.zeros(2)})
    assert np.array_equal(env.state(), obs[P])  # after the end: the last state, as before


def test_human_render_runs_headless_and_close_is_idempotent() -> None:
    env = surveillance_v1.parallel_env(map=open_room(), render_mode="human", max_cycles=3)
    env.reset(seed=0)
    while env.agents:
        env.step({P: np.zeros(2), E: np.zeros(2)})
    assert env.render() is None
    env.close()
    env.close()


def test_env_pickles_and_replays() -> None:
    env = surveillance_v1.parallel_env(map=pillar_room(), observation="lidar", n_rays=8)
    clone = pickle.loads(pickle.dumps(env))
    assert clone.config == env.config
    a, _ = env.reset(seed=5)
    b, _ = clone.reset(seed=5)
    assert np.array_equal(a[P], b[P]) and np.array_equal(a[E], b[E])


def _rollout(env, actions) -> list:
    """Everything a parallel env returns over ``actions`` (until it ends), as bytes/json."""
    out = []
    for a in actions:
        if not env.agents:
            break
        obs, *rest = env.step({P: a, E: a})
        out.append(([obs[P].tobytes(), obs[E].tobytes()], json.dumps(rest, sort_keys=True)))
    return out


@pytest.mark.parametrize("version", ["v0", "v1"])
def test_deepcopy_mid_episode_carries_the_episode_on(version: str) -> None:
    """A deep copy taken in a wall-contact step continues as the original would, bit for
    bit, and independently of it (deepcopy used to rebuild the env from its arguments,
    like pickle, so the copy raised "step() before reset()")."""
    import copy

    from envs import surveillance_v0

    module = {"v0": surveillance_v0, "v1": surveillance_v1}[version]
    # both agents driven up into the corridor's wall: contacts from step 39 on (seed 0)
    up = np.array([0.3, 1.0], dtype=np.float32)
    make = lambda: module.parallel_env(map="corridor", max_cycles=60)
    reference = make()
    reference.reset(seed=0)
    expected = _rollout(reference, [up] * 60)
    env = make()
    env.reset(seed=0)
    head = _rollout(env, [up] * 45)
    assert env.world._carry  # the copy is taken while a body touches a wall
    clone = copy.deepcopy(env)
    assert clone.world.space is not env.world.space and clone.kernel is env.kernel
    tail = _rollout(clone, [up] * 60)  # the copy first, so a shared state would show
    assert head + tail == expected and len(tail) == 15
    assert _rollout(env, [up] * 60) == tail

    def aec_rollout(aec) -> list:
        out = []
        for _ in aec.agent_iter():
            obs, reward, term, trunc, _info = aec.last()
            out.append((obs.tobytes(), reward, term, trunc))
            aec.step(None if term or trunc else up)
        return out

    aec = module.env(map="corridor", max_cycles=60)
    aec.reset(seed=0)
    aec_expected = aec_rollout(aec)
    aec.reset(seed=0)
    for _ in range(2 * 45):
        aec.step(up)
    aec_tail = aec_rollout(copy.deepcopy(aec))
    assert len(aec_tail) == 2 * 15 + 2  # the 15 remaining steps, then both agents' end
    assert aec_tail == aec_expected[-len(aec_tail) :]


def test_a_shallow_copy_mid_episode_carries_the_episode_on_independently() -> None:
    """copy.copy went through EzPickle and rebuilt an unreset env ("step() before
    reset()" on a copy of a running episode); it is a deep copy now."""
    import copy

    up = np.array([0.3, 1.0], dtype=np.float32)
    reference = surveillance_v1.parallel_env(map="corridor", max_cycles=30)
    reference.reset(seed=0)
    expected = _rollout(reference, [up] * 30)
    env = surveillance_v1.parallel_env(map="corridor", max_cycles=30)
    env.reset(seed=0)
    head = _rollout(env, [up] * 10)
    clone = copy.copy(env)
    assert clone.world.space is not env.world.space
    tail = _rollout(clone, [up] * 30)
    assert head + tail == expected
    assert _rollout(env, [up] * 30) == tail
