"""benchmarks/unseen_worlds.py: a tiny subset of each role, its JSONL rows and the resume."""

from __future__ import annotations

import importlib
import json
import shlex
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


def test_a_rerun_at_another_horizon_plays_its_episodes_again(unseen, tmp_path, capsys) -> None:
    """An episode's key names the horizon: rows that ended at 40 steps are not reused as
    the result of a 60-step run (a row of an older surveil, without one, counts as the
    default horizon's)."""
    out = tmp_path / "h.jsonl"
    argv = ["--role", "pursuer", "--worlds", "corridor~rot2.3", "--combos", "0",
            "--opponents", "herder", "--results", str(out)]  # fmt: skip
    assert unseen.main([*argv, "--max-cycles", "40"]) == 0
    assert unseen.main([*argv, "--max-cycles", "60"]) == 0
    assert "1 episodes selected, 1 to play" in capsys.readouterr().out.split("load average")[-1]
    rows = _rows(out)
    assert [(r["horizon"], r["steps"]) for r in rows] == [(40, 40), (60, 60)]
    assert unseen.main([*argv, "--max-cycles", "40"]) == 0  # both stay reusable
    assert "1 episodes selected, 0 to play" in capsys.readouterr().out
    old = {k: v for k, v in rows[0].items() if k != "horizon"}
    assert unseen.row_key(old) == unseen.row_key({**rows[0], "horizon": unseen.MAX_CYCLES})


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


def test_a_long_world_label_keeps_its_columns_apart(unseen, capsys) -> None:
    """A held-out world's label runs to 30 characters: its table row keeps a space before
    the combo (it was printed glued: 'two_rooms~x0.8rot1.3off(12,-3)[0.5, 2.0, 1.0]'), and
    the rows line up with the header."""
    world, opponent = "two_rooms~x0.8rot1.3off(12,-3)", "evader/toward_away:alternate-long"
    row = {"role": "pursuer", "world": world, "combo": [0.5, 2.0, 1.0], "opponent": opponent,
           "seed": 101, "winner": "pursuer", "cause": None, "t": None, "steps": 600}  # fmt: skip
    unseen.report([row])
    lines = capsys.readouterr().out.splitlines()
    head = next(line for line in lines if line.startswith("world"))
    line = next(line for line in lines if line.startswith(world))
    assert line.split()[:2] == [world, "[0.5,"]
    assert head.index("rho, L_max") == line.index("[0.5,")
    opp = next(line for line in lines if line.startswith(opponent))
    assert opp.split() == [opponent, "1/1"]


def test_an_evader_loss_says_whether_the_escape_is_open_to_the_body(unseen, capsys) -> None:
    """two_rooms at L_min 1: Prop. 2 holds only for a point evader (every escape crosses a
    piece nearer a wall than the 0.1 body); at L_min 2 the body has its escape."""
    base = {"role": "evader", "world": "two_rooms~rot2.2", "opponent": "pursuer/decomposition",
            "unit": 70.0, "steps": 100}  # fmt: skip
    lost = {"combo": [0.5, 1.5, 1.0], "seed": 619, "winner": "pursuer", "cause": None, "t": None}
    won = {"combo": [0.5, 1.5, 2.0], "seed": 7, "winner": "evader", "cause": "occluded", "t": 20}
    rows = [base | lost, base | won]
    unseen.report(rows)
    text = capsys.readouterr().out
    assert "escape is open to the evader's body: 1/1 escaped" in text
    assert "open only to a point evader (every escape crosses nearer a wall" in text
    assert ": 0/1 escaped" in text
    assert "(the horizon); Prop. 2's escape is open only to a point evader" in text
    assert unseen.body_open("two_rooms~rot2.2", 2.0)
    assert not unseen.body_open("two_rooms~x0.5", 1.0)


@pytest.mark.parametrize("label", ["nope", "zigzag:x:1"])
def test_an_unknown_opponent_is_a_usage_error_naming_it(unseen, tmp_path, capsys, label) -> None:
    results = tmp_path / "r.jsonl"
    with pytest.raises(SystemExit) as exc:
        unseen.main(["--role", "pursuer", "--worlds", "plus_w6", "--opponents", label,
                     "--results", str(results)])  # fmt: skip
    assert exc.value.code == 2
    assert f"--opponents: {label!r} is no opponent" in capsys.readouterr().err
    assert not results.exists()  # nothing played


def test_the_label_grammar_rebuilds_the_default_worlds(unseen) -> None:
    """Generic labels give the same geometry as the default set's hand-written worlds."""
    assert unseen.room_map("L_12x5") == unseen.built_map("L_12x5")
    assert unseen.room_map("U_14x10x5x4") == unseen.built_map("U_14x10")
    assert unseen.room_map("U_18x9x6x5") == unseen.built_map("U_wide")
    assert unseen.room_map("pillar:10:10:4:4:6:6") == unseen.built_map("pillar_centre")
    assert unseen.room_map("tee_w5") == unseen.built_map("tee_w5")  # arms 6: the role's
    assert unseen.room_map("plus_w1.2", "evader") == unseen.evader_world("plus_w1.2", 1, 0.5, 2)[0]
    assert unseen.room_map("plus_w5a7") != unseen.room_map("plus_w5")
    for combo in [(0.5, 2.0, 2.0), (0.3, 2.0, 1.0)]:  # "x0.30" is no default label
        assert unseen.pursuer_world("pillars~x0.30", combo) == unseen.pursuer_world(
            "pillars~x0.3", combo
        )
    assert unseen.transform_of("corner~x1.7rot-1.9") == unseen.PAPER["corner~x1.7rot-1.9"]
    assert unseen.transform_of("two_rooms~x0.7rot0.9off(5,-7)") == (
        "two_rooms", 0.9, 0.7, (5.0, -7.0))  # fmt: skip
    assert unseen.transform_of("maze~rot-1") == ("maze", -1.0, 1.0, (0.0, 0.0))
    # a fresh transform scales L_min and the speeds as the default set's do
    m, ov = unseen.pursuer_world("corner~x0.8rot1.2", (0.5, 2.0, 1.0))
    assert ov == pytest.approx({"l_min": 0.8, "l_max": 1.6, "v_pursuer": 0.8,
                                "v_evader": 0.4, "body_radius": 0.08})  # fmt: skip
    assert m.bounds[2] - m.bounds[0] < 14.0 * 0.8 * 1.42


@pytest.mark.parametrize(
    "role, label",
    [("pursuer", "maze~spin3"), ("pursuer", "nope~x2"), ("pursuer", "L_10"),
     ("pursuer", "rand:convex:x:3"), ("pursuer", "maze~x0"), ("evader", "floor_plan:x"),
     ("evader", "office~")],
)  # fmt: skip
def test_an_unknown_world_label_is_a_usage_error_naming_it(unseen, tmp_path, capsys, role,
                                                           label) -> None:  # fmt: skip
    results = tmp_path / "r.jsonl"
    with pytest.raises(SystemExit) as exc:
        unseen.main(["--role", role, "--worlds", label, "--results", str(results)])
    assert exc.value.code == 2
    assert f"unknown {role}-role world {label!r}" in capsys.readouterr().err
    assert not results.exists()


@pytest.mark.parametrize(
    "role, label, why",
    [("pursuer", "L_5x5", "0 < W < A"), ("pursuer", "U_10x10x3x12", "0 < B < H"),
     ("pursuer", "U_10x10x5x3", "0 < 2 A < W"), ("pursuer", "tee_w6a0", "arm = 0.0"),
     ("evader", "plus_w1.2a0", "arm = 0.0"), ("pursuer", "maze~x0", "finite scale > 0")],
)  # fmt: skip
def test_a_degenerate_world_label_is_a_usage_error_saying_why(unseen, tmp_path, capsys, role,
                                                             label, why) -> None:  # fmt: skip
    """A label that parses but builds no such room was played as another world: L_5x5 as a
    plain square, U_10x10x3x12 as a room with a bump, tee_w6a0 as a 6 x 6 square; a scale
    of 0 said only 'unknown world'."""
    results = tmp_path / "r.jsonl"
    with pytest.raises(SystemExit) as exc:
        unseen.main(["--role", role, "--worlds", label, "--results", str(results)])
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert f"unknown {role}-role world {label!r}" in err and why in err
    assert not results.exists()


def test_a_fresh_evader_world_draws_its_own_episodes(unseen, tmp_path, capsys) -> None:
    """Each other world's draws depend only on its label and L_min; it plays and its replay
    line names the L_min."""
    both = unseen.other_evader_jobs(["tee_w1.4", "random:star:2017"], [1.0, 2.0], 2)
    alone = unseen.other_evader_jobs(["random:star:2017"], [2.0], 2)
    assert alone == [j for j in both if j[1] == "random:star:2017" and j[2][2] == 2.0]
    assert len(alone) == 24  # 12 pursuers x 2 draws (the referee only on junctions)
    assert len([j for j in both if j[1] == "tee_w1.4"]) == 2 * 25
    assert len({j[4] for j in both}) > 40  # drawn seeds, not one per world
    out = tmp_path / "e.jsonl"
    argv = ["--role", "evader", "--worlds", "tee_w1.4", "--opponents", "still", "--l-mins",
            "2", "--draws", "1", "--results", str(out)]  # fmt: skip
    assert unseen.main(argv) == 0
    (row,) = _rows(out)
    assert row["world"] == "tee_w1.4" and row["combo"][2] == 2.0 and row["winner"] == "evader"
    assert "shooting evader escaped 1/1" in capsys.readouterr().out
    assert unseen.replay_command({**row, "winner": "pursuer"}).endswith(
        f"--seeds {row['seed']} --l-mins 2 --draws 1 --results replay.jsonl --play-again"
    )
    label = "office~x0.6rot1.7off(1,2)"
    assert f"--worlds '{label}' " in unseen.replay_command(
        {"role": "pursuer", "world": label, "combo": [0.5, 2.0, 2.0], "opponent": "herder",
         "seed": 101})  # fmt: skip


def _replays_its_episode(unseen, words, row, tmp_path, capsys, monkeypatch) -> None:
    """Run a row's replay command (``words``) in ``tmp_path``: it plays one episode, the
    row's own (the same draw, start, time and steps)."""
    monkeypatch.chdir(tmp_path)
    capsys.readouterr()
    assert unseen.main(words[2:]) == 0
    assert "1 episodes selected, 1 to play" in capsys.readouterr().out
    (again,) = _rows(tmp_path / "replay.jsonl")
    assert {k: again[k] for k in ("combo", "seed", "start", "t", "steps")} == {
        k: row[k] for k in ("combo", "seed", "start", "t", "steps")}  # fmt: skip


def test_rhos_and_a_seed_base_draw_a_fresh_set_s_episodes_and_replay_them(
    unseen, tmp_path, capsys, monkeypatch
) -> None:
    """``--rhos`` and ``--seed-base`` (fresh-e: rho 0.2 is in no default draw, seeds from
    6000): the other worlds' draws take their rho from them and their seeds from the base,
    the default arguments draw as before, each row records how it was drawn and its replay
    command plays the same episode; the default set's draws are fixed (refused)."""
    world = ["tee_w1.5a3.6"]
    rhos = [0.2, 0.3, 0.5, 0.8]
    fresh = unseen.other_evader_jobs(world, [1.0, 2.0], 2, rhos, 6000)
    assert {j[2][0] for j in fresh} == set(rhos) and {j[2][1] for j in fresh} == {2.0, 1.5}
    assert all(6000 <= j[4] < 7000 for j in fresh)
    default = unseen.other_evader_jobs(world, [1.0, 2.0], 2)
    assert default == unseen.other_evader_jobs(world, [1.0, 2.0], 2, unseen.EVADER_RHOS, 100)
    assert {j[2][0] for j in default} <= set(unseen.EVADER_RHOS)
    assert all(100 <= j[4] < 1100 for j in default)
    out = tmp_path / "f.jsonl"
    argv = ["--role", "evader", "--worlds", *world, "--opponents", "still", "--l-mins", "2",
            "--rhos", "0.2", "--seed-base", "6000", "--results", str(out)]  # fmt: skip
    assert unseen.main(argv) == 0
    row = _rows(out)[-1]  # (2 draws)
    assert (row["combo"][0], row["rhos"], row["seed_base"]) == (0.2, [0.2], 6000)
    assert 6000 <= row["seed"] < 7000 and row["winner"] == "evader"
    words = shlex.split(unseen.replay_command({**row, "winner": "pursuer"}))
    index = [(0.2, 2.0), (0.2, 1.5)].index(tuple(row["combo"][:2]))  # into --rhos's pairs
    assert words[words.index("--combos") + 1] == str(index)
    assert " --rhos 0.2 --seed-base 6000 " in shlex.join(words)
    _replays_its_episode(unseen, words, row, tmp_path, capsys, monkeypatch)
    for role, worlds, says in [
        ("evader", ["--worlds", "tee_w1.0"], "--rhos: draws the episodes of worlds outside"),
        ("evader", [], "--worlds selects its floor_plan:3"),
        ("pursuer", ["--worlds", "corner~rot0.37"], "--rhos: the evader role only"),
    ]:
        with pytest.raises(SystemExit) as exc:
            unseen.main(["--role", role, *worlds, "--rhos", "0.2", "--results", str(out)])
        assert exc.value.code == 2 and says in capsys.readouterr().err


def test_a_row_of_another_number_of_draws_replays_its_episode(
    unseen, tmp_path, capsys, monkeypatch
) -> None:
    """``--draws`` changes every evader episode's (rho, ratio) and seed (one generator
    draws them in turn): a row of a ``--draws 1`` run records it and its replay command
    says it, or the replay drew two episodes a pursuer and found none of that seed."""
    out = tmp_path / "d.jsonl"
    argv = ["--role", "evader", "--worlds", "tee_w1.5a3.6", "--opponents", "still",
            "--l-mins", "2", "--draws", "1", "--results", str(out)]  # fmt: skip
    assert unseen.main(argv) == 0
    (row,) = _rows(out)
    assert row["draws"] == 1
    words = shlex.split(unseen.replay_command({**row, "winner": "pursuer"}))
    assert words[words.index("--draws") + 1] == "1"
    _replays_its_episode(unseen, words, row, tmp_path, capsys, monkeypatch)
    default = [w for w in argv if w not in ("--draws", "1")]
    default[-1] = str(tmp_path / "two.jsonl")
    assert unseen.main(default) == 0
    rows = _rows(tmp_path / "two.jsonl")  # the default draws: rows as before
    assert len(rows) == 2 and all("draws" not in r for r in rows)


def test_a_replay_command_plays_its_episode_each_time(unseen, tmp_path, capsys, monkeypatch):
    """A loss's replay command, run as printed, plays the episode at its horizon every
    time: a second run (after a change of the code) read the first one's row from
    replay.jsonl and played nothing, and a row of a --max-cycles 40 run replayed at 600."""
    argv = ["--role", "pursuer", "--worlds", "corridor~rot2.3", "--combos", "0",
            "--opponents", "herder", "--max-cycles", "40", "--results",
            str(tmp_path / "run.jsonl")]  # fmt: skip
    assert unseen.main(argv) == 0
    (row,) = _rows(tmp_path / "run.jsonl")
    words = shlex.split(unseen.replay_command(row))
    assert words[:2] == ["python", "benchmarks/unseen_worlds.py"]
    monkeypatch.chdir(tmp_path)
    capsys.readouterr()
    for _ in range(2):
        assert unseen.main(words[2:]) == 0
        assert "1 episodes selected, 1 to play" in capsys.readouterr().out
    replays = _rows(tmp_path / "replay.jsonl")
    assert [(r["horizon"], r["steps"], r["winner"]) for r in replays] == [(40, 40, "pursuer")] * 2


@pytest.mark.parametrize(
    ("role", "name"),
    [("pursuer", "heldout_worlds_pursuer"), ("evader", "heldout_worlds_evader"),
     ("evader", "fresh_worlds_evader")],
)  # fmt: skip
def test_the_held_out_sets_parse_and_are_not_the_defaults(
    unseen, tmp_path, capsys, role, name
) -> None:
    """``--worlds @file`` reads the shipped held-out labels; every one builds (the opponent
    check comes after the worlds'), and none is in the role's default set (fresh-e's
    none in the older held-out set either)."""
    path = BENCHMARKS / f"{name}.txt"
    labels = path.read_text().split()
    assert len(labels) > 30 and len(set(labels)) == len(labels)
    defaults = unseen.PURSUER_WORLDS if role == "pursuer" else unseen.EVADER_NAMES
    assert not set(labels) & set(defaults)
    if name.startswith("fresh"):
        assert not set(labels) & set((BENCHMARKS / "heldout_worlds_evader.txt").read_text().split())
    with pytest.raises(SystemExit) as exc:
        unseen.main(["--role", role, "--worlds", f"@{path}", "--opponents", "nope",
                     "--results", str(tmp_path / "r.jsonl")])  # fmt: skip
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert "--opponents: 'nope' is no opponent" in err and f"unknown {role}-role world" not in err


@pytest.mark.slow
def test_the_referee_labels_the_starts_it_certifies(unseen, tmp_path, monkeypatch, capsys) -> None:
    """``--referee CPL``: a start the referee certifies for the evader (found by solving the
    untransformed corner world by hand, then moved by the label's similarity) is labelled
    ``evader`` beside its loss and in the summary, an uncertified one ``unknown``; the
    episodes come from the results file (nothing is played)."""
    import numpy as np

    from envs.maps import builtin_info
    from strategies.referee import GameSpec, solve

    monkeypatch.setenv("SURVEIL_CACHE_DIR", str(tmp_path / "cache"))
    corner = builtin_info("corner").map
    # corner~x0.5rot1off(3,-2) at combo 0 is the corner game at L in [2, 4], rho 0.5, r 0.1
    spec = GameSpec(corner, 2.0, 4.0, v_pursuer=1.0, v_evader=0.5, body_radius=0.1)
    ref = solve(spec, 12, evader_coarse=2, evader_steps=1, dt=0.1)
    starts = ref.lattice_starts()
    c, s = np.cos(1.0), np.sin(1.0)
    fwd = lambda q: (0.5 * np.array([[c, -s], [s, c]]) @ q + (3.0, -2.0)).tolist()
    label = "corner~x0.5rot1off(3,-2)"
    rows, want = [], {}
    for seed, kind in [(101, "evader"), (102, "unknown")]:
        i = int(np.flatnonzero(starts.label == kind)[0])
        p, e = starts.pursuer[i], starts.evader[i]
        assert ref.classify(p, e) == kind
        want[seed] = kind
        # the darter is held from the unknown start: 3 losses from 2 starts
        darter = "evader" if kind == "evader" else "pursuer"
        for opponent, winner in [("herder", "evader"), ("darter", darter)]:
            rows.append({"role": "pursuer", "world": label, "combo": [0.5, 2.0, 2.0],
                         "opponent": opponent, "seed": seed, "winner": winner,
                         "cause": "too_close" if winner == "evader" else None, "t": 3.0,
                         "steps": 30, "start": {"pursuer": fwd(p), "evader": fwd(e)}})  # fmt: skip
    out = tmp_path / "p.jsonl"
    out.write_text("".join(json.dumps(r) + "\n" for r in rows))
    argv = ["--role", "pursuer", "--worlds", label, "--combos", "0", "--opponents", "herder",
            "darter", "--seeds", "101", "102", "--results", str(out),
            "--referee", "12"]  # fmt: skip
    assert unseen.main(argv) == 0
    text = capsys.readouterr().out
    assert "4 episodes selected, 0 to play" in text
    for seed, kind in want.items():
        assert f"herder seed={seed}: too_close at 3.0 s; referee: {kind}" in text
    assert "darter seed=101: too_close at 3.0 s; referee: evader" in text
    assert (  # one verdict per lost episode; the two at seed 101 share a start
        "referee (cpl 12) on the 3 lost starts (2 distinct): 2 evader (unavoidable), 0 "
        "pursuer (the policy's regret), 1 unknown (the referee's resolution gap)" in text
    )
    assert "2 evader, 2 unknown" in text  # the world's episodes per start's label


def test_a_world_the_referee_cannot_afford_is_not_solved(unseen, tmp_path, monkeypatch,
                                                         capsys) -> None:  # fmt: skip
    """A solve over the memory budget labels that world's starts ``not solved`` (its reason
    printed) instead of stopping the report."""
    monkeypatch.setenv("SURVEIL_CACHE_DIR", str(tmp_path / "cache"))
    # the referee's budget only ($SURVEIL_MEMORY_BUDGET would refuse Prop. 2's decomposition)
    monkeypatch.setitem(importlib.import_module("referee_labels").SOLVE, "memory_budget", "10MB")
    row = {"role": "pursuer", "world": "L_10x4", "combo": [0.5, 2.0, 2.0], "opponent": "herder",
           "seed": 101, "winner": "evader", "cause": "too_close", "t": 3.0, "steps": 30,
           "start": {"pursuer": [1.0, 1.0], "evader": [1.0, 3.5]}}  # fmt: skip
    out = tmp_path / "p.jsonl"
    out.write_text(json.dumps(row) + "\n")
    argv = ["--role", "pursuer", "--worlds", "L_10x4", "--combos", "0", "--opponents", "herder",
            "--results", str(out), "--referee", "12"]  # fmt: skip
    assert unseen.main(argv) == 0
    text = capsys.readouterr().out
    assert "referee (cpl 12) not solved on map 'L_10x4'" in text and "memory budget" in text
    # the flag and the variable a user of this script sets, not solve()'s keywords
    assert "No --referee CPL fits" in text and "SURVEIL_MEMORY_BUDGET=1GB in the env" in text
    assert "cells_per_lmin" not in text and "memory_budget=" not in text
    assert "herder seed=101: too_close at 3.0 s; referee: not solved" in text
    assert "on the 1 lost starts (1 distinct): 0 evader" in text and "1 not solved" in text


def test_hindsight_labels_the_losses_to_open_loop_evaders(unseen, tmp_path, capsys) -> None:
    """``--hindsight CELL``: a loss to an open-loop evader gets the hindsight's verdict
    against its recorded path; a closed-loop evader's loss gets none. The orbit episode is
    in fact held by the decomposition pursuer over the horizon (played here), so no verdict
    but ``pursuer`` is right; its row is written as a loss to be labelled."""
    world, combo, orbit = "L_10x4", [0.5, 2.0, 2.0], "evader/orbit:1:0.25"
    unseen._init(50, 8.0)
    played = unseen.play(("pursuer", world, combo, orbit, 101))
    assert played["winner"] == "pursuer" and played["steps"] == 50  # a pursuer held: oracle
    lost = {**played, "winner": "evader", "cause": "occluded", "t": 3.0, "steps": 30}
    herder = {**lost, "opponent": "herder", "cause": "too_close"}
    out = tmp_path / "p.jsonl"
    out.write_text("".join(json.dumps(r) + "\n" for r in (lost, herder)))
    argv = ["--role", "pursuer", "--worlds", world, "--combos", "0", "--opponents", orbit,
            "herder", "--max-cycles", "50", "--results", str(out),
            "--hindsight", "0.05"]  # fmt: skip
    assert unseen.main(argv) == 0
    text = capsys.readouterr().out
    assert f"hindsight (cell 0.05) {world} {combo} {orbit} seed=101: pursuer" in text
    assert "of 5.0; " in text  # the path extended to the horizon, 50 steps
    assert f"{orbit} seed=101: occluded at 3.0 s; hindsight: pursuer" in text
    assert "herder seed=101: too_close at 3.0 s\n" in text  # closed loop: not labelled
    assert (
        "hindsight (cell 0.05) on the 1 losses to open-loop evaders: 0 evader (unavoidable), "
        "1 pursuer (the policy's regret), 0 unknown (the hindsight's resolution gap)" in text
    )


def test_a_long_hindsight_estimate_is_a_line_of_the_report(
    unseen, tmp_path, capsys, monkeypatch
) -> None:
    """An estimate beyond ``LONG_SECONDS`` is printed as one line of the report before the
    run, not as a Python warning quoting the script's source."""
    import warnings

    from strategies.referee import hindsight

    monkeypatch.setattr(hindsight, "LONG_SECONDS", 0.0)  # every estimate is long
    world, combo, orbit = "L_10x4", [0.5, 2.0, 2.0], "evader/orbit:1:0.25"
    unseen._init(50, 8.0)
    lost = {**unseen.play(("pursuer", world, combo, orbit, 101)), "winner": "evader",
            "cause": "occluded", "t": 3.0, "steps": 30}  # fmt: skip
    out = tmp_path / "p.jsonl"
    out.write_text(json.dumps(lost) + "\n")
    argv = ["--role", "pursuer", "--worlds", world, "--combos", "0", "--opponents", orbit,
            "--max-cycles", "50", "--results", str(out), "--hindsight", "0.05"]  # fmt: skip
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert unseen.main(argv) == 0
    assert not [w for w in caught if "hindsight(cell" in str(w.message)]
    text = capsys.readouterr().out
    line = f"hindsight (cell 0.05) {world} {combo} {orbit} seed=101: hindsight(cell = 0.05"
    assert line in text and "estimated up to about" in text
    assert text.index(line) < text.index(f"{orbit} seed=101: pursuer")  # before the verdict


def test_a_hindsight_over_the_memory_budget_is_not_solved(unseen, tmp_path, capsys) -> None:
    """A cell whose grid would exceed the memory budget labels the loss ``not solved`` (the
    reason printed) instead of stopping the report."""
    row = {"role": "pursuer", "world": "L_10x4", "combo": [0.5, 2.0, 2.0],
           "opponent": "evader/straight", "seed": 101, "winner": "evader", "cause": "occluded",
           "t": 3.0, "steps": 30, "horizon": 20}  # fmt: skip
    out = tmp_path / "p.jsonl"
    out.write_text(json.dumps(row) + "\n")
    argv = ["--role", "pursuer", "--worlds", "L_10x4", "--combos", "0", "--opponents",
            "evader/straight", "--max-cycles", "20", "--results", str(out),
            "--hindsight", "1e-6"]  # fmt: skip
    assert unseen.main(argv) == 0
    text = capsys.readouterr().out
    assert "evader/straight seed=101: not solved (hindsight(cell = 1e-06" in text
    assert "use --hindsight CELL >= " in text and "memory_budget=" not in text
    assert "occluded at 3.0 s; hindsight: not solved" in text
    assert "on the 1 losses to open-loop evaders: 0 evader" in text and "1 not solved" in text


def test_the_rotation_bound_labels_the_losses_to_open_loop_evaders(unseen, tmp_path, capsys):
    """``--rotation-bound``: a loss to an open-loop evader is labelled ``certain by T s`` or
    ``not proven`` against its recorded path (to the horizon); a closed-loop evader's loss
    is not labelled. The orbit (offset 0.25) at rho 0.5 round rand:polygons:3007's 3.0-long
    hull: no pursuer holds past 20.5 s (the decomposition pursuer was occluded at 8.4 s);
    round rand:star:3007's 7.0-long one nothing is proven (the decomposition pursuer holds
    it; its row is written as a loss here, to be labelled)."""
    orbit, combo = "evader/orbit:1:0.25", [0.5, 2.0, 2.0]
    worlds = ["rand:polygons:3007:3.0", "rand:star:3007:3.0"]
    base = {"role": "pursuer", "combo": combo, "seed": 101, "horizon": 600, "winner": "evader",
            "cause": "occluded", "t": 8.4, "steps": 84}  # fmt: skip
    rows = [base | {"world": w, "opponent": o} for w in worlds for o in (orbit, "herder")]
    out = tmp_path / "p.jsonl"
    out.write_text("".join(json.dumps(r) + "\n" for r in rows))
    argv = ["--role", "pursuer", "--worlds", *worlds, "--combos", "0", "--opponents", orbit,
            "herder", "--results", str(out), "--rotation-bound"]  # fmt: skip
    assert unseen.main(argv) == 0
    text = capsys.readouterr().out
    assert f"rotation bound {worlds[0]} {combo} {orbit} seed=101: certain by 20.5 s (lost " in text
    assert f"rotation bound {worlds[1]} {combo} {orbit} seed=101: not proven (lost " in text
    assert f"{orbit} seed=101: occluded at 8.4 s; rotation bound: certain by 20.5 s\n" in text
    assert f"{orbit} seed=101: occluded at 8.4 s; rotation bound: not proven\n" in text
    assert "herder seed=101: occluded at 8.4 s\n" in text  # closed loop: not labelled
    assert (
        "rotation bound on the 2 losses to open-loop evaders: 1 certain (unavoidable: no "
        "pursuer holds past the time given), 1 not proven" in text
    )


def test_open_loop_names_the_evaders_whose_path_ignores_the_pursuer(unseen) -> None:
    assert all(map(unseen.open_loop, ["evader/straight", "evader/wall_hugging",
                                      "evader/random", "evader/orbit:-1:1.0"]))  # fmt: skip
    assert not any(map(unseen.open_loop, ["evader/shooting", "evader/toward_away:toward",
                                          "herder", "evader/orbiter", "darter"]))  # fmt: skip


@pytest.mark.parametrize(
    "argv, message",
    [(["--role", "pursuer", "--referee", "0"], "argument --referee: '0': expected a finite"),
     (["--role", "pursuer", "--referee", "nan"], "argument --referee: 'nan': expected a finite"),
     (["--role", "evader", "--referee", "8"], "--referee: the pursuer role only"),
     (["--role", "pursuer", "--hindsight", "0"], "argument --hindsight: '0': expected a finite"),
     (["--role", "evader", "--hindsight", "0.1"], "--hindsight: the pursuer role only"),
     (["--role", "evader", "--rotation-bound"], "--rotation-bound: the pursuer role only")],
)  # fmt: skip
def test_a_bad_referee_cpl_is_a_usage_error_naming_it(unseen, tmp_path, capsys, argv,
                                                       message) -> None:  # fmt: skip
    results = tmp_path / "r.jsonl"
    with pytest.raises(SystemExit) as exc:
        unseen.main([*argv, "--worlds", "plus_w6", "--results", str(results)])
    assert exc.value.code == 2
    assert message in capsys.readouterr().err
    assert not results.exists()
