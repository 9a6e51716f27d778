"""What the shooting evader's shots before a void plan check (issue 13): the disc can
follow the straight path to the target, and the margin is taken against the rod's present
length (a pursuer on a long rod turns slower than at L_min).

The room: 10 x 10 with a thin wall (0.05 thick) from the floor up to y = 5 at x = 5; the
evader's body radius 0.1, its centre at the wall's west face just below the tip.
"""

from __future__ import annotations

import numpy as np
import pytest

from envs.maps import Map
from envs.surveillance.config import EnvConfig
from strategies.policies.shooting import ShootingEvader

_WALL = [(4.975, 0.0), (5.025, 0.0), (5.025, 5.0), (4.975, 5.0)]
_E = np.array([4.875, 4.9])  # 0.1 from the wall's west face, 0.1 below its tip


@pytest.fixture(scope="module")
def evader() -> ShootingEvader:
    m = Map([(0, 0), (10, 0), (10, 10), (0, 10)], [_WALL], name="wall_tip", merge=True)
    ev = ShootingEvader()
    config = EnvConfig(map=m, l_min=2.0, l_max=6.0, v_pursuer=1.0, v_evader=0.2, body_radius=0.1)
    ev.reset(role="evader", map=m, config=config, seed=0)
    return ev


@pytest.mark.parametrize("q", [(5.2, 5.3), (5.2, 5.6), (5.0, 5.4)])
def test_a_target_round_the_tip_in_sight_of_the_point_is_not_one_the_disc_reaches(evader, q):
    # the straight paths pass 0.015, 0.049 and 0.073 from the tip: the disc (0.1) stops there
    q = np.array(q)
    assert evader.kernel.line_of_sight(_E, q)
    assert not evader._disc_reaches(_E, q, 0.1)


@pytest.mark.parametrize("q", [(4.9, 3.0), (4.95, 3.0), (4.5, 6.0)])
def test_a_target_along_the_wall_or_in_the_open_is_reached(evader, q):
    # along the wall to a target nearer it than the body radius (0.075, 0.025): the disc
    # slides along the wall to beside it; (4.5, 6) is clear of everything by 0.1
    assert evader._disc_reaches(_E, np.array(q), 0.1)


def test_a_target_across_the_wall_is_not_reached(evader):
    assert not evader._disc_reaches(_E, np.array([5.2, 3.0]), 0.1)


def test_a_long_rod_leaves_more_margin_than_l_min(evader):
    # the rod along +x (theta 0) from 0.975 west of the wall: at every candidate 0.3 away
    # the pursuer must turn it off the wall. Against a rod of 5.5 it turns slower (its
    # least rod length 5.5 - (V_p + V_e) t, never below L_min, not L_min throughout): every
    # margin is larger (0.16-0.46 rad at L_min, 0.55-0.90 at 5.5)
    e = np.array([4.0, 3.0])
    ang = np.linspace(0.0, 2.0 * np.pi, 48, endpoint=False)
    cand = e + 0.3 * np.stack([np.cos(ang), np.sin(ang)], axis=1)
    short, _ = evader._margins(e, 0.0, cand)
    long, _ = evader._margins(e, 0.0, cand, rod=5.5)
    assert np.isfinite(short).all()
    assert (long > short + 0.1).all()
    # a rod at L_min: L_min's margins exactly
    same, _ = evader._margins(e, 0.0, cand, rod=2.0)
    assert np.array_equal(same, short)


def _grazing(evader):
    """A rod of 5 from (4.7, 5.3) down to the right, 0.027 clear of the wall's tip: the
    pursuer at (8.53, 2.09), the candidates 0.3, 0.6 and 0.9 away (24 directions)."""
    e, theta, rod = np.array([4.7, 5.3]), np.radians(-40.0), 5.0
    ang = np.linspace(0.0, 2.0 * np.pi, 24, endpoint=False)
    ring = np.stack([np.cos(ang), np.sin(ang)], axis=1)
    cand = np.concatenate([e + r * ring for r in (0.3, 0.6, 0.9)])
    return e, theta, rod, cand, evader.table.rows(cand)


def test_against_the_reach_a_step_past_the_tip_a_long_rod_grazes_has_a_margin(evader):
    # a step west of the tip puts it across the rod: the pursuer 5 m out must swing the
    # rod's far end round the tip. Eq. 6 lets it shorten the rod at V_p + V_e and turn at
    # the short rod's rate at once: no candidate 0.6 away has a margin; against where
    # it can be by then (within V_p t of where it is), five do, and the margins are the
    # larger of the two
    e, theta, rod, cand, rows = _grazing(evader)
    rate, _ = evader._rate_margins(e, theta, cand, rows, rod)
    reach, _ = evader._reach_margins(e, theta, cand, rows, rod)
    mid = slice(24, 48)
    assert (rate[mid] <= 0.0).all()
    assert (reach[mid] > 0.0).sum() == 5
    both, _ = evader._margins(e, theta, cand, rows, rod)
    assert np.array_equal(both, np.maximum(rate, reach))


def test_a_reach_margin_is_positive_only_where_no_orientation_in_reach_is_safe(evader):
    # the orientations the pursuer can give the rod at q: within asin(R / d) of the
    # direction from q to where it is now; bin by bin, a safe one among them exactly
    # where the margin is not positive
    e, theta, rod, cand, rows = _grazing(evader)
    reach, _ = evader._reach_margins(e, theta, cand, rows, rod)
    tab = evader.table
    p = e + rod * np.array([np.cos(theta), np.sin(theta)])
    finite = np.flatnonzero(np.isfinite(reach))
    assert len(finite) > 20 and (reach[finite] > 0).any() and (reach[finite] <= 0).any()
    for i in finite.tolist():
        q = cand[i]
        d = np.linalg.norm(p - q)
        turn = np.arcsin(1.0 * np.linalg.norm(q - e) / 0.2 / d)  # R = V_p |q - e| / V_e
        b = tab.bin_of(float(np.arctan2(*(p - q)[::-1])))
        k = int(turn // tab.bin_width)
        reachable = [(b + j) % tab.n_bins for j in range(-k, k + 1)]
        assert tab.safe[rows[i], reachable].any() == (reach[i] <= 0.0), (q, reach[i])


@pytest.mark.parametrize(("rod", "t"), [(5.8, 1.2), (5.8, 4.0), (2.0, 1.0), (3.0, 0.5)])
def test_the_most_a_shortening_rod_turns_is_eq_6_s_largest_rate_integrated(rod, t):
    # (V_p + V_e) / L(t), L shortening at V_p + V_e from `rod` down to L_min: the bound a
    # two-leg shot takes off its margins for the first leg (V_p 1, V_e 0.2, L_min 2)
    from strategies.policies.shooting import _most_turn

    s = (np.arange(200_000) + 0.5) * t / 200_000
    rate = 1.2 / np.maximum(2.0, rod - 1.2 * s)
    assert _most_turn(1.2, rod, 2.0, t) == pytest.approx(rate.sum() * t / 200_000, rel=1e-6)


# ---------------------------------------------------------------- the two-leg look
# (ShootingEvader._via_corner: where no straight shot on a long rod has a positive margin,
# first to the point beside a convex corner, then a shot from there; the wall's tip has two
# such points, 0.3 west and east of it)


def _every_corner_in_full(ev, e, theta, p, rod):
    """The two-leg look as first written (37bf9d1): per corner, nearest first, its first
    leg's checks, then the candidates and margins from its point, then the second leg's.
    Returns the look's answer and whether any corner's point had a positive margin."""
    from strategies.policies.shooting import _most_turn

    c = ev.config
    pts = ev._corner_points
    dist = np.linalg.norm(pts - e, axis=1)
    floor = min(c.body_radius, float(ev.map.distance_to_walls(e[None])[0]))
    positive = False
    for i in np.argsort(dist, kind="stable").tolist():
        if dist[i] > ev._n_r * ev.table.resolution:
            break
        t1 = float(dist[i]) / c.v_evader
        turn1 = _most_turn(c.v_pursuer + c.v_evader, rod, c.l_min, t1)
        if turn1 >= np.pi:
            break
        q0 = pts[i]
        if dist[i] <= c.v_evader * c.dt or ev._corner_rows[i] < 0 or ev._near_banned(q0[None])[0]:
            continue
        rays, ray_rows, corners, corner_rows = ev._candidates(q0)
        cand = np.concatenate([rays, corners])
        rows = np.concatenate([ray_rows, corner_rows])
        rod1 = max(c.l_min, rod - (c.v_pursuer + c.v_evader) * t1)
        margin = ev._rate_margins(q0, theta, cand, rows, rod1)[0] - turn1
        reach = ev._reach_margins(q0, theta, cand, rows, rod, p=p, lead=t1)[0]
        margin = np.maximum(margin, reach)
        margin[ev._near_banned(cand)] = -np.inf
        if not len(margin) or margin.max() <= 0.0:
            continue
        positive = True
        if not ev.kernel.line_of_sight(e, q0) or not ev._disc_reaches(e, q0, floor):
            continue
        floor1 = min(c.body_radius, float(ev.map.distance_to_walls(q0[None])[0]))
        for k in np.argsort(-margin, kind="stable").tolist():
            if margin[k] <= 0.0:
                break
            if ev._disc_reaches(q0, cand[k], floor1):
                return q0, positive
    return None, positive


def _looks(n: int = 300):
    """States round the wall's tip (e free, 0.1 from the walls): the rod of 2-6 m at a
    random orientation, the pursuer at its end."""
    m = Map([(0, 0), (10, 0), (10, 10), (0, 10)], [_WALL], name="wall_tip", merge=True)
    rng = np.random.default_rng(0)
    out = []
    while len(out) < n:
        e = rng.uniform([4.0, 3.5], [6.0, 5.5])
        if not m.contains(e[None])[0] or m.distance_to_walls(e[None])[0] < 0.1:
            continue
        theta, rod = rng.uniform(-np.pi, np.pi), rng.uniform(2.0, 6.0)
        out.append((e, theta, e + rod * np.array([np.cos(theta), np.sin(theta)]), rod))
    return out


class _Counting(ShootingEvader):
    """The shooting evader, counting the disc's path checks and the candidate sets."""

    def _reset(self) -> None:
        self.calls = {"disc": 0, "candidates": 0}
        super()._reset()

    def _disc_reaches(self, e, q, floor):
        self.calls["disc"] += 1
        return super()._disc_reaches(e, q, floor)

    def _candidates(self, e):
        self.calls["candidates"] += 1
        return super()._candidates(e)


def test_a_two_leg_look_finds_what_trying_every_corner_in_full_finds(evader):
    # the same corner point, or none, on every state (26 of the 300 find one)
    found = 0
    for e, theta, p, rod in _looks():
        want, _ = _every_corner_in_full(evader, e, theta, p, rod)
        got = evader._via_corner(e, theta, p, rod)
        assert (got is None) == (want is None), (e, theta, rod)
        if got is not None:
            assert np.array_equal(got, want)
            found += 1
    assert 10 <= found <= 290


def test_a_look_whose_corners_have_no_margin_traces_no_disc_path():
    # most looks find nothing (unseen-e's first 200 steps: 1,461 of 1,678 corner points
    # had no positive margin): there the look checks no path of the disc, and the
    # candidates from a corner's point are gathered once for the map, not on every look
    m = Map([(0, 0), (10, 0), (10, 10), (0, 10)], [_WALL], name="wall_tip", merge=True)
    config = EnvConfig(map=m, l_min=2.0, l_max=6.0, v_pursuer=1.0, v_evader=0.2, body_radius=0.1)
    ev = _Counting()
    ev.reset(role="evader", map=m, config=config, seed=0)
    ref = ShootingEvader()
    ref.reset(role="evader", map=m, config=config, seed=0)
    ev.calls.update(disc=0, candidates=0)
    idle = 0
    for e, theta, p, rod in _looks():
        _, positive = _every_corner_in_full(ref, e, theta, p, rod)
        disc = ev.calls["disc"]
        ev._via_corner(e, theta, p, rod)
        if not positive:
            assert ev.calls["disc"] == disc, (e, theta, rod)
            idle += 1
    assert idle >= 250
    assert ev.calls["candidates"] <= len(ev._corner_points) == 2


def test_a_margin_less_a_turn_is_integrated_only_where_it_can_exceed_the_turn(evader):
    # _rate_margins(..., less=t): the margins that can exceed t as without it, bit for
    # bit, and -inf where the margin is at most t (the first leg's turn, taken off after)
    e = np.array([4.0, 3.0])
    ang = np.linspace(0.0, 2.0 * np.pi, 48, endpoint=False)
    ring = np.stack([np.cos(ang), np.sin(ang)], axis=1)
    cand = np.concatenate([e + r * ring for r in (0.3, 0.6, 1.2)])
    rows = evader.table.rows(cand)
    # (finite margins -0.53..0.46, -1.69..0.71, -1.56..0.90, -0.74..0.20 rad)
    for theta, rod, t in ((0.0, 2.0, 0.2), (0.0, 4.0, 0.5), (0.0, 5.5, 0.3), (0.5, 4.0, 0.0)):
        full, _ = evader._rate_margins(e, theta, cand, rows, rod)
        less, _ = evader._rate_margins(e, theta, cand, rows, rod, less=t)
        kept = np.isfinite(less)
        assert np.array_equal(less[kept], full[kept])
        assert (full[~kept] - t <= 0.0).all()
        assert (less[kept] > t).any()
        if t:
            assert kept.sum() < np.isfinite(full).sum()
        else:
            assert np.array_equal(less, full)
