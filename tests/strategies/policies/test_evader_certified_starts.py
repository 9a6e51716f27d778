"""The shooting evader escapes from starts the referee certifies as evader wins (issue 13).

Found on worlds the evader was not developed on, at rho = 0.2, L in [2, 6], body radius
0.1, against the decomposition pursuer, from starts the referee (16 cells per L_min)
certifies as evader wins (helper-133's certstarts.py, session 22). There every crossing out
of the evader's cells is one its disc cannot make, so the cells' plans rank at least
n_cells and promise nothing; the evader walked them and was held for 8 D / V_e (or
escaped after minutes). Now a shot goes before such a plan when its disc can follow the
straight path to the target and the margin is positive against the rod's present length
(the rod near L_max at these starts: the pursuer turns slower than at L_min).
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
]  # fmt: skip


@pytest.mark.parametrize(("world", "seed", "start", "steps"), _STARTS, ids=["7202", "7204"])
def test_escapes_within_the_referee_s_certified_time(world, seed, start, steps):
    ev = ShootingEvader()
    r = run_episode(world, "pursuer/decomposition", ev, seed, max_cycles=steps,
                    overrides=_PARAMS, start=start)  # fmt: skip
    assert r.winner == "evader", r.summary()
