"""benchmarks/policy_sets.py label (benchmarks/set_labels.py): the referee's label of each
start of a set's rows, the losses it says no policy of the set's side could avoid, the
regrets, and the regret per set; on rows of ``unseen_worlds.py`` (both roles) whose starts
come from real solves, and the starts of ``evader_escapes.py`` rows."""

from __future__ import annotations

import importlib
import json
import math
import warnings
from pathlib import Path

import numpy as np
import pytest

from envs.errors import InvalidConfigError

BENCHMARKS = Path(__file__).resolve().parents[1] / "benchmarks"

# open_room~x0.5rot1off(3,-2) at (rho 0.2, L_max 2 L_min, L_min 2) is the open room's game
# at L in [2, 4], V_p 1, r 0.1 (judged untransformed); the rotated corner's at rho 0.5 the
# corner's. At 12 cells per L_min the referee certifies pursuer starts in the open room (at
# 8 none), at 8 a few evader starts in the corner: 2.5 s and 1.3 s a solve.
ROOM, ROOM_COMBO = "open_room~x0.5rot1off(3,-2)", [0.2, 2.0, 2.0]
CORNER, CORNER_COMBO = "corner~rot0.37", [0.5, 2.0, 2.0]


@pytest.fixture
def ps(monkeypatch):
    monkeypatch.syspath_prepend(str(BENCHMARKS))
    return importlib.import_module("policy_sets")


def _solve(name: str, rho: float, cpl: float):
    from envs.errors import VacuousBoundWarning
    from envs.maps import builtin_info
    from strategies.referee import GameSpec, solve

    spec = GameSpec(builtin_info(name).map, 2.0, 4.0, v_pursuer=1.0, v_evader=rho,
                    body_radius=0.1)  # fmt: skip
    with warnings.catch_warnings():  # rho 0.5: the pursuer bound certifies nothing (known)
        warnings.simplefilter("ignore", VacuousBoundWarning)
        return solve(spec, cpl, evader_coarse=2, evader_steps=1, dt=0.1)  # referee_labels'


def ps_similarity_back(rot: float, scale: float, offset):
    return importlib.import_module("referee_labels").similarity_back(rot, scale, offset)


def _forward(rot: float, scale: float, offset):
    c, s = math.cos(rot), math.sin(rot)
    r = np.array([[c, -s], [s, c]])
    return lambda q: (scale * r @ np.asarray(q, float) + offset).tolist()


def _pick(ref, kind: str, fwd, back, k: int = 0):
    """The ``k``-th lattice start of ``kind`` whose played positions (``fwd``: the
    similarity; ``back`` its inverse, as the tool maps them) the referee labels so."""
    starts = ref.lattice_starts()
    found = []
    for i in np.flatnonzero(starts.label == kind):
        p, e = starts.pursuer[i], starts.evader[i]
        if ref.classify(back(fwd(p)), back(fwd(e))) == kind:
            found.append((p, e))
            if len(found) > k:
                return found[k]
    raise AssertionError(f"no {kind} start")


def _row(world, combo, opponent, seed, won, start, horizon=600, t=3.0) -> dict:
    return {"role": "pursuer", "world": world, "combo": combo, "opponent": opponent,
            "seed": seed, "horizon": horizon, "winner": "pursuer" if won else "evader",
            "cause": None if won else "too_close", "t": None if won else t,
            "steps": horizon if won else round(10 * t), "start": start}  # fmt: skip


@pytest.fixture
def tiny(ps, tmp_path, monkeypatch):
    """A pursuer set of 7 episodes from 4 starts: in the open room, a start certified for
    the pursuer lost once and won once, another such start won, an uncertified start lost;
    in the corner, a start certified for the evader (at 8 cells per L_min) lost within
    and beyond its certified escape time. (sets, their directory, the escape bound, the
    shorter horizon in steps)."""
    monkeypatch.setenv("SURVEIL_CACHE_DIR", str(tmp_path / "cache"))
    room, corner = _solve("open_room", 0.2, 12), _solve("corner", 0.5, 8)
    to_room = _forward(1.0, 0.5, (3.0, -2.0))
    to_corner = _forward(0.37, 1.0, (0.0, 0.0))
    from_room = ps_similarity_back(1.0, 0.5, (3.0, -2.0))
    from_corner = ps_similarity_back(0.37, 1.0, (0.0, 0.0))

    def start(fwd, p, e):
        return {"pursuer": fwd(p), "evader": fwd(e)}

    held, held2 = _pick(room, "pursuer", to_room, from_room), _pick(room, "pursuer", to_room,
                                                                    from_room, 1)  # fmt: skip
    gap = _pick(room, "unknown", to_room, from_room)
    lost = _pick(corner, "evader", to_corner, from_corner)
    bound = corner.escape_time(*lost)
    assert bound is not None and 0 < bound < 60
    late = math.ceil(bound / 0.1) - 1  # a horizon one step short of the certified escape
    rows = [
        _row(ROOM, ROOM_COMBO, "herder", 101, False, start(to_room, *held)),
        _row(ROOM, ROOM_COMBO, "darter", 101, True, start(to_room, *held)),
        _row(ROOM, ROOM_COMBO, "herder", 104, True, start(to_room, *held2)),
        _row(ROOM, ROOM_COMBO, "herder", 102, False, start(to_room, *gap)),
        _row(CORNER, CORNER_COMBO, "herder", 103, False, start(to_corner, *lost)),
        _row(CORNER, CORNER_COMBO, "darter", 103, False, start(to_corner, *lost), late, 0.5),
        _row(CORNER, CORNER_COMBO, "herder", 105, True, start(to_corner, *lost)),
    ]
    d = tmp_path / "sets"
    d.mkdir()
    (d / "tiny.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rows))
    s = ps.PolicySet("tiny", "unseen_worlds.py", ("--role", "pursuer"), "pursuer", 3, 7, "-")
    return {"tiny": s}, d, bound, late


def _table_row(text: str, name: str) -> list[str]:
    return next(line for line in text.splitlines() if line.startswith(name + " ")).split()


def _labels(path: Path) -> list[dict]:
    return [json.loads(line) for line in path.read_text().splitlines()]


def test_label_counts_unavoidable_losses_regrets_and_the_regret(ps, tiny, tmp_path, capsys):
    """Each start is labelled at 8 cells per L_min, and at 12 only while undecided: the
    room's starts are certified for the pursuer at 12 (not at 8), the corner's for the
    evader at 8. The loss from a pursuer start is the regret (1 of the 3 episodes from such
    starts), the corner's loss within the escape bound unavoidable, the one whose horizon
    ends before it ``late``, the loss from the uncertified start undecided. A second run
    labels nothing."""
    sets, d, bound, late = tiny
    out = tmp_path / "labels"
    assert ps.label(str(d), [], [8.0, 12.0], str(out), sets=sets) == 0
    text = capsys.readouterr().out
    # episodes, losses, unavoidable, late, regrets, undecided, REGRET
    assert _table_row(text, "tiny") == ["tiny", "7", "4", "1", "1", "1", "1", "1/3", "=",
                                        "0.333"]  # fmt: skip
    assert "cpl 8: 4 starts to label in 2 games" in text
    assert "cpl 12: 3 starts to label in 1 games" in text  # the corner's start is certified
    assert "  tiny undecided: 1 unknown" in text
    assert (f"  regret: tiny {ROOM} {ROOM_COMBO} herder seed=101: too_close at 3.0 s; referee: "
            "pursuer (cpl 12)") in text  # fmt: skip
    assert (f"  unavoidable: tiny {CORNER} {CORNER_COMBO} herder seed=103: too_close at 3.0 s; "
            f"referee: evader (cpl 8), escape within {bound:.1f} s of 60") in text  # fmt: skip
    assert (f"  late: tiny {CORNER} {CORNER_COMBO} darter seed=103: too_close at 0.5 s; referee: "
            f"evader (cpl 8), escape within {bound:.1f} s of {late / 10:g}") in text  # fmt: skip
    assert f"  unknown: tiny {ROOM} {ROOM_COMBO} herder seed=102" in text
    assert "regrets: 1" in text
    labels = _labels(out / "tiny.labels.jsonl")
    assert sorted((x["cpl"], x["label"]) for x in labels) == [
        (8.0, "evader"), (8.0, "unknown"), (8.0, "unknown"), (8.0, "unknown"),
        (12.0, "pursuer"), (12.0, "pursuer"), (12.0, "unknown"),
    ]  # fmt: skip
    assert ps.label(str(d), ["tiny"], [8.0, 12.0], str(out), sets=sets) == 0
    again = capsys.readouterr().out
    assert "cpl 8: 0 starts to label" in again and "cpl 12: 0 starts to label" in again
    assert _table_row(again, "tiny") == _table_row(text, "tiny")
    assert len(_labels(out / "tiny.labels.jsonl")) == 7


def test_losses_only_labels_the_lost_starts_and_gives_no_regret(ps, tiny, tmp_path, capsys):
    """``--losses-only``: the start only won (seed 104) is not labelled, so the winnable
    episodes are not counted: no regret, said so; the regret is still listed."""
    sets, d, *_ = tiny
    out = tmp_path / "labels"
    assert ps.label(str(d), ["tiny"], [12.0], str(out), losses_only=True, sets=sets) == 0
    text = capsys.readouterr().out
    assert "cpl 12: 3 lost starts to label in 2 games" in text
    row = _table_row(text, "tiny")
    assert row[:7] == ["tiny", "7", "4", "1", "1", "1", "1"]
    assert "n/a (--losses-only: the winnable starts are not labelled)" in text
    assert len(_labels(out / "tiny.labels.jsonl")) == 3


def _evader_row(world, combo, opponent, seed, won, start, k=8.0, t=3.0) -> dict:
    return {"role": "evader", "world": world, "combo": combo, "opponent": opponent,
            "seed": seed, "horizon": k, "winner": "evader" if won else "pursuer",
            "cause": "occluded" if won else None, "t": t if won else None,
            "steps": 30 if won else 10**4, "start": start}  # fmt: skip


def test_an_evader_set_s_misses_are_unavoidable_from_pursuer_starts_regrets_from_evader_ones(
    ps, tiny, tmp_path, capsys
):
    """The same starts played by the shooting evader (``unseen_worlds.py --role evader``
    rows; the evader role's worlds are the same games: open_room~x0.5rot1off(3,-2) at
    L_min 2, rho 0.2 is the open room at [2, 4], V_p 1): a miss from the start certified
    for the pursuer is unavoidable; a miss from the corner's start certified for the
    evader is the evader's regret when its escape bound is within the horizon (k = 8
    D / V_e) and ``late`` when the horizon (k steps short of it) ends first; a miss from
    the uncertified start is undecided. The regret counts the episodes from the corner
    start within the horizon (2: the miss and a win), not the late one."""
    import unseen_worlds as uw

    sets, d, bound, _ = tiny
    pursuer_rows = [json.loads(line) for line in (d / "tiny.jsonl").read_text().splitlines()]
    held, gap, lost = (pursuer_rows[i]["start"] for i in (0, 3, 4))
    m, ov = uw.evader_world(CORNER, CORNER_COMBO[2], *CORNER_COMBO[:2])
    unit = uw.diameter(m) / ov["v_evader"]
    short = (math.ceil(bound / 0.1) - 1) * 0.1 / unit * (1 - 1e-9)  # one step short of it
    rows = [
        _evader_row(ROOM, ROOM_COMBO, "pursuer/greedy", 201, False, held),
        _evader_row(ROOM, ROOM_COMBO, "still", 201, True, held),
        _evader_row(ROOM, ROOM_COMBO, "pursuer/greedy", 202, False, gap),
        _evader_row(CORNER, CORNER_COMBO, "pursuer/decomposition", 203, False, lost),
        _evader_row(CORNER, CORNER_COMBO, "pursuer/decomposition", 203, False, lost, short),
        _evader_row(CORNER, CORNER_COMBO, "still", 203, True, lost),
    ]
    (d / "tinye.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rows))
    ev = ps.PolicySet("tinye", "unseen_worlds.py", ("--role", "evader"), "evader", 2, 6, "-")
    out = tmp_path / "labels"
    assert ps.label(str(d), ["tinye"], [8.0, 12.0], str(out), sets={**sets, "tinye": ev}) == 0
    text = capsys.readouterr().out
    assert "an evader set: a loss from a start certified for the pursuer is unavoidable" in text
    # episodes, losses, unavoidable, late, regrets, undecided, REGRET
    assert _table_row(text, "tinye") == ["tinye", "6", "4", "1", "1", "1", "1", "1/2", "=",
                                         "0.500"]  # fmt: skip
    held = "held to the horizon; referee:"
    assert (f"  unavoidable: tinye {ROOM} {ROOM_COMBO} pursuer/greedy seed=201: {held} pursuer "
            "(cpl 12)") in text  # fmt: skip
    horizon = math.ceil(8 * unit / 0.1) * 0.1
    assert (f"  regret: tinye {CORNER} {CORNER_COMBO} pursuer/decomposition seed=203: {held} "
            f"evader (cpl 8), escape within {bound:.1f} s of {horizon:g}") in text  # fmt: skip
    assert (f"  late: tinye {CORNER} {CORNER_COMBO} pursuer/decomposition seed=203: {held} "
            f"evader (cpl 8), escape within {bound:.1f} s of "
            f"{(math.ceil(bound / 0.1) - 1) * 0.1:g}") in text  # fmt: skip
    assert f"  unknown: tinye {ROOM} {ROOM_COMBO} pursuer/greedy seed=202" in text
    assert "regrets: 1" in text
    # the default labels every set in the directory, both roles (the labels are on file)
    assert ps.label(str(d), [], [8.0, 12.0], str(out), sets={**sets, "tinye": ev}) == 0
    text = capsys.readouterr().out
    assert _table_row(text, "tiny")[:2] == ["tiny", "7"] and _table_row(text, "tinye")[1] == "6"


def test_an_evader_escapes_row_is_judged_untransformed_from_the_start_its_seed_drew(
    ps, monkeypatch, tmp_path
):
    """evader_escapes.py rows record the start played (``start_drawn``); an older row
    without it is given the start its episode seed draws, the same one. A variant's
    start is judged in the untransformed world: the rotated T-junction's row and the
    one as is share a game, and its start maps back onto the one as is played."""
    import evader_escapes as ee
    import set_labels

    monkeypatch.setenv("SURVEIL_CACHE_DIR", str(tmp_path / "cache"))
    rows = [ee._play(("tee", v, "still", 3, 0.05, "safe", [])) for v in ("as is", "rot 0.37")]
    s = ps.PolicySet("esc", "evader_escapes.py", (), "evader", 0, 2, "-")
    starts = set_labels.starts_of(s, {str(i): ps._episode(s.script, r, str(i))
                                      for i, r in enumerate(rows)})  # fmt: skip
    older = {k: v for k, v in rows[1].items() if k != "start_drawn"}
    redrawn = set_labels.starts_of(s, {"1": ps._episode(s.script, older, "1")})["1"]
    assert redrawn.start == rows[1]["start_drawn"] == starts["1"].start
    assert starts["0"].game == starts["1"].game and starts["0"].role == "evader"
    m, ov, back = starts["1"].build()
    assert (m.digest, ov) == (ee.world("tee")[0].digest, ee.world("tee")[1])
    p, e = (back(rows[1]["start_drawn"][who]) for who in ("pursuer", "evader"))
    x0, y0, x1, y1 = m.bounds  # the rotated start, turned back: in the tee as is, as far apart
    assert all(x0 < q[0] < x1 and y0 < q[1] < y1 for q in (p, e))
    assert np.linalg.norm(p - e) == pytest.approx(math.dist(*rows[1]["start_drawn"].values()))
    played = ee.world("tee", "rot 0.37")
    assert starts["1"].horizon == pytest.approx(
        math.ceil(0.05 * ee.diameter(played[0]) / played[1]["v_evader"] / 0.1) * 0.1
    )


def test_label_refuses_what_it_cannot_judge(ps, tiny, tmp_path):
    """A set of a script whose rows give no start, a set the directory lacks, resolutions
    that do not increase: refused before any solve, naming what was expected."""
    sets, d, *_ = tiny
    other = ps.PolicySet("other", "nowhere.py", (), "evader", 0, 1, "-")
    (d / "other.jsonl").write_text("")
    both = {**sets, "other": other}
    with pytest.raises(InvalidConfigError, match=r"is played by nowhere\.py; expected a set of"):
        ps.label(str(d), ["other"], [12.0], None, sets=both)
    absent = ps.PolicySet("absent", "unseen_worlds.py", ("--role", "pursuer"), "pursuer", 0, 1,
                          "-")  # fmt: skip
    with pytest.raises(InvalidConfigError, match="holds no results file of set absent"):
        ps.label(str(d), ["absent"], [12.0], None, sets={**both, "absent": absent})
    with pytest.raises(InvalidConfigError, match="expected increasing resolutions"):
        ps.label(str(d), ["tiny"], [12.0, 8.0], None, sets=sets)
    with pytest.raises(InvalidConfigError, match="no such directory"):
        ps.label(str(tmp_path / "nope"), [], [12.0], None, sets=sets)
    assert not (d / "tiny.labels.jsonl").exists()


def test_a_bad_cpl_is_a_usage_error(ps, tmp_path, capsys):
    with pytest.raises(SystemExit) as exc:
        ps.main(["label", str(tmp_path), "--cpl", "0"])
    assert exc.value.code == 2
    assert "--cpl" in capsys.readouterr().err


def test_an_unknown_on_a_game_a_bound_certified_nothing_of_says_why(ps, tiny, tmp_path, capsys):
    """An ``unknown`` start on a game one bound certified no state of says nothing about
    that start (issue 13's blind spot of the pursuer bound): its label line keeps the
    reason (``why``) and the report prints it beside the loss and counts it. At 8 cells
    per L_min neither bound certifies a state of the open room at rho 0.2, and the pursuer
    bound none of the corner at rho 0.5 (its evader bound certifies some); at 12 both
    bounds certify states of the room, so an unknown start there is a gap at that start."""
    sets, d, *_ = tiny
    corner = _solve("corner", 0.5, 8)
    to_corner = _forward(0.37, 1.0, (0.0, 0.0))
    gap = _pick(corner, "unknown", to_corner, ps_similarity_back(0.37, 1.0, (0.0, 0.0)))
    start = {"pursuer": to_corner(gap[0]), "evader": to_corner(gap[1])}
    with (d / "tiny.jsonl").open("a") as f:
        f.write(json.dumps(_row(CORNER, CORNER_COMBO, "herder", 106, False, start)) + "\n")
    out = tmp_path / "labels"
    assert ps.label(str(d), ["tiny"], [8.0], str(out), sets=sets) == 0
    text = capsys.readouterr().out
    neither = "neither bound certified a state of this game"
    no_pursuer = "the pursuer bound certified no state of this game"
    assert (f"  unknown: tiny {ROOM} {ROOM_COMBO} herder seed=102: too_close at 3.0 s; referee: "
            f"unknown (cpl 8: {neither})\n") in text  # fmt: skip
    assert (f"  unknown: tiny {CORNER} {CORNER_COMBO} herder seed=106: too_close at 3.0 s; "
            f"referee: unknown (cpl 8: {no_pursuer})\n") in text  # fmt: skip
    assert ("  tiny undecided: 3 unknown (3 of them on games a bound certified no state of: "
            "unknown whatever the start)") in text  # fmt: skip
    labels = _labels(out / "tiny.labels.jsonl")
    # the room's three starts (held, held2, gap) and the corner's new one
    assert sorted(x.get("why", "") for x in labels if x["label"] == "unknown") == [
        neither, neither, neither, no_pursuer]  # fmt: skip
    assert all("why" not in x for x in labels if x["label"] != "unknown")
    assert ps.label(str(d), ["tiny"], [8.0, 12.0], str(out), sets=sets) == 0
    text = capsys.readouterr().out
    assert "herder seed=102: too_close at 3.0 s; referee: unknown (cpl 12)\n" in text
    assert "  tiny undecided: 2 unknown (1 of them on games" in text
