"""The decomposition pursuer stops riding a circle short of room that does not come
nearer to room (issue 13).

Charged along the rod, the pursuer keeps or reaches an orbit about the evader
(``_keep_orbit``); a circle short of room by less than ``ORBIT_REACH`` x L counts as
within reach, and the pursuer turns hard round it. Usually the circle drifts to room.
Against an exact charge it does not (a hard turn keeps its centre where it is): on
held-out random maps a circle short by 0.39 stayed short for six seconds until the
charge pinned the pursuer against the wall, with room about 3 m away round the
obstacles. The geodesic way from a circle's centre to room (``_room_field``) now tells
a ride that has stalled (the way unchanged for a second), and the circles are then
scored by it. Scoring them by it always lost episodes where the ride does reach room
(L_12x5, U_14x10: the guards below).
"""

from __future__ import annotations

import numpy as np
import pytest

from envs.maps import Map, load_map
from envs.surveillance.config import EnvConfig
from strategies.policies import make_policy
from strategies.policies.decomposition import _clearance_grid, _room_field
from strategies.runner import run_episode


def _policy(world: Map):
    config = EnvConfig(map=world, l_min=2.0, l_max=4.0, v_pursuer=1.0, v_evader=0.5)
    p = make_policy("pursuer/decomposition", table="distinct")
    p.reset(role="pursuer", map=config.map, config=config, seed=0)
    return p


def test_the_field_is_the_way_to_room_in_an_open_room():
    p = _policy(Map([(0, 0), (12, 0), (12, 12), (0, 12)], [], name="box12"))
    h = p.table.resolution
    need = 4.0  # a wall distance of 4: the centre square [4, 8]^2
    field = _room_field(p.config.map, p.table, need)
    clear = _clearance_grid(p.config.map, p.table)
    assert np.all(field[clear >= need] == 0.0)
    assert np.all(field[(clear > 0.0) & (clear < need)] > 0.0)
    # straight away from the south wall, along the grid's axis: need - clearance
    for y in (0.5, 1.0, 2.5, 3.5):
        i, j = (round((v - float(p.table.origin[k])) / h) for k, v in enumerate((6.0, y)))
        assert field[i, j] == pytest.approx(need - y, abs=1.5 * h)


def test_the_field_goes_round_a_wall():
    # a 12 x 12 room whose south side is a 2-wide corridor running east under a 1-thick
    # wall from the west wall, open to the room at x > 10
    room = Map(
        [(0, 0), (12, 0), (12, 12), (0, 12), (0, 3), (10, 3), (10, 2), (0, 2)],
        [],
        name="ledge",
    )
    p = _policy(room)
    h = p.table.resolution
    need = 3.0
    field = _room_field(room, p.table, need)
    i, j = (round((v - float(p.table.origin[k])) / h) for k, v in enumerate((2.0, 1.0)))
    # room lies 3 m north of (2, 1) as the crow flies (y >= 6 clears the ledge by 3),
    # but the corridor leads east round the ledge's end at x = 10 first
    assert field[i, j] > 8.0
    assert np.isfinite(field[i, j])


@pytest.mark.parametrize(
    ("world", "combo", "opponent", "cycles"),
    [
        # lost by "too_close" at 10.1 s and 13.1 s before (held-out combos 0 and 1)
        ("rand:convex:2005:3.5", 0, "evader/shooting", 150),
        ("rand:rectangles:2008:3.5", 1, "evader/toward_away:toward", 180),
    ],
)
def test_a_charge_on_a_random_map_no_longer_pins_the_pursuer(
    unseen, world, combo, opponent, cycles
):
    m, ov = unseen.pursuer_world(world, list(unseen.PURSUER_COMBOS[combo]))
    r = run_episode(m, "pursuer/decomposition", unseen.make_opponent(opponent), 101,
                    max_cycles=cycles, overrides=ov, start="safe")  # fmt: skip
    assert r.winner == "pursuer", r.summary()


@pytest.mark.parametrize(
    ("world", "cycles"),
    # scored by the way to room from the start, the pursuer lost these at 28.5 s and
    # 17.3 s; a stall judged on the inner circle alone lost U_14x10 at 16.6 s
    [("L_12x5", 300), ("U_14x10", 190)],
)
def test_a_ride_that_reaches_room_is_not_stalled(unseen, world, cycles):
    m, ov = unseen.pursuer_world(world, list(unseen.PURSUER_COMBOS[0]))
    r = run_episode(m, "pursuer/decomposition", unseen.make_opponent("evader/shooting"), 101,
                    max_cycles=cycles, overrides=ov, start="safe")  # fmt: skip
    assert r.winner == "pursuer", r.summary()


_CORNER = {"l_min": 2.0, "l_max": 4.0, "v_pursuer": 1.0, "v_evader": 0.5, "body_radius": 0.2}
_CORNER_X10 = {"l_min": 20.0, "l_max": 40.0, "v_pursuer": 10.0, "v_evader": 5.0, "body_radius": 2.0}


@pytest.mark.parametrize(
    ("world", "overrides", "seed", "cycles"),
    [
        # the ridden circle stood still while the other came nearer to room, 0.08 m a
        # step (a stall judged on the nearer circle's way lost it at 14.4 s)
        ("corner~rot0.37", _CORNER, 0, 180),
        # the ridden circle short by 0.26, within its pad, for seconds (lost at 8.8 s)
        ("corner~rot0.37", _CORNER, 1, 120),
        # short by 2.87 (body 2, pad 3) but one step's 3.43 (lost at 48.3 s when the
        # last step's shortfall alone was read)
        ("corner~x10.0rot1.1", _CORNER_X10, 2, 500),
    ],
)
def test_a_ride_round_a_nearly_free_circle_is_not_stalled(world, overrides, seed, cycles):
    # the corner world's variants of the pursuer-holds benchmark: the rides there reach
    # room, or hold, where a stall lost 14 episodes to straight chargers (candidate 4)
    r = run_episode(load_map(world), "pursuer/decomposition", "evader/shooting", seed,
                    max_cycles=cycles, overrides=overrides, start="safe")  # fmt: skip
    assert r.winner == "pursuer", r.summary()


@pytest.mark.parametrize(
    ("evader", "seed", "cycles"),
    [
        # the ridden circle short by 0.2046 against a pad of 0.2 (its own circle touching
        # the corridor's wall): the stall lost it at 23.5 s (report row 5.1's tally)
        ("toward", 9, 300),
        # a stall 0.1 beyond the pad, then the wall check's clear hard turn took the
        # circles farther from room: lost at 44.6 s
        ("toward", 27, 500),
        # a stall 0.004 beyond the pad: lost at 17.9 s, and at 27.9 s with the field
        # condition on the wall check alone
        ("shooting", 20, 340),
    ],
)
def test_a_ride_along_a_wall_the_circle_just_touches_is_not_stalled(evader, seed, cycles):
    # the paper's corner world from the runner's default start (not the safe start of
    # the benchmark sets), rho = 0.5; a52b3bf held all three to the horizon
    opponent = (
        make_policy("evader/toward_away", mode=evader)
        if evader == "toward"
        else make_policy("evader/shooting")
    )
    r = run_episode("corner", "pursuer/decomposition", opponent, seed, max_cycles=cycles)
    assert r.winner == "pursuer", r.summary()
