"""The shared episode runner: seeding, per-role observations, callbacks, failures."""

from __future__ import annotations

import time

import numpy as np
import pytest

from envs.errors import InvalidConfigError, InvalidPlacementError
from envs.surveillance.observations import decode_state, lidar_layout
from strategies.mixed import MixedPolicy
from strategies.policies.base import BasePolicy
from strategies.runner import (
    EpisodeTimeout,
    PolicyFailure,
    observation_options,
    run_episode,
)

MAP = "open_room"


class Probe(BasePolicy):
    """Records what it sees; moves on a fixed, observation-independent schedule."""

    def __init__(
        self, options=None, *, name="probe", fail_at=None, sleep=0.0, fail_reset=None,
        reset_sleep=0.0,
    ):  # fmt: skip
        super().__init__(name=name)
        self.uses_state = options is None or options.get("observation") == "state"
        self.observation_options = options
        self.fail_at, self.sleep, self.fail_reset = fail_at, sleep, fail_reset
        self.reset_sleep = reset_sleep
        self.seen: list[np.ndarray] = []

    def _reset(self) -> None:
        if self.fail_reset is not None:
            raise self.fail_reset
        time.sleep(self.reset_sleep)
        self.seen = []

    def act(self, observation):
        if self._steps == self.fail_at:
            raise RuntimeError("probe exploded")
        if self.sleep:
            time.sleep(self.sleep)
        self.seen.append(np.array(observation, copy=True))
        k = self._steps
        self._steps += 1
        return np.array([np.cos(0.1 * k), np.sin(0.1 * k)], dtype=np.float32) * 0.3


def test_same_seed_same_episode_bit_for_bit():
    a = run_episode(MAP, "pursuer/greedy", "evader/random", seed=7, max_cycles=60)
    b = run_episode(MAP, "pursuer/greedy", "evader/random", seed=7, max_cycles=60)
    c = run_episode(MAP, "pursuer/greedy", "evader/random", seed=8, max_cycles=60)
    assert np.array_equal(a.trajectory, b.trajectory)
    clocks = {"wall_seconds": 0, "decide_seconds": 0, "decide_max": 0, "reset_seconds": 0}
    assert a.to_record() | clocks == (b.to_record() | clocks)
    assert a.start != c.start
    assert a.trajectory.shape == (a.steps + 1, 2, 2)
    assert np.allclose(a.trajectory[0, 0], a.start["pursuer"])
    assert a.map_digest and a.observations == {
        "pursuer": {"observation": "state"},
        "evader": {"observation": "state"},
    }


def test_each_policy_gets_its_own_observation_bit_for_bit():
    lidar16 = {"observation": "lidar", "n_rays": 16}
    lidar8 = {"observation": "lidar", "n_rays": 8}
    # the env is built with the pursuer's lidar-8; the evader's lidar-16 is encoded aside
    p1, e1 = Probe(lidar8), Probe(lidar16)
    r1 = run_episode(MAP, p1, e1, seed=2, max_cycles=25, start="valid")
    # the env is built with the evader's lidar-16 (the pursuer reads state here)
    p2, e2 = Probe(None), Probe(lidar16)
    r2 = run_episode(MAP, p2, e2, seed=2, max_cycles=25, start="valid")
    assert np.array_equal(r1.trajectory, r2.trajectory)  # the probes ignore what they see
    assert len(e1.seen) == len(e2.seen) == r1.steps
    for a, b in zip(e1.seen, e2.seen, strict=True):
        assert np.array_equal(a, b)
    assert e1.seen[0].shape == (lidar_layout(16)["time"].stop,)
    assert p1.seen[0].shape == (lidar_layout(8)["time"].stop,)
    # the state reader got env.state(): it decodes to the exact positions
    for k, obs in enumerate(p2.seen):
        view = decode_state(obs, r2.config)
        assert np.allclose(view.pursuer_pos, r2.trajectory[k, 0], atol=1e-4)
    assert r1.observations["evader"] == {"observation": "lidar", "n_rays": 16, "lidar_range": None}


def test_analytic_policy_plays_the_same_beside_a_lidar_opponent():
    """An analytic pursuer reads the state even when the env encodes lidar for the evader."""
    lidar = {"observation": "lidar", "n_rays": 8}
    a = run_episode(MAP, "pursuer/greedy", Probe(lidar), seed=4, max_cycles=40)
    b = run_episode(MAP, "pursuer/greedy", Probe(None), seed=4, max_cycles=40)
    assert np.array_equal(a.trajectory, b.trajectory)
    assert observation_options(Probe(lidar)) == lidar
    assert observation_options(Probe(None)) == {"observation": "state"}


def test_step_callback_and_streamed_frames():
    seen, frames = [], []
    r = run_episode(
        MAP,
        "pursuer/greedy",
        "evader/straight",
        seed=1,
        max_cycles=12,
        on_step=seen.append,
        on_frame=frames.append,
    )
    assert [t.step for t in seen] == list(range(r.steps))
    assert seen[-1].done and not any(t.done for t in seen[:-1])
    for k, t in enumerate(seen):
        view = decode_state(t.state, r.config)
        assert np.allclose(view.evader_pos, r.trajectory[k, 1], atol=1e-4)
        assert set(t.actions) == {"pursuer", "evader"}
    assert len(frames) == r.steps + 1 and frames[0].ndim == 3 and r.frames is None
    kept = run_episode(MAP, "pursuer/greedy", "evader/straight", seed=1, max_cycles=12, record=True)
    assert len(kept.frames) == r.steps + 1
    assert np.array_equal(kept.frames[-1], frames[-1])


def test_a_raising_policy_is_blamed_by_role_and_step():
    with pytest.raises(PolicyFailure) as info:
        run_episode(MAP, "pursuer/greedy", Probe(fail_at=5), seed=0, max_cycles=30)
    assert info.value.role == "evader" and info.value.step == 5
    assert "probe exploded" in str(info.value) and "RuntimeError" in info.value.error
    with pytest.raises(PolicyFailure) as info:
        run_episode(MAP, Probe(fail_reset=KeyError("k")), "evader/random", seed=0, max_cycles=5)
    assert info.value.role == "pursuer" and info.value.step == -1
    # configuration errors stay what they are
    with pytest.raises(InvalidConfigError):
        run_episode(MAP, Probe(fail_reset=InvalidConfigError("bad")), "evader/random", 0)


class _Returns(BasePolicy):
    """A user's policy that overrides ``act`` and returns ``action`` from step 2 on."""

    def __init__(self, action):
        super().__init__(name="user")
        self.action = action

    def act(self, observation):
        self._steps += 1
        return self.action if self._steps > 2 else np.zeros(2)


@pytest.mark.parametrize(
    "action", [[np.nan, 0.0], [0.0, np.inf], np.zeros(3), np.zeros((1, 2)), None, "up"]
)
def test_an_action_the_env_refuses_is_the_policys_failure(action):
    # it escaped run_episode as the env's InvalidActionError naming only 'evader_0', so a
    # tournament stored the match as an error (nobody played) instead of a forfeit
    with pytest.raises(PolicyFailure) as info:
        run_episode(MAP, "pursuer/greedy", _Returns(action), seed=0, max_cycles=20)
    assert info.value.role == "evader" and info.value.policy == "user" and info.value.step == 2
    assert "InvalidActionError" in info.value.error


def test_actions_the_env_accepts_still_play():
    # lists, ints and out-of-box values are clipped by the env, not refused
    for action in ([0.5, 0.5], (1, 0), np.array([1, 0]), np.array([1e300, -1e300])):
        r = run_episode(MAP, "pursuer/greedy", _Returns(action), seed=0, max_cycles=10)
        assert r.steps >= 1


class _OneBuffer(BasePolicy):
    """A user's policy that writes every action into the same array."""

    def __init__(self):
        super().__init__(name="one-buffer")
        self.buf = np.zeros(2)

    def act(self, observation):
        self._steps += 1
        self.buf[:] = (np.cos(self._steps), np.sin(self._steps))
        return self.buf


def test_recorded_actions_are_copies_of_what_each_step_took():
    # a policy reusing its buffer made every recorded action the last one (DAgger datasets
    # and other on_step consumers read corrupted actions without a word)
    seen = []
    r = run_episode(MAP, "pursuer/greedy", _OneBuffer(), seed=0, max_cycles=6, on_step=seen.append)
    assert len(seen) == r.steps >= 3
    for k, t in enumerate(seen):
        assert np.allclose(t.actions["evader"], (np.cos(k + 1), np.sin(k + 1)))


def test_time_limit_blames_the_slow_side():
    with pytest.raises(EpisodeTimeout) as info:
        run_episode(
            MAP, Probe(sleep=0.02), "evader/random", seed=0, max_cycles=200, time_limit=0.15
        )
    assert info.value.role == "pursuer" and 0 < info.value.step < 200


def test_the_time_limit_is_each_roles_own_decision_clock():
    # The limit counted the whole episode, the env's work included, and an overrun was
    # blamed on the side that had spent more time in act: the env's time alone (a
    # 4096-ray lidar on a round room of 1000 walls) made the greedy pursuer forfeit, and a
    # pursuer whose reset overran the limit was not blamed when the evader acted slower.
    from envs.maps import Map

    a = np.linspace(0, 2 * np.pi, 1000, endpoint=False)
    disc = Map(np.c_[10 + 10 * np.cos(a), 10 + 10 * np.sin(a)], [], name="disc")
    lidar = Probe({"observation": "lidar", "n_rays": 4096})
    r = run_episode(
        disc, "pursuer/greedy", lidar, seed=1, max_cycles=40, start="valid", time_limit=0.3
    )
    assert r.steps == 40 and r.wall_seconds > 0.3  # the env's time alone is past the limit
    with pytest.raises(EpisodeTimeout) as info:
        run_episode(MAP, Probe(reset_sleep=0.3), Probe(sleep=0.002), seed=0, max_cycles=40,
                    time_limit=0.2)  # fmt: skip
    assert info.value.role == "pursuer" and info.value.step == -1
    assert "its clock ran out" in str(info.value) and "failed at reset" in str(info.value)


class _SlowThenRaises(Probe):
    """Its reset (or its act at step 2) runs past the clock, then raises ``error``: a
    policy that turns whatever interrupted it into an error of its own (a model loader
    reports any failure of its load as an ``InvalidConfigError``)."""

    def __init__(self, error, *, at_reset=True):
        super().__init__(name="wraps")
        self.error, self.at_reset = error, at_reset

    def _reset(self):
        super()._reset()
        if self.at_reset:
            time.sleep(0.3)
            raise self.error

    def act(self, observation):
        if not self.at_reset and self._steps == 2:
            time.sleep(0.3)
            raise self.error
        return super().act(observation)


@pytest.mark.parametrize(
    ("error", "at_reset"),
    [(InvalidConfigError("cannot load the model file"), True),
     (RuntimeError("Error calling __set_name__"), True),
     (RuntimeError("Error calling __set_name__"), False)],
)  # fmt: skip
def test_a_call_that_raises_past_its_clock_is_a_timeout_of_its_role(error, at_reset):
    # A tournament's alarm interrupted a learned model's first reset (its import of torch,
    # past a 1 s clock) and the model's loader wrapped the interruption in an
    # InvalidConfigError: the runner let it through as a configuration error, and the
    # match was stored as an error charged to nobody. Other errors raised past the clock
    # were forfeits for what they said, not for the clock.
    with pytest.raises(EpisodeTimeout) as info:
        run_episode(MAP, _SlowThenRaises(error, at_reset=at_reset), "evader/random", seed=0,
                    max_cycles=10, time_limit=0.1)  # fmt: skip
    assert info.value.role == "pursuer" and info.value.step == (-1 if at_reset else 2)
    text = str(info.value)
    assert "its clock ran out" in text and f"then raised {type(error).__name__}" in text
    assert info.value.__cause__ is error
    # within its clock, the call's own error stands
    with pytest.raises(type(error) if at_reset and isinstance(error, ValueError)
                       else PolicyFailure) as info:  # fmt: skip
        run_episode(MAP, _SlowThenRaises(error, at_reset=at_reset), "evader/random", seed=0,
                    max_cycles=10, time_limit=5)  # fmt: skip
    assert not isinstance(info.value, EpisodeTimeout)


def test_mixture_picks_one_component_per_episode_reproducibly():
    mix = MixedPolicy(["evader/straight", "evader/random"], [0.5, 0.5])
    picks = {
        s: run_episode(MAP, "pursuer/greedy", mix, seed=s, max_cycles=5).evader for s in range(12)
    }
    assert set(picks.values()) == {"evader/straight", "evader/random"}
    again = run_episode(MAP, "pursuer/greedy", mix, seed=3, max_cycles=5)
    assert again.evader == picks[3]


def test_bad_arguments_are_clear_errors():
    with pytest.raises(InvalidConfigError, match="start"):
        run_episode(MAP, "pursuer/greedy", "evader/random", 0, start="anywhere")
    with pytest.raises(InvalidConfigError, match="pursuer/KIND"):
        run_episode(MAP, "evader/random", "evader/random", 0)
    with pytest.raises(InvalidConfigError, match="observation"):
        run_episode(
            MAP, "pursuer/greedy", "evader/random", 0, observations={"evader": {"observation": 3}}
        )
    with pytest.raises(InvalidConfigError, match="seed"):
        run_episode(MAP, "pursuer/greedy", "evader/random", -1)
    with pytest.raises(InvalidConfigError, match="bogus"):
        run_episode(MAP, "pursuer/greedy", "evader/random", 0, overrides={"bogus": 1})
    with pytest.raises(InvalidPlacementError):
        run_episode(
            MAP, "pursuer/greedy", "evader/random", 0, start={"pursuer": (0, 0), "evader": (0, 0)}
        )
    given = {"pursuer": (3.0, 5.0), "evader": (5.5, 5.0)}
    r = run_episode(MAP, "pursuer/greedy", "evader/random", 0, start=given, max_cycles=3)
    assert r.start_kind == "given" and r.start["pursuer"] == [3.0, 5.0]


@pytest.mark.parametrize(
    ("bad", "message"),
    [
        ({"observations": [1]}, r"^observations = \[1\]: expected a mapping such as \{'pursuer'"),
        ({"observations": "state"}, r"^observations = 'state': expected a mapping"),
        ({"overrides": "abc"}, r"^overrides = 'abc': expected a mapping such as \{'v_evader'"),
        ({"overrides": [("l_min", 2.0)]}, r"^overrides = \[\('l_min', 2.0\)\]: expected a mapping"),
    ],
)
def test_overrides_and_observations_that_are_no_mapping_are_refused_by_name(bad, message):
    # observations=[1] was dict()'s TypeError 'cannot convert dictionary update sequence
    # element #0 to a sequence', overrides='abc' its ValueError '... has length 1; 2 is
    # required', neither naming the argument
    with pytest.raises(InvalidConfigError, match=message):
        run_episode(MAP, "pursuer/greedy", "evader/random", 0, max_cycles=3, **bad)


@pytest.mark.parametrize("limit", [-1.0, 0.0, float("nan"), "5", True])
def test_a_bad_time_limit_is_refused_not_blamed_on_a_policy(limit):
    # time_limit = -1 (or 0) made the pursuer forfeit at step 1 with EpisodeTimeout
    # ("episode exceeded its time limit of -1 s"); nan silently set no limit
    with pytest.raises(InvalidConfigError, match=r"time_limit = .*expected a finite number > 0"):
        run_episode(MAP, "pursuer/greedy", "evader/straight", seed=0, max_cycles=5,
                    time_limit=limit)  # fmt: skip


def test_a_transformed_built_in_plays_at_its_scaled_recommendations():
    """``run_episode("corridor~x10rot0.3", ...)``: the env plays the rotated corridor at ten
    times the corridor's L_min, L_max and speeds (its recommendation scaled with it), as
    the env built from the name does; a user's overrides still win."""
    from envs.surveillance.config import EnvConfig
    from strategies.runner import map_parameters

    world, params = map_parameters("corridor~x10rot0.3")
    assert params == {
        "l_min": 20.0, "l_max": 40.0, "v_pursuer": 10.0, "v_evader": 5.0, "body_radius": 1.0
    }  # fmt: skip
    assert world.digest == EnvConfig(map="corridor~x10rot0.3").map.digest
    assert EnvConfig(map="corridor~x10rot0.3").body_radius == 1.0
    assert EnvConfig(map="corridor").body_radius == EnvConfig(map=world).body_radius == 0.1
    r = run_episode("corridor~x10rot0.3", "pursuer/greedy", "evader/random", 0, max_cycles=5)
    assert (r.config.l_min, r.config.l_max, r.config.v_pursuer) == (20.0, 40.0, 10.0)
    assert r.config.body_radius == 1.0
    r = run_episode("corridor~x10", "pursuer/greedy", "evader/random", 0, max_cycles=5,
                    overrides={"l_min": 15.0})  # fmt: skip
    assert (r.config.l_min, r.config.l_max) == (15.0, 40.0)


def test_a_model_given_observations_of_another_shape_is_refused_before_it_loads(tmp_path):
    # A lidar_track model copied without its provenance.json (the registry's
    # pursuer/sb3:PATH, surveil play, zoo evaluate, a training opponent) was given the
    # env's state and failed its first act(), a forfeit: "failed at step 0:
    # InvalidObservationError: ... observation of shape (13,), but the model was trained
    # on shape (40,)". The zip records its input shape: refused as it is reset, unloaded.
    import shutil

    from strategies.policies import make_policy
    from strategies.policies.model_files import zoo_dir

    bare = tmp_path / "g.zip"
    shutil.copy(zoo_dir() / "dagger_pursuer_generalist" / "model.zip", bare)
    pol = make_policy(f"pursuer/sb3:{bare}")
    state = (r"^pursuer/sb3:.*g\.zip: model .*g\.zip takes observations of shape \(40,\), "
             r"but the game's observation 'state' has shape \(13,\): it would fail its "
             "first step")  # fmt: skip
    with pytest.raises(InvalidConfigError, match=state):
        run_episode(MAP, pol, "evader/straight", 0, max_cycles=3)
    assert pol.model is None  # refused before torch and the model were loaded
    rays16 = {"observation": "lidar_track", "n_rays": 16}
    with pytest.raises(InvalidConfigError, match=r"'lidar_track' with n_rays = 16 has shape "
                       r"\(24,\)"):  # fmt: skip
        run_episode(MAP, pol, "evader/straight", 0, max_cycles=3, overrides=rays16)
    trained = {"observation": "lidar_track", "n_rays": 32}  # what it was trained on: plays
    r = run_episode(MAP, pol, "evader/straight", 0, max_cycles=3, overrides=trained)
    assert r.steps == 3 and r.observations["pursuer"]["n_rays"] == 32


def test_shipped_and_saved_models_play_by_the_names_surveil_play_takes(tmp_path):
    # run_episode("corridor", "zoo:NAME", ...) said "pursuer: expected a 'pursuer/KIND'
    # policy name, got 'zoo:dagger_pursuer_generalist'" while surveil play, evaluate,
    # tournaments and training opponents all take zoo:NAME and model .zip paths
    import shutil
    import warnings

    from strategies.policies.model_files import zoo_dir

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the models' unseen map/parameter warnings
        r = run_episode(MAP, "zoo:dagger_pursuer_generalist", "zoo:dagger_evader_memory", 0,
                        max_cycles=3)  # fmt: skip
        assert (r.pursuer, r.evader, r.steps) == ("zoo:dagger_pursuer_generalist",
                                                  "zoo:dagger_evader_memory", 3)  # fmt: skip
        assert r.observations["pursuer"]["observation"] == "lidar_track"  # its provenance's
        saved = tmp_path / "m" / "model.zip"
        saved.parent.mkdir()
        src = zoo_dir() / "ppo_evader_vs_greedy_open_room"
        shutil.copy(src / "model.zip", saved)
        shutil.copy(src / "provenance.json", saved.parent / "provenance.json")
        again = run_episode(MAP, "pursuer/greedy", str(saved), 0, max_cycles=3)
        named = run_episode(MAP, "pursuer/greedy", "zoo:ppo_evader_vs_greedy_open_room", 0,
                            max_cycles=3)  # fmt: skip
    assert again.evader == str(saved)
    assert again.trajectory.tobytes() == named.trajectory.tobytes()  # the same model
    with pytest.raises(InvalidConfigError, match=r"^evader: model = 'zoo:dagger_pursuer_generalist'"
                       r": this model was trained as the pursuer"):  # fmt: skip
        run_episode(MAP, "pursuer/greedy", "zoo:dagger_pursuer_generalist", 0, max_cycles=3)
    with pytest.raises(InvalidConfigError, match=r"^pursuer: model = 'zoo:nope': no zoo model"):
        run_episode(MAP, "zoo:nope", "evader/straight", 0, max_cycles=3)


def test_a_models_input_shape_is_read_once_not_at_every_reset(tmp_path):
    # f626799's check read the zip's data entry at every reset (0.56 ms at load 13, on the
    # clock), and so a loaded model whose file was then rewritten failed its next reset
    import shutil

    from strategies.policies import make_policy
    from strategies.policies.model_files import zoo_dir

    path = tmp_path / "c.zip"
    shutil.copy(zoo_dir() / "dagger_pursuer_corridor" / "model.zip", path)
    pol = make_policy(f"pursuer/sb3:{path}")
    run_episode(MAP, pol, "evader/straight", 0, max_cycles=2)
    path.write_bytes(b"rewritten")  # the model is in memory: it plays on
    assert run_episode(MAP, pol, "evader/straight", 1, max_cycles=2).steps == 2
