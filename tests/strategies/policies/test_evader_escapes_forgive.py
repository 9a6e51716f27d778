"""The shooting evader retries a cell whose crossings it has all excluded (issue 13).

Found by a sweep of worlds, speeds and ranges the evader was not developed on: crossings
the evader stalls at or cycles through are excluded for their cell, and over an episode
the exclusions can empty every via of an escapable cell. The evader then had no plan
there and fell back to pressure for the rest of the horizon. ``two_rooms`` turned by
2.2 rad at L_min = 1, L_max = 1.5, rho = 0.5 against the decomposition pursuer (seed
619): 4,768 of 5,704 steps of pressure, held for 8 D / V_e. Now, after ``FORGIVE_STEPS``
(doubling with each retry) in an escapable cell without a crossing, that cell's
exclusions are forgotten and its plan is tried again: it escapes in 0.9 D / V_e.
"""

from __future__ import annotations

import math

import numpy as np

from envs.maps import builtin_info
from strategies.runner import run_episode


def test_escapes_after_excluding_every_crossing_of_a_cell():
    rot = 2.2
    c, s = math.cos(rot), math.sin(rot)
    m = builtin_info("two_rooms").map.transformed(np.array([[c, -s], [s, c]]), (0.0, 0.0))
    params = {"l_min": 1.0, "l_max": 1.5, "v_pursuer": 1.0, "v_evader": 0.5, "body_radius": 0.1}
    x0, y0, x1, y1 = m.bounds
    horizon = 1.5 * math.hypot(x1 - x0, y1 - y0) / params["v_evader"]  # seconds
    r = run_episode(m, "pursuer/decomposition", "evader/shooting", 619, start="safe",
                    max_cycles=math.ceil(horizon / 0.1), overrides=params)  # fmt: skip
    assert r.winner == "evader", r.summary()
