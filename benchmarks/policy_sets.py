"""Named policy benchmark sets: play them, total them, compare two runs episode by episode.

A change to a policy is measured per episode on fixed sets: each set below is one
benchmark command that README's "How well the analytic policies play" quotes, with the
figure last measured. ``run`` plays sets into a directory (one results file a set,
``DIR/SET.jsonl``, the scripts' own rows: ``benchmarks/episode_rows.py``; a rerun resumes),
``totals`` counts them, and ``compare`` lists the episodes whose winner changed between two
such directories::

    python benchmarks/policy_sets.py run holds-bench unseen-p0 --out out/base --workers 1
    # ... change the policy (in a worktree of its own), then from that checkout:
    python benchmarks/policy_sets.py run holds-bench unseen-p0 --out out/cand --workers 1
    python benchmarks/policy_sets.py compare out/base out/cand

The scripts run from the checkout this file is in (its code plays: it leads their
``PYTHONPATH``, whichever checkout is installed), one after the other,
each printing its own report; their rows record that code (``"code"``). ``compare`` lists,
per set both directories hold (a set only one holds is named, not compared), the episodes
the candidate lost that the base won and those it gained (world, opponent, seed, cause and
time of the loss, and the command that replays it), counts the rows only one side has,
says when a side's rows come from more than one code version, and exits with status 1
when the candidate lost an episode the base won (0 otherwise; 2 for a
bad directory or file), so a session can gate on it.

``label DIR`` asks the referee about every start of the sets in DIR (one solve per
game, cached on disk; ``--cpl 16 24``: a start undecided at 16 is labelled at 24) and
prints per set the losses no policy of the set's side could avoid (a pursuer set's: an
escape certified within the horizon; an evader set's: a start certified for the
pursuer), those from starts certified for the set's side (the policy's regrets: a
pursuer set's from starts the pursuer holds forever, an evader set's from starts with
an escape certified within the horizon), the undecided ones, and the regret: regrets /
episodes from such starts (``benchmarks/set_labels.py``; labels kept in
``SET.labels.jsonl``, ``--labels LDIR``, a rerun resumes; ``--losses-only`` labels the
lost starts alone)::

    python benchmarks/policy_sets.py label out/base --cpl 16 24 --losses-only

Which side won, per script (their rows differ): ``pursuer_holds.py`` keeps
``out["pursuer/decomposition"] = [winner, cause, time, ...]``; ``unseen_worlds.py`` keeps
``winner``, ``cause`` and ``t`` (an ``error`` row, a crash, is a loss); ``evader_escapes.py``
keeps ``out["shooting"] = [winner, time, ...]`` and no cause; ``fixed_starts.py`` keeps
``winner``, ``cause`` and ``t`` (an ``error`` row is a loss) and, from a start the
referee certified, ``regret``: ``compare`` says "a regret" beside such a loss.
"""

from __future__ import annotations

import argparse
import importlib
import os
import shlex
import subprocess
import sys
from collections import Counter
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import episode_rows
from bench_cli import integer, path_text, real, run

from analysis.arguments import CommandParser, output_dir
from envs.errors import InvalidConfigError

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
"""The checkout whose code the sets play (the scripts run from here)."""

SCRIPTS = ("pursuer_holds.py", "unseen_worlds.py", "evader_escapes.py", "fixed_starts.py")


@dataclass(frozen=True)
class PolicySet:
    """One benchmark command and the figure it last gave."""

    name: str
    script: str
    """One of :data:`SCRIPTS`, in ``benchmarks/``."""
    args: tuple[str, ...]
    """Its arguments, as README quotes them (``--results`` and ``--workers`` are added)."""
    role: str
    """The side whose wins are counted: ``"pursuer"`` or ``"evader"``."""
    won: int
    episodes: int
    measured: str
    """Where the figure comes from (a commit)."""
    alias: str = ""
    """The short name sessions used for it (b1, pu0, ...)."""

    def command(self) -> list[str]:
        return ["python", f"benchmarks/{self.script}", *self.args]


FRESH_WORLDS = " ".join(
    f"rand:{kind}:{seed}:3.0"
    for kind in ("convex", "rectangles", "star", "polygons")
    for seed in range(3001, 3009)
)
"""32 random maps nobody had used (docs/ANALYTIC_RESULTS.md, fresh-p0)."""
_HOLDS = "--seeds 8 --rho 0.5 --no-greedy"
_HELDOUT_P = "--worlds @benchmarks/heldout_worlds_pursuer.txt"
_BASE = "911efbc"
"""The commit every figure below holds at (branch combo-193: main a06dbce with helper-192's
pillars045-192 merged, ``_slide_through`` also against a charge running since the evader's
first move; merged into main as ed84b2a): all eighteen sets played there, compared per
episode with 7b2b484's rows: holds-bench-045 +3 (pillars seed 2 against the shooting,
toward-away and referee evaders, too close at 2.1 s before), corner-default +1 (seed 38
against the toward-away evader), every other winner the same. After it, ebfa164 (the
shooting evader's straight shots from rho 0.9 on, branch shoot-straight-195c) was played on
all eighteen at db73ef4: every winner the same, 16 sets row-identical, 77 rho-0.95 rows of
unseen-e and heldout-e with other escape times. Before: at 7b2b484 (branch decomp-orbit-190,
``_way_kept``, merged into main as 7f77e91: all seventeen sets played there, and holds-
bench-045 (the lead; the same 384 rows with main at 0d70970); compared per episode with
194babd's rows: holds-bench-03 +3, pillars seed 5 against the three chargers; heldout-p0 +1,
corner~x0.8rot1.2 against the herder; three escapes from the decomposition pursuer no longer
made, unseen-e random:rectangles:16 seed 1019, fresh-e random:rectangles:4504 seed 6880 and
rand:polygons:4605:1.5 seed 6032, escaped at 453, 479 and 649 s before; every other winner
the same). Before: at 194babd (all seventeen sets played there, compared per episode with
4be633d's rows after 9f49910's evader/referee replay: nothing lost; 9f49910 (evader/referee
plays the referee's evader-bound fallback, a stronger ground-truth opponent) lost holds-
variants, unseen-p0, heldout-p0 and fresh-p0 one episode each, two certified unavoidable,
one late, one unknown, none a certified regret; 194babd (the decomposition's slide-through
check against a charge) won holds-bench-03 +3; the certified starts were re-drawn (1c33d9d:
the referee's stronger pursuer bound) and certified-p played on them. Before: at 4be633d,
all seventeen, compared per episode with 5270138: heldout-e -1, random:star:2019 seed 258
(791d52a's give-way changed the decomposition pursuer's path there and the shooting evader's
herd, which escaped at 7.98 of 8 D/V_e, no longer escapes), every other episode's winner the
same; d6d8f9a (the shooting evader against a pursuer that does not turn the rod) moved
escape times only; lazy-speed-171 (786c56e) is the same decisions, faster). Before: at
5270138, all sixteen sets played, compared per episode with 8bef7db: unseen-e +1, heldout-e
+1 (3498ee2, the shooting evader's herd starts wherever the pursuer is), nothing lost;
fresh-e with 791668b: +3; 15b205d (the pursuers at edge parameters) was played alone on all
fifteen with every row identical, and 0d7e59f and 686f537 are the same decisions, faster.
After it 791d52a (the decomposition's hard turn gives way where it pushes into a wall) was
played on the eleven pursuer sets and the evader sets' decomposition episodes: every winner
and loss time as here). Before: at 8bef7db, all fifteen, compared per episode with 3765f76:
fresh-p0 +1 (0fee8e2, the pursuer's lead on a lap round a small obstacle: rand:star:3007:3.0
against the herder), nothing lost; 37bf9d1's two-leg shots moved escape times only). Before:
at 34fa4ca, compared per episode with 1283649: holds-bench +1, certified-e +2, nothing lost;
played again at 686fe46, the shooting evader's long-rod shots before any plan and reach
margins: every episode's winner as at 34fa4ca, escape times moved; and at 3765f76. Before:
all twelve sets were played at 94c5063; 5b239ab's pursuer change (probes round a small
obstacle an evader circles) changed only fresh-p0 (549 -> 552); 4d0ccce's (the way to room
once a ride against a charge stalls) was played on every pursuer set and on the evader sets'
episodes against the decomposition pursuer (holds-variants 558 -> 560, unseen-p0 426 -> 429,
heldout-p0 609 -> 614, heldout-p1 633 -> 636, fresh-p0 552 -> 555); bd36034's evader change
(the herd heads only for corners turning by 45 degrees or more) on the three evader sets
(heldout-e 775 -> 776) and, with 4d0ccce's pursuer, on their episodes against it; cdb9eac's
(a stalled fallback gives up its targets) and ddb7e92's (two guards on the stall) were each
played on all twelve (the evader's on the pursuer sets' shooting episodes) and, together, on
the evader sets' episodes against the decomposition pursuer and the pursuer sets' against
the shooting evader: no figure changed (ddb7e92)."""
_FRESH_E = "--worlds @benchmarks/fresh_worlds_evader.txt --rhos 0.2 0.3 0.5 0.8 --seed-base 6000"
"""fresh-e, the evader's held-out set made after the shooting evader's latest changes: 40
world labels nobody had used (``benchmarks/fresh_worlds_evader.txt``: two_rooms and office
transformed, junctions, random maps of seeds 4501-4510, 4604-4605, floor plans 9-10), rho
0.2-0.8 (0.2 in no other drawn set), seeds 6000-6999 (the other evader sets draw 100-1099)."""
_FIXED = _BASE
"""Where the three sets of ``fixed_starts.py`` were last played (first at c427419, 1283649's
policies: certified-e 310/312 there; certified-e grew to 468 episodes at ea81a89, played
at 34c7663, 3765f76, 8bef7db, 5270138, 4be633d and 194babd; certified-p's starts re-drawn at
1c33d9d, the referee's pursuer bound having grown): the
corner world's default starts (the reproduction report's episodes) and the referee's
certified starts (``benchmarks/certified_starts.json``)."""


_HOLDS_045 = _BASE
"""Where holds-bench-045 was last played: holds-bench's episodes at rho 0.45, in the band
between the sets' 0.3 and 0.5 (helper-189's fresh probe found pillars seed 2 lost there,
at rho 0.42-0.46 only, to the three charging evaders, too close at 2.1-2.2 s; the maze's
orbit seeds 0 and 5 and wall-hugging seed 6 are lost there too); first played at 0d70970
and 7b2b484, 378/384 both, every row the same; at 911efbc 381/384, pillars seed 2 held."""

_HOLDS_03 = _BASE
"""Where holds-bench-03 was last played: holds-bench's episodes at rho 0.3 instead of 0.5
(helper-166 found the decomposition pursuer's pillars losses there, seeds 3 and 5, to the
charging evaders: no set played rho 0.3 on the paper's worlds); first played at 80d5f9d
(378/384), again at 4be633d: every episode's winner the same; at 4c4631e (branch
decomp-pillars-177, the slide check) 381/384, seed 3 held against the three chargers, and
at 194babd (its merge); at 7b2b484 (branch decomp-orbit-190, the orbit choice keeps the
decomposition's clear turn toward room, ``_way_kept``) 384/384, seed 5 held too."""


def _set(name: str, alias: str, role: str, figure: str, measured: str, command: str):
    script, *args = shlex.split(command)
    won, episodes = (int(n) for n in figure.split("/"))
    return PolicySet(name, script, tuple(args), role, won, episodes, measured, alias)


SETS: dict[str, PolicySet] = {
    s.name: s
    for s in (
        _set("holds-bench", "b1", "pursuer", "380/384", _BASE,
             "pursuer_holds.py --worlds corridor l_hall open_room corner pillars maze "
             f"--variants 'as is' {_HOLDS}"),
        _set("holds-variants", "b2", "pursuer", "559/576", _BASE,
             "pursuer_holds.py --worlds corridor l_hall corner "
             f"--variants 'rot 0.37' 'x10 rot 1.1' off-centre {_HOLDS}"),
        _set("unseen-p0", "pu0", "pursuer", "428/450", _BASE,
             "unseen_worlds.py --role pursuer --combos 0"),
        _set("unseen-p1", "pu1", "pursuer", "446/450", _BASE,
             "unseen_worlds.py --role pursuer --combos 1"),
        _set("unseen-p2", "pu2", "pursuer", "486/486", _BASE,
             "unseen_worlds.py --role pursuer --combos 2"),
        _set("heldout-p0", "ph0", "pursuer", "614/648", _BASE,
             f"unseen_worlds.py --role pursuer {_HELDOUT_P} --combos 0"),
        _set("heldout-p1", "ph1", "pursuer", "636/648", _BASE,
             f"unseen_worlds.py --role pursuer {_HELDOUT_P} --combos 1"),
        _set("heldout-p2", "ph2", "pursuer", "666/666", _BASE,
             f"unseen_worlds.py --role pursuer {_HELDOUT_P} --combos 2"),
        _set("fresh-p0", "fresh_p0", "pursuer", "555/576", _BASE,
             f"unseen_worlds.py --role pursuer --combos 0 --worlds {FRESH_WORLDS}"),
        _set("unseen-e", "eunseen", "evader", "1188/1189", _BASE,
             "unseen_worlds.py --role evader"),
        _set("heldout-e", "eheldout", "evader", "776/779", _BASE,
             "unseen_worlds.py --role evader --worlds @benchmarks/heldout_worlds_evader.txt"),
        _set("fresh-e", "fresh_e", "evader", "1131/1139", _BASE,
             f"unseen_worlds.py --role evader {_FRESH_E}"),
        _set("escapes-bench", "bench3", "evader", "512/512", _BASE,
             "evader_escapes.py --seeds 4 --simple-seeds 0"),
        _set("corner-default", "cdef", "pursuer", "146/160", _FIXED,
             "fixed_starts.py --starts default --world corner --seeds 0-39"),
        _set("certified-p", "certp", "pursuer", "288/288", _FIXED,
             "fixed_starts.py --starts certified --role pursuer"),
        _set("certified-e", "certe", "evader", "468/468", _FIXED,
             "fixed_starts.py --starts certified --role evader"),
        _set("holds-bench-03", "b1r3", "pursuer", "384/384", _BASE,
             "pursuer_holds.py --worlds corridor l_hall open_room corner pillars maze "
             "--variants 'as is' --seeds 8 --rho 0.3 --no-greedy"),
        _set("holds-bench-045", "b1r45", "pursuer", "381/384", _HOLDS_045,
             "pursuer_holds.py --worlds corridor l_hall open_room corner pillars maze "
             "--variants 'as is' --seeds 8 --rho 0.45 --no-greedy"),
    )
}  # fmt: skip


# ------------------------------------------------------------------ reading the rows


@dataclass(frozen=True)
class Episode:
    """What ``compare`` says of one row."""

    key: str
    won: bool
    world: str
    opponent: str
    seed: int
    cause: str | None
    t: float | None
    code: str | None
    row: dict
    note: str = ""
    """Said after the result (``fixed_starts.py``: a loss from a certified start is a
    regret)."""


def _module(script: str):
    return importlib.import_module(script.removesuffix(".py"))


def _episode(script: str, row: dict, key: str) -> Episode:
    """``row`` of ``script`` as an :class:`Episode` (``KeyError``, ``IndexError`` or
    ``TypeError`` when it is not such a row)."""
    code = row.get("code")
    if script == "pursuer_holds.py":
        winner, cause, t = row["out"]["pursuer/decomposition"][:3]
        world = f"{row['world']} [{row['variant']}] rho={row['rho']}"
        return Episode(key, winner == "pursuer", world, row["evader"], row["seed"], cause, t,
                       code, row)  # fmt: skip
    if script == "unseen_worlds.py":
        world = f"{row['world']} {row['combo']}"
        cause = row["error"] if "error" in row else row["cause"]
        return Episode(key, row.get("winner") == row["role"], world, row["opponent"],
                       row["seed"], cause, row.get("t"), code, row)  # fmt: skip
    if script == "fixed_starts.py":
        world = row["world"] if row["combo"] is None else f"{row['world']} {row['combo']}"
        cause = row["error"] if "error" in row else row["cause"]
        # a loss from a certified start: the referee says the policy's side could win it
        note = f"a regret (certified {row['certified']}-win start)" if row.get("regret") else ""
        return Episode(key, row.get("winner") == row["role"] and "error" not in row, world,
                       row["opponent"], row["seed"], cause, row.get("t"), code, row,
                       note)  # fmt: skip
    winner, t = row["out"]["shooting"][:2]
    return Episode(key, winner == "evader", f"{row['world']} [{row['variant']}]",
                   row["pursuer"], row["seed"], None, t, code, row)  # fmt: skip


def read_set(path: str, policy_set: PolicySet) -> dict[str, Episode]:
    """The episodes of ``policy_set`` in the results file ``path``, by the script's own
    episode key; empty when there is no such file.

    Raises:
        InvalidConfigError: ``path`` is not a results file of the set's script (or holds
            rows of the other role), naming the file and what was expected.
    """
    module = _module(policy_set.script)
    own = policy_set.script in ("unseen_worlds.py", "fixed_starts.py")
    key_of = module.row_key if own else module._row_key
    rows = episode_rows.read(path, key_of, note_other_code=False)
    expected = f"expected rows of {policy_set.script} (set {policy_set.name})"
    out = {}
    for key, row in rows.items():
        if own and row["role"] != policy_set.role:
            raise InvalidConfigError(
                f"{path}: the row {key} is of the {row['role']} role; set {policy_set.name} "
                f"measures the {policy_set.role} ({expected})"
            )
        try:
            out[key] = _episode(policy_set.script, row, key)
        except (KeyError, IndexError, TypeError) as exc:
            raise InvalidConfigError(
                f"{path}: the row {key} has no {exc!s} as {policy_set.script} writes; {expected}"
            ) from None
    return out


def replay_command(policy_set: PolicySet, e: Episode) -> str:
    """The command that plays episode ``e`` again, as the set's script prints it (for
    ``evader_escapes.py``, which prints none: the script narrowed to the episode's world,
    variant and pursuer, which plays seeds 0 to the episode's)."""
    module = _module(policy_set.script)
    r = e.row
    if policy_set.script == "pursuer_holds.py":
        return module.replay_command(r["world"], r["variant"], r["rho"], r["evader"], r["seed"],
                                     r["max_cycles"], r["l_min"])  # fmt: skip
    if policy_set.script in ("unseen_worlds.py", "fixed_starts.py"):
        return module.replay_command(r)
    words = ["python", "benchmarks/evader_escapes.py", "--worlds", r["world"], "--variants",
             r["variant"], "--pursuers", r["pursuer"], "--seeds", str(r["seed"] + 1),
             "--simple-seeds", "0", "--k", f"{r['k']:g}", "--start", r["start"]]  # fmt: skip
    return shlex.join(words) + f"  # seeds 0-{r['seed']}"


# ------------------------------------------------------------------ the commands


def _sets_in(directory: str, sets: Mapping[str, PolicySet]) -> list[str]:
    """The names of the sets with a results file in ``directory``."""
    if not os.path.isdir(directory):
        what = "not a directory" if os.path.exists(directory) else "no such directory"
        raise InvalidConfigError(
            f"{directory!r}: {what}; expected a directory of results files "
            "written by 'policy_sets.py run --out DIR'"
        )
    names = [n for n in sets if os.path.isfile(os.path.join(directory, f"{n}.jsonl"))]
    if not names:
        raise InvalidConfigError(
            f"{directory!r} holds no results file of any set; expected files named SET.jsonl, "
            f"SET one of {', '.join(sets)}"
        )
    return names


def _versions(episodes: Mapping[str, Episode]) -> str:
    counts = Counter(str(e.code) if e.code else "not recorded" for e in episodes.values())
    return ", ".join(f"{c} ({n})" for c, n in counts.most_common())


def _wins(episodes: Mapping[str, Episode]) -> str:
    return f"{sum(e.won for e in episodes.values())}/{len(episodes)}"


def totals(directory: str, sets: Mapping[str, PolicySet] = SETS) -> int:
    """Print, per set with results in ``directory``, the wins of the set's role over its
    episodes beside the figure last measured, and the code versions of its rows."""
    names = _sets_in(directory, sets)
    read = {n: read_set(os.path.join(directory, f"{n}.jsonl"), sets[n]) for n in names}
    print(f"{'set':<16}{'role':<9}{'won':>11}  {'last measured':<28}code (rows)")
    for name, episodes in read.items():
        s = sets[name]
        note = ""
        if len(episodes) != s.episodes:
            note = f"  [{len(episodes)} of the set's {s.episodes} episodes]"
        last = f"{s.won}/{s.episodes} at {s.measured}"
        print(f"{name:<16}{s.role:<9}{_wins(episodes):>11}  {last:<28}{_versions(episodes)}{note}")
    return 0


def _describe(e: Episode) -> str:
    words = ["won" if e.won else "lost"]
    if e.cause is not None:
        words.append(str(e.cause))
    if e.t is not None:
        words.append(f"at {e.t:.2f} s")
    elif e.cause is None:
        words.append("to the horizon")
    return " ".join(words) + (f", {e.note}" if e.note else "")


def compare(base: str, cand: str, sets: Mapping[str, PolicySet] = SETS) -> int:
    """Print, per set in both directories, the episodes whose winner changed from ``base``
    to ``cand``; 1 when ``cand`` lost an episode ``base`` won, else 0.

    Raises:
        InvalidConfigError: a directory is missing or holds no set, or the two hold no set
            in common.
    """
    in_base, in_cand = _sets_in(base, sets), _sets_in(cand, sets)
    names = [n for n in in_base if n in in_cand]
    if not names:
        raise InvalidConfigError(
            f"{base!r} and {cand!r} have no set in common (base: {', '.join(in_base)}; "
            f"cand: {', '.join(in_cand)}); expected results files of the same set in both"
        )
    for side, only in (("base", in_base), ("cand", in_cand)):
        if set(only) - set(names):
            print(f"sets only in {side} (not compared): "
                  f"{', '.join(n for n in only if n not in names)}")  # fmt: skip
    lost_any = 0
    for name in names:
        s = sets[name]
        b = read_set(os.path.join(base, f"{name}.jsonl"), s)
        c = read_set(os.path.join(cand, f"{name}.jsonl"), s)
        both = [k for k in b if k in c]
        lost = [k for k in both if b[k].won and not c[k].won]
        gained = [k for k in both if c[k].won and not b[k].won]
        lost_any += len(lost)
        print(f"{name} ({s.role} wins): base {_wins(b)}, cand {_wins(c)}; {len(both)} episodes "
              f"in both: {len(lost)} lost, {len(gained)} gained")  # fmt: skip
        for side, episodes in (("base", b), ("cand", c)):
            if len({e.code for e in episodes.values()}) > 1:
                print(f"  note: the {side} rows come from more than one code version: "
                      f"{_versions(episodes)}")  # fmt: skip
        only_b, only_c = len(b) - len(both), len(c) - len(both)
        if only_b or only_c:
            print(f"  rows only in base: {only_b}, only in cand: {only_c} (not compared)")
        for label, keys in (("lost", lost), ("gained", gained)):
            for k in keys:
                e = c[k]
                print(f"  {label}: {e.world} {e.opponent} seed={e.seed}: cand {_describe(e)}; "
                      f"base {_describe(b[k])}")  # fmt: skip
                print(f"    replay: {replay_command(s, e)}")
    print(f"cand lost {lost_any} episode(s) that base won" if lost_any else "cand lost none")
    return 1 if lost_any else 0


def label(directory: str, names: Sequence[str], cpls: Sequence[float], labels_dir: str | None,
          losses_only: bool = False, sets: Mapping[str, PolicySet] = SETS) -> int:  # fmt: skip
    """Label the starts of the sets ``names`` (default: every set) in
    ``directory`` with the referee (:mod:`set_labels`), into ``labels_dir`` (default
    ``directory``), and print each set's losses, unavoidable ones, regrets, undecided
    ones and regret.

    Raises:
        InvalidConfigError: the directory holds no set, a named set is not in it or is not
            a set whose rows give starts, or a ``cpls`` value is not a resolution.
    """
    import set_labels

    cpls = set_labels.check_cpls(cpls)
    present = _sets_in(directory, sets)
    for n in names:
        if n not in present:
            raise InvalidConfigError(f"{directory!r} holds no results file of set {n} "
                                     f"({n}.jsonl); it holds {', '.join(present)}")  # fmt: skip
        set_labels.starts_of(sets[n], {})  # a set it cannot judge is refused before any solve
    chosen = list(dict.fromkeys(names)) or present
    out = labels_dir or directory
    output_dir("--labels", out)
    read = {n: read_set(os.path.join(directory, f"{n}.jsonl"), sets[n]) for n in chosen}
    set_labels.label_sets(sets, read, cpls, out, losses_only)
    return 0


def _playing_here() -> dict[str, str]:
    """The environment of a script that plays this checkout's code: :data:`ROOT` first on
    ``PYTHONPATH``. ``python benchmarks/X.py`` puts ``benchmarks/`` on the import path, not
    the checkout, so without it a script in a second checkout (a git worktree) imported
    the package from the checkout installed in editable mode, and its rows were that
    checkout's play."""
    paths = [ROOT, *[p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p]]
    return {**os.environ, "PYTHONPATH": os.pathsep.join(paths)}


def run_sets(names: Sequence[str], out: str, workers: int | None,
             sets: Mapping[str, PolicySet] = SETS) -> int:  # fmt: skip
    """Play each set through its script into ``out/SET.jsonl`` (resuming), then print the
    totals; non-zero when a script failed."""
    failed = []
    os.makedirs(out, exist_ok=True)
    for name in names:
        s = sets[name]
        results = os.path.abspath(os.path.join(out, f"{name}.jsonl"))
        argv = [sys.executable, os.path.join("benchmarks", s.script), *s.args, "--results", results]
        if workers is not None:
            argv += ["--workers", str(workers)]
        print(f"== {name}: {shlex.join([*s.command(), '--results', results])}", flush=True)
        code = subprocess.run(argv, cwd=ROOT, env=_playing_here()).returncode
        if code:
            print(f"== {name}: {s.script} exited with status {code}", flush=True)
            failed.append(name)
    written = {n: sets[n] for n in names if os.path.isfile(os.path.join(out, f"{n}.jsonl"))}
    if written:
        totals(out, written)
    if failed:
        print(f"failed: {', '.join(failed)}")
    return 1 if failed else 0


def _set_list() -> str:
    lines = ["sets (name, short name, figure last measured, command):"]
    for s in SETS.values():
        command = shlex.join(s.command()).replace(
            FRESH_WORLDS,
            "rand:KIND:SEED:3.0 (KIND convex rectangles star polygons, SEED 3001-3008)",
        )
        lines.append(f"  {s.name} ({s.alias}): {s.won}/{s.episodes} {s.role} wins at "
                     f"{s.measured}: {command}")  # fmt: skip
    return "\n".join(lines)


def _set_name(text: str) -> str:
    """A set's name, given as it or as its short name (``b1``, ``pu0``...)."""
    if text in SETS:
        return text
    for s in SETS.values():
        if text == s.alias:
            return s.name
    raise argparse.ArgumentTypeError(
        f"{text!r}: expected a set name, one of {', '.join(SETS)} (or its short name, "
        f"{', '.join(s.alias for s in SETS.values())})"
    )


def main(argv=None) -> int:
    ap = CommandParser(description=__doc__.splitlines()[0], epilog=_set_list(),
                       formatter_class=argparse.RawDescriptionHelpFormatter)  # fmt: skip
    sub = ap.add_subparsers(dest="command", required=True)
    p = sub.add_parser("run", help="play sets into DIR/SET.jsonl (resumes), then their totals")
    p.add_argument("sets", nargs="+", type=_set_name, metavar="SET",
                   help="a set's name or short name (listed by --help)")  # fmt: skip
    p.add_argument("--out", required=True, type=path_text("a directory"), metavar="DIR",
                   help="the results files go to DIR/SET.jsonl (a rerun resumes them)")  # fmt: skip
    p.add_argument("--workers", type=integer(1), default=None,
                   help="passed to each script (default: the script's own)")  # fmt: skip
    p = sub.add_parser("totals", help="per set in DIR: wins / episodes, code versions")
    p.add_argument("dir", type=path_text("a directory"), metavar="DIR",
                   help="a directory 'run --out DIR' wrote")  # fmt: skip
    p = sub.add_parser("label", help="the referee's label of each start of the sets in DIR: "
                       "losses unavoidable, regrets, undecided; the regret per set")  # fmt: skip
    p.add_argument("dir", type=path_text("a directory"), metavar="DIR",
                   help="a directory 'run --out DIR' wrote")  # fmt: skip
    p.add_argument("sets", nargs="*", type=_set_name, metavar="SET",
                   help="sets to label (default: every set in DIR)")  # fmt: skip
    p.add_argument("--cpl", nargs="+", type=real(0), default=[16.0], metavar="CPL",
                   help="the referee's cells per L_min (default 16); several: a start "
                   "undecided at one is labelled at the next")  # fmt: skip
    p.add_argument("--labels", type=path_text("a directory"), metavar="LDIR",
                   help="where SET.labels.jsonl go (default: DIR; a rerun resumes)")  # fmt: skip
    p.add_argument("--losses-only", action="store_true",
                   help="label the lost starts only (no regret: the winnable starts are "
                   "not counted)")  # fmt: skip
    p = sub.add_parser("compare", help="per episode: winner changed from BASE to CAND "
                       "(exit 1 when CAND lost one BASE won)")  # fmt: skip
    p.add_argument("base", type=path_text("a directory"), metavar="BASE",
                   help="the run of the code before the change ('run --out BASE')")  # fmt: skip
    p.add_argument("cand", type=path_text("a directory"), metavar="CAND",
                   help="the run of the changed code, from its own checkout")  # fmt: skip
    args = ap.parse_args(argv)
    if args.command == "run":
        output_dir("--out", args.out)  # a file there was "error: /etc/passwd: File exists"
        return run_sets(list(dict.fromkeys(args.sets)), args.out, args.workers)
    if args.command == "totals":
        return totals(args.dir)
    if args.command == "label":
        return label(args.dir, args.sets, args.cpl, args.labels, args.losses_only)
    return compare(args.base, args.cand)


if __name__ == "__main__":
    raise SystemExit(run(main))
