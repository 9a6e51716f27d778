"""The paper's figures, reproduced from the library's public functions (issue 12).

``surveil figures [--out DIR] [--only NAME...]`` writes them (:mod:`analysis.figures.cli`);
:mod:`analysis.figures.registry` names each one with its builder and caption, in modules
by group (:mod:`~analysis.figures.configuration` Figs. 1-2,
:mod:`~analysis.figures.decomposition` Figs. 3-8, :mod:`~analysis.figures.bounded_speed`
Fig. 9, :mod:`~analysis.figures.evasion` Figs. 10-13, :mod:`~analysis.figures.cooperative`
Figs. 14-16, :mod:`~analysis.figures.replays` the GIFs), all drawing the computed cases of
:mod:`analysis.figures.cases`. :mod:`analysis.figures.numbers` computes every number that
``docs/REPRODUCTION.md`` quotes and :mod:`analysis.figures.report` checks the report
against them (or rewrites it).

Importing the package is cheap: the registry and the figure modules load on first use.
"""

from __future__ import annotations

from typing import Any

__all__ = ["FigureSpec", "build_figure", "figure_names", "figure_spec", "figure_specs"]


def __getattr__(name: str) -> Any:
    if name in __all__:
        from analysis.figures import registry

        return getattr(registry, name)
    raise AttributeError(f"module 'analysis.figures' has no attribute {name!r}")
