"""benchmarks/unseen_worlds.py: a tiny subset of each role, its JSONL rows and the resume."""

from __future__ import annotations

import importlib
import json
from pathlib import Path

import pytest

BENCHMARKS = Path(__file__).resolve().parents[1] / "benchmarks"


@pytest.fixture
def unseen(monkeypatch):
    """The benchmark module (it imports its opponents module from beside it)."""
    monkeypatch.syspath_prepend(str(BENCHMARKS))
    return importlib.import_module("unseen_worlds")


def _rows(path: Path) -> list[dict]:
    return [json.loads(line) for line in path.read_text().splitlines()]


def test_the_evader_role_draws_the_sweeps_episodes(unseen) -> None:
    """The draws (rng 52, the worlds' order) give the 1189 episodes of helper-52's sweep."""
    jobs = unseen.evader_jobs(2)
    assert len(jobs) == len({unseen.job_key(j) for j in jobs}) == 1189
    assert jobs[:2] == [
        ("evader", "two_rooms~rot2.2", [0.95, 1.5, 1.0], "pursuer/corner_rounding", 715),
        ("evader", "two_rooms~rot2.2", [0.5, 2.0, 1.0], "pursuer/corner_rounding", 674),
    ]


def test_a_pursuer_subset_is_written_and_resumed(unseen, tmp_path, capsys) -> None:
    out = tmp_path / "p.jsonl"
    argv = ["--role", "pursuer", "--worlds", "corridor~rot2.3", "--combos", "0",
            "--opponents", "zigzag:1.1:1", "herder", "--max-cycles", "100",
            "--results", str(out)]  # fmt: skip
    assert unseen.main(argv) == 0
    rows = _rows(out)
    assert [(r["world"], r["combo"], r["opponent"], r["seed"]) for r in rows] == [
        ("corridor~rot2.3", [0.5, 2.0, 2.0], "zigzag:1.1:1", 101),
        ("corridor~rot2.3", [0.5, 2.0, 2.0], "herder", 101),
    ]
    assert all(r["winner"] == "pursuer" and r["steps"] == 100 for r in rows)
    assert "held 2/2 at rho 0.5" in capsys.readouterr().out
    assert unseen.main(argv) == 0  # the second run plays nothing new
    assert "2 episodes selected, 0 to play" in capsys.readouterr().out
    assert _rows(out) == rows


def test_an_evader_subset_escapes_and_prints_no_loss(unseen, tmp_path, capsys) -> None:
    out = tmp_path / "e.jsonl"
    argv = ["--role", "evader", "--worlds", "plus_w1.0", "--opponents", "still", "--results",
            str(out)]  # fmt: skip
    assert unseen.main(argv) == 0
    rows = _rows(out)
    assert len(rows) == 4  # 2 L_min x 2 draws
    assert all(r["winner"] == "evader" and 0 < r["t"] < 8 * r["unit"] for r in rows)
    text = capsys.readouterr().out
    assert "shooting evader escaped 4/4" in text and "lost:" not in text


def test_a_loss_is_printed_with_its_replay_command(unseen, capsys) -> None:
    row = {"role": "pursuer", "world": "maze~x0.7rot-2.6", "combo": [0.5, 2.0, 2.0],
           "opponent": "herder", "seed": 101, "winner": "evader", "cause": "too_close",
           "t": 31.17}  # fmt: skip
    unseen.report([row])
    text = capsys.readouterr().out
    assert "held 0/1" in text and "herder seed=101: too_close at 31.2 s" in text
    assert (
        "replay: python benchmarks/unseen_worlds.py --role pursuer --worlds maze~x0.7rot-2.6 "
        "--combos 0 --opponents 'herder' --seeds 101" in text
    )


@pytest.mark.parametrize("label", ["nope", "zigzag:x:1"])
def test_an_unknown_opponent_is_a_usage_error_naming_it(unseen, tmp_path, capsys, label) -> None:
    results = tmp_path / "r.jsonl"
    with pytest.raises(SystemExit) as exc:
        unseen.main(["--role", "pursuer", "--worlds", "plus_w6", "--opponents", label,
                     "--results", str(results)])  # fmt: skip
    assert exc.value.code == 2
    assert f"--opponents: {label!r} is no opponent" in capsys.readouterr().err
    assert not results.exists()  # nothing played
