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

On ``two_rooms`` scaled x1.6 and turned by -2.5 rad (the held-out set's
``two_rooms~x1.6rot-2.5``) at L_min 1.6, L_max 1.5 L_min, rho 0.5, against the
decomposition pursuer (seed 939), every route out of the evader's cells crosses a piece
at a corridor end that runs closer to a door jamb than the evader's body radius, so their
ranks (n_cells and more) promise nothing. The plan led to that dead end; the evader shot,
and a few steps into the shot the next cell's plan took over and led straight back: plan
and shots alternated for the whole horizon (8 D / V_e: 5,569 plan steps, 140 shooting).
Now from a dead end the evader shoots first (the plan only where no shot has a positive
margin, until a cell whose rank is a guarantee) and escapes at 0.30 D / V_e.
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


def test_shoots_first_from_a_dead_end_of_the_plan():
    info = builtin_info("two_rooms")
    scale, rot = 1.6, -2.5
    c, s = math.cos(rot), math.sin(rot)
    m = info.map.transformed(scale * np.array([[c, -s], [s, c]]), (0.0, 0.0))
    params = {"l_min": 1.0 * scale, "l_max": 1.5 * scale, "v_pursuer": scale,
              "v_evader": 0.5 * scale, "body_radius": 0.1 * scale}  # fmt: skip
    x0, y0, x1, y1 = m.bounds
    horizon = 1.5 * math.hypot(x1 - x0, y1 - y0) / params["v_evader"]  # seconds
    r = run_episode(m, "pursuer/decomposition", "evader/shooting", 939, start="safe",
                    max_cycles=math.ceil(horizon / 0.1), overrides=params)  # fmt: skip
    assert r.winner == "evader", r.summary()
