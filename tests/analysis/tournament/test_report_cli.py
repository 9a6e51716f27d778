"""The report renders (HTML parses, images exist and decode); the command line works."""

from __future__ import annotations

import base64
import io
import re
from html.parser import HTMLParser

import pytest
from PIL import Image

from analysis.cli import main
from analysis.tournament import Store, run_tournament, spec_from_dict
from analysis.tournament.report import write_report


class _Page(HTMLParser):
    def __init__(self):
        super().__init__()
        self.images, self.ids, self.tables = [], [], 0

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag == "img":
            self.images.append(a)
        if "id" in a:
            self.ids.append(a["id"])
        self.tables += tag == "table"


def test_report_renders_with_heat_maps_ratings_and_replays(tmp_path, small_spec):
    store = tmp_path / "s.sqlite"
    run_tournament(spec_from_dict(small_spec), store, backend="serial", progress=False)
    files = write_report(store, tmp_path / "rep")
    page = _Page()
    page.feed(files["html"].read_text())
    page.close()
    assert {"matrices", "games", "ratings", "paired", "regret", "replays", "errors"} <= set(
        page.ids
    )
    assert page.tables >= 4
    kinds = []
    for img in page.images:
        head, data = img["src"].split(",", 1)
        assert head.startswith("data:image/") and img["alt"]
        with Image.open(io.BytesIO(base64.b64decode(data))) as im:
            kinds.append(im.format)
            if im.format == "GIF":
                assert im.n_frames > 5
    assert kinds.count("PNG") == 2 and kinds.count("GIF") >= 2  # one replay per map
    md = files["markdown"].read_text()
    for name in re.findall(r"\]\(([^)]+)\)", md):
        assert (tmp_path / "rep" / name).is_file()
    assert "differs from the stored outcome" not in md  # replays re-simulate faithfully
    # the referee rebuilt every match's game from the spec's built-in maps (source
    # "builtin:NAME", their recommended parameters) and counted all 24
    regret = md.split("## Regret", 1)[1].split("\n## ", 1)[0]
    assert "not counted" not in regret
    assert re.search(r"\| pursuer \| pursuer/greedy \| 12 \|", regret)


def _mini_tournament(tmp_path):
    """(store, argv) of a 4-match tournament on the open room (greedy pursuer, two evaders,
    two seeds, 20 steps), played serially without progress bars."""
    return _tournament(
        tmp_path,
        "mini",
        'maps = ["open_room"]\npursuers = ["pursuer/greedy"]\n'
        'evaders = ["evader/random", "evader/straight"]\nseeds = 2\n[env]\nmax_cycles = 20\n',
    )


def _tournament(tmp_path, name, toml):
    """(store, argv) of the tournament spec ``toml`` written to NAME.toml, stored in
    NAME.sqlite, played serially without progress bars."""
    spec = tmp_path / f"{name}.toml"
    spec.write_text(toml)
    store = tmp_path / f"{name}.sqlite"
    argv = ["tournament", str(spec), "--store", str(store), "--no-progress", "--backend", "serial"]
    return store, argv


def test_cli_tournament_report_export_and_errors(tmp_path, capsys):
    store, argv = _mini_tournament(tmp_path)
    assert main([*argv, "--no-report"]) == 0
    out = capsys.readouterr().out
    assert "4 of 4 matches stored" in out and "evader/straight" in out
    # resumes: nothing to play; the report's regret table solves referee games, which
    # took 13 minutes without a word: it is announced on stderr before it starts
    assert main([*argv, "--report", str(tmp_path / "r0"), "--no-replays"]) == 0
    out, err = capsys.readouterr()
    assert "4 reused, 0 played" in out and f"report written to {tmp_path / 'r0'}" in out
    assert err.startswith(f"writing the report to {tmp_path / 'r0'}: its regret table solves")
    assert "(16 cells per L_min; cached" in err and err.rstrip().endswith("--no-report skips it")
    assert main(["report", str(store), "--out", str(tmp_path / "r"), "--no-replays"]) == 0
    assert (tmp_path / "r" / "report.html").is_file()
    assert capsys.readouterr().err.startswith(f"writing the report to {tmp_path / 'r'}: ")
    assert main(["export", str(store), str(tmp_path / "x.csv")]) == 0
    assert len((tmp_path / "x.csv").read_text().splitlines()) == 5
    assert main(["tournament", "--list"]) == 0
    assert "quick" in capsys.readouterr().out
    for bad, message in [
        (["tournament", str(tmp_path / "missing.toml")], "no such file"),
        (["report", str(tmp_path / "missing.sqlite")], "no such file"),
        (["export", str(store), str(tmp_path / "x.txt")], ".csv"),
        # under a file: was "x.csv: File exists"
        (["export", str(store), str(tmp_path / "x.csv" / "y.csv")], "is a file, not a directory"),
        (["evaluate", "--results", str(tmp_path / "old.jsonl")], "SQLite store"),
        # a device was "no such file" (readers) or "disk I/O error" (writers)
        (["tournament", "/dev/null"], "spec '/dev/null': is a character device, not a regular"),
        (["report", "/dev/null"], "store '/dev/null': is a character device, not a regular"),
        (["export", "/dev/null", str(tmp_path / "y.csv")], "is a character device"),
        (["tournament", "quick", "--store", "/dev/null"], "is a character device"),
        (["tournament", str(tmp_path)], "is a directory, not a file"),
        # a SPEC beside --list was ignored: the list printed, exit 0
        (["tournament", "--list", "quick"], "--list takes no SPEC, got 'quick'"),
        # no SPEC at all: the message named the program twice ("surveil: error: surveil ...")
        (["tournament"], "error: tournament SPEC: missing; expected a .toml file"),
    ]:
        capsys.readouterr()
        assert main(bad) == 2
        err = capsys.readouterr().err
        assert message in err and "Traceback" not in err and len(err.strip().splitlines()) == 1


def test_evaluate_is_a_one_off_tournament_without_double_counting(tmp_path, capsys):
    store = tmp_path / "e.sqlite"
    argv = [
        "evaluate",
        "--maps",
        "open_room",
        "--pursuers",
        "pursuer/greedy",
        "pursuer/greedy",
        "--evaders",
        "evader/random",
        "--seeds",
        "3",
        "--max-cycles",
        "20",
        "--results",
        str(store),
        "--no-progress",
        "--plot",
        str(tmp_path / "t.png"),
    ]
    assert main(argv) == 0
    captured = capsys.readouterr()
    # the CLI shows warnings as one line each: "surveil: warning: ..."
    assert "surveil: warning:" in captured.err and "merged into one entry" in captured.err
    out = captured.out
    assert "3 of 3 matches stored" in out  # the repeated pursuer is played once
    assert (tmp_path / "t.png").stat().st_size > 1000
    with Store(store) as db:
        assert db.conn.execute("SELECT COUNT(*) FROM results").fetchone()[0] == 3


def test_evaluate_takes_zoo_models_by_name(tmp_path, capsys):
    """`--pursuers zoo:NAME` is a learned model, as `zoo:NAME` is in a spec's roster."""
    argv = ["evaluate", "--maps", "corridor", "--pursuers", "zoo:ppo_pursuer_vs_straight_open_room",
            "--evaders", "evader/straight", "--seeds", "1", "--max-cycles", "10",
            "--results", str(tmp_path / "z.sqlite"), "--no-progress"]  # fmt: skip
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert "1 of 1 matches stored" in out and "zoo:ppo_pursuer_vs_straight_open_room" in out


@pytest.mark.parametrize("workers", ["1", "2"])
def test_evaluate_warns_once_per_model_at_a_game_it_was_not_trained_at(tmp_path, capsys, workers):
    """A model at another rho than its training's, on two maps, four matches: one warning
    per model and kind, said by the main process. It said nothing: the workers play a copy
    of the model file without the provenance.json the check reads (``surveil play`` said
    it)."""
    argv = ["evaluate", "--maps", "corridor", "l_hall", "--pursuers",
            "zoo:dagger_pursuer_generalist", "zoo:dagger_pursuer_l_hall", "--evaders",
            "evader/straight", "--seeds", "2", "--max-cycles", "3", "--config",
            '{"v_evader": 0.8}', "--workers", workers, "--results",
            str(tmp_path / "z.sqlite"), "--no-progress"]  # fmt: skip
    assert main(argv) == 0
    said = [x for x in capsys.readouterr().err.splitlines() if x.startswith("surveil: warning:")]
    rho = "rho = v_evader / v_pursuer: 0.5 in training (0.5 / 1), 0.8 here (0.8 / 1). Up to"
    assert [x.split(": this model")[0] for x in said] == [
        "surveil: warning: zoo:dagger_pursuer_generalist",
        "surveil: warning: zoo:dagger_pursuer_l_hall",
        "surveil: warning: zoo:dagger_pursuer_l_hall",
    ], said
    assert rho in said[0] and " plays a game it was not trained at" in said[0]
    assert rho in said[1]
    assert "trained on l_hall; it plays 'corridor', a map it has not seen" in said[2]


def test_a_regret_table_over_the_memory_budget_leaves_the_rest_of_the_report(
    tmp_path, small_spec, monkeypatch
):
    """`surveil report` under SURVEIL_MEMORY_BUDGET=130MB stopped with exit 2 at the
    referee's solve for the regret table (naming cells_per_lmin, which the report does not
    take); now the table says why it is missing and the report is written."""
    store = tmp_path / "s.sqlite"
    run_tournament(spec_from_dict(small_spec), store, backend="serial", progress=False)
    monkeypatch.setenv("SURVEIL_MEMORY_BUDGET", "130MB")
    monkeypatch.setenv("SURVEIL_CACHE_DIR", str(tmp_path / "cache"))
    files = write_report(store, tmp_path / "rep", replays=False)
    regret = files["markdown"].read_text().split("## Regret", 1)[1].split("\n## ", 1)[0]
    assert "Not solved: solve(map " in regret and "more than the memory budget" in regret
    assert "Use the resolution (the report's is 16 cells per L_min) <= " in regret
    assert "SURVEIL_MEMORY_BUDGET=" in regret and "memory_budget=" not in regret


def test_the_resume_command_keeps_the_backend_workers_and_address(monkeypatch, tmp_path):
    # "to resume: surveil tournament big.toml --store S --backend ray": without --workers 2
    # the resumed run took every core
    import analysis.tournament.driver as driver

    hints = []

    def fake_run(spec, store, **kw):
        hints.append(kw["resume_hint"])
        raise KeyboardInterrupt  # stop here: only the hint is under test

    monkeypatch.setattr(driver, "run_tournament", fake_run)
    store = tmp_path / "q.sqlite"
    for extra, want in [
        ([], f"surveil tournament quick --store {store}"),
        (["--workers", "2"], f"surveil tournament quick --store {store} --workers 2"),
        (
            ["--backend", "ray", "--workers", "3", "--address", "auto"],
            f"surveil tournament quick --store {store} --backend ray --workers 3 --address auto",
        ),
    ]:
        try:
            main(["tournament", "quick", "--store", str(store), *extra])
        except KeyboardInterrupt:
            pass
        assert hints[-1] == want


def test_a_report_directory_that_is_a_file_is_refused_before_the_run(tmp_path, capsys):
    # the run played every match, printed its table, then failed: "x: File exists"
    (tmp_path / "notes.txt").write_text("a file")
    (tmp_path / "s_report").write_text("a file where the default report goes")
    store = tmp_path / "t.sqlite"
    cases = [
        (["--store", str(store), "--report", str(tmp_path / "notes.txt")], "notes.txt"),
        (["--store", str(store), "--report", str(tmp_path / "notes.txt" / "r")], "notes.txt"),
        (["--store", str(tmp_path / "s.sqlite")], "s_report"),  # the default, beside it
    ]
    for argv, blocker in cases:
        assert main(["tournament", "quick", *argv]) == 2
        out, err = capsys.readouterr()
        assert err.startswith("surveil: error: --report = ") and len(err.splitlines()) == 1
        assert f"{blocker}' is a file, expected a directory" in err and not out
    assert not store.exists() and not (tmp_path / "s.sqlite").exists()
    Store(tmp_path / "empty.sqlite").close()
    argv = ["report", str(tmp_path / "empty.sqlite"), "--out", str(tmp_path / "notes.txt")]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "--out = " in err and "notes.txt' is a file, expected a directory" in err


def test_replay_captions_name_the_grid_value(tmp_path, monkeypatch):
    """A spec with ``[grid] rho = [...]`` has one scope per map and value, and a replay for
    each; their captions said only the map ('u.wkt: ... seed 0', twice), not which rho."""
    import analysis.tournament.report as report

    monkeypatch.setattr(report, "_regret_section", lambda a, say=None: ("-", "<p>-</p>"))
    spec = {
        "name": "grid",
        "maps": ["open_room"],
        "pursuers": ["pursuer/greedy"],
        "evaders": ["evader/straight"],
        "seeds": 1,
        "start": "valid",
        "env": {"max_cycles": 20},
        "grid": {"rho": [0.3, 0.6]},
    }
    store = tmp_path / "g.sqlite"
    run_tournament(spec_from_dict(spec), store, backend="serial", progress=False)
    md = write_report(store, tmp_path / "rep")["markdown"].read_text()
    replays = md.split("## Replays", 1)[1].split("\n## ", 1)[0]
    for rho in ("0.3", "0.6"):
        assert f"![open_room | rho={rho}: pursuer/greedy vs evader/straight, seed 0: " in replays


def test_exporting_an_unfinished_run_says_so(tmp_path, capsys):
    """``surveil export`` of a run still playing (or interrupted) wrote its stored rows and
    said only 'N matches of run R written', as if they were the run's results (the report
    says 'running: 79 of 240 matches stored')."""
    import sqlite3

    store, argv = _mini_tournament(tmp_path)
    assert main([*argv, "--no-report"]) == 0
    capsys.readouterr()
    assert main(["export", str(store), str(tmp_path / "all.csv")]) == 0
    assert capsys.readouterr().out.strip().endswith("all.csv")  # finished: nothing added
    with sqlite3.connect(store) as c:  # as a run interrupted after three of its matches
        c.execute("DELETE FROM results WHERE match_id = (SELECT match_id FROM run_matches "
                  "ORDER BY seq DESC LIMIT 1)")  # fmt: skip
        c.execute("UPDATE runs SET status = 'interrupted'")
    assert main(["export", str(store), str(tmp_path / "part.csv")]) == 0
    out = capsys.readouterr().out
    assert "3 matches of run " in out and out.strip().endswith(
        "; the run is interrupted with 3 of its 4 planned matches stored: these are not its "
        "results (rerun its tournament to finish it)"
    )


def test_a_report_can_skip_its_regret_table(tmp_path, capsys, monkeypatch):
    """A report's regret table solved referee games for over 9 minutes (no output under
    --no-progress) and could not be skipped: `surveil report --no-regret` (and `surveil
    tournament --no-regret`) write the report without a solve, saying so in its place."""
    import strategies.referee.regrets as regrets

    def no_solve(*args, **kwargs):
        raise AssertionError("--no-regret solved a referee game")

    monkeypatch.setattr(regrets, "solve", no_solve)
    store, argv = _mini_tournament(tmp_path)
    assert main([*argv, "--report", str(tmp_path / "r0"), "--no-replays", "--no-regret"]) == 0
    assert "without the regret table (--no-regret)" in capsys.readouterr().err
    assert main(["report", str(store), "--out", str(tmp_path / "r1"), "--no-regret"]) == 0
    err = capsys.readouterr().err
    assert err.startswith(f"writing the report to {tmp_path / 'r1'}: without the regret table")
    for rep in ("r0", "r1"):
        md = (tmp_path / rep / "report.md").read_text()
        regret = md.split("## Regret", 1)[1].split("\n## ", 1)[0]
        assert "Not computed: the report was written with --no-regret" in regret, regret
        assert (
            "<p>Not computed: the report was written with --no-regret"
            in (tmp_path / rep / "report.html").read_text()
        )


def test_a_long_regret_solve_is_announced_with_its_estimate(tmp_path, capsys, monkeypatch):
    """The report said only "can take minutes the first time": before a long solve it now
    gives the estimate `surveil referee` gives (unsolved_sizes, an upper bound). dt = 10 on
    the corridor: the pursuer's 10 s step has 1257 moves, up to about 5 min."""
    import strategies.referee.regrets as regrets

    def stop(*args, **kwargs):
        raise KeyboardInterrupt  # the solve itself is not under test (Ctrl-C: code 130)

    monkeypatch.setenv("SURVEIL_CACHE_DIR", str(tmp_path / "cache"))
    store, argv = _tournament(
        tmp_path,
        "slow",
        'maps = ["corridor"]\npursuers = ["pursuer/greedy"]\nevaders = ["evader/straight"]\n'
        'seeds = 1\nstart = "valid"\n[env]\nmax_cycles = 5\ndt = 10\nspawn_margin_steps = 0\n',
    )
    assert main([*argv, "--no-report"]) == 0
    capsys.readouterr()
    monkeypatch.setattr(regrets, "solve", stop)
    assert main(["report", str(store), "--no-replays"]) == 130
    err = capsys.readouterr().err
    line = next(x for x in err.splitlines() if x.startswith("the regret table: "))
    assert line.startswith("the regret table: solving 2 referee bound(s) not in the cache "
                           "(16 cells per L_min, ")  # fmt: skip
    assert "up to about 5 min, or " in line and "--no-regret skips" in line
    # rho 0.5: no pursuer retry (VACUOUS_RHO); the evader bound's may happen (solve's
    # evader_fallback), and is counted apart
    assert "if evader bounds certify next to nothing and are solved again finer" in line
    assert "pursuer bounds certify no state" not in line


def test_an_interrupted_report_leaves_the_previous_one_whole(tmp_path, monkeypatch):
    """A report killed in its regret solve left new pictures beside the older report.md
    (heatmaps.png replaced under it). Now nothing is written before everything is computed,
    pictures are named by their content and the pages replaced by a rename: the old report
    stays whole; a finished one removes the pictures of the one before, nothing else."""
    import analysis.tournament.report as report

    def snapshot(d):
        return {p.name: p.read_bytes() for p in d.iterdir()}

    def shown(d):
        return set(re.findall(r"\]\(([^)]+)\)", (d / "report.md").read_text()))

    rep = tmp_path / "rep"
    rep.mkdir()
    (rep / "notes.txt").write_text("the user's")
    (rep / "heatmaps.png").write_bytes(b"an older report's picture")
    (rep / "report.md").write_text("# old\n\n![held rate per pairing](heatmaps.png)\n")
    store, argv = _mini_tournament(tmp_path)
    assert main([*argv, "--no-report"]) == 0
    first = write_report(store, rep, replays=False, regret=False)
    assert not (rep / "heatmaps.png").exists() and (rep / "notes.txt").exists()
    assert set(snapshot(rep)) == shown(rep) | {"report.md", "report.html", "notes.txt"}
    assert {p.name for p in first.values()} == set(snapshot(rep)) - {"notes.txt"}
    # another run (other evaders: another heat map), interrupted in its regret solve
    other = tmp_path / "other.sqlite"
    spec = {"name": "other", "maps": ["open_room"], "pursuers": ["pursuer/greedy"],
            "evaders": ["evader/straight"], "seeds": 3, "env": {"max_cycles": 20}}  # fmt: skip
    run_tournament(spec_from_dict(spec), other, backend="serial", progress=False)
    before = snapshot(rep)

    def interrupted(a, say=None):
        raise KeyboardInterrupt

    monkeypatch.setattr(report, "_regret_section", interrupted)
    try:
        write_report(other, rep, replays=False)
    except KeyboardInterrupt:
        pass
    assert snapshot(rep) == before
    monkeypatch.undo()
    second = write_report(other, rep, replays=False, regret=False)
    assert set(snapshot(rep)) == shown(rep) | {"report.md", "report.html", "notes.txt"}
    assert second["markdown"].read_text() != before["report.md"].decode()
    assert {p.name for p in second.values()} == set(snapshot(rep)) - {"notes.txt"}


def test_a_run_with_error_matches_says_how_to_play_them_again(tmp_path, capsys):
    # A worker that died (the OOM killer, a Ray node lost) leaves its match stored as an
    # error, which a rerun keeps: the summary said "1 errors (see the report)" and
    # nothing of --retry-errors
    store, argv = _mini_tournament(tmp_path)
    assert main([*argv, "--no-report"]) == 0
    capsys.readouterr()
    with Store(store) as db:
        (run,) = db.runs()
        lost = db.rows(run["run_id"])[1]["match_id"]
        # what the process executor stores for the match of a worker that died
        died = {"match_id": lost, "status": "error", "error": "worker process died"}
        db.record(run["run_id"], died)
    assert main([*argv, "--no-report"]) == 0
    out = capsys.readouterr().out
    assert "4 reused, 0 played" in out
    assert (
        "1 of its matches are stored as errors, won by nobody (the first: worker process "
        "died); a rerun keeps them; to play them again: surveil tournament "
        f"{tmp_path / 'mini.toml'} --store {store} --backend serial --retry-errors"
    ) in out
    assert main([*argv, "--no-report", "--retry-errors"]) == 0
    out = capsys.readouterr().out
    assert "3 reused, 1 played" in out and "stored as errors" not in out
