"""``surveil tournament``, ``surveil report``, ``surveil export`` and the ``evaluate`` alias.

``surveil tournament SPEC`` plays a spec (a TOML file, or the name of a shipped spec:
``surveil tournament --list``) into a store, resuming what is already there, and prints
the overall table. ``surveil report STORE`` writes the Markdown and HTML report,
``surveil export STORE FILE.csv|FILE.jsonl`` flat files. ``surveil evaluate`` builds a
one-off spec from flags (the old interface) and runs it the same way.
"""

from __future__ import annotations

import argparse
import math
import sys
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING

from analysis.arguments import (
    MAP_HELP,
    integer,
    json_object,
    output_file,
    path_text,
    set_from_flag,
    why_not_a_file,
)
from envs.errors import InvalidConfigError
from envs.validation import writable_directory

if TYPE_CHECKING:
    from analysis.tournament.store import Store

__all__ = ["add_parsers", "format_cells", "shipped_specs"]

CONFIG_EXAMPLE = "'{\"v_evader\": 0.8}'"

EXIT_SIGNAL = {"SIGINT": 130, "SIGTERM": 143}
EXIT_ALL_ERRORS = 1
"""Exit code of a run (tournament, evaluate) whose every match ended in an error."""


def shipped_specs() -> dict[str, Path]:
    """The specs shipped in ``analysis/specs`` by name."""
    root = resources.files("analysis").joinpath("specs")
    return {
        p.name[: -len(".toml")]: Path(str(p)) for p in root.iterdir() if p.name.endswith(".toml")
    }


def _spec_path(text: str) -> Path:
    path = Path(text)
    problem = why_not_a_file(path)
    if problem is None:
        return path
    shipped = shipped_specs()
    if text in shipped:
        return shipped[text]
    if problem != "no such file":  # it exists, but is no spec file (/dev/null, a folder)
        raise InvalidConfigError(f"tournament spec {text!r}: {problem}")
    raise InvalidConfigError(
        f"tournament spec {text!r}: no such file and no shipped spec of that name; shipped "
        f"specs: {', '.join(sorted(shipped))}"
    )


def format_cells(cells, scope: str | None = None) -> str:
    """Plain-text table of cells (one scope, or all)."""
    head = ("scope", "pursuer", "evader", "n", "held [95% CI]", "mean escape s [95% CI]", "causes")
    body = []
    for c in cells:
        if scope is not None and c.scope != scope:
            continue
        esc = "-" if math.isnan(c.escape_mean) else f"{c.escape_mean:.2f}"
        if math.isfinite(c.escape_lo):
            esc += f" [{max(c.escape_lo, 0.0):.2f}, {c.escape_hi:.2f}]"
        rate = "-" if math.isnan(c.rate) else f"{c.rate:.2f} [{c.lo:.2f}, {c.hi:.2f}]"
        causes = ",".join(f"{k}:{v}" for k, v in sorted(c.causes.items()))
        body.append((c.scope, c.pursuer, c.evader, str(c.n), rate, esc, causes))
    widths = [max(len(row[i]) for row in [head, *body]) for i in range(len(head))]
    line = lambda cells: "  ".join(x.ljust(w) for x, w in zip(cells, widths, strict=True))
    return "\n".join([line(head), line(["-" * w for w in widths]), *map(line, body)])


def _print_outcome(
    summary,
    store: Path,
    report: str | None,
    replays: bool,
    regret: bool = True,
    retry: str | None = None,
) -> int:
    """Print the run's summary and overall table, write its report; the exit code.

    ``retry``: the command that plays the run's error matches again (said when there
    are some: a worker that died, killed by the OOM killer or a node lost, left its
    match an error that a plain rerun keeps)."""
    from analysis.tournament import statistics as st
    from analysis.tournament.report import write_report
    from analysis.tournament.store import Store

    print(summary.describe())
    with Store(store, create=False) as db:
        rows = db.rows(summary.run_id)
        failed = [r for r in rows if r["status"] == "error"]
        cells = st.cells(rows)
        scopes = {c.scope for c in cells}
        print(format_cells(cells, st.OVERALL if st.OVERALL in scopes else None))
        if failed and retry is not None and len(failed) < len(rows):
            print(
                f"{len(failed)} of its matches are stored as errors, won by nobody (the "
                f"first: {failed[0]['error']}); a rerun keeps them; to play them again: "
                f"{retry} --retry-errors"
            )
        if report:
            _announce_report(report, replays, regret, skip="--no-report skips it")
            files = write_report(
                db, report, run_id=summary.run_id, replays=replays, regret=regret, say=_say
            )
            print(f"report written to {files['html']} and {files['markdown']}")
    if summary.interrupted:
        return EXIT_SIGNAL.get(summary.interrupted, 130)
    if rows and len(failed) == len(rows):  # nothing was played: not a success
        again = f"; once that is fixed, to play them again: {retry} --retry-errors"
        print(
            f"surveil: error: every one of the {len(rows)} matches of run {summary.run_id} "
            f"in {store} ended in an error, the first: {failed[0]['error']}"
            + (again if retry else ""),
            file=sys.stderr,
        )
        return EXIT_ALL_ERRORS
    return 0


def _cmd_tournament(args: argparse.Namespace) -> int:
    from analysis.tournament.driver import default_store, run_tournament
    from analysis.tournament.spec import load_spec

    if args.list:
        if args.spec is not None:  # it was listed past without a word
            raise InvalidConfigError(
                f"tournament --list takes no SPEC, got {args.spec!r}; give one or the other"
            )
        import warnings

        for name, path in sorted(shipped_specs().items()):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # listing is not running
                spec = load_spec(path)
            print(f"{name:<14} {spec.description}")
        return 0
    if args.spec is None:
        raise InvalidConfigError(
            "tournament SPEC: missing; expected a .toml file or a shipped spec's name "
            "(`surveil tournament --list` lists them)"
        )
    path = _spec_path(args.spec)
    spec = load_spec(path)
    store = Path(args.store) if args.store else default_store(spec)
    if args.report is not None or args.report_default:
        # before the run: a file there failed only after every match ("x: File exists")
        where = args.report or str(store.with_name(store.stem + "_report"))
        writable_directory("--report", where, "(or --no-report)")
    hint = f"surveil tournament {args.spec} --store {store}"
    if args.backend != "process":
        hint += f" --backend {args.backend}"
    if args.workers is not None:  # else the resumed run took every core
        hint += f" --workers {args.workers}"
    if args.address is not None:
        hint += f" --address {args.address}"
    summary = run_tournament(
        spec,
        store,
        backend=args.backend,
        workers=args.workers,
        address=args.address,
        retry_errors=args.retry_errors,
        progress=not args.no_progress,
        resume_hint=hint,
    )
    report = args.report
    if report is None and not summary.interrupted and args.report_default:
        report = str(store.with_name(store.stem + "_report"))
    return _print_outcome(
        summary, store, report, not args.no_replays, not args.no_regret, retry=hint
    )


def _say(text: str) -> None:
    print(text, file=sys.stderr, flush=True)


def _announce_report(out: str, replays: bool, regret: bool = True, skip: str = "") -> None:
    """Say on stderr what the report is about to do: its regret table solves the referee's
    game of every map and parameter set the run played (a tournament's report sat silent
    for 13 minutes after its table: 9 games at 16 cells per L_min, under load)."""
    from strategies.referee.regrets import DEFAULT_CELLS_PER_LMIN

    extra = "; the replays re-simulate the decisive matches" if replays else ""
    what = (
        "its regret table solves the referee's game of each map and parameter set played "
        f"({DEFAULT_CELLS_PER_LMIN:g} cells per L_min; cached, so it can take minutes the "
        "first time and seconds after; --no-regret skips it)"
        if regret
        else "without the regret table (--no-regret)"
    )
    _say(f"writing the report to {out}: {what}{extra}" + (f"; {skip}" if skip else ""))


def _cmd_report(args: argparse.Namespace) -> int:
    from analysis.tournament.report import write_report
    from analysis.tournament.store import Store

    store = Path(args.store)
    out = args.out or str(store.with_name(store.stem + "_report"))
    writable_directory("--out", out)  # was "x: File exists" from the mkdir
    with Store(store, create=False) as db:
        run = db.run(args.run)  # a bad store or run is refused before the announcement
        _warn_doubled(db, run["run_id"])
        regret = not args.no_regret
        _announce_report(out, not args.no_replays, regret)
        files = write_report(
            db, out, run_id=args.run, replays=not args.no_replays, regret=regret, say=_say
        )
    print(f"report written to {files['html']} and {files['markdown']}")
    return 0


def _cmd_export(args: argparse.Namespace) -> int:
    from analysis.tournament.store import Store

    out = output_file(
        "out", args.out, suffixes=(".csv", ".jsonl", ".ndjson"), default_name="results.csv"
    )
    with Store(args.store, create=False) as db, db.snapshot():  # counts agree with the rows
        run = db.run(args.run)
        path = db.export(run["run_id"], out)
        line = f"{len(db.rows(run['run_id']))} matches of run {run['run_id']} written to {path}"
        if run["done"] < run["planned"] and run["status"] != "decided":  # said nothing
            line += (
                f"; the run is {run['status']} with {run['done']} of its {run['planned']} "
                "planned matches stored: these are not its results (rerun its tournament to "
                "finish it)"
            )
        print(line)
        _warn_doubled(db, run["run_id"])
    return 0


def _warn_doubled(db: Store, run_id: str) -> None:
    """Say on stderr that the run counts some starts twice (the report says it too)."""
    from analysis.tournament.report import doubled_note

    doubled = db.doubled(run_id)
    if doubled:
        _say(f"warning: {doubled_note(run_id, doubled)}")


def _cmd_evaluate(args: argparse.Namespace) -> int:
    from analysis.tournament.driver import run_tournament
    from analysis.tournament.spec import spec_from_dict

    env = json_object("--config", args.config, example=CONFIG_EXAMPLE)
    set_from_flag(env, "max_cycles", "--max-cycles", args.max_cycles)
    plot = None  # checked now, drawn after the run
    if args.plot:
        plot = output_file("--plot", args.plot, suffixes=(".png",), default_name="evaluate.png")
    store = Path(args.results or "out/evaluate.sqlite")
    if store.suffix.lower() in (".jsonl", ".json", ".csv", ".ndjson"):
        raise InvalidConfigError(
            f"--results {store}: results now go to a SQLite store (e.g. out/evaluate.sqlite); "
            "write flat files with: surveil export STORE FILE.csv"
        )
    spec = spec_from_dict(
        {
            "name": "evaluate",
            "maps": args.maps,
            "pursuers": list(args.pursuers),
            "evaders": list(args.evaders),
            "seeds": args.seeds,
            "start": args.start,
            "env": env,
        },
        source="surveil evaluate",
        # its fields came from flags: '--maps #1: ...', not 'surveil evaluate [maps #1]: ...'
        # (after 'surveil: error:', the program named twice)
        flags={
            "maps": "--maps",
            "pursuers": "--pursuers",
            "evaders": "--evaders",
            "env": "--config",
        },
    )
    summary = run_tournament(
        spec,
        store,
        backend="serial" if args.workers == 1 else "process",
        workers=args.workers,
        progress=not args.no_progress,
        resume_hint="the same surveil evaluate command",
    )
    code = _print_outcome(summary, store, None, False)
    if plot is not None:
        from analysis.tournament import statistics as st
        from analysis.tournament.report import heatmaps_png
        from analysis.tournament.store import Store

        with Store(store, create=False) as db:
            cells = st.cells(db.rows(summary.run_id))
        plot.write_bytes(heatmaps_png(st.payoff_matrices(cells), cells))
        print(f"table picture written to {plot}")
    return code


NO_REGRET_HELP = (
    "report without the regret table (it solves the referee's game of each map and "
    "parameter set played: seconds to hours the first time, cached after)"
)


def add_parsers(sub: argparse._SubParsersAction) -> None:
    """Add ``tournament``, ``report``, ``export`` and ``evaluate`` to the ``surveil`` CLI."""
    p = sub.add_parser(
        "tournament",
        help="play a tournament spec into a resumable store (see analysis/specs)",
        description="Play every match of a TOML spec, storing each as it finishes; rerun to "
        "resume. Ctrl-C stops cleanly.",
    )
    p.add_argument("spec", nargs="?", help="a spec file, or a shipped spec's name (--list)")
    p.add_argument("--list", action="store_true", help="list the shipped specs")
    p.add_argument(
        "--store",
        type=path_text("a file name or a directory"),
        help="SQLite store (default: out/tournaments/NAME.sqlite)",
    )
    p.add_argument(
        "--backend",
        choices=["serial", "process", "ray"],
        default="process",
        help="where matches play: this process, a process pool (default) or Ray (a local "
        "instance, or the cluster at --address)",
    )
    p.add_argument("--workers", type=integer(1), default=None, help="processes, or local Ray CPUs")
    p.add_argument("--address", help="Ray cluster address (with --backend ray)")
    p.add_argument("--retry-errors", action="store_true", help="replay matches stored as errors")
    p.add_argument(
        "--report",
        type=path_text("a directory name ('.' for the current directory)"),
        help="also write the report to this directory",
    )
    p.add_argument(
        "--no-report",
        dest="report_default",
        action="store_false",
        help="do not write the report beside the store when the run completes",
    )
    p.add_argument("--no-replays", action="store_true", help="report without GIF replays")
    p.add_argument("--no-regret", action="store_true", help=NO_REGRET_HELP)
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.set_defaults(func=_cmd_tournament)

    p = sub.add_parser("report", help="write a tournament's Markdown and HTML report")
    p.add_argument("store", help="the tournament's SQLite store")
    p.add_argument("--run", help="run id (prefix) or name (default: the latest)")
    p.add_argument(
        "--out",
        type=path_text("a directory name ('.' for the current directory)"),
        help="directory (default: STORE_report beside the store)",
    )
    p.add_argument("--no-replays", action="store_true", help="skip the GIF replays")
    p.add_argument("--no-regret", action="store_true", help=NO_REGRET_HELP)
    p.set_defaults(func=_cmd_report)

    p = sub.add_parser("export", help="export a tournament's results as CSV or JSON lines")
    p.add_argument("store", help="the tournament's SQLite store")
    p.add_argument(
        "out",
        type=path_text("a file name or a directory"),
        help="FILE.csv, FILE.jsonl or FILE.ndjson",
    )
    p.add_argument("--run", help="run id (prefix) or name (default: the latest)")
    p.set_defaults(func=_cmd_export)

    p = sub.add_parser(
        "evaluate", help="quick matchup table from flags (a one-off tournament spec)"
    )
    # the help names each default: `surveil evaluate --maps corridor` plays a roster the
    # user never typed
    maps, pursuers = ["corridor", "two_rooms"], ["pursuer/decomposition", "pursuer/greedy"]
    evaders = ["evader/shooting", "evader/straight"]
    p.add_argument("--maps", nargs="+", default=maps,
                   help=f"each {MAP_HELP} (default: {' '.join(maps)})")  # fmt: skip
    roster = "policy names, zoo:NAME (a shipped model) or a model .zip"
    p.add_argument("--pursuers", nargs="+", default=pursuers,
                   help=f"{roster} (default: {' '.join(pursuers)})")  # fmt: skip
    p.add_argument("--evaders", nargs="+", default=evaders,
                   help=f"{roster} (default: {' '.join(evaders)})")  # fmt: skip
    p.add_argument("--seeds", type=integer(1), default=10,
                   help="number of seeded starts per match (>= 1; default: 10)")  # fmt: skip
    p.add_argument("--max-cycles", type=integer(1), default=None,
                   help="episode horizon in steps (>= 1)")  # fmt: skip
    p.add_argument("--config", help=f"env overrides as JSON, e.g. {CONFIG_EXAMPLE}")
    p.add_argument(
        "--start",
        choices=["safe", "valid"],
        default="safe",
        help="starts in a non-escapable cell at L_min (safe) or any valid one",
    )
    p.add_argument("--workers", type=integer(1), default=1, help="processes to play in")
    p.add_argument(
        "--results",
        type=path_text("a file name or a directory"),
        help="SQLite store (default: out/evaluate.sqlite; resumable)",
    )
    p.add_argument(
        "--plot",
        type=path_text("a file name or a directory"),
        help="also draw the table as heat maps to this PNG",
    )
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.set_defaults(func=_cmd_evaluate)


if __name__ == "__main__":  # pragma: no cover
    sys.exit("use: surveil tournament SPEC")
