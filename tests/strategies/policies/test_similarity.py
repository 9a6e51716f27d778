"""The analytic policies on a world scaled by a name transform (``NAME~xS``): lengths and
speeds scale alike (``map_recommendations``), so the game and its time are the same and a
policy written in the game's terms plays the same episode, scaled. The decomposition
pursuer and the shooting and toward-away evaders do, exactly at S = 2 and 1/2 (powers of
two: no rounding). Its constants in seconds (ORBIT_LOOKAHEAD, WALL_HORIZON, CHARGE_PERSIST,
the distance gain) are right for this similarity; a length constant in metres would break
it. (wall_hugging's ``offset`` and orbit's radius are in metres: those evaders walk other
paths on a scaled world, session 30, helper-194.)"""

import numpy as np
import pytest

from strategies.runner import run_episode


@pytest.mark.parametrize("world", ["pillars", "l_hall"])
@pytest.mark.parametrize("evader", ["evader/shooting", "evader/toward_away"])
def test_a_scaled_world_plays_the_same_episode_scaled(world, evader):
    base = run_episode(world, "pursuer/decomposition", evader, 1, max_cycles=150)
    assert base.steps == 150
    for scale in (2.0, 0.5):
        r = run_episode(f"{world}~x{scale:g}", "pursuer/decomposition", evader, 1, max_cycles=150)
        assert (r.winner, r.steps) == (base.winner, base.steps)
        np.testing.assert_allclose(r.trajectory / scale, base.trajectory, rtol=0, atol=1e-9)
