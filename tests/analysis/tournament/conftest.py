"""Shared fixtures: small specs and test-only policies (a raising, a hanging, a slow one).

The ``test_policies`` fixture registers the test policies for one test only (other tests
enumerate the registry); the process backend forks its workers, which inherit them.
"""

from __future__ import annotations

import signal
import time

import numpy as np
import pytest

from strategies.policies import registry
from strategies.policies.baselines import RandomPolicy


class RaisingEvader(RandomPolicy):
    """Raises at step 3."""

    def _decide(self, snap):
        if self._steps == 3:
            raise ZeroDivisionError("the test evader divides by zero")
        return super()._decide(snap)


class HangingEvader(RandomPolicy):
    """Sleeps for ever at step 2 (SIGALRM interrupts it)."""

    def _decide(self, snap):
        if self._steps == 2:
            time.sleep(3600)
        return super()._decide(snap)


class DeafHangingEvader(RandomPolicy):
    """Hangs at step 2 with SIGALRM blocked: only killing the process ends it."""

    def _decide(self, snap):
        if self._steps == 2:
            signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGALRM})
            time.sleep(3600)
        return super()._decide(snap)


class SlowPursuer(RandomPolicy):
    """A random pursuer that takes a few milliseconds per decision."""

    def _decide(self, snap):
        time.sleep(0.002)
        return super()._decide(snap)


class NanEvader(RandomPolicy):
    """Returns a NaN action at step 3 (a user's policy overriding ``act``)."""

    def act(self, observation):
        action = super().act(observation)
        return np.array([np.nan, 0.0]) if self._steps == 4 else action


TEST_POLICIES = {
    "evader/test_raising": RaisingEvader,
    "evader/test_nan": NanEvader,
    "evader/test_hanging": HangingEvader,
    "evader/test_deaf": DeafHangingEvader,
    "pursuer/test_slow": SlowPursuer,
}


@pytest.fixture
def test_policies(monkeypatch):
    """Register the test policies for the duration of one test."""
    registry.policy_names()  # load the real ones first
    for name, cls in TEST_POLICIES.items():
        spec = registry.PolicySpec(name, cls, "test only", {"hold": 1})
        monkeypatch.setitem(registry._REGISTRY, name, spec)
    return TEST_POLICIES


@pytest.fixture
def small_spec():
    """A 2 maps x 2 pursuers x 2 evaders x 3 seeds spec of short episodes (24 matches)."""
    return {
        "name": "small",
        "maps": ["open_room", "corridor"],
        "pursuers": ["pursuer/greedy", "pursuer/tractrix"],
        "evaders": ["evader/straight", "evader/random"],
        "seeds": 3,
        "start": "valid",
        "env": {"max_cycles": 60},
    }


def comparable(rows):
    """Store rows without the wall-clock fields (which differ from run to run)."""
    skip = {"decide_pursuer", "decide_evader", "wall_seconds"}
    return [{k: v for k, v in r.items() if k not in skip} for r in rows]
