"""Learned vs analytic policies, through the tournament runner, with issue 9's targets.

One tournament (``analysis.tournament``: a SQLite store that resumes, common random starts
per map, a process pool) plays every zoo model beside the analytic policies and baselines of
its role against the other role's roster, on the maps the models trained on (*seen*) and on
maps no model saw (*held out*: seeded random maps with seeds outside any training set, and
the built-ins left out of training). Then it prints, per map group and pairing, the held
rate with its Wilson 95 % interval, and each target of issue 9 as a ratio measured in
this run:

* learned pursuer vs ``evader/shooting``: held rate / the decomposition pursuer's, on
  corridor, open_room and l_hall (target >= 0.9); on held-out maps, minus greedy's (>= 0).
  A map specialist (a model trained on one map) is judged on its own map, and when every
  target map has one, the specialists as a team (each on its own map);
* learned evader vs ``pursuer/decomposition``: escape rate minus ``evader/shooting``'s on
  two_rooms and office (>= 0); on held-out maps minus ``evader/straight``'s (>= 0);
* the per-step decision time of each model against the analytic policy of its role.

The report (``report.html``: tables, heat maps, ratings, replays) is written beside the
store. With ``--cards`` each model's ``CARD.md`` is rewritten from the run: its
"Measured" section names the env version the matches played (``surveillance_v1``), the
commit they were played at and the command; a ``## Notes`` section written by hand at
the end of a card is kept.

Usage::

    python benchmarks/learned_vs_analytic.py [--seeds 20] [--models NAME ...]
        [--store out/bench/learned.sqlite] [--workers 2] [--maps MAP ...] [--cards]
"""

from __future__ import annotations

import argparse
import os
import shlex
from collections import defaultdict
from pathlib import Path

from bench_cli import integer, run

from analysis.tournament import run_tournament, spec_from_dict
from analysis.tournament.identity import ENV_ID
from analysis.tournament.report import analyse, write_report
from analysis.tournament.statistics import wilson_interval
from training import zoo

SEEN_PURSUER = ["corridor", "open_room", "l_hall"]
SEEN_EVADER = ["two_rooms", "office"]
HELD_OUT = ["pillars", "random:9001", "random:9002", "random:rectangles:9003"]
PURSUERS = ["pursuer/decomposition", "pursuer/greedy", "pursuer/tractrix"]
EVADERS = ["evader/shooting", "evader/straight", "evader/toward_away", "evader/random"]


def _rate(rows, pursuer, evader, maps):
    got = [r for r in rows if r["pursuer"] == pursuer and r["evader"] == evader
           and r["map"] in maps and r["winner"] is not None]  # fmt: skip
    held = sum(r["winner"] == "pursuer" for r in got)
    lo, hi = wilson_interval(held, len(got)) if got else (float("nan"), float("nan"))
    return (held / len(got) if got else float("nan")), lo, hi, len(got)


def _fmt(rate, lo, hi, n):
    return f"{rate:5.2f} [{lo:.2f}, {hi:.2f}] n={n}"


def measured_at(args) -> dict:
    """Where a run's figures come from: the env version its matches play, the commit and
    whether the code differs from it, and the command (without ``--store`` and
    ``--workers``, which do not change a figure)."""
    from training.train import _git

    sha = _git("rev-parse", "HEAD")
    status = _git("status", "--porcelain", "--", "envs", "strategies", "training", "analysis",
                  "benchmarks", ":(exclude)training/zoo/models")  # fmt: skip
    words = ["python", "benchmarks/learned_vs_analytic.py", "--seeds", str(args.seeds),
             "--max-cycles", str(args.max_cycles)]  # fmt: skip
    if args.models:
        words += ["--models", *args.models]
    if args.maps:
        words += ["--maps", *args.maps]
    return {"env": ENV_ID, "sha": sha or None, "dirty": None if status is None else bool(status),
            "command": shlex.join([*words, "--cards"])}  # fmt: skip


NOTES = "## Notes"
"""A card's hand-written last section, kept when the card is rewritten from a run."""


def with_notes(new: str, old: str | None) -> str:
    """Card text ``new`` followed by the ``## Notes`` section of the card it replaces."""
    if not old or f"\n{NOTES}\n" not in f"\n{old}":
        return new
    notes = old[f"\n{old}".index(f"\n{NOTES}\n") :]
    return new.rstrip("\n") + "\n\n" + notes.rstrip("\n") + "\n"


def card(name: str, role: str, rows, args, decide=None, measured=None) -> str:
    """The model card of zoo model ``name``: recipe, training curves, measured rates.

    ``decide``: per-step decision times by ``(role, label)`` from the same run, for the
    model's line beside the analytic policy of its role. ``measured``: :func:`measured_at`
    of the run (computed here when not given).
    """
    measured = measured or measured_at(args)
    trained_on = zoo.trained_env(name) or "an env version git cannot tell"
    prov = zoo.info(name)
    cfg = prov["config"]
    size = zoo.model_path(name).stat().st_size
    trained = zoo.training_maps(name)
    seen = [m for m in trained if any(r["map"] == m for r in rows)]
    params = f"{cfg['expert_params']} " if cfg.get("expert_params") else ""
    how = f"imitating `{prov['expert']}` {params}" if "expert" in prov else ""
    article = "An" if role == "evader" else "A"
    obs = prov["env_config"]
    rays = f" ({obs.get('n_rays')} rays)" if obs["observation"] != "state" else ""
    if cfg.get("features"):  # computed from the state by SB3Policy, as in training
        rays += (
            f" plus the analytic features {', '.join(f'`{f}`' for f in cfg['features'])} "
            "(a learned policy with analytic features: each step it reads the state and "
            "computes them from the map, see `strategies/policies/learner_inputs.py`)"
        )
    # a DAgger run records its network and size; an RL recipe names the net in its
    # policy_kwargs or keeps SB3's default (the card said "None (None parameters)")
    net = prov.get("net_arch") or (cfg.get("policy_kwargs") or {}).get("net_arch")
    network = f"{net}" if net else f"{str(prov.get('algo', 'SB3')).upper()}'s default MLP"
    if prov.get("parameters"):
        network += f" ({prov['parameters']} parameters)"
    amount = (f"labelled states: {prov['samples'][-1]}" if "samples" in prov
              else f"timesteps: {prov.get('timesteps', '-')}")  # fmt: skip
    lines = [
        f"# {name}",
        "",
        f"{article} {role} trained by {prov.get('method', 'rl')} {how}against {prov['opponent']}, "
        f"observing `{obs['observation']}`{rays}. Retrain it bit for bit "
        f"with `python -m training.zoo reproduce {name}`; its recipe is `config.toml` beside "
        "this card.",
        "",
        f"- training maps: {', '.join(trained)}",
        f"- network: {network}, model file {size / 1024:.0f} KiB",
        f"- {amount}; wall time "
        f"{prov.get('wall_seconds', prov.get('wall_time', float('nan'))):.0f} s on 2 cores",
        f"- trained on `{trained_on}`",
        f"- code: {prov.get('git_sha')} (dirty: {prov.get('git_dirty')}); "
        f"versions {prov.get('versions') or prov.get('packages')}",
        "",
    ]
    if "disagreement" in prov:
        alone = prov.get("validation") or []
        lines += ["## DAgger curve", "",
                  f"Measured in training, on `{trained_on}`. "
                  "won: episodes won by the rollout policy, the expert acting with "
                  "probability beta^i (so iteration 0 is the expert alone); alone: won by "
                  "the learner alone in the validation episodes (against "
                  f"`{cfg.get('validation_opponent') or 'the training pool'}`), which pick "
                  f"the shipped iteration ({prov.get('best_iteration', '-')}).", "",
                  "| iteration | samples | disagreement | fit error | won | alone |",
                  "|---|---|---|---|---|---|"]  # fmt: skip
        curves = zip(prov["samples"], prov["disagreement"], prov["fit_error"], prov["held"],
                     strict=False)  # fmt: skip
        for i, (n, d, f, h) in enumerate(curves):
            v = f"{alone[i]:.2f}" if i < len(alone) and alone[i] is not None else "-"
            lines.append(f"| {i} | {n} | {d:.3f} | {f:.3f} | {h:.2f} | {v} |")
        lines.append("")
    sha = (measured["sha"] or "an unknown commit")[:12]
    dirty = " (with uncommitted changes)" if measured["dirty"] else ""
    if trained_on == measured["env"]:
        versions = f"Trained and measured on `{measured['env']}`."
    else:
        versions = (f"Trained on `{trained_on}`, measured on `{measured['env']}` (what "
                    f"changed is in `envs/{measured['env']}.py`'s version history; the model "
                    "was not retrained for it).")  # fmt: skip
    lines += [
        f"## Measured on {measured['env']} ({args.seeds} seeded safe starts per map, "
        f"max_cycles {args.max_cycles})",
        "",
        f"Measured at {sha}{dirty} by `{measured['command']}`. {versions}",
        "",
        "Rates are the model's wins (a pursuer holds, an evader escapes) with Wilson 95 % "
        "intervals; the analytic policy of the model's role is measured in its place on the "
        "same starts.",
        "",
        "| maps | opponent | this model | analytic in its place |",
        "|---|---|---|---|",
    ]
    ref = "pursuer/decomposition" if role == "pursuer" else "evader/shooting"
    opponents = EVADERS if role == "pursuer" else PURSUERS
    played = {r["map"] for r in rows}
    held_out = [m for m in HELD_OUT if m in played]  # a --maps run names what it played
    for label, maps in (("seen: " + ", ".join(seen), seen),
                        ("held out: " + ", ".join(held_out), held_out)):  # fmt: skip
        if not any(r["map"] in maps for r in rows):
            continue
        for o in opponents:
            pair = (name, o) if role == "pursuer" else (o, name)
            pair_ref = (ref, o) if role == "pursuer" else (o, ref)
            r, lo, hi, n = _rate(rows, *pair, maps)
            q, qlo, qhi, qn = _rate(rows, *pair_ref, maps)
            if role == "evader":
                r, lo, hi = 1 - r, 1 - hi, 1 - lo
                q, qlo, qhi = 1 - q, 1 - qhi, 1 - qlo
            lines.append(f"| {label} | {o} | {_fmt(r, lo, hi, n)} | {_fmt(q, qlo, qhi, qn)} |")
    t_m, t_ref = (decide or {}).get((role, name)), (decide or {}).get((role, ref))
    if t_m and t_ref:
        a_ms, b_ms = 1e3 * sum(t_m) / len(t_m), 1e3 * sum(t_ref) / len(t_ref)
        lines += ["", "Decision time per step in the same run (mean over matches, wall "
                  f"clock): {a_ms:.3f} ms against `{ref}`'s {b_ms:.3f} ms "
                  f"({a_ms / b_ms:.2f}x)."]  # fmt: skip
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=integer(1), default=20, help="seeded safe starts per map")
    ap.add_argument("--models", nargs="*", default=None, help="zoo names (default: all)")
    ap.add_argument("--store", default="out/bench/learned.sqlite")
    ap.add_argument("--workers", type=integer(1), default=2)
    ap.add_argument("--max-cycles", type=integer(1), default=300)
    ap.add_argument("--maps", nargs="*", default=None,
                    help="play only these maps (default: the seen and held-out maps)")  # fmt: skip
    ap.add_argument("--cards", action="store_true",
                    help="write each model's CARD.md into the zoo from this run")  # fmt: skip
    args = ap.parse_args(argv)
    names = args.models or zoo.list_models()
    learned = {"pursuer": [], "evader": []}
    for name in names:
        learned[zoo.info(name)["role"]].append(name)
    print(f"load average: {os.getloadavg()}; models: {names}")
    spec = spec_from_dict(
        {
            "name": "learned_vs_analytic",
            "maps": args.maps or sorted(set(SEEN_PURSUER + SEEN_EVADER + HELD_OUT), key=str),
            "seeds": args.seeds,
            "start": "safe",
            "time_limit": 300,
            "pursuers": PURSUERS + [{"model": f"zoo:{n}", "label": n} for n in learned["pursuer"]],
            "evaders": EVADERS + [{"model": f"zoo:{n}", "label": n} for n in learned["evader"]],
            "env": {"max_cycles": args.max_cycles},
        }
    )
    summary = run_tournament(spec, args.store, workers=args.workers)
    if summary.interrupted:  # the store keeps the matches played: the same command resumes
        raise KeyboardInterrupt(summary.interrupted)
    print(f"{summary.played} played, {summary.reused} reused, {summary.seconds:.0f} s")
    a = analyse(args.store)
    rows = a.rows
    groups = {"seen (pursuer maps)": SEEN_PURSUER, "seen (evader maps)": SEEN_EVADER,
              "held out": HELD_OUT}  # fmt: skip
    print("\nheld rate of the pursuer [Wilson 95%], per map group")
    played = {r["map"] for r in rows}
    for gname, maps in groups.items():
        if not played & set(maps):
            continue
        print(f"\n== {gname}: {', '.join(m for m in maps if m in played)}")
        for p in PURSUERS + learned["pursuer"]:
            for e in EVADERS + learned["evader"]:
                if (
                    p in PURSUERS
                    and e in EVADERS
                    and not (p == "pursuer/decomposition" or e == "evader/shooting")
                ):
                    continue  # baseline vs baseline: in the report
                print(f"  {p:<44} {e:<40} {_fmt(*_rate(rows, p, e, maps))}")
    print("\ntargets (ratios measured in this run)")
    for m in learned["pursuer"]:
        # a map specialist is judged on the target maps it trained on
        own = [x for x in SEEN_PURSUER if x in zoo.training_maps(m)] or SEEN_PURSUER
        if not played & set(own):
            print(f"  {m}: its target maps ({', '.join(own)}) were not played in this run "
                  "(--maps): no verdict")  # fmt: skip
            continue
        r_l = _rate(rows, m, "evader/shooting", own)[0]
        r_d = _rate(rows, "pursuer/decomposition", "evader/shooting", own)[0]
        h_l = _rate(rows, m, "evader/shooting", HELD_OUT)[0]
        h_g = _rate(rows, "pursuer/greedy", "evader/shooting", HELD_OUT)[0]
        ratio = r_l / r_d if r_d else float("nan")
        held_out = (
            (f"; held out {h_l:.2f} vs greedy {h_g:.2f} ({'met' if h_l >= h_g else 'NOT met'})")
            if played & set(HELD_OUT)
            else ""
        )
        verdict = "met" if ratio >= 0.9 else "NOT met"
        print(f"  {m}: seen ({', '.join(own)}) held {r_l:.2f} / decomposition {r_d:.2f} = "
              f"{ratio:.2f} (target >= 0.9: {verdict}){held_out}")  # fmt: skip
    team = {x: [m for m in learned["pursuer"] if zoo.training_maps(m) == [x]] for x in SEEN_PURSUER}
    if all(team.values()) and set(SEEN_PURSUER) <= played:  # one specialist per target map
        got = [_rate(rows, team[x][0], "evader/shooting", [x]) for x in SEEN_PURSUER]
        held = sum(r * n for r, _, _, n in got)
        n = sum(n for *_, n in got)
        r_d = _rate(rows, "pursuer/decomposition", "evader/shooting", SEEN_PURSUER)[0]
        ratio = held / n / r_d if n and r_d else float("nan")
        print(f"  specialists ({', '.join(team[x][0] for x in SEEN_PURSUER)}), each on its own "
              f"map: held {held / n:.2f} / decomposition {r_d:.2f} = {ratio:.2f} (target >= 0.9: "
              f"{'met' if ratio >= 0.9 else 'NOT met'})")  # fmt: skip
    for m in learned["evader"]:
        # a map specialist is judged on the target maps it trained on, as for the pursuer
        own = [x for x in SEEN_EVADER if x in zoo.training_maps(m)] or SEEN_EVADER
        if not played & set(own):
            print(f"  {m}: its target maps ({', '.join(own)}) were not played in this run "
                  "(--maps): no verdict")  # fmt: skip
            continue
        e_l = 1 - _rate(rows, "pursuer/decomposition", m, own)[0]
        e_s = 1 - _rate(rows, "pursuer/decomposition", "evader/shooting", own)[0]
        h_l = 1 - _rate(rows, "pursuer/decomposition", m, HELD_OUT)[0]
        h_s = 1 - _rate(rows, "pursuer/decomposition", "evader/straight", HELD_OUT)[0]
        verdict = "met" if h_l >= h_s else "NOT met"
        held_out = (
            f"; held out {h_l:.2f} vs straight {h_s:.2f} ({verdict})"
            if played & set(HELD_OUT)
            else ""
        )
        print(f"  {m}: seen ({', '.join(own)}) escape {e_l:.2f} vs shooting {e_s:.2f} "
              f"({'met' if e_l >= e_s else 'NOT met'}){held_out}")  # fmt: skip
    decide = defaultdict(list)
    for r in rows:
        for role in ("pursuer", "evader"):
            t = r.get(f"decide_{role}")
            if t is not None:
                decide[(role, r[role])].append(t)
    print("\nper-step decision time (mean over matches, same run)")
    for role, ref in (("pursuer", "pursuer/decomposition"), ("evader", "evader/shooting")):
        t_ref = decide.get((role, ref))
        for m in learned[role]:
            t_m = decide.get((role, m))
            if t_ref and t_m:
                a_ms, b_ms = 1e3 * sum(t_m) / len(t_m), 1e3 * sum(t_ref) / len(t_ref)
                print(f"  {m:<44} {a_ms:7.3f} ms vs {ref} {b_ms:7.3f} ms "
                      f"({a_ms / b_ms:5.2f}x its time)")  # fmt: skip
    if args.cards:
        measured = measured_at(args)
        played = {r["map"] for r in rows}
        for role in ("pursuer", "evader"):
            for m in learned[role]:
                path = zoo.MODELS_DIR / m / "CARD.md"
                if not played & {*zoo.training_maps(m), *HELD_OUT}:
                    # its card's table has a row for its seen maps and for the held-out
                    # ones: a run of neither wrote a card without a single rate over it
                    print(
                        f"card: {path} left as it was: this run played none of the "
                        f"maps {m} trained on ({', '.join(zoo.training_maps(m))}) nor "
                        f"the held-out ones ({', '.join(HELD_OUT)})"
                    )
                    continue
                old = path.read_text() if path.is_file() else None
                path.write_text(with_notes(card(m, role, rows, args, decide, measured), old))
                print(f"card: {path}")
    out = write_report(args.store, Path(args.store).with_suffix("") / "report", replays=False)
    print(f"\nreport: {out.get('html', out)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(run(main))
