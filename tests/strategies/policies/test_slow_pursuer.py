"""A very slow pursuer (rho huge) or evader is legal input: the analytic policies play it.

Their probe rays were sized by the evader's reach within the pursuer's turning horizon,
which grows as 1 / V_p: at V_p = 1e-9 that asked numpy for terabytes. A ray stops at its
first sample off the table's grid, so the rays now end past the grid's diagonal.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from envs.errors import RhoAboveOneWarning
from envs.surveillance.config import EnvConfig
from strategies.policies import make_policy
from strategies.runner import run_episode
from tests.strategies.policies.conftest import state_observations


@pytest.mark.parametrize(("name", "role"), [("pursuer/decomposition", "pursuer"),
                                            ("evader/shooting", "evader")])  # fmt: skip
def test_a_very_slow_pursuer_is_played(box_world, name, role) -> None:
    with pytest.warns(RhoAboveOneWarning):
        cfg = EnvConfig(map=box_world, l_min=2.0, l_max=4.0, v_pursuer=1e-9, v_evader=0.5)
    policy = make_policy(name)
    policy.reset(role=role, map=box_world, config=cfg, seed=0)
    nx, ny = policy.table.shape
    assert policy._n_r <= math.ceil(math.hypot(nx, ny)) + 2
    for obs in state_observations(cfg, n=3):
        action = policy.act(obs)
        assert action.shape == (2,) and np.all(np.isfinite(action))
        assert np.all(np.abs(action) <= 1.0)


def test_a_very_slow_evader_is_played() -> None:
    # with no probe within the horizon's reach (V_e = 1e-3: the rays hold 2 samples, the
    # first probe is the 3rd) the corner probes indexed an empty array: IndexError at step 1
    result = run_episode(
        "corridor", "pursuer/decomposition", "evader/shooting", seed=0, max_cycles=5,
        overrides={"v_evader": 1e-3},
    )  # fmt: skip
    assert result.winner == "pursuer" and result.steps == 5
