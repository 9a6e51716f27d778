"""Issue 13: from safe starts the decomposition pursuer holds on a variant of the corridor.

The corridor (a pursuer's world: no witness region at L_min, Prop. 2) rotated by 30
degrees, scaled by 3 (lengths, speeds and the agents' discs alike, so the game is the
same up to the similarity) and moved off the origin, at rho = 0.5, against every evader
of the registry: a compact version of ``benchmarks/pursuer_holds.py``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from envs.maps import builtin_info
from strategies.policies import make_policy, policy_names
from strategies.runner import run_episode

SCALE = 3.0
EVADERS = [*policy_names("evader"), "evader/toward_away:away"]


@pytest.fixture(scope="module")
def variant():
    info = builtin_info("corridor")
    a = math.radians(30.0)
    rot = SCALE * np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])
    world = info.map.transformed(rot, (7.3, -2.1))
    params = {k: SCALE * v for k, v in info.params().items()}
    params["v_evader"] = 0.5 * params["v_pursuer"]
    params["body_radius"] = SCALE * 0.1  # the env's default, scaled
    return world, params


@pytest.mark.parametrize("evader", EVADERS)
def test_decomposition_pursuer_holds_on_the_turned_scaled_corridor(variant, evader):
    world, params = variant
    opponent = (
        make_policy("evader/toward_away", mode="away") if evader.endswith(":away") else evader
    )
    for seed in (0, 1):
        r = run_episode(
            world,
            "pursuer/decomposition",
            opponent,
            seed,
            start="safe",
            max_cycles=150,
            overrides=params,
        )
        assert r.winner == "pursuer", r.summary()
