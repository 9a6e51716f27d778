"""Regret: the share of certified-winnable starts a policy loses, and the tournament hook."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from envs.errors import InvalidConfigError
from strategies.referee import Regret, regret, regret_table, tournament_regret
from strategies.runner import run_episode
from tests.strategies.referee.conftest import DT, L_MAX, L_MIN, RADIUS

# rho = 0.5 on purpose: the pursuer bound's own warning is tested in test_vacuity
pytestmark = pytest.mark.filterwarnings("ignore::envs.errors.VacuousBoundWarning")


def _match(ref, start, pursuer, evader, winner, max_cycles=200):
    s = ref.spec
    return {"map": s.map, "l_min": s.l_min, "l_max": s.l_max, "v_pursuer": s.v_pursuer,
            "v_evader": s.v_evader, "body_radius": RADIUS, "dt": DT, "max_cycles": max_cycles,
            "pursuer": pursuer, "evader": evader, "start": start, "winner": winner}  # fmt: skip


def test_regret_counts_only_certified_winnable_starts(corridor_half):
    refs = {}
    rng = np.random.default_rng(0)
    won_e = corridor_half.sample_starts(3, rng, kind="evader")
    unknown = corridor_half.sample_starts(2, rng, kind="unknown")
    matches = [
        _match(corridor_half, won_e[0], "p/a", "e/x", "evader"),
        _match(corridor_half, won_e[1], "p/a", "e/x", "pursuer"),  # e/x blew a won start
        _match(corridor_half, won_e[2], "p/b", "e/y", "evader"),
        _match(corridor_half, unknown[0], "p/a", "e/y", "pursuer"),
        _match(corridor_half, unknown[1], "p/b", "e/x", "evader"),
    ]
    rows = {(r.role, r.policy): r for r in regret(matches, referees=refs, cache=False)}
    assert len(refs) == 1  # one game, solved once
    # the referee of the test fixture and this one agree on the labels
    assert rows[("evader", "e/x")] == Regret("evader", "e/x", 3, 2, 1, 1, 0)
    assert rows[("evader", "e/y")] == Regret("evader", "e/y", 2, 1, 0, 1, 0)
    assert rows[("pursuer", "p/a")] == Regret("pursuer", "p/a", 3, 0, 0, 1, 2)
    assert math.isnan(rows[("pursuer", "p/a")].rate)
    assert rows[("evader", "e/x")].rate == 0.5
    lo, hi = rows[("evader", "e/x")].interval()
    assert 0.0 < lo < 0.5 < hi < 1.0
    # a certified escape longer than the match's horizon is not winnable in that match
    short = _match(corridor_half, won_e[0], "p/a", "e/z", "pursuer", max_cycles=1)
    (z,) = [r for r in regret([short], referees=refs) if r.policy == "e/z"]
    assert z.winnable == 0 and z.unknown == 1 and z.late == 1


def test_a_start_certified_for_the_evader_counts_alike_on_both_rows(corridor_half):
    """The same start, the same horizon rule on both roles' rows: a start certified for the
    evader is the pursuer's "certified for the opponent" exactly when it is the evader's
    "certified winnable", i.e. when its certified escape time is within the match's
    horizon; beyond it both rows count it unknown, and late. The pursuer's row counted it
    for the opponent whatever the horizon (surveil tournament quick: 24 such matches on
    each pursuer's row, 9 winnable on each evader's, 15 of them certified beyond 30 s)."""
    refs: dict = {}
    (start,) = corridor_half.sample_starts(1, np.random.default_rng(3), kind="evader")
    regret([_match(corridor_half, start, "p", "e", "evader")], referees=refs, cache=False)
    (ref,) = refs.values()  # the referee regret() counts with
    t = ref.escape_time(start["pursuer"], start["evader"])
    fits = math.ceil(t / DT - 1e-6)  # the fewest steps whose horizon holds the escape
    assert fits >= 2, t
    matches = [
        _match(corridor_half, start, "p/in", "e/in", "pursuer", max_cycles=fits),
        _match(corridor_half, start, "p/out", "e/out", "pursuer", max_cycles=fits - 1),
    ]
    rows = {r.policy: r for r in regret(matches, referees=refs)}

    def counts(policy):  # winnable, lost, unknown, certified for the opponent
        r = rows[policy]
        return r.winnable, r.lost, r.unknown, r.hopeless

    assert counts("p/in") == (0, 0, 0, 1) and counts("e/in") == (1, 1, 0, 0)
    assert counts("p/out") == (0, 0, 1, 0) and counts("e/out") == (0, 0, 1, 0)
    assert [rows[p].late for p in ("p/in", "e/in", "p/out", "e/out")] == [0, 0, 1, 1]


def test_the_regret_table_names_the_horizon_its_counts_are_within():
    rows = [Regret("pursuer", "p", 3, 0, 0, 2, 1, late=2)]
    head, row = regret_table(rows, horizon=30.0)
    assert head[3] == "certified winnable (within the 30 s horizon)"
    assert head[7] == "certified for the opponent (within the 30 s horizon)"
    assert (
        head[8] == "of the unknown, late (certified for the evader, escape beyond the 30 s horizon)"
    )
    assert row[6:] == ["2", "1", "2"]
    head, _ = regret_table(rows, horizon=(30.0, 60.0))
    assert head[3] == "certified winnable (within each match's horizon, 30-60 s)"
    assert regret_table(rows)[0][7] == "certified for the opponent (within the horizon)"


def test_regret_table_formats_rates_with_intervals():
    table = regret_table([Regret("pursuer", "p", 10, 4, 1, 6, 0), Regret("evader", "e", 5, 0,
                                                                         0, 5, 0)])  # fmt: skip
    assert table[0][0] == "role" and len(table) == 3
    assert table[1][5].startswith("0.25 [") and table[2][5] == "-"


def test_regret_rejects_malformed_matches(corridor_half):
    good = _match(corridor_half, {"pursuer": (-2.2, 0.0), "evader": (-0.9, 0.0)}, "p", "e",
                  "evader")  # fmt: skip
    with pytest.raises(InvalidConfigError, match=r"match 0: missing \['winner'\]"):
        regret([{k: v for k, v in good.items() if k != "winner"}])
    with pytest.raises(InvalidConfigError, match="winner = 'draw'"):
        regret([{**good, "winner": "draw"}])
    with pytest.raises(InvalidConfigError, match=r"dt = -0\.1"):
        regret([{**good, "dt": -0.1}])


def test_regret_refuses_a_bad_match_before_solving_any_game(corridor_half, monkeypatch):
    """A solve takes seconds to minutes: a malformed match anywhere in the list is named
    before the first one starts (it was found only after the games before it were solved)."""
    good = _match(corridor_half, {"pursuer": (-2.2, 0.0), "evader": (-0.9, 0.0)}, "p", "e",
                  "evader")  # fmt: skip

    def no_solve(*args, **kwargs):
        raise AssertionError("a game was solved before the matches were checked")

    monkeypatch.setattr("strategies.referee.regrets.solve", no_solve)
    with pytest.raises(InvalidConfigError, match=r"match 1: missing \['winner'\]"):
        regret([good, {k: v for k, v in good.items() if k != "winner"}], cache=False)


def test_regret_shows_a_bar_over_the_games_it_solves(corridor_half, capsys):
    start = {"pursuer": (-2.2, 0.0), "evader": (-0.9, 0.0)}
    matches = [_match(corridor_half, start, "p", "e", w) for w in ("evader", "pursuer")]
    rows = regret(matches, cells_per_lmin=4, cache=False, progress=True)
    assert {r.policy for r in rows} == {"p", "e"}
    err = capsys.readouterr().err
    assert "referee: solving the games played" in err and "0/1" in err  # two matches, one game
    regret(matches, referees={}, cells_per_lmin=4, cache=False, progress=False)
    assert capsys.readouterr().err == ""


def test_tournament_regret_from_runner_records(corridor_half):
    """Rows carrying the shared runner's record: its start and parameters are used."""
    world = corridor_half.spec.map
    overrides = {"l_min": L_MIN, "l_max": L_MAX, "v_pursuer": 1.0, "v_evader": 0.5,
                 "body_radius": RADIUS, "dt": DT}  # fmt: skip
    rows = []
    for i, start in enumerate(corridor_half.sample_starts(2, np.random.default_rng(1),
                                                          kind="evader")):  # fmt: skip
        r = run_episode(world, "pursuer/greedy", "evader/shooting", i, max_cycles=300,
                        overrides=overrides, start=start)  # fmt: skip
        rows.append({"status": "ok", "winner": r.winner, "pursuer": r.pursuer,
                     "evader": r.evader, "record": json.dumps(r.to_record())})  # fmt: skip
    rows.append({"status": "forfeit", "winner": "pursuer", "pursuer": "x", "evader": "y"})
    spec = {"maps": [{"label": world.name, "source": "<inline>", "digest": world.digest}]}
    table = tournament_regret(json.dumps(spec), rows, geometry={world.digest: world.to_dict()},
                              cells_per_lmin=12, cache=False)  # fmt: skip
    # rho = 0.5: a row says the pursuer bound certifies nothing informative, the last one
    # that the default evader lattice (coarse 3) certified next to nothing and the
    # referee's evader bound is the finer one (coarse 2)
    *table, note, evader_note = table
    assert note[0] == evader_note[0] == "-" and len(note) == len(table[0])
    assert note[1].startswith("pursuer regret: in 1 game(s) the pursuer bound certifies")
    assert "rho = 0.5" in note[1] and "'unknown'" in note[1]
    assert evader_note[1] == (
        "evader regret: in 1 game(s) the default evader lattice certified next to nothing "
        "and the referee's is finer (solve's evader_fallback), e.g. map 'dead_end' at "
        "rho = 0.5: evader_coarse = 2 (spacing 0.1667, step 0.7 s) for 3 (spacing 0.25, "
        "step 1 s)"
    )
    assert table[0][3] == "certified winnable (within the 30 s horizon)"  # 300 steps of 0.1 s
    by_policy = {row[1]: row for row in table[1:]}
    assert set(by_policy) == {"pursuer/greedy", "evader/shooting"}
    assert by_policy["evader/shooting"][3] == "2"  # both starts certified for the evader
    assert by_policy["pursuer/greedy"][7] == "2"  # ... so hopeless for the pursuer


def test_tournament_regret_redraws_the_runners_start_from_the_seed(monkeypatch):
    """Rows without a record: the start is drawn again exactly as the runner drew it."""
    rows, starts = [], []
    for seed in (0, 1):
        r = run_episode("open_room", "pursuer/greedy", "evader/straight", seed, max_cycles=50,
                        overrides={"v_evader": 0.25}, start="valid")  # fmt: skip
        starts.append(r.start)
        rows.append({"status": "ok", "winner": r.winner, "pursuer": r.pursuer,
                     "evader": r.evader, "map": "open_room", "variant": "slow",
                     "start": "valid", "seed": seed})  # fmt: skip
    spec = {"maps": [{"label": "open_room", "source": "open_room"}], "env": {"max_cycles": 50},
            "variants": [{"label": "slow", "overrides": {}, "rho": 0.25}]}  # fmt: skip
    from strategies.referee import regrets

    seen = []

    def spy(matches, **kw):
        matches = list(matches)
        seen.extend(matches)
        return regret(matches, **kw)

    monkeypatch.setattr(regrets, "regret", spy)
    table = tournament_regret(spec, rows, cells_per_lmin=6, cache=False)
    for m, s in zip(seen, starts, strict=True):
        assert np.allclose(m["start"]["pursuer"], s["pursuer"])
        assert np.allclose(m["start"]["evader"], s["evader"])
    assert all(m["v_evader"] == 0.25 and m["max_cycles"] == 50 for m in seen)
    # 6 cells per L_min is too coarse for the pursuer bound (tau = 2 s): a note says so
    assert len(table) == 4 and "certified no state" in table[3][1]


def test_tournament_regret_names_a_pursuer_lattice_the_referee_fell_back_to():
    """The open room at rho = 0.3, 16 cells per L_min: the default pursuer lattice
    certifies no state, solve falls back to one cell finer (98 %), and a note row says
    which lattice the pursuer rows were counted on."""
    rows = []
    for seed in (0, 1):
        r = run_episode("open_room", "pursuer/greedy", "evader/straight", seed, max_cycles=50,
                        overrides={"v_evader": 0.3}, start="valid")  # fmt: skip
        rows.append({"status": "ok", "winner": r.winner, "pursuer": r.pursuer,
                     "evader": r.evader, "record": json.dumps(r.to_record())})  # fmt: skip
    spec = {"maps": [{"label": "open_room", "source": "open_room"}]}
    table = tournament_regret(spec, rows, cells_per_lmin=16, cache=False)
    notes = [row[1] for row in table if row[0] == "-"]
    assert notes == [
        "pursuer regret: in 1 game(s) the default pursuer lattice certified no state and the "
        "referee's is one cell finer (solve's pursuer_fallback), e.g. map 'open_room' at "
        "rho = 0.3: pursuer_coarse = 3 (spacing 0.375, step 1.2 s) for 4 (spacing 0.5, "
        "step 1.5 s)"
    ]


def test_tournament_regret_refuses_a_changed_map(corridor_half):
    rows = [{"status": "ok", "winner": "pursuer", "pursuer": "a", "evader": "b",
             "map": "m", "variant": "", "start": "valid", "seed": 0}]  # fmt: skip
    spec = {"maps": [{"label": "m", "source": "open_room", "digest": "0" * 64}]}
    with pytest.raises(InvalidConfigError, match="has changed since the run"):
        tournament_regret(spec, rows, cache=False, strict=True)
    # a report still renders: the match is left out and the last row says why
    table = tournament_regret(spec, rows, cache=False)
    assert len(table) == 2 and "1 matches not counted" in table[1][1]
    assert "has changed since the run" in table[1][1] and len(table[1]) == len(table[0])
    spec = {"maps": [{"label": "m", "source": "/nonexistent/map.json"}]}
    with pytest.raises(InvalidConfigError, match="cannot find the map"):
        tournament_regret(spec, rows, cache=False, strict=True)


def test_the_vacuity_note_of_several_games_gives_one_as_an_example(monkeypatch):
    """A report's regret table said 'in 2 game(s) ...: map 'corridor': ...' and named only
    the first game, as if its reason were the whole list (the fallback's note says e.g.)."""
    import warnings

    from envs.errors import VacuousBoundWarning
    from strategies.referee import regrets

    def two_vacuous(matches, **kw):
        warnings.warn("map 'corridor': the first reason", VacuousBoundWarning, stacklevel=1)
        warnings.warn("map 'open_room': the second reason", VacuousBoundWarning, stacklevel=1)
        return []

    monkeypatch.setattr(regrets, "regret", two_vacuous)
    *_, note = tournament_regret(json.dumps({"maps": []}), [], cache=False)
    assert note[1].startswith("pursuer regret: in 2 game(s) the pursuer bound certifies")
    assert note[1].endswith("not as winnable: e.g. map 'corridor': the first reason")
