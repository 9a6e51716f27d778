"""Policy parameters follow the one rule of envs.validation, at make_policy and in the classes."""

from __future__ import annotations

import math

import numpy as np
import pytest

from envs.errors import InvalidConfigError, InvalidObservationError
from strategies.policies import make_policy, policy_names
from strategies.policies.baselines import GreedyPursuer, RandomPolicy
from strategies.policies.registry import policy_spec
from tests.strategies.policies.conftest import state_observations

ALL = policy_names()


def _typed_params(kind: type) -> list[tuple[str, str]]:
    return [
        (name, key)
        for name in ALL
        for key, (declared, _) in policy_spec(name).types.items()
        if declared is kind
    ]


@pytest.mark.parametrize(("name", "key"), _typed_params(float) + _typed_params(int))
@pytest.mark.parametrize("bad", [True, "1", "no", [1], math.nan])
def test_numeric_parameters_refuse_bools_strings_and_nan(name, key, bad) -> None:
    with pytest.raises(InvalidConfigError, match=rf"policy '{name}': {key} = "):
        make_policy(name, **{key: bad})


@pytest.mark.parametrize(("name", "key"), _typed_params(int))
def test_integer_parameters_refuse_floats(name, key) -> None:
    with pytest.raises(InvalidConfigError, match=rf"{key} = 4.0: expected an integer"):
        make_policy(name, **{key: 4.0})


def test_every_parameter_of_every_policy_has_a_checkable_type() -> None:
    """A new policy parameter without a type annotation would escape the checks."""
    for name in ALL:
        for key, (declared, _) in policy_spec(name).types.items():
            assert declared in (bool, int, float, str), (name, key)


def test_switches_are_booleans_only() -> None:
    with pytest.raises(InvalidConfigError, match=r"shoot = 'no': expected true or false"):
        make_policy("evader/shooting", shoot="no")
    with pytest.raises(InvalidConfigError, match=r"shoot = 1: expected true or false"):
        make_policy("evader/shooting", shoot=1)
    assert make_policy("evader/shooting", shoot=np.bool_(False)).shoot is False


def test_none_only_where_the_signature_allows_it() -> None:
    with pytest.raises(InvalidConfigError, match=r"gain = None: expected a finite number"):
        make_policy("pursuer/greedy", gain=None)
    assert make_policy("evader/straight", heading=None).heading is None


@pytest.mark.parametrize(
    ("name", "params", "pattern"),
    [
        ("pursuer/decomposition", {"n_bins": True}, r"n_bins = True: expected an integer"),
        ("pursuer/decomposition", {"rays": 1e9}, r"rays = 1000000000.0: expected an integer"),
        ("pursuer/decomposition", {"rays": 10**9}, r"rays = 1000000000: expected an integer in"),
        ("evader/shooting", {"rays": 10**9}, r"rays = 1000000000: expected an integer in"),
        ("pursuer/decomposition", {"n_bins": 300}, r"n_bins = 300: expected an integer in \[8,"),
        ("evader/shooting", {"probe_every": 0}, r"probe_every = 0: expected an integer in"),
        ("pursuer/greedy", {"target": 1.0}, r"target = 1.0: expected a number in \[0, 1\)"),
        ("evader/toward_away", {"mode": "sideways"}, r"mode = 'sideways': expected one of"),
        ("pursuer/tractrix", {"gain": -1}, r"gain = -1: expected a finite number >= 0"),
    ],
)
def test_ranges_are_checked_before_anything_is_allocated(name, params, pattern) -> None:
    with pytest.raises(InvalidConfigError, match=pattern):
        make_policy(name, **params)


def test_direct_construction_uses_the_same_rule() -> None:
    with pytest.raises(InvalidConfigError, match=r"gain = True"):
        GreedyPursuer(gain=True)
    with pytest.raises(InvalidConfigError, match=r"hold = '3'"):
        RandomPolicy(hold="3")


@pytest.mark.parametrize("bad", [None, 3, b"pursuer/greedy", ""])
def test_make_policy_needs_a_name(bad) -> None:
    with pytest.raises(InvalidConfigError, match="policy name = "):
        make_policy(bad)


@pytest.mark.parametrize("name", ["pursuer/greedy", "evader/straight", "pursuer/decomposition"])
def test_a_bad_observation_is_an_observation_error(name, box_config) -> None:
    pol = make_policy(name)
    pol.reset(role=name.split("/")[0], map=box_config.map, config=box_config, seed=0)
    obs = state_observations(box_config)[0].copy()
    obs[3] = np.nan
    with pytest.raises(
        InvalidObservationError, match=r"expected finite values, got nan at index 3"
    ):
        pol.act(obs)
    with pytest.raises(InvalidObservationError, match=r"shape"):
        pol.act(np.zeros(5))
    with pytest.raises(InvalidObservationError, match="real numbers"):
        pol.act(["a"] * obs.size)


@pytest.mark.parametrize("name", ["pursuer/decomposition", "evader/shooting"])
@pytest.mark.parametrize(
    ("resolution", "pattern"),
    [
        # no grid node in the free region: numpy's IndexError at reset
        (8.0, r"resolution = 8 leaves no node of its 1 x 1 grid inside the free region"),
        # free area / res**2 overflowed: OverflowError at reset
        (1e155, r"resolution = 1e\+155 leaves no node of its 1 x 1 grid"),
        # res**2 underflowed to 0: ZeroDivisionError; then inf memory estimates overflowed
        (
            1e-300,
            r"resolution = 1e-300: expected a grid spacing no finer than the map's "
            r"length tolerance 1.98e-08",
        ),
        (5e-324, r"resolution = 4.94066e-324: expected a grid spacing no finer than"),
    ],
)
def test_a_table_resolution_no_grid_can_have_is_refused_naming_it(name, resolution, pattern):
    """The decomposition pursuer's and shooting evader's ``resolution`` (their safety
    table's grid spacing) at 8, 1e155 or 1e-300 on the corner world failed at reset with
    a bare IndexError / OverflowError / ZeroDivisionError (a PolicyFailure of the run)."""
    from envs.surveillance.config import EnvConfig

    cfg = EnvConfig(map="corner")
    policy = make_policy(name, resolution=resolution)
    with pytest.raises(InvalidConfigError, match=pattern):
        policy.reset(role=name.split("/")[0], map=cfg.map, config=cfg, seed=0)
