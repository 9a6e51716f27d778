"""EnvConfig validation: every bad value raises InvalidConfigError naming it."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from envs import surveillance_v1
from envs.errors import InvalidConfigError, UnknownNameError
from envs.maps import Map
from envs.surveillance.config import EnvConfig
from tests.envs.surveillance._worlds import open_room


@pytest.mark.parametrize(
    ("kwargs", "pattern"),
    [
        ({"l_min": 0.0}, r"^l_min = 0.0: expected a finite number > 0$"),
        ({"l_min": -1}, r"^l_min = -1: expected a finite number > 0$"),
        ({"l_min": math.nan}, r"^l_min = nan: expected a finite number > 0$"),
        ({"l_min": "2"}, r"^l_min = '2': expected a finite number > 0, got str$"),
        ({"l_min": True}, r"^l_min = True: expected a finite number > 0, got bool$"),
        ({"l_max": 1.5}, r"^l_max = 1.5: expected a value > l_min = 2.0$"),
        ({"l_max": math.inf}, r"^l_max = inf: expected a finite number > 0$"),
        ({"v_pursuer": 0}, r"^v_pursuer = 0: expected a finite number > 0$"),
        ({"v_evader": -0.5}, r"^v_evader = -0.5: expected a finite number > 0$"),
        ({"v_evader": [0.5]}, r"^v_evader = \[0.5\]: expected a finite number > 0, got list$"),
        ({"dt": 0.0}, r"^dt = 0.0: expected a finite number > 0$"),
        ({"max_cycles": 0}, r"^max_cycles = 0: expected an integer >= 1$"),
        ({"max_cycles": 10.0}, r"^max_cycles = 10.0: expected an integer >= 1$"),
        ({"max_cycles": True}, r"^max_cycles = True: expected an integer >= 1, got bool$"),
        (
            {"observation": "pixels"},
            r"^observation = 'pixels': expected one of 'state', 'lidar', 'lidar_track'$",
        ),
        ({"n_rays": 0}, r"^n_rays = 0: expected an integer in \[1, 4096\]$"),
        ({"n_rays": 10**9}, r"^n_rays = 1000000000: expected an integer in \[1, 4096\]$"),
        ({"lidar_range": -2.0}, r"^lidar_range = -2.0: expected a finite number > 0$"),
        ({"reward": "dense"}, r"^reward = 'dense': expected one of 'zero_sum', 'sparse'$"),
        (
            {"body_radius": 1.0},
            r"^body_radius = 1.0: expected a value in \(0, l_min / 2 = 1.0\)$",
        ),
        ({"body_radius": 0}, r"^body_radius = 0: expected a finite number > 0$"),
        ({"spawn_margin_steps": -1}, r"^spawn_margin_steps = -1: expected an integer >= 0$"),
        ({"render_mode": "ansi"}, r"^render_mode = 'ansi': expected one of 'human', 'rgb_array'$"),
        ({"map": 42}, r"^map: expected a Map, a built-in map name or a path .* got int 42$"),
    ],
)
def test_bad_values_raise_naming_value_and_range(kwargs: dict, pattern: str) -> None:
    base = {"map": open_room()}
    with pytest.raises(InvalidConfigError, match=pattern):
        EnvConfig(**{**base, **kwargs})
    with pytest.raises(InvalidConfigError, match=pattern):  # the factories validate too
        surveillance_v1.parallel_env(**{**base, **kwargs})


def test_misspelt_option_is_a_type_error() -> None:
    with pytest.raises(TypeError, match="lmin"):
        surveillance_v1.parallel_env(map=open_room(), lmin=2.0)


def test_unknown_map_name_is_named() -> None:
    with pytest.raises(UnknownNameError, match="no_such_world"):
        surveillance_v1.parallel_env(map="no_such_world")


def test_config_is_frozen_and_normalised() -> None:
    cfg = EnvConfig(map="open_room", l_min=1, l_max=np.float32(3.0), max_cycles=np.int64(20))
    assert isinstance(cfg.map, Map) and cfg.map.name == "open_room"
    assert type(cfg.l_min) is float and type(cfg.l_max) is float and type(cfg.max_cycles) is int
    assert cfg.rho == 0.5 and cfg.lidar_max_range == 3.0
    with pytest.raises(dataclasses.FrozenInstanceError):
        cfg.l_min = 2.0  # type: ignore[misc]
    record = cfg.to_dict()
    assert record["map"] == "open_room" and record["map_digest"] == cfg.map.digest
    assert EnvConfig(map=cfg.map, l_min=1.0, l_max=3.0, max_cycles=20) == cfg


def test_map_file_path_is_loaded(tmp_path) -> None:
    from envs.maps.io import save_map

    path = tmp_path / "room.json"
    save_map(open_room(), path)
    env = surveillance_v1.parallel_env(map=str(path))
    assert env.map == open_room()


def test_defaults_match_the_env_card() -> None:
    env = surveillance_v1.parallel_env()
    cfg = env.config
    assert cfg.map.name == "corridor"
    assert (cfg.l_min, cfg.l_max, cfg.v_pursuer, cfg.v_evader) == (2.0, 4.0, 1.0, 0.5)
    assert (cfg.dt, cfg.max_cycles, cfg.observation, cfg.reward) == (0.1, 500, "state", "zero_sum")
    assert env.metadata["render_fps"] == pytest.approx(10.0)
