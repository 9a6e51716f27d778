"""A golden seeded rollout (OpenSpiel playthrough style): if it changes, bump the version.

Regenerate deliberately with ``SURVEIL_REGEN_GOLDEN=1 pytest tests/envs/surveillance``
*and* a new ``surveillance_vN`` when rewards, dynamics, observations or defaults change
(only the current version's file is rewritten: a retired version's is frozen).
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import pytest

from envs import surveillance_v0, surveillance_v1

P, E = "pursuer_0", "evader_0"
VERSIONS = {0: surveillance_v0, 1: surveillance_v1}


def _rounded(x: np.ndarray) -> list[float]:
    return [float(f"{v:.7g}") for v in x.tolist()]


def _rollout(module, map_name: str, seed: int, observation: str) -> dict:
    env = module.parallel_env(map=map_name, observation=observation, max_cycles=60)
    obs, _ = env.reset(seed=seed)
    rng = np.random.default_rng(seed)
    steps = [{"obs": _rounded(obs[P])}]
    while env.agents:
        actions = {a: rng.uniform(-1.0, 1.0, 2).astype(np.float32) for a in env.agents}
        obs, rew, term, trunc, infos = env.step(actions)
        info = infos[P]
        steps.append(
            {
                "obs": _rounded(obs[P]),
                "reward": rew[P],
                "terminated": term[P],
                "truncated": trunc[P],
                "cause": info.get("cause"),
                "feature": info.get("feature"),
                "break_time": info.get("break_time"),
            }
        )
    return {"map": map_name, "seed": seed, "observation": observation, "steps": steps}


# an occlusion by a maze corner, then two truncations (state and lidar observations);
# v1 adds an occlusion in a step where a wall deflected a body (v0 timed it at 0.503)
_COMMON = [("maze", 37, "state"), ("pillars", 3, "state"), ("corner", 5, "lidar")]
CASES = {0: _COMMON, 1: [*_COMMON, ("maze", 59, "state")]}


@pytest.mark.parametrize("version", list(VERSIONS))
def test_golden_rollouts(version: int) -> None:
    current = [_rollout(VERSIONS[version], *case) for case in CASES[version]]
    golden_file = Path(__file__).with_name(f"golden_rollout_v{version}.json")
    if os.environ.get("SURVEIL_REGEN_GOLDEN") and version == max(VERSIONS):  # v0 is frozen
        golden_file.write_text(json.dumps(current, separators=(",", ":")) + "\n")
    golden = json.loads(golden_file.read_text())
    assert len(golden) == len(current)
    for want, got in zip(golden, current, strict=True):
        assert (want["map"], want["seed"]) == (got["map"], got["seed"])
        assert len(want["steps"]) == len(got["steps"]), want["map"]
        for k, (w, g) in enumerate(zip(want["steps"], got["steps"], strict=True)):
            where = f"{want['map']} step {k}"
            assert np.allclose(w["obs"], g["obs"], atol=1e-6), where
            for key in ("reward", "terminated", "truncated", "cause", "feature"):
                assert w.get(key) == pytest.approx(g.get(key)), (where, key)
            if w.get("break_time") is not None:
                assert g["break_time"] == pytest.approx(w["break_time"], abs=1e-6), where
