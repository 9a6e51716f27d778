"""The seeded start sampler: valid and safe starts are valid surveillance configurations."""

from __future__ import annotations

import numpy as np
import pytest

from envs import surveillance_v0
from envs.geometry import kernel_for
from strategies.policies.starts import sample_start


@pytest.mark.parametrize("kind", ["valid", "safe"])
@pytest.mark.parametrize(
    ("l_min", "l_max"),
    [(2.0, 4.0), (1.0, 1.0001), (1.5, 1.6)],  # the last two are narrower than the buffer
)
def test_starts_lie_inside_the_sensor_range_and_reset_accepts_them(kind, l_min, l_max):
    env = surveillance_v0.parallel_env(map="open_room", l_min=l_min, l_max=l_max)
    rng = np.random.default_rng(7)
    for _ in range(3):
        start = sample_start(env.config, rng, kind=kind)
        p, e = np.asarray(start["pursuer"]), np.asarray(start["evader"])
        assert l_min <= np.linalg.norm(p - e) <= l_max
        assert kernel_for(env.config.map).line_of_sight(p, e)
        env.reset(seed=0, options=start)  # raises InvalidPlacementError if not valid
    env.close()


def test_same_generator_state_same_start():
    env = surveillance_v0.parallel_env(map="corridor")
    a = sample_start(env.config, np.random.default_rng(3), kind="safe")
    b = sample_start(env.config, np.random.default_rng(3), kind="safe")
    assert a == b


@pytest.mark.parametrize("map_name", ["corridor", "two_rooms"])
def test_escapable_starts_put_the_rod_in_an_escapable_cell(map_name):
    """Checked against the exact decomposition at L_min: the orientation of the start's
    rod lies in a cell the evader can escape from (or where no cell is classified safe)."""
    import math

    from strategies.cspace import decompose

    env = surveillance_v0.parallel_env(map=map_name)
    cfg = env.config
    dec = decompose(cfg.map, cfg.l_min)
    rng = np.random.default_rng(3)
    for _ in range(4):
        start = sample_start(cfg, rng, kind="escapable")
        p, e = np.asarray(start["pursuer"]), np.asarray(start["evader"])
        assert cfg.l_min <= np.linalg.norm(p - e) <= cfg.l_max
        env.reset(seed=0, options=start)
        theta = math.atan2(p[1] - e[1], p[0] - e[0])
        cell = dec.cell_at(float(e[0]), float(e[1]), theta)
        safe_here = [ca for ca in dec.free_arcs(e) if ca.escapable is False]
        assert cell is None or cell.escapable or not safe_here
    env.close()
