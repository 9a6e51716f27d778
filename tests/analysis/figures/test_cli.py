"""`surveil figures`: draw, list, print numbers, check and update the report."""

from __future__ import annotations

import contextlib
import io
import shutil
import tempfile
from pathlib import Path

import pytest

from analysis.cli import main

pytest.importorskip("matplotlib")


def test_list_and_numbers(capsys):
    assert main(["figures", "--list"]) == 0
    out = capsys.readouterr().out
    assert "fig03-corridor" in out and "Fig. 3" in out and "fn4-replay" in out
    assert main(["figures", "--numbers", "fig12."]) == 0
    out = capsys.readouterr().out
    assert "fig12.alpha" in out and "-0.4636" in out


def test_only_draws_the_named_figures(tmp_path, capsys):
    assert (
        main(["figures", "--only", "fig12", "fig15", "--out", str(tmp_path), "--scale", "0.3"]) == 0
    )
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "fig12-greedy.png",
        "fig15-wall-following.png",
    ]


def test_bad_input_is_a_clear_error(tmp_path, capsys):
    assert main(["figures", "--only", "fig99", "--out", str(tmp_path)]) == 2
    assert "fig99" in capsys.readouterr().err
    assert main(["figures", "--numbers", "zzz"]) == 2
    assert main(["figures", "--only", "fig12", "--scale", "-1", "--out", str(tmp_path)]) == 2
    assert "scale" in capsys.readouterr().err


def test_a_scale_below_the_drawing_floors_is_refused(tmp_path, capsys):
    # --scale 1e-9 exited 0 with a 128 x 72 PNG: the 20 dpi floor drew it at scale 0.2
    out = tmp_path / "f"
    assert main(["figures", "--only", "fig12", "--scale", "1e-9", "--out", str(out)]) == 2
    assert "scale = 1e-09: expected a size factor in [0.25, 4]" in capsys.readouterr().err
    assert not out.exists()


def test_check_refuses_a_file_that_is_not_a_report(tmp_path, capsys):
    # a JSON file or an empty one got 122 "problems" (exit 1) and the advice to --update
    # it, which --update then refused; a missing file named no flag
    other = tmp_path / "x.json"
    other.write_text('{"a": 1}\n')
    empty = tmp_path / "empty.md"
    empty.write_text("")
    for path, needle in ((other, "not a report"), (empty, "an empty file, not a report"),
                         (tmp_path / "no.md", "cannot read it")):  # fmt: skip
        assert main(["figures", "--check", str(path)]) == 2
        out, err = capsys.readouterr()
        assert f"--check = '{path}': " in err and needle in err and out == "", err


@pytest.mark.parametrize(
    ("first", "second"),
    [("--check", "--update"), ("--update", "--report"), ("--list", "--check")],
)
def test_one_job_a_call_two_are_refused(first, second, tmp_path, capsys):
    # "--check F --update F" checked F, said "every quoted number matches" and updated
    # nothing; "--list --check F" listed and checked nothing, each without a word
    report = tmp_path / "r.md"
    report.write_text("31<!--n:corridor.regions-->\n")
    argv = [first] if first == "--list" else [first, str(report)]
    assert main(["figures", *argv, second, str(report), "--out", str(tmp_path / "o")]) == 2
    out, err = capsys.readouterr()
    assert err.startswith(f"surveil: error: {second}: not allowed with argument {first}")
    assert out == "" and report.read_text() == "31<!--n:corridor.regions-->\n"
    assert not (tmp_path / "o").exists()


def test_an_interrupted_figure_leaves_the_previous_one_whole(tmp_path, monkeypatch):
    # a figure was written in place: Ctrl-C while a GIF's frames were encoded left a
    # truncated file in docs/figures
    from analysis.figures import style
    from analysis.figures.registry import build_figure

    before = build_figure("fig12", tmp_path, scale=0.3).read_bytes()
    real = style.save_png

    def interrupted(fig, path, scale):
        real(fig, path, scale)
        with open(path, "r+b") as f:  # half of it on disk when the signal came
            f.truncate(f.seek(0, 2) // 2)
        raise KeyboardInterrupt

    monkeypatch.setattr(style, "save_png", interrupted)
    with pytest.raises(KeyboardInterrupt):
        build_figure("fig12", tmp_path, scale=0.5)
    assert [p.name for p in tmp_path.iterdir()] == ["fig12-greedy.png"]
    assert (tmp_path / "fig12-greedy.png").read_bytes() == before


def test_a_report_its_user_cannot_write_is_refused_before_the_drawing(tmp_path):
    # --report FILE was read up front but written only after every figure was drawn
    # (minutes): then "FILE: Permission denied"
    from tests.analysis.tournament.test_store_failures import _as_a_user_who_cannot_write

    shared = Path(tempfile.mkdtemp(prefix="surveil-figures-test-"))
    try:
        shared.chmod(0o755)
        out = shared / "out"
        out.mkdir()
        out.chmod(0o777)
        report = shared / "REPRODUCTION.md"
        report.write_text("31<!--n:corridor.regions-->\n")
        assert main(["figures", "--only", "fig12", "--scale", "0.3", "--out", str(tmp_path)]) == 0

        def draw_and_report():
            err = io.StringIO()
            argv = ["figures", "--only", "fig12", "--scale", "0.3", "--out", str(out)]
            with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
                code = main([*argv, "--report", str(report)])
            return code, err.getvalue(), sorted(p.name for p in out.iterdir())

        code, err, drawn = _as_a_user_who_cannot_write(report, draw_and_report)
        assert code == 2 and err.startswith(f"surveil: error: --report = '{report}': cannot ")
        assert "left unchanged" in err and len(err.splitlines()) == 1
        assert drawn == []  # refused before the first figure
        assert report.read_text() == "31<!--n:corridor.regions-->\n"
    finally:
        shutil.rmtree(shared, ignore_errors=True)
