"""rho > 1 (issue 13): the toward-away evader's ``"away"`` mode flees along the walls and
charges once it cannot flee, instead of pressing into the first wall or corner; at
rho <= 1 it runs straight away as before.

Before the change, at rho 1.1 the away evader escaped 51 of 144 episodes (12 worlds, six
pursuers, safe and valid starts): it stood in a corner with the pursuer 2.25 away to
the horizon (corner, decomposition pursuer, seed 0: still at (13.91, 0.10) from step
120 to 760).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from envs.surveillance.config import EnvConfig
from envs.surveillance.observations import StateEncoder
from strategies.policies import make_policy
from strategies.runner import map_parameters, run_episode

pytestmark = pytest.mark.filterwarnings("ignore::envs.errors.RhoAboveOneWarning")


def horizon_steps(world: str, rho: float, dt: float = 0.1) -> int:
    """Twice the time to cross the range band at the speed surplus plus the world's
    diameter at V_e, in steps (the benchmark's horizon for rho > 1)."""
    m, p = map_parameters(world)
    v_e = rho * p["v_pursuer"]
    seconds = 2.0 * ((p["l_max"] - p["l_min"]) / (v_e - p["v_pursuer"]) + m.diameter / v_e)
    return math.ceil(seconds / dt)


def overrides(world: str, rho: float) -> dict:
    _, p = map_parameters(world)
    return dict(p, v_evader=rho * p["v_pursuer"])


@pytest.mark.parametrize(
    ("world", "pursuer", "start"),
    [
        ("corner", "pursuer/decomposition", "safe"),  # stood in the corner from 12 s
        ("corner", "pursuer/greedy", "valid"),
        ("corridor", "pursuer/tractrix", "safe"),
        ("pillars", "pursuer/corner_rounding", "safe"),
    ],
)
def test_away_escapes_a_slower_pursuer(world, pursuer, start):
    rho = 1.1
    away = make_policy("evader/toward_away", mode="away")
    steps = horizon_steps(world, rho)
    r = run_episode(
        world, pursuer, away, 0, max_cycles=steps, overrides=overrides(world, rho), start=start
    )
    assert r.winner == "evader", r.summary()


def _observation(config: EnvConfig, pursuer, evader) -> np.ndarray:
    enc = StateEncoder(config)
    return enc.encode(tuple(pursuer), (0.0, 0.0), tuple(evader), (0.0, 0.0), True, 0)


def _config(v_evader: float) -> EnvConfig:
    from envs.maps import load_map

    return EnvConfig(
        map=load_map("open_room"), l_min=2.0, l_max=4.0, v_pursuer=1.0, v_evader=v_evader
    )


def _heading(v_evader: float, pursuer, evader, **params) -> np.ndarray:
    config = _config(v_evader)
    pol = make_policy("evader/toward_away", mode="away", **params)
    pol.reset(role="evader", map=config.map, config=config, seed=0)
    return np.asarray(pol.act(_observation(config, pursuer, evader)), float)


def test_away_slides_along_a_wall_it_would_press_into():
    """The pursuer below an evader 0.15 from the right wall (x = 10), a little to the
    left: straight away heads into the wall; faster than the pursuer the evader runs up
    the wall (1.5 x 0.96 opens L faster than V_p 1 can close it)."""
    a = _heading(1.5, (9.0, 2.0), (9.85, 5.0))
    assert a[0] == pytest.approx(0.0, abs=1e-6)
    assert a[1] == pytest.approx(1.0)


def test_away_charges_where_the_slide_would_not_outrun_the_pursuer():
    """The same wall, the pursuer farther left: up the wall L opens at 1.5 x 0.58, less
    than V_p: it runs at the pursuer."""
    a = _heading(1.5, (7.0, 3.0), (9.85, 5.0))
    rod = np.array([7.0 - 9.85, 3.0 - 5.0])
    assert a == pytest.approx(rod / np.hypot(*rod), abs=1e-6)


def test_away_charges_from_a_corner():
    """In the top-right corner with the pursuer on the diagonal no flight opens L: it
    runs at the pursuer (footnote 4: at rho > 1 that closes L to L_min)."""
    a = _heading(1.5, (7.5, 7.5), (9.85, 9.85))
    assert a == pytest.approx(np.array([-1.0, -1.0]) / math.sqrt(2.0), abs=1e-6)


@pytest.mark.parametrize("v_evader", [0.5, 1.0])
def test_away_runs_straight_away_at_rho_at_most_one(v_evader):
    """At rho <= 1 nothing changed: straight away, into the wall or the corner."""
    for pursuer, evader in [((9.0, 2.0), (9.85, 5.0)), ((7.5, 7.5), (9.85, 9.85))]:
        a = _heading(v_evader, pursuer, evader)
        away = np.subtract(evader, pursuer)
        assert a == pytest.approx(away / np.hypot(*away), abs=1e-6)


def test_pure_away_runs_straight_away_at_any_rho():
    """``pure=True`` is footnote 4's escape as worded (the reproduction report's
    ``run_away``): straight away into the wall and the corner, even at rho 1.5."""
    for pursuer, evader in [((9.0, 2.0), (9.85, 5.0)), ((7.5, 7.5), (9.85, 9.85))]:
        a = _heading(1.5, pursuer, evader, pure=True)
        away = np.subtract(evader, pursuer)
        assert a == pytest.approx(away / np.hypot(*away), abs=1e-6)
