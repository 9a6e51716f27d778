"""The decomposition pursuer's orbit choice gives way to its own turn off a wall (issue 13).

Against a charge with a circle within reach, the hard turn toward that circle gives way to
the decomposition's own turn when the hard turn's path meets a wall within
``ORBIT_LOOKAHEAD`` whatever the evader does (``_orbit_choice``). It gave way only where
the own turn's path was clear for all of ``WALL_HORIZON``: on the paper's L-shaped hall
turned by 0.37 rad (rho 0.5), an evader nobody had written for it (session 26's "shadow"
evader, which heads for the shadow a convex corner casts from the pursuer) walked the
pursuer into the square pillar's corner from a safe start: the hard ccw turn's wall was
0.1 s ahead (the body already touching it), the decomposition's cw turn met a wall only
2.0 s ahead with the evader following the rod, so the hard turn stood and the pursuer
pushed into the pillar for three steps: too close at 1.31 s. A circle that needs the
pursuer to pass through a wall first is not one it will reach; the own turn now wins
when its path stays clear for ``ORBIT_LOOKAHEAD`` in both modes.
"""

from __future__ import annotations

import math

import numpy as np

from strategies.policies.base import BasePolicy
from strategies.runner import run_episode

# the shadow evader's walk from the start below: its headings (degrees), one a step
_WALK = (-34.6, -34.9, -35.4, -35.8, -36.1, -36.4, -36.7, -37.1, -6.0, -6.0, -5.8, -5.8)


class _ScriptedWalk(BasePolicy):
    """Full speed on a fixed schedule of headings (the recorded walk, open loop)."""

    roles = ("evader",)

    def _decide(self, snap):
        a = _WALK[min(self._steps, len(_WALK) - 1)]
        return self.v_max * np.array([math.cos(math.radians(a)), math.sin(math.radians(a))])


def test_the_hard_turn_gives_way_when_it_would_push_into_a_wall_at_once():
    start = {"pursuer": (0.1326908662063826, 5.406267427161315),
             "evader": (-0.9361936868315048, 7.610804977822903)}  # fmt: skip
    ov = {"l_min": 2.0, "l_max": 4.0, "v_pursuer": 1.0, "v_evader": 0.5, "body_radius": 0.2}
    r = run_episode("l_hall~rot0.37", "pursuer/decomposition", _ScriptedWalk(), 0,
                    max_cycles=60, overrides=ov, start=start)  # fmt: skip
    assert r.winner == "pursuer", (r.cause, r.escape_time)
