"""Repository hygiene that would otherwise creep back."""

from __future__ import annotations

from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_benchmarks_use_the_installed_package() -> None:
    """Benchmarks import the installed package; none edits sys.path to find the checkout."""
    offenders = [
        p.name for p in sorted((ROOT / "benchmarks").glob("*.py")) if "sys.path" in p.read_text()
    ]
    assert offenders == []


def test_ci_runs_the_linter_the_formatter_and_the_lower_bounds() -> None:
    ci = (ROOT / ".ci" / "run").read_text()
    for step in ("ruff check .", "ruff format --check .", "scripts/check_min_versions.sh"):
        assert step in ci, step
    assert (ROOT / "scripts" / "check_min_versions.sh").exists()
