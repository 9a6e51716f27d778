"""The shooting evader escapes on a rescaled, rotated evader-win built-in (issue 13).

Found by ``benchmarks/evader_escapes.py``: on ``office`` scaled x10 and rotated by 1.1 rad,
against the corner-rounding pursuer (seed 2), the evader reached a rank-0 cell whose vias
all hug a wall (no crossing keeps the evader's disc clear, so no witness) and left it
for a rank-8 neighbour whose plan crossed straight back into it, through one of two
pieces in turn. Leaving a cell without a witness was not put on the trail of
crossings, so the A -> B -> A check never fired and the evader alternated between the
two cells for the whole horizon (8 D / V_e). Now such a departure is on the trail, the
two crossings are excluded, and it escapes within 2 D / V_e.

Against the referee pursuer (seed 0) the same corner made a three-cell cycle (a rank-6
cell's plan into a rank-0 cell without a reachable crossing, on to another, and back;
about 6 D / V_e at HEAD before, held for 8 D / V_e after the first fix): a return to
any cell still on the trail now excludes every crossing of the cycle.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from envs.maps import builtin_info
from strategies.runner import run_episode


def _office_x10_rot():
    info = builtin_info("office")
    scale, rot = 10.0, 1.1
    c, s = math.cos(rot), math.sin(rot)
    m = info.map.transformed(scale * np.array([[c, -s], [s, c]]), (0.0, 0.0))
    params = {k: v * scale for k, v in info.params().items()}
    params["body_radius"] = 0.1 * scale
    return m, params


@pytest.mark.parametrize(
    ("pursuer", "seed"), [("pursuer/corner_rounding", 2), ("pursuer/referee", 0)]
)
def test_escapes_where_it_cycled_between_cells(pursuer, seed):
    m, params = _office_x10_rot()
    x0, y0, x1, y1 = m.bounds
    horizon = 2.0 * math.hypot(x1 - x0, y1 - y0) / params["v_evader"]  # seconds
    r = run_episode(m, pursuer, "evader/shooting", seed, start="safe",
                    max_cycles=math.ceil(horizon / 0.1), overrides=params)  # fmt: skip
    assert r.winner == "evader", r.summary()
