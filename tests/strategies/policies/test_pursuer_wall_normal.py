"""The decomposition pursuer does not let an override turn the rod back into a wall's
normal (issue 13, the herder's pins).

A charger running straight at a pursuer that slides along a wall closes in while the rod
lies within asin(rho) of the wall's normal. The herder (benchmarks/unseen_opponents.py)
repositions opposite the pursuer's nearest wall and charges; before, ``_keep_orbit``'s
wall-path fallback (where no circle is within reach) could override the decomposition's
turn away from the normal with a hard turn back through it.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from strategies.policies import decomposition, make_policy
from strategies.policies.base import Snapshot
from strategies.runner import build_env, run_episode


def test_a_herded_pursuer_keeps_off_the_wall(unseen):
    """Fresh random world rand:polygons:3008:3.0 at (rho, L_max / L_min, L_min) =
    (0.5, 2, 2), the benchmark's seed: lost by "too_close" at 32.4 s before."""
    m, ov = unseen.pursuer_world("rand:polygons:3008:3.0", list(unseen.PURSUER_COMBOS[0]))
    herder = unseen.make_opponent("herder")
    r = run_episode(m, "pursuer/decomposition", herder, 101, max_cycles=340, overrides=ov,
                    start="safe")  # fmt: skip
    assert r.winner == "pursuer", r.summary()


def _at_the_south_wall(psi_deg: float, y: float = 1.0):
    """open_room (10 x 10, rho 0.5): the pursuer at height y, the rod psi_deg off the
    south wall's normal (pointing down), at L_target."""
    config = build_env("open_room", {}).config
    p = make_policy("pursuer/decomposition")
    p.reset(role="pursuer", map=config.map, config=config, seed=0)
    L = p.L_target
    theta = -0.5 * math.pi + math.radians(psi_deg)
    u = np.array([math.cos(theta), math.sin(theta)])
    pursuer = np.array([5.0, y])
    snap = Snapshot(pursuer - L * u, pursuer, 0.5 * u, 0.5 * u, 0.0)
    return p, snap, L


def test_an_override_into_the_normal_gives_way():
    p, snap, L = _at_the_south_wall(10.0)  # rod 10 deg ccw of the normal, cone 30 deg
    assert p._off_the_normal(snap, 0.2, -0.4, L) == 0.2  # cw turns back into it
    assert p._off_the_normal(snap, 0.2, 0.7, L) == 0.7  # a harder turn away stands
    assert p._off_the_normal(snap, -0.1, -0.4, L) == -0.4  # own turns into it too
    p, snap, L = _at_the_south_wall(-10.0)  # mirrored
    assert p._off_the_normal(snap, -0.2, 0.4, L) == -0.2


@pytest.mark.parametrize(("psi", "y"), [(40.0, 1.0), (10.0, 3.0)])
def test_outside_the_cone_or_away_from_walls_an_override_stands(psi, y):
    # 40 deg > asin(0.5); 3 m from the wall > L
    p, snap, L = _at_the_south_wall(psi, y)
    assert p._off_the_normal(snap, 0.2, -0.4, L) == -0.4


def test_a_herded_pursuer_at_a_straight_wall_does_not_swing_through_the_normal(unseen):
    """Held-out world rand:star:2007:3.5 at combo 0, the benchmark's seed, the whole
    episode: lost by "too_close" at 9.8 s before (``_keep_orbit``'s swings toward a
    circle within reach took the rod back through the wall's normal while the herder
    pushed it there)."""
    m, ov = unseen.pursuer_world("rand:star:2007:3.5", list(unseen.PURSUER_COMBOS[0]))
    herder = unseen.make_opponent("herder")
    r = run_episode(m, "pursuer/decomposition", herder, 101, max_cycles=600, overrides=ov,
                    start="safe")  # fmt: skip
    assert r.winner == "pursuer", r.summary()


def test_a_swing_toward_a_circle_gives_way_only_to_a_herding_evader():
    p, snap, L = _at_the_south_wall(20.0)  # rod 20 deg ccw of the normal
    assert p._off_the_normal(snap, 0.2, -0.4, L, herding=True) == -0.4  # no sign yet
    p._crossings.append(None)  # a charge step
    assert p._off_the_normal(snap, 0.2, -0.4, L, herding=True) == -0.4
    p._crossings.append((snap.theta, -0.4))  # crossing away from the normal
    assert p._off_the_normal(snap, 0.2, -0.4, L, herding=True) == -0.4
    p._crossings.append((snap.theta, 0.4))  # across > 0 turns the rod cw, to the normal
    assert p._off_the_normal(snap, 0.2, -0.4, L, herding=True) == 0.2
    # the sign lasts ORBIT_LOOKAHEAD seconds of steps
    for _ in range(round(p.ORBIT_LOOKAHEAD / p.config.dt)):
        p._crossings.append(None)
    assert p._off_the_normal(snap, 0.2, -0.4, L, herding=True) == -0.4


def test_a_swing_toward_a_circle_stands_unless_the_charge_is_pure_pursuit():
    """The slide's theory is a charge along the rod; the velocity estimate is one step
    old, so it may lie off the rod by the rod's turn in that step, V_p dt / L."""
    p, snap, L = _at_the_south_wall(20.0)
    p._crossings.append((snap.theta, 0.4))  # herded toward the normal
    lag = p.config.v_pursuer * p.config.dt / L
    for off, vetoed in ((0.9 * lag, True), (1.1 * lag, False), (0.5, False)):
        a = snap.theta + off
        ve = 0.5 * np.array([math.cos(a), math.sin(a)])
        s = Snapshot(snap.evader, snap.pursuer, ve, ve, 0.0)
        assert p._off_the_normal(s, 0.2, -0.4, L, herding=True) == (0.2 if vetoed else -0.4)
    s = Snapshot(snap.evader, snap.pursuer, -snap.evader_velocity, ve, 0.0)  # running away
    assert p._off_the_normal(s, 0.2, -0.4, L, herding=True) == -0.4


def test_the_slide_floor_is_the_closed_form():
    """helper-99's integration (dt 1e-4, issue 13): from the normal 0.877 at rho 0.5 and
    0.955 at rho 0.3; from 20 deg past the normal 0.690, from 20 deg short 0.985."""
    f = decomposition._slide_floor
    assert f(math.pi / 2, 0.5) == pytest.approx(0.877, abs=5e-4)
    assert f(math.pi / 2, 0.3) == pytest.approx(0.955, abs=5e-4)
    assert f(math.radians(110.0), 0.5) == pytest.approx(0.690, abs=5e-4)
    assert f(math.radians(70.0), 0.5) == pytest.approx(0.985, abs=5e-4)
    assert f(math.radians(55.0), 0.5) == 1.0  # cos phi > rho: the range never falls


def test_the_slide_floor_against_a_direct_integration():
    rho, phi, r, dt = 0.5, math.radians(105.0), 1.0, 1e-4
    least = r
    while math.cos(phi) < rho:  # V_p = 1
        r += (math.cos(phi) - rho) * dt
        phi -= math.sin(phi) / r * dt
        least = min(least, r)
    assert decomposition._slide_floor(math.radians(105.0), rho) == pytest.approx(least, rel=1e-3)


@pytest.mark.parametrize("psi", [5.0, 8.0])
def test_near_the_normal_a_swing_toward_a_circle_stands(psi):
    """At L_target = 1.06 L_min both slides end closer than L_min from within about
    10 deg of the normal at rho 0.5 (0.877 from on it): the cone does not choose."""
    p, snap, L = _at_the_south_wall(psi)
    p._crossings.append((snap.theta, 0.4))
    assert L * decomposition._slide_floor(math.pi / 2 - math.radians(psi), 0.5) < 2.0
    assert p._off_the_normal(snap, 0.2, -0.4, L, herding=True) == -0.4


def test_at_a_corner_a_swing_toward_a_circle_stands():
    """The cone is a straight wall's: where the pursuer's nearest wall point is a
    vertex (the corner world's inner corner at (5, 5)), the swing stands."""
    config = build_env("corner", {}).config
    p = make_policy("pursuer/decomposition")
    p.reset(role="pursuer", map=config.map, config=config, seed=0)
    L = p.L_target
    theta = math.radians(45.0 + 20.0)  # 20 deg off the normal toward (5, 5)
    u = np.array([math.cos(theta), math.sin(theta)])
    pursuer = np.array([4.3, 4.3])
    snap = Snapshot(pursuer - L * u, pursuer, 0.5 * u, 0.5 * u, 0.0)
    p._crossings.append((theta, 0.4))  # herded toward the normal
    assert p._off_the_normal(snap, 0.2, -0.4, L) == 0.2  # the wall-path veto: no change
    assert p._off_the_normal(snap, 0.2, -0.4, L, herding=True) == -0.4
    # the same rod and sign 0.7 from a straight wall: the swing gives way
    p, snap, L = _at_the_south_wall(20.0, y=0.7)
    p._crossings.append((snap.theta, 0.4))
    assert p._off_the_normal(snap, 0.2, -0.4, L, herding=True) == 0.2
