"""The decomposition pursuer keeps its own turn, clear of walls, over a hard turn toward a
circle nearer to having room but farther from it (issue 13, holds-bench-03 seed 5).

On the paper's pillars world at rho 0.3, seed 5, the charging evaders (shooting,
toward-away, the referee's: the same pure-pursuit charge there) charged the pursuer east
of the triangular pillar. The decomposition turned counter-clockwise, up the free side
toward the room north of the pillar; the hard clockwise turn's circle was short of room by
less (0.57 against 0.80, within ORBIT_REACH) but lay round the pillar's tip, farther from
room by the geodesic way (1.44 against 1.17). The pick alternated between the two for two
seconds, the rod stood still while the charge pushed the pursuer into the pocket between
the pillar's tip and the room's south-east corner: too close at 8.7-9.0 s. ``_way_kept``
keeps the decomposition's turn there (``_orbit_choice``) against a charge that has lasted
CHARGE_PERSIST (from 3.2 s on).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from strategies.policies import make_policy
from strategies.policies.base import Snapshot
from strategies.runner import build_env, run_episode

PILLARS_03 = {"l_min": 2.0, "l_max": 4.0, "v_pursuer": 1.0, "v_evader": 0.3, "body_radius": 0.2}

# holds-bench-03's safe start of pillars (pursuer_holds.py --rho 0.3), seed 5
START_5 = {"pursuer": (18.444973826408386, 2.9709938168525696),
           "evader": (16.22391641139984, 3.853605806827545)}  # fmt: skip


@pytest.mark.parametrize("evader", ["evader/toward_away", "evader/shooting"])
def test_the_charged_pursuer_turns_round_to_room_not_into_the_pocket(evader):
    # lost before at 9.0 s (toward_away) and 8.7 s (shooting); 20 s is twice that
    r = run_episode("pillars", "pursuer/decomposition", evader, 5,
                    max_cycles=200, overrides=PILLARS_03, start=START_5)  # fmt: skip
    assert r.winner == "pursuer", (r.cause, r.escape_time)


def _charged_east_of_the_pillar(ex: float, ey: float, theta_deg: float, run: int = 100):
    """pillars at rho 0.3: the evader at (ex, ey) charging along the rod at full speed,
    the pursuer at L_target along the rod at theta_deg, the charge ``run`` steps long."""
    config = build_env("pillars", PILLARS_03).config
    p = make_policy("pursuer/decomposition")
    p.reset(role="pursuer", map=config.map, config=config, seed=0)
    p._charge_run = run
    L = p.L_target
    t = math.radians(theta_deg)
    u = np.array([math.cos(t), math.sin(t)])
    e = np.array([ex, ey])
    v = config.v_evader * u
    return p, Snapshot(e, e + L * u, v, v, 0.0), L


HI, LO = 0.46, -0.45  # the hard turns ccw and cw there


@pytest.mark.parametrize(("ex", "ey", "theta"), [(16.77, 3.45, -29.7), (17.0, 3.3, -37.6)])
def test_a_hard_turn_round_the_pillar_gives_way_to_the_clear_turn_toward_room(ex, ey, theta):
    p, snap, L = _charged_east_of_the_pillar(ex, ey, theta)
    # the cw circle is nearer to having room, the ccw one nearer to room
    assert p._after(snap, LO, L, False) > p._after(snap, HI, L, False) + 0.01 * L
    assert p._after(snap, LO, L, True) < p._after(snap, HI, L, True) - p.table.resolution
    assert all(p._time_to_wall(snap, HI, L, f) == math.inf for f in (True, False))
    assert p._orbit_pick(snap, HI, HI, LO, L) == LO
    assert p._orbit_choice(snap, HI, HI, LO, L) == HI


def test_where_the_own_turn_meets_a_wall_the_hard_turn_stands():
    # lower down, by the east wall: the ccw path meets it 1.0 s ahead, cw's way is longer
    p, snap, L = _charged_east_of_the_pillar(17.6, 2.76, -45.5)
    assert p._time_to_wall(snap, HI, L, True) < math.inf
    assert p._after(snap, LO, L, True) < p._after(snap, HI, L, True) - p.table.resolution
    assert p._way_kept(snap, HI, LO, HI, LO, L) == LO


def test_against_a_short_charge_the_hard_turn_stands():
    # 30 steps < CHARGE_PERSIST / dt + 1: herders and darters charge in bursts
    p, snap, L = _charged_east_of_the_pillar(16.77, 3.45, -29.7, run=30)
    assert p._orbit_choice(snap, HI, HI, LO, L) == LO
