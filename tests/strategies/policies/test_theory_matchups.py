"""The theory's predictions, played in the env (few seeds, short episodes).

* Fig. 3 corridor, rho = 0.5, safe start: the decomposition pursuer keeps surveillance
  against every registered evader (Secs. 4-5).
* Fig. 6 two rooms: the shooting evader escapes from every registered pursuer (Prop. 2).
* rho > 1: the evader escapes (footnote 4).
* The decomposition pursuer does at least as well as the greedy one; the shooting evader
  escapes sooner than the straight-line evader.
"""

from __future__ import annotations

import pytest

from strategies.policies import policy_names
from strategies.runner import run_episode as play_episode

SEEDS = (0, 1)


@pytest.mark.parametrize("evader", policy_names("evader"))
def test_corridor_decomposition_pursuer_holds_against_every_evader(evader):
    for seed in SEEDS:
        r = play_episode("corridor", "pursuer/decomposition", evader, seed, max_cycles=250)
        assert r.winner == "pursuer", r.summary()
        assert r.steps == 250


@pytest.mark.parametrize("pursuer", policy_names("pursuer"))
def test_two_rooms_shooting_evader_escapes_from_every_pursuer(pursuer):
    for seed in SEEDS:
        r = play_episode("two_rooms", pursuer, "evader/shooting", seed, max_cycles=1000)
        assert r.winner == "evader", r.summary()
        assert r.cause in ("occluded", "too_far", "too_close")


@pytest.mark.parametrize("map_name", ["corridor", "open_room", "pillars", "two_rooms"])
@pytest.mark.parametrize("pursuer", ["pursuer/decomposition", "pursuer/greedy"])
@pytest.mark.filterwarnings("ignore::envs.errors.RhoAboveOneWarning")  # rho > 1 on purpose
def test_faster_evader_escapes_everywhere(map_name, pursuer):
    r = play_episode(
        map_name, pursuer, "evader/shooting", 0, max_cycles=400, overrides={"v_evader": 1.5}
    )
    assert r.winner == "evader", r.summary()


def test_decomposition_beats_greedy_in_the_corridor():
    held = {
        p: sum(
            play_episode("corridor", p, "evader/shooting", s, max_cycles=250).winner == "pursuer"
            for s in SEEDS
        )
        for p in ("pursuer/decomposition", "pursuer/greedy")
    }
    assert held["pursuer/decomposition"] == len(SEEDS)
    assert held["pursuer/greedy"] < held["pursuer/decomposition"]


def test_shooting_escapes_sooner_than_straight_line():
    times = {}
    for e in ("evader/shooting", "evader/straight"):
        rs = [play_episode("two_rooms", "pursuer/greedy", e, s, max_cycles=1000) for s in SEEDS]
        times[e] = sum(r.escape_time if r.escape_time is not None else 100.0 for r in rs)
    assert times["evader/shooting"] < times["evader/straight"]
