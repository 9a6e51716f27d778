"""Hostile input to reset/step raises project errors naming the value."""

from __future__ import annotations

import numpy as np
import pytest

from envs import surveillance_v1
from envs.errors import (
    EpisodeStateError,
    InfeasibleError,
    InvalidActionError,
    InvalidConfigError,
    InvalidPlacementError,
    UnknownNameError,
    UnknownOptionWarning,
)
from envs.surveillance_v1 import parallel_env


@pytest.fixture
def env():
    e = parallel_env()
    e.reset(seed=0)
    return e


@pytest.mark.parametrize("seed", ["x", -1, 1.5, True])
def test_reset_rejects_bad_seeds(seed):
    with pytest.raises(InvalidConfigError, match="seed"):
        parallel_env().reset(seed=seed)


def test_numpy_integer_seed_equals_python_seed():
    a, _ = parallel_env().reset(seed=np.int64(7))
    b, _ = parallel_env().reset(seed=7)
    assert all(np.array_equal(a[k], b[k]) for k in a)


@pytest.mark.parametrize("options", [[1, 2], "pursuer", (("pursuer", (1, 1)),)])
def test_reset_rejects_options_that_are_not_a_dict(env, options):
    with pytest.raises(InvalidPlacementError, match="options"):
        env.reset(options=options)


@pytest.mark.parametrize(
    ("options", "meant"),
    [
        ({"pursuer_0": (1.0, 1.0), "evader_0": (2.0, 2.0)}, ["pursuer", "evader"]),
        ({"persuer": (1.0, 1.0)}, ["pursuer"]),
        ({"Evader": (1.0, 1.0)}, ["evader"]),
    ],
)
def test_a_misspelt_placement_warns_naming_the_key_it_resembles(env, options, meant):
    # it was ignored without a word, and the start drawn at random
    want = [
        f"reset: options key {key!r} is not read by the env (its keys are ['pursuer', "
        f"'evader']; other keys are left to wrappers): did you mean {m!r}? The start is "
        "drawn at random."
        for key, m in zip(options, meant, strict=True)
    ]
    for reset in (env.reset, surveillance_v1.env().reset):  # the AEC conversion too
        with pytest.warns(UnknownOptionWarning) as caught:
            reset(seed=0, options=options)
        assert [str(w.message) for w in caught] == want


def test_options_the_env_does_not_read_are_left_to_wrappers_without_a_word(env):
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        # pettingzoo.test's api_test and parallel_api_test reset with these options
        env.reset(seed=0, options={"options": 1})
        env.reset(seed=0, options={"curriculum_level": 2, 3: "x", "start": "safe"})
        p, e = env._pursuer, env._evader
        env.reset(seed=0, options={"pursuer": p, "evader": e, "wrapper_flag": True})
    assert (env._pursuer, env._evader) == (p, e)


def test_reset_rejects_boolean_or_string_positions(env):
    p, e = env._pursuer, env._evader
    env.reset(options={"pursuer": np.array(p, dtype=np.float32).astype(float), "evader": list(e)})
    for bad in [(True, False), ("1", "2"), np.array(["1", "2"])]:
        with pytest.raises(InvalidPlacementError, match="pursuer"):
            env.reset(options={"pursuer": bad, "evader": e})


@pytest.mark.parametrize("actions", [None, [0.0, 0.0], 3])
def test_step_rejects_actions_that_are_not_a_dict(env, actions):
    with pytest.raises(InvalidActionError, match="dict"):
        env.step(actions)


@pytest.mark.parametrize(
    "action",
    [
        np.array([True, False]),
        ["0.1", "0.2"],
        [1 + 1j, 0.0],
        # a bool beside a number: numpy read it as 1.0 and the step went on (helper-123's probe)
        (True, 0.0),
        [0.5, np.bool_(False)],
    ],
)
def test_step_rejects_non_real_actions(env, action):
    with pytest.raises(InvalidActionError, match="pursuer_0"):
        env.step({"pursuer_0": action, "evader_0": [0.0, 0.0]})


@pytest.mark.parametrize(
    "action",
    [[10**400, 0], np.array([[True] * 50] * 50), ["x" * 1000, "y"]],
    ids=["huge-int", "bool-array", "long-strings"],
)
def test_a_refused_action_is_shown_on_one_short_line(env, action):
    # the message held the action's whole repr (400 digits; a numpy array over many lines)
    with pytest.raises(InvalidActionError, match="pursuer_0") as info:
        env.step({"pursuer_0": action, "evader_0": [0.0, 0.0]})
    assert "\n" not in str(info.value) and len(str(info.value)) < 200


def test_integer_and_list_actions_are_accepted(env):
    env.step({"pursuer_0": np.array([1, 0]), "evader_0": [0, 0]})
    assert env._step == 1


@pytest.mark.parametrize("make", [surveillance_v1.parallel_env, surveillance_v1.env])
@pytest.mark.parametrize("space", ["observation_space", "action_space"])
def test_an_unknown_agent_is_a_project_error_naming_it(make, space):
    # was a bare KeyError('pursuer'); UnknownNameError is still a KeyError
    e = make()
    with pytest.raises(UnknownNameError, match=r"agent = 'pursuer': expected one of \['pursuer_0'"):
        getattr(e, space)("pursuer")
    with pytest.raises(KeyError):
        getattr(e, space)(["pursuer_0"])
    e.close()


def test_the_aec_env_observing_an_unknown_agent_is_a_project_error_naming_it():
    e = surveillance_v1.env(map="corner")
    e.reset(seed=0)
    with pytest.raises(UnknownNameError, match=r"agent = 'nobody': expected one of \['pursuer_0'"):
        e.observe("nobody")
    assert e.observe("evader_0").shape == e.observation_space("evader_0").shape
    e.close()


def test_an_action_for_an_unknown_agent_is_refused_naming_it(env):
    """A misspelt agent's action was ignored silently (the episode went on without it)."""
    actions = {"pursuer_0": [1.0, 0.0], "evader_0": [0.0, 0.0], "pursuer_1": [0.0, 1.0]}
    with pytest.raises(UnknownNameError, match=r"unknown agent\(s\) \['pursuer_1'\]"):
        env.step(actions)
    assert env._step == 0  # refused before anything moved


@pytest.mark.parametrize("make", [surveillance_v1.env, surveillance_v1.raw_env])
def test_the_aec_env_refuses_a_bad_action_on_its_own_turn_and_goes_on(make):
    """The AEC conversion buffered the pursuer's NaN until the evader's turn, refused it
    there, and kept it: every later step raised the same error until a reset."""
    e, ref = make(map="corner"), make(map="corner")
    e.reset(seed=0)
    ref.reset(seed=0)
    with pytest.raises(InvalidActionError, match=r"pursuer_0: action must be finite"):
        e.step(np.array([np.nan, 0.0]))
    assert e.agent_selection == "pursuer_0"  # the turn is still the pursuer's
    for env_ in (e, ref):  # the same cycle, played after the refusal and without it
        env_.step(np.array([0.5, 0.0], dtype=np.float32))
        env_.step(np.array([0.0, 0.5], dtype=np.float32))
    np.testing.assert_array_equal(e.observe("pursuer_0"), ref.observe("pursuer_0"))
    assert e.infos == ref.infos
    e.close()
    ref.close()


@pytest.mark.parametrize("call", ["step", "observe", "render", "state", "agent_iter"])
def test_the_aec_env_before_reset_is_an_episode_state_error(call):
    """PettingZoo's order wrapper raised a bare AssertionError here (none under -O)."""
    e = surveillance_v1.env(map="corner", render_mode="rgb_array")
    args = {"step": (np.zeros(2),), "observe": ("pursuer_0",)}.get(call, ())
    with pytest.raises(EpisodeStateError, match=rf"{call}\(\) before reset\(\)"):
        getattr(e, call)(*args)
    e.reset(seed=0)
    e.observe("pursuer_0")
    e.step(np.zeros(2))
    e.close()


@pytest.mark.parametrize(
    ("over", "name"),
    [
        ({"dt": 1e-310}, "v_pursuer"),  # 1 / dt overflowed: NaN velocities from step 1
        ({"dt": 5e-324}, "v_pursuer"),  # V dt underflowed: the shooting evader's reset / 0
        ({"v_evader": 1e-300}, "v_evader"),  # the evader could not move at all
        ({"map": "corridor~off(1e6,0)", "dt": 1e-12}, "v_pursuer"),  # rounding 2.2e-10 there
    ],
)
def test_a_step_that_moves_no_body_is_refused(over, name):
    with pytest.raises(InvalidConfigError, match=rf"with {name} = .* would not move a body"):
        parallel_env(**over)


def test_small_steps_and_speeds_that_move_a_body_still_play():
    from strategies.runner import run_episode

    for over in ({"dt": 1e-9}, {"v_evader": 1e-12}, {"dt": 1e-5, "v_pursuer": 1e-6}):
        result = run_episode(
            "corridor", "pursuer/greedy", "evader/shooting", 0, max_cycles=5, overrides=over
        )
        assert result.steps == 5, over


def _next_episode(env) -> dict:
    obs, _ = env.reset()
    return obs


@pytest.mark.parametrize(
    "options",
    [
        {"pursuer": (1e9, 0.0), "evader": (1.0, 1.0)},  # outside the map
        {"pursuer": (True, 1.0), "evader": (1.0, 1.0)},
        [("pursuer", (1.0, 1.0))],  # not a dict
    ],
)
def test_a_refused_reset_leaves_the_env_as_it_was(env, options):
    """reset(seed=7, options=bad) reseeded the generator before refusing the options, so
    the next reset() played seed 7's stream instead of the one under way."""
    untouched = parallel_env()
    untouched.reset(seed=0)
    with pytest.raises(InvalidPlacementError):
        env.reset(seed=7, options=options)
    a, b = _next_episode(env), _next_episode(untouched)
    assert all(np.array_equal(a[k], b[k]) for k in a)


def test_a_random_start_that_finds_nothing_draws_nothing():
    """The maze at dt = 2 rules every proposal out (rod clearance 6): the refused reset
    used to leave the generator advanced by its 25,600 proposals."""
    env = parallel_env(map="maze", dt=2.0)
    before = env.np_random.bit_generator.state
    with pytest.raises(InfeasibleError, match="no valid surveillance configuration"):
        env.reset()
    assert env.np_random.bit_generator.state == before
