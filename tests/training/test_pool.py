"""Opponent pools: one member drawn per episode, in the proportions asked for."""

from __future__ import annotations

import numpy as np
import pytest

from envs.errors import InvalidConfigError
from strategies.runner import run_episode
from training.pool import OpponentPool
from training.single_agent import SingleAgentEnv

EVADERS = ["evader/straight", "evader/shooting", "evader/random"]


def test_the_pool_samples_what_it_is_told() -> None:
    pool = OpponentPool(EVADERS, weights=[6, 3, 1])
    n = 6000
    counts = np.bincount([pool.index(s) for s in range(n)], minlength=3)
    expected = np.array(pool.probabilities) * n
    # Pearson chi-square, 2 degrees of freedom: 13.8 is its 0.999 quantile
    assert np.sum((counts - expected) ** 2 / expected) < 13.8
    assert pool.probabilities == pytest.approx((0.6, 0.3, 0.1))


def test_a_zero_weight_member_is_never_drawn_and_draws_are_seeded() -> None:
    pool = OpponentPool(EVADERS, weights=[1, 0, 1])
    assert 1 not in {pool.index(s) for s in range(2000)}
    assert [pool.index(s) for s in range(50)] == [pool.index(s) for s in range(50)]
    assert pool.select(3) is pool.select(3)  # built once, reused


def test_nash_weights_from_a_payoff_matrix() -> None:
    # rows: the learner's population; columns: the pool. The column player mixes 50/50
    # (0.9 y + 0.2 (1 - y) = 0.5 y + 0.6 (1 - y)); a dominated column gets nothing.
    pool = OpponentPool.from_payoffs(EVADERS, [[0.9, 0.2, 0.95], [0.5, 0.6, 0.9]])
    assert pool.probabilities == pytest.approx((0.5, 0.5, 0.0), abs=1e-9)
    mixed = OpponentPool.from_payoffs(EVADERS, [[0.9, 0.2, 0.95], [0.5, 0.6, 0.9]], floor=0.3)
    assert mixed.probabilities == pytest.approx((0.45, 0.45, 0.1), abs=1e-9)


def test_the_runner_and_the_training_env_draw_from_a_pool() -> None:
    pool = OpponentPool(["evader/straight", "evader/random"])
    seen = {run_episode("open_room", "pursuer/greedy", pool, s, max_cycles=5).evader
            for s in range(12)}  # fmt: skip
    assert seen == {"evader/straight", "evader/random"}
    env = SingleAgentEnv("pursuer", pool, map="open_room", max_cycles=5)
    names = set()
    env.reset(seed=0)
    for _ in range(12):
        names.add(env.opponent.name)
        env.reset()
    assert names == {"evader/straight", "evader/random"}
    env.close()


@pytest.mark.parametrize(
    "members, weights",
    [
        ([], None),
        ("evader/straight", None),
        (["evader/straight", "pursuer/greedy"], None),
        (["evader/straight"], [1, 2]),
        (["evader/straight", "evader/random"], [0, 0]),
        (["evader/straight", "evader/random"], [1, float("nan")]),
        (["evader/straight", "evader/random"], [-1, 2]),
    ],
)
def test_bad_pools_say_what_is_wrong(members, weights) -> None:
    with pytest.raises(InvalidConfigError, match="opponent pool"):
        OpponentPool(members, weights)


def test_a_pursuer_learner_refuses_a_pool_of_pursuers() -> None:
    with pytest.raises(InvalidConfigError, match="pool of evader"):
        SingleAgentEnv("pursuer", OpponentPool(["pursuer/greedy"]), map="open_room")
