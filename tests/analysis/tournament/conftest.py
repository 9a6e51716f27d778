"""Shared fixtures: small specs and test-only policies (raising, hanging, slow ones).

The ``test_policies`` fixture registers the test policies for one test only (other tests
enumerate the registry); the process backend forks its workers, which inherit them.
"""

from __future__ import annotations

import signal
import time
from typing import ClassVar

import numpy as np
import pytest

from envs.errors import InvalidConfigError
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


class DeafPickEvader(RandomPolicy):
    """A mixture whose pick of the episode's policy hangs with SIGALRM blocked.

    The runner picks before any policy decides (the harness's work, on no clock).
    """

    def select(self, seed):
        signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGALRM})
        time.sleep(3600)


class LidarEvader(RandomPolicy):
    """A random evader that asks for a 4096-ray lidar: the env's work, on no clock."""

    uses_state = False
    observation_options: ClassVar[dict] = {"observation": "lidar", "n_rays": 4096}

    def act(self, observation):
        self._steps += 1
        return self.rng.uniform(-0.7, 0.7, 2)


class SlowResetPursuer(RandomPolicy):
    """A random pursuer whose reset takes 1.5 s."""

    def _reset(self):
        time.sleep(1.5)


class MapSetUpPursuer(RandomPolicy):
    """A random pursuer whose reset builds something of the map once per process, in
    1.5 s (as the shooting evader builds its escape plan), then finds it built."""

    built: ClassVar[set[str]] = set()  # the digests of the maps built in this process

    def _reset(self):
        if self.map.digest not in self.built:
            time.sleep(1.5)
            self.built.add(self.map.digest)


class WrappingHangPursuer(RandomPolicy):
    """Its reset hangs, and it reports whatever interrupts it as a configuration error of
    its own, as a model loader reports any failure of its load as a bad model file."""

    def _reset(self):
        try:
            time.sleep(3600)
        except Exception as exc:
            raise InvalidConfigError(f"cannot load the model file ({exc})") from exc


class SlowActEvader(RandomPolicy):
    """A random evader that takes 2 ms per decision (or the wait for a CPU under load)."""

    def _decide(self, snap):
        time.sleep(0.002)
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
    "evader/test_deaf_pick": DeafPickEvader,
    "evader/test_lidar": LidarEvader,
    "evader/test_slow_act": SlowActEvader,
    "pursuer/test_slow_reset": SlowResetPursuer,
    "pursuer/test_map_set_up": MapSetUpPursuer,
    "pursuer/test_wrapping_hang": WrappingHangPursuer,
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
