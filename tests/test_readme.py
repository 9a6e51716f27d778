"""README.md and docs/*.md as a newcomer meets them: their Python blocks run as written,
every `surveil` command they quote names a subcommand and flags the CLI accepts, and every
file they link or name in backticks is in the repository (the experiment histories moved
from the README to docs/ stay reachable)."""

from __future__ import annotations

import argparse
import re
from pathlib import Path

import pytest

from analysis.cli import build_parser

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
REPO_PATH = re.compile(
    r"`((?:analysis|benchmarks|docs|envs|scripts|strategies|tests|training)/[\w./-]+"
    r"\.(?:py|md|toml|json|txt|sh|png|gif))`"
)


def _python_blocks(text: str) -> list[str]:
    return re.findall(r"```python\n(.*?)```", text, re.S)


def test_every_python_block_of_the_readme_runs_as_written(monkeypatch, capsys):
    from strategies.policies import registry

    monkeypatch.setattr(registry, "_REGISTRY", dict(registry._REGISTRY))  # the example registers
    blocks = _python_blocks((ROOT / "README.md").read_text(encoding="utf-8"))
    assert len(blocks) >= 2  # the env step API and "Your own policy"
    for block in blocks:
        exec(compile(block, "README.md", "exec"), {})
    out = capsys.readouterr().out
    assert "corridor: pursuer/decomposition vs evader/away (seed 0)" in out


def _surveil_commands(text: str) -> list[str]:
    """`surveil ...` in inline code (lines joined) and at the start of a bash block's line."""
    flat = re.sub(r"\s*\n\s*", " ", text)
    inline = re.findall(r"`(surveil [^`]+)`", flat)
    blocks = re.findall(r"```bash\n(.*?)```", text, re.S)
    lines = [line.split(" #")[0].strip() for b in blocks for line in b.splitlines()]
    return inline + [line for line in lines if line.startswith("surveil ")]


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_every_surveil_command_quoted_is_one_the_cli_takes(page):
    parser = build_parser()
    (sub,) = (a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    for command in _surveil_commands(page.read_text(encoding="utf-8")):
        words = command.split()
        if words[1] in ("...", "MAP"):  # "surveil ...": a placeholder
            continue
        assert words[1] in sub.choices, f"{page.name}: {command!r}: no subcommand {words[1]!r}"
        flags = {o for a in sub.choices[words[1]]._actions for o in a.option_strings}
        unknown = [w for w in words[2:] if w.startswith("--") and w.split("=")[0] not in flags]
        assert not unknown, f"{page.name}: {command!r}: surveil {words[1]} takes no {unknown}"


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_every_file_a_page_links_or_names_exists(page):
    text = page.read_text(encoding="utf-8")
    for target in re.findall(r"\]\(([^)#\s]+)(?:#[^)]*)?\)", text):
        if not target.startswith(("http://", "https://")):
            assert (page.parent / target).exists(), f"{page.name} links {target}: no such file"
    for path in REPO_PATH.findall(text):
        assert (ROOT / path).exists(), f"{page.name} names `{path}`: no such file"
