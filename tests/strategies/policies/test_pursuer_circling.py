"""The decomposition pursuer against an evader circling a small obstacle (issue 13).

An obstacle whose convex hull's perimeter is within the evader's circle at the rod's least
turn rate (``2 pi V_e / omega``) is one the evader can go round faster than the straight
probes foresee: the pursuer probes round every corner of the walk along it
(:meth:`DecompositionPursuer._walk_corners`).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from envs.maps import Map
from envs.surveillance.config import EnvConfig
from strategies.policies import make_policy
from strategies.runner import build_env
from tests.strategies.policies.conftest import decomposition_pursuer, orbit_episode


def _pursuer(world: Map, rho: float = 0.5, body: float = 0.1):
    config = EnvConfig(
        map=world, l_min=2.0, l_max=4.0, v_pursuer=1.0, v_evader=rho, body_radius=body
    )
    return decomposition_pursuer(config)


def _room(side: float) -> Map:
    """A 12 x 8 room with a square pillar of side ``side`` at (5, 3)."""
    x, y = 5.0, 3.0
    pillar = [(x, y), (x + side, y), (x + side, y + side), (x, y + side)]
    return Map([(0, 0), (12, 0), (12, 8), (0, 8)], [pillar], name=f"pillar_{side}")


@pytest.mark.parametrize(
    ("world", "seconds", "base_loss"),
    [("rand:star:3007:3.0", 16.0, 14.0), ("rand:polygons:3005:3.0", 19.0, 17.0)],
)
def test_an_evader_circling_a_small_obstacle_is_held(unseen, world, seconds, base_loss):
    # the fresh_p0 losses to the orbit (offset 0.25, ccw) at rho 0.5, L_min 2: both
    # regrets by hindsight; before the walk's corners were probed, occluded at 14.0 s and
    # 17.0 s (the rod idled at a near target, then the best orientation jumped ~120
    # degrees ahead of it); held beyond that now
    r = orbit_episode(unseen, world, round(seconds / 0.1))
    assert r.winner == "pursuer", (r.summary(), base_loss)


def test_only_obstacles_within_the_evaders_circle_are_walked_round():
    # rho 0.5, L_min 2: omega = sqrt(0.75) / 2, the circle 2 pi V_e / omega = 7.26 long
    assert _pursuer(_room(2.0))._small is None  # perimeter 8
    small = _pursuer(_room(1.5))._small  # 6
    assert small is not None and list(small.perimeter) == [1]
    assert small.perimeter[1] == pytest.approx(6.0)
    assert len(small.corners[1]) == 4
    # a slower evader's circle is shorter: 2 pi 0.3 / (sqrt(0.91) / 2) = 3.95
    assert _pursuer(_room(1.5), rho=0.3)._small is None
    assert _pursuer(_room(0.9), rho=0.3)._small is not None  # 3.6
    # the built-in worlds' obstacles (pillars, maze walls, the L-hall's pillar) are larger
    for name in ("pillars", "maze", "l_hall"):
        config = build_env(name, {"v_evader": 0.5}).config
        p = make_policy("pursuer/decomposition")
        p.reset(role="pursuer", map=config.map, config=config, seed=0)
        assert p._small is None, name


def test_a_non_convex_obstacle_is_measured_by_its_hull():
    # a U-shaped obstacle: perimeter 8.4, its hull's 5.6 (the evader walks past the pocket)
    u = [(5, 3), (6.4, 3), (6.4, 4.4), (6.0, 4.4), (6.0, 3.6), (5.4, 3.6), (5.4, 4.4), (5, 4.4)]
    world = Map([(0, 0), (12, 0), (12, 8), (0, 8)], [u], name="u_pillar")
    small = _pursuer(world)._small
    assert small is not None and small.perimeter[1] == pytest.approx(5.6)
    assert len(small.corners[1]) == 4  # the pocket's corners are not on the hull


def test_every_corner_of_the_walk_round_a_small_obstacle_is_probed():
    # a 1 x 1 pillar (5, 3) .. (6, 4); the evader hugs its south face walking east, so
    # round it counter-clockwise: (6, 3) and (6, 4) are the corners ahead that
    # _corners_in_reach probes anyway; (5, 4) comes 2.6 along the walk, within the
    # probes' reach V_e (pi / omega - t_e) = 3.33, and (5, 3), 3.6 along it, is not
    p = _pursuer(_room(1.0))
    e, v = np.array([5.4, 2.85]), np.array([0.5, 0.0])
    probes = p._corners_in_reach(e, v)
    vertices = [tuple(np.round(p._corner_vertex[_index(p, s)], 6)) for s, *_ in probes]
    assert vertices == [(6.0, 3.0), (6.0, 4.0), (5.0, 4.0)]
    _, delay, rays, sense = probes[2]
    assert delay == pytest.approx(2.6 / 0.5)
    assert sense == 1  # the walk turns ccw round it, so must the rod
    assert rays.any() and np.all(p._dirs[rays][:, 1] <= 1e-9)  # round it: down its west face
    # walking west instead: (5, 3) first, then (5, 4) and (6, 4) along the walk (2.4)
    back = p._corners_in_reach(e, -v)
    vertices = [tuple(np.round(p._corner_vertex[_index(p, s)], 6)) for s, *_ in back]
    assert vertices == [(5.0, 3.0), (5.0, 4.0), (6.0, 4.0)]
    assert back[2][1] == pytest.approx(2.4 / 0.5) and back[2][3] == -1
    # not walking along it (heading away from the wall), or off it: no walk
    assert p._walk_corners(e, 0.0, -0.5, 0.5, 3.3, []) == []
    assert p._walk_corners(np.array([5.4, 2.4]), 0.5, 0.0, 0.5, 3.3, []) == []
    # the walk's probes lower the value of the orientation behind (5, 4): the rod
    # pointing north-west from the evader, where the walk brings it next
    row = p.table.row(e)
    b = p.table.bin_of(math.radians(120.0))
    without = p._probe_values(e)
    for s, d, r, sn in probes[:2]:
        without = np.minimum(without, p._probe_values(s, d, r, sn))
    assert p._values(e, row, v)[b] < without[b]


def _index(p, start: np.ndarray) -> int:
    return int(np.flatnonzero(np.all(p._corners == start, axis=1))[0])
