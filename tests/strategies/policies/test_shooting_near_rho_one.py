"""The shooting evader near rho = 1, where most optimal escape arcs do not exist (the
extremals turn back before the target, THEORY §4.3): a failed solve is not paid again
every step (issue 13: at rho 0.99 each failure cost 100-150 ms on the corridor), and from
``ARC_RHO_MAX`` on no arc is solved at all: the shots follow their straight paths (the
solves' machinery is tested there with the threshold lifted)."""

from __future__ import annotations

import math

import numpy as np

from strategies.policies import make_policy
from strategies.policies.shooting import arcs as shot_arcs
from strategies.runner import run_episode


def test_from_arc_rho_max_on_shots_follow_straight_paths_unsolved(monkeypatch):
    # issue 13's goal, under 1 ms a decision: near rho = 1 a solve integrated arcs ~6 times
    # the target's distance, 20-70 ms a replan (random:star:9203, rho 0.99, L_min 5)
    evader = make_policy("evader/shooting")
    assert 0.9 <= evader.ARC_RHO_MAX < 0.95
    calls = []
    monkeypatch.setattr(shot_arcs, "escape_path", lambda *a, **k: calls.append(a))
    shots = []

    def on_step(_):
        if evader.mode == "shoot" and evader._arc is not None:
            shots.append(evader._arc)

    r = run_episode(
        "corridor", "pursuer/greedy", evader, 0, start="safe", max_cycles=120,
        overrides={"v_evader": 0.95}, on_step=on_step,
    )  # fmt: skip
    assert r.winner == "evader"
    assert shots and not calls  # shots, and not one solve
    for start, _, path in shots:
        d = path[-1] - start
        off = (path - start) @ np.array([-d[1], d[0]]) / np.hypot(*d)
        assert np.abs(off).max() < 1e-12  # a straight path


def test_a_failed_arc_is_followed_straight_until_the_replan(monkeypatch):
    evader = make_policy("evader/shooting")
    evader.ARC_RHO_MAX = 1.0  # (the solves near rho = 1, as below ARC_RHO_MAX)
    calls: list[tuple[int, bool]] = []  # (decision, solved) of every arc solve
    real = shot_arcs.escape_path  # read by the shot's arc (_Arcs._start_arc)

    def counted(*args, **kwargs):
        path = real(*args, **kwargs)
        calls.append((evader._steps, path is not None))
        return path

    arcs: list[tuple[int, object]] = []  # (decision, the shot it follows after it)

    def on_step(_):
        arcs.append((evader._steps - 1, evader._arc))

    monkeypatch.setattr(shot_arcs, "escape_path", counted)
    r = run_episode(
        "corridor", "pursuer/greedy", evader, 0, start="safe", max_cycles=120,
        overrides={"v_evader": 0.95}, on_step=on_step,
    )  # fmt: skip
    assert r.winner == "evader"
    failed = [s for s, ok in calls if not ok]
    assert len(failed) >= 2  # the case at issue (9 of 10 solves failed before)
    solved_at = [s for s, _ in calls]
    kept = dict(arcs)
    for s in failed:
        # no solve in the replan steps after a failure (before: one every step) ...
        assert not [t for t in solved_at if s < t < s + evader.replan], (s, solved_at)
        # ... and meanwhile the evader follows the straight path to that shot's target
        shot = kept[s]
        assert shot is not None
        start, _, path = shot
        d = path[-1] - start
        off = (path - start) @ np.array([-d[1], d[0]]) / np.hypot(*d)
        assert np.abs(off).max() < 1e-12  # a straight path
        steps = [t for t in range(s + 1, s + evader.replan) if t in kept]
        assert all(kept[t] is shot or kept[t] is None for t in steps)


def test_arcs_near_rho_one_are_integrated_at_the_capped_step(monkeypatch):
    # issue 13: at rho 0.99 the default step (1/32 of the natural length, 0.01 here) took
    # ~10,000 RK4 steps per integration and 100-150 ms per solve
    from strategies.control import evasion

    steps: list[tuple[float, float]] = []  # (step, x_e) of each integration
    for name in ("integrate_reduced", "integrate_reduced_end"):  # fine, coarse
        real = getattr(evasion, name)

        def counted(*args, real=real):
            steps.append((args[5], args[6]))
            return real(*args)

        monkeypatch.setattr(evasion, name, counted)
    evader = make_policy("evader/shooting")
    evader.ARC_RHO_MAX = 1.0  # (the solves near rho = 1, as below ARC_RHO_MAX)
    run_episode(
        "corridor", "pursuer/greedy", evader, 0, start="safe", max_cycles=100,
        overrides={"v_evader": 0.99},
    )  # fmt: skip
    assert len(steps) > 20  # (108 before evasion._root_free skipped the jump searches: 28)
    natural = evasion._natural_length(2.0, 0.99)
    for h, x_e in steps:
        want = max(evasion.default_step(x_e, 2.0, 0.99), min(natural / 4, x_e / 1024))
        assert h in (want, 8.0 * want)  # the fine grid or the bracketing coarse one
        assert want > natural / 32 or x_e <= 32 * natural  # coarser than the default's


def test_the_capped_step_is_the_default_up_to_32_natural_lengths():
    from strategies.control.evasion import _natural_length, capped_step, default_step

    L = 2.0
    for rho in np.linspace(0.1, 0.99, 90):
        ell = _natural_length(L, rho)
        for x in np.linspace(0.01, 4.0, 80) * L:
            h, d = capped_step(x, L, rho), default_step(x, L, rho)
            if x <= 32 * ell:
                assert h == d
            else:
                assert d < h <= max(d, ell / 4)
                assert x / h <= max(1024, 4 * x / ell) * (1 + 1e-12)
        # the shooting evader's farthest candidate, L (pi rho / (1 + rho) + 2) + one grid
        # step L / 20: within 32 natural lengths from rho 0.1 to 0.8 (its arcs unchanged)
        if rho <= 0.8:
            assert L * (math.pi * rho / (1 + rho) + 2.05) <= 32 * ell
    assert capped_step(2.0, L, 0.9999) is None  # refused as solve_escape refuses it
