"""The referee's labels of a policy set's starts: which losses no policy of the set's side
could avoid, and the policy's regret (``policy_sets.py label``).

Each episode of a set starts from a start (the pursuer's and the evader's positions) in
one game (world, L range, speeds, body radius). The referee (:mod:`strategies.referee`,
through ``referee_labels.py``: the bounded-speed ground truth at ``CPL`` cells per
L_min, with a fine evader lattice) labels each start:

* ``evader``: certified for the evader, with a certified escape time T (no pursuer of
  speed V_p holds it longer against the best evader). The best evader escapes within
  the episode's horizon when T is within it; when T is beyond it (``late``: the bound
  is loose, a multiple of the referee's step), some pursuer might still hold to the
  horizon.
* ``pursuer``: certified for the pursuer (some pursuer of speed V_p holds it forever,
  against every evader).
* ``unknown`` (the referee's resolution error; where one bound certifies no state of the
  game at all, e.g. the pursuer bound from rho ~ 0.3 or in narrow passages, every start the
  other leaves is unknown, and its line says so: ``"why"`` in the labels file, the reason
  beside the loss in the report), ``not solved`` (over the memory budget,
  ``$SURVEIL_MEMORY_BUDGET``), ``not a start`` (surveillance does not hold there: a
  start the runner drew that the referee's margins refuse), ``no start`` (a crashed
  episode's row records none): undecided.

A loss of a *pursuer set* (the decomposition pursuer did not hold) is *unavoidable*
from an ``evader`` start with T within the horizon, ``late`` from one with T beyond it,
and the policy's *regret* from a ``pursuer`` start. A loss of an *evader set* (the
shooting evader did not escape by the horizon) is *unavoidable* from a ``pursuer``
start, the policy's *regret* from an ``evader`` start with T within the horizon, and
``late`` from one with T beyond it (undecided: a certificate of an escape, not of one
within the horizon). Starts are *winnable* for the set's side when a loss from them is
a regret.

The *regret* of a set is regrets / certified-winnable episodes (episodes from such
starts; issue 13's regret, :class:`strategies.referee.Regret`). At rho >= 0.35 the
pursuer bound has certified nothing at any resolution tried
(``strategies.referee.pursuer_bound``): there no start is certified for the pursuer, so a
pursuer set's loss is unavoidable or undecided and its regret undefined, and an evader
set's loss is a regret or undecided. "Unavoidable" is against the best opponent: a
weaker evader (a zig-zag, a herder) might have been held, a weaker pursuer (a greedy
follower) escaped, from such a start.

The starts: ``unseen_worlds.py`` and ``fixed_starts.py`` rows record the start played;
``evader_escapes.py`` rows record none before ``start_drawn`` (the episode seed drew a
safe start): it is drawn again as the runner draws it (``strategies.runner``'s start
seed), which is the start played while the start sampler has not changed since the row
(its ``code``).

The referee's resolution (its error bound): the opponent is known to a cell of side
h = L_min / CPL (its position within h / sqrt(2)); the certified player moves on a
lattice ``coarse`` cells apart (``strategies.referee.solve``: the pursuer's
``round(2 / rho)`` cells, at most a quarter of the range L_max - L_min; the evader's 2
cells, one spacing a step), in steps of whole env steps. A start neither bound certifies
is ``unknown``: the gap shrinks as CPL grows, and the solve's states grow about as CPL's
third to fourth power (minutes a world at 24 on the sets' worlds).

The work is one solve per game (a transformed built-in world is judged untransformed:
the same game, so its variants share a solve), cached on disk
(``$SURVEIL_CACHE_DIR``). With several ``--cpl`` values, a start is labelled at the
first, and at the next only while it is undecided (certificates hold at any
resolution). Labels are appended, as they come, to ``SET.labels.jsonl`` in the labels
directory (one line per start and CPL; a rerun labels only what the file lacks), then
the report is printed from the file.
"""

from __future__ import annotations

import itertools
import json
import math
import os
import time
import warnings
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass

import episode_rows
import numpy as np
import referee_labels

from envs.errors import InvalidConfigError, VacuousBoundWarning
from envs.maps import Map
from strategies.referee.pursuer_bound import VACUOUS_RHO

__all__ = ["LABELS_SUFFIX", "Start", "label_sets", "starts_of"]

LABELS_SUFFIX = ".labels.jsonl"
"""The labels of set S go to ``S.labels.jsonl`` in the labels directory."""

UNDECIDED = ("unknown", "not solved", "not a start", "no start")
"""The outcomes that decide nothing, as the report orders them."""


@dataclass(frozen=True)
class Start:
    """The start of one episode, as the referee judges it."""

    key: str
    """The start's identity: its game and positions (the episodes of one start share it)."""
    role: str
    """The side the set measures (``"pursuer"`` or ``"evader"``): whose loss it judges."""
    game: str
    """The game's identity (one solve): the untransformed world and its parameters."""
    world: str
    """How the report names the start's world."""
    rho: float
    horizon: float
    """The episode's horizon in seconds (the time the pursuer had to hold)."""
    build: Callable[[], tuple[Map, dict, Callable | None]] | None
    """(map, env overrides, the map from the played world back to the judged one), or
    None when there is nothing to judge (``why``)."""
    start: Mapping[str, object] | None
    why: str = ""
    """Why there is no start to judge (``no start``)."""


def _judged_game(m: Map, ov: Mapping[str, float]) -> str:
    return json.dumps([m.digest, *(float(ov[k]) for k in sorted(ov))])


def _dt() -> float:
    from envs.surveillance.config import EnvConfig

    return EnvConfig.__dataclass_fields__["dt"].default


def _evader_horizon(m: Map, ov: Mapping[str, float], k: float) -> float:
    """The horizon in seconds of an evader-role episode of ``k`` D / V_e on the played
    world (``math.ceil`` of it in steps, as the scripts play it)."""
    import unseen_worlds as uw

    return math.ceil(k * uw.diameter(m) / ov["v_evader"] / _dt()) * _dt()


def _unseen(row: dict) -> Start:
    import unseen_worlds as uw
    from referee_labels import similarity_back

    world = f"{row['world']} {row['combo']}"
    if row["role"] == "evader":
        rho, ratio, l_min = row["combo"]
        sim = uw.evader_similarity_of(row["world"])
        m, ov = uw.evader_world(row["world"], l_min, rho, ratio, untransformed=True)
        horizon = _evader_horizon(*uw.evader_world(row["world"], l_min, rho, ratio),
                                  row.get("horizon", uw.K))  # fmt: skip
        back = None if sim is None else similarity_back(*sim[1:])
        return _start("evader", world, m, ov, back, row.get("start"), horizon)
    sim = uw.similarity_of(row["world"])
    m, ov = uw.pursuer_world(row["world"], row["combo"], untransformed=True)
    back = None if sim is None else similarity_back(*sim[1:])
    horizon = row.get("horizon", uw.MAX_CYCLES) * _dt()
    return _start("pursuer", world, m, ov, back, row.get("start"), horizon)


def _holds(row: dict) -> Start:
    import pursuer_holds as ph
    from referee_labels import similarity_back

    out = row["out"]["pursuer/decomposition"]
    world = f"{row['world']} [{row['variant']}] rho={row['rho']}"
    if row["l_min"] is not None:
        return Start(
            json.dumps([world, row["seed"], row["l_min"]]), "pursuer", "", world, row["rho"],
            row["max_cycles"] * _dt(), None, None,
            "played at --l-min: the referee judges the world's own L_min only",
        )  # fmt: skip
    _, rot, scale, offset = next(v for v in ph.VARIANTS if v[0] == row["variant"])
    m, params = ph._world(row["world"], 0.0, 1.0, (0.0, 0.0))
    ov = {"l_min": params["l_min"], "l_max": params["l_max"], "v_pursuer": params["v_pursuer"],
          "v_evader": row["rho"] * params["v_pursuer"], "body_radius": 0.2}  # fmt: skip
    start = out[4] if len(out) > 4 else None
    back = similarity_back(rot, scale, offset)
    return _start("pursuer", world, m, ov, back, start, row["max_cycles"] * _dt())


def _escapes(row: dict) -> Start:
    """An ``evader_escapes.py`` row: the world variant judged untransformed (its lengths
    and speeds scale with it), the start the row records or, in an older row, the one
    its episode seed draws."""
    import evader_escapes as ee
    from referee_labels import similarity_back

    world = f"{row['world']} [{row['variant']}]"
    played, played_ov = ee.world(row["world"], row["variant"])
    horizon = _evader_horizon(played, played_ov, row["k"])
    m, ov = ee.world(row["world"], "as is")
    start = row.get("start_drawn")
    if start is None:
        start = _drawn_start(played, played_ov, row["seed"], row["start"])
    back = similarity_back(*ee.VARIANTS[row["variant"]])
    return _start("evader", world, m, ov, back, start, horizon)


def _drawn_start(m: Map, ov: Mapping[str, float], seed: int, kind: str) -> dict:
    """The start ``run_episode(m, ..., seed, overrides=ov, start=kind)`` plays: the start
    sampler's draw from the episode's start seed, on the env's state config."""
    from envs.surveillance.config import EnvConfig
    from strategies.policies.starts import sample_start
    from strategies.runner import episode_seeds

    drawn = sample_start(EnvConfig(map=m, **ov), np.random.default_rng(episode_seeds(seed)[1]),
                         kind=kind)  # fmt: skip
    return {k: [float(x) for x in drawn[k]] for k in ("pursuer", "evader")}


def _fixed(row: dict) -> Start:
    import fixed_starts as fs

    from envs.surveillance.config import EnvConfig

    if row["starts"] == "default":  # the world as the runner plays it given its name
        cfg = EnvConfig(map=row["world"])
        ov = {k: getattr(cfg, k) for k in ("l_min", "l_max", "v_pursuer", "v_evader",
                                           "body_radius")}  # fmt: skip
        return _start(row["role"], row["world"], cfg.map, ov, None, row.get("start_drawn"),
                      cfg.max_cycles * cfg.dt)  # fmt: skip
    m, ov = fs.world(row["role"], row["world"], row["combo"])
    horizon = row["horizon"] * _dt()
    if row["role"] == "evader":
        horizon = _evader_horizon(m, ov, row["horizon"])
    return _start(row["role"], f"{row['world']} {row['combo']}", m, ov, None, row["start"],
                  horizon)  # fmt: skip


def _start(role: str, world: str, m: Map, ov: dict, back, start, horizon: float) -> Start:
    game = _judged_game(m, ov)
    rho = ov["v_evader"] / ov["v_pursuer"]
    if start is None:
        return Start(json.dumps([world, None]), role, game, world, rho, horizon, None, None,
                     "the row records no start (a crash)")  # fmt: skip
    key = json.dumps([game, world, start])
    return Start(key, role, game, world, rho, horizon, lambda: (m, ov, back), start)


STARTS = {"unseen_worlds.py": _unseen, "pursuer_holds.py": _holds, "fixed_starts.py": _fixed,
          "evader_escapes.py": _escapes}  # fmt: skip
"""How a set's row gives its start, per script."""


def starts_of(policy_set, episodes: Mapping[str, object]) -> dict[str, Start]:
    """The start of each episode of ``policy_set`` (``policy_sets.read_set``'s), by the
    episode's key.

    Raises:
        InvalidConfigError: the set's script is not one whose rows give starts (naming it
            and the scripts that do).
    """
    if policy_set.script not in STARTS:
        raise InvalidConfigError(
            f"set {policy_set.name} is played by {policy_set.script}; expected a set of "
            f"{', '.join(STARTS)}, whose rows give their starts"
        )
    of = STARTS[policy_set.script]
    return {k: of(e.row) for k, e in episodes.items()}


# ------------------------------------------------------------------ the labels file


def _label_key(line: dict) -> str:
    return episode_rows.key([line["start"], line["cpl"]])


def read_labels(path: str) -> dict[str, dict]:
    """The labels in ``path`` by (start, CPL); empty when there is no file.

    Raises:
        InvalidConfigError: ``path`` is not a labels file (naming it and the line).
    """
    return episode_rows.read(path, _label_key, note_other_code=False)


def _final(start: Start, labels: Mapping[str, dict], cpls: Sequence[float]) -> dict:
    """The start's outcome over ``cpls``: the first certificate, else the last label at
    the finest CPL labelled (``{"label": ..., "cpl": ..., "escape_bound": ...}``).

    Raises:
        AssertionError: two resolutions certify the start for different players (a bound
            is wrong).
    """
    if start.build is None:
        return {"label": "no start", "cpl": None, "escape_bound": None}
    got = [labels[k] for c in cpls if (k := episode_rows.key([start.key, c])) in labels]
    certified = {g["label"] for g in got if g["label"] in ("pursuer", "evader")}
    if len(certified) > 1:
        raise AssertionError(f"{start.world}: the start {start.start} is certified for both "
                             f"players at cpl {[g['cpl'] for g in got]}")  # fmt: skip
    for g in got:
        if g["label"] in ("pursuer", "evader"):
            return g
    return got[-1] if got else {"label": "not labelled", "cpl": None, "escape_bound": None}


def _in_time(start: Start, final: dict) -> bool:
    """``final`` certifies an escape from ``start`` within the episode's horizon."""
    bound = final["escape_bound"]
    return final["label"] == "evader" and bound is not None and bound <= start.horizon + 1e-9


def _winnable(start: Start, final: dict) -> bool:
    """The referee certifies that the set's side can win from ``start`` within the
    episode: the pursuer holds forever, the evader escapes within the horizon."""
    if start.role == "pursuer":
        return final["label"] == "pursuer"
    return _in_time(start, final)


def _outcome(start: Start, final: dict) -> str:
    """The report's column of a lost start: ``unavoidable``, ``regret`` or an undecided
    kind (``late`` for an escape certified beyond the horizon)."""
    label = final["label"]
    if _winnable(start, final):
        return "regret"
    if label == "evader":  # a pursuer set's loss within the bound, or an escape too late
        return "unavoidable" if _in_time(start, final) else "late"
    return "unavoidable" if label == "pursuer" else label


# ------------------------------------------------------------------ labelling


def _to_label(starts: Iterable[Start], lost: set[str], cpl: float, labels: Mapping[str, dict],
              earlier: Sequence[float], losses_only: bool) -> list[Start]:  # fmt: skip
    """The starts still to label at ``cpl``: not in the file at it, not certified at an
    ``earlier`` CPL, lost ones only with ``losses_only``; ordered by game, the games with
    a lost start first (one solve each)."""
    todo: dict[str, Start] = {}
    for s in starts:
        if s.build is None or s.key in todo or (losses_only and s.key not in lost):
            continue
        if episode_rows.key([s.key, cpl]) in labels:
            continue
        if _final(s, labels, earlier)["label"] in ("pursuer", "evader"):
            continue
        todo[s.key] = s
    games_lost = {s.game for s in todo.values() if s.key in lost}
    return sorted(todo.values(), key=lambda s: (s.game not in games_lost, s.game, s.key))


def label_starts(starts: Sequence[Start], lost: set[str], cpls: Sequence[float], path: str,
                 losses_only: bool = False) -> dict[str, dict]:  # fmt: skip
    """Label ``starts`` at each of ``cpls`` in turn (a start certified at one is not
    labelled at the next), appending each label to ``path`` as it comes; every label in
    the file afterwards."""
    labels = read_labels(path)
    for i, cpl in enumerate(cpls):
        todo = _to_label(starts, lost, cpl, labels, cpls[:i], losses_only)
        games = list(dict.fromkeys(s.game for s in todo))
        what = "lost starts" if losses_only else "starts"
        print(f"  cpl {cpl:g}: {len(todo)} {what} to label in {len(games)} games", flush=True)
        if not todo:
            continue
        with episode_rows.appending(path) as write:
            t_game, game = time.perf_counter(), None
            for s in todo:
                if s.game != game:
                    if game is not None:
                        _said_game(games, game, todo, t_game, labels, cpl)
                    game, t_game = s.game, time.perf_counter()
                m, ov, back = s.build()
                with warnings.catch_warnings():  # said once per set (rho >= 0.35)
                    warnings.simplefilter("ignore", VacuousBoundWarning)
                    label, bound = referee_labels.judge(m, ov, s.start, cpl, back)
                line = {"start": s.key, "cpl": cpl, "label": label, "escape_bound": bound,
                        "world": s.world}  # fmt: skip
                if label == "unknown" and (why := referee_labels.unknown_why(m, ov, cpl)):
                    line["why"] = why
                write(line)
                labels[_label_key(line)] = line
            _said_game(games, game, todo, t_game, labels, cpl)
    return labels


def _said_game(games, game, todo, t0, labels, cpl) -> None:
    """Progress: one line per game labelled."""
    mine = [s for s in todo if s.game == game]
    got = [labels[episode_rows.key([s.key, cpl])]["label"] for s in mine]
    counts = ", ".join(f"{got.count(v)} {v}" for v in dict.fromkeys(got))
    print(f"    [{games.index(game) + 1}/{len(games)}] {mine[0].world}: {counts} "
          f"({time.perf_counter() - t0:.0f} s)", flush=True)  # fmt: skip


# ------------------------------------------------------------------ the report


@dataclass
class SetLabels:
    """One set's counts (episodes)."""

    name: str
    episodes: int
    losses: int
    unavoidable: int
    late: int
    """Losses from starts certified for the evader with an escape time beyond the horizon."""
    regrets: int
    undecided: dict[str, int]
    blind: int
    """Of the ``unknown`` losses, those on games a bound certified no state of (``why``)."""
    winnable: int | None
    """Episodes from starts certified winnable for the set's side (None: not every start
    labelled)."""
    rhos: tuple[float, ...]

    def regret(self) -> str:
        """``regrets/winnable = rate`` or why there is none."""
        if self.winnable is None:
            return "n/a (--losses-only: the winnable starts are not labelled)"
        if not self.winnable:
            why = ""
            if min(self.rhos) >= VACUOUS_RHO:
                why = f": at rho >= {VACUOUS_RHO:g} the pursuer bound certifies nothing"
            return f"n/a (no certified-winnable episode{why})"
        return f"{self.regrets}/{self.winnable} = {self.regrets / self.winnable:.3f}"


def tally(name: str, episodes: Mapping[str, object], starts: Mapping[str, Start],
          labels: Mapping[str, dict], cpls: Sequence[float], losses_only: bool,
          lines: list[str]) -> SetLabels:  # fmt: skip
    """One set's counts; each loss's line (with its outcome) appended to ``lines``."""
    undecided = {k: 0 for k in UNDECIDED}
    unavoidable = late = regrets = winnable = losses = blind = 0
    complete = not losses_only
    for key, e in episodes.items():
        s = starts[key]
        final = _final(s, labels, cpls)
        if final["label"] == "not labelled" and (not e.won or not losses_only):
            complete = False
        winnable += _winnable(s, final)
        if e.won:
            continue
        losses += 1
        kind = _outcome(s, final)
        if kind == "unavoidable":
            unavoidable += 1
        elif kind == "late":
            late += 1
        elif kind == "regret":
            regrets += 1
        else:
            undecided[kind] = undecided.get(kind, 0) + 1
        why = final.get("why") if kind == "unknown" else None
        blind += why is not None
        at = ""
        if final["cpl"] is not None:
            at = f" (cpl {final['cpl']:g}{': ' + why if why else ''})"
        bound = final["escape_bound"]
        extra = "" if bound is None else f", escape within {bound:.1f} s of {s.horizon:g}"
        cause = f"{e.cause} at {e.t:.1f} s" if e.t is not None else str(e.cause)
        if e.t is None and e.cause is None:  # an evader set's miss
            cause = "held to the horizon"
        lines.append(f"  {kind}: {name} {e.world} {e.opponent} seed={e.seed}: {cause}; "
                     f"referee: {final['label']}{at}{extra}")  # fmt: skip
    rhos = tuple(sorted({s.rho for s in starts.values()}))
    return SetLabels(name, len(episodes), losses, unavoidable, late, regrets,
                     {k: v for k, v in undecided.items() if v}, blind,
                     winnable if complete else None, rhos)  # fmt: skip


def label_sets(sets: Mapping[str, object], read: Mapping[str, Mapping[str, object]],
               cpls: Sequence[float], labels_dir: str,
               losses_only: bool = False) -> list[SetLabels]:  # fmt: skip
    """Label each set's starts (``read``: its episodes, ``policy_sets.read_set``'s) into
    ``labels_dir/SET.labels.jsonl`` and print, per set, its losses, the unavoidable ones,
    the regrets, the undecided ones and the regret; then every loss with its outcome."""
    out, lines = [], []
    for name, episodes in read.items():
        starts = starts_of(sets[name], episodes)
        lost = {starts[k].key for k, e in episodes.items() if not e.won}
        path = os.path.join(labels_dir, name + LABELS_SUFFIX)
        print(f"== {name}: {len(episodes)} episodes, {len(lost)} lost starts; labels in {path}",
              flush=True)  # fmt: skip
        if min((s.rho for s in starts.values()), default=0.0) >= VACUOUS_RHO:
            print(f"  rho >= {VACUOUS_RHO:g}: the referee's pursuer bound certifies nothing "
                  "here, so its labels are 'evader' or 'unknown'", flush=True)  # fmt: skip
        if sets[name].role == "evader":
            print("  an evader set: a loss from a start certified for the pursuer is "
                  "unavoidable, from one certified for the evader (escape within the "
                  "horizon) a regret", flush=True)  # fmt: skip
        labels = label_starts(list(starts.values()), lost, cpls, path, losses_only)
        out.append(tally(name, episodes, starts, labels, cpls, losses_only, lines))
    cpl = "/".join(f"{c:g}" for c in cpls)
    print(
        f"referee labels at cpl {cpl}, in episodes (unavoidable: lost from a start certified "
        "for the other side, an evader's escape within the horizon; late: certified for the "
        "evader, escape bound beyond the horizon; regret: lost from a start certified for "
        "the set's side, an evader's escape within the horizon; REGRET: regrets / "
        "episodes from such starts)"
    )
    head = ("set", "episodes", "losses", "unavoidable", "late", "regrets", "undecided")
    print(f"{head[0]:<16}" + "".join(f"{h:>12}" for h in head[1:]) + "  REGRET")
    for t in out:
        cols = (t.episodes, t.losses, t.unavoidable, t.late, t.regrets, sum(t.undecided.values()))
        print(f"{t.name:<16}" + "".join(f"{c:>12}" for c in cols) + f"  {t.regret()}")
    for t in out:
        if t.undecided:
            kinds = ", ".join(f"{n} {k}" for k, n in t.undecided.items())
            if t.blind:
                kinds += (f" ({t.blind} of them on games a bound certified no state of: "
                          "unknown whatever the start)")  # fmt: skip
            print(f"  {t.name} undecided: {kinds}")
    for line in lines:
        print(line)
    regrets = [x for x in lines if x.startswith("  regret:")]
    print(f"regrets: {len(regrets)}" + ("" if regrets else " (none certified)"))
    return out


def check_cpls(values: Sequence[float]) -> list[float]:
    """``--cpl`` values, increasing, each a resolution the referee takes.

    Raises:
        InvalidConfigError: a value is not a positive finite number, or they do not
            increase (naming them).
    """
    from strategies.referee.spec import check_cells_per_lmin

    cpls = [check_cells_per_lmin(v, "--cpl") for v in values]
    if any(b <= a for a, b in itertools.pairwise(cpls)):
        raise InvalidConfigError(f"--cpl {' '.join(f'{c:g}' for c in cpls)}: expected "
                                 "increasing resolutions (a start undecided at one is "
                                 "labelled at the next)")  # fmt: skip
    return cpls
