"""``python -m training.zoo {list,info,reproduce,evaluate}``: see :mod:`training.zoo`."""

from __future__ import annotations

import json
import math
import sys
import warnings

from envs.console import CommandParser, interrupts_recorded, progress_flags
from strategies.policies.model_files import NoProvenanceWarning
from training import zoo
from training.cli import resume_note, run_cli
from training.config import opponent_name
from training.train import evaluate_model

_NAME_HELP = "a shipped model (python -m training.zoo list)"


def main(argv: list[str] | None = None) -> int:
    """Run the zoo command line; returns the exit code (2 and one line for a user error)."""
    return run_cli("python -m training.zoo", lambda: _main(argv))


def _main(argv: list[str] | None) -> int:
    # an argument a subcommand does not take is refused by it (was the top-level usage)
    parser = CommandParser(
        prog="python -m training.zoo",
        description="The shipped models: list them, show one's provenance, retrain one "
        "from its recipe, or play one against an opponent.",
    )
    sub = parser.add_subparsers(dest="command", required=True)
    sub.add_parser("list", help="names of the shipped models")
    p_info = sub.add_parser("info", help="provenance of one model")
    p_info.add_argument("name", help=_NAME_HELP)
    p_rep = sub.add_parser("reproduce", help="retrain a model from its stored config")
    p_rep.add_argument("name", help=_NAME_HELP)
    p_rep.add_argument("--output-dir", default=None, help="default: out/zoo/NAME")
    p_rep.add_argument("--install", action="store_true", help="replace the shipped model")
    progress_flags(
        p_rep,
        "no progress (default: a bar on a terminal, else a line per episode or per "
        "tenth of the timesteps, on stderr; a shipped model retrains in 2 to 50 minutes)",
    )
    p_ev = sub.add_parser("evaluate", help="play a model against an opponent")
    p_ev.add_argument("name", help=_NAME_HELP)
    p_ev.add_argument(
        "--opponent",
        required=True,
        help="the other role's policy: a name (evader/shooting; surveil policies), "
        "zoo:NAME or a model .zip",
    )
    p_ev.add_argument("--episodes", type=int, default=50, help="episodes (default 50)")
    p_ev.add_argument("--seed", type=int, default=0, help="seed of the first (default 0)")
    p_ev.add_argument(
        "--start",
        default="safe",
        choices=["env", "valid", "safe"],
        help="starts: the env's random one, or sample_start's valid or safe (default)",
    )
    with interrupts_recorded() as ctrl_c:  # imports for seconds: a Ctrl-C lands here
        args = parser.parse_args(argv)
        if args.command in ("reproduce", "evaluate"):
            import stable_baselines3  # noqa: F401  (what they play or train: torch's import)
    if ctrl_c.seen:  # one CPython discarded in an import's callback: honoured now
        raise KeyboardInterrupt
    if args.command == "list":
        for name in zoo.list_models():
            prov = zoo.info(name)
            maps = prov.get("maps") or [prov["config"].get("map")]
            how = prov.get("method", "rl")
            features = (prov.get("config") or {}).get("features")
            if features:  # a learned policy with analytic features: say which
                how += f" + features {', '.join(features)}"
            opponents = prov["opponent"]  # one name, or a pool's list (was printed as one)
            if not isinstance(opponents, str):
                opponents = ", ".join(opponents)
            print(f"{name}\t{prov['role']} ({how}) vs {opponents} on {', '.join(maps)}")
    elif args.command == "info":
        print(json.dumps(zoo.info(args.name), indent=2))
    elif args.command == "reproduce":
        try:
            r = zoo.reproduce(args.name, args.output_dir, install_result=args.install,
                              progress_bar=not args.no_progress)  # fmt: skip
        except KeyboardInterrupt:  # said only "interrupted", though a rerun resumes
            print(resume_note(zoo.run_config(args.name, args.output_dir)), file=sys.stderr)
            raise
        if not hasattr(r, "timesteps"):  # a DAgger recipe
            print(f"dagger: {r.samples[-1]} labelled states in {r.wall_seconds:.1f} s "
                  f"-> {r.model_path}")  # fmt: skip
            return 0
        if r.already_trained:  # was "trained 151552 timesteps in 0.0 s"
            print(f"already trained: {r.timesteps} timesteps -> {r.model_path}")
        else:
            print(f"trained {r.timesteps} timesteps in {r.wall_time:.1f} s -> {r.model_path}")
        if r.evaluation is not None:
            print(_line(r.evaluation))
    else:
        from envs import validation

        # named as the flags (was "episodes: ..." and, for --seed -3, numpy's traceback)
        validation.integer("--episodes", args.episodes, minimum=1)
        validation.integer("--seed", args.seed, minimum=0)
        other = "evader" if zoo.info(args.name)["role"] == "pursuer" else "pursuer"
        # a misspelt opponent named as the flag (was "unknown policy ..." alone)
        opponent_name(args.opponent, other, f"--opponent = {args.opponent!r}")
        with warnings.catch_warnings():
            # the check above warned of a bare model already, named as the flag (the
            # evaluation's own check said it a second time, as "opponent = ...")
            warnings.simplefilter("ignore", NoProvenanceWarning)
            ev = evaluate_model(
                zoo.model_path(args.name),
                args.opponent,
                episodes=args.episodes,
                seed=args.seed,
                start=args.start,
            )
        print(_line(ev))
    return 0


def _on(maps: tuple[str, ...]) -> str:
    if len(maps) > 1:
        return f" on {', '.join(maps)} (one drawn an episode)"
    return f" on {maps[0]}" if maps else ""


def _line(ev) -> str:
    t = "-" if math.isnan(ev.mean_escape_time) else f"{ev.mean_escape_time:.2f} s"
    return (
        f"{ev.role} vs {ev.opponent}{_on(ev.maps)}: "
        f"success {ev.successes}/{ev.episodes} "
        f"({ev.success_rate:.0%}), mean escape time {t}, causes "
        + (", ".join(f"{c} {n}" for c, n in sorted(ev.causes.items())) or "none")
    )


if __name__ == "__main__":
    sys.exit(main())
