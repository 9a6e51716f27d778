"""The evaluation harness: intervals against closed forms, episodes, JSONL resume."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from scipy import stats

from analysis.evaluate import (
    bootstrap_mean_interval,
    evaluate,
    format_table,
    play_episode,
    t_mean_interval,
    wilson_interval,
)
from envs.errors import InvalidConfigError


def test_wilson_interval_closed_form():
    # hand-computed: p = 0.8, n = 10, z = 1.959964
    lo, hi = wilson_interval(8, 10)
    assert lo == pytest.approx(0.4901625, abs=1e-6)
    assert hi == pytest.approx(0.9433178, abs=1e-6)
    assert wilson_interval(0, 5)[0] == 0.0 and wilson_interval(5, 5)[1] == 1.0
    assert wilson_interval(0, 0) == (0.0, 1.0)
    # coverage: the true p lies inside the 95% interval about 95% of the time
    rng = np.random.default_rng(0)
    k = rng.binomial(30, 0.3, size=4000)
    inside = [wilson_interval(int(x), 30)[0] <= 0.3 <= wilson_interval(int(x), 30)[1] for x in k]
    assert 0.92 < np.mean(inside) < 0.98
    with pytest.raises(InvalidConfigError):
        wilson_interval(6, 5)


def test_mean_intervals():
    x = [1.0, 2.0, 4.0, 7.0]
    m, lo, hi = t_mean_interval(x)
    ref = stats.t.interval(0.95, 3, loc=np.mean(x), scale=stats.sem(x))
    assert (m, lo, hi) == pytest.approx((3.5, *ref))
    assert math.isnan(t_mean_interval([])[0])
    assert t_mean_interval([2.0])[1] == -math.inf
    bm, blo, bhi = bootstrap_mean_interval(x, seed=1)
    assert bm == 3.5 and min(x) <= blo < bm < bhi <= max(x)


def test_play_episode_result_fields():
    r = play_episode("open_room", "pursuer/greedy", "evader/random", 3, max_cycles=40)
    assert r.winner in ("pursuer", "evader")
    assert r.trajectory.shape == (r.steps + 1, 2, 2)
    assert np.allclose(r.trajectory[0, 0], r.start["pursuer"], atol=1e-4)
    if r.winner == "pursuer":
        assert r.steps == 40 and r.cause is None and r.escape_time is None
    else:
        assert 0 < r.escape_time <= r.steps * r.dt
    again = play_episode("open_room", "pursuer/greedy", "evader/random", 3, max_cycles=40)
    assert np.array_equal(again.trajectory, r.trajectory)  # same seed, same episode
    assert json.loads(json.dumps(r.to_record()))["seed"] == 3
    assert "open_room" in r.summary()


def test_faster_evader_straight_away_breaks_range():
    r = play_episode(
        "open_room",
        "pursuer/greedy",
        "evader/toward_away",
        0,
        max_cycles=300,
        overrides={"v_evader": 1.5, "v_pursuer": 0.5},
        start="valid",
    )
    assert r.winner == "evader" and r.cause in ("too_far", "occluded", "too_close")


def test_evaluate_is_a_resumable_one_off_tournament(tmp_path):
    path = tmp_path / "res.sqlite"
    kw = dict(max_cycles=30, results_path=path, progress=False)
    rows = evaluate(["open_room"], ["pursuer/greedy"], ["evader/random"], range(3), **kw)
    assert len(rows) == 1 and rows[0].n == 3
    assert rows[0].rate_lo <= rows[0].rate <= rows[0].rate_hi
    again = evaluate(["open_room"], ["pursuer/greedy"], ["evader/random"], range(3), **kw)
    assert again == rows  # stored matches are reused, not replayed
    twice = evaluate(
        ["open_room"], ["pursuer/greedy", "pursuer/greedy"], ["evader/random"], range(3), **kw
    )
    assert [r.n for r in twice] == [3]  # a repeated name is one entry
    text = format_table(again)
    assert "pursuer/greedy" in text and "evader/random" in text


def test_evaluate_stops_when_a_signal_stopped_its_tournament(tmp_path, monkeypatch):
    """SIGTERM ends the tournament early; evaluate must not play its next variant."""
    import analysis.tournament as tournament

    calls = []

    def interrupted(spec, store, **kw):
        calls.append(spec)
        return tournament.RunSummary("r", "evaluate", store, 3, 0, interrupted="SIGTERM")

    monkeypatch.setattr(tournament, "run_tournament", interrupted)
    with pytest.raises(KeyboardInterrupt, match="SIGTERM"):
        evaluate(["open_room"], ["pursuer/greedy"], ["evader/random"], range(3),
                 overrides=[{}, {"v_evader": 1.5}], results_path=tmp_path / "r.sqlite",
                 progress=False)  # fmt: skip
    assert len(calls) == 1


@pytest.mark.parametrize("n", [1, 3, 10, 57])
def test_wilson_ends_agree_with_the_general_formula(n):
    z = stats.norm.ppf(0.975)
    for k in (0, n):
        p = k / n
        centre = (p + z * z / (2 * n)) / (1 + z * z / n)
        half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
        assert wilson_interval(k, n) == pytest.approx((centre - half, centre + half), abs=1e-12)
