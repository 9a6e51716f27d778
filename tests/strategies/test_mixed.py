"""Zero-sum matrix games: hand-solved games, a second method, and mixed policies."""

from __future__ import annotations

import numpy as np
import pytest

from envs.errors import InvalidConfigError
from strategies.mixed import (
    MixedPolicy,
    column_exploitability,
    row_exploitability,
    solve_zero_sum,
)


def fictitious_play(a: np.ndarray, iterations: int) -> tuple[np.ndarray, np.ndarray]:
    """Brown's fictitious play: empirical mixtures of best responses (Robinson 1951)."""
    m, n = a.shape
    rows, cols = np.zeros(m), np.zeros(n)
    rows[0] = cols[0] = 1.0
    for _ in range(iterations):
        rows[np.argmax(a @ cols)] += 1.0
        cols[np.argmin(rows @ a)] += 1.0
    return rows / rows.sum(), cols / cols.sum()


def test_two_by_two_without_saddle_point():
    # row mixes p: 3p - (1 - p) = 1 - p  ->  p = 0.4, v = 0.6; column q: 3q = 1 - 2q -> 0.2
    sol = solve_zero_sum([[3.0, 0.0], [-1.0, 1.0]])
    assert sol.value == pytest.approx(0.6, abs=1e-9)
    assert sol.row == pytest.approx([0.4, 0.6], abs=1e-9)
    assert sol.col == pytest.approx([0.2, 0.8], abs=1e-9)


def test_two_by_two_with_saddle_point():
    # row 2 dominates; column 1 is then best: pure equilibrium (2, 1), value 3
    sol = solve_zero_sum([[1.0, 2.0], [3.0, 4.0]])
    assert sol.value == pytest.approx(3.0)
    assert sol.row.tolist() == [0.0, 1.0] and sol.col.tolist() == [1.0, 0.0]
    assert sol.row_exploitability == pytest.approx([2.0, 0.0])
    assert sol.col_exploitability == pytest.approx([0.0, 1.0])


def test_three_by_three_hand_solved():
    # rock-paper-scissors: uniform, value 0
    rps = solve_zero_sum([[0, -1, 1], [1, 0, -1], [-1, 1, 0]])
    assert rps.value == pytest.approx(0.0, abs=1e-9)
    assert rps.row == pytest.approx([1 / 3] * 3) and rps.col == pytest.approx([1 / 3] * 3)
    # skew-symmetric, unequal: x A = 0 gives -2b + c = 0, 2a - c = 0, -a + b = 0
    skew = np.array([[0.0, 2.0, -1.0], [-2.0, 0.0, 1.0], [1.0, -1.0, 0.0]])
    sol = solve_zero_sum(skew + 5.0)  # a constant shift moves the value, not the strategies
    assert sol.value == pytest.approx(5.0, abs=1e-9)
    assert sol.row == pytest.approx([0.25, 0.25, 0.5], abs=1e-9)
    assert sol.col == pytest.approx([0.25, 0.25, 0.5], abs=1e-9)
    # a dominated third row (row 1 beats it everywhere) gets weight 0
    dom = solve_zero_sum([[3.0, 0.0, 2.0], [0.0, 3.0, 2.0], [-1.0, -1.0, 1.0]])
    assert dom.row[2] == 0.0
    assert dom.value == pytest.approx(1.5, abs=1e-9)  # columns 1-2 alone: value 1.5 < 2
    assert dom.row == pytest.approx([0.5, 0.5, 0.0], abs=1e-9)


@pytest.mark.parametrize("seed", range(6))
def test_random_games_against_fictitious_play(seed):
    rng = np.random.default_rng(seed)
    m, n = rng.integers(2, 7, size=2)
    a = rng.normal(size=(m, n))
    sol = solve_zero_sum(a)
    # an equilibrium certifies itself: no pure deviation gains (minimax theorem)
    assert (a @ sol.col).max() == pytest.approx(sol.value, abs=1e-8)
    assert (sol.row @ a).min() == pytest.approx(sol.value, abs=1e-8)
    assert abs(sol.gap) < 1e-8
    # fictitious play brackets the value: min_j (x A)_j <= v <= max_i (A y)_i, tightening
    x, y = fictitious_play(a, 20000)
    lower, upper = (x @ a).min(), (a @ y).max()
    assert lower - 1e-12 <= sol.value <= upper + 1e-12
    assert upper - lower < 0.05
    assert row_exploitability(a, sol.row) == pytest.approx(0.0, abs=1e-8)
    assert column_exploitability(a, sol.col) == pytest.approx(0.0, abs=1e-8)
    assert row_exploitability(a, x) >= -1e-12 and column_exploitability(a, y) >= -1e-12


def test_bad_matrices_are_refused():
    for bad in ([], [[1.0, np.nan]], [1.0, 2.0], [["a", "b"]]):
        with pytest.raises(InvalidConfigError):
            solve_zero_sum(bad)
    with pytest.raises(InvalidConfigError):
        row_exploitability([[1.0, 0.0]], [-1.0])


def test_mixed_policy_samples_its_weights_reproducibly():
    mix = MixedPolicy(["evader/straight", "evader/random", "evader/toward_away"], [0.2, 0.8, 0.0])
    assert [p.name for p in mix.components] == ["evader/straight", "evader/random"]
    picks = [mix.select(s).name for s in range(2000)]
    share = picks.count("evader/random") / len(picks)
    assert abs(share - 0.8) < 4 * np.sqrt(0.8 * 0.2 / len(picks))
    assert [mix.select(s).name for s in range(50)] == picks[:50]  # seeded by the episode
    own = MixedPolicy(["evader/straight", "evader/random"], seed=3)
    again = MixedPolicy(["evader/straight", "evader/random"], seed=3)
    assert [own.select().name for _ in range(20)] == [again.select().name for _ in range(20)]
    with pytest.raises(InvalidConfigError, match="roles"):
        MixedPolicy(["evader/straight", "pursuer/greedy"])
    with pytest.raises(InvalidConfigError):
        MixedPolicy(["evader/straight"], [-1.0])
    with pytest.raises(InvalidConfigError):
        MixedPolicy([])


@pytest.mark.parametrize(
    ("make", "message"),
    [
        # a lone name was iterated letter by letter: "unknown policy 'e'"
        (lambda: MixedPolicy("evader/straight"), r"policies = 'evader/straight': expected a list"),
        (lambda: MixedPolicy(3), r"policies = 3: expected a list"),
        # a component that is no policy was taken, and failed at the first episode
        (lambda: MixedPolicy(["evader/straight", 3]), r"components must be policy names or "),
        # numpy's bare 'expected non-negative integer', naming no argument
        (lambda: MixedPolicy(["evader/straight"], seed=-1), r"MixedPolicy: seed = -1: expected"),
    ],
)
def test_a_mixture_of_no_policies_or_a_bad_seed_is_refused_by_name(make, message):
    with pytest.raises(InvalidConfigError, match=message):
        make()


def test_a_mixture_reset_with_a_bad_seed_is_refused_by_name():
    from envs import surveillance_v1

    config = surveillance_v1.parallel_env(map="corridor").config
    mix = MixedPolicy(["evader/straight", "evader/random"])
    with pytest.raises(InvalidConfigError, match=r"reset: seed = -3: expected an integer >= 0"):
        mix.reset(role="evader", map=config.map, config=config, seed=-3)
    assert mix.current is None  # nothing drawn
    assert MixedPolicy(p for p in ["evader/straight"]).components[0].name == "evader/straight"


def test_mixed_policy_plays_through_the_policy_protocol():
    from envs import surveillance_v1

    env = surveillance_v1.parallel_env(map="open_room", max_cycles=10)
    mix = MixedPolicy.from_weights({"pursuer/greedy": 1.0, "pursuer/random": 1.0})
    assert mix.roles == ("pursuer",)
    obs, _ = env.reset(seed=0)
    mix.reset(role="pursuer", map=env.config.map, config=env.config, seed=5)
    first = mix.current.name
    action = mix.act(obs["pursuer_0"])
    assert action.shape == (2,) and np.all(np.abs(action) <= 1.0)
    mix.reset(role="pursuer", map=env.config.map, config=env.config, seed=5)
    assert mix.current.name == first
    assert mix.observation_options == {"observation": "state"}


def test_mixed_policy_predict_is_its_component_s_act_single_and_batched():
    from envs import surveillance_v1

    env = surveillance_v1.parallel_env(map="open_room", max_cycles=10)
    obs, _ = env.reset(seed=1)
    seen = [obs["pursuer_0"]]
    rng = np.random.default_rng(0)
    for _ in range(5):
        obs, *_ = env.step({a: rng.uniform(-1, 1, 2).astype(np.float32) for a in env.agents})
        seen.append(obs["pursuer_0"])
    mixes = [MixedPolicy.from_weights({"pursuer/greedy": 1.0, "pursuer/random": 1.0}) for _ in "ab"]
    for mix in mixes:
        mix.reset(role="pursuer", map=env.config.map, config=env.config, seed=3)
    acting, predicting = mixes
    for o in seen:
        action, state = predicting.predict(o, state="kept?", deterministic=True)
        assert state is None
        assert action.tobytes() == acting.act(o).tobytes()
    for mix in mixes:
        mix.reset(role="pursuer", map=env.config.map, config=env.config, seed=3)
    batch, _ = predicting.predict(np.stack(seen))
    assert batch.shape == (len(seen), 2)
    assert batch.tobytes() == np.stack([acting.act(o) for o in seen]).tobytes()
