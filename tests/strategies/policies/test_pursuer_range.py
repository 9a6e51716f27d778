"""The decomposition pursuer closes in to its target distance while it turns hard.

Its safety table is built for the rod L_target + body radius; a longer rod has fewer
free orientations (Prop. 3), so an orientation the table calls clear can be blocked for
the real rod. Before, a turn the pursuer wanted at full rate took all of V_p and the
distance drifted with the evader's radial motion: in the pillar room, from a safe start
at L = 2.45 against the wall-hugging evader, L grew to 2.57 while the pursuer swung the
rod under the triangular pillar, and the pillar's vertex occluded the evader at t = 4.9 s
(issue 13). Now part of V_p is kept for closing in while L exceeds its target.
"""

from __future__ import annotations

import numpy as np

from strategies.policies import make_policy
from strategies.runner import run_episode


def test_the_pursuer_closes_in_while_it_turns():
    pursuer = make_policy("pursuer/decomposition")
    r = run_episode("pillars", pursuer, "evader/wall_hugging", 5, start="safe", max_cycles=60)
    assert r.winner == "pursuer", r.summary()
    L = np.linalg.norm(r.trajectory[:, 0] - r.trajectory[:, 1], axis=1)
    assert L[0] > pursuer.L_target + 0.3  # starts far out
    assert L[20:].max() < pursuer.L_target + 0.05  # within 2 s at its distance, and stays
