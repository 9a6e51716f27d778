"""The decomposition pursuer at edge parameters the env accepts (issue 13).

* A range band narrower than twice the one-step buffer (``L_max - L_min < 4 V_e dt +
  0.02 L_min``): the held distance, L_min plus the buffer, lay past the band's middle, and
  past L_max itself when the band was narrower than one buffer (L_min 2, L_max 2.2,
  V_e 1, dt 0.1: 2.22); every pursuer aiming at it ended ``"too_far"`` within 1-20 steps.
  Now the band's middle (the same buffer both ways).
* ``range_margin`` 1 (its documented upper end) aimed at L_max plus the buffer.
* A long step: the distance correction ``distance_gain (L - L_target)`` held for ``dt``
  moved L by ``distance_gain dt`` times its error (3 at dt 1: each step overshot by
  twice the error, alternately too close and too far); now at most ``1 / dt`` is used.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from envs.surveillance.config import EnvConfig
from strategies.policies import make_policy
from strategies.policies.base import distance_target
from strategies.runner import run_episode

NARROW = {"l_min": 2.0, "v_pursuer": 2.0, "v_evader": 1.0, "dt": 0.1}


@pytest.mark.parametrize("l_max", [2.05, 2.1, 2.2, 2.4])
@pytest.mark.filterwarnings("ignore::envs.errors.NarrowBandWarning")  # narrow on purpose
def test_the_distance_target_is_the_middle_of_a_narrow_band(l_max):
    from strategies.policies.base import distance_ceiling

    c = EnvConfig(map="open_room", l_max=l_max, **NARROW)
    middle = 0.5 * (2.0 + l_max)
    assert distance_target(c) == pytest.approx(middle)  # was 2.22 at every l_max here
    assert distance_ceiling(c) == pytest.approx(middle)


def test_a_wide_band_keeps_the_buffer_below_and_mirrors_it_above():
    from strategies.policies.base import distance_ceiling

    c = EnvConfig(map="corridor")  # L_min 2, L_max 4, V_e 0.5, dt 0.1
    assert distance_target(c) == 2.0 + 2.0 * 0.5 * 0.1 + 0.01 * 2.0
    assert distance_ceiling(c) == pytest.approx(4.0 - 0.12)


@pytest.mark.parametrize("world", ["open_room", "corridor"])
def test_the_pursuer_holds_a_band_as_wide_as_two_evader_steps(world):
    # L_max - L_min = 2 V_e dt: aiming at 2.22, past L_max 2.2, it lost too_far in 14
    # (open room) and 4 steps (corridor); from the middle it holds
    pursuer = make_policy("pursuer/decomposition")
    r = run_episode(
        world, pursuer, "evader/shooting", 0, overrides=dict(NARROW, l_max=2.2), max_cycles=200
    )
    assert r.winner == "pursuer", r.summary()
    assert pursuer.L_target == pytest.approx(2.1)


MARGIN_LOSSES = [("corridor", "evader/straight", 0), ("open_room", "evader/random", 0)]


@pytest.mark.parametrize(("world", "evader", "seed"), MARGIN_LOSSES)
def test_a_full_range_margin_stays_inside_the_band(world, evader, seed):
    # range_margin 1 aimed at 4.12 with L_max 4: lost too_far in 27 and 87 steps
    pursuer = make_policy("pursuer/decomposition", range_margin=1.0)
    r = run_episode(world, pursuer, evader, seed, max_cycles=200)
    assert r.winner == "pursuer", r.summary()
    assert pursuer.L_target == pytest.approx(4.0 - 0.12)
    L = np.linalg.norm(r.trajectory[:, 0] - r.trajectory[:, 1], axis=1)
    assert L.max() < 4.0


@pytest.mark.parametrize(("world", "evader", "seed", "dt"), [
    ("corridor", "evader/toward_away", 2, 1.0),  # lost too_close at step 1
    ("open_room", "evader/straight", 3, 1.0),  # too_close at step 20
    ("open_room", "evader/straight", 0, 1.25),  # too_far at step 4
])  # fmt: skip
def test_a_long_step_does_not_overshoot_the_distance(world, evader, seed, dt):
    pursuer = make_policy("pursuer/decomposition")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = run_episode(
            world, pursuer, evader, seed, overrides={"dt": dt}, max_cycles=100, start="valid"
        )
    assert r.winner == "pursuer", r.summary()
