"""The shooting evader escapes where the theory says it wins: no loops, no freezes.

Worlds where Prop. 2 holds (every cell escapable at some rank) that the evader was not
developed on: a plus-shaped crossroads and a T-junction of corridors 1.6 wide (L_min = 2).
Before, in the crossroads the plan stepped across a piece at a junction into a cell whose
plan crossed straight back (a two-cell loop for the whole episode, 150 s, against a
pursuer that barely moves). Now a crossing that leads back (A -> B -> A) or that the
evader cannot get closer to is excluded for that cell, and the fallback holds its
direction: the evader escapes every episode, within a horizon proportional to the map's
diameter over V_e.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from envs.maps.junctions import crossroads, t_junction
from strategies.cspace import decompose
from strategies.policies.base import BasePolicy
from strategies.runner import run_episode

OVERRIDES = {"l_min": 2.0, "l_max": 4.0, "v_pursuer": 1.0, "v_evader": 0.5}


class StandStill(BasePolicy):
    """A pursuer that does not move (it kept the old plan looping)."""

    roles = ("pursuer",)

    def _decide(self, snap):
        return np.zeros(2)


@pytest.mark.parametrize("world", [crossroads(), t_junction()], ids=lambda m: m.name)
def test_prop2_holds_on_these_worlds(world):
    assert decompose(world, 2.2).evader_wins  # L_min + body radius


@pytest.mark.parametrize("world", [crossroads(), t_junction()], ids=lambda m: m.name)
@pytest.mark.parametrize("pursuer", ["still", "pursuer/greedy", "pursuer/decomposition"])
def test_the_shooting_evader_escapes_every_episode(world, pursuer):
    x0, y0, x1, y1 = world.bounds
    diameter = math.hypot(x1 - x0, y1 - y0)
    horizon = 2.0 * diameter / OVERRIDES["v_evader"]  # seconds
    for seed in range(6):
        p = StandStill() if pursuer == "still" else pursuer
        r = run_episode(world, p, "evader/shooting", seed, max_cycles=int(horizon / 0.1),
                        start="valid", overrides=OVERRIDES)  # fmt: skip
        assert r.winner == "evader", r.summary()
