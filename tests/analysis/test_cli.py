"""The ``surveil`` command line, run in-process as a user would."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from analysis.cli import main


def test_maps_lists_every_builtin(capsys):
    from envs.maps import builtin_names

    assert main(["maps"]) == 0
    out = capsys.readouterr().out
    for name in builtin_names():
        assert name in out


def test_play_prints_the_outcome_and_writes_a_gif(tmp_path, capsys):
    out = tmp_path / "replay.gif"
    code = main(
        [
            "play",
            "--map",
            "open_room",
            "--pursuer",
            "pursuer/greedy",
            "--evader",
            "evader/straight",
            "--seed",
            "1",
            "--max-cycles",
            "15",
            "--out",
            str(out),
        ]
    )
    assert code == 0
    text = capsys.readouterr().out
    assert "open_room" in text and ("kept surveillance" in text or "escaped" in text)
    with Image.open(out) as gif:
        assert gif.n_frames >= 2
        first = np.asarray(gif.convert("RGB"))
        gif.seek(gif.n_frames - 1)
        last = np.asarray(gif.convert("RGB"))
    assert first.shape == last.shape and not np.array_equal(first, last)


def test_play_png_strip_with_decomposition_overlay(tmp_path):
    out = tmp_path / "strip.png"
    code = main(
        [
            "play",
            "--map",
            "corridor",
            "--pursuer",
            "pursuer/greedy",
            "--evader",
            "evader/random",
            "--max-cycles",
            "8",
            "--overlay",
            "--out",
            str(out),
        ]
    )
    assert code == 0
    img = np.asarray(Image.open(out).convert("RGB"))
    # the overlay paints regions with escapable cells in its two tints
    from analysis.overlay import ONLY_ESCAPABLE, SOME_ESCAPABLE

    colours = {tuple(c) for c in img.reshape(-1, 3)[::7]}
    assert SOME_ESCAPABLE in colours or ONLY_ESCAPABLE in colours


def test_analyze_writes_the_decomposition_picture(tmp_path, capsys):
    out = tmp_path / "dec.png"
    assert main(["analyze", "corridor", "--length", "2", "--out", str(out)]) == 0
    assert "pursuer can hold" in capsys.readouterr().out
    with Image.open(out) as img:
        assert img.size[0] > 400 and img.size[1] > 200


def test_analyze_a_transformed_built_in_at_its_scaled_length(tmp_path, capsys):
    """``corner~x2rot1`` recommends twice the corner's L_min (no --length needed), and the
    decomposition of a similar world at the similar rod is the same one (its counts)."""
    counts = []
    for name in ("corner", "corner~x2rot1"):
        assert main(["analyze", name, "--no-graph", "--out", str(tmp_path / "a.png")]) == 0
        text = capsys.readouterr().out
        counts.append([line for line in text.splitlines() if "regions" in line])
        assert f"'{name}' at L = {2 if name == 'corner' else 4}" in text
    assert counts[0] == counts[1] and counts[0]


@pytest.mark.parametrize("command", [["play", "--no-gif"], ["evaluate", "--maps", "corridor"]])
def test_max_cycles_given_twice_differently_is_refused(command, capsys):
    """``--max-cycles 10`` beside ``--config '{"max_cycles": 20}'``: which one was meant is
    unknown, so neither wins silently (the flag did); the same value twice is fine."""
    argv = [*command, "--max-cycles", "10", "--config", '{"max_cycles": 20}']
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "--max-cycles 10 and --config max_cycles = 20: give max_cycles once" in err


def test_figure_tractrix(tmp_path):
    out = tmp_path / "tractrix.png"
    assert main(["figure", "tractrix", "--out", str(out)]) == 0
    assert out.stat().st_size > 1000


def test_bad_input_is_a_clear_error(capsys):
    assert main(["play", "--map", "no_such_map", "--no-gif"]) == 2
    err = capsys.readouterr().err
    assert "no_such_map" in err
    assert main(["play", "--seed", "not-a-number"]) == 2  # argparse errors return too
    assert "--seed = 'not-a-number'" in capsys.readouterr().err


def test_evaluate_prints_the_table_resumes_and_plots(tmp_path, capsys):
    results, picture = tmp_path / "runs.sqlite", tmp_path / "table.png"
    argv = [
        "evaluate",
        "--maps",
        "open_room",
        "--pursuers",
        "pursuer/greedy",
        "--evaders",
        "evader/straight",
        "evader/random",
        "--seeds",
        "2",
        "--max-cycles",
        "20",
        "--results",
        str(results),
        "--plot",
        str(picture),
        "--no-progress",
    ]
    assert main(argv) == 0
    first = capsys.readouterr().out
    assert "pursuer/greedy" in first and "evader/random" in first
    assert "4 of 4 matches stored" in first  # 2 evaders x 2 seeds, stored as they finish
    assert picture.stat().st_size > 1000
    # a second run replays nothing: every match is already in the store
    assert main(argv) == 0
    second = capsys.readouterr().out
    assert "4 reused, 0 played" in second
    assert second.splitlines()[-5:-1] == first.splitlines()[-5:-1]


def test_policies_lists_the_registry_and_play_takes_parameters(tmp_path, capsys):
    from strategies.policies import policy_names

    assert main(["policies", "--role", "evader"]) == 0
    out = capsys.readouterr().out
    assert all(name in out for name in policy_names("evader"))
    assert "pursuer/greedy" not in out
    assert "zoo:NAME (python -m training.zoo list)" in out  # as play takes them (e0e30f8)
    argv = [
        "play",
        "--map",
        "open_room",
        "--pursuer",
        "pursuer/greedy",
        "--evader",
        "evader/toward_away",
        "--evader-params",
        '{"mode": "away"}',
        "--max-cycles",
        "5",
        "--no-gif",
    ]
    assert main(argv) == 0
    assert main([*argv[:-3], "--evader-params", '{"no_such_param": 1}', "--no-gif"]) != 0


def test_train_runs_a_tiny_config_through_the_cli(tmp_path, capsys):
    import training
    from training.config import load_config

    configs = Path(training.__file__).parent / "configs"
    config = load_config(configs / "ppo_pursuer_vs_straight_open_room.toml")
    small = tmp_path / "tiny.toml"
    tiny = config.replace(total_timesteps=64, n_steps=32, batch_size=32, eval_episodes=0)
    small.write_text(tiny.to_toml())
    assert main(["train", str(small), "--output-dir", str(tmp_path / "run")]) == 0
    assert (tmp_path / "run" / "model.zip").exists()
    assert (tmp_path / "run" / "provenance.json").exists()


def test_a_run_whose_every_match_errored_does_not_exit_0(tmp_path, capsys):
    """Every match stored as an error (here: no safe start, the start margins cover the
    corridor at v_pursuer = 100) printed an empty table and exited 0; one ok match is
    enough for 0 (the table then says the rest)."""
    argv = ["evaluate", "--maps", "corridor", "--pursuers", "pursuer/greedy", "--evaders",
            "evader/straight", "--seeds", "1", "--max-cycles", "5", "--no-progress",
            "--workers", "1", "--results", str(tmp_path / "r.sqlite")]  # fmt: skip
    assert main([*argv, "--config", '{"v_pursuer": 100}']) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("surveil: error: every one of the 1 matches")
    assert "no safe start" in err[0]
    assert main(argv) == 0


def test_play_takes_a_shipped_model_or_a_model_file_as_evaluate_does(tmp_path, capsys):
    # `surveil evaluate --pursuers zoo:NAME` played; `surveil play --pursuer zoo:NAME` said
    # "expected a policy name of the form 'pursuer/KIND'"
    from strategies.policies.model_files import zoo_dir

    model = zoo_dir() / "ppo_evader_vs_greedy_open_room" / "model.zip"
    fast = ["--map", "open_room", "--max-cycles", "5", "--no-gif"]
    for argv, named in (
        (
            ["--pursuer", "zoo:ppo_pursuer_vs_straight_open_room", "--evader", "evader/straight"],
            "open_room: zoo:ppo_pursuer_vs_straight_open_room vs evader/straight",
        ),
        (["--pursuer", "pursuer/greedy", "--evader", str(model)], f"greedy vs {model} ("),
    ):
        assert main(["play", *argv, *fast]) == 0
        out = capsys.readouterr().out
        # the outcome names the model as it was given, as evaluate's and tournament's tables
        # label it (it said pursuer/sb3:/abs/path/model.zip, then evader//abs/path/model.zip)
        assert named in out and ("kept surveillance" in out or "escaped" in out)
        assert "sb3:" not in out and "//" not in out


def test_play_and_evaluate_take_the_registry_name_of_a_model_file(tmp_path, capsys):
    """README (Policies) and surveil policies: trained models are ROLE/sb3:PATH. play and
    evaluate read any name ending in .zip as a file path and looked for the file
    'pursuer/sb3:PATH' ("no such file (/cwd/pursuer/sb3:...)")."""
    from strategies.policies.model_files import zoo_dir

    model = zoo_dir() / "ppo_pursuer_vs_straight_open_room" / "model.zip"
    fast = ["--map", "open_room", "--max-cycles", "5", "--no-gif"]
    assert main(["play", "--pursuer", f"pursuer/sb3:{model}", *fast]) == 0
    out = capsys.readouterr().out
    assert f"open_room: pursuer/sb3:{model} vs evader/shooting" in out  # as it was named
    assert "kept surveillance" in out
    argv = ["evaluate", "--maps", "open_room", "--seeds", "1", "--max-cycles", "5"]
    argv += ["--pursuers", f"pursuer/sb3:{model}", "--evaders", "evader/straight"]
    assert main([*argv, "--results", str(tmp_path / "e.sqlite"), "--no-progress"]) == 0
    assert "1 of 1 matches stored" in capsys.readouterr().out
    # the other role's name is refused, one line, naming the flag
    assert main(["play", "--pursuer", f"evader/sb3:{model}", *fast]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--pursuer" in err[0] and "'pursuer/KIND'" in err[0]


@pytest.mark.parametrize(
    ("command", "flag"),
    [("play", "--map"), ("analyze", "map"), ("referee", "map"), ("evaluate", "--maps")],
)
def test_every_map_argument_says_what_it_takes(command, flag, capsys):
    """A new user's first question: how do I give my own world? The help said 'built-in
    name or map file' (no formats, no random:SEED, which every command takes) or nothing
    (evaluate --maps); ``surveil maps`` named the built-ins only."""
    assert main([command, "--help"]) == 0
    text = " ".join(capsys.readouterr().out.split())
    at = text.index(f" {flag} ", text.index("options:") if flag.startswith("-") else 0)
    assert "(.json, .geojson or .wkt" in text[at:] and "random:SEED" in text[at:]
    assert main(["maps", "--help"]) == 0
    text = " ".join(capsys.readouterr().out.split())
    assert "a map file (.json, .geojson or .wkt" in text and "random:KIND:SEED" in text


def test_evaluate_help_names_the_defaults_it_plays(capsys):
    """README: `surveil evaluate --maps corridor two_rooms --seeds 20`. Which pursuers and
    evaders that plays, and how many seeds without --seeds, the help did not say."""
    assert main(["evaluate", "--help"]) == 0
    text = " ".join(capsys.readouterr().out.split())
    for flag, default in [
        ("--maps", "corridor two_rooms"),
        ("--pursuers", "pursuer/decomposition pursuer/greedy"),
        ("--evaders", "evader/shooting evader/straight"),
        ("--seeds", "10"),
    ]:
        at = text.index(f" {flag} ", text.index("options:"))
        assert f"default: {default})" in text[at : text.index(" --", at + len(flag) + 2)]


def test_every_argument_of_every_command_has_a_help_text():
    """`surveil policies --help`, `figure --help`, `tournament --help` and `referee --help`
    listed --role, NAME, --backend and --kind with their choices and not a word on them
    (what --kind labels, which backend is the default, which figure each name draws)."""
    import argparse

    from analysis.cli import build_parser

    (commands,) = [a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction)]
    bare = [
        f"{name} {a.option_strings[0] if a.option_strings else a.dest}"
        for name, parser in commands.choices.items()
        for a in parser._actions
        if not a.help and not isinstance(a, argparse._HelpAction)
    ]
    assert bare == []


def test_every_command_s_help_says_what_it_does(capsys):
    """`surveil report --help` (and policies, play, export, evaluate, ...) printed its usage
    and arguments and not a word on what the command does: argparse shows a subcommand's
    one-line help only in `surveil --help`."""
    import argparse

    from analysis.cli import build_parser

    (commands,) = [a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction)]
    for name, parser in commands.choices.items():
        parser.print_help()
        text = " ".join(capsys.readouterr().out.split())
        assert parser.description, name
        assert " ".join(parser.description.split()) in text, name


@pytest.mark.parametrize("unbuffered", ["1", ""])
def test_a_reader_that_leaves_is_not_an_error(unbuffered):
    """``surveil figures --numbers | head -2`` (docs/REPRODUCTION.md's command, looked at
    with head) ended with "surveil: error: [Errno 32] Broken pipe" and exit 2 (output
    unbuffered), or Python's "Exception ignored ... BrokenPipeError" at exit (buffered).
    Now it stops silently with 141 (128 + SIGPIPE), as a shell reports such a command."""
    import os
    import subprocess
    import sys

    env = {**os.environ, "PYTHONUNBUFFERED": unbuffered}
    root = Path(__file__).resolve().parents[2]
    proc = subprocess.Popen(
        [sys.executable, "-m", "analysis.cli", "maps"],
        cwd=root,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    proc.stdout.close()  # the reader leaves before a line is written (imports take longer)
    err = proc.stderr.read().decode()
    assert proc.wait(timeout=120) == 141, err
    assert err == ""


def test_sigterm_stops_a_command_as_ctrl_c_does(tmp_path, capsys, monkeypatch):
    """``kill`` / ``timeout`` sent SIGTERM's default action: surveil play died at once and
    left its hidden temporary replay (.play.gif.PID.tmp) beside the output, and surveil
    train printed no resume note. Now it stops as on Ctrl-C (exit 143)."""
    import os
    import signal

    import analysis.replay

    frames = []
    add = analysis.replay.GifStream.add

    def add_then_kill(self, frame):
        frames.append(1)
        if len(frames) == 3:
            os.kill(os.getpid(), signal.SIGTERM)
        add(self, frame)

    monkeypatch.setattr(analysis.replay.GifStream, "add", add_then_kill)
    monkeypatch.setattr(analysis.replay.GifStream, "__call__", add_then_kill)

    def ignore(signum, frame):  # the caller's handler (without the fix: pytest survives)
        pass

    outer = signal.signal(signal.SIGTERM, ignore)
    try:
        out = tmp_path / "x.gif"
        assert main(["play", "--max-cycles", "50", "--out", str(out)]) == 143
        assert signal.getsignal(signal.SIGTERM) is ignore  # restored for the caller
    finally:
        signal.signal(signal.SIGTERM, outer)
    assert capsys.readouterr().err == "surveil: stopped by SIGTERM\n"
    assert list(tmp_path.iterdir()) == []  # neither the replay nor its temporary file


def test_sigterm_stops_python_m_training_with_its_resume_note(tmp_path, capsys, monkeypatch):
    import os
    import signal

    import training.cli
    from training.cli import cli_train

    cfg = tmp_path / "c.toml"
    cfg.write_text(f'role = "pursuer"\nopponent = "evader/straight"\noutput_dir = "{tmp_path}/r"\n')

    def killed(config, progress_bar=False):
        os.kill(os.getpid(), signal.SIGTERM)
        raise ValueError("not stopped")  # a SurveilValueError would be exit code 2

    monkeypatch.setattr(training.cli, "train", killed)
    outer = signal.signal(signal.SIGTERM, lambda signum, frame: None)  # as above
    try:
        assert cli_train([str(cfg)]) == 143
    finally:
        signal.signal(signal.SIGTERM, outer)
    err = capsys.readouterr().err
    assert err.startswith("stopped before the first checkpoint") and err.endswith(
        "python -m training: stopped by SIGTERM\n"
    )
