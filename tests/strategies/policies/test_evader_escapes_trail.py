"""The shooting evader's cycle check sees a cycle of crossings of any length (issue 13).

A return to a cell still on the evader's trail of crossings excludes every crossing made
since it left that cell (``ShootingEvader._plan_heading``). The trail kept the last 4,
then 16 crossings (16 fitted to random:polygons:0 seed 0 against the decomposition
pursuer). Against a stronger pursuer (the look-ahead arbiter of branch
``decomp-look-ahead-disagree``) the same episode went round an exact 21-crossing loop
of 25.4 s from 170 s to the end of the 8 D / V_e horizon: the plan walked east along
the bottom wall through cells of rank 2408 down to 2400 (every route counts crossings
the evader's disc cannot make), met a cell whose only via it had excluded, and the
pressure charge walked it back west through 12 cells to where the plan resumed. The
cycle was longer than the trail, so it was never caught; seed 2 the same. Now the trail
keeps n_cells + 1 crossings: among that many in a row some cell is entered twice
(pigeonhole), so every cycle is caught. Both episodes escape (229.6 s and 167.5 s);
against main's decomposition pursuer they escape at 229.3 s and 234.9 s (were 272.4 s
and 254.0 s).

Here the cycle is scripted: the evader's plan answers "which cell?" from a list, and
the evader goes round a cycle of k distinct cells and re-enters the first (the 16-crossing
trail caught k <= 17).
"""

from __future__ import annotations

import numpy as np
import pytest

from envs.maps import load_map
from envs.surveillance.config import EnvConfig
from strategies.policies.shooting import ShootingEvader

OVERRIDES = {"l_min": 2.0, "l_max": 4.0, "v_pursuer": 1.0, "v_evader": 0.5, "body_radius": 0.1}


class _Scripted:
    """The evader's escape plan with ``cell_at`` answered from a list (and no region
    test to keep the last cell): every call is a crossing into the next listed cell."""

    def __init__(self, plan, cells):
        self._plan = plan
        self._cells = iter(cells)

    def __getattr__(self, name):
        return getattr(self._plan, name)

    def well_inside(self, region, point):
        return False

    def cell_at(self, point, theta):
        return next(self._cells)


@pytest.fixture(scope="module")
def evader():
    m = load_map("random:polygons:0")
    ev = ShootingEvader()
    ev.reset(role="evader", map=m, config=EnvConfig(map=m, **OVERRIDES), seed=0)
    return ev


@pytest.mark.parametrize("k", [3, 17, 18, 21, 100])
def test_a_cycle_of_k_crossings_is_caught(evader, k):
    ev = evader
    ev.restart()
    plan = ev.plan
    n = len(plan.rank)
    # k distinct escapable cells, spread over the map, in a cycle: c0 -> c1 -> ... -> c0
    cycle = [int(c) for c in np.flatnonzero(plan.rank >= 0)[:: n // k][:k]]
    assert len(set(cycle)) == k
    ev.plan = _Scripted(plan, [*cycle, cycle[0]])
    e = np.array([5.0, 1.0])  # a free point; the cells' witnesses are computed from it
    try:
        for _ in range(k):
            ev._plan_heading(e, 0.0)
        assert not ev._excluded  # no cell entered twice yet
        ev._plan_heading(e, 0.0)  # back in c0
    finally:
        ev.plan = plan
    # every crossing of the cycle is out (the piece each cell was left through, or -1)
    assert set(ev._excluded) == set(cycle)
