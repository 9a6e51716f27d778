"""TrainConfig: TOML loading, round trips, and errors that name the bad field."""

from __future__ import annotations

from pathlib import Path

import pytest

from envs.errors import InvalidConfigError
from training.config import TrainConfig, load_config

CONFIGS = sorted((Path(__file__).resolve().parents[2] / "training" / "configs").glob("*.toml"))


def test_example_configs_exist():
    names = {p.stem for p in CONFIGS}
    assert {"ppo_pursuer_vs_straight_corridor", "ppo_evader_vs_greedy_open_room"} <= names


@pytest.mark.parametrize("path", CONFIGS, ids=lambda p: p.stem)
def test_example_configs_load_and_round_trip(path, tmp_path):
    from training.config import load_any_config

    config = load_any_config(path)
    out = tmp_path / "again.toml"
    out.write_text(config.to_toml())
    assert load_any_config(out) == config
    assert type(config).from_dict(config.to_dict()) == config


def test_a_pool_of_opponents_round_trips_and_is_checked(tmp_path):
    cfg = TrainConfig(role="pursuer", opponent=("evader/straight", "evader/shooting"),
                      opponent_weights=(3.0, 1.0))  # fmt: skip
    out = tmp_path / "pool.toml"
    out.write_text(cfg.to_toml())
    assert load_config(out) == cfg
    pool = cfg.opponent_policy()
    assert pool.probabilities == pytest.approx((0.75, 0.25))
    assert cfg.opponent_policy() is not pool  # one per env: their policies keep state
    with pytest.raises(InvalidConfigError, match="pursuer/greedy"):
        TrainConfig(role="pursuer", opponent=("evader/straight", "pursuer/greedy"))
    with pytest.raises(InvalidConfigError, match="opponent pool"):
        TrainConfig(role="pursuer", opponent=("evader/straight",), opponent_weights=(1.0, 2.0))
    # 'a evader learner needs an 'pursuer/KIND' policy' was the message
    want = (r"^opponent: an evader learner needs a 'pursuer/KIND' policy "
            r"\(a model: 'zoo:NAME' or a .zip path\), got 'evader/straight'$")  # fmt: skip
    with pytest.raises(InvalidConfigError, match=want):
        TrainConfig(role="evader", opponent="evader/straight")


def test_overrides_and_defaults(tmp_path):
    p = tmp_path / "c.toml"
    p.write_text('role = "evader"\nopponent = "pursuer/greedy"\n[env]\nmax_cycles = 77\n')
    config = load_config(p, seed=5, total_timesteps=1000)
    assert (config.seed, config.total_timesteps, config.env) == (5, 1000, {"max_cycles": 77})
    assert config.net_arch == (64, 64) and config.algo == "ppo"
    assert config.env_kwargs() == {"map": "open_room", "start": "env", "max_cycles": 77}


BASE = {"role": "pursuer", "opponent": "evader/straight"}


@pytest.mark.parametrize(
    ("changes", "field"),
    [
        ({"role": "bishop"}, "role"),
        ({"opponent": "pursuer/greedy"}, "opponent"),
        ({"algo": "dqn"}, "algo"),
        ({"total_timesteps": 0}, "total_timesteps"),
        ({"total_timesteps": 1.5}, "total_timesteps"),
        ({"seed": -1}, "seed"),
        ({"n_envs": True}, "n_envs"),
        ({"learning_rate": -1e-3}, "learning_rate"),
        ({"gamma": 1.5}, "gamma"),
        ({"net_arch": [64, 0]}, r"net_arch\[1\]"),
        ({"net_arch": "64"}, "net_arch"),
        ({"env": {"max_cycles": 0}}, "env.max_cycles"),
        ({"env": {"l_min": 5.0}}, "env.l_max"),
        ({"env": {"map": "corridor"}}, "env"),
        ({"env": {"speed": 2}}, "speed"),
        ({"algo_kwargs": {"n_epoch": 3}}, "n_epoch"),
        ({"algo_kwargs": {"seed": 3}}, "seed"),
        ({"algo": "sac", "algo_kwargs": {"n_epochs": 3}}, "n_epochs"),
        ({"start": "far"}, "start"),
        ({"eval_episodes": -2}, "eval_episodes"),
        ({"map": "atlantis"}, "map"),
        ({"map": ""}, "map"),
    ],
)
def test_bad_values_name_the_field(changes, field):
    with pytest.raises(InvalidConfigError, match=field):
        TrainConfig(**{**BASE, **changes})


def test_bad_files(tmp_path):
    with pytest.raises(InvalidConfigError, match="no such file"):
        load_config(tmp_path / "missing.toml")
    # a directory was a bare IsADirectoryError ('surveil: error: /etc: Is a directory')
    with pytest.raises(InvalidConfigError, match=r"config: '.*' is a directory, expected a TOML"):
        load_config(tmp_path)
    bad = tmp_path / "bad.toml"
    bad.write_text("role = \n")
    with pytest.raises(InvalidConfigError, match="not valid TOML"):
        load_config(bad)
    unknown = tmp_path / "unknown.toml"
    unknown.write_text('role = "pursuer"\nopponent = "evader/straight"\ntimesteps = 5\n')
    with pytest.raises(InvalidConfigError, match="timesteps"):
        load_config(unknown)
    missing = tmp_path / "missing_role.toml"
    missing.write_text('opponent = "evader/straight"\n')
    with pytest.raises(InvalidConfigError, match="role"):
        load_config(missing)


def test_every_field_has_a_docstring():
    import inspect

    import training.config as module

    src = inspect.getsource(module.TrainConfig)
    for name in TrainConfig.__dataclass_fields__:
        after = src.split(f"\n    {name}:", 1)[1].split("\n", 2)[1].strip()
        assert after.startswith('"""'), name


@pytest.mark.parametrize(
    ("env", "category"),
    [
        ({"l_min": 2.0, "l_max": 2.05}, "NarrowBandWarning"),
        ({"v_evader": 1.5}, "RhoAboveOneWarning"),
    ],
)
def test_a_legal_env_s_warning_comes_after_every_field_passed(env, category):
    """The [env] table is checked midway: its warning (a narrow band, rho > 1) came before
    a later field's refusal (algo = 'nope'), as one more thing to fix; now a refused config
    says its error alone and an accepted one still warns, once."""
    import warnings

    from envs import errors

    warning = getattr(errors, category)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with pytest.raises(InvalidConfigError, match=r"algo = 'nope': expected"):
            TrainConfig(role="pursuer", opponent="evader/straight", env=env, algo="nope")
    assert not [w for w in caught if issubclass(w.category, warning)]
    with pytest.warns(warning) as said:
        TrainConfig(role="pursuer", opponent="evader/straight", env=env)
    assert len([w for w in said if issubclass(w.category, warning)]) == 1
