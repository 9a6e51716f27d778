"""Plan features (issue 9): the crossing they point at is recomputed from the decomposition's
pieces, the cell's verdict from the decomposition's own flag, and in every mode they carry
what a fresh shooting evader decides at the same state."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely

from envs.maps import Map
from envs.surveillance.config import EnvConfig
from envs.surveillance.observations import StateEncoder
from strategies.policies.escape_plan import CROSS_REL
from strategies.policies.plan_features import PLAN_FEATURES, PlanFeatures
from strategies.policies.shooting import ShootingEvader
from strategies.runner import build_env

_PILLAR = Map([(0, 0), (12, 0), (12, 8), (0, 8)], [[(8, 5), (10, 5), (10, 7), (8, 7)]],
              name="pillar_box")  # fmt: skip


@pytest.fixture(scope="module", params=["corridor", "pillar_box"])
def feats(request):
    """corridor: 15 of its 46 cells escapable; pillar_box: all of them."""
    if request.param == "corridor":
        config = build_env("corridor", {}).config
    else:
        config = EnvConfig(map=_PILLAR, l_min=2.0, l_max=4.0, v_pursuer=1.0, v_evader=0.5)
    return PlanFeatures(config)


def _states(feats, n, seed=0):
    """States with the evader at random free grid points and the pursuer at a random angle
    and distance in [L_min, L_max]: (state, evader, pursuer)."""
    c = feats.config
    enc = StateEncoder(c)
    rng = np.random.default_rng(seed)
    xmin, ymin, xmax, ymax = c.map.bounds
    out = []
    while len(out) < n:
        e = rng.uniform((xmin, ymin), (xmax, ymax))
        if feats.evader.table.row(e) < 0 or c.map.distance_to_walls(e[None])[0] < c.body_radius:
            continue
        th = rng.uniform(-math.pi, math.pi)
        p = e + rng.uniform(c.l_min, c.l_max) * np.array([math.cos(th), math.sin(th)])
        out.append((enc.encode(tuple(p), (0.0, 0.0), tuple(e), (0.0, 0.0), True, 0), e, p))
    return out


def _world(f, e, p, i):
    """The direction of features (i, i + 1) back in map coordinates."""
    u = (p - e) / np.linalg.norm(p - e)
    n = np.array([-u[1], u[0]])
    return f[i] * u + f[i + 1] * n


def test_the_crossing_lies_just_across_a_via_of_the_cell(feats):
    c, plan = feats.config, feats.evader.plan
    dec = plan.dec
    crossed = refused = 0
    for state, e, p in _states(feats, 150):
        f = feats(state)
        assert f.shape == (len(PLAN_FEATURES),) and np.all(np.abs(f) <= 1.0)
        cell = dec.cell_at(float(e[0]), float(e[1]), math.atan2(p[1] - e[1], p[0] - e[0]))
        if cell is None:
            assert f[0] == 0.0 and f[4] == 1.0
            continue
        # the verdict is the decomposition's own flag (Sec. 4), not the plan's ranks
        assert f[0] == (1.0 if cell.escapable else -1.0)
        assert (f[1] > 0) == cell.escapable
        refused += not cell.escapable
        if f[4] >= 1.0:  # no crossing, or one farther than L_max
            continue
        d = _world(f, e, p, 2)
        assert abs(np.linalg.norm(d) - 1.0) < 1e-5
        target = e + f[4] * c.l_max * d
        vias = shapely.union_all(
            [shapely.MultiLineString(list(dec.boundaries[b].segments)) for b in plan.vias[cell.id]]
        )
        gap = shapely.distance(vias, shapely.Point(target))
        assert gap <= CROSS_REL * dec.L + 1e-4  # just across one of the cell's vias
        # and the crossing keeps the evader's disc off the walls
        assert c.map.distance_to_walls(target[None])[0] >= c.body_radius - CROSS_REL * dec.L - 1e-4
        crossed += 1
    if c.map.name == "corridor":  # mostly non-escapable cells (the pursuer wins there)
        assert refused > 50
    else:
        assert crossed > 20


def test_the_features_carry_a_fresh_shooting_evaders_decision(feats):
    """A shooting evader without memory decides at each state as the features say: it walks
    to their crossing, shoots toward their candidate, walks toward the witness region, or
    presses when they offer nothing."""
    c = feats.config
    step = c.v_evader * c.dt
    modes = {}
    for state, e, p in _states(feats, 120, seed=1):
        f = feats(state)
        ev = ShootingEvader()
        ev.reset(role="evader", map=c.map, config=c, seed=0)
        a = np.asarray(ev.act(state), dtype=float)
        h = a / np.linalg.norm(a)
        modes[ev.mode] = modes.get(ev.mode, 0) + 1
        if ev.mode == "plan":
            assert f[0] == 1.0 and f[2:4].any()
            w = ev._witness
            d = _world(f, e, p, 2)
            gap = np.linalg.norm(w.target - e)
            np.testing.assert_allclose(d, (w.target - e) / gap, atol=1e-5)
            assert f[4] == pytest.approx(min(gap / c.l_max, 1.0), abs=1e-5)
            region = ev.plan.dec.cells[ev._plan_cell].region
            if np.linalg.norm(w.cross - e) > step and ev.plan.well_inside(region, e + step * d):
                assert h @ d > 0.9999  # straight at the crossing, where the step stays inside
        elif ev.mode == "shoot":
            assert f[9] > 0.0 and f[10] in (1.0, -1.0)
            end = ev._arc[2][-1] if ev._arc is not None else e + a
            to = (end - e) / np.linalg.norm(end - e)
            assert to @ _world(f, e, p, 7) > 0.999  # the arc ends at the candidate
        elif ev.mode == "region":
            assert h @ _world(f, e, p, 5) > 0.9999
        else:
            assert ev.mode == "pressure"
            assert f[9] == 0.0 and not f[2:4].any() and not f[5:7].any()
    # corridor: mostly pressure and shooting; pillar_box: mostly the plan
    assert len(modes) >= 2 and modes.get("plan", 0) + modes.get("shoot", 0) > 20, modes


def test_an_evader_without_memory_decides_each_step_as_a_fresh_one(feats):
    """memory=False (the DAgger labeller): over a run of states each action is a fresh
    evader's at that state; the evader with memory keeps its arcs and differs."""
    c = feats.config
    states = [s for s, _, _ in _states(feats, 60, seed=2)]
    acts = {}
    for memory in (False, True):
        ev = ShootingEvader(memory=memory)
        ev.reset(role="evader", map=c.map, config=c, seed=0)
        acts[memory] = np.array([ev.act(s) for s in states])
    fresh = []
    for s in states:
        ev = ShootingEvader()
        ev.reset(role="evader", map=c.map, config=c, seed=0)
        fresh.append(ev.act(s))
    assert np.array_equal(acts[False], np.array(fresh))
    assert not np.array_equal(acts[True], acts[False])
