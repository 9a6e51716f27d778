"""The ``surveil`` command line.

``surveil play`` is the main job: one episode on a built-in world between two registered
policies, its outcome printed and its replay written to a GIF. The other subcommands list
maps, draw the configuration-space decomposition of a world, draw the optimal-control
figures of the paper, and evaluate policies against each other.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Sequence
from pathlib import Path

from analysis.figures import cli as figures_cli

__all__ = ["build_parser", "main"]

DEFAULT_OUT = Path("out")


def _cmd_maps(args: argparse.Namespace) -> int:
    from envs.maps import builtin_info, builtin_names

    for name in builtin_names():
        info = builtin_info(name)
        m = info.map
        print(
            f"{name:<12} {m.n_vertices:>4} vertices  L_min={info.l_min:g} L_max={info.l_max:g} "
            f"v_p={info.v_pursuer:g} v_e={info.v_evader:g}  {info.description}"
        )
        if args.plot:
            from envs.maps.plot import plot_map

            out = Path(args.plot)
            out.mkdir(parents=True, exist_ok=True)
            plot_map(m, path=out / f"{name}.png")
    if args.plot:
        print(f"wrote map pictures to {args.plot}/")
    return 0


def _cmd_policies(args: argparse.Namespace) -> int:
    from strategies.policies import describe_policy, policy_names

    for name in policy_names(args.role):
        print(f"{name:<26} {describe_policy(name)}")
    print("learned policies: ROLE/sb3:PATH (a stable-baselines3 model zip)")
    return 0


def _cmd_play(args: argparse.Namespace) -> int:
    from analysis.replay import write_replay
    from strategies.policies import make_policy
    from strategies.runner import run_episode

    overrides = json.loads(args.config) if args.config else {}
    pursuer = make_policy(args.pursuer, **json.loads(args.pursuer_params or "{}"))
    evader = make_policy(args.evader, **json.loads(args.evader_params or "{}"))
    result = run_episode(
        args.map,
        pursuer,
        evader,
        seed=args.seed,
        max_cycles=args.max_cycles,
        overrides=overrides,
        record=not args.no_gif,
    )
    print(result.summary())
    if not args.no_gif:
        out = Path(args.out)
        out.parent.mkdir(parents=True, exist_ok=True)
        write_replay(result, out, decomposition=args.overlay, fps=args.fps)
        print(f"replay written to {out}")
    return 0


def _cmd_analyze(args: argparse.Namespace) -> int:
    from envs.maps import load_map
    from strategies.cspace import decompose, draw_decomposition

    world = load_map(args.map)
    length = args.length if args.length is not None else _default_length(args.map)
    dec = decompose(world, length)
    out = Path(args.out or DEFAULT_OUT / f"decomposition_{world.name}_L{length:g}.png")
    out.parent.mkdir(parents=True, exist_ok=True)
    draw_decomposition(dec, out, show_graph=not args.no_graph)
    print(dec.summary() if hasattr(dec, "summary") else repr(dec))
    print(f"picture written to {out}")
    return 0


def _default_length(map_name: str) -> float:
    from envs.maps import builtin_info, builtin_names

    if map_name in builtin_names():
        return builtin_info(map_name).l_min
    raise SystemExit(f"surveil: --length is required for map {map_name!r} (not a built-in)")


def _cmd_figure(args: argparse.Namespace) -> int:
    from analysis.figures.evasion import draw_figure

    params = json.loads(args.params) if args.params else {}
    out = Path(args.out or DEFAULT_OUT / f"figure_{args.name}.png")
    out.parent.mkdir(parents=True, exist_ok=True)
    draw_figure(args.name, out, **params)
    print(f"figure written to {out}")
    return 0


def _cmd_evaluate(args: argparse.Namespace) -> int:
    from analysis.evaluate import evaluate, format_table

    overrides = json.loads(args.config) if args.config else None
    table = evaluate(
        maps=args.maps,
        pursuers=args.pursuers,
        evaders=args.evaders,
        seeds=range(args.seeds),
        max_cycles=args.max_cycles,
        overrides=overrides,
        start=args.start,
        results_path=Path(args.results) if args.results else None,
        workers=args.workers,
    )
    print(format_table(table))
    if args.plot:
        from analysis.plots import plot_matchups

        Path(args.plot).parent.mkdir(parents=True, exist_ok=True)
        plot_matchups(table, args.plot)
        print(f"table picture written to {args.plot}")
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
    parser = argparse.ArgumentParser(
        prog="surveil",
        description="Visibility-based surveillance with a finite sensor range.",
    )
    sub = parser.add_subparsers(dest="command", required=True)

    p = sub.add_parser("maps", help="list the built-in maps")
    p.add_argument("--plot", metavar="DIR", help="also draw each map to DIR/NAME.png")
    p.set_defaults(func=_cmd_maps)

    p = sub.add_parser("policies", help="list the registered policies")
    p.add_argument("--role", choices=["pursuer", "evader"], default=None)
    p.set_defaults(func=_cmd_policies)

    p = sub.add_parser("play", help="play one episode and write its replay (the main job)")
    p.add_argument(
        "--map", default="corridor", help="built-in name or map file (default: corridor)"
    )
    p.add_argument("--pursuer", default="pursuer/decomposition", help="registered pursuer policy")
    p.add_argument("--evader", default="evader/shooting", help="registered evader policy")
    p.add_argument("--pursuer-params", help="pursuer parameters as JSON (see surveil policies)")
    p.add_argument("--evader-params", help='evader parameters as JSON, e.g. \'{"mode": "away"}\'')
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--max-cycles", type=int, default=None, help="episode horizon in steps")
    p.add_argument("--config", help="env overrides as JSON, e.g. '{\"v_evader\": 0.8}'")
    p.add_argument("--out", default=str(DEFAULT_OUT / "play.gif"), help="GIF path")
    p.add_argument("--fps", type=int, default=20)
    p.add_argument("--overlay", action="store_true", help="draw the decomposition under the replay")
    p.add_argument("--no-gif", action="store_true", help="only print the outcome")
    p.set_defaults(func=_cmd_play)

    p = sub.add_parser("analyze", help="draw the critical curves, regions and graph G_L")
    p.add_argument("map", help="built-in name or map file")
    p.add_argument("--length", type=float, default=None, help="rod length L (default: L_min)")
    p.add_argument("--out", help="PNG path")
    p.add_argument("--no-graph", action="store_true", help="omit the connectivity graph panel")
    p.set_defaults(func=_cmd_analyze)

    p = sub.add_parser("figure", help="draw the paper's optimal-control figures")
    p.add_argument("name", choices=["shooting", "greedy", "tractrix"])
    p.add_argument("--params", help="parameters as JSON, e.g. '{\"rho\": 0.5}'")
    p.add_argument("--out", help="PNG path")
    p.set_defaults(func=_cmd_figure)

    p = sub.add_parser("evaluate", help="play every pursuer against every evader")
    p.add_argument("--maps", nargs="+", default=["corridor", "two_rooms"])
    p.add_argument("--pursuers", nargs="+", default=["pursuer/decomposition", "pursuer/greedy"])
    p.add_argument("--evaders", nargs="+", default=["evader/shooting", "evader/straight"])
    p.add_argument("--seeds", type=int, default=10, help="number of seeded starts per match")
    p.add_argument("--max-cycles", type=int, default=None)
    p.add_argument("--config", help="env overrides as JSON, e.g. '{\"v_evader\": 0.8}'")
    p.add_argument(
        "--start",
        choices=["safe", "valid"],
        default="safe",
        help="starts in a non-escapable cell at L_min (safe) or any valid configuration",
    )
    p.add_argument("--workers", type=int, default=1, help="processes to play in")
    p.add_argument("--results", help="JSONL file written as matches finish (resumable)")
    p.add_argument("--plot", help="also draw the table as heat maps to this PNG")
    p.set_defaults(func=_cmd_evaluate)

    _add_train_parser(sub)
    figures_cli.add_parser(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``surveil`` console script."""
    args = build_parser().parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except ValueError as exc:  # project errors subclass ValueError and name the bad value
        print(f"surveil: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
