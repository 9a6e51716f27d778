"""``surveil referee``: solve the bounded-speed game of a world, label starts, draw it.

::

    surveil referee corridor                          # summary at the default resolution
    surveil referee corner --cells-per-lmin 24 --out out/referee_corner.png
    surveil referee my_map.json --config '{"v_evader": 0.25}' --classify 3 1 4.5 1
    surveil referee open_room --sample 5 --kind pursuer   # certified starts, as JSON lines
    surveil referee corner --estimate 6 8             # and the estimate (not a certificate)

The game is the one ``surveil play`` plays on that world (a built-in map's recommended
range and speeds, then ``--config``). The solution is cached on disk (``$SURVEIL_CACHE_DIR``),
so a second call is fast.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

from analysis.arguments import (
    MAP_HELP,
    check_env_options,
    integer,
    json_object,
    output_file,
    path_text,
    real,
    say_warnings,
    warnings_held,
)

__all__ = ["add_parser", "run"]

CONFIG_EXAMPLE = "'{\"v_evader\": 0.25}'"
ESTIMATE_CPLS = (6.0, 8.0)
"""``--estimate``'s resolutions when none is given."""
ESTIMATE_KNOB = "the largest --estimate CPL (the others in proportion)"
"""How a memory budget message names ``--estimate``'s knob."""


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the ``referee`` subcommand to the ``surveil`` parser."""
    p = subparsers.add_parser(
        "referee",
        help="solve the bounded-speed game: who provably wins from which start",
        description="Solve the bounded-speed surveillance game of a world at one resolution: "
        "the starts the pursuer provably holds from, those the evader provably escapes from, "
        "and the gap between them (the resolution error).",
    )
    p.add_argument("map", type=path_text("a built-in map name or a map file"), help=MAP_HELP)
    p.add_argument("--config", help=f"env overrides as JSON, e.g. {CONFIG_EXAMPLE}")
    p.add_argument(
        "--cells-per-lmin",
        type=real(0.0),
        default=16.0,
        help="resolution: opponent cells per L_min (default 16; the states grow about as its "
        "third to fourth power)",
    )
    p.add_argument(
        "--out",
        type=path_text("a file name or a directory"),
        help="draw the winning sets to this picture (.png, .pdf, .svg)",
    )
    p.add_argument(
        "--classify",
        nargs=4,
        type=float,
        metavar=("PX", "PY", "EX", "EY"),
        help="label the start with the pursuer at (PX, PY) and the evader at (EX, EY)",
    )
    p.add_argument("--sample", type=integer(1), help="print this many certified starts")
    p.add_argument(
        "--kind",
        choices=["pursuer", "evader", "unknown"],
        help="the label of the starts --sample prints (default: pursuer)",
    )
    p.add_argument("--seed", type=integer(0), help="seed of --sample (>= 0; default 0)")
    p.add_argument(
        "--estimate",
        nargs="*",
        type=real(0.0),
        metavar="CPL",
        help="also solve the plain discrete game (an estimate, not a certificate) at these "
        "cells per L_min (default 6 8) and print its shares and its contested share (the "
        "resolution error); with --classify, the start's estimated label too",
    )
    p.add_argument(
        "--no-pursuer-fallback",
        action="store_true",
        help="keep the default pursuer lattice even when it certifies nothing (by default "
        "the pursuer bound is then solved once more one cell finer, and kept if it certifies; "
        "rho < 0.35 only)",
    )
    p.add_argument(
        "--no-evader-fallback",
        action="store_true",
        help="keep the default evader lattice even when it certifies next to nothing (by "
        "default the evader bound is then solved once more at half the cells per spacing, "
        "and kept if it certifies more)",
    )
    p.add_argument("--no-cache", action="store_true", help="neither read nor write the cache")
    p.set_defaults(func=run)
    return p


def run(args: argparse.Namespace) -> int:
    """Run ``surveil referee``."""
    import warnings

    import numpy as np

    from envs.errors import (
        InvalidConfigError,
        MemoryBudgetError,
        NarrowBandWarning,
        NoStartError,
        SurveilValueError,
        VacuousBoundWarning,
    )
    from envs.surveillance.config import EnvConfig
    from envs.surveillance.physics import check_step
    from envs.surveillance.placement import check_room
    from strategies.referee import referee_for
    from strategies.referee.estimates import check_cpls, check_estimate
    from strategies.referee.referee import (
        check_sample_size,
        check_solve_budget,
        check_start,
    )
    from strategies.referee.spec import GameSpec, check_cells_per_lmin
    from strategies.runner import map_parameters

    check_cells_per_lmin(args.cells_per_lmin, "--cells-per-lmin")  # 1e100 was a traceback
    if args.sample is None:  # they were dropped without a word, after the solve
        flags = (("--kind", args.kind), ("--seed", args.seed))
        given = [f"{f} {v}" for f, v in flags if v is not None]
        if given:
            raise InvalidConfigError(
                f"{' '.join(given)}: {'they choose' if len(given) > 1 else 'it chooses'} the "
                "starts --sample prints; add --sample N (or leave them out)"
            )
    overrides = json_object("--config", args.config, example=CONFIG_EXAMPLE)
    out = None
    if args.out:
        out = output_file(
            "--out", args.out, suffixes=(".png", ".pdf", ".svg"), default_name="referee.png"
        )
    try:
        world, params = map_parameters(args.map)
    except SurveilValueError as exc:
        raise type(exc)(f"map: {exc}") from None
    check_env_options(overrides, "--config")
    # the config's warnings (a game no pursuer can be sure to win) are held until every
    # refusal below has had its say and the long solve its announcement
    with warnings_held() as held:
        try:
            cfg = EnvConfig(map=world, **{**params, **overrides})
        except SurveilValueError as exc:  # the map's own parameters were checked above
            raise type(exc)(f"--config: {exc}") from None
    # what the solve cannot change is checked before it (it can take minutes)
    try:  # a step the env refuses: dt = 1e4 hung in the budget's move count (4e8 vectors)
        check_step(cfg.map, cfg.dt, max(cfg.v_pursuer, cfg.v_evader), cfg.body_radius)
    except SurveilValueError as exc:
        # blame --config only when it set one of the step's numbers; else the map's defaults
        if overrides.keys() & {"dt", "v_pursuer", "v_evader", "body_radius"}:
            raise type(exc)(f"--config: {exc}") from None
        raise type(exc)(
            f"map {args.map!r} at its default step: {exc} (set dt or the speeds with --config)"
        ) from None
    # no agent or no rod fits (a corridor narrower than two radii): said as the env says it,
    # not as "no lattice point ... lies 0.1 from the walls; refine the resolution"
    check_room(cfg.map, cfg.body_radius, cfg.l_min, where="referee")
    if args.classify is not None:
        try:
            check_start(cfg, tuple(args.classify[:2]), tuple(args.classify[2:]))
        except SurveilValueError as exc:
            raise type(exc)(f"--classify: {exc}") from None
    if args.estimate:
        try:
            check_cpls(args.estimate)
        except SurveilValueError as exc:
            raise type(exc)(f"--estimate: {exc}") from None
    if args.sample:  # 1e9 starts: numpy's MemoryError, after the solve
        with MemoryBudgetError.naming("--sample"):
            check_sample_size(args.sample)
    if args.estimate is not None:  # its memory too, before the referee's solve
        with MemoryBudgetError.naming(ESTIMATE_KNOB):
            check_estimate(GameSpec.from_config(cfg), tuple(args.estimate) or ESTIMATE_CPLS)
    with MemoryBudgetError.naming("--cells-per-lmin"):  # a refusal before any announcement
        check_solve_budget(GameSpec.from_config(cfg), args.cells_per_lmin, dt=cfg.dt)
    _say_if_long(cfg, args)
    for w in held:
        if issubclass(w.category, NarrowBandWarning):  # true of the referee's game too
            w.message = NarrowBandWarning(
                f"{world.name}: {w.message}; the same holds in the referee's game, whose "
                "steps are whole env steps (its pursuer bound can certify no start with the "
                "evader in open space)"
            )
    say_warnings(held)
    t = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", VacuousBoundWarning)  # the summary says it below
        try:
            with MemoryBudgetError.naming("--cells-per-lmin"):  # this command's flag
                ref = referee_for(
                    cfg,
                    args.cells_per_lmin,
                    cache=not args.no_cache,
                    pursuer_fallback=not args.no_pursuer_fallback,
                    evader_fallback=not args.no_evader_fallback,
                )
        except NoStartError as exc:  # nothing to report, classify or sample: the message
            raise exc.named("--cells-per-lmin") from None  # names a resolution with a start
    s = ref.summary()
    print(
        f"{world.name}: rho = {cfg.rho:g}, L in [{cfg.l_min:g}, {cfg.l_max:g}], "
        f"{args.cells_per_lmin:g} cells per L_min ({time.perf_counter() - t:.1f} s)"
    )
    print(
        f"  {s['starts']} lattice starts: pursuer wins {s['pursuer']:.1%}, evader wins "
        f"{s['evader']:.1%}, unknown {s['gap']:.1%} (the resolution error)"
    )
    for role in ("pursuer", "evader"):
        b = s[f"{role}_bound"]
        print(
            f"  {role} bound: cell {b['cell']:.4g}, lattice {b['spacing']:.4g}, step "
            f"{b['tau']:.4g} s, {b['states']} states, {b['iterations']} sweeps, "
            f"{b['seconds']['build'] + b['seconds']['solve']:.1f} s"
        )
        fell = b.get("fallback_from")
        if fell is not None:
            what = "no state" if role == "pursuer" else "next to nothing"
            print(
                f"    (the default lattice {fell['spacing']:.4g}, step {fell['tau']:.4g} s, "
                f"certified {what}: this is the fallback, {role}_coarse = {b['coarse']})"
            )
    vacuous = s["pursuer_bound"]["vacuous"]
    if vacuous is not None:
        print(f"  the pursuer wins above say nothing: {vacuous}")
    if args.classify is not None:
        px, py, ex, ey = args.classify
        label = ref.classify((px, py), (ex, ey))
        extra = ""
        if label == "evader":
            extra = f" (surveillance breaks within {ref.escape_time((px, py), (ex, ey)):.1f} s)"
        print(f"start pursuer ({px:g}, {py:g}), evader ({ex:g}, {ey:g}): {label}{extra}")
    if args.estimate is not None:
        _print_estimate(ref.spec, args)
    if args.sample:
        rng = np.random.default_rng(0 if args.seed is None else args.seed)
        for start in ref.sample_starts(args.sample, rng, kind=args.kind or "pursuer"):
            print(json.dumps(start))
    if out is not None:
        from strategies.referee.draw import draw_referee

        draw_referee(ref, path=Path(out))
        print(f"wrote {out}")
    return 0


LONG_SOLVE_SECONDS = 30.0
"""A solve estimated (an upper bound) to take longer is announced on standard error first."""


def _say_if_long(cfg, args: argparse.Namespace) -> None:
    """Say on standard error what is about to be solved, and how long it may take, when
    the estimate (:func:`strategies.referee.referee.unsolved_sizes`, an upper bound) is
    over :data:`LONG_SOLVE_SECONDS`: ``--config '{"dt": 10}'`` on the corridor (the
    pursuer's step rounded up to 10 s, 1257 moves a step instead of 29) solved for many
    minutes without a word."""
    from strategies.referee._budget import duration
    from strategies.referee.referee import evader_fallback_size, fallback_size, unsolved_sizes
    from strategies.referee.spec import GameSpec

    spec = GameSpec.from_config(cfg)
    sizes = unsolved_sizes(spec, args.cells_per_lmin, cache=not args.no_cache, dt=cfg.dt)
    seconds = sum(s.seconds for s in sizes)
    retry = None  # the pursuer bound's retry one cell finer, solved only if the default fails
    if not args.no_pursuer_fallback:
        retry = fallback_size(spec, args.cells_per_lmin, cache=not args.no_cache, dt=cfg.dt)
    eretry = None  # the evader bound's retry, solved only if the default certifies little
    if not args.no_evader_fallback:
        eretry = evader_fallback_size(spec, args.cells_per_lmin, cache=not args.no_cache, dt=cfg.dt)
    retries = sum(r.seconds for r in (retry, eretry) if r is not None)
    if seconds + retries <= LONG_SOLVE_SECONDS:
        return
    parts = "; ".join(f"{s.describe()}, a step of {s.tau:g} s, {s.moves} moves" for s in sizes)
    # the steps without the env's dt: a dt longer than them rounds them up to itself
    free = {s.what: s for s in unsolved_sizes(spec, args.cells_per_lmin, cache=False)}
    longer = [s for s in sizes if s.moves > free[s.what].moves]
    otherwise = ", ".join(f"{free[s.what].tau:g} s for the {s.what} otherwise" for s in longer)
    why = (
        f"; each step is a whole number of env steps (dt = {cfg.dt:g}), {otherwise}, and a "
        "longer step has more moves: a smaller dt is faster"
        if longer
        else "; a smaller --cells-per-lmin is faster"
    )
    if not sizes:  # both bounds cached: the fallback sizes say a default certified little
        for r, what, flag in (
            (retry, "pursuer lattice certifies no state (cached): solving it once more one "
             "cell finer", "--no-pursuer-fallback"),
            (eretry, "evader lattice certifies next to nothing (cached): solving it once more "
             "at half the cells per spacing", "--no-evader-fallback"),
        ):  # fmt: skip
            if r is None:
                continue
            print(
                f"{cfg.map.name}: the default {what} ({r.describe()}, a step of {r.tau:g} s, "
                f"{r.moves} moves; {flag} skips it): up to about {duration(r.seconds)} (an "
                "upper bound, estimated before the solve)",
                file=sys.stderr,
                flush=True,
            )
        return
    more = ""
    if retry is not None:  # afac520's fallback: a second pursuer solve when the first is 0 %
        more = (
            f", or {duration(seconds + retry.seconds)} if the default pursuer lattice "
            f"certifies no state and the solve retries it one cell finer ({retry.describe()}, "
            f"a step of {retry.tau:g} s, {retry.moves} moves; --no-pursuer-fallback skips it)"
        )
    if eretry is not None:  # a second evader solve when the first certifies next to nothing
        total = seconds + retries
        more += (
            f", or {duration(total)} if the default evader lattice certifies next to nothing "
            f"and the solve retries it at half the cells per spacing ({eretry.describe()}, a "
            f"step of {eretry.tau:g} s, {eretry.moves} moves; --no-evader-fallback skips it)"
        )
    print(
        f"{cfg.map.name}: solving the referee's bounds ({parts}): up to about "
        f"{duration(seconds)}{more} (an upper bound, estimated before the solve){why}",
        file=sys.stderr,
        flush=True,
    )


def _print_estimate(spec, args: argparse.Namespace) -> None:
    """The estimate's shares beside the certificates (never mixed with them)."""
    from envs.errors import MemoryBudgetError
    from strategies.referee import estimate

    cpls = tuple(args.estimate) or ESTIMATE_CPLS
    t = time.perf_counter()
    with MemoryBudgetError.naming(ESTIMATE_KNOB):  # checked up front too
        est = estimate(spec, cpls, cache=not args.no_cache)
    s = est.summary()
    print(
        f"estimate (the plain discrete game at {', '.join(f'{c:g}' for c in est.cpls)} cells "
        f"per L_min, both information orders; not a certificate; "
        f"{time.perf_counter() - t:.1f} s):"
    )
    print(
        f"  {s['starts']} lattice starts: pursuer {s['pursuer']:.1%}, evader "
        f"{s['evader']:.1%}, contested {s['contested']:.1%} (the resolution error)"
    )
    for sol in s["solutions"]:
        print(
            f"  {sol['cells_per_lmin']:g} cells per L_min, {sol['steps']:.3g} cells a step: "
            f"cell {sol['cell']:.4g}, step {sol['tau']:.4g} s, {sol['states']} states, "
            f"pursuer wins "
            f"{sol['evader_first']:.1%} (evader moves first) / {sol['pursuer_first']:.1%} "
            f"(pursuer first), {sol['iterations']} sweeps, "
            f"{sol['seconds']['build'] + sol['seconds']['solve']:.1f} s"
        )
    if args.classify is not None:
        px, py, ex, ey = args.classify
        print(f"  start pursuer ({px:g}, {py:g}), evader ({ex:g}, {ey:g}): estimated "
              f"{est.classify((px, py), (ex, ey))}")  # fmt: skip
