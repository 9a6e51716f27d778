"""The ``train`` command: argument parsing for ``surveil train`` and ``python -m training``.

``analysis.cli`` wires its ``train`` subcommand to :func:`add_train_arguments` and
:func:`run_train`, or simply calls :func:`cli_train` with the remaining arguments.
"""

from __future__ import annotations

import argparse
import math
import os
import signal
import sys
import threading
import warnings
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from envs import validation
from envs.console import (
    EXIT_READER_GONE,
    OneLineWarnings,
    interrupts_recorded,
    progress_flags,
    reader_gone,
)
from envs.errors import InvalidConfigError, SurveilValueError
from training.config import TrainConfig, load_any_config
from training.selfplay import self_play
from training.train import TrainResult, latest_checkpoint, train

if TYPE_CHECKING:
    from training.dagger import DaggerConfig

__all__ = ["add_train_arguments", "cli_train", "run_cli", "run_train"]


def add_train_arguments(parser: argparse.ArgumentParser) -> argparse.ArgumentParser:
    """Add the ``train`` options to ``parser`` (a subparser of ``surveil``)."""
    parser.add_argument("config", help="TOML training config (see training/configs/)")
    parser.add_argument("--output-dir", default=None, help="override output_dir")
    parser.add_argument("--timesteps", type=int, default=None, help="override total_timesteps")
    parser.add_argument("--seed", type=int, default=None, help="override seed")
    parser.add_argument(
        "--self-play",
        type=int,
        default=None,
        metavar="ROUNDS",
        help="alternate ROUNDS (>= 1) rounds of pursuer/evader training instead of one run",
    )
    progress_flags(
        parser,
        "no progress (default: a bar on a terminal, else a line per tenth of the "
        "timesteps or per DAgger episode, on stderr)",
    )
    return parser


def run_train(args: argparse.Namespace) -> int:
    """Run a parsed ``train`` command; prints one line per trained model. Returns 0.

    Raises:
        InvalidConfigError: a bad config file or override (naming the field).
    """
    # the flags' values are named as flags, not as fields of the config file
    if args.timesteps is not None:
        validation.integer("--timesteps", args.timesteps, minimum=1)
    if args.seed is not None:
        validation.integer("--seed", args.seed, minimum=0)
    if args.self_play is not None:  # 0 ran one plain run without a word
        validation.integer("--self-play", args.self_play, minimum=1)
    overrides = {}
    if args.output_dir is not None:
        overrides["output_dir"] = args.output_dir
    if args.seed is not None:
        overrides["seed"] = args.seed
    with interrupts_recorded() as ctrl_c:  # imports for seconds: a Ctrl-C lands here
        config = load_any_config(args.config, **overrides)
        import stable_baselines3  # noqa: F401  (training's import, torch's: seconds)
    if ctrl_c.seen:  # one CPython discarded in an import's callback: honoured now
        raise KeyboardInterrupt
    validation.writable_directory("output_dir", os.fspath(config.output_dir))
    progress = not args.no_progress  # as python -m training.zoo reproduce: on unless told
    if not isinstance(config, TrainConfig):  # a DAgger recipe
        if args.timesteps is not None or args.self_play is not None:
            raise InvalidConfigError(
                f"{args.config}: --timesteps and --self-play apply to RL configs; this is a "
                "DAgger config (set iterations and episodes in the file)"
            )
        from training.dagger import dagger

        try:
            r = dagger(config, verbose=progress)
        except KeyboardInterrupt:
            print(resume_note(config), file=sys.stderr)
            raise
        print(f"dagger {config.role}: {r.samples[-1]} labelled states, disagreement "
              f"{r.disagreement[0]:.3f} -> {r.disagreement[-1]:.3f} -> {r.model_path}")  # fmt: skip
        return 0
    if args.timesteps is not None:
        config = config.replace(total_timesteps=args.timesteps)
    if args.self_play is not None:
        try:
            results = self_play(config, args.self_play, progress_bar=progress).stages
        except KeyboardInterrupt:
            print(
                "stopped: rerun the same command to resume (finished stages are kept, the "
                f"interrupted one continues from its checkpoints under {config.output_dir})",
                file=sys.stderr,
            )
            raise
    else:
        try:
            results = (train(config, progress_bar=progress),)
        except KeyboardInterrupt:
            print(resume_note(config), file=sys.stderr)
            raise
    for r in results:
        print(summary(r))
    return 0


def resume_note(config: TrainConfig | DaggerConfig) -> str:
    """What an interrupted run kept: the checkpoint (an RL run) or the iterations (a DAgger
    run) a rerun continues from, or nothing."""
    if not isinstance(config, TrainConfig):
        return _dagger_resume_note(config)
    latest = latest_checkpoint(config.output_dir)
    if latest is None:
        return (
            f"stopped before the first checkpoint (every checkpoint_freq = "
            f"{config.checkpoint_freq:,} timesteps): a rerun starts over"
        )
    done, path = latest
    return (
        f"stopped: {done:,} of {config.total_timesteps:,} timesteps are in {path}; rerun the "
        "same command to resume from there"
    )


def _dagger_resume_note(config) -> str:
    """What an interrupted DAgger run kept (its finished iterations), for the terminal."""
    import json

    progress = Path(config.output_dir) / "progress.json"
    try:
        done = len(json.loads(progress.read_text())["samples"])
    except (OSError, ValueError, KeyError, TypeError):
        done = 0
    if done == 0:
        return "stopped before the first iteration finished: a rerun starts over"
    return (
        f"stopped: {done} of {config.iterations} iterations are in {config.output_dir}; "
        "rerun the same command to resume from there"
    )


def cli_train(argv: Sequence[str] | None = None) -> int:
    """``python -m training CONFIG [--output-dir D] [--timesteps N] [--seed S] [--self-play R]
    [--no-progress]``.

    Progress goes to stderr unless ``--no-progress``: a bar on a terminal, else a line
    per tenth of an RL run's timesteps or per DAgger episode (and a DAgger iteration's
    line on stdout).

    Args:
        argv: the arguments (``None``: ``sys.argv[1:]``).

    Returns:
        The exit code: 0, 2 for a user error (one line on stderr naming the value), 130
        when interrupted. A traceback means a bug.
    """
    parser = add_train_arguments(
        argparse.ArgumentParser(prog="python -m training", description="Train a policy with SB3.")
    )
    return run_cli(
        "python -m training", lambda: run_train(parser.parse_args(None if argv is None else argv))
    )


def run_cli(prog: str, func: Callable[[], int]) -> int:
    """Run a command's body under the project's error contract.

    User errors (the project's ``SurveilValueError``, files that cannot be read or
    written) print one line ``PROG: error: ...`` and return 2; Ctrl-C returns 130;
    SIGTERM returns 143 (cleaning up as on Ctrl-C); a reader of the output that left
    (``| head``) returns 141 silently; argparse's own exits pass through;
    anything else is a bug and keeps its traceback.
    """
    previous = None
    if threading.current_thread() is threading.main_thread():  # SIGTERM stops as Ctrl-C does
        previous = signal.signal(signal.SIGTERM, _raise_sigterm)
    shown = warnings.showwarning  # each warning once, one line, as surveil shows them
    warnings.showwarning = OneLineWarnings(shown, prog)
    try:
        code = int(func() or 0)
        if sys.stdout is not None:  # a reader gone (`| head`) is met here, not at exit
            sys.stdout.flush()
        return code
    except SystemExit as exc:  # argparse: --help (0) or a usage error (2, already printed)
        return exc.code if isinstance(exc.code, int) else 2
    except BrokenPipeError as exc:
        if reader_gone():
            return EXIT_READER_GONE
        print(f"{prog}: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt as exc:
        if str(exc) == "SIGTERM":
            print(f"{prog}: stopped by SIGTERM", file=sys.stderr)
            return 143
        print(f"{prog}: interrupted", file=sys.stderr)
        return 130
    except (SurveilValueError, OSError) as exc:
        if isinstance(exc, OSError) and exc.filename is not None and exc.strerror:
            message = f"{exc.filename}: {exc.strerror}"
        else:
            message = str(exc) or type(exc).__name__
        print(f"{prog}: error: {message}", file=sys.stderr)
        return 2
    finally:
        warnings.showwarning = shown
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)


def _raise_sigterm(signum: int, frame: object) -> None:
    """SIGTERM (``kill``, ``timeout``) as a KeyboardInterrupt: the resume note is printed
    and temporary files are cleaned up, as on Ctrl-C (it was the default action: no word)."""
    raise KeyboardInterrupt("SIGTERM")


def summary(result: TrainResult) -> str:
    """One line: what was trained, for how long, where, and how it did."""
    c = result.config
    head = (
        f"{c.algo.upper()} {c.role} vs {_opponents(c)} on {', '.join(c.maps)}: "
        f"{result.timesteps} timesteps"
        # a finished run returned as is was "71680 timesteps in 0.0 s"
        + (" (already trained)" if result.already_trained else f" in {result.wall_time:.1f} s")
        + (f" (resumed from {result.resumed_from.name})" if result.resumed_from else "")
        + f" -> {result.model_path}"
    )
    ev = result.evaluation
    if ev is None:
        return head
    t = "-" if math.isnan(ev.mean_escape_time) else f"{ev.mean_escape_time:.2f} s"
    return head + (
        f"; eval: success {ev.successes}/{ev.episodes} ({ev.success_rate:.0%}), "
        f"mean escape time {t}"
    )


def _opponents(config: TrainConfig) -> str:
    """The opponent(s) as the config names them, a pool as a list with each member's share
    (was a Python tuple: ``('evader/straight', 'evader/shooting')``)."""
    pool = (config.opponent,) if isinstance(config.opponent, str) else config.opponent
    if not config.opponent_weights:
        return ", ".join(pool)
    total = sum(config.opponent_weights)
    shares = (w / total for w in config.opponent_weights)
    return ", ".join(f"{name} ({p:.0%})" for name, p in zip(pool, shares, strict=True))
