"""Keep ``docs/REPRODUCTION.md`` true: its quoted numbers and its figure gallery.

**Tagged numbers.** Every number the report quotes as computed is followed by an HTML
comment naming its key in :data:`analysis.figures.numbers.NUMBERS`, which renders as
nothing::

    31<!--n:corridor.regions--> regions
    `2.2500, 2.7500`<!--n:stratified.critical-->   (a code span for values with spaces)

:func:`check_report` recomputes each key and lists the quotes that differ;
:func:`update_report` rewrites them. A plain token may hold letters, digits and
``. - + / _ :``; anything else goes in a code span.

**Untagged results.** In a table whose header has a column named "we compute", a decimal
number with three or more decimals that is not tagged is reported too (parameters such
as ρ = 0.5 are written with fewer decimals and are not results).

**The gallery.** The text between ``<!-- figures:begin -->`` and ``<!-- figures:end -->``
is generated from the figure registry (image, title, caption, command).
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

from analysis.figures.registry import figure_specs

__all__ = ["Drift", "check_report", "gallery", "tags", "update_report"]

TAG = re.compile(
    r"(?:`(?P<code>[^`\n]+)`|(?P<word>[A-Za-z0-9.+\-/_:]+))<!--\s*n:(?P<key>[A-Za-z0-9_.\-]+)\s*-->"
)
BEGIN, END = "<!-- figures:begin -->", "<!-- figures:end -->"
_RESULT = re.compile(r"(?<![\w.])-?\d+\.\d{3,}(?:e[-+]?\d+)?")


@dataclass(frozen=True)
class Drift:
    """One problem of the report.

    Attributes:
        line: 1-based line number (0 for the whole file).
        key: the number's key, or ``""``.
        quoted: what the report says.
        expected: what the code computes now (or what is missing).
    """

    line: int
    key: str
    quoted: str
    expected: str

    def __str__(self) -> str:
        where = f"line {self.line}: " if self.line else ""
        if self.key:
            return (
                f"{where}{self.key}: the report says {self.quoted!r}, the code computes "
                f"{self.expected!r}"
            )
        return f"{where}{self.quoted} ({self.expected})"


_CODE = re.compile(r"```.*?```|`[^`\n]*`", re.S)


def _literal_spans(text: str) -> list[tuple[int, int]]:
    """Code blocks, and code spans that contain a tag (examples of the syntax), pairing
    backticks from the left as Markdown does."""
    return [m.span() for m in _CODE.finditer(text) if "<!--" in m.group(0)]


def _matches(text: str) -> list[re.Match]:
    spans = _literal_spans(text)
    return [m for m in TAG.finditer(text) if not any(a <= m.start() < b for a, b in spans)]


def tags(text: str) -> list[tuple[int, str, str]]:
    """``(line, key, quoted)`` for every tagged number of ``text`` (not in code examples)."""
    out = []
    for m in _matches(text):
        line = text.count("\n", 0, m.start()) + 1
        quoted = m.group("code") if m.group("code") is not None else m.group("word")
        out.append((line, m.group("key"), quoted))
    return out


def gallery() -> str:
    """The generated figure gallery (Markdown), one entry per registered figure, each
    replay right after the figure it animates (same ``figNN`` prefix)."""
    groups: dict[str, list] = {}
    for s in figure_specs():
        groups.setdefault(s.name.split("-")[0], []).append(s)
    parts = [BEGIN, ""]
    for s in (s for g in groups.values() for s in g):
        parts.append(f"#### {s.paper}: {s.title}")
        parts.append("")
        parts.append(f"![{s.name}](figures/{s.filename})")
        parts.append("")
        parts.append(f"{s.caption} (`surveil figures --only {s.name}`)")
        parts.append("")
    parts.append(END)
    return "\n".join(parts)


def _untagged(text: str) -> list[Drift]:
    out = []
    lines = text.split("\n")
    col = None
    for i, line in enumerate(lines, start=1):
        if not line.lstrip().startswith("|"):
            col = None
            continue
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        low = [c.lower() for c in cells]
        if any("we compute" in c for c in low):
            col = next(k for k, c in enumerate(low) if "we compute" in c)
            continue
        if col is None or col >= len(cells) or set(line.replace("|", "").strip()) <= set("-: "):
            continue
        bare = TAG.sub("", cells[col])
        bare = re.sub(r"`[^`]*`", "", bare)
        for m in _RESULT.finditer(bare):
            out.append(
                Drift(
                    i,
                    "",
                    f"untagged result {m.group(0)!r} in the 'we compute' column",
                    "tag it with <!--n:KEY--> or write it with fewer decimals",
                )
            )
    return out


def check_report(text: str, values: Mapping[str, str], *, require_all: bool = True) -> list[Drift]:
    """Every difference between the report and the code.

    Args:
        text: the report.
        values: ``{key: text}`` from :func:`analysis.figures.numbers.compute_numbers`.
        require_all: also report keys of ``values`` the report never quotes.

    Returns:
        The problems, empty when the report is current.
    """
    out = []
    seen = set()
    for line, key, quoted in tags(text):
        seen.add(key)
        if key not in values:
            out.append(Drift(line, key, quoted, "<no such number>"))
        elif values[key] != quoted:
            out.append(Drift(line, key, quoted, values[key]))
    if require_all:
        for key in values:
            if key not in seen:
                out.append(Drift(0, "", f"number {key!r} is never quoted", "quote it or drop it"))
    if BEGIN not in text or END not in text:
        out.append(Drift(0, "", "the figure gallery markers are missing", f"{BEGIN} ... {END}"))
    else:
        cur = text[text.index(BEGIN) : text.index(END) + len(END)]
        if cur != gallery():
            out.append(
                Drift(
                    0,
                    "",
                    "the figure gallery differs from the registry",
                    "regenerate it with --report",
                )
            )
    out.extend(_untagged(text))
    return out


def update_report(text: str, values: Mapping[str, str]) -> tuple[str, list[Drift]]:
    """Rewrite every tagged number with its current value and regenerate the gallery.

    Returns:
        ``(new_text, changes)``; unknown keys are left as they are and listed.
    """
    changes = []

    def sub(m: re.Match) -> str:
        key = m.group("key")
        quoted = m.group("code") if m.group("code") is not None else m.group("word")
        line = text.count("\n", 0, m.start()) + 1
        if key not in values:
            changes.append(Drift(line, key, quoted, "<no such number>"))
            return m.group(0)
        new = values[key]
        if new != quoted:
            changes.append(Drift(line, key, quoted, new))
        plain = re.fullmatch(r"[A-Za-z0-9.+\-/_:]+", new) and m.group("code") is None
        return (new if plain else f"`{new}`") + f"<!--n:{key}-->"

    pieces, last = [], 0
    for m in _matches(text):
        pieces += [text[last : m.start()], sub(m)]
        last = m.end()
    out = "".join(pieces) + text[last:]
    if BEGIN in out and END in out:
        a, b = out.index(BEGIN), out.index(END) + len(END)
        out = out[:a] + gallery() + out[b:]
    else:
        out = out.rstrip("\n") + "\n\n" + gallery() + "\n"
    return out, changes


def read(path: str | Path) -> str:
    """The report's text."""
    return Path(path).read_text(encoding="utf-8")
