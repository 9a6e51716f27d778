"""Every number ``docs/REPRODUCTION.md`` quotes, computed now from the library.

Each :class:`Number` has a key (``corridor.regions``), a one-line description and a
function computing it; :meth:`Number.text` formats it the way the report prints it. The
report tags each quoted number with its key (:mod:`analysis.figures.report`), and a test
recomputes them all, so the report cannot drift from the code. ``surveil figures
--numbers [PREFIX...]`` prints them.

The computations reuse the cases the figures draw (:mod:`analysis.figures.cases`); they are
declared by section in :mod:`~analysis.figures.numbers.cspace` (Secs. 3-4, THEORY.md
section 8), :mod:`~analysis.figures.numbers.control` (Secs. 5-7) and
:mod:`~analysis.figures.numbers.episodes` (the replays), which register on import.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from envs.errors import UnknownNameError

__all__ = ["NUMBERS", "Number", "compute_numbers", "fmt_list", "number", "yes_no"]


@dataclass(frozen=True)
class Number:
    """One quoted number.

    Attributes:
        key: its name in the report's tags, e.g. ``"corridor.regions"``.
        what: what it is, one line.
        compute: returns the value.
        fmt: a format string (``"{:.4f}"``) or a function value -> text.
    """

    key: str
    what: str
    compute: Callable[[], Any]
    fmt: str | Callable[[Any], str] = "{}"

    def text(self) -> str:
        """The value as the report prints it."""
        v = self.compute()
        return self.fmt(v) if callable(self.fmt) else self.fmt.format(v)


NUMBERS: dict[str, Number] = {}


def number(key: str, what: str, fmt: str | Callable[[Any], str] = "{}"):
    """Decorator registering a number."""

    def deco(fn: Callable[[], Any]) -> Callable[[], Any]:
        if key in NUMBERS:  # pragma: no cover - a programming error
            raise ValueError(f"number {key!r} registered twice")
        NUMBERS[key] = Number(key, what, fn, fmt)
        return fn

    return deco


def compute_numbers(prefixes: list[str] | None = None) -> dict[str, str]:
    """``{key: text}`` for every number (or those whose key starts with a prefix).

    Raises:
        UnknownNameError: a prefix matches no number.
    """
    keys = list(NUMBERS)
    if prefixes:
        for p in prefixes:
            if not any(k.startswith(p) for k in keys):
                raise UnknownNameError(f"no number starts with {p!r}; keys: {', '.join(keys)}")
        keys = [k for k in keys if any(k.startswith(p) for p in prefixes)]
    return {k: NUMBERS[k].text() for k in keys}


def fmt_list(fmt: str) -> Callable[[Any], str]:
    return lambda xs: ", ".join(fmt.format(x) for x in xs)


def yes_no(v: bool) -> str:
    return "yes" if v else "no"


# the declarations register themselves; imported last, once the registry exists
from analysis.figures.numbers import control, cspace, episodes  # noqa: E402, F401
