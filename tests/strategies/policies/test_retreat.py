"""The decomposition pursuer's retreat room (Sec. 5 with the pursuer's own clearance).

* ``retreat_times`` against a brute force: the geometry kernel's exact ray distances.
* A pursuer whose rod points at a nearby wall, with the evader charging along the rod,
  turns toward orientations with more room, not into the wall.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from analysis.evaluate import make_env
from envs.geometry import kernel_for
from strategies.policies.base import Snapshot
from strategies.policies.decomposition import DecompositionPursuer


def _pursuer(map_name: str) -> DecompositionPursuer:
    cfg = make_env(map_name).config
    pol = DecompositionPursuer(resolution=0.1)
    pol.reset(role="pursuer", map=cfg.map, config=cfg, seed=0)
    return pol


@pytest.mark.parametrize("map_name", ["open_room", "maze"])
def test_retreat_times_match_exact_ray_distances(map_name):
    pol = _pursuer(map_name)
    c = pol.config
    kernel = kernel_for(c.map)
    tab = pol.table
    rng = np.random.default_rng(3)
    xmin, ymin, xmax, ymax = c.map.bounds
    bins = np.arange(0, tab.n_bins, pol._room_step)
    ang = tab.bin_centre(bins)
    checked = 0
    while checked < 20:
        e = rng.uniform((xmin, ymin), (xmax, ymax))
        if not c.map.contains(e[None])[0] or c.map.distance_to_walls(e[None])[0] < 0.3:
            continue
        got = pol.retreat_times(e)[bins]
        h = tab.resolution

        def room(d):
            return np.minimum((d - c.body_radius - pol.L_target) / c.v_evader, pol.horizon)

        want = room(kernel.ray_distances(e, ang, 50.0))
        # the grid marches in steps h and snaps the evader and each sample to grid points,
        # shifting a ray sideways by up to sqrt(2) h: a ray grazing a wall may stop early
        # or late, so the bounds are rays shifted sideways by 1.5 h
        normal = np.stack([-np.sin(ang), np.cos(ang)], axis=1)
        lo, hi = want.copy(), want.copy()
        for sgn in (-1.5, 1.5):
            for k, (a, n) in enumerate(zip(ang, normal, strict=True)):
                o = e + sgn * h * n
                if c.map.contains(o[None])[0]:
                    r = room(kernel.ray_distances(o, [a], 50.0))[0]
                    lo[k], hi[k] = min(lo[k], r), max(hi[k], r)
        tol = 2.0 * h / c.v_evader
        assert np.all(got <= hi + tol), (e, np.max(got - hi))
        assert np.all(got >= lo - tol), (e, np.max(lo - got))
        checked += 1


def test_rod_pointing_at_a_near_wall_turns_toward_room():
    pol = _pursuer("open_room")
    c = pol.config
    xmin, _, _, ymax = c.map.bounds
    e = np.array([xmin + pol.L_target + 0.6, 0.5 * ymax])  # 0.6 from pinning the pursuer
    theta = math.pi  # the rod points at the wall x = xmin
    p = e + pol.L_target * np.array([math.cos(theta), math.sin(theta)])
    charge = c.v_evader * np.array([math.cos(theta), math.sin(theta)])
    snap = Snapshot(e, p, charge, charge, 0.0)
    room = pol.retreat_times(e)
    b0 = pol.table.bin_of(theta)
    rot, target = pol._target(snap)
    assert rot != 0.0
    assert room[target] > room[b0] + 1.0
