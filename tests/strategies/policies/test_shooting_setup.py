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
