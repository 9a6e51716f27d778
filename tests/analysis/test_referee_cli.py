"""``surveil referee``: the summary, a labelled start, certified starts, the picture, errors."""

from __future__ import annotations

import json

import pytest

from analysis.cli import main


@pytest.mark.filterwarnings("ignore::envs.errors.RhoAboveOneWarning")  # rho = 1.5 on purpose
def test_referee_summary_classify_sample_and_picture(tmp_path, capsys, monkeypatch):
    monkeypatch.setenv("SURVEIL_CACHE_DIR", str(tmp_path / "cache"))
    out = tmp_path / "ref.png"
    code = main(["referee", "open_room", "--config", '{"v_evader": 1.5}', "--cells-per-lmin",
                 "8", "--classify", "5", "8", "5", "5", "--sample", "2", "--kind", "evader",
                 "--out", str(out)])  # fmt: skip
    assert code == 0
    text = capsys.readouterr().out.splitlines()
    assert text[0].startswith("open_room: rho = 1.5, L in [2, 4], 8 cells per L_min")
    assert "evader wins 100.0%" in text[1]
    # a long step of a fast evader: the pursuer bound's 0 % is flagged, with the numbers
    assert text[4].startswith("  the pursuer wins above say nothing: pursuer bound at rho = 1.5")
    assert "the range band is used up" in text[4] and "= -3.56;" in text[4]
    assert text[5].startswith("start pursuer (5, 8), evader (5, 5): evader (surveillance breaks")
    starts = [json.loads(line) for line in text[6:8]]
    assert all(set(s) == {"pursuer", "evader"} for s in starts)
    assert out.stat().st_size > 10_000
    assert any((tmp_path / "cache" / "referee").iterdir())  # solved once, cached


def test_referee_summary_flags_a_pursuer_bound_that_certified_nothing(capsys, monkeypatch):
    monkeypatch.setenv("SURVEIL_CACHE_DIR", "/nonexistent")
    base = ["referee", "open_room", "--config", '{"v_evader": 0.2}', "--no-cache"]
    assert main([*base, "--cells-per-lmin", "12"]) == 0  # 88 % certified: no note
    text = capsys.readouterr().out
    assert "pursuer wins 8" in text and "say nothing" not in text
    assert main([*base, "--cells-per-lmin", "8"]) == 0  # too coarse: 0 %, and a note
    text = capsys.readouterr().out
    assert "pursuer wins 0.0%" in text and "say nothing" in text and "certified no state" in text


def test_referee_summary_names_the_pursuer_lattice_it_fell_back_to(capsys, monkeypatch):
    """At 16 cells per L_min the default pursuer lattice (spacing 0.5, step 1.5 s) certifies
    no state of the open room at rho = 0.3; the fallback one cell finer (0.375, 1.2 s)
    certifies most starts, and the summary says which lattice it is;
    --no-pursuer-fallback keeps the default's 0 %, with its note."""
    monkeypatch.setenv("SURVEIL_CACHE_DIR", "/nonexistent")
    base = ["referee", "open_room", "--config", '{"v_evader": 0.3}', "--no-cache"]
    assert main(base) == 0
    text = capsys.readouterr().out.splitlines()
    assert "pursuer wins 89.6%" in text[1]
    assert text[2].startswith("  pursuer bound: cell 0.125, lattice 0.375, step 1.2 s")
    assert text[3] == (
        "    (the default lattice 0.5, step 1.5 s, certified no state: this is the fallback, "
        "pursuer_coarse = 3)"
    )
    assert "say nothing" not in "\n".join(text)
    assert main([*base, "--no-pursuer-fallback"]) == 0
    text = capsys.readouterr().out
    assert "pursuer wins 0.0%" in text and "lattice 0.5, step 1.5 s" in text
    assert "say nothing" in text and "fallback" not in text


@pytest.mark.filterwarnings("ignore::envs.errors.VacuousBoundWarning")  # rho 0.5
def test_referee_summary_names_the_evader_lattice_it_fell_back_to(capsys, monkeypatch):
    """The corridor at its own rho = 0.5, 16 cells per L_min: the default evader lattice
    (spacing 0.5, step 2 s) certifies 0.45 % of its live states, the fallback at half the
    cells per spacing (0.25, 1 s) twice that, and the summary says which lattice it is
    (it said nothing: two_rooms' 0.05 % of the starts for coarse 2's 100 % looked like the
    game's answer); --no-evader-fallback keeps the default."""
    monkeypatch.setenv("SURVEIL_CACHE_DIR", "/nonexistent")
    base = ["referee", "corridor", "--no-cache"]
    assert main(base) == 0
    text = capsys.readouterr().out.splitlines()
    i = next(i for i, line in enumerate(text) if line.startswith("  evader bound:"))
    assert text[i].startswith("  evader bound: cell 0.125, lattice 0.25, step 1 s")
    assert text[i + 1] == (
        "    (the default lattice 0.5, step 2 s, certified next to nothing: this is the "
        "fallback, evader_coarse = 2)"
    )
    assert main([*base, "--no-evader-fallback"]) == 0
    text = capsys.readouterr().out
    assert "evader bound: cell 0.125, lattice 0.5, step 2 s" in text and "fallback" not in text


def test_referee_estimate_is_printed_beside_the_certificates(capsys, monkeypatch):
    monkeypatch.setenv("SURVEIL_CACHE_DIR", "/nonexistent")
    argv = ["referee", "open_room", "--config", '{"v_evader": 0.2}', "--cells-per-lmin", "8",
            "--no-cache", "--classify", "5", "8", "5", "5", "--estimate", "3", "4"]  # fmt: skip
    assert main(argv) == 0
    text = capsys.readouterr().out.splitlines()
    head = [i for i, line in enumerate(text) if line.startswith("estimate (the plain discrete")]
    assert len(head) == 1 and "at 3, 4 cells per L_min" in text[head[0]]
    assert "not a certificate" in text[head[0]]
    i = head[0]
    assert "contested" in text[i + 1] and "(the resolution error)" in text[i + 1]
    assert text[i + 2].startswith("  3 cells per L_min, 4 cells a step:")
    assert "(evader moves first)" in text[i + 2]
    assert text[i + 3].startswith("  4 cells per L_min, 5.33 cells a step:")
    assert text[i + 4].startswith("  start pursuer (5, 8), evader (5, 5): estimated ")
    assert text[i + 4].split()[-1] in ("pursuer", "evader", "contested")


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["referee", "nowhere"], "map: unknown map 'nowhere'"),
        (["referee", "open_room", "--config", "[1]"], "--config = '[1]': expected a JSON object"),
        # a TypeError traceback, and a value refused without naming --config (play named it)
        (["referee", "open_room", "--config", '{"bogus": 1}'],
         "--config: unknown env option(s) ['bogus']; options are l_min, "),
        (["referee", "open_room", "--config", '{"v_evader": 0}'],
         "error: --config: v_evader = 0: expected a finite number > 0"),
        (["referee", "open_room", "--cells-per-lmin", "-2"], "--cells-per-lmin = '-2'"),
        (["referee", "open_room", "--cells-per-lmin", "4", "--classify", "1", "1", "9", "9"],
         "distance 11.3137 outside [l_min, l_max] = [2, 4]"),
    ],
)  # fmt: skip
def test_referee_bad_input_is_one_line(argv, message, capsys, tmp_path, monkeypatch):
    monkeypatch.setenv("SURVEIL_CACHE_DIR", str(tmp_path))
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("surveil: error:") and message in err and "Traceback" not in err


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--classify", "1", "1", "9", "9"], "--classify: start pursuer=(1.0, 1.0)"),
        (["--classify", "nan", "1", "3", "1"], "--classify: pursuer = (nan, 1.0)"),
        (["--estimate", "6"], "--estimate: cpls = (6.0,): expected at least two"),
        (["--estimate", "6", "6"], "--estimate: cpls = (6.0, 6.0)"),
        # numpy's MemoryError traceback, after the solve
        (["--sample", "1000000000", "--kind", "unknown"], "--sample = 1000000000 starts would"),
        # dropped without a word after the solve: they choose the starts --sample prints
        (["--kind", "evader"], "--kind evader: it chooses the starts --sample prints; add"),
        (["--kind", "evader", "--seed", "3"], "--kind evader --seed 3: they choose the"),
    ],
)
def test_referee_bad_start_or_resolutions_fail_before_the_solve(extra, message, capsys, tmp_path,
                                                                 monkeypatch):  # fmt: skip
    # they were found only after the whole solve (minutes at a fine resolution)
    import strategies.referee

    def no_solve(*args, **kwargs):
        raise AssertionError("the solve started")

    monkeypatch.setenv("SURVEIL_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(strategies.referee, "referee_for", no_solve)
    assert main(["referee", "open_room", "--cells-per-lmin", "4", *extra]) == 2
    err = capsys.readouterr().err
    assert err.startswith("surveil: error:") and message in err and "Traceback" not in err


def test_a_solve_over_the_budget_names_this_command_s_flags(capsys, monkeypatch):
    """The budget message names --cells-per-lmin and $SURVEIL_MEMORY_BUDGET (it named
    solve()'s cells_per_lmin and memory_budget=, neither of which this command has); an
    --estimate over the budget is refused before the referee's solve, not after it."""
    monkeypatch.setenv("SURVEIL_CACHE_DIR", "/nonexistent")
    monkeypatch.setenv("SURVEIL_MEMORY_BUDGET", "200MB")
    base = ["referee", "open_room", "--config", '{"v_evader": 0.2}', "--no-cache"]
    assert main([*base, "--cells-per-lmin", "40"]) == 2
    err = capsys.readouterr().err
    assert "Use --cells-per-lmin <= " in err and "SURVEIL_MEMORY_BUDGET=6GB in the env" in err
    assert "cells_per_lmin" not in err and "memory_budget=" not in err
    assert main([*base, "--cells-per-lmin", "4", "--estimate", "30", "40"]) == 2
    out, err = capsys.readouterr()
    assert out == ""  # refused before the referee's solve printed its summary
    assert "Use the largest --estimate CPL (the others in proportion) <= " in err
    assert "cpls" not in err.split("):", 1)[1] and "memory_budget=" not in err


def test_a_solve_over_the_budget_is_refused_before_its_announcement(capsys, monkeypatch):
    """``--cells-per-lmin 100000`` announced "up to about 1.08e+19 h" and then refused the
    solve for its memory: the refusal comes first and alone."""
    monkeypatch.setenv("SURVEIL_CACHE_DIR", "/nonexistent")
    monkeypatch.setenv("SURVEIL_MEMORY_BUDGET", "200MB")
    # dt = 10: a long solve (announced at any budget), over 200 MB at 16 cells per L_min
    assert main(["referee", "corridor", "--config", '{"dt": 10}', "--no-cache"]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.startswith("surveil: error: solve(map 'corridor'"), err
    assert "Use --cells-per-lmin <= " in err and "solving the referee's bounds" not in err


@pytest.mark.parametrize(("cpl", "fit"), [("1e-09", "1"), ("0.9", "1")])
def test_a_resolution_with_no_lattice_start_is_refused_naming_one_that_has(
    cpl, fit, capsys, monkeypatch
):
    """``--cells-per-lmin 1e-9`` printed "0 lattice starts: pursuer wins 0.0%, ..." and
    exited 0 (a cell of 2e9 m on the corridor)."""
    monkeypatch.setenv("SURVEIL_CACHE_DIR", "/nonexistent")
    assert main(["referee", "corridor", "--cells-per-lmin", cpl, "--no-cache"]) == 2
    out, err = capsys.readouterr()
    assert out == ""
    assert f"--cells-per-lmin = {cpl}: the referee's lattices" in err
    assert f"the coarsest resolution with one is --cells-per-lmin {fit} (" in err
    assert main(["referee", "corridor", "--cells-per-lmin", fit, "--no-cache"]) == 0
    assert "16 lattice starts" in capsys.readouterr().out


@pytest.mark.parametrize("dt", ["1e4", "1e9"])
def test_a_step_the_env_refuses_is_refused_before_the_solve(dt, capsys, monkeypatch):
    """``--config '{"dt": 1e4}'`` hung (killed after 60 s): the budget check enumerates the
    moves of a step, about 4e8 lattice vectors at V_p tau = 1e4 m. The env refuses a step
    that crosses the map (physics.check_step); so does the referee now, before solving."""
    monkeypatch.setenv("SURVEIL_CACHE_DIR", "/nonexistent")
    argv = ["referee", "corridor", "--config", f'{{"dt": {dt}}}', "--no-cache"]
    assert main(argv) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.startswith(f"surveil: error: --config: dt = {float(dt)!r} with ")
    assert "i.e. dt <= 16.92" in err


def test_a_step_refused_at_the_map_s_defaults_does_not_blame_config(capsys, monkeypatch, tmp_path):
    """A map file 0.05 wide at the default dt = 0.1 and speed 1: the step crosses it. The
    message said '--config: dt = 0.1 ...' although no --config was given (or one that set
    only l_max); it names the map and says where dt is set."""
    monkeypatch.setenv("SURVEIL_CACHE_DIR", "/nonexistent")
    tiny = tmp_path / "tiny.json"
    tiny.write_text(json.dumps({"boundary": [[0, 0], [0.05, 0], [0.05, 0.03], [0, 0.03]]}))
    for extra in ([], ["--config", '{"l_max": 5}']):
        assert main(["referee", str(tiny), "--no-cache", *extra]) == 2
        out, err = capsys.readouterr()
        assert out == "" and err.startswith(f"surveil: error: map {str(tiny)!r} at its default ")
        assert "dt = 0.1 with " in err and "(set dt or the speeds with --config)" in err
    assert main(["referee", str(tiny), "--no-cache", "--config", '{"dt": 0.2}']) == 2
    assert capsys.readouterr().err.startswith("surveil: error: --config: dt = 0.2 with ")


def test_a_long_solve_is_announced_with_its_estimate_before_it_starts(capsys, monkeypatch):
    """``--config '{"dt": 10}'`` on the corridor solved for many minutes without a word:
    the pursuer's step is rounded up to 10 s (1257 moves, 29 at the default step)."""
    import strategies.referee as referee

    def stop(*args, **kwargs):
        raise KeyboardInterrupt  # the solve itself is not under test (Ctrl-C: code 130)

    monkeypatch.setattr(referee, "referee_for", stop)
    monkeypatch.setenv("SURVEIL_CACHE_DIR", "/nonexistent")
    assert main(["referee", "corridor", "--config", '{"dt": 10}', "--no-cache"]) == 130
    err = capsys.readouterr().err
    assert err.startswith("corridor: solving the referee's bounds (pursuer bound: ")
    assert "a step of 10 s, 1257 moves" in err and "up to about" in err
    assert "dt = 10" in err and "1.5 s for the pursuer bound otherwise" in err
    # a short solve says nothing first
    assert main(["referee", "corridor", "--cells-per-lmin", "4", "--no-cache"]) == 130
    assert capsys.readouterr().err == "surveil: interrupted\n"


def test_a_narrow_band_is_said_after_the_refusals_and_the_announcement(capsys, monkeypatch):
    """dt = 10 on the corridor: the band [2, 4] is narrower than two evader steps (10 m).
    The env's NarrowBandWarning came first, before the budget's refusal of the same run and
    before the long solve's announcement (66d3fbf, reverted); a refused run says its error
    alone, and a run that solves says the warning after its announcement, for the referee's
    game too."""
    import strategies.referee as referee

    def stop(*args, **kwargs):
        raise KeyboardInterrupt  # the solve itself is not under test

    monkeypatch.setenv("SURVEIL_CACHE_DIR", "/nonexistent")
    monkeypatch.setattr(referee, "referee_for", stop)
    argv = ["referee", "corridor", "--config", '{"dt": 10}', "--no-cache"]
    monkeypatch.setenv("SURVEIL_MEMORY_BUDGET", "200MB")
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("surveil: error: solve(") and len(err.splitlines()) == 1, err
    monkeypatch.delenv("SURVEIL_MEMORY_BUDGET")
    warning = "surveil: warning: corridor: l_max - l_min = 2 < 2 v_evader dt = 10 ("
    for extra, first in (([], "corridor: solving the referee's bounds"), (["--cells-per-lmin",
                         "4"], warning)):  # fmt: skip
        assert main([*argv, *extra]) == 130
        lines = capsys.readouterr().err.splitlines()
        assert lines[0].startswith(first) and lines[-1] == "surveil: interrupted", lines
        (said,) = [line for line in lines if line.startswith("surveil: warning:")]
        assert said.startswith(warning) and "dt <= 2)" in said
        assert said.endswith("the same holds in the referee's game, whose steps are whole env "
                             "steps (its pursuer bound can certify no start with the evader in "
                             "open space)")  # fmt: skip


def test_a_long_solve_s_announcement_counts_the_pursuer_bound_s_fallback(capsys, monkeypatch):
    """At rho < VACUOUS_RHO a pursuer bound certifying nothing is solved once more one cell
    finer (afac520): the announcement gave the first solve's time only (here 5 min of up to
    23), and says nothing of a retry where none can happen (rho 0.5, or the flag off)."""
    import strategies.referee as referee
    from envs.surveillance.config import EnvConfig
    from strategies.referee.referee import fallback_size, unsolved_sizes
    from strategies.referee.spec import GameSpec

    def stop(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(referee, "referee_for", stop)
    monkeypatch.setenv("SURVEIL_CACHE_DIR", "/nonexistent")
    slow = ["referee", "corridor", "--config", '{"dt": 10, "v_evader": 0.1}', "--no-cache"]
    assert main(slow) == 130
    err = capsys.readouterr().err
    assert "if the default pursuer lattice certifies no state and the solve retries it" in err
    assert "(pursuer bound's fallback: " in err and "a step of 10 s, 2233 moves" in err
    assert main([*slow, "--no-pursuer-fallback"]) == 130
    err = capsys.readouterr().err
    assert "up to about" in err and "fallback" not in err
    fast = ["referee", "corridor", "--config", '{"dt": 10}', "--no-cache"]
    assert main(fast) == 130
    err = capsys.readouterr().err  # rho 0.5: no pursuer retry; the evader bound's may happen
    assert "pursuer bound's fallback" not in err
    assert "if the default evader lattice certifies next to nothing and the solve retries" in err
    assert main([*fast, "--no-evader-fallback"]) == 130
    assert "fallback" not in capsys.readouterr().err
    # the retry is the lattice solve() falls back to: pursuer_coarse one less than the default
    cfg = EnvConfig(map="corridor", v_evader=0.1)
    spec = GameSpec.from_config(cfg)
    (default,) = (s for s in unsolved_sizes(spec, 16, cache=False) if s.kind == "pursuer")
    retry = fallback_size(spec, 16, cache=False)
    assert retry.kind == "pursuer" and retry.tau < default.tau and retry.points > default.points
    assert fallback_size(spec, 16, cache=False, pursuer_coarse=4) is None  # asked for: kept
    assert fallback_size(GameSpec.from_config(EnvConfig(map="corridor")), 16) is None


@pytest.mark.filterwarnings("ignore::envs.errors.VacuousBoundWarning")  # rho 0.3
def test_a_cached_solve_announces_only_the_retry_that_can_happen(tmp_path, capsys, monkeypatch):
    """The README's `surveil referee open_room --config '{"v_evader": 0.2}' ...` run a
    second time (both bounds cached, the default pursuer lattice certifying 90 %) announced
    "solving the referee's bounds (): up to about 0 s, or 70 s if the default pursuer
    lattice certifies no state": a retry solve() does not make when the cached default
    certifies. Where the cached default certifies nothing the retry is announced alone."""
    import strategies.referee as referee
    from envs.surveillance.config import EnvConfig
    from strategies.referee.referee import fallback_size, solve
    from strategies.referee.spec import GameSpec

    def stop(*args, **kwargs):
        raise KeyboardInterrupt

    cache = tmp_path / "cache"
    monkeypatch.setenv("SURVEIL_CACHE_DIR", str(cache))
    monkeypatch.setattr(referee, "referee_for", stop)  # the CLI stops after announcing
    for rho, certifies in ((0.2, True), (0.3, False)):  # at 12 cells per L_min: 1.6 s, 2 s
        spec = GameSpec.from_config(EnvConfig(map="open_room", v_evader=rho))
        assert fallback_size(spec, 12, cache_dir=cache) is not None  # unsolved: may retry
        ref = solve(spec, 12, dt=0.1, cache_dir=cache, pursuer_fallback=False)  # as the CLI
        assert bool(ref.pursuer.win.any()) is certifies
        retry = fallback_size(spec, 12, cache_dir=cache, dt=0.1)
        assert (retry is None) is certifies
        cmd = ["referee", "open_room", "--config", f'{{"v_evader": {rho}}}']
        assert main([*cmd, "--cells-per-lmin", "12"]) == 130
        err = capsys.readouterr().err
        if certifies:
            assert err == "surveil: interrupted\n"
        else:
            assert err.startswith(
                "open_room: the default pursuer lattice certifies no state (cached): solving "
                "it once more one cell finer (pursuer bound's fallback: "
            ), err
            assert "()" not in err and "up to about 0 s" not in err


@pytest.mark.parametrize("flag", [["--cells-per-lmin", "1e100"], ["--estimate", "1e300", "2e300"]])
def test_an_absurd_resolution_is_one_line_naming_the_flag(flag, capsys):
    """--cells-per-lmin 1e100 was an OverflowError traceback from the memory estimate (1e300
    a ZeroDivisionError); --estimate 1e300 2e300 too."""
    assert main(["referee", "corner", *flag]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"surveil: error: {flag[0]}") and "Traceback" not in err, err
    assert "expected at most 1e+12" in err and len(err.strip().splitlines()) == 1


def test_a_lattice_that_misses_a_narrow_passage_names_a_resolution_that_does_not(
    tmp_path, capsys, monkeypatch
):
    """A ring corridor 0.5 wide round a 9 x 9 block (agents of radius 0.1): no point of the
    lattice at 8 cells per L_min lies in it, and the refusal was the lattice's own, naming
    no flag: "no lattice point of spacing 0.5 lies 0.1 from the walls of map 'ring'; refine
    the resolution" (16 and 12 hold none either; 9.51 does). A map where no agent fits at
    all is said so up front, as the env says it (refining could not help there)."""
    monkeypatch.setenv("SURVEIL_CACHE_DIR", str(tmp_path))
    ring = tmp_path / "ring.json"
    block = [[0.5, 0.5], [9.5, 0.5], [9.5, 9.5], [0.5, 9.5]]
    ring.write_text(json.dumps({"boundary": [[0, 0], [10, 0], [10, 10], [0, 10]],
                                "obstacles": [block]}))  # fmt: skip
    assert main(["referee", str(ring), "--cells-per-lmin", "8"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("surveil: error: --cells-per-lmin = 8: the referee's lattices hold ")
    assert "no start with the players in range [2, 4], body_radius = 0.1 from the walls" in err
    assert "the next finer resolution with one is --cells-per-lmin 9.51 (" in err
    assert main(["referee", str(ring), "--cells-per-lmin", "9.51"]) == 0
    assert "lattice starts" in capsys.readouterr().out
    slit = tmp_path / "slit.json"
    slit.write_text(json.dumps({"boundary": [[0, 0], [100, 0], [100, 0.15], [0, 0.15]]}))
    assert main(["referee", str(slit), "--cells-per-lmin", "8"]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.startswith("surveil: error: referee: map 'slit' cannot hold an ")
    assert "no point of its free space is body_radius = 0.1 from the walls" in err
