"""Scripted tournaments: spec, match identity, resumable store, backends, analysis, reports.

Python API::

    from analysis.tournament import load_spec, run_tournament, write_report
    summary = run_tournament("analysis/specs/quick.toml", "out/quick.sqlite")
    write_report("out/quick.sqlite", "out/quick_report")

Modules: :mod:`.spec` (TOML, validated), :mod:`.identity` (match identity), :mod:`.store`
(SQLite, WAL, one writer), :mod:`.worker` (one match, in any backend), :mod:`.executors`
(serial, process, Ray), :mod:`.driver` (resumable runs), :mod:`.statistics` (intervals,
payoff matrices, Nash, ratings, paired tests), :mod:`.report` (Markdown and HTML).
"""

from analysis.tournament.driver import RunSummary, default_store, run_tournament
from analysis.tournament.spec import Spec, load_spec, spec_from_dict
from analysis.tournament.store import Store, StoreBusyError, StoreError

__all__ = [
    "RunSummary",
    "Spec",
    "Store",
    "StoreBusyError",
    "StoreError",
    "default_store",
    "load_spec",
    "run_tournament",
    "spec_from_dict",
]
