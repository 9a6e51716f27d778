"""The PSRO loop: tournaments, Nash pools, alternating learners, a final rating."""

from __future__ import annotations

import json

import numpy as np
import pytest

from analysis.psro import PsroConfig, psro
from envs.errors import InvalidConfigError


def test_two_rounds_train_each_role_against_the_nash_pool_and_rate_them(tmp_path):
    cfg = PsroConfig(maps=("open_room",), pursuers=("pursuer/greedy",),
                     evaders=("evader/straight", "evader/random"), rounds=2, seeds=3,
                     timesteps=256, max_cycles=30, floor=0.2,
                     observation={"observation": "lidar_track", "n_rays": 8},
                     output_dir=str(tmp_path / "psro"))  # fmt: skip
    r = psro(cfg)
    assert [x["role"] for x in r.rounds] == ["pursuer", "evader"]
    first, second = r.rounds
    # round 0: the pursuer trains against the evaders' Nash mixture (plus the floor)
    assert set(first["pool"]) == {"evader/straight", "evader/random"}
    assert sum(first["pool"].values()) == pytest.approx(1.0)
    assert min(first["pool"].values()) >= 0.2 / 2 - 1e-12
    # round 1: the evader's pool holds the round-0 snapshot beside the anchor
    assert set(second["pool"]) == {"pursuer/greedy", "psro_pursuer_0"}
    # the last tournament rates every snapshot, and the run is on disk
    assert {"psro_pursuer_0", "psro_evader_1"} <= set(r.ratings)
    assert all(np.isfinite(v) and v >= -1e-9 for v in r.exploitability.values())
    record = json.loads((tmp_path / "psro" / "psro.json").read_text())
    assert record["rounds"][1]["learner"] == "psro_evader_1"
    # a rerun reuses the finished tournaments and trainings and gives the same answer
    again = psro(cfg)
    assert again.rounds == r.rounds and again.value == pytest.approx(r.value)


@pytest.mark.parametrize(
    "bad",
    [
        {"pursuers": ("evader/straight",)},
        {"maps": ()},
        {"rounds": 0},
        {"floor": 2.0},
        {"first_role": "referee"},
    ],
)
def test_bad_psro_configs_name_the_field(bad):
    base = dict(maps=("open_room",), pursuers=("pursuer/greedy",), evaders=("evader/straight",))
    with pytest.raises(InvalidConfigError):
        PsroConfig(**{**base, **bad})
