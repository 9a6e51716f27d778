"""``surveil figures``: regenerate the paper's figures, print or check the report's numbers.

::

    surveil figures                                   # every figure into out/figures/
    surveil figures --out docs/figures --report docs/REPRODUCTION.md   # the docs, one command
    surveil figures --only fig03 fig06-replay         # some of them (names or prefixes)
    surveil figures --list                            # names, paper figures, titles
    surveil figures --numbers corridor. fig11         # the quoted numbers (by key prefix)
    surveil figures --check docs/REPRODUCTION.md      # exit 1 if the report has drifted
    surveil figures --update docs/REPRODUCTION.md     # rewrite its numbers, draw nothing
"""

from __future__ import annotations

import argparse
import shutil
import sys
import tempfile
import time
from pathlib import Path

from analysis.arguments import output_dir, path_text
from envs.errors import InvalidConfigError
from envs.files import written_whole

__all__ = ["add_parser", "run"]

DEFAULT_OUT = Path("out") / "figures"


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the ``figures`` subcommand to the ``surveil`` parser."""
    p = subparsers.add_parser(
        "figures",
        help="regenerate the paper's figures (and check docs/REPRODUCTION.md)",
        description="Regenerate our version of every figure of the paper (PNGs and GIF "
        "replays), and print, check or update the numbers docs/REPRODUCTION.md quotes.",
    )
    p.add_argument(
        "--out",
        default=str(DEFAULT_OUT),
        type=path_text("a directory name ('.' for the current directory)"),
        help=f"directory (default: {DEFAULT_OUT})",
    )
    p.add_argument("--only", nargs="+", metavar="NAME", help="figure names or unique prefixes")
    p.add_argument("--scale", type=float, default=1.0, help="size factor in [0.25, 4] (default 1)")
    # one job per call: "--check F --update F" checked and said nothing of the update
    mode = p.add_mutually_exclusive_group()
    mode.add_argument("--list", action="store_true", help="list the figures and exit")
    mode.add_argument(
        "--numbers",
        nargs="*",
        metavar="PREFIX",
        help="print the report's numbers (optionally those whose key starts so)",
    )
    mode.add_argument(
        "--report",
        metavar="FILE",
        type=path_text("a file name"),
        help="after drawing, rewrite FILE's tagged numbers and figure gallery",
    )
    mode.add_argument(
        "--check",
        metavar="FILE",
        type=path_text("a file name"),
        help="only check FILE against the code: exit 1 listing what drifted",
    )
    mode.add_argument(
        "--update",
        metavar="FILE",
        type=path_text("a file name"),
        help="only rewrite FILE's tagged numbers and figure gallery (draw nothing)",
    )
    p.set_defaults(func=run)
    return p


def run(args: argparse.Namespace) -> int:
    """Run ``surveil figures``."""
    from analysis.figures.registry import build_figure, check_scale, select

    if args.list:
        for s in select(None):
            print(f"{s.name:<24} {s.paper:<32} {s.title}")
        return 0
    if args.numbers is not None:
        from analysis.figures.numbers import NUMBERS, compute_numbers

        for key, text in compute_numbers(args.numbers or None).items():
            print(f"{key:<30} {text:<24} {NUMBERS[key].what}")
        return 0
    if args.check:
        return _check(Path(args.check))
    if args.update:
        _update(Path(args.update), "--update")
        return 0
    specs = select(args.only)
    check_scale(args.scale)  # before drawing anything
    if args.report:
        _report_text(Path(args.report), "--report")
    out = output_dir("--out", args.out)  # made here; an existing file is refused up front
    from tqdm import tqdm

    bar = tqdm(specs, unit="figure", disable=not sys.stderr.isatty())
    for s in bar:
        bar.set_description(s.name)
        t0 = time.perf_counter()
        path = build_figure(s.name, out, scale=args.scale)
        size = path.stat().st_size / 1024
        tqdm.write(f"{path}  ({size:.0f} kB, {time.perf_counter() - t0:.1f} s)")
    if args.report:
        _update(Path(args.report), "--report")
    return 0


def _check(path: Path) -> int:
    from analysis.figures.numbers import compute_numbers
    from analysis.figures.report import check_report

    # not a report (a JSON file, an empty one) is exit 2, as for --update: it listed 122
    # "problems" (exit 1) and advised --update, which then refused the file
    text = _report_text(path, "--check")
    if not text.strip():
        raise InvalidConfigError(f"--check = {str(path)!r}: an empty file, not a report")
    problems = check_report(text, compute_numbers())
    for p in problems:
        print(f"{path}: {p}")
    if problems:
        print(
            f"{len(problems)} problem(s); rewrite the numbers with: surveil figures --update "
            f"{path} (or redraw and rewrite: --out docs/figures --report {path})"
        )
        return 1
    print(f"{path}: every quoted number matches the code")
    return 0


def _report_text(path: Path, flag: str) -> str:
    """The text of the report ``flag`` names: a file with tagged numbers or the gallery
    markers, or an empty one (it gets the gallery). Any other file is refused unchanged
    (the gallery was appended to whatever file was given, a JSON file included).

    Raises:
        InvalidConfigError: no such file, not a report, or (``--report``, ``--update``:
            it is to be rewritten) a file or folder that cannot be written.
    """
    from analysis.figures.report import BEGIN, END, read, tags

    try:
        text = read(path)
    except (OSError, UnicodeDecodeError) as exc:
        reason = getattr(exc, "strerror", None) or type(exc).__name__
        raise InvalidConfigError(f"{flag} = {str(path)!r}: cannot read it ({reason})") from None
    if text.strip() and not tags(text) and not (BEGIN in text and END in text):
        raise InvalidConfigError(
            f"{flag} = {str(path)!r}: not a report (no tagged number such as "
            f"31<!--n:corridor.regions--> and no {BEGIN} ... {END}); left unchanged"
        )
    if flag != "--check":  # it will be rewritten: said now, not after the drawing
        try:
            with path.open("r+b"), tempfile.TemporaryFile(dir=path.parent):
                pass  # the file and a new one beside it (the rewrite's) can be written
        except OSError as exc:
            reason = exc.strerror or type(exc).__name__
            raise InvalidConfigError(
                f"{flag} = {str(path)!r}: cannot write it ({reason}); left unchanged"
            ) from None
    return text


def _update(path: Path, flag: str) -> None:
    from analysis.figures.numbers import compute_numbers
    from analysis.figures.report import update_report

    text, changes = update_report(_report_text(path, flag), compute_numbers())
    # whole or not at all: an interrupted write truncated the report
    with written_whole(path, flag) as tmp:
        tmp.write_text(text, encoding="utf-8")
        shutil.copymode(path, tmp)
    for c in changes:
        print(f"{path}: {c}")
    print(f"{path}: {len(changes)} number(s) changed; gallery regenerated")
