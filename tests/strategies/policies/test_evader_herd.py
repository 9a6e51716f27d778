"""The shooting evader's herd (its last resort after a long charge, issue 13).

With the trail of ``n_cells + 1`` crossings (test_evader_escapes_trail.py) the evader
loses two escapes of the unseen-worlds benchmark that its charge and herd had won by
luck, each against the decomposition pursuer at rho 0.3:

* ``random:star:11`` [0.3, 1.5, 2] seed 507: from ~160 s the charge settles into a loop
  (period ~51 s) in the open, the pursuer orbiting the evader; the herd started only
  from a step where the pursuer came within L_min of a concave corner, which the old
  path's orbit happened to do at ~360 s and the new one never does. Now it starts from
  within L_max (the pursuer's leash): escaped 465.0 s (6.13 D / V_e).
* ``office`` at half scale [0.3, 2, 2] seed 909: the herd froze for the last 270 s of
  the horizon with the evader pressed against a wall, its target (the far side of the
  pursuer from the corner) across that wall. Now a herd heading into a wall slides
  along it, as the charge does: escaped 531.9 s (5.53 D / V_e).

Both are decisions of the pressure branch, tested here from the frozen states.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from envs.maps import builtin_info, load_map
from envs.surveillance.config import EnvConfig
from strategies.policies.base import Snapshot
from strategies.policies.shooting import ShootingEvader


def _pressing(m, params, seed=0) -> ShootingEvader:
    """A shooting evader past its charge (``HERD_AFTER``) with no plan, shot or walk
    (the pressure branch decides)."""
    ev = ShootingEvader()
    ev.reset(role="evader", map=m, config=EnvConfig(map=m, **params), seed=seed)
    ev._plan_heading = lambda e, theta: None
    ev._best_candidate = lambda e, theta, in_sight=False: None
    ev._region_walk = lambda e: None
    ev._pressed = math.ceil(ev._herd_after) + 1
    return ev


def _snap(e, p) -> Snapshot:
    return Snapshot(np.array(e, float), np.array(p, float), np.zeros(2), np.zeros(2), 0.0)


def test_a_herd_into_a_wall_slides_along_it():
    # office~x0.5, seed 909 with the n_cells + 1 trail, from 500 s to the horizon: the
    # evader at the west face (x = 5.925) of a wall below a door, the pursuer in the
    # door, the herd's target east of the wall
    m = builtin_info("office").map.transformed(0.5 * np.eye(2))
    params = {"l_min": 1.0, "l_max": 2.0, "v_pursuer": 0.5, "v_evader": 0.15,
              "body_radius": 0.05}  # fmt: skip
    ev = _pressing(m, params)
    ev._herding = True
    e, p = np.array([5.88, 5.935]), np.array([6.177, 6.933])
    to = ev._herd(e, p, (p - e) / np.linalg.norm(p - e), float(np.linalg.norm(p - e)))
    assert to[0] > 0.9  # the herd heads into the wall
    v = ev._decide(_snap(e, p))
    assert math.hypot(*v) == pytest.approx(0.15)
    assert v[0] <= 1e-12  # not into the wall (its face is x = 5.925)
    assert abs(v[1]) == pytest.approx(0.15)  # along it
    # the step keeps the evader's clearance (brute force: the distance to the walls)
    d0, d1 = m.distance_to_walls(np.stack([e, e + 0.1 * v]))
    assert d1 >= d0 - 1e-12


def test_the_herd_starts_within_l_max_of_a_concave_corner():
    m = load_map("random:star:11")
    params = {"l_min": 2.0, "l_max": 3.0, "v_pursuer": 1.0, "v_evader": 0.3,
              "body_radius": 0.1}  # fmt: skip
    concave = m.vertices[~m.vertex_convex]
    ev = _pressing(m, params)
    # 2.83 from the room corner (0, 0), nearest of the concave corners: within L_max
    # but not L_min (before, the charge went on here)
    e, p = np.array([4.0, 2.0]), np.array([2.0, 2.0])
    dist = np.linalg.norm(concave - p, axis=1)
    assert 2.0 < dist.min() <= 3.0
    assert float(m.distance_to_walls(np.stack([e, p])).min()) > 0.5
    v = ev._decide(_snap(e, p))
    assert ev._herding
    assert np.allclose(v, 0.3 * ev._herd(e, p, (p - e) / 2.0, 2.0))
    # farther than L_max from every concave corner: it charges
    ev = _pressing(m, params)
    e, p = np.array([13.0, 5.5]), np.array([13.0, 3.5])
    assert np.linalg.norm(concave - p, axis=1).min() > 3.0
    assert float(m.distance_to_walls(np.stack([e, p])).min()) > 0.5
    v = ev._decide(_snap(e, p))
    assert not ev._herding
    assert np.allclose(v, [0.0, -0.3])
