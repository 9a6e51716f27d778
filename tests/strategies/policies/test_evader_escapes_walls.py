"""The shooting evader's fallbacks do not press it into a wall for good (issue 13).

Found by a sweep of worlds, speeds and pursuers the evader was not developed on; each
episode was held for the whole 8 D / V_e horizon before:

* ``random:rectangles:11``, rho = 0.3, against a pursuer that copies the evader's
  velocity (seed 337): the rod lay along a wall, and the pressure fallback's slide
  "perpendicular to the rod" pushed the evader straight into that wall for 5,865
  steps. It now slides the way that leaves the wall, and escapes in 0.67 D / V_e.
* ``random:convex:11``, rho = 0.8 against the registered greedy pursuer (seed 140) and
  rho = 0.95 against a greedy one with gain 1, target 0.6 (seed 1048): the best
  shooting probe lay behind the tip of a wall spike thinner than the grid, which the
  ray (cut at its first grid point off the free region) ran through; 2,158 and 1,561
  steps of shooting at it, pressed against the spike. Once an arc makes no headway, the
  probes it aims at are now in line of sight; they escape in 0.30 and 1.37 D / V_e.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from envs.maps import load_map
from strategies.policies import make_policy
from strategies.policies.base import BasePolicy
from strategies.runner import run_episode


class _Mirror(BasePolicy):
    """A pursuer that copies the evader's velocity (the rod only translates)."""

    roles = ("pursuer",)

    def _decide(self, snap):
        return np.array(snap.evader_velocity, dtype=float)


def _play(world: str, pursuer, seed: int, rho: float, ratio: float, k: float):
    m = load_map(world)
    params = {"l_min": 2.0, "l_max": 2.0 * ratio, "v_pursuer": 1.0, "v_evader": rho,
              "body_radius": 0.1}  # fmt: skip
    x0, y0, x1, y1 = m.bounds
    horizon = k * math.hypot(x1 - x0, y1 - y0) / rho  # k D / V_e, seconds
    return run_episode(m, pursuer, "evader/shooting", seed, start="safe",
                       max_cycles=math.ceil(horizon / 0.1), overrides=params)  # fmt: skip


def test_slides_off_a_wall_the_rod_lies_along():
    r = _play("random:rectangles:11", _Mirror(), 337, rho=0.3, ratio=1.5, k=1.5)
    assert r.winner == "evader", r.summary()


@pytest.mark.parametrize(
    ("pursuer", "seed", "rho", "k"),
    [("pursuer/greedy", 140, 0.8, 1.0), ("greedy gain 1", 1048, 0.95, 2.0)],
)
def test_shoots_only_at_probes_in_line_of_sight(pursuer, seed, rho, k):
    if pursuer == "greedy gain 1":
        pursuer = make_policy("pursuer/greedy", gain=1.0, target=0.6)
    r = _play("random:convex:11", pursuer, seed, rho=rho, ratio=2.0, k=k)
    assert r.winner == "evader", r.summary()
