"""The decomposition pursuer leads an evader's lap round a small obstacle (issue 13).

On a lap round an obstacle small enough to circle (:meth:`DecompositionPursuer._walk_corners`)
the rod cannot keep pace with the walk for ever; reached, the decomposition's target left
the rod idle while the walk's heading ran ahead of it. The rod now turns the walk's way to
the far end of its free arc (:meth:`DecompositionPursuer._walk_lead`).
"""

from __future__ import annotations

import numpy as np
import pytest

from envs.maps import Map
from envs.surveillance.config import EnvConfig
from tests.strategies.policies.conftest import decomposition_pursuer, orbit_episode

# rand:convex:2005:3.5 (held-out, rho 0.5, L in [2, 4]) at 6 s of the orbit at 0.25 (ccw,
# seed 101) as hindsight's pursuer (cell 0.02) played it: the evader has begun its lap
# and the rod leads it by about 15 degrees
_P6 = (12.599122022359696, 11.683485515879134)
_E6 = (13.317546036363881, 13.62800652657402)


def test_a_lead_on_a_lap_is_kept(unseen):
    # before: the rod turned back 20 degrees to the decomposition's target and idled
    # 2 s while the lap turned the evader's heading 90 degrees; occluded 8.9 s on
    # (hindsight's pursuer holds 17.7 s on); held 13.6 s now
    r = orbit_episode(
        unseen, "rand:convex:2005:3.5", 125, start={"pursuer": list(_P6), "evader": list(_E6)}
    )
    assert r.winner == "pursuer", r.summary()


@pytest.mark.parametrize(
    ("world", "seconds"), [("rand:convex:5105:4.0", 20.0), ("rand:polygons:3007:3.0", 10.5)]
)
def test_a_lap_from_the_safe_start_lasts_longer(unseen, world, seconds):
    # the orbit losses of unseen-p0 and fresh-p0: occluded at 17.9 s and 8.4 s before,
    # at 20.9 s and 10.9 s now (hindsight: a pursuer holds 27.8 s on the first)
    r = orbit_episode(unseen, world, round(seconds / 0.1))
    assert r.winner == "pursuer", r.summary()


def _pillar_pursuer():
    # a 12 x 8 room with a 1.5 m square pillar at (5, 3): small at rho 0.5, L_min 2
    pillar = [(5.0, 3.0), (6.5, 3.0), (6.5, 4.5), (5.0, 4.5)]
    world = Map([(0, 0), (12, 0), (12, 8), (0, 8)], [pillar], name="pillar_1.5")
    config = EnvConfig(
        map=world, l_min=2.0, l_max=4.0, v_pursuer=1.0, v_evader=0.5, body_radius=0.1
    )
    return decomposition_pursuer(config)


@pytest.mark.parametrize("sense", [1, -1])
def test_a_lap_is_a_walk_along_a_small_obstacle(sense):
    # the evader 0.25 below the pillar's bottom wall: walking along it (east is
    # counter-clockwise round the pillar, west clockwise) is a lap, the way the map's
    # ring runs (free space on its left: clockwise) or not; walking away from it is none
    p = _pillar_pursuer()
    e = np.array([5.75, 2.75])
    ring, _, forward = p._walk(e, 0.5 * sense, 0.0, 0.5)
    assert ring == 1 and forward == (sense < 0)
    assert p._walk(e, 0.0, -0.5, 0.5) is None
    assert p._walk(e + np.array([0.0, -0.5]), 0.5 * sense, 0.0, 0.5) is None  # not hugging
