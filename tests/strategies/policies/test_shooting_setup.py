"""The shooting evader builds its plan's crossings and region tests at reset, not while
it plays (issue 13: every decision under 1 ms; built on first use, they cost 1-2 ms in
each decision that entered a new cell)."""

from __future__ import annotations

from envs.maps.junctions import crossroads
from strategies.policies import make_policy
from strategies.policies.escape_plan import escape_plan
from strategies.runner import run_episode

OVERRIDES = {"l_min": 2.0, "l_max": 4.0, "v_pursuer": 1.0, "v_evader": 0.5}


def _built(plan) -> dict[str, int]:
    """Entries in each of the plan's caches (built on first use)."""
    caches = ("_pieces", "_keeps", "_ends", "_spans", "_polygons")
    return {name: len(plan.__dict__.get(name, ())) for name in caches}


def test_decisions_build_nothing_after_reset():
    escape_plan.cache_clear()  # a plan no earlier episode filled
    world = crossroads()
    evader = make_policy("evader/shooting")
    after_reset = {}
    modes = set()

    def on_step(_):
        if not after_reset:
            return
        modes.add(evader.mode)

    orig_reset = evader.reset

    def reset(**kw):
        orig_reset(**kw)
        after_reset.update(_built(evader.plan))

    evader.reset = reset
    for seed in range(3):
        after_reset.clear()
        r = run_episode(world, "pursuer/greedy", evader, seed, max_cycles=400,
                        start="valid", overrides=OVERRIDES, on_step=on_step)  # fmt: skip
        assert r.steps > 10
        assert after_reset["_spans"] > 0
        assert _built(evader.plan) == after_reset
    assert "plan" in modes  # the decisions used the plan's witnesses


def test_the_table_is_distinct_rows_with_the_eager_lookups():
    # issue 13: the eager table costs about 0.1 ms a grid point at reset (22 s on the
    # corridor at L_min 0.5, 94 s at 0.21); distinct rows answer the same at every node
    import numpy as np

    from strategies.policies.safety import safety_table
    from strategies.runner import build_env

    config = build_env("corridor", {}).config
    evader = make_policy("evader/shooting")
    evader.reset(role="evader", map=config.map, config=config, seed=0)
    tab = evader.table
    eager = safety_table(config.map, evader.L_eff, tab.resolution, tab.n_bins, disk_cache=False)
    inside = eager.cell >= 0
    assert len(tab.safe) < int(inside.sum())  # one row per distinct row, not per node
    assert np.array_equal(tab.cell >= 0, inside) and tab.shape == eager.shape
    mine, want = tab.cell[inside], eager.cell[inside]
    for field in ("free", "safe", "guaranteed", "ccw", "cw"):
        assert np.array_equal(getattr(tab, field)[mine], getattr(eager, field)[want]), field


def test_the_walk_to_a_witness_region_looks_up_the_plans_own_grid_points():
    # issue 13: the walk's arrays are the plan's grid points; they were looked up with the
    # distinct table's rows (numbered otherwise), which on office answered "in a witness
    # region?" wrongly at 1,526 of 35,214 grid points and sent the walk elsewhere
    import numpy as np

    from strategies.policies.base import unit
    from strategies.runner import build_env

    config = build_env("office", {}).config
    evader = make_policy("evader/shooting")
    evader.reset(role="evader", map=config.map, config=config, seed=0)
    plan, h = evader.plan, evader.table.resolution
    assert plan.region.any() and not plan.region.all()
    rng = np.random.default_rng(0)
    outside = np.flatnonzero(~plan.region & (plan.region_next >= 0))
    picks = np.concatenate([rng.choice(outside, 300), rng.choice(np.flatnonzero(plan.region), 50)])
    walked = 0
    for i in picks.tolist():
        p = plan.points[i] + rng.uniform(-h / 3, h / 3, 2)
        d = np.hypot(*(plan.points - p).T)
        j = int(np.argmin(d))  # the grid point nearest p, by brute force
        assert j == i
        got = evader._region_walk(p)
        if plan.region[j]:
            assert got is None
        else:
            assert np.array_equal(got, unit(plan.points[plan.region_next[j]] - p))
            walked += 1
    assert walked == 300


def test_a_lazy_tables_decomposition_is_the_plans(monkeypatch):
    """With a lazy table the plan is built on the table's decomposition, not on a second
    copy read back from the disk cache (0.9 s of the reset on a 200 m floor plan at
    L_min 3), and it is the plan built on the copy read back (the cache's round trip is
    exact): the same ranks, walk and crossings."""
    import dataclasses

    import numpy as np

    import strategies.cspace.cache as cache
    from strategies.runner import build_env

    config = build_env("two_rooms", {}).config  # witness regions: a walk grid
    escape_plan.cache_clear()
    reads = []
    read = cache._read
    monkeypatch.setattr(cache, "_read", lambda *a: reads.append(a) or read(*a))
    evader = make_policy("evader/shooting", table="lazy")
    evader.reset(role="evader", map=config.map, config=config, seed=0)
    monkeypatch.undo()
    assert evader.plan.dec is evader.table.decomposition
    assert len(reads) == 1  # the table's (built or read), not the plan's
    escape_plan.cache_clear()
    again = escape_plan(config.map, evader.L_eff, evader.table.resolution, config.body_radius)
    assert again.dec is not evader.plan.dec  # read back from the disk cache
    assert np.array_equal(again.rank, evader.plan.rank) and again.vias == evader.plan.vias
    for field in ("points", "region", "region_next"):
        assert np.array_equal(getattr(again, field), getattr(evader.plan, field)), field
    mine, other = dataclasses.replace(evader.plan), dataclasses.replace(again)
    for plan in (mine, other):
        plan.prepare(config.body_radius, (config.v_evader * config.dt, 0.0))
    for key, want in other._spans.items():
        got = mine._spans[key]
        for g, w in zip(got or (), want or (), strict=True):
            assert np.asarray(g).tobytes() == np.asarray(w).tobytes()


def test_a_decomposition_of_another_map_or_length_is_refused():
    import pytest

    from envs.errors import InvalidConfigError
    from envs.maps import builtin_map
    from strategies.cspace import decompose

    world = builtin_map("two_rooms")
    dec = decompose(world, 2.1, cache=True)
    with pytest.raises(
        InvalidConfigError, match=r"at L = 2.1.*expected that of map 'two_rooms' at L = 2.2"
    ):
        escape_plan(world, 2.2, 0.5, 0.1, dec)
    with pytest.raises(InvalidConfigError, match="expected that of map 'corridor'"):
        escape_plan(builtin_map("corridor"), 2.1, 0.5, 0.1, dec)
