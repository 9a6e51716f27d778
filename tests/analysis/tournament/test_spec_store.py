"""Specs validated on load, match identity by content, the SQLite store and its lock."""

from __future__ import annotations

import contextlib
import csv
import hashlib
import json
import re
import shutil
import sqlite3
import warnings

import pytest

from analysis.tournament import Store, StoreBusyError, load_spec, run_tournament, spec_from_dict
from analysis.tournament.identity import plan
from envs.errors import InvalidConfigError, NarrowBandWarning
from strategies.policies.model_files import zoo_dir

from .conftest import comparable


@pytest.mark.parametrize(
    ("patch", "message"),
    [
        ({"pursuers": ["pursuer/nope"]}, r"\[pursuers #1\].*pursuer/nope"),
        ({"pursuers": ["evader/random"]}, r"\[pursuers #1\].*'pursuer/KIND'"),
        (
            {"evaders": [{"policy": "evader/toward_away", "params": {"mode": "sideways"}}]},
            r"\[evaders #1\]",
        ),
        ({"evaders": [{"policy": "evader/random", "colour": "red"}]}, r"unknown field.*colour"),
        ({"seeds": 0}, r"seeds = 0"),
        ({"seeds": [1, 1]}, r"repeated"),
        ({"seeds": True}, r"seeds = True"),
        ({"start": "anywhere"}, r"start = 'anywhere'"),
        ({"maps": ["atlantis"]}, r"\[maps #1\].*atlantis"),
        ({"env": {"l_min": -1}}, r"\[env\].*l_min = -1"),
        ({"env": {"max_cycles": 1.5}}, r"\[env\].*max_cycles"),
        ({"env": {"bogus": 1}}, r"\[env\].*bogus"),
        ({"grid": {"rho": [0.5, "fast"]}}, r"\[grid\].*rho = 'fast'"),
        ({"grid": {"rho": [0.5], "v_evader": [1.0]}}, r"rho.*v_evader"),
        ({"env": {"l_max": 1.0}}, r"l_max"),
        # a step across the map: every match was stored as an error, the run exited 0
        ({"env": {"dt": 1e9}}, r"\[env\] on map .*: dt = 1000000000.0 with .* i\.e\. dt <= "),
        ({"env": {"body_radius": 1e-12}}, r"\[env\] on map .*: body_radius = 1e-12 .* substeps"),
        ({"grid": {"dt": [0.1, 1e9]}}, r"\[grid\] dt=1e\+09 on map .*: dt = 1000000000.0 "),
        ({"time_limit": 0}, r"time_limit = 0"),
        # the default store out/tournaments/NAME.sqlite was ./escape.sqlite, outside out/
        ({"name": "../../escape"}, r"name = '\.\./\.\./escape': expected a plain name"),
        ({"name": "a\\b"}, r"expected a plain name"),
        ({"name": ".."}, r"expected a plain name"),
        # a label with a line break split the report's Markdown table rows (and the terminal's)
        (
            {"evaders": [{"policy": "evader/straight", "label": "two\nlines"}]},
            r"\[evaders #1\]: label = 'two\\nlines': expected one line of printable text",
        ),
        ({"pursuers": [{"policy": "pursuer/greedy", "label": "a\tb"}]}, r"label = 'a\\tb'"),
        ({"name": "run\n2"}, r"name = 'run\\n2': expected one line of printable text"),
        ({"env": {"dt": 1e-310}}, r"dt = 1e-310 with v_pursuer = .* would not move a body"),
        ({"colour": "red"}, r"unknown field.*colour"),
        ({"evaders": [{"model": "zoo:no_such_model"}]}, r"no zoo model 'no_such_model'"),
        ({"sprt": {"role": "pursuer", "candidate": "pursuer/greedy"}}, r"\[sprt\].*baseline"),
        (
            {"sprt": {"role": "pursuer", "candidate": "pursuer/greedy", "baseline": "x"}},
            r"\[sprt\]: baseline = 'x': expected a label of the pursuer roster",
        ),
        (
            {
                "sprt": {
                    "role": "pursuer",
                    "candidate": "pursuer/greedy",
                    "baseline": "pursuer/tractrix",
                    "p1": 0.5,
                }
            },
            r"\[sprt\]: p1 = 0.5: expected a number in \(0.5, 1\)",
        ),
        ({"sprt": {"role": "both", "candidate": "a", "baseline": "b"}}, r"\[sprt\].*role = 'both'"),
    ],
)
def test_bad_specs_name_the_field(small_spec, patch, message):
    with pytest.raises(InvalidConfigError, match=message):
        spec_from_dict({**small_spec, **patch}, source="SPEC.toml")


def test_a_narrow_band_is_warned_about_once_at_load_after_the_refusals(small_spec):
    """dt = 2.5 on the open room and the corridor (L in [2, 4], V_e 0.5): the band is
    narrower than two evader steps (2.5 m), once per (map, variant) and not per match; a
    spec refused for another value says its error alone."""
    with warnings.catch_warnings(record=True) as shown:
        warnings.simplefilter("always")
        spec_from_dict({**small_spec, "grid": {"dt": [0.1, 2.5]}}, source="SPEC.toml")
        with pytest.raises(InvalidConfigError, match=r"dt = 1000000000.0"):
            spec_from_dict({**small_spec, "grid": {"dt": [2.5, 1e9]}}, source="SPEC.toml")
    assert [(w.category, w.filename) for w in shown] == [(NarrowBandWarning, __file__)]
    assert str(shown[0].message).startswith(
        "SPEC.toml: l_max - l_min < 2 v_evader dt in ['open_room dt=2.5', 'corridor dt=2.5']: "
    )


def test_toml_spec_and_relative_map_files(tmp_path):
    world = {
        "name": "box",
        "boundary": [[0, 0], [12, 0], [12, 8], [0, 8]],
        "obstacles": [[[5, 3], [7, 3], [7, 5], [5, 5]]],
    }
    (tmp_path / "worlds").mkdir()
    (tmp_path / "worlds" / "box.json").write_text(json.dumps(world))
    (tmp_path / "t.toml").write_text(
        'maps = ["worlds/box.json", "open_room"]\npursuers = ["pursuer/greedy"]\n'
        'evaders = ["evader/random"]\nseeds = [4, 7]\n[grid]\nrho = [0.5, 0.8]\n'
    )
    spec = load_spec(tmp_path / "t.toml")
    assert spec.name == "t" and [m.label for m in spec.maps] == ["worlds/box.json", "open_room"]
    assert [v.label for v in spec.variants] == ["rho=0.5", "rho=0.8"]
    cfg = spec.env_config(spec.maps[1], spec.variants[1])
    assert cfg["v_evader"] == pytest.approx(0.8 * cfg["v_pursuer"])
    assert len(list(plan(spec))) == 2 * 2 * 2  # seeds x maps x variants
    (tmp_path / "bad.toml").write_text("maps = [")
    with pytest.raises(InvalidConfigError, match="not valid TOML"):
        load_spec(tmp_path / "bad.toml")


def test_a_spec_takes_transformed_maps_as_load_map_does(tmp_path):
    """``MAP~[xS][rotR][off(X,Y)]`` of a built-in, a random map or a file beside the spec:
    the same world as :func:`envs.maps.load_map` builds, a built-in's parameters scaled;
    a malformed transform names the map entry."""
    from envs.maps import load_map, save_map

    (tmp_path / "worlds").mkdir()
    save_map(load_map("pillars"), tmp_path / "worlds" / "p.json")
    names = ["corner~x10rot1.1", "random:rectangles:3~off(1.5,-2)", "worlds/p.json~rot0.5"]
    (tmp_path / "t.toml").write_text(
        f"maps = {json.dumps(names)}\npursuers = ['pursuer/greedy']\n"
        "evaders = ['evader/random']\nseeds = 1\n"
    )
    spec = load_spec(tmp_path / "t.toml")
    assert [m.label for m in spec.maps] == names
    for entry, name in zip(spec.maps, names, strict=True):
        path = tmp_path / name if name.startswith("worlds") else None
        want = load_map(str(path) if path else name)
        assert entry.map.digest == want.digest, name
    corner = spec.env_config(spec.maps[0], spec.variants[0])
    assert (corner["l_min"], corner["v_pursuer"]) == (20.0, 10.0)  # corner's 2 and 1, x10
    assert corner["body_radius"] == 1.0  # the bodies too: the corner's game, x10
    assert spec.env_config(spec.maps[1], spec.variants[0])["body_radius"] == 0.1
    with pytest.raises(InvalidConfigError, match=r"\[maps #1\].*scale 0\.0"):
        spec_from_dict({"maps": ["corner~x0"], "pursuers": ["pursuer/greedy"],
                        "evaders": ["evader/random"], "seeds": 1})  # fmt: skip


@pytest.mark.parametrize("name", ["corner~x1e-300", "random:3~rot1~x1e-300"])
def test_a_transform_that_leaves_no_valid_map_names_the_map_entry(name):
    """A well-formed transform whose result no map can be (scaled to nothing): one error
    naming the spec entry and the map, not a bare 'boundary: degenerate polygon'."""
    pattern = rf"\[maps #1\]: map = '{re.escape(name)}'.*size .* expected one in"
    with pytest.raises(InvalidConfigError, match=pattern):
        spec_from_dict({"maps": [name], "pursuers": ["pursuer/greedy"],
                        "evaders": ["evader/random"], "seeds": 1})  # fmt: skip


def test_duplicate_roster_entries_are_merged_or_rejected(small_spec):
    with pytest.warns(UserWarning, match="merged"):
        spec = spec_from_dict({**small_spec, "pursuers": ["pursuer/greedy", "pursuer/greedy"]})
    assert [p.label for p in spec.pursuers] == ["pursuer/greedy"]
    assert len(list(plan(spec))) == 2 * 1 * 2 * 3  # not counted twice
    with pytest.raises(InvalidConfigError, match="labelled 'g'"):
        spec_from_dict(
            {
                **small_spec,
                "pursuers": [
                    {"policy": "pursuer/greedy", "label": "g"},
                    {"policy": "pursuer/greedy", "params": {"gain": 2.0}, "label": "g"},
                ],
            }
        )
    with pytest.raises(InvalidConfigError, match="same world"):
        spec_from_dict({**small_spec, "maps": ["corridor", str(_builtin_file("corridor"))]})


def test_a_parameter_given_at_its_default_is_the_same_entry(small_spec):
    """``{"gain": 4}`` is pursuer/greedy's default: the same policy plays, so the same
    entry and the same matches (it was another identity: every match played twice)."""
    explicit = {"policy": "pursuer/greedy", "params": {"gain": 4, "target": 0.0}}
    with pytest.warns(UserWarning, match="merged"):
        spec = spec_from_dict({**small_spec, "pursuers": ["pursuer/greedy", explicit]})
    assert len(spec.pursuers) == 1 and spec.pursuers[0].params == {}
    alone = spec_from_dict({**small_spec, "pursuers": [explicit]})
    plain = spec_from_dict({**small_spec, "pursuers": ["pursuer/greedy"]})
    assert [m.match_id for m, _ in plan(alone)] == [m.match_id for m, _ in plan(plain)]
    other = {"policy": "pursuer/greedy", "params": {"gain": 4.5, "target": 0.0}}
    changed = spec_from_dict({**small_spec, "pursuers": [other]})
    assert changed.pursuers[0].params == {"gain": 4.5}
    assert not {m.match_id for m, _ in plan(changed)} & {m.match_id for m, _ in plan(plain)}


def _builtin_file(name):
    from importlib import resources

    return resources.files("envs.maps").joinpath("data", f"{name}.json")


def test_a_changed_map_file_makes_new_matches(tmp_path, small_spec):
    world = {
        "name": "box",
        "boundary": [[0, 0], [12, 0], [12, 8], [0, 8]],
        "obstacles": [[[5, 3], [7, 3], [7, 5], [5, 5]]],
    }
    path = tmp_path / "box.json"
    path.write_text(json.dumps(world))
    d = {**small_spec, "maps": ["box.json"], "seeds": 2}
    store = tmp_path / "s.sqlite"
    first = run_tournament(
        spec_from_dict(d, base_dir=tmp_path), store, backend="serial", progress=False
    )
    assert first.played == first.planned == 8
    again = run_tournament(
        spec_from_dict(d, base_dir=tmp_path), store, backend="serial", progress=False
    )
    assert again.played == 0 and again.reused == 8  # same content: nothing replayed
    world["obstacles"][0][0] = [4.5, 3]  # edit the file in place, same path and name
    path.write_text(json.dumps(world))
    edited = run_tournament(
        spec_from_dict(d, base_dir=tmp_path), store, backend="serial", progress=False
    )
    assert edited.run_id != first.run_id and edited.reused == 0 and edited.played == 8
    with Store(store) as db:
        assert len(db.runs()) == 2
        ids_first = {r["match_id"] for r in db.rows(first.run_id)}
        ids_edited = {r["match_id"] for r in db.rows(edited.run_id)}
    assert not ids_first & ids_edited  # never mixed in


def test_a_changed_model_file_makes_new_matches(tmp_path):
    src = zoo_dir() / "ppo_pursuer_vs_straight_open_room"
    shutil.copytree(src, tmp_path / "m")
    d = {
        "maps": ["open_room"],
        "pursuers": [{"model": "m/model.zip", "label": "ppo"}],
        "evaders": ["evader/straight"],
        "seeds": 2,
        "env": {"max_cycles": 30},
    }
    spec = spec_from_dict(d, base_dir=tmp_path)
    assert spec.pursuers[0].observation == {"observation": "state"}  # from provenance.json
    store = tmp_path / "s.sqlite"
    s1 = run_tournament(spec, store, backend="serial", progress=False)
    assert s1.played == 2 and s1.errors == 0 and s1.forfeits == 0
    with (tmp_path / "m" / "model.zip").open("ab") as f:
        f.write(b"retrained")  # same path, new content
    s2 = run_tournament(
        spec_from_dict(d, base_dir=tmp_path), store, backend="serial", progress=False
    )
    assert s2.run_id != s1.run_id and s2.reused == 0


def test_a_model_named_as_a_string_is_a_model_entry(tmp_path):
    # "pursuer/sb3:PATH" (the registry's name, README) was taken as a policy name: the
    # match identity held the path but not the file's content, so a retrained model's
    # old matches were reused without a word; "zoo:NAME" and "m.zip" were refused as
    # names (surveil evaluate takes all three); a model entry's 'params' were ignored
    shutil.copytree(zoo_dir() / "ppo_pursuer_vs_straight_open_room", tmp_path / "m")
    digest = hashlib.sha256((tmp_path / "m" / "model.zip").read_bytes()).hexdigest()
    base = {"maps": ["open_room"], "evaders": ["evader/straight"], "seeds": 1}

    def entry(item):
        return spec_from_dict({**base, "pursuers": [item]}, base_dir=tmp_path).pursuers[0]

    as_table = entry({"model": "m/model.zip"})
    for text in ("pursuer/sb3:m/model.zip", "m/model.zip"):
        got = entry(text)
        assert got.model_sha256 == digest and got.name == "pursuer/sb3"
        assert got.identity() == as_table.identity()
    assert entry("zoo:ppo_pursuer_vs_straight_open_room").model_sha256 == digest
    with pytest.raises(InvalidConfigError, match=r"#1\]: policy = 'pursuer/sb3:m/model.zip' "
                       r"names a model file: write model = 'm/model.zip'"):  # fmt: skip
        entry({"policy": "pursuer/sb3:m/model.zip", "label": "ppo"})
    with pytest.raises(InvalidConfigError, match=r"'params' applies to 'policy' entries"):
        entry({"model": "m/model.zip", "params": {"deterministic": False}})
    # was "was trained as a evader, not a pursuer"
    with pytest.raises(InvalidConfigError, match=r"model 'zoo:ppo_evader_vs_greedy_open_room' "
                       r"was trained as the evader, not the pursuer$"):  # fmt: skip
        entry("zoo:ppo_evader_vs_greedy_open_room")


def test_store_lock_refuses_a_second_writer(tmp_path, small_spec):
    store = tmp_path / "s.sqlite"
    holder = Store(store)
    holder.lock()
    try:
        with pytest.raises(StoreBusyError, match=r"being written by pid \d+"):
            run_tournament(spec_from_dict(small_spec), store, backend="serial", progress=False)
    finally:
        holder.close()
    done = run_tournament(spec_from_dict(small_spec), store, backend="serial", progress=False)
    assert done.played == 24  # the lock is free again


def test_store_lock_is_the_same_through_a_symlink(tmp_path, small_spec):
    # a symlink to the store took a lock file of its own (link.sqlite.lock): two drivers
    # wrote the one store at once
    store = tmp_path / "s.sqlite"
    Store(store).close()
    link = tmp_path / "link.sqlite"
    link.symlink_to(store.name)
    holder = Store(link)
    holder.lock()
    try:
        with pytest.raises(StoreBusyError, match=r"being written by pid \d+"):
            run_tournament(spec_from_dict(small_spec), store, backend="serial", progress=False)
    finally:
        holder.close()
    assert not (tmp_path / "link.sqlite.lock").exists()


def test_store_rejects_foreign_files_and_exports(tmp_path, small_spec):
    bogus = tmp_path / "notes.sqlite"
    bogus.write_text("hello, not a database" * 100)
    with pytest.raises(InvalidConfigError, match="not a tournament store"):
        Store(bogus)
    with pytest.raises(InvalidConfigError, match="no such file"):
        Store(tmp_path / "missing.sqlite", create=False)
    # a model file that is no model: refused on load (was: every match an error row)
    (tmp_path / "notes.zip").write_text("not a zip")
    bad = {**small_spec, "pursuers": [{"model": "notes.zip"}]}
    with pytest.raises(InvalidConfigError, match=r"\[pursuers #1\]: model = 'notes.zip': not a"):
        spec_from_dict(bad, base_dir=tmp_path)
    # another program's database, or an empty file: refused and left as it was (the
    # schema and WAL mode were written into them, and a reader said "no runs yet")
    other = tmp_path / "other.db"
    with contextlib.closing(sqlite3.connect(other)) as conn:
        conn.execute("CREATE TABLE notes (a)")
        conn.commit()
    empty = tmp_path / "empty.sqlite"
    empty.touch()
    cases = [
        (other, True, "other tables ['notes']"),
        (other, False, "other tables"),
        (empty, False, "an empty file"),
    ]
    for path, create, what in cases:
        before = path.read_bytes()
        with pytest.raises(
            InvalidConfigError, match=f"not a tournament store: it is .*{re.escape(what)}"
        ):
            Store(path, create=create)
        assert path.read_bytes() == before
    Store(empty).close()  # a writer may start a store in an empty file
    store = tmp_path / "s.sqlite"
    summary = run_tournament(spec_from_dict(small_spec), store, backend="serial", progress=False)
    with Store(store) as db:
        rows = db.rows(summary.run_id)
        db.export(summary.run_id, tmp_path / "r.csv")
        db.export(summary.run_id, tmp_path / "r.jsonl")
        with pytest.raises(InvalidConfigError, match=r"\.csv"):
            db.export(summary.run_id, tmp_path / "r.txt")
        assert db.run(summary.run_id[:6])["name"] == "small"
        with pytest.raises(InvalidConfigError, match="no run"):
            db.run("zzz")
    with (tmp_path / "r.csv").open() as f:
        flat = list(csv.DictReader(f))
    assert len(flat) == len(rows) == 24 and flat[0]["match_id"] == rows[0]["match_id"]
    lines = (tmp_path / "r.jsonl").read_text().splitlines()
    assert [json.loads(x)["match_id"] for x in lines] == [r["match_id"] for r in rows]
    # the journal mode is WAL and a match's result is one row keyed by its identity
    con = sqlite3.connect(store)
    assert con.execute("PRAGMA journal_mode").fetchone()[0] == "wal"
    assert con.execute("SELECT COUNT(*) FROM results").fetchone()[0] == 24
    con.close()


def test_a_different_spec_reuses_shared_matches(tmp_path, small_spec):
    store = tmp_path / "s.sqlite"
    a = run_tournament(spec_from_dict(small_spec), store, backend="serial", progress=False)
    wider = {**small_spec, "name": "wider", "seeds": 4}
    b = run_tournament(spec_from_dict(wider), store, backend="serial", progress=False)
    assert b.reused == 24 and b.played == 8 and a.run_id != b.run_id
    with Store(store) as db:
        narrow, wide = db.rows(a.run_id), db.rows(b.run_id)
    assert len(narrow) == 24 and len(wide) == 32  # each run sees only its own matches
    by_id = {r["match_id"]: r for r in comparable(wide)}
    for r in comparable(narrow):
        assert by_id[r["match_id"]] == r | {"seq": by_id[r["match_id"]]["seq"]}


def test_more_matches_than_the_memory_budget_can_plan_are_refused(small_spec, monkeypatch):
    """``surveil evaluate --seeds 1000000000`` built a tuple of a billion seeds (MemoryError,
    or the OOM killer) and ``--seeds 1000000`` grew past 1.5 GB planning: the plan's size
    (2.1 kB a match, measured) is checked against the memory budget from the counts alone,
    naming how many seeds fit."""
    from envs.errors import MemoryBudgetError

    monkeypatch.setenv("SURVEIL_MEMORY_BUDGET", "10MB")
    per_seed = len(list(plan(spec_from_dict({**small_spec, "seeds": 1}))))
    fit = int(10e6 // (2100 * per_seed))
    with pytest.raises(MemoryBudgetError, match=rf"SPEC.toml: seeds = 1,000,000 make "
                       rf"{1_000_000 * per_seed:,} matches .* expected seeds <= {fit:,}, "
                       r"or raise the budget with SURVEIL_MEMORY_BUDGET=20GB in"):  # fmt: skip
        spec_from_dict({**small_spec, "seeds": 10**6}, source="SPEC.toml")
    with pytest.raises(MemoryBudgetError):
        spec_from_dict({**small_spec, "seeds": list(range(fit + 1))})
    assert len(spec_from_dict({**small_spec, "seeds": fit}).seeds) == fit


def test_a_map_file_s_recommendations_apply_and_editing_them_is_a_new_run(tmp_path):
    """A map file's metadata (l_min, l_max, speeds, body radius) applies as a built-in's
    does, as EnvConfig(map=path) and surveil play read it. The map's digest is its geometry
    only, so the spec's hash (the run) names the file's recommendations: an edited
    recommendation is a new run whose matches are played, not rows added to the old
    run's (its report would count both)."""
    from envs.maps import load_map, save_map

    room = tmp_path / "room.json"
    save_map(load_map("open_room"), room, metadata={"l_min": 1.5, "l_max": 3.0})
    plain = tmp_path / "plain.json"
    save_map(load_map("corner"), plain, metadata={"author": "anyone"})
    d = {"maps": ["room.json", "plain.json", "room.json~x2", "corridor"], "seeds": 2,
         "pursuers": ["pursuer/greedy"], "evaders": ["evader/straight"],
         "env": {"max_cycles": 20}}  # fmt: skip
    spec = spec_from_dict(d, base_dir=tmp_path)
    v = spec.variants[0]
    got = [spec.env_config(m, v) for m in spec.maps]
    assert (got[0]["l_min"], got[0]["l_max"], got[0]["v_evader"]) == (1.5, 3.0, 0.5)
    assert (got[1]["l_min"], got[1]["l_max"]) == (2.0, 4.0)  # recommends nothing
    assert (got[2]["l_min"], got[2]["l_max"], got[2]["body_radius"]) == (3.0, 6.0, 0.2)
    maps = spec.to_dict()["maps"]  # a built-in's and a plain file's entry as before
    assert [("params" in m) for m in maps] == [True, False, True, False]
    store = tmp_path / "s.sqlite"
    first = run_tournament(spec, store, backend="serial", progress=False)
    assert (first.planned, first.played) == (8, 8)
    save_map(load_map("open_room"), room, metadata={"l_min": 1.0, "l_max": 3.0})
    edited = spec_from_dict(d, base_dir=tmp_path)
    assert edited.env_config(edited.maps[0], v)["l_min"] == 1.0
    again = run_tournament(edited, store, backend="serial", progress=False)
    assert again.run_id != first.run_id and (again.reused, again.played) == (4, 4)
    with Store(store) as db:
        assert len(db.rows(again.run_id)) == 8 and len(db.rows(first.run_id)) == 8
    with pytest.raises(InvalidConfigError, match=r"\[maps #1\]: map = 'room.json': .*l_min"):
        save_map(load_map("open_room"), room, metadata={"l_min": "1"})
        spec_from_dict(d, base_dir=tmp_path)


def test_another_time_limit_makes_new_matches(tmp_path, small_spec):
    # The limit was not part of a match's identity: a forfeit on time under a limit of
    # 1 s was reused by a spec whose limit is 300 s (and a match played out under 300 s
    # by a spec whose slow policy would forfeit under 1 s).
    d = {**small_spec, "maps": ["open_room"], "seeds": 1, "time_limit": 30}
    store = tmp_path / "s.sqlite"
    first = run_tournament(spec_from_dict(d), store, backend="serial", progress=False)
    assert first.played == 4
    longer = run_tournament(
        spec_from_dict({**d, "time_limit": 60}), store, backend="serial", progress=False
    )
    assert longer.reused == 0 and longer.played == 4
    with Store(store) as db:
        assert not {r["match_id"] for r in db.rows(first.run_id)} & {
            r["match_id"] for r in db.rows(longer.run_id)
        }
    (_, doc), *_ = plan(spec_from_dict(d))
    assert doc["time_limit"] == 30.0 and doc["version"] == 2


# The spec of data/store_identity_v1.sql: a store written by 94c5063 (match identity
# version 1: the limit counted the whole match), dumped with sqlite3's iterdump after
# run_tournament(spec_from_dict(_OLD_SPEC), "old.sqlite", backend="serial") run from a
# checkout of that commit.
_OLD_SPEC = {
    "name": "old_clock",
    "maps": ["open_room"],
    "pursuers": ["pursuer/greedy"],
    "evaders": ["evader/random"],
    "seeds": 2,
    "start": "valid",
    "time_limit": 30,
    "env": {"max_cycles": 10},
}
_OLD_RUN = "e9ddc92e6e602cb3"


def test_a_run_an_older_surveil_stored_is_played_again_and_said_so(tmp_path):
    # A store from before the per-role clocks: the same spec reused both of its matches
    # (stored under the old meaning of the time limit) without a word.
    from importlib import resources

    from analysis.tournament.report import write_report

    store = tmp_path / "old.sqlite"
    dump = resources.files("tests.analysis.tournament").joinpath("data", "store_identity_v1.sql")
    with contextlib.closing(sqlite3.connect(store)) as c:
        c.executescript(dump.read_text())
    s = run_tournament(spec_from_dict(_OLD_SPEC), store, backend="serial", progress=False)
    assert s.run_id != _OLD_RUN and s.reused == 0 and s.played == 2
    said = s.describe()
    assert f"run {_OLD_RUN} in {store} is this spec played by an older surveil" in said
    assert "none of its 2 stored matches is reused" in said and f"--run {_OLD_RUN}" in said
    with Store(store) as db:
        assert len(db.rows(s.run_id)) == 2 and len(db.rows(_OLD_RUN)) == 2  # never mixed
    old = write_report(store, tmp_path / "old", run_id=_OLD_RUN, replays=False, regret=False)
    new = write_report(store, tmp_path / "new", run_id=s.run_id, replays=False, regret=False)
    assert "30 s per match, as an older surveil applied it" in old["markdown"].read_text()
    assert "30 s of decision time per role per match" in new["markdown"].read_text()
    # a resume of the new run says it no more (it was repeated on every resume)
    again = run_tournament(spec_from_dict(_OLD_SPEC), store, backend="serial", progress=False)
    assert again.run_id == s.run_id and (again.reused, again.played) == (2, 0)
    assert "older surveil" not in again.describe()


def test_a_run_whose_matches_an_older_surveil_identified_otherwise_counts_each_once(tmp_path):
    """data/store_identity_v1_same_run.sql: 00d1beb (49a40b0~1: the spec already had its
    time_limit_rule, the match identity was still version 1) played _OLD_SPEC, dumped as
    store_identity_v1.sql was. Its run id is today's, but its matches' ids are not: the
    rerun added today's 2 matches to the run's 2 old ones, and the report counted 4
    matches of 2 starts (every cell's n doubled)."""
    from importlib import resources

    from analysis.tournament.report import write_report

    store = tmp_path / "old.sqlite"
    dump = resources.files("tests.analysis.tournament").joinpath(
        "data", "store_identity_v1_same_run.sql"
    )
    with contextlib.closing(sqlite3.connect(store)) as c:
        c.executescript(dump.read_text())
    with Store(store) as db:
        (old,) = db.runs()
    s = run_tournament(spec_from_dict(_OLD_SPEC), store, backend="serial", progress=False)
    assert s.run_id == old["run_id"] == "6933253d456d535e"  # the same run
    assert (s.planned, s.reused, s.played) == (2, 0, 2)
    with Store(store) as db:
        assert len(db.rows(s.run_id)) == 2  # was 4: seeds 0 and 1, each twice
        (aside,) = {r["run_id"] for r in db.runs()} - {s.run_id}
    said = s.describe()
    assert f"run {s.run_id} in {store} held 2 matches an older surveil identified" in said
    assert f"--run {aside}" in said
    with Store(store) as db:
        rows, kept = db.rows(s.run_id), db.rows(aside)
        assert len(kept) == 2  # the old run's matches, as they were
        assert {r["seed"] for r in rows} == {r["seed"] for r in kept} == {0, 1}
        assert {r["run_id"]: r["status"] for r in db.runs()}[aside] == "finished"
    md = write_report(store, tmp_path / "r", run_id=s.run_id, replays=False, regret=False)
    assert "2 of 2 matches stored" in md["markdown"].read_text()
    # a resume neither plays nor sets aside anything more
    again = run_tournament(spec_from_dict(_OLD_SPEC), store, backend="serial", progress=False)
    assert (again.reused, again.played) == (2, 0) and "older surveil" not in again.describe()
    with Store(store) as db:
        assert len(db.runs()) == 2


def test_a_run_already_counted_twice_is_said_so_by_report_and_export(tmp_path, monkeypatch, capsys):
    """The store data/store_identity_v1_same_run.sql left after a surveil without
    set_aside (00d1beb .. db301a8) resumed it: today's 2 matches beside the old 2. Until
    the spec's next tournament repairs it, its report and export counted every start
    twice without a word; both now say so and name the repair."""
    from importlib import resources

    from analysis.cli import main
    from analysis.tournament.report import analyse

    store = tmp_path / "old.sqlite"
    dump = resources.files("tests.analysis.tournament").joinpath(
        "data", "store_identity_v1_same_run.sql"
    )
    with contextlib.closing(sqlite3.connect(store)) as c:
        c.executescript(dump.read_text())
    with monkeypatch.context() as m:  # the older driver: no set_aside
        m.setattr(Store, "set_aside", lambda self, run_id, planned: None)
        s = run_tournament(spec_from_dict(_OLD_SPEC), store, backend="serial", progress=False)
    with Store(store) as db:
        assert len(db.rows(s.run_id)) == 4 and db.doubled(s.run_id) == 2
    (note,) = analyse(store, s.run_id).notes
    assert f"run {s.run_id} holds 2 start(s) twice" in note and "surveil tournament" in note
    assert main(["export", str(store), str(tmp_path / "rows.csv")]) == 0
    assert "holds 2 start(s) twice" in capsys.readouterr().err
    # the spec's next tournament repairs it, and nothing says it any more
    run_tournament(spec_from_dict(_OLD_SPEC), store, backend="serial", progress=False)
    with Store(store) as db:
        assert db.doubled(s.run_id) == 0
    assert analyse(store, s.run_id).notes == []
    assert main(["export", str(store), str(tmp_path / "rows.csv")]) == 0
    assert "twice" not in capsys.readouterr().err


def test_an_older_run_from_another_checkout_is_said_so(tmp_path):
    """data/store_identity_v1_zoo.sql: 94c5063 played _OLD_SPEC's open_room with the zoo
    evader from a checkout in /tmp/h132-old (dumped as store_identity_v1.sql was): its
    spec names the model under that root, so the same spec from this checkout (the same
    model's bytes under another path) was not recognised and the message was missing."""
    from importlib import resources

    store = tmp_path / "old.sqlite"
    data = resources.files("tests.analysis.tournament").joinpath("data")
    dump = data.joinpath("store_identity_v1_zoo.sql").read_text()
    assert "/tmp/h132-old/training/zoo/models/" in dump  # another checkout's path
    with contextlib.closing(sqlite3.connect(store)) as c:
        c.executescript(dump)
    zoo = {**_OLD_SPEC, "name": "old_clock_zoo", "evaders": ["zoo:ppo_evader_vs_greedy_open_room"]}
    s = run_tournament(spec_from_dict(zoo), store, backend="serial", progress=False)
    assert (s.reused, s.played) == (0, 2)
    assert "run 40ffb68c9c0885cf in " in s.describe() and "older surveil" in s.describe()


def test_a_model_without_its_provenance_is_said_so(tmp_path):
    """A model zip copied without its provenance.json played without a word, though
    nothing checked its role or observation: a pursuer model entered as an evader played
    garbage, and a lidar model given the state forfeited every match."""
    from strategies.policies.model_files import NoProvenanceWarning

    (tmp_path / "bare").mkdir()
    shutil.copy(zoo_dir() / "dagger_pursuer_corridor" / "model.zip", tmp_path / "bare" / "p.zip")
    d = {"maps": ["corridor"], "pursuers": ["pursuer/greedy"], "seeds": 1}
    with pytest.warns(NoProvenanceWarning, match=r"\[evaders #1\]: model = 'bare/p.zip': no "
                      r"provenance.json beside .*role and the observation"):  # fmt: skip
        spec_from_dict({**d, "evaders": [{"model": "bare/p.zip"}]}, base_dir=tmp_path)
    shutil.copytree(zoo_dir() / "dagger_pursuer_corridor", tmp_path / "whole")
    with warnings.catch_warnings():
        warnings.simplefilter("error", NoProvenanceWarning)  # with it: not a word
        spec_from_dict({**d, "pursuers": [{"model": "whole/model.zip"}], "evaders":
                        ["evader/straight"]}, base_dir=tmp_path)  # fmt: skip


def test_a_model_given_another_observation_is_refused_as_the_spec_is_read(tmp_path):
    """A lidar model zip without its provenance.json was given the env's state and failed
    its first act() in every match: the spec loaded and every match was a forfeit. The
    zip's ``data`` records the input shape: the spec is refused, naming both shapes."""
    from strategies.policies.model_files import NoProvenanceWarning

    (tmp_path / "bare").mkdir()
    for name, short in (("dagger_pursuer_generalist", "g"), ("dagger_pursuer_corridor", "c")):
        shutil.copy(zoo_dir() / name / "model.zip", tmp_path / "bare" / f"{short}.zip")
    d = {"maps": ["corridor"], "evaders": ["evader/straight"], "seeds": 1}
    lidar = {"model": "bare/g.zip", "label": "g"}  # lidar_track, 32 rays: 40 inputs
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", NoProvenanceWarning)
        refused = (r"^<spec> \[pursuers\]: 'g': model .*g\.zip takes observations of shape "
                   r"\(40,\), but the spec's env observation 'state' has shape \(13,\): every "
                   "match would be a forfeit")  # fmt: skip
        with pytest.raises(InvalidConfigError, match=refused):
            spec_from_dict({**d, "pursuers": [lidar]}, base_dir=tmp_path)
        with pytest.raises(InvalidConfigError, match=r"\(40,\), but its entry's observation "
                           r"'lidar_track' with n_rays = 16 has shape \(24,\)"):  # fmt: skip
            spec_from_dict({**d, "pursuers": [{**lidar, "observation": {
                "observation": "lidar_track", "n_rays": 16}}]}, base_dir=tmp_path)  # fmt: skip
        with pytest.raises(InvalidConfigError, match=r"'bare/c.zip': model .*c\.zip takes "
                           r"observations of shape \(13,\), but the spec's env observation "
                           r"'lidar' with n_rays = 32 has shape \(38,\)"):  # fmt: skip
            spec_from_dict({**d, "pursuers": ["bare/c.zip"], "env": {"observation": "lidar"}},
                           base_dir=tmp_path)  # fmt: skip
        given = {"observation": "lidar_track", "n_rays": 32}  # what it was trained on: plays
        spec = spec_from_dict({**d, "pursuers": [{**lidar, "observation": given}]},
                              base_dir=tmp_path)  # fmt: skip
    assert spec.pursuers[0].observation == given
    whole = {"model": "zoo:dagger_pursuer_generalist"}  # its provenance gives the observation
    assert spec_from_dict({**d, "pursuers": [whole]}).pursuers[0].observation["n_rays"] == 32


_CORRIDOR_MODEL = "zoo:dagger_pursuer_corridor"  # a PPO zip


@pytest.mark.parametrize(
    ("change", "match"),
    [
        # stored as SQLite's 64-bit integer: an OverflowError traceback once the store was open
        (
            {"seeds": [2**64]},
            r"seeds\[0\] = 18446744073709551616: expected an integer in "
            r"\[0, 9223372036854775807\]",
        ),
        # each match an error: "policy 'pursuer/random' reads the 'state' observation, ..."
        (
            {"pursuers": [{"policy": "pursuer/random", "observation": {"observation": "lidar"}}]},
            r"\[pursuers #1\]: policy 'pursuer/random' reads the state, so it cannot be given "
            r"observation = \{'observation': 'lidar'\}",
        ),
        # each match an error: "algo must be one of (...), got 'DQN'"
        (
            {"pursuers": [{"model": _CORRIDOR_MODEL, "algo": "dqn"}]},
            r"\[pursuers #1\]: model = 'zoo:dagger_pursuer_corridor': algo = 'dqn': expected "
            r"one of \['A2C', 'DDPG', 'PPO', 'SAC', 'TD3'\]",
        ),
        # the grid's rho set v_evader in every match, the [env] value dropped unsaid
        (
            {"env": {"v_evader": 0.3}, "grid": {"rho": [0.5, 0.7]}},
            r"<spec> \[env\]: v_evader = 0.3 and <spec> \[grid\] rho both set the evader's "
            r"speed \(rho sets v_evader = rho \* v_pursuer\); give one",
        ),
        # each match an error: "cannot load the model file ... 'ActorCriticPolicy' object
        # has no attribute 'actor'"
        (
            {"pursuers": [{"model": _CORRIDOR_MODEL, "algo": "SAC"}]},
            r"algo = 'SAC': .*model.zip was saved by PPO, which SAC cannot load; give "
            r"algo = 'PPO', or no algo",
        ),
    ],
)
def test_a_spec_refuses_on_load_what_made_every_match_of_an_entry_an_error(change, match):
    d = {"maps": ["corridor"], "pursuers": ["pursuer/greedy"], "evaders": ["evader/straight"]}
    with pytest.raises(InvalidConfigError, match=match):
        spec_from_dict({**d, "seeds": 1, **change})


def test_what_a_spec_still_takes_beside_those_refusals():
    d = {"maps": ["corridor"], "evaders": ["evader/straight"], "seeds": [0, 2**63 - 1]}
    spec = spec_from_dict(
        {
            **d,
            "pursuers": [
                {"policy": "pursuer/random", "observation": {"observation": "state"}},
                {"model": _CORRIDOR_MODEL, "algo": "a2c", "label": "a2c"},  # loads PPO's
                {"model": _CORRIDOR_MODEL, "algo": "ppo"},
            ],
        }
    )
    assert spec.seeds == (0, 2**63 - 1)
    faster = spec_from_dict({**d, "pursuers": ["pursuer/greedy"], "env": {"v_pursuer": 2.0},
                             "grid": {"rho": [0.25]}})  # fmt: skip
    assert faster.env_config(faster.maps[0], faster.variants[0])["v_evader"] == 0.5
    assert [p.params.get("algo") for p in spec.pursuers] == [None, "A2C", "PPO"]
