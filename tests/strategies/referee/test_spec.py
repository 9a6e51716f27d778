"""GameSpec and Resolution: validation through envs.validation, derived values, keys."""

from __future__ import annotations

import math

import numpy as np
import pytest

from envs.errors import InvalidConfigError
from envs.surveillance.config import EnvConfig
from strategies.referee import GameSpec, Resolution
from tests.strategies.referee.conftest import open_room


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"l_min": True}, "l_min = True"),
        ({"l_min": "1"}, "l_min = '1'"),
        ({"l_min": -1.0}, "l_min = -1.0"),
        ({"l_max": 1.0}, "l_max = 1.0: expected a number > l_min"),
        ({"v_evader": math.nan}, "v_evader = nan"),
        ({"v_pursuer": 0}, "v_pursuer = 0"),
        ({"body_radius": 0.0}, "body_radius = 0.0"),
        # the two bodies overlap at L_min: accepted, and solved, before
        ({"body_radius": 0.5}, r"body_radius = 0.5: expected a value in \(0, l_min / 2 = 0.5\)"),
        ({"body_radius": 0.6}, r"body_radius = 0.6: expected .* overlap at L_min"),
        ({"opponent_clearance": -0.1}, "opponent_clearance = -0.1"),
    ],
)
def test_game_spec_rejects_bad_values_naming_them(kwargs, match):
    base = {"map": open_room(), "l_min": 1.0, "l_max": 2.0}
    with pytest.raises(InvalidConfigError, match=match):
        GameSpec(**{**base, **kwargs})


def test_game_spec_rejects_a_map_name():
    with pytest.raises(InvalidConfigError, match=r"expected an envs\.maps\.Map"):
        GameSpec("open_room", 1.0, 2.0)


def test_game_spec_defaults_and_from_config():
    cfg = EnvConfig(map=open_room(), l_min=1.5, l_max=3.0, v_pursuer=2.0, v_evader=0.5,
                    body_radius=0.2)  # fmt: skip
    spec = GameSpec.from_config(cfg)
    assert (spec.l_min, spec.l_max, spec.v_pursuer, spec.v_evader) == (1.5, 3.0, 2.0, 0.5)
    assert spec.body_radius == 0.2 and spec.opponent_clearance == 0.1
    assert spec.rho == 0.25
    assert spec.margin == pytest.approx(1e-6 * spec.map.scale)
    assert GameSpec.from_config(cfg, v_evader=1.0).rho == 0.5


def test_game_spec_numpy_scalars_are_numbers():
    spec = GameSpec(open_room(), np.float32(1.0), np.int64(2))
    assert isinstance(spec.l_max, float) and spec.l_max == 2.0


def test_keys_are_exact_and_distinguish_parameters():
    a = GameSpec(open_room(), 1.0, 2.0)
    assert a.key() == GameSpec(open_room(), 1.0, 2.0).key()
    assert a.key() != GameSpec(open_room(), 1.0, 2.0 + 1e-15).key()
    assert a.key() != GameSpec(open_room(6.0), 1.0, 2.0).key()
    r = Resolution(0.1, 4, 0.5)
    assert r.key() != Resolution(0.1, 4, 0.5, sweep_pieces=3).key()


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"cell": 0}, "cell = 0"),
        ({"coarse": 2.0}, "coarse = 2.0: expected an integer >= 1"),
        ({"coarse": 0}, "coarse = 0"),
        ({"tau": -1}, "tau = -1"),
        ({"sweep_pieces": True}, "sweep_pieces = True"),
    ],
)
def test_resolution_rejects_bad_values(kwargs, match):
    with pytest.raises(InvalidConfigError, match=match):
        Resolution(**{"cell": 0.1, **kwargs})


def test_for_role_scales_to_the_game_and_rounds_tau_up_to_env_steps():
    spec = GameSpec(open_room(), 2.0, 4.0, 1.0, 0.5)
    rp = Resolution.for_role(spec, "pursuer", 20, coarse=4, steps=2)
    assert rp.cell == pytest.approx(0.1) and rp.spacing == pytest.approx(0.4)
    assert rp.tau == pytest.approx(0.8)  # 2 spacings at V_p = 1
    re = Resolution.for_role(spec, "evader", 20, coarse=4, steps=2)
    assert re.tau == pytest.approx(1.6)  # 2 spacings at V_e = 0.5
    snapped = Resolution.for_role(spec, "pursuer", 20, coarse=4, steps=2, dt=0.3)
    assert snapped.tau == pytest.approx(0.9)  # 0.8 rounded up to 3 steps of 0.3
    with pytest.raises(InvalidConfigError, match="role = 'referee'"):
        Resolution.for_role(spec, "referee")
