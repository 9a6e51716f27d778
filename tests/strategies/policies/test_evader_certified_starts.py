"""The shooting evader escapes from starts the referee certifies as evader wins (issue 13).

Found on worlds the evader was not developed on, at rho = 0.2, L in [2, 6], body radius
0.1, against the decomposition pursuer, from starts the referee (16 cells per L_min)
certifies as evader wins (helper-133's certstarts.py, session 22). There every crossing out
of the evader's cells is one its disc cannot make, so the cells' plans rank at least
n_cells and promise nothing; the evader walked them and was held for 8 D / V_e (or
escaped after minutes). Now a shot goes before such a plan when its disc can follow the
straight path to the target and the margin is positive against the rod's present length
(the rod near L_max at these starts: the pursuer turns slower than at L_min).

Session 24 (helper-146, helper-139's starts on six more worlds, same game): the referee's
own evader escapes the last misses with one short straight step past the corner of an
obstacle the long rod grazes (the rod pivots about the corner: its far end, 5 m out,
swings many times as far as the evader steps, more than the pursuer, 5 times as fast, can
follow). From random:polygons:7302 the shooting evader had no plan and no shot with a
positive margin at L_min's rate (pressure from the first step, held); from
random:rectangles:7303 it walked a guaranteed (rank-8) plan cell by cell for 21-105 s.
Now such a shot goes first while the rod is long, plan or no plan, and its margin is also
taken against where the pursuer can be by then (random:convex:7308: no margin against the
rate of eq. 6 was positive there).
"""

from __future__ import annotations

import pytest

from strategies.policies.shooting import ShootingEvader
from strategies.runner import run_episode

_PARAMS = {"l_min": 2.0, "l_max": 6.0, "v_pursuer": 1.0, "v_evader": 0.2, "body_radius": 0.1}

# (world, seed, start, steps): the referee's certified time (dt 0.1 s)
_STARTS = [
    # certified within 3.9 s; 1283649: held for 644 s; now occluded at 1.62 s
    ("random:polygons:7202", 1330,
     {"pursuer": [7.005995067896629, 2.066969047239773],
      "evader": [12.299555793973322, 4.799555793973322]}, 39),
    # certified within 2.6 s; 1283649: held for 8 D / V_e (911 s); now occluded at 2.43 s.
    # A void plan yielding to any shot with a positive margin at L_min's rate held it too
    ("random:convex:7204", 1330,
     {"pursuer": [7.063932052297361, 7.109369883830196],
      "evader": [3.7995557939733224, 2.7995557939733224]}, 26),
    # certified within 1.3 s (the referee's evader: 0.73 s); a3657e8: pressure from the
    # first step, held for 8 D / V_e; now occluded at 0.51 s
    ("random:polygons:7302", 1333,
     {"pursuer": [8.0023122183654, 6.055129488827748],
      "evader": [3.7995557939733224, 8.799555793973322]}, 13),
    # certified within 2.6 s (the referee's evader: 1.64 s); a3657e8: a rank-8 plan,
    # occluded at 21.02 s; now at 1.38 s
    ("random:rectangles:7303", 1331,
     {"pursuer": [13.058160792531037, 15.075358382327751],
      "evader": [12.549555793973322, 10.799555793973322]}, 26),
    # certified within 5.2 s (the referee's evader: 4.83 s, 0.75 m east under an obstacle,
    # then 0.17 m north past its bottom corner); a3657e8 and eq. 6's margins alone: held
    # for 8 D / V_e; against the pursuer's reach, occluded at 1.53 s
    ("random:convex:7308", 1335,
     {"pursuer": [3.0418897865750254, 9.009510688927215],
      "evader": [4.549555793973322, 3.2995557939733224]}, 52),
    # certified within 11.7 s (the referee's evader: 0.25 m south, then east under the
    # corner of the obstacle 0.2 m away, occluded at 2.81 s); 3765f76: every straight shot
    # past the corner grazes it closer than the body radius, the plan promises nothing
    # (rank 1487 of 1470 cells) and walked north, too close at 130.8 s; a shot in two
    # legs (to the point beside the corner, then past it) occludes at 2.17 s
    ("random:polygons:7306", 1333,
     {"pursuer": [3.0023122183654003, 14.055129488827749],
      "evader": [2.5495557939733224, 8.299555793973322]}, 117),
]  # fmt: skip


@pytest.mark.parametrize(
    ("world", "seed", "start", "steps"),
    _STARTS,
    ids=["7202", "7204", "7302", "7303", "7308", "7306"],
)
def test_escapes_within_the_referee_s_certified_time(world, seed, start, steps):
    ev = ShootingEvader()
    r = run_episode(world, "pursuer/decomposition", ev, seed, max_cycles=steps,
                    overrides=_PARAMS, start=start)  # fmt: skip
    assert r.winner == "evader", r.summary()
