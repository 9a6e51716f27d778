"""Shared fixtures: a small world, its config, state observations along a path, and the
unseen-worlds benchmark module."""

from __future__ import annotations

import importlib
import math
from pathlib import Path

import numpy as np
import pytest

from envs.maps import Map
from envs.surveillance.config import EnvConfig
from envs.surveillance.observations import StateEncoder

BENCHMARKS = Path(__file__).resolve().parents[3] / "benchmarks"


@pytest.fixture(scope="session")
def box_world() -> Map:
    """A 12 x 8 room with one square pillar (convex corners for the corner policies)."""
    return Map(
        [(0, 0), (12, 0), (12, 8), (0, 8)],
        [[(8, 5), (10, 5), (10, 7), (8, 7)]],
        name="pillar_box",
    )


@pytest.fixture(scope="session")
def box_config(box_world: Map) -> EnvConfig:
    return EnvConfig(map=box_world, l_min=2.0, l_max=4.0, v_pursuer=1.0, v_evader=0.5)


def state_observations(config: EnvConfig, n: int = 12, seed: int = 0) -> list[np.ndarray]:
    """Observations of an evader walking a circle with the pursuer 2.5 away, in free space."""
    enc = StateEncoder(config)
    rng = np.random.default_rng(seed)
    out = []
    for k in range(n):
        a = 0.3 * k
        e = (3.0 + 1.0 * math.cos(a), 2.0 + 0.8 * math.sin(a))
        th = 0.5 + 0.1 * k
        p = (e[0] + 2.5 * math.cos(th), e[1] + 2.5 * math.sin(th))
        ve = tuple(rng.uniform(-0.5, 0.5, 2))
        vp = tuple(rng.uniform(-1, 1, 2))
        out.append(enc.encode(p, vp, e, ve, True, k))
    return out


def decomposition_pursuer(
    world: str | EnvConfig = "open_room", overrides: dict | None = None, **params
):
    """A ``pursuer/decomposition`` (with ``params``) reset at seed 0 on a built-in map's
    env (its recommended parameters with ``overrides``) or on an ``EnvConfig``."""
    from strategies.policies import make_policy
    from strategies.runner import build_env

    config = (
        world if isinstance(world, EnvConfig) else build_env(world, dict(overrides or {})).config
    )
    policy = make_policy("pursuer/decomposition", **params)
    policy.reset(role="pursuer", map=config.map, config=config, seed=0)
    return policy


@pytest.fixture
def unseen(monkeypatch):
    """The unseen-worlds benchmark module (benchmarks/unseen_worlds.py): its worlds,
    parameter combos and opponents, for replaying a benchmark episode in a test."""
    monkeypatch.syspath_prepend(str(BENCHMARKS))
    return importlib.import_module("unseen_worlds")


def orbit_episode(unseen, world: str, max_cycles: int, start="safe"):
    """The decomposition pursuer against the orbit at offset 0.25 (ccw, seed 101) on an
    unseen-worlds ``world`` with combo 0's parameters, as unseen-p0 / fresh-p0 play it."""
    from strategies.runner import run_episode

    m, ov = unseen.pursuer_world(world, unseen.PURSUER_COMBOS[0])
    return run_episode(
        m,
        "pursuer/decomposition",
        unseen.make_opponent("evader/orbit:1:0.25"),
        101,
        max_cycles=max_cycles,
        overrides=ov,
        start=start,
    )
