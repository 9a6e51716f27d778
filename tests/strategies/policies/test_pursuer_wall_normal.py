"""The decomposition pursuer does not let an override turn the rod back into a wall's
normal (issue 13, the herder's pins).

A charger running straight at a pursuer that slides along a wall closes in while the rod
lies within asin(rho) of the wall's normal. The herder (benchmarks/unseen_opponents.py)
repositions opposite the pursuer's nearest wall and charges; before, ``_keep_orbit``'s
wall-path fallback (where no circle is within reach) could override the decomposition's
turn away from the normal with a hard turn back through it.
"""

from __future__ import annotations

import importlib
import math
from pathlib import Path

import numpy as np
import pytest

from strategies.policies import make_policy
from strategies.policies.base import Snapshot
from strategies.runner import build_env, run_episode

BENCHMARKS = Path(__file__).resolve().parents[3] / "benchmarks"


@pytest.fixture
def unseen(monkeypatch):
    monkeypatch.syspath_prepend(str(BENCHMARKS))
    return importlib.import_module("unseen_worlds")


def test_a_herded_pursuer_keeps_off_the_wall(unseen):
    """Fresh random world rand:polygons:3008:3.0 at (rho, L_max / L_min, L_min) =
    (0.5, 2, 2), the benchmark's seed: lost by "too_close" at 32.4 s before."""
    m, ov = unseen.pursuer_world("rand:polygons:3008:3.0", list(unseen.PURSUER_COMBOS[0]))
    herder = unseen.make_opponent("herder")
    r = run_episode(m, "pursuer/decomposition", herder, 101, max_cycles=340, overrides=ov,
                    start="safe")  # fmt: skip
    assert r.winner == "pursuer", r.summary()


def _at_the_south_wall(psi_deg: float, y: float = 1.0):
    """open_room (10 x 10, rho 0.5): the pursuer at height y, the rod psi_deg off the
    south wall's normal (pointing down), at L_target."""
    config = build_env("open_room", {}).config
    p = make_policy("pursuer/decomposition")
    p.reset(role="pursuer", map=config.map, config=config, seed=0)
    L = p.L_target
    theta = -0.5 * math.pi + math.radians(psi_deg)
    u = np.array([math.cos(theta), math.sin(theta)])
    pursuer = np.array([5.0, y])
    snap = Snapshot(pursuer - L * u, pursuer, 0.5 * u, 0.5 * u, 0.0)
    return p, snap, L


def test_an_override_into_the_normal_gives_way():
    p, snap, L = _at_the_south_wall(10.0)  # rod 10 deg ccw of the normal, cone 30 deg
    assert p._off_the_normal(snap, 0.2, -0.4, L) == 0.2  # cw turns back into it
    assert p._off_the_normal(snap, 0.2, 0.7, L) == 0.7  # a harder turn away stands
    assert p._off_the_normal(snap, -0.1, -0.4, L) == -0.4  # own turns into it too
    p, snap, L = _at_the_south_wall(-10.0)  # mirrored
    assert p._off_the_normal(snap, -0.2, 0.4, L) == -0.2


@pytest.mark.parametrize(("psi", "y"), [(40.0, 1.0), (10.0, 3.0)])
def test_outside_the_cone_or_away_from_walls_an_override_stands(psi, y):
    # 40 deg > asin(0.5); 3 m from the wall > L
    p, snap, L = _at_the_south_wall(psi, y)
    assert p._off_the_normal(snap, 0.2, -0.4, L) == -0.4
