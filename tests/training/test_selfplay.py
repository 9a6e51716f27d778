"""Self-play with tiny budgets: alternation, opponents by SB3 name, warm starts, resume."""

from __future__ import annotations

import json

import pytest

from envs.errors import InvalidConfigError
from training import self_play


def test_two_rounds_alternate_against_latest_models(tiny, tmp_path):
    config = tiny(total_timesteps=64, eval_episodes=1, output_dir=str(tmp_path / "sp"))
    result = self_play(config, rounds=2)
    stages = result.stages
    assert [s.config.role for s in stages] == ["pursuer", "evader", "pursuer", "evader"]
    assert stages[0].config.opponent == "evader/straight"
    assert stages[1].config.opponent == f"pursuer/sb3:{stages[0].model_path}"
    assert stages[2].config.opponent == f"evader/sb3:{stages[1].model_path}"
    assert stages[3].config.opponent == f"pursuer/sb3:{stages[2].model_path}"
    assert [s.config.seed for s in stages] == [0, 1, 2, 3]
    for s in stages:
        assert s.model_path.is_file() and s.timesteps == 64
        assert s.evaluation is not None and s.evaluation.opponent == s.config.opponent
    prov = json.loads(stages[2].provenance_path.read_text())
    assert prov["init_model"] == str(stages[0].model_path)  # warm start from round 0
    assert result.policy_names == {
        "pursuer": f"pursuer/sb3:{stages[2].model_path}",
        "evader": f"evader/sb3:{stages[3].model_path}",
    }
    # rerunning finds every stage finished and trains nothing
    again = self_play(config, rounds=2)
    assert [s.wall_time for s in again.stages] == [0.0] * 4


def test_a_warm_started_round_trains(tiny, tmp_path):
    """A warm start loaded the earlier model's timestep counter, which left no timestep to
    train: every round after the first returned its warm start unchanged (same weights,
    'trained' in 0.04 s), whatever the new opponent."""
    import hashlib
    import zipfile

    config = tiny(total_timesteps=64, eval_episodes=0, output_dir=str(tmp_path / "sp"))
    stages = self_play(config, rounds=2).stages

    def weights(stage):
        with zipfile.ZipFile(stage.model_path) as z:
            return hashlib.sha256(z.read("policy.pth")).hexdigest()

    for later, earlier in ((stages[2], stages[0]), (stages[3], stages[1])):
        prov = json.loads(later.provenance_path.read_text())
        assert prov["init_model"] == str(earlier.model_path)
        assert weights(later) != weights(earlier)
        assert later.timesteps == 64


def test_bad_rounds(tiny):
    with pytest.raises(InvalidConfigError, match="rounds"):
        self_play(tiny(), rounds=0)
