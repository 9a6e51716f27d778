"""Tournament reports: Markdown beside its pictures, and one self-contained HTML page.

:func:`write_report` reads a run from a store and writes ``report.md``, ``report.html``
(images embedded as data URIs: the page can be mailed on its own) and the pictures
(``heatmaps-HASH.png``, ``ratings-HASH.png``, ``replay_K-HASH.gif``, each named by its
content) into a directory. Nothing is written until everything is computed, then the
pictures, then the pages, each through a rename; the previous report's pictures are
removed last: an interrupted report leaves the previous one whole. Sections:

1. the run (spec, counts, forfeits and errors);
2. payoff matrices per map and overall as heat maps and tables (held rate with its
   Wilson interval, mean time to escape, causes);
3. the zero-sum game of each matrix: Nash mixtures, value, exploitability;
4. Bradley-Terry ratings with bootstrap intervals;
5. paired comparisons on shared starts (McNemar exact, Holm-adjusted);
6. regret on certified starts (filled by the referee, :mod:`strategies.referee`, when it
   offers ``tournament_regret``);
7. replays of the most decisive matches, re-simulated from their seeds through the
   shared runner (and checked against the stored outcome), as GIFs.
"""

from __future__ import annotations

import base64
import hashlib
import html
import io
import json
import math
import os
import re
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from analysis.tournament import statistics as st
from analysis.tournament.store import Store
from envs.files import written_whole

__all__ = ["Analysis", "analyse", "write_report"]

MAX_REPLAYS = 4
REPLAY_FRAMES = 90
REPLAY_SIZE = 260


@dataclass
class Analysis:
    """Everything a report shows, computed from one run's rows."""

    run: dict[str, Any]
    rows: list[dict[str, Any]]
    cells: list[st.Cell]
    matrices: list[st.Matrix]
    games: list[st.Game]
    ratings: list[st.Rating]
    paired: list[st.PairedComparison]
    errors: list[dict[str, Any]]
    notes: list[str] = field(default_factory=list)
    geometry: dict[str, Any] = field(default_factory=dict)  # map digest -> stored geometry


def doubled_note(run_id: str, n: int) -> str:
    """What ``n`` starts held twice (:meth:`Store.doubled`) do to a run's figures, and the
    command that repairs it."""
    return (
        f"run {run_id} holds {n} start(s) twice (matches an older surveil identified "
        "otherwise, added beside today's): its counts and intervals count them twice; run "
        "its `surveil tournament` once more (its finished matches are reused, the older "
        "ones set aside as a run of their own) before reading these figures"
    )


def analyse(store: Store | str | os.PathLike[str], run_id: str | None = None) -> Analysis:
    """Compute the statistics of a run (default: the store's latest)."""
    db = store if isinstance(store, Store) else Store(store, create=False)
    with db.snapshot():  # a running tournament's counts and rows at one moment
        run = db.run(run_id)
        rows = db.rows(run["run_id"])
        doubled = db.doubled(run["run_id"])
        errors = db.errors(run["run_id"])
        geometry = {m["digest"]: db.map_geometry(m["digest"]) for m in _spec(run).get("maps", [])}
    notes = [doubled_note(run["run_id"], doubled)] if doubled else []
    cells = st.cells(rows)
    matrices = st.payoff_matrices(cells)
    return Analysis(
        run=run,
        rows=rows,
        cells=cells,
        matrices=matrices,
        games=st.games(matrices),
        ratings=st.ratings(rows),
        paired=st.paired_comparisons(rows),
        errors=errors,
        notes=notes,
        geometry=geometry,
    )


def _spec(run: dict[str, Any]) -> dict[str, Any]:
    spec = run["spec"]
    return json.loads(spec) if isinstance(spec, str) else spec


# --------------------------------------------------------------------------- pictures
def _png(fig: Any) -> bytes:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110)
    return buf.getvalue()


def heatmaps_png(matrices: list[st.Matrix], cells: list[st.Cell]) -> bytes:
    """One heat map per scope: held rate, its Wilson interval and the mean escape time."""
    from matplotlib.figure import Figure

    by = {(c.scope, c.pursuer, c.evader): c for c in cells}
    n = len(matrices)
    cols = min(n, 3)
    rows = math.ceil(n / cols)
    ps = max(len(m.pursuers) for m in matrices)
    es = max(len(m.evaders) for m in matrices)
    fig = Figure(figsize=(cols * (1.8 + 1.2 * es), rows * (1.3 + 0.6 * ps)), layout="constrained")
    axes = np.atleast_1d(fig.subplots(rows, cols, squeeze=False)).ravel()
    image = None
    for ax, m in zip(axes, matrices, strict=False):
        image = ax.imshow(m.rate, cmap="RdYlBu", vmin=0.0, vmax=1.0, aspect="auto")
        for i, p in enumerate(m.pursuers):
            for j, e in enumerate(m.evaders):
                c = by.get((m.scope, p, e))
                if c is None or c.n == 0:
                    continue
                esc = "" if math.isnan(c.escape_mean) else f"\n{c.escape_mean:.1f} s"
                colour = "white" if c.rate < 0.3 or c.rate > 0.8 else "black"
                ax.text(
                    j,
                    i,
                    f"{c.rate:.2f}\n[{c.lo:.2f}, {c.hi:.2f}]{esc}",
                    ha="center",
                    va="center",
                    fontsize=6.5,
                    color=colour,
                )
        ax.set_xticks(
            range(len(m.evaders)),
            [_short(e) for e in m.evaders],
            rotation=30,
            ha="right",
            fontsize=7,
        )
        ax.set_yticks(range(len(m.pursuers)), [_short(p) for p in m.pursuers], fontsize=7)
        ax.set_title(f"{m.scope} (n <= {int(m.n.max())} per cell)", fontsize=8)
    for ax in axes[n:]:
        ax.set_visible(False)
    if image is not None:
        fig.colorbar(image, ax=axes[:n].tolist(), shrink=0.8).set_label(
            "surveillance held to the horizon (rate)", fontsize=8
        )
    fig.suptitle(
        "pursuers (rows) vs evaders (columns): held rate, 95% CI, mean escape time", fontsize=9
    )
    return _png(fig)


def ratings_png(ratings: list[st.Rating]) -> bytes:
    """Strengths with their bootstrap intervals, pursuers and evaders on one scale."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(6.0, 0.9 + 0.32 * len(ratings)), layout="constrained")
    ax = fig.subplots()
    y = np.arange(len(ratings))[::-1]
    for k, r in zip(y, ratings, strict=True):
        colour = "#2856dc" if r.role == "pursuer" else "#dc3232"
        ax.errorbar(
            r.strength,
            k,
            xerr=[[r.strength - r.lo], [r.hi - r.strength]],
            fmt="o",
            color=colour,
            capsize=3,
        )
    ax.set_yticks(y, [f"{r.role[0].upper()}: {_short(r.label)}" for r in ratings], fontsize=7)
    ax.axvline(0.0, color="grey", lw=0.6)
    ax.set_xlabel(
        "Bradley-Terry strength (logit; pursuer minus evader = log-odds of holding)", fontsize=8
    )
    return _png(fig)


def _short(label: str) -> str:
    return label.split("/", 1)[-1] if label.count("/") == 1 else label


# --------------------------------------------------------------------------- replays
@dataclass
class Replay:
    """A re-simulated match: its caption, GIF bytes and whether it matched the store."""

    title: str
    gif: bytes
    consistent: bool


def _decisive(a: Analysis) -> list[dict[str, Any]]:
    """Per map scope: the Nash-heaviest pursuer vs evader, their quickest escape or a hold."""
    picks = []
    best = {g.scope: g for g in a.games}
    strength = {(r.role, r.label): r.strength for r in a.ratings}
    scopes = [m.scope for m in a.matrices if m.scope != st.OVERALL]
    for scope in scopes[:MAX_REPLAYS]:
        g = best.get(scope)
        if g is not None:
            p = max(g.pursuers, key=g.pursuers.get)
            e = max(g.evaders, key=g.evaders.get)
        else:
            m = next(m for m in a.matrices if m.scope == scope)
            p = max(m.pursuers, key=lambda x: strength.get(("pursuer", x), 0.0))
            e = max(m.evaders, key=lambda x: strength.get(("evader", x), 0.0))
        variants = len({r["variant"] for r in a.rows}) > 1
        starts = len({r["start"] for r in a.rows}) > 1
        mine = [
            r
            for r in a.rows
            if r["pursuer"] == p
            and r["evader"] == e
            and r["status"] == "ok"
            and st.scope_of(r, variants=variants, starts=starts) == scope
        ]
        escapes = [r for r in mine if r["winner"] == "evader"]
        if escapes:
            picks.append(min(escapes, key=lambda r: r["escape_time"]))
        elif mine:
            picks.append(mine[0])
    return picks


def _replay(db: Store, run: dict[str, Any], row: dict[str, Any]) -> Replay | None:
    from envs.maps.io import map_from_dict
    from strategies.policies import make_policy
    from strategies.runner import run_episode

    ident = db.identity(row["match_id"])
    geometry = db.map_geometry(ident["map"])
    if geometry is None:
        return None
    world = map_from_dict(geometry, source="store").map
    spec = run["spec"]
    entries = {(p["role"], p["label"]): p for p in (*spec["pursuers"], *spec["evaders"])}
    pols = {}
    for role in ("pursuer", "evader"):
        entry = entries[(role, row[role])]
        if entry["model"] is not None:
            path = entry.get("model_path")
            if not path or not Path(path).is_file() or _sha(path) != entry["model"]:
                return None  # the model file is gone or changed: no faithful replay
            pols[role] = make_policy(f"{role}/sb3:{path}", **entry["params"])
        else:
            pols[role] = make_policy(entry["name"], **entry["params"])
    result = run_episode(
        world,
        pols["pursuer"],
        pols["evader"],
        ident["seed"],
        overrides=ident["env"],
        start=ident["start"],
        observations={
            "pursuer": ident["pursuer"]["observation"],
            "evader": ident["evader"]["observation"],
        },
    )
    consistent = result.winner == row["winner"] and result.steps == row["steps"]
    outcome = (
        f"escape at {result.escape_time:.1f} s ({result.cause})"
        if result.winner == "evader"
        else f"held {result.steps} steps"
    )
    # the variant too (a [grid] run has one scope per map and value: two 'u.wkt' replays
    # at rho = 0.1 and 1.5 were captioned alike)
    where = f"{row['map']} | {row['variant']}" if row.get("variant") else row["map"]
    title = f"{where}: {row['pursuer']} vs {row['evader']}, seed {row['seed']}: {outcome}"
    return Replay(title, _gif(result), consistent)


def _sha(path: str) -> str:
    import hashlib

    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def _gif(result: Any) -> bytes:
    from PIL import Image

    from analysis.replay import iter_trajectory_frames

    last = len(result.trajectory) - 1
    picks = sorted({round(k * last / max(REPLAY_FRAMES - 1, 1)) for k in range(REPLAY_FRAMES)})
    frames = [
        Image.fromarray(f)
        for f in iter_trajectory_frames(result, size=REPLAY_SIZE, trail=60, indices=picks)
    ]
    buf = io.BytesIO()
    durations = [60] * (len(frames) - 1) + [1500]
    frames[0].save(
        buf, format="GIF", save_all=True, append_images=frames[1:], duration=durations, loop=0
    )
    return buf.getvalue()


# --------------------------------------------------------------------------- writing
NO_REGRET = (
    "Not computed: the report was written with --no-regret (the table solves the referee's "
    "game of each map and parameter set played; the solves are cached, so paid once)"
)
"""The regret section of a report written with ``regret=False``."""


def _regret_section(a: Analysis, say: Callable[[str], None] | None = None) -> tuple[str, str]:
    """The referee's regret table (Markdown, HTML), or a note saying why it is missing
    (its games' solves, a bar over them on a terminal, would exceed the memory budget).
    ``say`` is told the estimate first when the solves not cached may take longer than
    :data:`analysis.referee_cli.LONG_SOLVE_SECONDS` (a report solved for over 9 minutes
    without a word under ``--no-progress``)."""
    from envs.errors import MemoryBudgetError
    from strategies.referee import tournament_regret
    from strategies.referee.regrets import DEFAULT_CELLS_PER_LMIN

    geometry = {d: g for d, g in a.geometry.items() if g is not None}
    before = None if say is None else (lambda sizes: _say_if_long(sizes, say))
    try:
        table = tournament_regret(a.run["spec"], a.rows, geometry=geometry, before_solve=before)
    except MemoryBudgetError as exc:  # one table, not the whole report (it stopped there)
        knob = f"the resolution (the report's is {DEFAULT_CELLS_PER_LMIN:g} cells per L_min)"
        text = f"Not solved: {exc.named(knob, MemoryBudgetError.ENV_BUDGET)}"
        return text, f"<p>{html.escape(text)}</p>"
    return _md_table(table), _html_table(table)


def _say_if_long(sizes: list, say: Callable[[str], None]) -> None:
    """Tell ``say`` the regret table's solves (:func:`~strategies.referee.regrets.regret`'s
    ``before_solve`` sizes) and their time, an upper bound, when it is long: the estimate
    ``surveil referee`` announces (:func:`strategies.referee._budget.duration`)."""
    from analysis.referee_cli import LONG_SOLVE_SECONDS
    from strategies.referee._budget import duration
    from strategies.referee.regrets import DEFAULT_CELLS_PER_LMIN

    retries = ("pursuer bound's fallback", "evader bound's fallback")
    first = [s for s in sizes if s.what not in retries]
    seconds = sum(s.seconds for s in first)
    retry = sum(s.seconds for s in sizes) - seconds
    if seconds + retry <= LONG_SOLVE_SECONDS:
        return
    states = sum(s.states for s in first)
    why = [
        text
        for what, text in zip(
            retries,
            ("pursuer bounds certify no state and are solved again one cell finer",
             "evader bounds certify next to nothing and are solved again finer"),
            strict=True,
        )
        if any(s.what == what for s in sizes)
    ]  # fmt: skip
    more = f", or {duration(seconds + retry)} if {' or '.join(why)}" if retry else ""
    say(
        f"the regret table: solving {len(first)} referee bound(s) not in the cache "
        f"({DEFAULT_CELLS_PER_LMIN:g} cells per L_min, {states / 1e6:.3g} M states): up to "
        f"about {duration(seconds)}{more} (an upper bound, estimated before the solve); "
        "--no-regret skips the table"
    )


def _fmt(x: float, digits: int = 2) -> str:
    return "-" if x is None or (isinstance(x, float) and math.isnan(x)) else f"{x:.{digits}f}"


def _tables(a: Analysis) -> dict[str, list[list[str]]]:
    t: dict[str, list[list[str]]] = {}
    t["cells"] = [
        ["scope", "pursuer", "evader", "n", "held [95% CI]", "mean escape s [95% CI]", "causes"]
    ]
    for c in a.cells:
        esc = _fmt(c.escape_mean)
        if math.isfinite(c.escape_lo):
            esc += f" [{max(c.escape_lo, 0):.2f}, {c.escape_hi:.2f}]"
        t["cells"].append(
            [
                c.scope,
                c.pursuer,
                c.evader,
                str(c.n),
                f"{_fmt(c.rate)} [{c.lo:.2f}, {c.hi:.2f}]",
                esc,
                ", ".join(f"{k}: {v}" for k, v in sorted(c.causes.items())),
            ]
        )
    t["games"] = [
        [
            "scope",
            "value (held rate)",
            "pursuer mixture",
            "evader mixture",
            "pursuer exploitability",
            "evader exploitability",
        ]
    ]
    for g in a.games:
        mix = lambda d: ", ".join(f"{k}: {v:.2f}" for k, v in d.items() if v > 0.005) or "-"
        t["games"].append(
            [
                g.scope,
                f"{g.value:.3f}",
                mix(g.pursuers),
                mix(g.evaders),
                ", ".join(f"{k}: {v:.2f}" for k, v in g.pursuer_exploitability.items()),
                ", ".join(f"{k}: {v:.2f}" for k, v in g.evader_exploitability.items()),
            ]
        )
    t["ratings"] = [["role", "policy", "strength", "95% interval", "matches"]]
    for r in a.ratings:
        t["ratings"].append(
            [r.role, r.label, f"{r.strength:+.2f}", f"[{r.lo:+.2f}, {r.hi:+.2f}]", str(r.matches)]
        )
    t["paired"] = [
        ["role", "a", "b", "shared starts", "a only", "b only", "p (McNemar)", "p (Holm)"]
    ]
    for p in a.paired:
        t["paired"].append(
            [
                p.role,
                p.a,
                p.b,
                str(p.pairs),
                str(p.a_only),
                str(p.b_only),
                f"{p.p_value:.3g}",
                f"{p.p_holm:.3g}",
            ]
        )
    t["errors"] = [["match", "kind", "message"]]
    for e in a.errors[:50]:
        t["errors"].append([str(e["match_id"])[:12], e["kind"], e["message"]])
    return t


def _md_table(rows: list[list[str]]) -> str:
    if len(rows) < 2:
        return "(none)"
    esc = lambda s: str(s).replace("|", "\\|")
    lines = ["| " + " | ".join(map(esc, rows[0])) + " |", "|" + "---|" * len(rows[0])]
    lines += ["| " + " | ".join(map(esc, r)) + " |" for r in rows[1:]]
    return "\n".join(lines)


def _html_table(rows: list[list[str]]) -> str:
    if len(rows) < 2:
        return "<p>(none)</p>"
    head = "".join(f"<th>{html.escape(str(c))}</th>" for c in rows[0])
    body = "".join(
        "<tr>" + "".join(f"<td>{html.escape(str(c))}</td>" for c in r) + "</tr>" for r in rows[1:]
    )
    return f"<table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"


_CSS = """body{font-family:system-ui,sans-serif;max-width:1100px;margin:2em auto;padding:0 1em;
color:#222}table{border-collapse:collapse;font-size:13px;margin:.5em 0 1.5em}
td,th{border:1px solid #ccc;padding:3px 7px;text-align:left}th{background:#f0f0f4}
img{max-width:100%}figure{display:inline-block;margin:.5em}figcaption{font-size:12px}
.warn{color:#a40}"""


def write_report(
    store: Store | str | os.PathLike[str],
    out_dir: str | os.PathLike[str],
    *,
    run_id: str | None = None,
    replays: bool = True,
    regret: bool = True,
    say: Callable[[str], None] | None = None,
) -> dict[str, Path]:
    """Write ``report.md``, ``report.html`` and the pictures of a run into ``out_dir``.

    Args:
        store, out_dir, run_id: the store, the directory, the run (default: the latest).
        replays: re-simulate the decisive matches as GIFs.
        regret: the regret table (the referee solves each game played, seconds to hours
            the first time); False writes :data:`NO_REGRET` in its place.
        say: told, before a long regret solve, what it solves and its estimated time.

    Returns:
        ``{"markdown": path, "html": path, ...}`` of every file written.
    """
    db = store if isinstance(store, Store) else Store(store, create=False)
    a = analyse(db, run_id)
    out = Path(out_dir)
    images: list[tuple[str, str, bytes, str]] = []  # (section, file, bytes, caption)
    if a.matrices:
        images.append(
            ("matrices", "heatmaps", heatmaps_png(a.matrices, a.cells), "held rate per pairing")
        )
    if a.ratings:
        images.append(("ratings", "ratings", ratings_png(a.ratings), "ratings"))
    if replays:
        for k, row in enumerate(_decisive(a)):
            rep = _replay(db, a.run, row)
            if rep is None:
                a.notes.append(f"no replay of {row['match_id'][:12]}: model or map unavailable")
                continue
            if not rep.consistent:
                a.notes.append(
                    f"replay of {row['match_id'][:12]} differs from the stored "
                    "outcome: the code changed since it was played (set the spec's "
                    "salt to replay everything)"
                )
            images.append(("replays", f"replay_{k}", rep.gif, rep.title))
    # each picture is named by its content: one written beside an older report.md never
    # replaces a picture that report shows
    images = [(sec, _image_name(stem, data), data, cap) for sec, stem, data, cap in images]
    tables = _tables(a)
    if regret:
        regret_md, regret_html = _regret_section(a, say)
    else:
        regret_md, regret_html = NO_REGRET, f"<p>{html.escape(NO_REGRET)}</p>"
    # nothing is written before everything is computed (the regret table can take hours):
    # an interrupted report leaves the previous one as it was, its pictures included
    markdown = _markdown(a, tables, images, regret_md)
    page = _html(a, tables, images, regret_html)
    out.mkdir(parents=True, exist_ok=True)
    before = _pictures_of(out / "report.md")
    files: dict[str, Path] = {}
    for _, name, data, _ in images:
        files[name] = _write_atomically(out / name, data)
    files["html"] = _write_atomically(out / "report.html", page.encode("utf-8"))
    files["markdown"] = _write_atomically(out / "report.md", markdown.encode("utf-8"))
    # then the pictures no report shows: the previous report's, and those of a report
    # interrupted while it wrote them
    strays = {p.name for p in out.iterdir() if _HASHED.fullmatch(p.name)}
    for name in (before | strays) - files.keys():
        (out / name).unlink(missing_ok=True)
    return files


_PICTURE = re.compile(r"(heatmaps|ratings|replay_\d+)(-[0-9a-f]{12})?\.(png|gif)")
"""The names of the pictures a report writes (and wrote, without the hash, before they had
one)."""
_HASHED = re.compile(r"(heatmaps|ratings|replay_\d+)-[0-9a-f]{12}\.(png|gif)")


def _image_name(stem: str, data: bytes) -> str:
    """``heatmaps-0123456789ab.png``: the stem, the content's hash and its type."""
    suffix = ".gif" if data[:4] == b"GIF8" else ".png"
    return f"{stem}-{hashlib.sha256(data).hexdigest()[:12]}{suffix}"


def _pictures_of(markdown: Path) -> set[str]:
    """The report's pictures that ``markdown`` (a report.md, if there is one) shows."""
    try:
        text = markdown.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError):
        return set()
    return {m for m in re.findall(r"!\[[^\]]*\]\(([^)/\\]+)\)", text) if _PICTURE.fullmatch(m)}


def _write_atomically(path: Path, data: bytes) -> Path:
    """Write ``path`` through a temporary file beside it and a rename: a reader (or an
    interruption) sees the old file or the new one, never half of one."""
    with written_whole(path, "report file") as tmp:  # a full disk: named, the old one kept
        tmp.write_bytes(data)
    return path


def _header(a: Analysis) -> list[str]:
    run, spec = a.run, a.run["spec"]
    statuses = {s: sum(r["status"] == s for r in a.rows) for s in ("ok", "forfeit", "error")}
    sequential = []
    if spec.get("sprt"):
        from analysis.tournament.driver import Sequential

        sequential = [Sequential(spec["sprt"], a.rows).describe()]
    return [
        f"run `{run['run_id']}` ({run['status']}): {run['done']} of {run['planned']} matches "
        f"stored; {statuses['forfeit']} forfeits, {statuses['error']} errors",
        f"maps: {', '.join(m['label'] for m in spec['maps'])}; seeds: {len(spec['seeds'])}; "
        f"starts: {', '.join(spec['starts'])}; {_time_limit(spec)}",
        f"env: {json.dumps(spec['env'])}; grid: "
        f"{', '.join(v['label'] for v in spec['variants'] if v['label']) or 'none'}",
        *sequential,
    ]


def _time_limit(spec: dict[str, Any]) -> str:
    """How a run's time limit was applied (a run an older surveil played says so)."""
    limit = f"time limit {spec['time_limit']:g} s"
    if spec.get("time_limit_rule"):
        return (
            f"{limit} of decision time per role per match (its policy's reset and actions; "
            "a role whose clock runs out forfeits)"
        )
    return (
        f"{limit} per match, as an older surveil applied it: the whole match's time, the "
        "env's set-up included, charged to the side that had decided slower"
    )


_SECTIONS = [
    (
        "matrices",
        "Payoff matrices",
        "cells",
        "Held rate = share of matches in which the pursuer kept surveillance to the horizon "
        "(95% Wilson interval); mean time to escape over the escapes (Student t interval).",
    ),
    (
        "games",
        "Zero-sum games (Nash equilibria)",
        "games",
        "The pursuer maximises the held rate, the evader minimises it. Value = the held rate the "
        "equilibrium pursuer mixture guarantees against any evader of the roster; "
        "exploitability = how much a best-responding opponent gains against a pure policy.",
    ),
    (
        "ratings",
        "Ratings",
        "ratings",
        "Bradley-Terry strengths pooled over maps: P(hold) = sigmoid(pursuer - evader), "
        "MAP fit with a N(0, 3^2) prior, 95% posterior (Laplace) intervals.",
    ),
    (
        "paired",
        "Paired comparisons on shared starts",
        "paired",
        "Same-role policies on the same seeded starts against the same opponent: McNemar's "
        "exact test on the discordant pairs (a won where b lost, and conversely).",
    ),
]


def _markdown(a: Analysis, tables: dict, images: list, regret: str) -> str:
    name = a.run["name"]
    lines = [f"# Tournament report: {name}", "", *[f"- {h}" for h in _header(a)], ""]
    lines += [f"> {n}" for n in a.notes]
    for key, title, table, text in _SECTIONS:
        lines += [f"## {title}", "", text, ""]
        lines += [f"![{cap}]({f})" for sec, f, _, cap in images if sec == key]
        lines += ["", _md_table(tables[table]), ""]
    lines += ["## Regret on certified starts", "", regret, "", "## Replays", ""]
    reps = [(f, cap) for sec, f, _, cap in images if sec == "replays"]
    lines += [f"![{cap}]({f})\n\n{cap}\n" for f, cap in reps] or ["(none)"]
    lines += ["", "## Errors and forfeits", "", _md_table(tables["errors"]), ""]
    return "\n".join(lines)


def _uri(name: str, data: bytes) -> str:
    mime = "image/gif" if name.endswith(".gif") else "image/png"
    return f"data:{mime};base64,{base64.b64encode(data).decode()}"


def _html(a: Analysis, tables: dict, images: list, regret: str) -> str:
    esc = html.escape
    name = esc(a.run["name"])
    parts = [
        f"<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>"
        f"<title>Tournament report: {name}</title><style>{_CSS}</style></head><body>",
        f"<h1>Tournament report: {name}</h1><ul>",
    ]
    parts += [f"<li>{esc(h)}</li>" for h in _header(a)] + ["</ul>"]
    parts += [f"<p class='warn'>{esc(n)}</p>" for n in a.notes]
    for key, title, table, text in _SECTIONS:
        parts += [f"<h2 id='{key}'>{esc(title)}</h2><p>{esc(text)}</p>"]
        parts += [
            f"<img src='{_uri(f, d)}' alt='{esc(cap)}'>" for sec, f, d, cap in images if sec == key
        ]
        parts.append(_html_table(tables[table]))
    parts += [
        "<h2 id='regret'>Regret on certified starts</h2>",
        regret,
        "<h2 id='replays'>Replays</h2>",
    ]
    reps = [(f, d, cap) for sec, f, d, cap in images if sec == "replays"]
    parts += [
        f"<figure><img src='{_uri(f, d)}' alt='{esc(cap)}'><figcaption>{esc(cap)}"
        "</figcaption></figure>"
        for f, d, cap in reps
    ] or ["<p>(none)</p>"]
    parts += [
        "<h2 id='errors'>Errors and forfeits</h2>",
        _html_table(tables["errors"]),
        "</body></html>",
    ]
    return "\n".join(parts)
