"""The decomposition pursuer's pin override (``_avoid_pin``) stands down against an
evader that reverses its velocity every step (issue 13, the herder at a concave corner).

The herder (benchmarks/unseen_opponents.py) heads opposite the pursuer's nearest wall
point; at a concave corner's bisector that point alternates between the two walls and the
herder's velocity reverses every step. The override's wall-path check extrapolates the
evader's velocity for two seconds, so it fired on every other step and undid the
decomposition's turn in between: the rod stood still while the herder walked the
pursuer into the corner.
"""

from __future__ import annotations

import numpy as np
import pytest

from strategies.runner import run_episode
from tests.strategies.policies.conftest import decomposition_pursuer


def test_a_herder_at_a_corner_bisector_does_not_pin_the_pursuer(unseen):
    """Fresh random world rand:rectangles:3005:3.0 at (rho, L_max / L_min, L_min) =
    (0.5, 2, 2), the benchmark's seed: lost by "too_close" at 16.1 s before, after 36
    steps of the override firing on every other step."""
    m, ov = unseen.pursuer_world("rand:rectangles:3005:3.0", list(unseen.PURSUER_COMBOS[0]))
    herder = unseen.make_opponent("herder")
    r = run_episode(m, "pursuer/decomposition", herder, 101, max_cycles=600, overrides=ov,
                    start="safe")  # fmt: skip
    assert r.winner == "pursuer", r.summary()


@pytest.mark.parametrize(
    ("history", "now", "chatters"),
    [
        ([(0.5, 0.0), (-0.5, 0.1)], (0.5, 0.0), True),  # reversed twice running
        ([(0.5, 0.0), (0.5, 0.1)], (-0.5, 0.0), False),  # a zig-zag's one flip
        ([(0.5, 0.0), (-0.5, 0.1)], (-0.4, 0.3), False),  # reversed once, then kept
        ([(0.5, 0.0), (0.4, 0.2)], (0.3, 0.3), False),  # kept
        ([(-0.5, 0.1)], (0.5, 0.0), False),  # one step of history is not enough
    ],
)
def test_chatter_is_two_reversals_running(history, now, chatters):
    p = decomposition_pursuer()
    for v in history:
        p._velocities.append(v)
    assert p._chatters(np.array(now)) is chatters
