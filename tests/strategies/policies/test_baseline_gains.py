"""A proportional gain above 1 / dt overshoots its target every step; the baselines apply
at most 1 / dt (:func:`strategies.policies.baselines.step_gain`)."""

import numpy as np
import pytest

from strategies.policies import make_policy
from strategies.policies.base import BasePolicy
from strategies.policies.baselines import step_gain
from strategies.runner import run_episode


class _Still(BasePolicy):
    """An evader that stands where it starts."""

    def _decide(self, snap):
        return np.zeros(2)


def test_step_gain_is_the_gain_up_to_one_over_dt():
    assert step_gain(4.0, 0.1) == 4.0
    assert step_gain(50.0, 0.1) == pytest.approx(10.0)
    assert step_gain(10.0, 0.1) == pytest.approx(10.0)


@pytest.mark.parametrize("gain", [4.0, 50.0])
def test_a_greedy_pursuer_settles_at_its_distance_whatever_its_gain(gain):
    """Against an evader that stands still the distance error shrinks every step and
    never changes sign; at gain 50 (dt 0.1) it chattered about the target, +-0.05."""
    distances = []
    r = run_episode(
        "open_room",
        make_policy("pursuer/greedy", gain=gain),
        _Still(),
        seed=3,
        max_cycles=80,
        start="valid",
        on_step=lambda t: distances.append(t.info["distance"]),
    )
    assert r.winner == "pursuer"
    moves = np.diff(distances)  # the pursuer closes in, then the distance stays put
    assert np.all(moves <= 1e-5) or np.all(moves >= -1e-5), "the error changed sign"
    settled = np.asarray(distances[-20:])
    assert np.ptp(settled) < 1e-5, (gain, settled)
