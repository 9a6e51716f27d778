"""Every user error of ``surveil`` is one line, exit code 2, no traceback, found before the run.

Each case goes through ``analysis.cli.main`` as a user's command would. "Before the run"
is checked by the outcome line: ``play`` prints it only after an episode was played.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest
from PIL import Image

from analysis.cli import main

ROOT = Path(__file__).resolve().parents[2]

FAST = ["--pursuer", "pursuer/greedy", "--evader", "evader/straight", "--max-cycles", "5"]


def assert_fails(capsys, argv: list[str], *needles: str) -> str:
    """Run ``surveil ARGV``: exit code 2, one ``surveil: error:`` line naming each needle."""
    assert main(argv) == 2
    out, err = capsys.readouterr()
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("surveil: error: "), err
    assert "Traceback" not in err
    for needle in needles:
        assert needle in lines[0], (needle, lines[0])
    assert "kept surveillance" not in out and "escaped" not in out  # no episode was played
    return lines[0]


@pytest.fixture
def map_file(tmp_path) -> Path:
    from envs.maps import builtin_map, save_map

    path = tmp_path / "room.json"
    save_map(builtin_map("open_room"), path)
    return path


# ---------------------------------------------------------------------- map files
def test_missing_map_file(capsys, tmp_path):
    missing = str(tmp_path / "nowhere.json")
    assert_fails(
        capsys, ["play", "--map", missing, "--no-gif"], "--map", missing, "no such map file"
    )
    assert_fails(capsys, ["analyze", missing], "map", missing, "no such map file")


def test_a_directory_given_as_a_map(capsys, tmp_path):
    folder = tmp_path / "maps.json"
    folder.mkdir()
    assert_fails(capsys, ["play", "--map", str(folder), "--no-gif"], "--map", "is a directory")
    assert_fails(capsys, ["analyze", str(tmp_path)], "is a directory")


@pytest.mark.parametrize(
    ("content", "needle"),
    [
        (b"", "not valid JSON"),
        (b'{"boundary": [[0, 0], [1, 0]', "not valid JSON"),
        (b"\xff\xfe\x00\x01", "not UTF-8"),
        (b'{"boundary": [[0, 0], [10, 0], [10, "ten"], [0, 10]]}', "vertex 2"),
        (b'{"boundary": [[0, 0], [10, 0], [0, 0]]}', "boundary"),
        (b"[1, 2, 3]", "room.json"),
        (b'{"boundary": ' + b"[" * 5000 + b"]" * 5000 + b"}", "nested too deeply"),
        (b'{"boundary": [[0, 0], [10, 0], [10, NaN], [0, 10]]}', "got nan at index (2, 1)"),
    ],
    ids=[
        "empty",
        "truncated",
        "binary",
        "string-coordinate",
        "degenerate",
        "not-an-object",
        "deep",  # a RecursionError traceback before
        "nan",
    ],
)
def test_a_broken_map_file_of_each_kind(capsys, tmp_path, content, needle):
    path = tmp_path / "room.json"
    path.write_bytes(content)
    assert_fails(capsys, ["play", "--map", str(path), "--no-gif"], "--map", str(path), needle)


def test_a_wkt_map_with_a_nan_is_refused_on_one_line(capsys, tmp_path):
    # the message held the coordinates' numpy repr, which spans lines
    path = tmp_path / "room.wkt"
    path.write_text("POLYGON ((0 0, 12 0, 12 nan, 0 8, 0 0))")
    line = assert_fails(capsys, ["play", "--map", str(path), "--no-gif"], "got nan at index (2, 1)")
    assert "array([[ 0.,  0.], [12.,  0.], [12., nan]" in line


@pytest.mark.parametrize(
    ("content", "needle"),
    [(b'x = "caf\xe9"\n', "not valid TOML"), (b"x = " + b"[" * 5000 + b"]" * 5000, "too deeply")],
    ids=["latin-1", "deep"],  # UnicodeDecodeError / RecursionError tracebacks before
)
def test_a_broken_training_config_is_refused_on_one_line(capsys, tmp_path, content, needle):
    path = tmp_path / "c.toml"
    path.write_bytes(content)
    out = tmp_path / "out"
    assert_fails(capsys, ["train", str(path), "--output-dir", str(out)], "c.toml", needle)
    assert_fails(capsys, ["tournament", str(path)], "c.toml", needle)


# ---------------------------------------------------------------------- outputs
def test_an_output_under_a_file_is_refused_before_the_episode(capsys, tmp_path):
    blocker = tmp_path / "file.txt"
    blocker.write_text("x")
    out = str(blocker / "sub" / "replay.gif")
    assert_fails(capsys, ["play", *FAST, "--out", out], "--out", "is a file, not a directory")
    assert_fails(capsys, ["figure", "tractrix", "--out", out.replace(".gif", ".png")], "--out")
    assert_fails(capsys, ["maps", "--plot", str(blocker)], "--plot", "is a file")
    # an empty name listed the maps, drew nothing and exited 0
    assert_fails(capsys, ["maps", "--plot", ""], "--plot")


def test_an_output_with_a_wrong_suffix(capsys, tmp_path):
    assert_fails(capsys, ["play", *FAST, "--out", str(tmp_path / "r.mp4")], "--out", ".gif or .png")


def test_a_new_directory_without_a_slash_is_refused_with_the_remedy(capsys, tmp_path):
    """README: `--out DIR` writes DIR/play.gif. A DIR that does not exist yet has no suffix
    and was refused as 'expected a file ending in .gif or .png', naming no directory."""
    new_dir = str(tmp_path / "replays")
    err = assert_fails(capsys, ["play", *FAST, "--out", new_dir], "--out", ".gif or .png")
    assert f"or a directory: an existing one, or '{new_dir}/' to create it" in err
    assert not (tmp_path / "replays").exists()
    assert main(["play", *FAST, "--out", new_dir + "/"]) == 0  # the remedy works
    assert (tmp_path / "replays" / "play.gif").exists()
    capsys.readouterr()
    err = assert_fails(capsys, ["play", *FAST, "--out", "x.mp4"], "--out")
    assert err.endswith("--out = 'x.mp4': expected a file ending in .gif or .png")  # as README


def test_a_directory_as_the_output_holds_the_default_name(capsys, tmp_path):
    assert main(["play", "--map", "open_room", *FAST, "--out", str(tmp_path)]) == 0
    with Image.open(tmp_path / "play.gif") as gif:
        assert gif.n_frames == 6
    assert main(["analyze", "corridor", "--out", str(tmp_path)]) == 0
    assert (tmp_path / "decomposition_corridor_L2.png").stat().st_size > 1000
    assert not (tmp_path.parent / f"{tmp_path.name}.png").exists()  # not DIR.png
    new_dir = str(tmp_path / "figs") + "/"  # a trailing slash names a directory to create
    assert main(["figure", "tractrix", "--out", new_dir]) == 0
    assert (tmp_path / "figs" / "figure_tractrix.png").exists()
    assert not list(tmp_path.glob(".*.tmp*"))  # no temporary files left behind


# ---------------------------------------------------------------------- JSON options
@pytest.mark.parametrize(
    ("text", "needles"),
    [
        ('{"foo": 1}', ["--config", "unknown env option(s) ['foo']", "l_min"]),
        ("[1, 2]", ["--config = '[1, 2]'", "expected a JSON object", "got a JSON array"]),
        ('{"v_evader": 0.8', ["--config", "not valid JSON", "column 17"]),
        ("", ["--config", "not valid JSON"]),
        ('{"l_min": -1}', ["--config: l_min = -1: expected a finite number > 0"]),
        ('{"v_evader": "fast"}', ["--config: v_evader = 'fast'", "got str"]),
        ('{"n_rays": true}', ["--config: n_rays = True", "got bool"]),
        ("[" * 3000 + "]" * 3000, ["--config", "nested too deeply"]),  # a traceback before
    ],
)
def test_bad_config(capsys, text, needles):
    assert_fails(capsys, ["play", *FAST, "--no-gif", "--config", text], *needles)


@pytest.mark.parametrize(
    ("argv", "needles"),
    [
        (
            ["--pursuer", "pursuer/greedy", "--pursuer-params", '{"gain": null}'],
            ["--pursuer-params", "policy 'pursuer/greedy': gain = None"],
        ),
        (
            ["--pursuer", "pursuer/decomposition", "--pursuer-params", '{"n_bins": true}'],
            ["--pursuer-params", "n_bins = True: expected an integer"],
        ),
        (
            ["--evader", "evader/shooting", "--evader-params", '{"shoot": "no"}'],
            ["--evader-params", "shoot = 'no': expected true or false"],
        ),
        (
            ["--pursuer", "pursuer/decomposition", "--pursuer-params", '{"rays": 1e9}'],
            ["--pursuer-params", "rays = 1000000000.0: expected an integer"],
        ),
        (
            ["--evader", "evader/toward_away", "--evader-params", '{"no_such": 1}'],
            ["--evader-params", "no parameter(s) ['no_such']"],
        ),
        (["--evader", "pursuer/greedy"], ["--evader = 'pursuer/greedy'", "'evader/KIND'"]),
        (["--pursuer", "pursuer/nobody"], ["--pursuer", "unknown policy 'pursuer/nobody'"]),
        (["--pursuer-params", "{gain: 1}"], ["--pursuer-params", "not valid JSON"]),
    ],
)
def test_bad_policies_and_parameters(capsys, argv, needles):
    assert_fails(capsys, ["play", "--max-cycles", "5", "--no-gif", *argv], *needles)


def test_unknown_figure_parameter(capsys):
    assert_fails(
        capsys,
        ["figure", "shooting", "--params", '{"bogus": 1}'],
        "--params",
        "no parameter(s) ['bogus']",
        "rho (default 0.5)",
    )
    assert_fails(capsys, ["figure", "shooting", "--params", '{"rho": "half"}'], "--params", "rho")


# ---------------------------------------------------------------------- numbers
@pytest.mark.parametrize(
    ("argv", "needles"),
    [
        (["play", "--seed", "-1"], ["--seed = '-1': expected an integer >= 0"]),
        (["play", "--seed", "1.5"], ["--seed = '1.5'"]),
        (["play", "--fps", "0"], ["--fps = '0': expected an integer in [1, 100]"]),
        (["play", "--max-cycles", "0"], ["--max-cycles = '0'"]),
        (["analyze", "corridor", "--length", "-2"], ["--length = '-2'", "> 0"]),
        (["analyze", "corridor", "--length", "nan"], ["--length = 'nan'"]),
        (["play", "--no-such-flag"], ["unrecognized arguments: --no-such-flag"]),
        (["no-such-command"], ["invalid choice: 'no-such-command'"]),
    ],
)
def test_bad_numbers_and_flags_name_the_flag(capsys, argv, needles):
    assert_fails(capsys, argv, *needles)


@pytest.mark.parametrize(
    ("argv", "command"),
    [
        (["policies", "--role", "evader", "extra"], "policies"),
        (["maps", "x", "y"], "maps"),
        (["play", "--no-gif", "--no-such-flag"], "play"),
        (["report", "x.db", "--nope"], "report"),
    ],
)
def test_an_argument_no_command_takes_points_at_its_commands_help(capsys, argv, command):
    """It pointed at 'surveil --help', whose usage lists the commands, not their flags."""
    line = assert_fails(capsys, argv, "unrecognized arguments: ")
    assert line.endswith(f"(see 'surveil {command} --help')"), line


def test_analyze_needs_a_length_for_a_map_file(capsys, map_file):
    assert_fails(capsys, ["analyze", str(map_file)], "--length is required", str(map_file))


def test_analyze_refuses_a_rod_that_fits_nowhere(capsys):
    assert_fails(
        capsys, ["analyze", "corridor", "--length", "1e9"], "--length = 1e+09", "fits nowhere"
    )


def test_rho_above_one_is_played_with_one_warning_line(capsys):
    argv = ["play", *FAST, "--no-gif", "--config", json.dumps({"v_evader": 1.5})]
    assert main(argv) == 0
    out, err = capsys.readouterr()
    assert "escaped" in out or "kept surveillance" in out
    assert err.strip().splitlines() == [
        "surveil: warning: v_evader = 1.5 > v_pursuer = 1.0 (rho = 1.5 > 1): the evader can "
        "always escape by running at the pursuer (Sec. 5 of the paper); legal, but no pursuer "
        "can win"
    ]


@pytest.mark.parametrize(
    "config", [{"dt": 3}, {"v_evader": 1.5}], ids=["narrow_band", "rho_above_one"]
)
def test_a_refused_play_says_its_error_without_the_config_s_warning(capsys, config):
    """A legal config no pursuer can be sure to win (a band narrower than two evader steps,
    rho > 1) with an unknown --pursuer: the config's warning came first, then the error;
    the error comes alone, and the warning once when the episode is played."""
    argv = ["play", *FAST, "--no-gif", "--config", json.dumps(config)]
    assert_fails(capsys, [*argv, "--pursuer", "nope"], "--pursuer = 'nope'")
    assert main(argv) == 0
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("surveil: warning: "), err
    assert ("l_max - l_min = 2 < 2 v_evader dt = 3 (" in err[0]) is ("dt" in config)


def test_a_models_warning_names_it_as_the_user_did(capsys):
    """It named the zip's absolute path: 'pursuer/sb3:/.../training/zoo/models/.../model.zip:
    this model plays a game it was not trained at'."""
    argv = ["play", "--map", "corridor", "--pursuer", "zoo:dagger_pursuer_generalist",
            "--evader", "evader/straight", "--max-cycles", "2", "--no-gif",
            "--config", json.dumps({"v_evader": 0.8})]  # fmt: skip
    assert main(argv) == 0
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(
        "surveil: warning: zoo:dagger_pursuer_generalist: this model plays a game it was not "
        "trained at: rho = v_evader / v_pursuer: 0.5 in training"
    ), err


def test_only_user_errors_lose_their_traceback():
    from analysis.arguments import user_error
    from envs.errors import InvalidObservationError
    from strategies.runner import PolicyFailure

    assert user_error(ZeroDivisionError("bug")) is None
    assert user_error(ValueError("a numpy bug")) is None  # not a project error
    assert user_error(FileNotFoundError(2, "No such file or directory", "x.toml")) == (
        "x.toml: No such file or directory"
    )
    failure = PolicyFailure("pursuer", "pursuer/sb3:m.zip", 3, "InvalidObservationError: ...")
    failure.__cause__ = InvalidObservationError("observation: expected shape (13,)")
    assert user_error(failure) == str(failure)
    failure.__cause__ = KeyError("a bug inside a policy")
    assert user_error(failure) is None


def test_ctrl_c_while_the_parser_imports_is_a_clean_exit(monkeypatch, capsys) -> None:
    # building the parser imports training (torch, SB3) for seconds: a Ctrl-C there was a
    # KeyboardInterrupt traceback (`timeout -s INT 5 surveil tournament ...`)
    import analysis.cli

    def interrupted():
        raise KeyboardInterrupt

    monkeypatch.setattr(analysis.cli, "build_parser", interrupted)
    assert main(["maps"]) == 130
    assert capsys.readouterr().err == "surveil: interrupted\n"


def test_a_ctrl_c_cpython_discards_while_the_parser_imports_still_stops_the_run() -> None:
    """A Ctrl-C whose KeyboardInterrupt is raised inside a weakref callback (as importlib's
    module-lock callbacks run during the parser's imports) is discarded by CPython
    ("Exception ignored in ...") and the command ran on: 2 of 20 Ctrl-Cs 1.5-4 s after
    `surveil tournament` started, under load. Reproduced here without the timing: the
    SIGINT is delivered inside such a callback while the parser is built."""
    script = """if True:
        import gc, signal, sys, weakref
        # as a terminal's foreground job: a test run started in the background ignores
        # SIGINT, and so would this child
        signal.signal(signal.SIGINT, signal.default_int_handler)
        import analysis.cli

        real = analysis.cli.build_parser

        class Thing:
            pass

        def build_parser():
            thing = Thing()
            keep = weakref.ref(thing, lambda ref: signal.raise_signal(signal.SIGINT))
            del thing
            gc.collect()
            return real()

        analysis.cli.build_parser = build_parser
        sys.exit(analysis.cli.main(["maps"]))
    """
    run = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, cwd=ROOT, timeout=120
    )
    assert "Exception ignored" in run.stderr  # the KeyboardInterrupt CPython discarded
    assert run.returncode == 130, run.stdout
    assert run.stderr.endswith("surveil: interrupted\n")
    assert "corridor" not in run.stdout  # the maps were not listed


def test_a_model_without_its_provenance_is_said_so_as_it_plays(tmp_path, capsys, monkeypatch):
    """A pursuer model copied without its provenance.json played the evader without a word
    ('pursuer/decomposition vs bare/p.zip: pursuer kept surveillance'): nothing can check
    its role or observation."""
    import shutil

    from strategies.policies.model_files import zoo_dir

    shutil.copy(zoo_dir() / "dagger_pursuer_corridor" / "model.zip", tmp_path / "p.zip")
    monkeypatch.chdir(tmp_path)
    assert main(["play", "--evader", "p.zip", "--no-gif", "--max-cycles", "3"]) == 0
    err = capsys.readouterr().err
    assert err.startswith(
        f"surveil: warning: --evader: model = 'p.zip': no provenance.json beside "
        f"{tmp_path / 'p.zip'}: the role and the observation this model was trained for "
        "are unknown and unchecked"
    ), err


@pytest.mark.parametrize(
    ("params", "needle"),
    [
        # the first two were SB3Policy's TypeError tracebacks; "no" played as true
        ('{"foo": 1}', "has no parameter(s) ['foo']; a model's parameters are ['algo', "),
        ('{"role": "pursuer"}', "has no parameter(s) ['role']"),
        ('{"deterministic": "no"}', "deterministic = 'no': expected true or false"),
        ('{"deterministic": 0}', "deterministic = 0: expected true or false"),
    ],
)
def test_a_models_bad_parameters_are_one_line(capsys, params, needle) -> None:
    argv = ["play", "--evader", "zoo:ppo_evader_vs_greedy_open_room", "--evader-params", params,
            "--no-gif", "--max-cycles", "2"]  # fmt: skip
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("surveil: error: --evader-params: ") and needle in err, err
    assert len(err.splitlines()) == 1


EVALUATE = ["evaluate", "--maps", "corridor", "--pursuers", "pursuer/greedy", "--evaders",
            "evader/straight", "--seeds", "1", "--max-cycles", "5", "--no-progress"]  # fmt: skip


@pytest.mark.parametrize(
    ("extra", "needles"),
    [
        # the first two were json's and a TypeError's tracebacks
        (["--config", "{"], ["--config = '{': not valid JSON"]),
        (["--config", "[1]"], ["--config = '[1]': expected a JSON object"]),
        # these ran (0: serially), or played every match before refusing the picture
        (["--workers", "0"], ["--workers = '0': expected an integer >= 1"]),
        (["--plot", "table.txt"], ["--plot = 'table.txt': expected a file ending in .png"]),
        (["--plot", "notes/table.png"], ["--plot", "'notes' is a file, not a directory"]),
    ],
)
def test_evaluate_bad_flags_fail_before_any_match(capsys, tmp_path, monkeypatch, extra, needles):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "notes").write_text("a file")
    line = assert_fails(capsys, [*EVALUATE, "--results", "e.sqlite", *extra], *needles)
    assert not (tmp_path / "e.sqlite").exists(), line


def test_a_ctrl_c_python_wraps_is_an_interrupt_not_a_traceback(capsys, monkeypatch):
    """A Ctrl-C while a class with a cached_property was created (a policy module imported
    as a tournament planned, 2 s into ``surveil tournament``) reached the CLI as Python
    3.11's "RuntimeError: Error calling __set_name__ on 'cached_property' instance ...":
    a traceback and exit 1."""
    from analysis import cli

    class Stopping:
        def __set_name__(self, owner, name):
            raise KeyboardInterrupt  # where the signal landed

    def maps(args):
        try:
            type("Plan", (), {"pieces": Stopping()})
        except KeyboardInterrupt as exc:  # Python >= 3.12 does not wrap it: as 3.11 did
            raise RuntimeError("Error calling __set_name__ on 'Stopping' instance") from exc

    monkeypatch.setattr(cli, "_cmd_maps", maps)
    assert main(["maps"]) == 130
    assert capsys.readouterr().err == "surveil: interrupted\n"


def test_workers_far_above_the_cpus_are_said_so_and_played(capsys, tmp_path, monkeypatch):
    """``--workers 1000`` on two cores started the processes without a word: a warning line
    names the number and os.cpu_count(), and the matches are played as asked."""
    import os

    from analysis.tournament.executors import OVERSUBSCRIBED, available_cpus

    monkeypatch.chdir(tmp_path)
    many = OVERSUBSCRIBED * available_cpus() + 1
    assert main([*EVALUATE, "--results", "e.sqlite", "--workers", str(many)]) == 0
    out, err = capsys.readouterr()
    assert err.startswith(f"surveil: warning: workers = {many}: far above the "), err
    assert f"(os.cpu_count() = {os.cpu_count()})" in err and "played as asked" in err
    assert "1 of 1 matches stored" in out + err
    # at the limit: no word
    limit = OVERSUBSCRIBED * available_cpus()
    assert main([*EVALUATE, "--results", "f.sqlite", "--workers", str(limit)]) == 0
    assert "far above" not in capsys.readouterr().err


@pytest.mark.parametrize("workers", ["0", "-1", "two"])
def test_tournament_workers_are_checked_before_the_store(capsys, tmp_path, workers):
    # --workers 0 with --backend ray never scheduled a match: each batch was stored as an
    # error ("overran the time limit") after 65 s; with the process backend the run was
    # refused as "workers = 0" after the store had it marked 'running'
    store = tmp_path / "t.sqlite"
    argv = ["tournament", "quick", "--store", str(store), "--workers", workers]
    assert_fails(capsys, [*argv, "--backend", "ray"], f"--workers = '{workers}': expected an")
    assert_fails(capsys, argv, f"--workers = '{workers}': expected an integer >= 1")
    assert not store.exists()


def test_play_refuses_a_model_that_is_not_there_or_of_the_other_role(capsys, tmp_path):
    (tmp_path / "notes.zip").write_text("not a zip")
    cases = [
        (["--pursuer", "zoo:nope"], "--pursuer: model = 'zoo:nope': no zoo model 'nope'; known: ["),
        (["--evader", str(tmp_path / "notes.zip")], "not a stable-baselines3 model zip"),
        (["--evader", str(tmp_path / "gone.zip")], "--evader: model = ", "no such file"),
        # named as the user did, not by the zip's absolute path
        (
            ["--pursuer", "zoo:ppo_evader_vs_greedy_open_room"],
            "--pursuer: model = 'zoo:ppo_evader_vs_greedy_open_room': this model was trained as "
            "the evader (its provenance.json says role = 'evader'); it cannot play the pursuer",
        ),
    ]
    for argv, *needles in cases:
        assert_fails(capsys, ["play", *FAST, *argv, "--no-gif"], *needles)


def test_figures_into_an_existing_file_is_refused_before_drawing(capsys, tmp_path):
    blocker = tmp_path / "somefile"
    blocker.write_text("x")
    assert_fails(capsys, ["figures", "--out", str(blocker), "--only", "fig10"], "--out",
                 "is a file, expected a directory")  # fmt: skip


@pytest.mark.parametrize("empty", ["", "  "])
def test_figures_into_an_empty_directory_name_is_refused(capsys, tmp_path, monkeypatch, empty):
    """--out '' was the working directory (Path('') is '.'): the figures landed there."""
    monkeypatch.chdir(tmp_path)
    assert_fails(capsys, ["figures", "--out", empty, "--only", "fig10"], "--out",
                 "expected a directory name")  # fmt: skip
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("t_max", [0, -2])
def test_a_tractrix_over_no_time_is_refused(capsys, tmp_path, t_max):
    out = str(tmp_path / "t.png")
    params = json.dumps({"t_max": t_max})
    assert_fails(capsys, ["figure", "tractrix", "--params", params, "--out", out], "--params",
                 f"t_max = {t_max}: expected a finite number > 0")  # fmt: skip
    assert not (tmp_path / "t.png").exists()


def test_the_step_budget_error_says_how_to_pass_a_step_here(capsys, tmp_path):
    """The theory says "pass step="; surveil figure takes it as a --params key."""
    out = str(tmp_path / "g.png")
    line = assert_fails(capsys, ["figure", "greedy", "--params", '{"x_max": 3e4}', "--out", out],
                        "--params", 'add "step": H (the RK4 step) to --params')  # fmt: skip
    assert "step=" not in line
    params = '{"x_max": 3e4, "step": 1.0}'
    assert main(["figure", "greedy", "--params", params, "--out", out]) == 0
    assert (tmp_path / "g.png").stat().st_size > 1000


def test_a_decomposition_over_the_budget_names_the_variable_not_the_keyword(
    tmp_path, capsys, monkeypatch
):
    # a command line has no memory_budget= (the message said decompose(..., memory_budget=))
    monkeypatch.setenv("SURVEIL_MEMORY_BUDGET", "100MB")
    assert main(["analyze", "corner", "--out", str(tmp_path / "x.png")]) == 2
    err = capsys.readouterr().err
    assert "SURVEIL_MEMORY_BUDGET=1GB in the environment" in err, err
    assert "memory_budget=" not in err and "0GB" not in err


@pytest.mark.parametrize(
    ("argv", "needle"),
    [
        (["evaluate", "--seeds", "0"], "--seeds = '0': expected an integer >= 1"),
        (["evaluate", "--seeds", "2.5"], "--seeds = '2.5': expected an integer >= 1"),
        (["evaluate", "--max-cycles", "0"], "--max-cycles = '0': expected an integer >= 1"),
    ],
)
def test_evaluate_counts_are_checked_as_its_flags(capsys, argv, needle):
    """``surveil evaluate --seeds 0`` said "surveil evaluate: seeds = 0" (the spec's field,
    not the flag) and ``--seeds 2.5`` was argparse's "invalid int value"."""
    assert_fails(capsys, argv, needle)


@pytest.mark.parametrize(
    ("argv", "prefix"),
    [
        (["--maps", "corridor", "nope"], "--maps #2: map = 'nope': neither a built-in map"),
        (["--pursuers", "nope"], "--pursuers #1: policy = 'nope': a pursuer entry"),
        (["--evaders", "pursuer/greedy"], "--evaders #1: policy = 'pursuer/greedy': an evader"),
        (["--config", '{"l_min": -1}'], "--config: l_min = -1: expected a finite number > 0"),
        (["--config", '{"rho": 2}'], "--config: unknown env parameter(s) ['rho']"),
    ],
)
def test_evaluate_names_the_flag_a_bad_value_came_from(capsys, argv, prefix):
    """``surveil evaluate --maps nope`` said "surveil: error: surveil evaluate [maps #1]:
    ..." (the program twice, then the spec's field, not the flag), and ``--config`` was
    "[env]"; ``surveil play --config`` says "--config: l_min = -1" as README quotes."""
    line = assert_fails(capsys, ["evaluate", "--seeds", "1", *argv])
    assert line.startswith(f"surveil: error: {prefix}"), line


def test_play_on_a_huge_map_names_its_own_flags(tmp_path, capsys, monkeypatch):
    """``surveil play`` on a 1.4e9 m map said "use resolution >= 2.81e+04": the safe
    start's judge has no such flag here. Now the judge's refusal names ``--start valid``,
    a policy's names the policy whose resolution it is, and a valid start plays."""
    from envs.maps import Map, save_map

    monkeypatch.setenv("SURVEIL_MEMORY_BUDGET", "1GB")
    s = 1e8
    path = tmp_path / "huge.json"
    save_map(Map([(0, 0), (14 * s, 0), (14 * s, 5 * s), (5 * s, 5 * s), (5 * s, 14 * s),
                  (0, 14 * s)], name="huge"), path)  # fmt: skip
    play = ["play", "--map", str(path), "--no-gif"]
    line = assert_fails(capsys, play, "'safe' start on map 'huge'", "use --start valid")
    assert "resolution >=" not in line and "kind=" not in line
    line = assert_fails(capsys, [*play, "--start", "valid"],
                        "use 'pursuer/decomposition' with resolution >= ")  # fmt: skip
    line = assert_fails(capsys, [*play, "--start", "valid", "--pursuer", "pursuer/greedy"],
                        "use 'evader/shooting' with resolution >= ",
                        "SURVEIL_MEMORY_BUDGET=")  # fmt: skip
    assert main([*play, "--start", "valid", *FAST]) == 0
    assert "kept surveillance" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("argv", "needle"),
    [
        (["play", "--no-gif", "--out", ""], "--out = ''"),
        (["play", "--no-gif", "--map", " "], "--map = ' '"),
        (["analyze", "corridor", "--out", ""], "--out = ''"),
        (["analyze", ""], "map = ''"),
        (["figure", "tractrix", "--out", ""], "--out = ''"),
        (["referee", "corridor", "--out", ""], "--out = ''"),
        (["evaluate", "--maps", "corridor", "--seeds", "1", "--plot", ""], "--plot = ''"),
        (["evaluate", "--maps", "corridor", "--seeds", "1", "--results", ""], "--results = ''"),
        (["tournament", "quick", "--store", ""], "--store = ''"),
        (["tournament", "quick", "--report", ""], "--report = ''"),
        (["report", "x.sqlite", "--out", ""], "--out = ''"),
        (["export", "x.sqlite", ""], "out = ''"),
        (["figures", "--check", ""], "--check = ''"),
        (["figures", "--out", ""], "--out = ''"),
    ],
)
def test_an_empty_file_or_map_name_is_refused(argv, needle, capsys, tmp_path, monkeypatch):
    # an empty name counted as the flag's absence: `figure --out ''` wrote out/...png,
    # `referee --out ''` and `evaluate --plot ''` drew nothing, all with exit 0
    monkeypatch.chdir(tmp_path)
    assert_fails(capsys, argv, needle, "expected")
    assert not any(tmp_path.iterdir())  # nothing written


def test_a_model_given_observations_of_another_shape_is_one_line_before_play(
    tmp_path, capsys, monkeypatch
):
    """surveil play gave a lidar model copied without its provenance.json the state and
    it failed at its first step ('failed at step 0: InvalidObservationError: ...'): the
    shape its zip records is checked as it is reset, a configuration error."""
    import shutil

    from strategies.policies.model_files import zoo_dir

    shutil.copy(zoo_dir() / "dagger_pursuer_generalist" / "model.zip", tmp_path / "g.zip")
    monkeypatch.chdir(tmp_path)
    assert main(["play", "--pursuer", "g.zip", "--no-gif", "--max-cycles", "3"]) == 2
    out, err = capsys.readouterr()
    lines = err.strip().splitlines()
    assert [line.split(":")[1] for line in lines] == [" warning", " error"], err
    assert lines[1].startswith(
        f"surveil: error: g.zip: model {tmp_path / 'g.zip'} takes observations of shape "
        "(40,), but the game's observation 'state' has shape (13,): it would fail its first "
        "step; give it the observation it was trained on"
    ), err
    assert out == ""  # no episode played


def test_the_no_provenance_warning_says_what_is_still_checked(tmp_path, capsys, monkeypatch):
    """NoProvenanceWarning said a model 'given another observation, plays without a word'
    just before the same model was refused for the shape of its observation."""
    import shutil

    from strategies.policies.model_files import zoo_dir

    shutil.copy(zoo_dir() / "dagger_pursuer_generalist" / "model.zip", tmp_path / "g.zip")
    monkeypatch.chdir(tmp_path)
    assert main(["play", "--pursuer", "g.zip", "--no-gif", "--max-cycles", "3"]) == 2
    warning, error = capsys.readouterr().err.strip().splitlines()
    assert "given another observation, plays without a word" not in warning
    assert (
        "are unknown and unchecked (a model of the other role plays without a word, and so "
        "does one given another observation of the size it takes; only observations of "
        "another size are refused)" in warning
    ), warning
    assert "takes observations of shape (40,)" in error


def test_a_replay_asked_for_with_no_gif_is_refused(capsys, tmp_path, monkeypatch):
    """``play --no-gif --out x.gif`` (or ``--overlay``) played, printed the outcome and wrote
    no replay, without a word: one of the two flags was dropped."""
    monkeypatch.chdir(tmp_path)
    for extra, needles in (
        (["--out", "x.gif"], ["--no-gif writes no replay; --out is for the replay"]),
        (["--overlay"], ["--overlay is for the replay"]),
        (["--out", "x.gif", "--overlay"], ["--out and --overlay are for the replay"]),
        (["--fps", "5"], ["--fps is for the replay"]),
    ):
        assert_fails(capsys, ["play", *FAST, "--no-gif", *extra], *needles)
    assert list(tmp_path.iterdir()) == []
    assert main(["play", *FAST]) == 0  # the default replay is still out/play.gif
    assert (tmp_path / "out" / "play.gif").is_file()


@pytest.mark.parametrize(
    ("argv", "flag"),
    [
        (["play", *FAST, "--no-gif", "--config", '{"l_min": 2, "l_min": 3}'], "--config"),
        (["play", *FAST, "--no-gif", "--evader-params", '{"mode": "toward", "mode": "away"}'],
         "--evader-params"),
    ],
)  # fmt: skip
def test_a_json_key_given_twice_is_refused(capsys, argv, flag):
    """``--config '{"l_min": 2, "l_min": 3}'`` played at L_min 3 without a word (JSON keeps
    a repeated key's last value): a typo'd or pasted-over config ran something else."""
    line = assert_fails(capsys, argv, flag, "given twice", "expected each key once")
    assert "'l_min'" in line or "'mode'" in line
