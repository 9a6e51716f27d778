"""The registry of the paper's figures: name -> builder, caption, file kind.

Every figure module registers its builders with :func:`register` on import; the package
imports them all, in paper order, the first time the registry is read
(:func:`figure_specs`). A builder takes the output path and a size factor and writes one
file: a PNG (matplotlib) or a GIF (an episode replay).
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path

from envs.errors import InvalidConfigError, UnknownNameError
from envs.files import written_whole
from envs.validation import positive

MAX_SCALE = 4.0
"""Largest size factor (a 4x documentation figure is already a few thousand pixels wide)."""
MIN_SCALE = 0.25
"""Smallest size factor: below it the smaller replays (Fig. 9's and footnote 4's, drawn at 0.8
times the factor) would fall under the 60-pixel floor of ``replays._size`` and, under 0.2,
the PNGs under the 20 dpi floor of ``style.save_png``: a smaller factor was silently drawn
larger than asked."""

__all__ = [
    "FigureSpec",
    "build_figure",
    "check_scale",
    "figure_names",
    "figure_spec",
    "figure_specs",
    "register",
    "select",
]

KINDS = ("png", "gif")
"""File kinds a builder may write."""

_MODULES = (
    "analysis.figures.configuration",
    "analysis.figures.decomposition",
    "analysis.figures.bounded_speed",
    "analysis.figures.evasion",
    "analysis.figures.cooperative",
    "analysis.figures.replays",
)
"""Figure modules, imported in this order (paper order within each)."""

Builder = Callable[[Path, float], None]


@dataclass(frozen=True)
class FigureSpec:
    """One figure of the reproduction.

    Attributes:
        name: file stem and CLI name, e.g. ``"fig03-corridor"``.
        paper: what it reproduces, e.g. ``"Fig. 3"`` (or ``"Sec. 5, footnote 4"``).
        title: a few words.
        caption: what it shows and which equation or proposition it illustrates.
        kind: ``"png"`` or ``"gif"``.
        build: ``build(path, scale)`` writes the file; ``scale`` multiplies its size.
    """

    name: str
    paper: str
    title: str
    caption: str
    kind: str
    build: Builder

    @property
    def filename(self) -> str:
        """The file name the figure is written to."""
        return f"{self.name}.{self.kind}"


_REGISTRY: dict[str, FigureSpec] = {}


def register(
    name: str, *, paper: str, title: str, caption: str, kind: str = "png"
) -> Callable[[Builder], Builder]:
    """Decorator registering a builder under ``name``.

    Raises:
        InvalidConfigError: duplicate name or unknown kind.
    """
    if kind not in KINDS:
        raise InvalidConfigError(f"figure {name!r}: kind = {kind!r}, expected one of {KINDS}")

    def deco(build: Builder) -> Builder:
        if name in _REGISTRY:
            raise InvalidConfigError(f"figure {name!r} is already registered")
        _REGISTRY[name] = FigureSpec(name, paper, title, " ".join(caption.split()), kind, build)
        return build

    return deco


def _load() -> None:
    for module in _MODULES:
        importlib.import_module(module)


def figure_specs() -> tuple[FigureSpec, ...]:
    """Every registered figure, in paper order."""
    _load()
    return tuple(_REGISTRY.values())


def figure_names() -> list[str]:
    """The names of every registered figure, in paper order."""
    return [s.name for s in figure_specs()]


def figure_spec(name: str) -> FigureSpec:
    """The figure called ``name``, or the only one whose name starts with ``name``.

    Raises:
        UnknownNameError: no figure or several figures match (the message lists them).
    """
    specs = {s.name: s for s in figure_specs()}
    if name in specs:
        return specs[name]
    hits = [s for n, s in specs.items() if isinstance(name, str) and n.startswith(name)]
    if len(hits) == 1:
        return hits[0]
    if hits:
        raise UnknownNameError(
            f"figure {name!r} is ambiguous: it begins {', '.join(s.name for s in hits)}"
        )
    raise UnknownNameError(f"unknown figure {name!r}; known figures: {', '.join(specs)}")


def select(names: Iterable[str] | None) -> tuple[FigureSpec, ...]:
    """The figures named, in paper order: a name selects itself, a prefix every figure it
    begins (``fig03`` is the picture and the replay); all of them for ``None``.

    Raises:
        UnknownNameError: a name that is neither (the message lists the figures).
    """
    specs = figure_specs()
    if names is None:
        return specs
    wanted: set[str] = set()
    for n in names:
        hits = [s.name for s in specs if s.name == n] or [
            s.name for s in specs if isinstance(n, str) and n and s.name.startswith(n)
        ]
        if not hits:
            figure_spec(n)  # raises with the list of names
        wanted.update(hits)
    return tuple(s for s in specs if s.name in wanted)


def check_scale(scale: object) -> float:
    """``scale`` as a float in [:data:`MIN_SCALE`, :data:`MAX_SCALE`], or InvalidConfigError
    naming it."""
    value = positive("scale", scale)
    if not MIN_SCALE <= value <= MAX_SCALE:
        raise InvalidConfigError(
            f"scale = {scale!r}: expected a size factor in [{MIN_SCALE:g}, {MAX_SCALE:g}]"
        )
    return value


def build_figure(name: str, out_dir: str | Path, *, scale: float = 1.0) -> Path:
    """Build one figure into ``out_dir`` (created if missing) and return its path.

    Args:
        name: a figure name or unique prefix (:func:`figure_names`).
        out_dir: output directory.
        scale: size factor in [0.25, 4] (1 for the documentation; smaller is faster).
    """
    spec = figure_spec(name)
    scale = check_scale(scale)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    path = out / spec.filename
    # drawn beside it, then renamed: an interrupted build (Ctrl-C while a GIF's frames are
    # encoded) leaves the previous figure whole, not a truncated file in docs/figures
    from analysis.figures.style import context

    with written_whole(path, "figure") as tmp, context():
        spec.build(tmp, scale)
    return path
