"""Each policy's regret: the share of the starts the referee certifies winnable for its
role that it nevertheless lost.

A start counts for a side only within the match's horizon (``max_cycles * dt``), the same
rule on both sides' rows: a start certified for the pursuer counts for it (it holds forever,
so past any horizon), one certified for the evader only when its certified escape time fits
in the horizon. A pursuer's winnable starts are those certified for the pursuer; an
evader's, those certified for the evader within the horizon, which are also the starts a
pursuer's row counts "certified for the opponent". A start certified for the evader with a
longer certified escape time (*late*, as ``benchmarks/policy_sets.py label`` calls it) is
neither side's in that match: the pursuer may hold it to the horizon, the evader may not
escape by then, so both rows count it unknown (and late). Starts the referee leaves unknown,
or certifies for the opponent, say nothing about a policy and are only counted.

* :func:`regret` computes :class:`Regret` rows from match outcomes (plain mappings: the
  map, the env parameters, the start positions, the winner).
* :func:`regret_table` formats them (a header row, then one row per policy).
* :func:`tournament_regret` is the hook the tournament report calls with its run's spec
  and match rows (it rebuilds each match's game and start from the records the shared
  runner wrote, or from the seed when a row carries no record).
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import warnings
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.stats import binomtest

from envs import validation as V
from envs.errors import (
    InvalidConfigError,
    InvalidPlacementError,
    MemoryBudgetError,
    NoStartError,
    VacuousBoundWarning,
)
from envs.maps import Map
from strategies.referee._budget import SolveSize
from strategies.referee.referee import (
    Referee,
    check_solve_budget,
    evader_fallback_size,
    fallback_size,
    solve,
    unsolved_sizes,
)
from strategies.referee.spec import GameSpec

__all__ = ["Regret", "regret", "regret_table", "tournament_regret"]

DEFAULT_CELLS_PER_LMIN = 16.0
"""Resolution of the referees built for regret (cached on disk, so paid once per game)."""


@dataclass(frozen=True)
class Regret:
    """One policy's regret.

    Attributes:
        role: ``"pursuer"`` or ``"evader"``.
        policy: its name.
        matches: matches it played.
        winnable: of those, starts certified winnable for its role (within the horizon).
        lost: of the winnable, those it lost.
        unknown: matches from starts no bound certifies within the match's horizon (late
            ones included).
        hopeless: matches from starts certified for its opponent (within the horizon).
        late: of the unknown, starts certified for the evader with a certified escape
            time beyond the match's horizon (counted alike on both roles' rows).
    """

    role: str
    policy: str
    matches: int
    winnable: int
    lost: int
    unknown: int
    hopeless: int
    late: int = 0

    @property
    def rate(self) -> float:
        """lost / winnable (NaN when nothing was winnable)."""
        return self.lost / self.winnable if self.winnable else math.nan

    def interval(self, confidence: float = 0.95) -> tuple[float, float]:
        """Wilson interval of the rate (NaNs when nothing was winnable)."""
        if not self.winnable:
            return math.nan, math.nan
        ci = binomtest(self.lost, self.winnable).proportion_ci(confidence, method="wilson")
        return float(ci.low), float(ci.high)


def _game_key(world: Map, params: Mapping[str, float]) -> tuple:
    return (world.digest, *(float(params[k]) for k in _PARAMS))


_PARAMS = ("l_min", "l_max", "v_pursuer", "v_evader", "body_radius", "dt")


def regret(
    matches: Iterable[Mapping[str, Any]],
    *,
    cells_per_lmin: float = DEFAULT_CELLS_PER_LMIN,
    referees: dict | None = None,
    cache: bool = True,
    cache_dir: str | os.PathLike | None = None,
    progress: bool | None = None,
    before_solve: Callable[[list[SolveSize]], None] | None = None,
) -> list[Regret]:
    """Regret of every policy in ``matches``.

    Args:
        matches: mappings with ``map`` (a :class:`Map`), ``l_min``, ``l_max``,
            ``v_pursuer``, ``v_evader``, ``body_radius``, ``dt``, ``max_cycles``,
            ``pursuer`` and ``evader`` (policy names), ``start`` (``{"pursuer": (x, y),
            "evader": (x, y)}``) and ``winner`` (``"pursuer"`` or ``"evader"``).
        cells_per_lmin: resolution of the referees (one per game, solved or loaded from
            the cache).
        referees: a dict to reuse referees across calls (filled in place), keyed by game;
            None for a game whose lattices hold no start at ``cells_per_lmin``
            (:class:`~envs.errors.NoStartError`): its matches count as unknown.
        cache: use the referees' on-disk cache.
        cache_dir: its directory.
        progress: a bar over the games to solve on standard error: shown (``True``),
            hidden (``False``) or, by default, on a terminal only (a solve not cached
            takes seconds to minutes).
        before_solve: called once before any game is solved with the estimated sizes
            (:func:`~strategies.referee.referee.unsolved_sizes`, time an upper bound) of
            the bounds to solve, games over the memory budget left out (their solve is
            refused at once), then those of the pursuer bounds' possible retries one cell
            finer (:func:`~strategies.referee.referee.fallback_size`, ``what`` ``"pursuer
            bound's fallback"``) and of the evader bounds' possible retries at half the
            cells per spacing (:func:`~strategies.referee.referee.evader_fallback_size`):
            what a caller tells its user before a long solve.

    Returns:
        One :class:`Regret` per (role, policy), pursuers first, sorted by name.

    Raises:
        InvalidConfigError: a match lacks a field or has a bad value (named).
    """
    referees = {} if referees is None else referees
    # every match is read first, so a bad one is refused before any solve (minutes each)
    read = [(_read_match(m, f"match {i}"), m) for i, m in enumerate(matches)]
    games: dict[tuple, tuple] = {}  # the games to solve, in the order first played
    for (world, params, *_), _ in read:
        key = _game_key(world, params)
        if key not in referees and key not in games:
            games[key] = (world, params)
    if before_solve is not None:
        before_solve(_sizes(games, cells_per_lmin, cache, cache_dir))
    from tqdm import tqdm

    bar = tqdm(total=len(games), desc="referee: solving the games played", unit="game",
               disable=None if progress is None else not progress, leave=False)  # fmt: skip
    with bar:
        for key, (world, params) in games.items():
            spec = _spec(world, params)
            try:
                referees[key] = solve(
                    spec, cells_per_lmin, dt=params["dt"], cache=cache, cache_dir=cache_dir
                )
            except NoStartError:  # its lattices miss the map's passages: it certifies nothing
                referees[key] = None
            bar.update()
    tally: dict[tuple[str, str], list[int]] = {}
    for (world, params, start, winner, horizon), m in read:
        ref = referees[_game_key(world, params)]
        label, escape = _label(ref, start)
        late = label == "evader" and escape > horizon + 1e-9
        if late:  # certified, but not within this match: neither side's (module docstring)
            label = "unknown"
        for role in ("pursuer", "evader"):
            t = tally.setdefault((role, str(m[role])), [0, 0, 0, 0, 0, 0])
            t[0] += 1
            if label == role:
                t[1] += 1
                t[2] += winner != role
            elif label == "unknown":
                t[3] += 1
                t[5] += late
            else:
                t[4] += 1
    rows = [Regret(r, p, *v) for (r, p), v in tally.items()]
    return sorted(rows, key=lambda x: (x.role != "pursuer", x.policy))


def _spec(world: Map, params: Mapping[str, float]) -> GameSpec:
    return GameSpec(world, params["l_min"], params["l_max"], params["v_pursuer"],
                    params["v_evader"], body_radius=params["body_radius"])  # fmt: skip


def _sizes(games, cells_per_lmin, cache, cache_dir) -> list[SolveSize]:
    """The bounds :func:`regret` will solve for ``games`` (those within the memory
    budget), then the pursuer bounds' possible retries (see its ``before_solve``)."""
    sizes, retries = [], []
    for world, params in games.values():
        spec, kw = _spec(world, params), dict(cache=cache, cache_dir=cache_dir, dt=params["dt"])
        try:
            check_solve_budget(spec, cells_per_lmin, dt=params["dt"])
        except MemoryBudgetError:
            continue  # refused before it starts: no time to announce
        sizes += unsolved_sizes(spec, cells_per_lmin, **kw)
        for size in (fallback_size, evader_fallback_size):
            retry = size(spec, cells_per_lmin, **kw)
            retries += [] if retry is None else [retry]
    return sizes + retries


def _read_match(m: Mapping[str, Any], where: str):
    if not isinstance(m, Mapping):
        raise InvalidConfigError(f"{where}: expected a mapping, got {type(m).__name__}")
    missing = [k for k in ("map", "pursuer", "evader", "start", "winner", "max_cycles", *_PARAMS)
               if k not in m]  # fmt: skip
    if missing:
        raise InvalidConfigError(f"{where}: missing {missing}")
    world = m["map"]
    if not isinstance(world, Map):
        raise InvalidConfigError(f"{where}: map = {world!r}: expected an envs.maps.Map")
    params = {k: V.positive(k, m[k], where=where) for k in _PARAMS}
    start = m["start"]
    if not isinstance(start, Mapping) or "pursuer" not in start or "evader" not in start:
        raise InvalidConfigError(f"{where}: start = {start!r}: expected pursuer and evader")
    start = {k: V.point(f"start {k}", start[k], where=where) for k in ("pursuer", "evader")}
    winner = V.choice("winner", m["winner"], ("pursuer", "evader"), where=where)
    horizon = V.integer("max_cycles", m["max_cycles"], minimum=1, where=where) * params["dt"]
    return world, params, start, winner, horizon


def _label(ref: Referee | None, start) -> tuple[str, float]:
    if ref is None:  # no lattice start at this resolution (NoStartError): nothing certified
        return "unknown", math.inf
    try:
        label = ref.classify(start["pursuer"], start["evader"])
    except InvalidPlacementError:
        return "unknown", math.inf  # surveillance did not hold at the start: not a game
    if label == "evader":
        t = ref.escape_time(start["pursuer"], start["evader"])
        return label, math.inf if t is None else t
    return label, math.inf


def regret_table(
    rows: Iterable[Regret],
    confidence: float = 0.95,
    horizon: float | tuple[float, float] | None = None,
) -> list[list[str]]:
    """A table of regrets: a header row, then one row per policy.

    Args:
        rows: :func:`regret`'s rows.
        confidence: of the regret's Wilson interval.
        horizon: the matches' horizon in seconds (``max_cycles * dt``), or its least and
            greatest when they differ, for the header to name: the counts certified for
            a side are within it (:func:`regret`); by default the header says "the
            horizon" without a value.
    """
    within, beyond = _horizon_words(horizon)
    out = [["role", "policy", "matches", f"certified winnable ({within})", "lost",
            "regret [95% CI]", "unknown", f"certified for the opponent ({within})",
            f"of the unknown, late (certified for the evader, escape {beyond})"]]  # fmt: skip
    for r in rows:
        if r.winnable:
            lo, hi = r.interval(confidence)
            rate = f"{r.rate:.2f} [{lo:.2f}, {hi:.2f}]"
        else:
            rate = "-"
        out.append([r.role, r.policy, str(r.matches), str(r.winnable), str(r.lost), rate,
                    str(r.unknown), str(r.hopeless), str(r.late)])  # fmt: skip
    return out


def _horizon_words(horizon: float | tuple[float, float] | None) -> tuple[str, str]:
    """The header's words for the horizon the counts are within, and beyond it."""
    if horizon is None:
        return "within the horizon", "beyond the horizon"
    lo, hi = (horizon, horizon) if isinstance(horizon, int | float) else horizon
    if hi - lo < 1e-9:
        return f"within the {lo:.4g} s horizon", f"beyond the {lo:.4g} s horizon"
    each = f"each match's horizon, {lo:.4g}-{hi:.4g} s"
    return f"within {each}", f"beyond {each}"


# ---------------------------------------------------------------------- the tournament hook
def tournament_regret(
    spec: Mapping[str, Any] | str,
    rows: Iterable[Mapping[str, Any]],
    *,
    geometry: Mapping[str, Any] | None = None,
    cells_per_lmin: float = DEFAULT_CELLS_PER_LMIN,
    cache: bool = True,
    cache_dir: str | os.PathLike | None = None,
    strict: bool = False,
    progress: bool | None = None,
    before_solve: Callable[[list[SolveSize]], None] | None = None,
) -> list[list[str]]:
    """The regret table of a tournament run, for its report.

    Args:
        spec: the run's normalised spec (its ``to_dict()``, or that as JSON): ``maps``
            (``label``, ``source``, ``digest``), ``env``, ``variants``.
        rows: its matches. Each needs ``status``, ``winner``, ``pursuer``, ``evader`` and
            either ``record`` (the shared runner's :meth:`EpisodeResult.to_record`, as a
            dict or JSON: start positions, overrides, map) or ``map``, ``variant``,
            ``start`` (the start kind) and ``seed`` (the start is drawn again exactly as
            the runner drew it).
        geometry: map digest -> map as our JSON schema (what the store keeps), for maps
            that are neither built-in nor loadable from their source.
        cells_per_lmin: resolution of the referees.
        cache: use the referees' on-disk cache.
        cache_dir: its directory.
        strict: raise on a match whose game cannot be rebuilt (a map not found or
            changed since the run); by default such matches are left out and a last row
            says how many and why, so a report still renders.
        progress: :func:`regret`'s bar over the games to solve (by default on a terminal).
        before_solve: :func:`regret`'s, called with the estimated sizes of what it solves.

    Returns:
        :func:`regret_table`'s rows (only matches played out, status ``"ok"``; its header
        names their horizon, ``max_cycles * dt``), then a
        note row when a game's pursuer bound is vacuous (a
        :class:`~envs.errors.VacuousBoundWarning`: at rho = 0.5 its pursuer rows count no
        certified start because the bound certifies none, not because none is winnable),
        then one when a game's pursuer bound is the fallback lattice (the default one
        certified no state; :func:`~strategies.referee.referee.solve`'s
        ``pursuer_fallback``), then one when a game's evader bound is the fallback lattice
        (the default one certified next to nothing; ``evader_fallback``), then one when
        matches were left out.

    Raises:
        InvalidConfigError: with ``strict``, a match whose game cannot be rebuilt.
    """
    if isinstance(spec, str):
        spec = json.loads(spec)
    maps = {m["label"]: m for m in spec.get("maps", [])}
    variants = {v.get("label", ""): v for v in spec.get("variants", [])}
    matches, skipped = [], []
    for row in rows:
        if row.get("status", "ok") != "ok" or row.get("winner") not in ("pursuer", "evader"):
            continue
        try:
            matches.append(_match_of(row, spec, maps, variants, geometry))
        except (InvalidConfigError, InvalidPlacementError) as exc:
            if strict:
                raise
            skipped.append(str(exc))
    referees: dict = {}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", VacuousBoundWarning)
        results = regret(matches, cells_per_lmin=cells_per_lmin, referees=referees,
                         cache=cache, cache_dir=cache_dir, progress=progress,
                         before_solve=before_solve)  # fmt: skip
    for w in caught:  # other warnings go on as they came
        if not issubclass(w.category, VacuousBoundWarning):
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    horizons = [m["max_cycles"] * m["dt"] for m in matches]
    table = regret_table(results, horizon=(min(horizons), max(horizons)) if horizons else None)
    vacuous = sorted({str(w.message) for w in caught
                      if issubclass(w.category, VacuousBoundWarning)})  # fmt: skip
    if vacuous:
        eg = "e.g. " if len(vacuous) > 1 else ""  # one game's reason stands for all
        note = (f"pursuer regret: in {len(vacuous)} game(s) the pursuer bound certifies "
                f"nothing informative, so their starts count as unknown, not as winnable: "
                f"{eg}{vacuous[0]}")  # fmt: skip
        table.append(["-", note, *[""] * (len(table[0]) - 2)])
    for role, what in (
        ("pursuer", "certified no state and the referee's is one cell finer"),
        ("evader", "certified next to nothing and the referee's is finer"),
    ):
        fell = [getattr(ref, role) for ref in referees.values()
                if getattr(ref, role).fallback_from is not None]  # fmt: skip
        if fell:
            table.append(["-", _fallback_note(role, what, fell),
                          *[""] * (len(table[0]) - 2)])  # fmt: skip
    if skipped:
        note = f"{len(skipped)} matches not counted: {skipped[0]}"
        table.append(["-", note, *[""] * (len(table[0]) - 2)])
    return table


def _fallback_note(role: str, what: str, fell: list) -> str:
    """The regret table's note on the games whose ``role`` bound is solve's fallback
    lattice (``pursuer_fallback`` / ``evader_fallback``), naming the first."""
    b, was = fell[0], fell[0].fallback_from
    return (f"{role} regret: in {len(fell)} game(s) the default {role} lattice {what} "
            f"(solve's {role}_fallback), e.g. map {b.spec.map.name!r} at rho = "
            f"{b.spec.rho:.3g}: {role}_coarse = {b.res.coarse} (spacing {b.res.spacing:.4g}, "
            f"step {b.res.tau:.4g} s) for {was.coarse} (spacing {was.spacing:.4g}, step "
            f"{was.tau:.4g} s)")  # fmt: skip


def _match_of(row, spec, maps, variants, geometry) -> dict[str, Any]:
    """The match mapping :func:`regret` reads, rebuilt from one tournament row."""
    record = row.get("record")
    if isinstance(record, str):
        record = json.loads(record)
    if record:  # the runner's record: the resolved env parameters and the start
        name = record.get("map")
        world = _map_of(name, record.get("map_digest"), maps, geometry)
        params = {**_builtin_params(name), **dict(record.get("overrides") or {})}
        cfg = _config(world, params, None)
        start = record["start"]
    else:  # resolve the parameters as the spec does and draw the start again
        entry = maps.get(row["map"], {})
        source = entry.get("source", row["map"])
        world = _map_of(source, entry.get("digest"), maps, geometry)
        variant = variants.get(row.get("variant", ""), {})
        # a file map's recommendations as the spec stored them (the file may have changed)
        recommended = entry["params"] if "params" in entry else _builtin_params(source)
        params = {**recommended, **dict(spec.get("env") or {}),
                  **dict(variant.get("overrides") or {})}  # fmt: skip
        cfg = _config(world, params, variant.get("rho"))
        start = _redraw_start(cfg, row)
    return {
        "map": world, **{k: getattr(cfg, k) for k in _PARAMS},
        "max_cycles": cfg.max_cycles, "pursuer": row["pursuer"], "evader": row["evader"],
        "start": start, "winner": row["winner"],
    }  # fmt: skip


def _builtin_name(source):
    """A tournament spec names a built-in map's source ``builtin:NAME``."""
    if isinstance(source, str) and source.startswith("builtin:"):
        return source[len("builtin:") :]
    return source


def _builtin_params(name) -> dict[str, float]:
    """A built-in's recommended parameters (scaled for ``NAME~xS...``), else none."""
    from envs.maps.io import builtin_parameters

    return builtin_parameters(_builtin_name(name)) or {}


def _map_of(source, digest, maps, geometry) -> Map:
    from envs.maps import builtin_names, load_map
    from envs.maps.io import map_from_dict

    world = None
    if geometry and digest in geometry:
        g = geometry[digest]
        world = map_from_dict(json.loads(g) if isinstance(g, str) else g).map
    elif isinstance(source, str):
        if source in maps:
            source = maps[source].get("source", source)
        source = _builtin_name(source)
        if source in builtin_names() or os.path.exists(str(source)):
            world = load_map(source)
    if world is None:
        raise InvalidConfigError(f"tournament_regret: cannot find the map {source!r}")
    if digest and world.digest != digest:
        raise InvalidConfigError(
            f"tournament_regret: map {source!r} has changed since the run (digest "
            f"{world.digest[:12]} != {str(digest)[:12]})"
        )
    return world


def _config(world: Map, params: Mapping[str, Any], rho):
    """The env config of a match (``rho`` sets v_evader = rho v_pursuer, as a spec's
    variant does)."""
    from envs.errors import RhoAboveOneWarning
    from envs.surveillance.config import EnvConfig

    kw = {k: v for k, v in params.items() if k not in ("map", "map_digest", "render_mode")}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RhoAboveOneWarning)
        cfg = EnvConfig(map=world, **kw)
        if rho is not None:
            kw["v_evader"] = float(rho) * cfg.v_pursuer
            cfg = EnvConfig(map=world, **kw)
    return cfg


def _redraw_start(cfg, row: Mapping[str, Any]):
    """The start the shared runner drew for this row's seed and start kind."""
    from strategies.policies.starts import sample_start
    from strategies.runner import episode_seeds

    _, s_start, _, _ = episode_seeds(int(row["seed"]))
    judge = dataclasses.replace(cfg, observation="state")  # as the runner judges starts
    return sample_start(judge, np.random.default_rng(s_start), kind=row.get("start", "safe"))
