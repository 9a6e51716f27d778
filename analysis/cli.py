"""The ``surveil`` command line.

``surveil play`` is the main job: one episode on a built-in world between two registered
policies, its outcome printed and its replay written to a GIF. The other subcommands list
maps, draw the configuration-space decomposition of a world, draw the optimal-control
figures of the paper, and play tournaments between policies (``surveil tournament``,
``surveil report``; ``surveil evaluate`` is a quick one-off tournament from flags).
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
import warnings
from collections.abc import Sequence
from pathlib import Path

from analysis import referee_cli
from analysis.arguments import (
    MAP_HELP,
    Parser,
    check_env_options,
    integer,
    interrupts_recorded,
    json_object,
    output_dir,
    output_file,
    path_text,
    reader_gone,
    real,
    say_warnings,
    set_from_flag,
    sigterm_as_interrupt,
    user_error,
    warnings_held,
)
from analysis.figures import cli as figures_cli
from analysis.replay import DEFAULT_FPS, MAX_FPS
from envs.console import OneLineWarnings
from envs.errors import InvalidConfigError, OutputError, SurveilValueError, UnknownNameError

__all__ = ["build_parser", "main"]

DEFAULT_OUT = Path("out")
PARAMS_EXAMPLE = "'{\"gain\": 2.0}'"
FIGURE_EXAMPLE = "'{\"rho\": 0.5}'"
CONFIG_EXAMPLE = "'{\"v_evader\": 0.8}'"


def _cmd_maps(args: argparse.Namespace) -> int:
    from envs.maps import builtin_info, builtin_names

    out = output_dir("--plot", args.plot) if args.plot is not None else None  # '' refused
    for name in builtin_names():
        info = builtin_info(name)
        m = info.map
        print(
            f"{name:<12} {m.n_vertices:>4} vertices  L_min={info.l_min:g} L_max={info.l_max:g} "
            f"v_p={info.v_pursuer:g} v_e={info.v_evader:g}  {info.description}"
        )
        if out is not None:
            from envs.maps.plot import plot_map

            plot_map(m, path=out / f"{name}.png")
    if out is not None:
        print(f"wrote map pictures to {out}/")
    return 0


def _cmd_policies(args: argparse.Namespace) -> int:
    from strategies.policies import describe_policy, policy_names

    for name in policy_names(args.role):
        print(f"{name:<26} {describe_policy(name)}")
    print(
        "learned policies: ROLE/sb3:PATH (a stable-baselines3 model zip); play, evaluate, "
        "tournament rosters and training opponents also take zoo:NAME (python -m "
        "training.zoo list) or a model .zip, tournament specs { model = ... }"
    )
    return 0


def _env_config(flag_map: str, map_: str, overrides: dict, where: str):
    """The env config of a run, validated before the run (names the flag at fault)."""
    from envs.maps.io import recommended_parameters
    from envs.surveillance.config import EnvConfig, resolve_map

    check_env_options(overrides, where)
    try:
        world = resolve_map(map_)
        # a built-in or a file by name (transformed or not): its recommendations apply
        named = recommended_parameters(map_) is not None
    except SurveilValueError as exc:
        raise type(exc)(f"{flag_map}: {exc}") from None
    try:
        return EnvConfig(map=map_ if named else world, **overrides)
    except SurveilValueError as exc:
        raise type(exc)(f"{where}: {exc}") from None


def _policy(flag: str, name: str, params_flag: str, params_text: str | None):
    """The policy a flag names, with the parameters of its ``-params`` flag, checked."""
    from strategies.policies import make_policy
    from strategies.policies.model_files import is_model_reference, model_policy_name

    params = json_object(params_flag, params_text, example=PARAMS_EXAMPLE)
    role = flag.lstrip("-")
    given = name
    if name.startswith(f"{role}/sb3:"):  # the registry's name of a model file (surveil policies)
        name = name.removeprefix(f"{role}/sb3:")
    elif name.startswith(("pursuer/sb3:", "evader/sb3:")):
        raise InvalidConfigError(
            f"{flag} = {name!r}: expected a policy name of the form '{role}/KIND' "
            "(see surveil policies)"
        )
    if is_model_reference(name):  # zoo:NAME or a .zip, as surveil evaluate takes them
        # a refusal names the model as the user did (was the zip's absolute path)
        name = model_policy_name(name, role, f"{flag}: model = {name!r}")
    if not name.startswith(f"{role}/"):
        raise InvalidConfigError(
            f"{flag} = {name!r}: expected a policy name of the form '{role}/KIND' "
            "(see surveil policies)"
        )
    try:
        policy = make_policy(name, **params)
    except UnknownNameError as exc:
        raise UnknownNameError(f"{flag}: {exc}") from None
    except SurveilValueError as exc:  # say which flag brought the value
        raise type(exc)(f"{params_flag if params else flag}: {exc}") from None
    if name != given:  # a model: its warnings and errors name it as the user did
        policy.name = given  # (was 'pursuer/sb3:/abs/path/training/zoo/models/.../model.zip')
    return policy


def _cmd_play(args: argparse.Namespace) -> int:
    from envs.errors import MemoryBudgetError
    from strategies.runner import VALID_START, run_episode

    # everything is checked before the episode: options, policies, the output file
    overrides = json_object("--config", args.config, example=CONFIG_EXAMPLE)
    set_from_flag(overrides, "max_cycles", "--max-cycles", args.max_cycles)
    with warnings_held() as held:  # a legal config's warnings: said if nothing is refused
        config = _env_config("--map", args.map, overrides, "--config")
        pursuer = _policy("--pursuer", args.pursuer, "--pursuer-params", args.pursuer_params)
        evader = _policy("--evader", args.evader, "--evader-params", args.evader_params)
        out = None
        if args.no_gif:  # a replay asked for and not written, without a word
            asked = (("--out", args.out), ("--overlay", args.overlay), ("--fps", args.fps))
            given = [f for f, v in asked if v]
            if given:
                raise InvalidConfigError(
                    f"--no-gif writes no replay; {' and '.join(given)} "
                    f"{'are' if len(given) > 1 else 'is'} for the replay: give one or the other"
                )
        else:
            where = args.out if args.out is not None else str(DEFAULT_OUT / "play.gif")
            out = output_file("--out", where, suffixes=(".gif", ".png"), default_name="play.gif")
    say_warnings(held)
    fps = DEFAULT_FPS if args.fps is None else args.fps
    shading: tuple = ()
    if args.overlay and out is not None:
        from analysis.overlay import decomposition_shading

        shading = decomposition_shading(config.map, config.l_min)
    stream = None
    if out is not None and out.suffix.lower() == ".gif":
        from analysis.replay import GifStream

        stream = GifStream(out, fps)  # frames go to the file as they are drawn
    try:
        try:
            result = run_episode(
                args.map,
                pursuer,
                evader,
                seed=args.seed,
                overrides=overrides,
                start=args.start,
                on_frame=stream if stream is not None and not shading else None,
            )
        except MemoryBudgetError as exc:  # the safe start's judge: this command's --start
            if exc.args[1] != VALID_START:
                raise
            raise exc.named("--start valid") from None
        shown = {  # a model as the user named it (as evaluate's and tournament's labels do),
            # not the sb3:PATH it was loaded from nor 'pursuer//abs/path/model.zip'
            role: name
            for role, name in (("pursuer", args.pursuer), ("evader", args.evader))
            if name.startswith("zoo:") or name.endswith(".zip")
        }
        print(dataclasses.replace(result, **shown).summary())
        if stream is not None and shading:  # redraw under the overlay, one frame at a time
            from analysis.replay import iter_trajectory_frames

            for frame in iter_trajectory_frames(result, shading=shading):
                stream.add(frame)
        if stream is not None:
            stream.close()
    except BaseException:
        if stream is not None:
            stream.abort()
        raise
    if out is not None and stream is None:  # a PNG strip: a few frames from the trajectory
        from analysis.replay import write_replay

        write_replay(result, out, decomposition=args.overlay, fps=fps)
    if out is not None:
        print(f"replay written to {out}")
    return 0


def _picture_file(out: str | None, default_name: str) -> Path:
    """``--out`` of a command that draws one picture (.png, .pdf or .svg): the file it
    names, ``default_name`` inside a directory it names, ``out/default_name`` without it."""
    return output_file(
        "--out",
        out or DEFAULT_OUT / default_name,
        suffixes=(".png", ".pdf", ".svg"),
        default_name=default_name,
    )


def _cmd_analyze(args: argparse.Namespace) -> int:
    from envs.maps import load_map
    from envs.maps.io import recommended_parameters

    try:
        world = load_map(args.map)
        params = recommended_parameters(args.map)
    except SurveilValueError as exc:
        raise type(exc)(f"map: {exc}") from None
    length = args.length
    if length is None:
        if params is None:
            raise InvalidConfigError(
                f"--length is required for map {args.map!r}: only built-in maps and map "
                "files whose metadata recommends parameters give a rod length (their L_min)"
            )
        length = params["l_min"]
    diameter = world.diameter
    if length > diameter:
        raise InvalidConfigError(
            f"--length = {length:g}: a rod this long fits nowhere in map {world.name!r} "
            f"(its widest extent is {diameter:.4g})"
        )
    default_name = f"decomposition_{world.name}_L{length:g}.png"
    out = _picture_file(args.out, default_name)
    from strategies.cspace import decompose, draw_decomposition

    dec = decompose(world, length)
    if not dec.cells:
        print(
            f"a rod of length {length:g} fits nowhere in map {world.name!r}: no position "
            "and orientation keeps it clear of the walls; nothing to decompose"
        )
        return 0
    draw_decomposition(dec, out, show_graph=not args.no_graph)
    print(dec.summary() if hasattr(dec, "summary") else repr(dec))
    print(f"picture written to {out}")
    return 0


def _cmd_figure(args: argparse.Namespace) -> int:
    from analysis.figures.evasion import draw_figure, figure_parameters

    params = json_object("--params", args.params, example=FIGURE_EXAMPLE)
    known = figure_parameters(args.name)
    unknown = sorted(set(params) - set(known))
    if unknown:
        raise InvalidConfigError(
            f"--params: figure {args.name!r} has no parameter(s) {unknown}; its parameters "
            "are " + ", ".join(f"{k} (default {v!r})" for k, v in known.items())
        )
    default_name = f"figure_{args.name}.png"
    out = _picture_file(args.out, default_name)
    try:
        draw_figure(args.name, out, **params)
    except OutputError:
        raise  # the picture could not be written: not a parameter's fault
    except SurveilValueError as exc:
        # the theory's "pass step=" is, on this command line, a "step" in --params
        message = str(exc).replace("pass step=", """add "step": H (the RK4 step) to --params""")
        raise type(exc)(f"--params: {message}") from None
    print(f"figure written to {out}")
    return 0


def _cmd_train(args: argparse.Namespace) -> int:
    # DESIGN.md: analysis calls training only from the command line
    from training.cli import run_train

    return run_train(args)


def _add_train_parser(sub: argparse._SubParsersAction) -> None:
    from training.cli import add_train_arguments

    p = sub.add_parser("train", help="train a learned policy (SB3) against a fixed opponent")
    add_train_arguments(p)
    p.set_defaults(func=_cmd_train)


def build_parser() -> argparse.ArgumentParser:
    """Return the argument parser of the ``surveil`` command."""
    parser = Parser(
        prog="surveil",
        description="Visibility-based surveillance with a finite sensor range.",
    )
    sub = parser.add_subparsers(dest="command", required=True)

    p = sub.add_parser(
        "maps",
        help="list the built-in maps",
        description="List the built-in maps. Wherever a command takes a map it also takes "
        f"{MAP_HELP.removeprefix('a built-in name (surveil maps), ')}.",
    )
    p.add_argument(
        "--plot",
        metavar="DIR",
        type=path_text("a directory name ('.' for the current directory)"),
        help="also draw each map to DIR/NAME.png",
    )
    p.set_defaults(func=_cmd_maps)

    p = sub.add_parser("policies", help="list the registered policies")
    p.add_argument(
        "--role",
        choices=["pursuer", "evader"],
        default=None,
        help="list only this role's policies",
    )
    p.set_defaults(func=_cmd_policies)

    p = sub.add_parser("play", help="play one episode and write its replay (the main job)")
    p.add_argument(
        "--map",
        default="corridor",
        type=path_text("a built-in map name or a map file"),
        help=f"{MAP_HELP} (default: corridor)",
    )
    p.add_argument(
        "--pursuer",
        default="pursuer/decomposition",
        help="registered pursuer policy, zoo:NAME (a shipped model) or a model .zip",
    )
    p.add_argument(
        "--evader",
        default="evader/shooting",
        help="registered evader policy, zoo:NAME (a shipped model) or a model .zip",
    )
    p.add_argument("--pursuer-params", help="pursuer parameters as JSON (see surveil policies)")
    p.add_argument("--evader-params", help='evader parameters as JSON, e.g. \'{"mode": "away"}\'')
    p.add_argument("--seed", type=integer(0), default=0, help="episode seed (>= 0)")
    p.add_argument(
        "--start",
        choices=["safe", "valid"],
        default="safe",
        help="safe: in a non-escapable cell at L_min where one exists (judged by a "
        "decomposition pursuer); valid: any valid surveillance configuration",
    )
    p.add_argument("--max-cycles", type=integer(1), default=None, help="episode horizon in steps")
    p.add_argument("--config", help=f"env overrides as JSON, e.g. {CONFIG_EXAMPLE}")
    p.add_argument(
        "--out",
        type=path_text("a file name or a directory"),
        help=f"replay: a .gif, a .png strip, or a directory (DIR/play.gif; default: "
        f"{DEFAULT_OUT / 'play.gif'})",
    )
    p.add_argument(
        "--fps",
        type=integer(1, MAX_FPS),
        default=None,
        help=f"GIF frame rate (1-{MAX_FPS}; default {DEFAULT_FPS})",
    )
    p.add_argument("--overlay", action="store_true", help="draw the decomposition under the replay")
    p.add_argument("--no-gif", action="store_true", help="only print the outcome")
    p.set_defaults(func=_cmd_play)

    p = sub.add_parser("analyze", help="draw the critical curves, regions and graph G_L")
    p.add_argument("map", type=path_text("a built-in map name or a map file"), help=MAP_HELP)
    p.add_argument(
        "--length", type=real(0.0), default=None, help="rod length L (default: a built-in's L_min)"
    )
    p.add_argument(
        "--out",
        type=path_text("a file name or a directory"),
        help="picture (.png, .pdf, .svg) or a directory",
    )
    p.add_argument("--no-graph", action="store_true", help="omit the connectivity graph panel")
    p.set_defaults(func=_cmd_analyze)

    p = sub.add_parser("figure", help="draw the paper's optimal-control figures")
    p.add_argument(
        "name",
        choices=["shooting", "greedy", "tractrix"],
        help="shooting: optimal escapes (Fig. 11); greedy: greedy evasion (Fig. 12); "
        "tractrix: the tractrix (Fig. 14)",
    )
    p.add_argument("--params", help="parameters as JSON, e.g. '{\"rho\": 0.5}'")
    p.add_argument(
        "--out",
        type=path_text("a file name or a directory"),
        help="picture (.png, .pdf, .svg) or a directory",
    )
    p.set_defaults(func=_cmd_figure)

    from analysis.tournament.cli import add_parsers as add_tournament_parsers

    add_tournament_parsers(sub)
    _add_train_parser(sub)
    figures_cli.add_parser(sub)
    referee_cli.add_parser(sub)
    _describe_from_help(sub)
    return parser


def _describe_from_help(sub) -> None:
    """Give every subcommand without a description its one-line help as one, so that
    ``surveil COMMAND --help`` says what the command does (argparse prints none otherwise)."""
    for action in sub._choices_actions:
        command = sub.choices[action.dest]
        if command.description is None and action.help:
            command.description = action.help[0].upper() + action.help[1:] + "."


def _interrupt_inside(exc: BaseException) -> KeyboardInterrupt | None:
    """The ``KeyboardInterrupt`` an exception wraps (its cause or context, at any depth),
    or None."""
    seen: set[int] = set()
    cur: BaseException | None = exc
    while cur is not None and id(cur) not in seen:
        if isinstance(cur, KeyboardInterrupt):
            return cur
        seen.add(id(cur))
        cur = cur.__cause__ or cur.__context__
    return None


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``surveil`` console script.

    Returns:
        0 on success, 2 for a user error (one line on stderr: ``surveil: error: ...``
        naming the value, what was expected and where it came from), 130 when
        interrupted (Ctrl-C), 143 when stopped by SIGTERM (cleaning up as on Ctrl-C), 141
        (128 + SIGPIPE, silently) when the reader of its output left (``surveil maps |
        head -1``). A traceback means a bug.
    """
    try:
        with interrupts_recorded() as ctrl_c:
            args = build_parser().parse_args(argv)  # imports for seconds: Ctrl-C lands here
            if ctrl_c.seen:  # one CPython discarded in an import's callback: honoured now
                raise KeyboardInterrupt
    except SystemExit as exc:  # argparse: --help (0) or a usage error (2, already printed)
        return int(exc.code or 0) if not isinstance(exc.code, str) else 2
    except KeyboardInterrupt:
        print("surveil: interrupted", file=sys.stderr)
        return 130
    with warnings.catch_warnings(), sigterm_as_interrupt():
        warnings.showwarning = OneLineWarnings(warnings.showwarning, "surveil")
        try:
            code = int(args.func(args) or 0)
            if sys.stdout is not None:  # a reader gone (`| head`) is met here, not at exit
                sys.stdout.flush()
            return code
        except KeyboardInterrupt as exc:
            if str(exc) == "SIGTERM":
                print("surveil: stopped by SIGTERM", file=sys.stderr)
                return 143
            print("surveil: interrupted", file=sys.stderr)
            return 130
        except Exception as exc:
            if isinstance(exc, BrokenPipeError) and reader_gone():
                return 141
            stopped = _interrupt_inside(exc)
            if stopped is not None:  # a Ctrl-C Python wrapped: a class body's
                # cached_property (3.11: "RuntimeError: Error calling __set_name__ on
                # 'cached_property' instance '_pieces' in 'EscapePlan'", a traceback, exit 1)
                sigterm = str(stopped) == "SIGTERM"
                print(f"surveil: {'stopped by SIGTERM' if sigterm else 'interrupted'}",
                      file=sys.stderr)  # fmt: skip
                return 143 if sigterm else 130
            message = user_error(exc)
            if message is None:
                raise  # a bug: keep the traceback
            print(f"surveil: error: {message}", file=sys.stderr)
            return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
