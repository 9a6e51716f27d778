"""The shooting evader against a pursuer that does not turn the rod (issue 13).

A radial follower (the greedy pursuer, a tractrix, one that stands still while the
range is mid-band or aims at the evader's extrapolated position) moves only along the
rod. Where the evader's plan promises nothing (a rank of at least n_cells), walking it
lets such a pursuer back off, and the charge that pins it begins again: on
``random:star:12`` (L_min 2, L_max 4, rho 0.3, seed 7004) against the greedy pursuer
holding the band's middle the evader alternated the two and escaped at 4.68 D / V_e
(the herd pinning the pursuer at last; 4.3-5.0 against a lazy and a lead pursuer of
task F's probe). Against a pursuer whose speed across the rod averages below
``RADIAL_SHARE`` V_e the plan no longer takes over from pressure: 0.69 D / V_e. The
decomposition pursuer turns the rod (0.55-0.71 V_p across it on average), and against
it the evader walks such a plan as before.
"""

from __future__ import annotations

import math

from envs.maps import load_map
from strategies.policies import make_policy
from strategies.policies.shooting import ShootingEvader
from strategies.runner import run_episode

PARAMS = {"l_min": 2.0, "l_max": 4.0, "v_pursuer": 1.0, "v_evader": 0.3, "body_radius": 0.1}


def _horizon(m, k: float) -> int:
    """``k`` D / V_e in steps (D the bounding-box diagonal)."""
    x0, y0, x1, y1 = m.bounds
    return math.ceil(k * math.hypot(x1 - x0, y1 - y0) / PARAMS["v_evader"] / 0.1)


def test_charges_on_against_a_pursuer_that_does_not_turn_the_rod():
    m = load_map("random:star:12")
    ev = ShootingEvader()
    modes: dict[str, int] = {}

    def count(_):
        modes[ev.mode] = modes.get(ev.mode, 0) + 1

    pursuer = make_policy("pursuer/greedy", target=0.5)
    r = run_episode(m, pursuer, ev, 7004, start="safe", overrides=PARAMS,
                    max_cycles=_horizon(m, 2.0), on_step=count)  # fmt: skip
    assert r.winner == "evader", (r.summary(), modes)  # 4.68 D / V_e before
    assert ev._across < ShootingEvader.RADIAL_SHARE * ev._across_n  # a radial follower


def test_the_decomposition_pursuer_counts_as_turning_the_rod():
    m = load_map("random:star:12")
    ev = ShootingEvader()
    run_episode(m, "pursuer/decomposition", ev, 7004, start="safe", overrides=PARAMS,
                max_cycles=200)  # fmt: skip
    assert ev._across_n >= ShootingEvader.RADIAL_STEPS
    assert ev._across >= ShootingEvader.RADIAL_SHARE * ev._across_n
