"""Every registered policy honours the protocol: shapes, bounds, seeding, predict()."""

from __future__ import annotations

import numpy as np
import pytest

from envs.errors import InvalidConfigError, UnknownNameError
from strategies.policies import Policy, describe_policy, make_policy, policy_names
from strategies.policies.base import BasePolicy
from tests.strategies.policies.conftest import state_observations

ALL = policy_names()


def _run(name: str, config, seed: int, observations) -> np.ndarray:
    pol = make_policy(name)
    role = name.split("/")[0]
    pol.reset(role=role, map=config.map, config=config, seed=seed)
    return np.stack([pol.act(o) for o in observations])


@pytest.mark.parametrize("name", ALL)
def test_actions_have_the_right_shape_dtype_and_bounds(name, box_config):
    obs = state_observations(box_config)
    acts = _run(name, box_config, 3, obs)
    assert acts.shape == (len(obs), 2)
    assert acts.dtype == np.float32
    assert np.all(np.isfinite(acts))
    assert np.all(np.abs(acts) <= 1.0)
    assert np.all(np.linalg.norm(acts, axis=1) <= 1.0 + 1e-6)  # never above the speed bound


@pytest.mark.parametrize("name", ALL)
def test_same_seed_same_actions_bit_for_bit(name, box_config):
    obs = state_observations(box_config, seed=5)
    a = _run(name, box_config, 11, obs)
    b = _run(name, box_config, 11, obs)
    assert a.tobytes() == b.tobytes()


@pytest.mark.parametrize("name", ALL)
def test_predict_matches_act_single_and_batched(name, box_config):
    obs = state_observations(box_config, seed=2)
    role = name.split("/")[0]
    acting, predicting, batched = make_policy(name), make_policy(name), make_policy(name)
    for p in (acting, predicting, batched):
        p.reset(role=role, map=box_config.map, config=box_config, seed=7)
        assert isinstance(p, Policy)
    for o in obs:
        a = acting.act(o)
        b, state = predicting.predict(o, state=None, episode_start=None, deterministic=True)
        assert state is None
        assert a.tobytes() == np.asarray(b).tobytes()
    c, _ = batched.predict(np.stack(obs))
    assert c.shape == (len(obs), 2)
    ref = _run(name, box_config, 7, obs)
    assert c.tobytes() == ref.tobytes()


def test_random_policy_seeds_differ(box_config):
    obs = state_observations(box_config)
    assert (
        _run("evader/random", box_config, 1, obs).tobytes()
        != _run("evader/random", box_config, 2, obs).tobytes()
    )


def test_unknown_name_lists_the_known_ones():
    with pytest.raises(UnknownNameError, match="pursuer/greedy"):
        make_policy("pursuer/no_such_policy")
    with pytest.raises(UnknownNameError):
        make_policy("nonsense")


def test_bad_parameters_and_roles_raise(box_config):
    with pytest.raises(InvalidConfigError, match="no parameter"):
        make_policy("pursuer/greedy", speed=3)
    with pytest.raises(InvalidConfigError, match="mode"):
        make_policy("evader/toward_away", mode="sideways")
    pol = make_policy("pursuer/greedy")
    with pytest.raises(InvalidConfigError, match="cannot play"):
        pol.reset(role="evader", map=box_config.map, config=box_config, seed=0)
    with pytest.raises(InvalidConfigError, match="role"):
        pol.reset(role="referee", map=box_config.map, config=box_config, seed=0)
    with pytest.raises(InvalidConfigError, match="reset"):
        make_policy("pursuer/greedy").act(state_observations(box_config)[0])


@pytest.mark.parametrize("name", ALL)
@pytest.mark.parametrize(
    ("bad", "message"),
    [
        ({"seed": -5}, r"reset: seed = -5: expected an integer >= 0"),
        ({"seed": 1.5}, r"reset: seed = 1.5: expected an integer >= 0"),
        ({"map": None}, r"reset: map = None: expected the env's Map"),
        ({"config": None}, r"reset: config = None: expected the env's EnvConfig"),
        ({"config": {"l_min": 2.0}}, r"reset: config = \{'l_min': 2.0\}: expected the env's"),
    ],
)
def test_a_reset_with_a_bad_seed_map_or_config_is_refused_by_name(name, bad, message, box_config):
    # seed -5 was numpy's 'expected non-negative integer' (no argument named); map=None
    # and config=None an AttributeError deep in a policy's set-up (edge_ring, l_min...)
    pol = make_policy(name)
    args = {"role": name.split("/")[0], "map": box_config.map, "config": box_config, "seed": 0}
    with pytest.raises(InvalidConfigError, match=message):
        pol.reset(**{**args, **bad})
    with pytest.raises(InvalidConfigError, match=r"call reset\(\) before act\(\)"):
        pol.act(state_observations(box_config)[0])


def test_a_failed_reset_leaves_the_policy_asking_for_a_reset(box_config, tmp_path):
    # the set-up raised after the role was taken: act() then played on a half-built
    # policy (an SB3 policy without its model: AttributeError 'NoneType' object has no
    # attribute 'observation_space')
    obs = state_observations(box_config)[0]
    pol = make_policy(f"pursuer/sb3:{tmp_path / 'missing.zip'}")
    with pytest.raises(InvalidConfigError, match="no model file"):
        pol.reset(role="pursuer", map=box_config.map, config=box_config, seed=0)
    with pytest.raises(InvalidConfigError, match=r"call reset\(\) before act\(\)"):
        pol.act(obs)
    greedy = make_policy("pursuer/greedy")
    greedy.reset(role="pursuer", map=box_config.map, config=box_config, seed=0)
    greedy.act(obs)
    with pytest.raises(InvalidConfigError, match="seed"):  # a refused reset of a played one
        greedy.reset(role="pursuer", map=box_config.map, config=box_config, seed=-1)
    assert np.all(np.isfinite(greedy.act(obs)))  # refused before anything changed


def test_policy_names_by_role_and_descriptions():
    assert set(policy_names("pursuer")) | set(policy_names("evader")) == set(ALL)
    assert all(n.startswith("pursuer/") for n in policy_names("pursuer"))
    for n in ALL:
        assert describe_policy(n)
    with pytest.raises(InvalidConfigError):
        policy_names("referee")


def test_sb3_name_form_is_lazy_and_checks_the_file(box_config, tmp_path):
    pol = make_policy(f"pursuer/sb3:{tmp_path / 'missing.zip'}")
    assert pol.role is None and pol.model is None
    with pytest.raises(InvalidConfigError, match="no model file"):
        pol.reset(role="pursuer", map=box_config.map, config=box_config, seed=0)


def test_every_policy_class_is_registered_and_exercised():
    # completeness: a policy class added to the package but not to the registry (and so
    # to the parametrised tests above and the theory matchups) fails here
    import inspect

    import strategies.policies.baselines as b
    import strategies.policies.cooperative as c
    import strategies.policies.decomposition as d
    import strategies.policies.shooting as s
    from strategies.policies import BasePolicy, policy_spec

    def home(obj, mod) -> bool:  # defined in the module, or in the package's modules
        return obj.__module__ == mod.__name__ or obj.__module__.startswith(mod.__name__ + ".")

    classes = {
        obj
        for mod in (b, c, d, s)
        for _, obj in inspect.getmembers(mod, inspect.isclass)
        if issubclass(obj, BasePolicy) and obj is not BasePolicy and home(obj, mod)
    }
    assert {cls.__name__ for cls in classes} >= {"DecompositionPursuer", "ShootingEvader"}
    registered = {policy_spec(n).factory for n in ALL}
    assert classes <= registered, classes - registered
    assert {n.split("/")[0] for n in ALL} == {"pursuer", "evader"}


class _UserPolicy(BasePolicy):
    def _decide(self, snap):
        return np.zeros(2)


class _NoName(_UserPolicy):
    def __init__(self):  # forgets name=
        super().__init__()


class _Required(_UserPolicy):
    def __init__(self, gain, *, name=None):
        super().__init__(name=name)


class _NotAPolicy:
    def __init__(self, *, name=None):
        self.name = name


def test_a_factory_make_policy_could_not_call_is_refused_when_registered(monkeypatch):
    # each was registered, then every make_policy(name) raised a bare TypeError (a
    # tournament naming it died with a traceback); a non-str name raised AttributeError
    from strategies.policies import registry

    monkeypatch.setattr(registry, "_REGISTRY", dict(registry._REGISTRY))
    cases = [
        ("evader/u1", lambda: _UserPolicy(), "does not take name="),
        ("evader/u2", _NoName, "does not take name="),
        ("evader/u3", _Required, r"parameter\(s\) \['gain'\] have no default"),
        ("evader/u4", 5, "factory = 5: expected a class or function"),
        (5, _UserPolicy, "policy name = 5: expected a non-empty string"),
    ]
    for name, factory, message in cases:
        with pytest.raises(InvalidConfigError, match=message):
            registry.register_policy(name, factory, "a user's policy")
    registry.register_policy("evader/u5", _NotAPolicy, "a user's non-policy")
    with pytest.raises(InvalidConfigError, match=r"returned _NotAPolicy .* not a policy"):
        make_policy("evader/u5")
    # the documented shapes register and build
    registry.register_policy("evader/u6", _UserPolicy, "a user's policy")
    registry.register_policy("evader/u7", lambda **kw: _UserPolicy(**kw), "a lambda")
    assert make_policy("evader/u6").name == "evader/u6" and make_policy("evader/u7")


def test_the_readmes_own_policy_example_runs(monkeypatch, capsys):
    """README, Policies: the example of a user's policy registers and plays as written."""
    from pathlib import Path

    from strategies.policies import registry

    text = (Path(__file__).parents[3] / "README.md").read_text(encoding="utf-8")
    start = text.index("```python", text.index("Your own policy:")) + len("```python")
    monkeypatch.setattr(registry, "_REGISTRY", dict(registry._REGISTRY))
    exec(compile(text[start : text.index("```", start)], "README.md", "exec"), {})
    assert "corridor: pursuer/decomposition vs evader/away (seed 0)" in capsys.readouterr().out
