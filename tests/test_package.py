"""Packaging and architecture checks: the right packages, layered imports."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]


@pytest.mark.parametrize("name", ["envs", "strategies", "analysis", "training"])
def test_top_level_packages_are_ours(name: str) -> None:
    # PyPI has unrelated distributions called "envs" etc.; ours must be the ones imported.
    module = __import__(name)
    assert Path(module.__file__).resolve().is_relative_to(REPO)


def test_imports_go_downward_only() -> None:
    lint = Path(sys.executable).parent / "lint-imports"
    if not lint.exists():
        pytest.skip("import-linter is not installed (pip install surveil[test])")
    proc = subprocess.run(
        [str(lint), "--config", str(REPO / "pyproject.toml")],
        cwd=REPO,
        capture_output=True,
        text=True,
        check=False,
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr


def test_envs_does_not_know_policies() -> None:
    # DESIGN.md: nothing in envs knows a policy exists (stronger than the layer rule:
    # no string-level mention either, so no lazy import can sneak in).
    for path in (REPO / "envs").rglob("*.py"):
        text = path.read_text(encoding="utf-8")
        for upper in ("strategies", "training", "analysis"):
            assert f"import {upper}" not in text and f"from {upper}" not in text, path
