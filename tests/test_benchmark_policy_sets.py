"""benchmarks/policy_sets.py: named sets played into results files, their totals, and the
per-episode comparison of two runs, on rows the benchmark scripts actually wrote."""

from __future__ import annotations

import importlib
import json
import re
import shutil
import signal
from pathlib import Path

import pytest

from envs.errors import InvalidConfigError

BENCHMARKS = Path(__file__).resolve().parents[1] / "benchmarks"

# A herder pins the decomposition pursuer on the rotated corner from seed 1 at 8.7 s
# (too_close) and not from seed 0 within 12 s: a 6 s horizon holds both.
CORNER = ("--role", "pursuer", "--worlds", "corner~rot0.37", "--combos", "0", "--opponents",
          "herder", "--seeds", "0", "1")  # fmt: skip


@pytest.fixture
def ps(monkeypatch):
    """The module (it imports the benchmark scripts from beside it)."""
    monkeypatch.syspath_prepend(str(BENCHMARKS))
    return importlib.import_module("policy_sets")


def _tiny(ps, name: str, script: str, args: tuple[str, ...], role: str = "pursuer"):
    return ps.PolicySet(name, script, args, role, 0, 2, "-")


def _rows(path: Path) -> list[dict]:
    return [json.loads(line) for line in path.read_text().splitlines()]


def _write(path: Path, rows: list[dict]) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("".join(json.dumps(r) + "\n" for r in rows))


@pytest.fixture(scope="module")
def corner_runs(tmp_path_factory):
    """The corner set played by ``run`` at two horizons, 12 s (base) and 6 s (cand)."""
    import sys

    sys.path.insert(0, str(BENCHMARKS))
    try:
        ps = importlib.import_module("policy_sets")
        root = tmp_path_factory.mktemp("corner")
        for out, cycles in (("long", "120"), ("short", "60")):
            tiny = _tiny(ps, "corner", "unseen_worlds.py", (*CORNER, "--max-cycles", cycles))
            assert ps.run_sets(["corner"], str(root / out), 1, {"corner": tiny}) == 0
    finally:
        sys.path.remove(str(BENCHMARKS))
    # The 6 s rows stand for a candidate policy that holds seed 1: an episode's key names
    # its horizon (a rerun at another horizon plays it again), so they are keyed as the
    # base's episodes, played to 120 steps.
    short = root / "short" / "corner.jsonl"
    _write(short, [{**r, "horizon": 120} for r in _rows(short)])
    return root, tiny


def test_run_plays_a_set_into_its_file_and_totals_count_the_role_s_wins(ps, corner_runs, capsys):
    root, tiny = corner_runs
    long = {r["seed"]: r for r in _rows(root / "long" / "corner.jsonl")}
    short = {r["seed"]: r for r in _rows(root / "short" / "corner.jsonl")}
    assert (long[0]["winner"], long[1]["winner"], long[1]["cause"]) == ("pursuer", "evader",
                                                                       "too_close")  # fmt: skip
    assert 6 < long[1]["t"] < 12
    assert short[0]["winner"] == short[1]["winner"] == "pursuer"
    assert ps.totals(str(root / "long"), {"corner": tiny}) == 0
    out = capsys.readouterr().out
    line = next(x for x in out.splitlines() if x.startswith("corner"))
    assert line.split()[:3] == ["corner", "pursuer", "1/2"]
    assert f"{long[0]['code']} (2)" in line


def test_compare_lists_the_episodes_whose_winner_changed(ps, corner_runs, capsys):
    """Base 12 s, cand 6 s: seed 1's loss is gained (exit 0); the other way round it is
    lost (exit 1), printed with its cause, time and replay command."""
    root, tiny = corner_runs
    sets = {"corner": tiny}
    assert ps.compare(str(root / "long"), str(root / "short"), sets) == 0
    out = capsys.readouterr().out
    assert "base 1/2, cand 2/2; 2 episodes in both: 0 lost, 1 gained" in out
    gained = [x for x in out.splitlines() if x.startswith("  gained:")]
    assert len(gained) == 1 and "corner~rot0.37 [0.5, 2.0, 2.0] herder seed=1:" in gained[0]
    assert "cand won to the horizon; base lost too_close at 8." in gained[0]
    assert ps.compare(str(root / "short"), str(root / "long"), sets) == 1
    out = capsys.readouterr().out
    assert "0 gained" in out and "1 lost" in out
    assert "  lost: corner~rot0.37 [0.5, 2.0, 2.0] herder seed=1: cand lost too_close" in out
    assert (
        "    replay: python benchmarks/unseen_worlds.py --role pursuer --worlds corner~rot0.37 "
        "--combos 0 --opponents 'herder' --seeds 1" in out
    )
    assert "cand lost 1 episode(s) that base won" in out


def test_swapped_winners_are_one_lost_and_one_gained(ps, corner_runs, tmp_path, capsys):
    """The base's two rows with their winners swapped: seed 0 (held at base) is lost, seed
    1 (lost at base) is gained; an unchanged comparison lists neither."""
    root, tiny = corner_runs
    rows = _rows(root / "long" / "corner.jsonl")
    swap = {"pursuer": "evader", "evader": "pursuer"}
    _write(tmp_path / "cand" / "corner.jsonl", [{**r, "winner": swap[r["winner"]]} for r in rows])
    assert ps.compare(str(root / "long"), str(tmp_path / "cand"), {"corner": tiny}) == 1
    out = capsys.readouterr().out
    assert "1 lost, 1 gained" in out
    assert "  lost: corner~rot0.37 [0.5, 2.0, 2.0] herder seed=0:" in out
    assert "  gained: corner~rot0.37 [0.5, 2.0, 2.0] herder seed=1:" in out
    assert ps.compare(str(root / "long"), str(root / "long"), {"corner": tiny}) == 0
    out = capsys.readouterr().out
    assert "0 lost, 0 gained" in out and "lost:" not in out and "gained:" not in out


def test_rows_on_one_side_and_mixed_code_versions_are_said(ps, corner_runs, tmp_path, capsys):
    root, tiny = corner_runs
    rows = _rows(root / "long" / "corner.jsonl")
    cand = [{**rows[0], "code": "0123456789ab"}]  # one row, other code than the base's
    _write(tmp_path / "cand" / "corner.jsonl", cand)
    _write(tmp_path / "mixed" / "corner.jsonl", [*rows[:1], {**rows[1], "code": None}])
    assert ps.compare(str(root / "long"), str(tmp_path / "cand"), {"corner": tiny}) == 0
    out = capsys.readouterr().out
    assert "1 episodes in both" in out and "rows only in base: 1, only in cand: 0" in out
    assert "more than one code version" not in out
    assert ps.compare(str(tmp_path / "mixed"), str(root / "long"), {"corner": tiny}) == 0
    out = capsys.readouterr().out
    assert "note: the base rows come from more than one code version: " in out
    assert "not recorded (1)" in out and "note: the cand rows" not in out


def test_pursuer_holds_rows_are_read_by_their_own_winner_field(ps, tmp_path, capsys):
    """pursuer_holds.py keeps the winner in out["pursuer/decomposition"]: on the rotated
    corner the toward-away evader wins from seed 2 at 14.70 s (3.18 s before 4d0ccce, 13.55 s
    before ddb7e92) and not from seeds 0-1 within 20 s. A cand whose two rows swapped
    winners loses seed 0 and gains seed 2; a cand played at another horizon shares no
    episode (the horizon is in this script's key)."""
    args = ("--worlds", "corner", "--variants", "rot 0.37", "--rho", "0.5", "--evaders",
            "evader/toward_away", "--seeds", "3", "--no-greedy")  # fmt: skip
    sets = {"holds": _tiny(ps, "holds", "pursuer_holds.py", (*args, "--max-cycles", "200"))}
    assert ps.run_sets(["holds"], str(tmp_path / "base"), 1, sets) == 0
    out = capsys.readouterr().out
    assert "2/3" in next(x for x in out.splitlines() if x.startswith("holds"))
    rows = _rows(tmp_path / "base" / "holds.jsonl")
    by_seed = {r["seed"]: r for r in rows}
    assert [by_seed[s]["out"]["pursuer/decomposition"][0] for s in range(3)] == [
        "pursuer", "pursuer", "evader"]  # fmt: skip
    swapped = []
    for r in rows:
        r = json.loads(json.dumps(r))
        if r["seed"] in (0, 2):
            r["out"]["pursuer/decomposition"][:3] = by_seed[2 - r["seed"]]["out"][
                "pursuer/decomposition"][:3]  # fmt: skip
        swapped.append(r)
    _write(tmp_path / "cand" / "holds.jsonl", swapped)
    assert ps.compare(str(tmp_path / "base"), str(tmp_path / "cand"), sets) == 1
    out = capsys.readouterr().out
    assert "base 2/3, cand 2/3; 3 episodes in both: 1 lost, 1 gained" in out
    assert "  lost: corner [rot 0.37] rho=0.5 evader/toward_away seed=0: cand lost too_close" in out
    assert "  gained: corner [rot 0.37] rho=0.5 evader/toward_away seed=2: cand won" in out
    assert "replay: surveil play --map 'corner~rot0.37' --pursuer pursuer/decomposition" in out
    assert "--evader evader/toward_away --seed 0 --start safe --max-cycles 200" in out
    other = [{**r, "max_cycles": 30} for r in rows]
    _write(tmp_path / "other" / "holds.jsonl", other)
    assert ps.compare(str(tmp_path / "base"), str(tmp_path / "other"), sets) == 0
    assert "0 episodes in both" in (out := capsys.readouterr().out)
    assert "rows only in base: 3, only in cand: 3" in out


def test_evader_escapes_rows_count_the_evader_s_escapes(ps, tmp_path, capsys):
    """evader_escapes.py keeps the winner in out["shooting"] and no cause: a cand where the
    pursuer held seed 1 lost it, with a replay command narrowed to that world and pursuer."""
    args = ("--worlds", "tee", "--pursuers", "still", "--seeds", "2", "--simple-seeds", "0",
            "--k", "1")  # fmt: skip
    sets = {"tee": _tiny(ps, "tee", "evader_escapes.py", args, role="evader")}
    assert ps.run_sets(["tee"], str(tmp_path / "base"), 1, sets) == 0
    rows = _rows(tmp_path / "base" / "tee.jsonl")
    assert all(r["out"]["shooting"][0] == "evader" for r in rows)
    capsys.readouterr()
    for r in rows:
        if r["seed"] == 1:
            r["out"]["shooting"][:2] = [None, None]  # held to the horizon
    _write(tmp_path / "cand" / "tee.jsonl", rows)
    assert ps.compare(str(tmp_path / "base"), str(tmp_path / "cand"), sets) == 1
    out = capsys.readouterr().out
    assert "tee (evader wins): base 2/2, cand 1/2" in out
    assert "  lost: tee [as is] still seed=1: cand lost to the horizon; base won at " in out
    assert (
        "replay: python benchmarks/evader_escapes.py --worlds tee --variants 'as is' "
        "--pursuers still --seeds 2 --simple-seeds 0 --k 1 --start safe  # seeds 0-1" in out
    )


def test_a_missing_or_empty_directory_is_refused_naming_it(ps, tmp_path):
    with pytest.raises(InvalidConfigError, match=r"'.*nowhere': no such directory"):
        ps.totals(str(tmp_path / "nowhere"))
    (tmp_path / "empty").mkdir()
    (tmp_path / "empty" / "notes.jsonl").write_text("{}\n")
    expected = r"holds no results file of any set; expected files named SET.jsonl, SET one of"
    with pytest.raises(InvalidConfigError, match=expected + r" holds-bench, holds-variants"):
        ps.compare(str(tmp_path / "empty"), str(tmp_path / "empty"))


def test_a_row_of_another_script_or_role_is_refused_naming_it(ps, tmp_path):
    escapes_row = {"world": "tee", "variant": "as is", "pursuer": "still", "seed": 0, "k": 1.0,
                   "start": "safe", "simple": [], "out": {"shooting": ["evader", 1.0]}}  # fmt: skip
    _write(tmp_path / "d" / "holds-bench.jsonl", [escapes_row])
    with pytest.raises(InvalidConfigError, match=r"holds-bench.jsonl, line 1: the row has no "
                       r"field 'rho'"):  # fmt: skip
        ps.totals(str(tmp_path / "d"))
    pursuer_row = {"role": "pursuer", "world": "corridor", "combo": [0.5, 2.0, 2.0],
                   "opponent": "herder", "seed": 101, "winner": "pursuer"}  # fmt: skip
    _write(tmp_path / "e" / "unseen-e.jsonl", [pursuer_row])
    with pytest.raises(InvalidConfigError, match=r"is of the pursuer role; set unseen-e "
                       r"measures the evader"):  # fmt: skip
        ps.totals(str(tmp_path / "e"))
    no_out = {k: v for k, v in escapes_row.items() if k != "out"}
    _write(tmp_path / "f" / "escapes-bench.jsonl", [no_out])
    with pytest.raises(InvalidConfigError, match=r"has no 'out' as evader_escapes.py writes"):
        ps.totals(str(tmp_path / "f"))


def test_the_command_line_lists_the_sets_and_a_bad_directory_is_one_line_exit_2(
    ps, tmp_path, capsys
):
    bench_cli = importlib.import_module("bench_cli")
    with pytest.raises(SystemExit):
        ps.main(["--help"])
    text = capsys.readouterr().out
    for s in ps.SETS.values():
        assert f"  {s.name} ({s.alias}): {s.won}/{s.episodes} {s.role} wins" in text
    old = signal.getsignal(signal.SIGTERM)
    try:
        assert bench_cli.run(lambda: ps.main(["totals", str(tmp_path / "nowhere")])) == 2
    finally:
        signal.signal(signal.SIGTERM, old)  # run() answers SIGTERM: not in pytest's process
    err = capsys.readouterr().err
    assert "nowhere': no such directory" in err and "Traceback" not in err
    (tmp_path / "a.jsonl").write_text("")
    with pytest.raises(InvalidConfigError, match=r"a.jsonl': not a directory; expected a dir"):
        ps.totals(str(tmp_path / "a.jsonl"))  # it said 'no such directory'
    with pytest.raises(SystemExit):
        ps.main(["run", "--help"])
    text = capsys.readouterr().out
    assert "a set's name or short name" in text and "DIR/SET.jsonl" in text
    with pytest.raises(SystemExit):
        ps.main(["run", "nope", "--out", str(tmp_path)])
    assert "'nope': expected a set name, one of holds-bench" in capsys.readouterr().err


def test_each_set_is_the_command_readme_quotes(ps):
    """The sets are the README's commands (its table and the unseen-worlds paragraphs), so
    a figure there and a set here mean the same episodes."""
    readme = (BENCHMARKS.parent / "README.md").read_text()
    for name in (
        "holds-bench",
        "unseen-p0",
        "escapes-bench",
        "corner-default",
        "fresh-e",
        "holds-bench-03",
        "holds-bench-045",
    ):
        command = ps.SETS[name].command()
        quoted = " ".join(f'"{w}"' if " " in w else w for w in command)
        assert quoted in readme, quoted
    assert len(ps.FRESH_WORLDS.split()) == 32


def test_readmes_table_of_sets_gives_each_set_s_figure(ps):
    """README's table of the eighteen sets quotes each set's figure as this module holds it
    (and the commit they were all measured at), so the two cannot drift apart."""
    readme = (BENCHMARKS.parent / "README.md").read_text()
    start = readme.index("| set | what it plays, and the command | wins |")
    quoted = {}
    for row in readme[start : readme.index("\n\n", start)].splitlines()[2:]:
        cells = [cell.strip() for cell in row.strip().strip("|").split("|")]
        names = re.findall(r"`([^`]+)`", cells[0])  # `unseen-p0`, `-p1`, `-p2`
        names = [names[0].rsplit("-", 1)[0] + n if n.startswith("-") else n for n in names]
        quoted.update(zip(names, (f.strip() for f in cells[-1].split(",")), strict=True))
    assert quoted == {name: f"{s.won}/{s.episodes}" for name, s in ps.SETS.items()}
    (measured,) = {s.measured for s in ps.SETS.values()}
    assert f"The eighteen sets and their figures, all played at {measured}" in readme


def test_run_says_which_script_failed_and_exits_non_zero(ps, tmp_path, capsys):
    sets = {"bad": _tiny(ps, "bad", "pursuer_holds.py", ("--worlds", "nowhere"))}
    assert ps.run_sets(["bad"], str(tmp_path), 1, sets) == 1
    out = capsys.readouterr().out
    assert "== bad: pursuer_holds.py exited with status 2" in out
    assert "failed: bad" in out


def test_a_set_only_one_directory_holds_is_named_not_compared(ps, corner_runs, tmp_path, capsys):
    root, tiny = corner_runs
    other = _tiny(ps, "other", "unseen_worlds.py", CORNER)
    sets = {"corner": tiny, "other": other}
    shutil.copy(root / "long" / "corner.jsonl", tmp_path / "other.jsonl")
    assert ps.compare(str(root / "long"), str(root / "short"), sets) == 0
    assert "sets only in" not in capsys.readouterr().out
    (tmp_path / "base").mkdir()
    shutil.copy(root / "long" / "corner.jsonl", tmp_path / "base" / "corner.jsonl")
    shutil.copy(root / "long" / "corner.jsonl", tmp_path / "base" / "other.jsonl")
    assert ps.compare(str(tmp_path / "base"), str(root / "short"), sets) == 0
    out = capsys.readouterr().out
    assert "sets only in base (not compared): other" in out and "other (pursuer" not in out
    with pytest.raises(InvalidConfigError, match=r"have no set in common \(base: corner; "
                       r"cand: other\)"):  # fmt: skip
        ps.compare(str(root / "long"), str(tmp_path), sets)


def test_a_set_s_short_name_is_taken_as_help_shows_it(ps):
    # --help lists "holds-bench (b1)", and 'run b1' was refused as no set name
    for s in ps.SETS.values():
        assert ps._set_name(s.alias) == ps._set_name(s.name) == s.name


def test_run_plays_the_code_of_the_checkout_it_is_in(tmp_path, capfd, monkeypatch):
    # 'python benchmarks/X.py' imports the package from the checkout installed in editable
    # mode, not from the one the script is in: 'policy_sets.py run' in a second checkout
    # (a git worktree with the candidate policy) played the installed checkout's code, and
    # its rows said so ('VERSION (scripts: VERSION)'). The second checkout here: a copy of
    # benchmarks/ beside links to this one's packages.
    import importlib.util
    import sys

    other = tmp_path / "checkout"
    other.mkdir()
    for package in ("envs", "strategies", "analysis", "training"):
        (other / package).symlink_to(BENCHMARKS.parent / package, target_is_directory=True)
    shutil.copytree(BENCHMARKS, other / "benchmarks", ignore=shutil.ignore_patterns("__pycache__"))
    monkeypatch.syspath_prepend(str(other / "benchmarks"))
    spec = importlib.util.spec_from_file_location(
        "policy_sets_elsewhere", other / "benchmarks" / "policy_sets.py"
    )
    module = importlib.util.module_from_spec(spec)
    monkeypatch.setitem(sys.modules, spec.name, module)  # its dataclasses look it up
    spec.loader.exec_module(module)
    assert module.ROOT == str(other)
    args = (*CORNER[:-2], "0", "--max-cycles", "10")
    tiny = _tiny(module, "corner", "unseen_worlds.py", args)
    assert module.run_sets(["corner"], str(tmp_path / "out"), 1, {"corner": tiny}) == 0
    (row,) = _rows(tmp_path / "out" / "corner.jsonl")
    err = capfd.readouterr().err
    assert "(scripts:" not in str(row["code"]) and "policies that play are imported" not in err


def test_corner_default_rows_are_read_by_their_winner_and_replayed_by_fixed_starts(
    ps, tmp_path, capsys
):
    """fixed_starts.py --starts default: the corner world as the report plays it. The
    herder pins the pursuer from seed 1 (too_close at 19.7 s) and not from seed 0 in the
    500 steps: 1/2; a cand that loses seed 0 too is one lost, with the replay command."""
    args = ("--starts", "default", "--world", "corner", "--opponents", "herder", "--seeds",
            "0-1")  # fmt: skip
    sets = {"cdef": _tiny(ps, "cdef", "fixed_starts.py", args)}
    assert ps.run_sets(["cdef"], str(tmp_path / "base"), 1, sets) == 0
    out = capsys.readouterr().out
    assert next(x for x in out.splitlines() if x.startswith("cdef")).split()[:3] == [
        "cdef", "pursuer", "1/2"]  # fmt: skip
    rows = {r["seed"]: r for r in _rows(tmp_path / "base" / "cdef.jsonl")}
    assert (rows[0]["winner"], rows[0]["steps"]) == ("pursuer", 500)
    assert (rows[1]["winner"], rows[1]["cause"]) == ("evader", "too_close")
    assert rows[0]["start"] is None and set(rows[0]["start_drawn"]) == {"pursuer", "evader"}
    lost = {**rows[0], "winner": "evader", "cause": "too_close", "t": 5.0}
    _write(tmp_path / "cand" / "cdef.jsonl", [lost, rows[1]])
    assert ps.compare(str(tmp_path / "base"), str(tmp_path / "cand"), sets) == 1
    out = capsys.readouterr().out
    assert "cdef (pursuer wins): base 1/2, cand 0/2; 2 episodes in both: 1 lost, 0 gained" in out
    assert (
        "  lost: corner herder seed=0: cand lost too_close at 5.00 s; base won to the horizon\n"
        in out
    )
    assert (
        "    replay: python benchmarks/fixed_starts.py --starts default --world corner "
        "--opponents herder --seeds 0 --results replay.jsonl --play-again" in out
    )


def test_a_loss_from_a_certified_start_is_compared_as_a_regret(ps, tmp_path, capsys):
    """fixed_starts.py --starts certified: the shooting evader escapes the decomposition
    pursuer from the first two certified evader-win starts on plus_w1.6a4.5 (at 25.0 s and
    9.8 s); played to 0.01 D / V_e (0.8 s) it escapes from neither, and its rows say each
    loss is a regret. Those rows, keyed at the base's horizon, stand for a cand that lost
    both: compare names them as regrets."""
    args = ("--starts", "certified", "--role", "evader", "--worlds", "plus_w1.6a4.5",
            "--opponents", "pursuer/decomposition", "--seeds", "0", "1")  # fmt: skip
    base = {"certe": _tiny(ps, "certe", "fixed_starts.py", args, role="evader")}
    short = {"certe": _tiny(ps, "certe", "fixed_starts.py", (*args, "--k", "0.01"), "evader")}
    assert ps.run_sets(["certe"], str(tmp_path / "base"), 1, base) == 0
    assert ps.run_sets(["certe"], str(tmp_path / "short"), 1, short) == 0
    capsys.readouterr()
    won = _rows(tmp_path / "base" / "certe.jsonl")
    expected = [("evader", False, "evader")] * 2
    assert [(r["winner"], r["regret"], r["certified"]) for r in won] == expected
    held = _rows(tmp_path / "short" / "certe.jsonl")
    assert [(r["winner"], r["regret"]) for r in held] == [("pursuer", True)] * 2
    _write(tmp_path / "cand" / "certe.jsonl", [{**r, "horizon": 8.0} for r in held])
    assert ps.compare(str(tmp_path / "base"), str(tmp_path / "cand"), base) == 1
    out = capsys.readouterr().out
    assert "certe (evader wins): base 2/2, cand 0/2; 2 episodes in both: 2 lost" in out
    assert (
        "  lost: plus_w1.6a4.5 [0.2, 3.0, 2.0] pursuer/decomposition seed=0: cand lost to the "
        "horizon, a regret (certified evader-win start); base won occluded at 25.02 s" in out
    )
    assert (
        "replay: python benchmarks/fixed_starts.py --starts certified --role evader --worlds "
        "plus_w1.6a4.5 --opponents pursuer/decomposition --seeds 1 --results replay.jsonl "
        "--play-again" in out
    )
    assert ps.totals(str(tmp_path / "short"), short) == 0
    assert "0/2" in next(x for x in capsys.readouterr().out.splitlines() if x.startswith("certe"))
