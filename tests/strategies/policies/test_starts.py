"""The seeded start sampler: valid and safe starts are valid surveillance configurations."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from envs import surveillance_v1
from envs.errors import InfeasibleError, RelaxedStartWarning
from envs.geometry import kernel_for
from strategies.policies.starts import sample_start


@pytest.mark.parametrize("kind", ["valid", "safe"])
@pytest.mark.parametrize(
    ("l_min", "l_max"),
    [(2.0, 4.0), (1.0, 1.0001), (1.5, 1.6)],  # the last two are narrower than the buffer
)
@pytest.mark.filterwarnings("ignore::envs.errors.NarrowBandWarning")  # narrow on purpose
def test_starts_lie_inside_the_sensor_range_and_reset_accepts_them(kind, l_min, l_max):
    env = surveillance_v1.parallel_env(map="open_room", l_min=l_min, l_max=l_max)
    rng = np.random.default_rng(7)
    for _ in range(3):
        start = sample_start(env.config, rng, kind=kind)
        p, e = np.asarray(start["pursuer"]), np.asarray(start["evader"])
        assert l_min <= np.linalg.norm(p - e) <= l_max
        assert kernel_for(env.config.map).line_of_sight(p, e)
        env.reset(seed=0, options=start)  # raises InvalidPlacementError if not valid
    env.close()


@pytest.mark.parametrize("kind", ["valid", "safe"])
@pytest.mark.filterwarnings("ignore::envs.errors.NarrowBandWarning")  # one step: on purpose
def test_starts_without_a_range_margin_are_accepted_by_reset(kind):
    # spawn_margin_steps = 0 leaves no range margin: a safe start is drawn at L = L_max
    # exactly when the pursuer's target length lies beyond L_max, and half of those
    # proposals were a rounding error too far ("distance 0.1 is not in [l_min, l_max] =
    # [0.05, 0.1] (too_far)": run_episode(start="safe") raised InvalidPlacementError)
    env = surveillance_v1.parallel_env(
        map="open_room", l_min=2.0, l_max=2.2, v_evader=2.0, spawn_margin_steps=0
    )
    rng = np.random.default_rng(0)
    for _ in range(12):
        start = sample_start(env.config, rng, kind=kind)
        _, infos = env.reset(seed=0, options=start)  # InvalidPlacementError if not valid
        assert 2.0 <= infos["pursuer_0"]["distance"] <= 2.2
    env.close()


def test_same_generator_state_same_start():
    env = surveillance_v1.parallel_env(map="corridor")
    a = sample_start(env.config, np.random.default_rng(3), kind="safe")
    b = sample_start(env.config, np.random.default_rng(3), kind="safe")
    assert a == b


@pytest.mark.parametrize("map_name", ["corridor", "two_rooms"])
def test_escapable_starts_put_the_rod_in_an_escapable_cell(map_name):
    """Checked against the exact decomposition at L_min: the orientation of the start's
    rod lies in a cell the evader can escape from (or where no cell is classified safe)."""
    import math

    from strategies.cspace import decompose

    env = surveillance_v1.parallel_env(map=map_name)
    cfg = env.config
    dec = decompose(cfg.map, cfg.l_min)
    rng = np.random.default_rng(3)
    for _ in range(4):
        start = sample_start(cfg, rng, kind="escapable")
        p, e = np.asarray(start["pursuer"]), np.asarray(start["evader"])
        assert cfg.l_min <= np.linalg.norm(p - e) <= cfg.l_max
        env.reset(seed=0, options=start)
        theta = math.atan2(p[1] - e[1], p[0] - e[0])
        cell = dec.cell_at(float(e[0]), float(e[1]), theta)
        safe_here = [ca for ca in dec.free_arcs(e) if ca.escapable is False]
        assert cell is None or cell.escapable or not safe_here
    env.close()


@pytest.mark.parametrize("map_name", ["corner", "maze"])
def test_safe_starts_leave_retreat_clearance_and_survive_a_charge(map_name):
    """Issue 13: a safe start leaves the pursuer room to back away from an evader charging
    along the rod (maze seed 5 used to put its back to a wall, lost "too_close" at 1.1 s),
    and a charging toward_away evader at rho = 0.5 does not win within 2 s."""
    from envs.maps import builtin_info
    from strategies.policies.starts import has_retreat_clearance, retreat_clearance_required
    from strategies.runner import episode_seeds, run_episode

    params = dict(builtin_info(map_name).params())
    params["v_evader"] = 0.5 * params["v_pursuer"]
    env = surveillance_v1.parallel_env(map=map_name, **params)
    cfg = env.config
    kernel = kernel_for(cfg.map)
    for seed in (5, 6, 10):
        start = sample_start(cfg, np.random.default_rng(episode_seeds(seed)[1]), kind="safe")
        p, e = np.asarray(start["pursuer"]), np.asarray(start["evader"])
        need = retreat_clearance_required(cfg, float(np.linalg.norm(p - e)))
        assert 0.5 < need < 1.0  # rho = 0.5, L just above L_min = 2
        assert has_retreat_clearance(cfg.map, kernel, p, e, need, cfg.body_radius)
        r = run_episode(
            map_name,
            "pursuer/decomposition",
            "evader/toward_away",
            seed,
            start="safe",
            max_cycles=20,
            overrides=params,
        )
        assert r.start == {"pursuer": list(p), "evader": list(e)}
        assert r.winner == "pursuer", (seed, r.cause, r.escape_time)
    env.close()


def test_retreat_clearance_rejects_a_pursuer_backed_against_a_wall():
    """The maze start of issue 13 (seed 5 before the fix): 0.18 of room behind the pursuer."""
    from strategies.policies.starts import has_retreat_clearance

    env = surveillance_v1.parallel_env(map="open_room")
    cfg = env.config
    kernel = kernel_for(cfg.map)
    _, ymin, xmax, ymax = cfg.map.bounds
    y = 0.5 * (ymin + ymax)
    p = np.array([xmax - 0.3, y])  # 0.3 from the right wall, facing away from it
    e = p - np.array([2.45, 0.0])
    assert has_retreat_clearance(cfg.map, kernel, p, e, 0.19, cfg.body_radius)
    assert not has_retreat_clearance(cfg.map, kernel, p, e, 0.21, cfg.body_radius)
    assert has_retreat_clearance(cfg.map, kernel, e, p, 0.74, cfg.body_radius)  # turned round
    env.close()


def test_a_very_slow_evader_has_safe_starts():
    # rho = 1e-12 asks for a retreat of 2e-24, which does not move p: the zero-length
    # segment's test divided 0 by 0 and refused every start ("no safe start at L = 2.3")
    env = surveillance_v1.parallel_env(map="corridor", v_evader=1e-12)
    start = sample_start(env.config, np.random.default_rng(0), kind="safe")
    env.reset(seed=0, options=start)
    assert env.agents
    env.close()


@pytest.mark.parametrize("map_name", ["corridor", "two_rooms"])
def test_a_lazy_table_draws_the_same_start_as_an_eager_one(map_name, monkeypatch):
    """On maps too large for a stored table the judge's table is lazy and has classified
    nothing before the first draw; "nothing is safe anywhere" (Prop. 2, which lets any
    valid start through) must still be decided for the whole map, not for the empty
    table (it was: every large map drew unchecked starts)."""
    from strategies.policies.decomposition import DecompositionPursuer

    env = surveillance_v1.parallel_env(map=map_name)
    eager = [sample_start(env.config, np.random.default_rng(s), kind="safe") for s in (1, 2)]
    monkeypatch.setattr(DecompositionPursuer, "EAGER_TABLE_POINTS", 0)
    monkeypatch.setattr(DecompositionPursuer, "DISTINCT_TABLE_POINTS", 0)
    lazy = [sample_start(env.config, np.random.default_rng(s), kind="safe") for s in (1, 2)]
    assert lazy == eager
    env.close()


def test_a_start_the_margins_rule_out_names_them():
    """``surveil play --config '{"v_pursuer": 100}'`` said only "no safe start at L = 2.5
    found on map 'corridor' in 25600 proposals": the cause is the rod clearance the start
    margins ask (max(V_p, V_e) dt spawn_margin_steps = 30 m), now named with its factors;
    with spawn_margin_steps = 0 a start is found."""
    from envs.surveillance.config import EnvConfig

    cfg = EnvConfig(map="corridor", v_pursuer=100.0)
    with pytest.raises(InfeasibleError, match=r"rod clearance 30 from convex vertices.*"
                       r"= 100 x 0.1 x 3: lower spawn_margin_steps"):  # fmt: skip
        sample_start(cfg, np.random.default_rng(0), kind="safe")
    cfg = EnvConfig(map="corridor", v_pursuer=100.0, spawn_margin_steps=0)
    assert set(sample_start(cfg, np.random.default_rng(0), kind="safe")) == {"pursuer", "evader"}


def test_a_judge_beyond_the_memory_budget_names_the_valid_start(monkeypatch):
    """``surveil play`` on a 1.4e9 m map: the safe start's judge (a decomposition pursuer
    at L_min / 20) refused its table naming ``resolution >= 2.81e+04``, which neither the
    sampler nor ``play`` lets the user set; the refusal now names ``kind='valid'``, and
    that start is drawn."""
    from envs.errors import MemoryBudgetError
    from envs.maps import Map
    from envs.surveillance.config import EnvConfig

    monkeypatch.setenv("SURVEIL_MEMORY_BUDGET", "1GB")
    s = 1e8
    huge = Map([(0, 0), (14 * s, 0), (14 * s, 5 * s), (5 * s, 5 * s), (5 * s, 14 * s),
                (0, 14 * s)], name="huge")  # fmt: skip
    cfg = EnvConfig(map=huge)
    with pytest.raises(MemoryBudgetError, match=r"'safe' start on map 'huge' .* its grid of "
                       r"14,000,000,000 x 14,000,000,000 nodes .*; use kind='valid' \(a valid "
                       r"start needs no judge\)") as err:  # fmt: skip
        sample_start(cfg, np.random.default_rng(0), kind="safe")
    assert "resolution >=" not in str(err.value)
    start = sample_start(cfg, np.random.default_rng(0), kind="valid")
    assert set(start) == {"pursuer", "evader"}


def test_a_judge_whose_decomposition_is_beyond_the_budget_names_the_valid_start(
    monkeypatch, tmp_path
):
    """A 600-gon room: the safe start's judge refused the map's decomposition itself
    (before its table), and the refusal said only "Raise the budget ..., or use a shorter L
    or a smaller map", though a valid start needs no judge; it now names ``kind='valid'``
    as the table's refusal does, and that start is drawn."""
    from envs.errors import MemoryBudgetError
    from envs.maps import Map
    from envs.surveillance.config import EnvConfig

    monkeypatch.setenv("SURVEIL_MEMORY_BUDGET", "50MB")
    monkeypatch.setenv("SURVEIL_CACHE_DIR", str(tmp_path))  # decomposed afresh, not read back
    n = 600
    ring = [(20 * np.cos(2 * np.pi * k / n), 20 * np.sin(2 * np.pi * k / n)) for k in range(n)]
    cfg = EnvConfig(map=Map(ring, name="round"))
    with pytest.raises(MemoryBudgetError, match=r"'safe' start on map 'round' is judged on a "
                       r"decomposition pursuer's decomposition of the map, which does not fit: "
                       r"decompose\(map 'round'.*; use kind='valid' \(a valid start needs no "
                       r"judge\), or raise the budget") as err:  # fmt: skip
        sample_start(cfg, np.random.default_rng(0), kind="safe")
    assert "shorter L" not in str(err.value)
    assert set(sample_start(cfg, np.random.default_rng(0), kind="valid")) == {"pursuer", "evader"}


@pytest.mark.parametrize("rho", [0.9, 0.99])
def test_near_one_rho_draws_a_safe_cell_start_as_rho_one_does(rho):
    """Issue 13: at rho = 0.99 the retreat a safe start asks for (25 at L_min = 2) is longer
    than the corridor, and at rho = 0.9 no orientation is admissible: ``"safe"`` refused
    every start (InfeasibleError naming the rod clearance) while rho = 1 drew one. Where
    nothing is admissible the start lies in a safe cell, as at rho >= 1."""
    from strategies.policies.decomposition import DecompositionPursuer
    from strategies.runner import run_episode

    env = surveillance_v1.parallel_env(map="corridor", v_evader=rho)
    cfg = env.config
    with pytest.warns(RelaxedStartWarning, match="safe cell only"):
        start = sample_start(cfg, np.random.default_rng(0), kind="safe")
    p, e = np.asarray(start["pursuer"]), np.asarray(start["evader"])
    judge = DecompositionPursuer(turn_rate="one")
    judge.reset(role="pursuer", map=cfg.map, config=cfg, seed=0)
    tab = judge.table
    theta = float(np.arctan2(*(p - e)[::-1]))
    assert tab.safe[tab.row(e), tab.bin_of(theta)]
    env.reset(seed=0, options=start)
    assert env.agents
    env.close()
    with pytest.warns(RelaxedStartWarning):
        r = run_episode("corridor", "pursuer/decomposition", "evader/shooting", 0,
                        overrides={"v_evader": rho}, max_cycles=5)  # fmt: skip
    assert r.start_kind == "safe" and r.steps >= 1
    with warnings.catch_warnings():  # where an admissible start exists, no warning
        warnings.simplefilter("error", RelaxedStartWarning)
        sample_start(
            surveillance_v1.parallel_env(map="corridor", v_evader=0.5).config,
            np.random.default_rng(0),
            kind="safe",
        )


def test_a_retreat_longer_than_the_map_draws_the_relaxed_start_at_once(monkeypatch):
    """At rho = 0.99 the retreat a safe start asks for (24.5 at L_0 = 2.45) is longer than
    the corridor's diameter (16.9), so no proposal can pass it: the sampler judged all
    25,600 proposals (about 10,000 probe fans of V(theta), 3 s) before drawing the first
    one in a safe cell. It draws that one at once, the same start (seeds 0-5 drew the
    same before and after, /work/scratch/s15/helper-88/starts_*.jsonl)."""
    from strategies.policies.decomposition import DecompositionPursuer

    calls = []
    real = DecompositionPursuer.orientation_values

    def counted(self, evader):
        calls.append(1)
        return real(self, evader)

    monkeypatch.setattr(DecompositionPursuer, "orientation_values", counted)
    cfg = surveillance_v1.parallel_env(map="corridor", v_evader=0.99).config
    with pytest.warns(RelaxedStartWarning, match=r"more than the map's diameter 16\.92"):
        start = sample_start(cfg, np.random.default_rng(0), kind="safe")
    assert not calls
    # drawn before this change from the same seed, after its 25,600 proposals
    assert start == {
        "pursuer": (2.949769056304625, -0.13225155478071748),
        "evader": (4.191386997143269, -2.302132862361297),
    }
