"""docs/REPRODUCTION.md says what the code computes now; the tag machinery catches drift."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from analysis.cli import main
from analysis.figures.numbers import NUMBERS, compute_numbers
from analysis.figures.report import BEGIN, END, check_report, gallery, tags, update_report
from envs.errors import UnknownNameError

REPORT = Path(__file__).resolve().parents[3] / "docs" / "REPRODUCTION.md"


def test_the_report_matches_the_code(tmp_path, capsys):
    """Every tagged number equals its recomputed value, every number is quoted, the
    gallery matches the registry, and no computed result is left untagged. If this fails,
    regenerate with `surveil figures --out docs/figures --report docs/REPRODUCTION.md` and
    re-read the rows whose numbers changed: their status may have changed too."""
    problems = check_report(REPORT.read_text(encoding="utf-8"), compute_numbers())
    fix = (
        "\ndocs/REPRODUCTION.md has drifted from the code. Regenerate it and the pictures with\n"
        "    surveil figures --out docs/figures --report docs/REPRODUCTION.md\n"
        "then re-read the rows whose numbers changed (their status may change too)."
    )
    assert not problems, "\n".join(map(str, problems)) + fix
    _command_line_finds_and_repairs_drift(tmp_path, capsys)


def _command_line_finds_and_repairs_drift(tmp_path, capsys):
    """`surveil figures --check` finds a tampered number (exit 1) and --report puts it
    back (part of the test above, so that the numbers are computed once)."""
    copy = tmp_path / "REPRODUCTION.md"
    shutil.copy(REPORT, copy)
    text = copy.read_text(encoding="utf-8")
    assert "31<!--n:corridor.regions-->" in text
    copy.write_text(
        text.replace("31<!--n:corridor.regions-->", "19<!--n:corridor.regions-->"),
        encoding="utf-8",
    )
    assert main(["figures", "--check", str(copy)]) == 1
    out = capsys.readouterr().out
    assert "corridor.regions" in out and "'19'" in out
    args = ["figures", "--only", "fig12", "--scale", "0.3", "--out", str(tmp_path / "f")]
    assert main([*args, "--report", str(copy)]) == 0
    assert copy.read_text(encoding="utf-8") == text
    assert main(["figures", "--check", str(copy)]) == 0


def _doc(body: str) -> str:
    return body + "\n\n" + gallery() + "\n"


def test_a_wrong_number_is_caught_and_rewritten():
    text = _doc("| a | b | we compute | c |\n|---|---|---|---|\n| x | y | 31<!--n:k--> | z |")
    values = {"k": "32"}
    (problem,) = check_report(text, values)
    assert problem.key == "k" and problem.quoted == "31" and problem.expected == "32"
    assert problem.line == 3
    new, changes = update_report(text, values)
    assert "32<!--n:k-->" in new and len(changes) == 1
    assert check_report(new, values) == []


def test_values_with_spaces_live_in_code_spans():
    text = _doc("list `1.0, 2.0`<!--n:xs--> and plain 3<!--n:y-->")
    assert [(k, q) for _, k, q in tags(text)] == [("xs", "1.0, 2.0"), ("y", "3")]
    new, _ = update_report(text, {"xs": "1.0, 2.5", "y": "(4, 5)"})
    assert "`1.0, 2.5`<!--n:xs-->" in new and "`(4, 5)`<!--n:y-->" in new


def test_examples_in_code_are_not_tags():
    text = _doc("write `31<!--n:KEY-->` like this\n```\n5<!--n:other-->\n```\n")
    assert tags(text) == []


def test_unknown_unquoted_untagged_and_missing_gallery():
    text = "| claim | we compute |\n|---|---|\n| c | 2.3431 and 1<!--n:nope--> and L = 2.5 |"
    problems = [str(p) for p in check_report(text, {"k": "1"})]
    assert any("nope" in p and "no such number" in p for p in problems)
    assert any("'k' is never quoted" in p for p in problems)
    assert any("untagged result '2.3431'" in p for p in problems)
    assert not any("2.5" in p for p in problems)  # a parameter, not a result
    assert any("gallery markers" in p for p in problems)
    stale = text.replace("2.3431 and ", "") + f"\n{BEGIN}\nold\n{END}\n"
    assert any("gallery differs" in str(p) for p in check_report(stale, {"nope": "1", "k": "1"}))


def test_numbers_are_described_and_prefixes_checked():
    assert all(n.what and n.key == k for k, n in NUMBERS.items())
    assert set(compute_numbers(["e5.T"])) == {"e5.T_plus", "e5.T_minus"}
    with pytest.raises(UnknownNameError, match="no number starts"):
        compute_numbers(["no.such."])


def test_a_file_that_is_not_a_report_is_refused_unchanged(tmp_path, capsys):
    # --update appended the gallery to any file (a JSON file, say); --report did so after
    # drawing every figure, and found a missing file only then
    notes = tmp_path / "notes.json"
    notes.write_text('{"a": 1}\n', encoding="utf-8")
    assert main(["figures", "--update", str(notes)]) == 2
    assert "not a report" in capsys.readouterr().err
    assert notes.read_text(encoding="utf-8") == '{"a": 1}\n'
    out = tmp_path / "f"
    for report, needle in [(notes, "not a report"), (tmp_path / "no.md", "cannot read it")]:
        assert main(["figures", "--only", "fig12", "--out", str(out), "--report", str(report)]) == 2
        assert needle in capsys.readouterr().err
    assert not out.exists()  # refused before drawing
