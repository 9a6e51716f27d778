"""The shooting evader's fallback makes progress (issue 13).

Found on a world the evader was not developed on (the office scaled by 0.8, turned by
-1.4 rad and shifted by (6, 2)), rho = 0.2, L in [1.6, 4.8], body radius 0.08, against
the decomposition pursuer, seed 8. From 8 s the evader's cell has no plan its disc can
take (a rank of at least n_cells) and it falls back to shots and pressure at the tip of
a thin wall: a shot at the point past the wall's end, in sight but not reachable by the
disc pressed to the end, then a slide along the wall back, the pursuer's turns keeping
that shot's margin alternately positive and not. It stayed in a 0.09 x 0.05 m box from
30 s to the 1,320 s horizon (8 D / V_e), where the referee certifies evader wins from
other starts on this world at this speed ratio (499 of them). Now a fallback that keeps
within L_min / 8 of its mean position for 2 L_min / V_e gives up the targets it shot at
(``ShootingEvader._fallback_stalled``): the evader leaves the wall's tip, and escapes
(too close, while herding) at 768.9 s.
"""

from __future__ import annotations

import numpy as np

from strategies.policies.shooting import ShootingEvader
from strategies.runner import run_episode

_PARAMS = {"l_min": 1.6, "l_max": 4.8, "v_pursuer": 0.8, "v_evader": 0.16, "body_radius": 0.08}


def _office(cycles: int):
    evader = ShootingEvader()
    r = run_episode("office~x0.8rot-1.4off(6,2)", "pursuer/decomposition", evader, 8,
                    max_cycles=cycles, overrides=_PARAMS)  # fmt: skip
    return r, evader


def test_fallback_leaves_the_tip_of_a_wall():
    # steps 400-1000 (40-100 s): on aeb694f all within 0.06 m of their mean
    r, _ = _office(1000)
    e = r.trajectory[400:1001, 1]
    spread = float(np.linalg.norm(e - e.mean(axis=0), axis=1).max())
    assert spread > 0.25 * _PARAMS["l_min"], spread
