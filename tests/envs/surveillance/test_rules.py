"""The pure rule functions: surveillance status, reward components, truncation."""

from __future__ import annotations

import pytest

from envs.geometry import kernel_for
from envs.surveillance import rules
from tests.envs.surveillance._worlds import pillar_room


def test_status_checks_range_inclusively_then_line_of_sight() -> None:
    k = kernel_for(pillar_room())
    assert rules.surveillance_status(k, (2.0, 1.0), (2.0, 3.0), 2.0, 4.0).holds  # L = l_min
    assert rules.surveillance_status(k, (2.0, 1.0), (2.0, 5.0), 2.0, 4.0).holds  # L = l_max
    s = rules.surveillance_status(k, (2.0, 1.0), (2.0, 2.5), 2.0, 4.0)
    assert (s.holds, s.cause, s.distance) == (False, "too_close", 1.5)
    s = rules.surveillance_status(k, (1.0, 1.0), (1.0, 6.0), 2.0, 4.0)
    assert (s.holds, s.cause) == (False, "too_far")
    s = rules.surveillance_status(k, (3.0, 5.0), (7.0, 5.0), 2.0, 5.0)
    assert s.cause == "occluded" and s.feature is not None
    # an occluded pair out of range reports the range (checked first)
    assert rules.surveillance_status(k, (1.0, 5.0), (9.0, 5.0), 2.0, 5.0).cause == "too_far"


@pytest.mark.parametrize("cycles", [1, 7, 500])
def test_reward_components(cycles: int) -> None:
    rc = rules.reward_components
    held = rc("zero_sum", escaped=False, truncated=False, max_cycles=cycles)
    assert (held.surveillance, held.escape, held.horizon) == (1.0 / cycles, 0.0, 0.0)
    assert rc("zero_sum", escaped=False, truncated=True, max_cycles=cycles).total == 1.0 / cycles
    lost = rc("zero_sum", escaped=True, truncated=False, max_cycles=cycles)
    assert (lost.surveillance, lost.escape, lost.total) == (0.0, -1.0, -1.0)
    assert rc("sparse", escaped=False, truncated=False, max_cycles=cycles).total == 0.0
    assert rc("sparse", escaped=False, truncated=True, max_cycles=cycles).horizon == 1.0
    assert rc("sparse", escaped=True, truncated=True, max_cycles=cycles).total == -1.0
    with pytest.raises(ValueError, match="dense"):
        rc("dense", escaped=False, truncated=False, max_cycles=cycles)


def test_truncation_at_the_horizon() -> None:
    assert not rules.truncated(4, 5) and rules.truncated(5, 5) and rules.truncated(6, 5)
