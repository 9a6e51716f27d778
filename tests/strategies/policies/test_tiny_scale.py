"""The analytic policies on a world scaled far down: their tables' rod length kept its
digits (6 decimals made it 0 at 1e-7: every reset raised ``safety_table: L = 0.0``)."""

import pytest

from strategies.policies.base import rounded_length
from strategies.runner import run_episode


def test_rounded_length_keeps_six_digits_of_any_length():
    assert rounded_length(2.1 + 1e-12) == 2.1  # float noise does not make another table
    assert rounded_length(0.7050000000001) == 0.705
    assert rounded_length(2.2e-7 * (1 + 1e-12)) == 2.2e-7
    assert rounded_length(1.234567e-9) == pytest.approx(1.23457e-9, rel=1e-12)


@pytest.mark.parametrize("scale", ["1e-7", "1e-5"])
def test_the_corridor_scaled_down_is_played_as_at_scale_one(scale):
    """corridor~x1e-7, seed 0: the decomposition pursuer holds the shooting evader as it
    does on the corridor itself (500 steps there)."""
    r = run_episode(
        f"corridor~x{scale}", "pursuer/decomposition", "evader/shooting", 0, max_cycles=150
    )
    assert r.winner == "pursuer", (r.winner, r.cause)
