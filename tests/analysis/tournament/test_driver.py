"""Running tournaments: backends agree, failures forfeit, interruptions resume exactly."""

from __future__ import annotations

import os
import signal
import sqlite3
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from analysis.tournament import Store, run_tournament, spec_from_dict
from analysis.tournament.executors import ProcessExecutor
from strategies.runner import run_episode

from .conftest import comparable


def test_serial_and_process_backends_store_the_same_results(tmp_path, small_spec):
    spec = spec_from_dict(small_spec)
    a = run_tournament(spec, tmp_path / "a.sqlite", backend="serial", progress=False)
    b = run_tournament(spec, tmp_path / "b.sqlite", backend="process", workers=2, progress=False)
    assert a.played == b.played == 24 and a.complete and b.complete
    with Store(tmp_path / "a.sqlite") as x, Store(tmp_path / "b.sqlite") as y:
        assert comparable(x.rows(a.run_id)) == comparable(y.rows(b.run_id))


def test_a_ctrl_c_before_the_matches_play_marks_the_run_interrupted(
    tmp_path, small_spec, monkeypatch
):
    """A Ctrl-C while the executor started (Ray's start takes seconds; the run's own signal
    handler is set only when the matches play) left the run 'running' in the store.
    The KeyboardInterrupt is raised where the signal lands, in the executor's start."""
    from analysis.tournament import driver

    def interrupted_start(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(driver, "make_executor", interrupted_start)
    spec = spec_from_dict(small_spec)
    with pytest.raises(KeyboardInterrupt):
        run_tournament(spec, tmp_path / "s.sqlite", backend="process", progress=False)
    with Store(tmp_path / "s.sqlite") as db:
        assert [r["status"] for r in db.runs()] == ["interrupted"]
    monkeypatch.undo()
    s = run_tournament(spec, tmp_path / "s.sqlite", backend="serial", progress=False)
    assert s.played == s.planned == 24


@pytest.mark.parametrize(("backend", "workers"), [("process", 0), ("ray", 0), ("ray", -2)])
def test_a_worker_count_below_one_is_refused_before_the_store(
    tmp_path, small_spec, backend, workers
):
    # ray with 0 CPUs scheduled nothing and stored every batch as an overrun error; the
    # process backend refused it after marking the run 'running' in the store
    from envs.errors import InvalidConfigError

    store = tmp_path / "s.sqlite"
    spec = spec_from_dict(small_spec)
    with pytest.raises(InvalidConfigError, match=f"workers = {workers}: expected an integer >= 1"):
        run_tournament(spec, store, backend=backend, workers=workers, progress=False)
    assert not store.exists()


def test_more_than_one_worker_for_the_serial_backend_is_refused(tmp_path, small_spec, capsys):
    # `surveil tournament spec --backend serial --workers 4` played serially without a word
    from analysis.cli import main
    from envs.errors import InvalidConfigError

    store = tmp_path / "s.sqlite"
    spec = spec_from_dict(small_spec)
    with pytest.raises(InvalidConfigError, match="workers = 4: the serial backend plays one"):
        run_tournament(spec, store, backend="serial", workers=4, progress=False)
    assert not store.exists()
    toml = tmp_path / "mini.toml"
    toml.write_text(
        'maps = ["open_room"]\npursuers = ["pursuer/greedy"]\nevaders = ["evader/random"]\n'
    )
    argv = ["tournament", str(toml), "--store", str(store), "--backend", "serial", "--workers", "4"]
    assert main(argv) != 0
    assert "workers = 4: the serial backend" in capsys.readouterr().err
    assert not store.exists()


def test_sprt_stops_a_decided_run_and_a_rerun_keeps_the_decision(tmp_path):
    import analysis.tournament.statistics as st

    d = {
        "maps": ["open_room"],
        "pursuers": ["pursuer/greedy", "pursuer/random"],
        "evaders": ["evader/straight", "evader/random"],
        "seeds": 40,
        "start": "valid",
        "env": {"max_cycles": 60},
        "sprt": {"role": "pursuer", "candidate": "pursuer/greedy", "baseline": "pursuer/random"},
    }
    d["sprt"]["p1"] = 0.9  # decided after 5 discordant starts won by the candidate alone
    spec = spec_from_dict(d)
    s = run_tournament(spec, tmp_path / "s.sqlite", backend="serial", progress=False)
    assert s.decided == "a better" and s.complete and s.played < s.planned
    assert "'pursuer/greedy' is better than 'pursuer/random'" in s.describe()
    with Store(tmp_path / "s.sqlite") as db:
        rows = db.rows(s.run_id)
        assert db.run(s.run_id)["status"] == "decided"
    (pc,) = [c for c in st.paired_comparisons(rows) if c.role == "pursuer"]
    a_only, b_only = (pc.a_only, pc.b_only) if pc.a == "pursuer/greedy" else (pc.b_only, pc.a_only)
    assert st.sprt(a_only, b_only, p1=0.9) == "a better"
    # the run stopped at its first decision: without the last seed's pairs it was undecided
    last = max(r["seed"] for r in rows)
    earlier = [r for r in rows if r["seed"] < last]
    (pc,) = [c for c in st.paired_comparisons(earlier) if c.role == "pursuer"]
    a_only, b_only = (pc.a_only, pc.b_only) if pc.a == "pursuer/greedy" else (pc.b_only, pc.a_only)
    assert st.sprt(a_only, b_only, p1=0.9) == "undecided"
    from analysis.tournament.report import write_report

    files = write_report(tmp_path / "s.sqlite", tmp_path / "rep", run_id=s.run_id, replays=False)
    assert "'pursuer/greedy' is better than" in files["markdown"].read_text()
    again = run_tournament(spec, tmp_path / "s.sqlite", backend="serial", progress=False)
    assert again.played == 0 and again.reused == len(rows) and again.decided == "a better"
    # without [sprt] the same matches are reused and the rest is played
    del d["sprt"]
    full = run_tournament(
        spec_from_dict(d), tmp_path / "s.sqlite", backend="serial", progress=False
    )
    assert full.reused == len(rows) and full.reused + full.played == full.planned == 160


@pytest.mark.parametrize("backend", ["serial", "process"])
def test_raising_and_hanging_policies_forfeit_and_the_run_goes_on(tmp_path, test_policies, backend):
    d = {
        "maps": ["open_room"],
        "pursuers": ["pursuer/greedy"],
        "evaders": ["evader/test_raising", "evader/test_hanging", "evader/random"],
        "seeds": 2,
        "start": "valid",
        # 2 s (b128fd5) while the limit counted the env's build and the start's draw: 0.5 s
        # ran out before the hanging evader's step at load 6.5, blaming the pursuer
        "time_limit": 0.5,
        "env": {"max_cycles": 40},
    }
    t0 = time.monotonic()
    workers = None if backend == "serial" else 2  # the serial backend refuses more than one
    s = run_tournament(
        spec_from_dict(d), tmp_path / "s.sqlite", backend=backend, workers=workers, progress=False
    )
    assert time.monotonic() - t0 < 15
    assert s.played == 6 and s.forfeits == 4 and s.errors == 0
    with Store(tmp_path / "s.sqlite") as db:
        rows = {(r["evader"], r["seed"]): r for r in db.rows(s.run_id)}
        errors = db.errors(s.run_id)
    for seed in (0, 1):
        raised = rows[("evader/test_raising", seed)]
        assert raised["status"] == "forfeit" and raised["winner"] == "pursuer"
        assert raised["blame"] == "evader" and "ZeroDivisionError" in raised["error"]
        assert "step 3" in raised["error"]
        hung = rows[("evader/test_hanging", seed)]
        assert hung["status"] == "forfeit" and hung["blame"] == "evader"
        assert "time limit" in hung["error"]
        assert rows[("evader/random", seed)]["status"] == "ok"
    assert len(errors) == 4 and {e["kind"] for e in errors} == {"forfeit"}


def test_a_policy_returning_a_nan_action_forfeits(tmp_path, test_policies):
    # the env refused the action outside the policy's own call, so the match was stored as
    # an 'error' (nobody played: left out of every table) and the NaN policy lost nothing
    d = {
        "maps": ["open_room"],
        "pursuers": ["pursuer/greedy"],
        "evaders": ["evader/test_nan", "evader/random"],
        "seeds": 2,
        "start": "valid",
        "env": {"max_cycles": 40},
    }
    s = run_tournament(spec_from_dict(d), tmp_path / "s.sqlite", backend="serial", progress=False)
    assert s.played == 4 and s.forfeits == 2 and s.errors == 0
    with Store(tmp_path / "s.sqlite") as db:
        rows = {(r["evader"], r["seed"]): r for r in db.rows(s.run_id)}
    for seed in (0, 1):
        nan = rows[("evader/test_nan", seed)]
        assert nan["status"] == "forfeit" and nan["blame"] == "evader", nan["error"]
        assert nan["winner"] == "pursuer" and "step 3" in nan["error"]
        assert "InvalidActionError" in nan["error"] and "finite" in nan["error"]


def test_a_hang_that_ignores_signals_is_killed_and_blamed_on_who_was_deciding(
    tmp_path, test_policies
):
    # A hang in the evader's act with SIGALRM blocked was killed and stored as an error
    # (nobody won: left out of every table): the driver did not know who was deciding. A
    # hang while no policy decides (here a mixture's pick of its policy: the harness's
    # work, on no clock) stays an error.
    d = {
        "maps": ["open_room"],
        "pursuers": ["pursuer/greedy"],
        "evaders": ["evader/test_deaf", "evader/test_deaf_pick", "evader/random"],
        "seeds": 2,
        "start": "valid",
        "time_limit": 0.5,
        "env": {"max_cycles": 30},
    }
    ex = ProcessExecutor(2, kill_grace=1.0)
    s = run_tournament(spec_from_dict(d), tmp_path / "s.sqlite", executor=ex, progress=False)
    assert s.played == 6 and s.forfeits == 2 and s.errors == 2
    with Store(tmp_path / "s.sqlite") as db:
        rows = db.rows(s.run_id)
    deaf = [r for r in rows if r["evader"] == "evader/test_deaf"]
    assert all(r["status"] == "forfeit" and r["blame"] == "evader" for r in deaf), deaf
    assert all(r["winner"] == "pursuer" and "evader killed" in r["error"] for r in deaf)
    picked = [r for r in rows if r["evader"] == "evader/test_deaf_pick"]
    assert all(r["status"] == "error" and r["winner"] is None for r in picked), picked
    assert all("killed" in r["error"] and "no policy was deciding" in r["error"] for r in picked)
    assert all(r["status"] == "ok" for r in rows if r["evader"] == "evader/random")


def test_a_time_limit_longer_than_an_alarm_can_be_set_plays(tmp_path):
    # setitimer overflows near 1e12 s: a spec's time_limit = 1e12 (valid: finite, > 0)
    # stored every match as an error ('OverflowError: timestamp out of range ...')
    d = {
        "maps": ["open_room"],
        "pursuers": ["pursuer/greedy"],
        "evaders": ["evader/random"],
        "seeds": 1,
        "start": "valid",
        "time_limit": 1e12,
        "env": {"max_cycles": 5},
    }
    s = run_tournament(spec_from_dict(d), tmp_path / "s.sqlite", backend="serial", progress=False)
    with Store(tmp_path / "s.sqlite") as db:
        (row,) = db.rows(s.run_id)
    assert row["status"] == "ok", row["error"]


def _round_room(tmp_path: Path, walls: int = 1000) -> str:
    """A map file: a round room of ``walls`` walls (a lidar's work grows with them)."""
    import numpy as np

    from envs.maps import Map
    from envs.maps.io import save_map

    a = np.linspace(0, 2 * np.pi, walls, endpoint=False)
    path = tmp_path / "round.json"
    save_map(Map(np.c_[10 + 10 * np.cos(a), 10 + 10 * np.sin(a)], [], name="round"), path)
    return str(path)


def _play(tmp_path: Path, d: dict, backend: str):
    """The spec ``d`` played on ``backend`` (two workers for the process backend): the
    run's summary and its stored rows."""
    workers = None if backend == "serial" else 2
    s = run_tournament(
        spec_from_dict(d), tmp_path / "s.sqlite", backend=backend, workers=workers, progress=False
    )
    with Store(tmp_path / "s.sqlite") as db:
        return s, db.rows(s.run_id)


@pytest.mark.parametrize("backend", ["serial", "process"])
def test_the_envs_time_is_on_no_policys_clock(tmp_path, test_policies, backend):
    # The limit counted the whole match, and an overrun forfeited the side that had spent
    # more time deciding: here the env's work (a 4096-ray lidar on 1000 walls: 6.3 and
    # 5.7 s for two 60-step matches at load 13, 0.9-1.2 s at load 2, so 120 steps: 2.0 s
    # at load 2, the precondition below with a margin on an idle machine) ran out a limit
    # of 0.5 s that neither side came near (0.03 s of decisions at most in 60 steps at
    # load 13; with 300 walls and 150 steps the greedy pursuer's clock reached 0.31 s at
    # load 14).
    world = _round_room(tmp_path)
    # While no policy decides, each stretch of the env's work has the limit + 1 s (a hang
    # is an error, not this test's subject). The first stretch of a process also did the
    # map's one-time work: its geometry kernel and the start sampler's room (0.19 + 0.12 s
    # of the 0.47 s first stretch at load 11; the longest step: 0.19 s), and at load 8 it
    # once ran past 1.5 s ('MatchTimeout: the env or the harness gave no answer'). Done
    # here first (the process backend's workers fork after it), the first stretch took
    # 0.12 s at load 10 and the longest 0.14 s: 10x inside the 1.5 s.
    run_episode(world, "pursuer/greedy", "evader/random", 0, max_cycles=1, start="valid")
    d = {
        "maps": [world],
        "pursuers": ["pursuer/greedy"],
        "evaders": ["evader/test_lidar"],
        "seeds": [1, 2],
        "start": "valid",
        "time_limit": 0.5,
        "env": {"max_cycles": 120},
    }
    _, rows = _play(tmp_path, d, backend)
    assert len(rows) == 2 and all(r["status"] == "ok" for r in rows), [r["error"] for r in rows]
    # the env's time alone (the match's, less both roles' act calls) is past the limit
    env = [r["wall_seconds"] - r["steps"] * (r["decide_pursuer"] + r["decide_evader"])
           for r in rows]  # fmt: skip
    assert min(env) > 0.5, (env, rows)


@pytest.mark.parametrize("backend", ["serial", "process"])
def test_a_policy_past_its_own_clock_forfeits_though_the_other_decided_slower(
    tmp_path, test_policies, backend
):
    # A pursuer whose reset takes 1.5 s against a limit of 1 s: the overrun was blamed on
    # the evader, which spends 2 ms a step deciding (greedy: about 0.05 ms).
    d = {
        "maps": ["open_room"],
        "pursuers": ["pursuer/test_slow_reset", "pursuer/greedy"],
        "evaders": ["evader/test_slow_act"],
        "seeds": 1,
        "start": "valid",
        "time_limit": 1.0,
        "env": {"max_cycles": 10},
    }
    rows = {r["pursuer"]: r for r in _play(tmp_path, d, backend)[1]}
    slow = rows["pursuer/test_slow_reset"]
    assert slow["status"] == "forfeit" and slow["blame"] == "pursuer", slow["error"]
    assert slow["winner"] == "evader" and "failed at reset: its clock ran out" in slow["error"]
    # 10 decisions of 2 ms (0.41 s for 20 decisions of 5 ms at load 12: sleeps wait for a
    # CPU): the evader's clock is within the limit
    assert rows["pursuer/greedy"]["status"] == "ok", rows["pursuer/greedy"]["error"]


@pytest.mark.parametrize("backend", ["serial", "process"])
def test_a_policys_one_time_set_up_of_a_map_is_on_no_clock(
    tmp_path, test_policies, backend, monkeypatch
):
    # The shooting evader builds its escape plan of a map in its first reset there and
    # caches it (9 s of CPU, 72 s of wall time at load 14 on a 1000-wall room; later resets
    # 0.03 s of CPU): each worker's first match on that map paid it on its clock, and a
    # limit of 30 s forfeited it. This pursuer's first reset on a map takes 1.5 s.
    from analysis.tournament import worker

    monkeypatch.setattr(worker, "_SET_UP", set(), raising=False)  # a fresh process's
    monkeypatch.setattr(test_policies["pursuer/test_map_set_up"], "built", set())
    d = {
        "maps": ["open_room"],
        "pursuers": ["pursuer/test_map_set_up"],
        "evaders": ["evader/random"],
        "seeds": 2,
        "start": "valid",
        "time_limit": 1.0,
        "env": {"max_cycles": 10},
    }
    _, rows = _play(tmp_path, d, backend)
    assert [r["status"] for r in rows] == ["ok", "ok"], [r["error"] for r in rows]
    with Store(tmp_path / "s.sqlite") as db:  # the record says what each reset took
        resets = [db.record_of(r["match_id"])["reset_seconds"] for r in rows]
    assert all(set(t) == {"pursuer", "evader"} and t["pursuer"] < 1.0 for t in resets), resets


@pytest.mark.parametrize("backend", ["serial", "process"])
def test_a_hang_a_policy_reports_as_its_own_error_forfeits_on_its_clock(
    tmp_path, test_policies, backend
):
    # A learned model on the roster, time limit 1 s: the alarm interrupted its first reset
    # (importing torch, 2.5 s at load 8) and its loader reported the interruption as
    # 'InvalidConfigError: ...: cannot load the model file ... (MatchTimeout: no answer 1 s
    # after its clock ran out ...)': the match was stored as an error charged to nobody.
    d = {
        "maps": ["open_room"],
        "pursuers": ["pursuer/test_wrapping_hang", "pursuer/greedy"],
        "evaders": ["evader/random"],
        "seeds": 1,
        "start": "valid",
        "time_limit": 0.5,
        "env": {"max_cycles": 10},
    }
    s, stored = _play(tmp_path, d, backend)
    assert s.errors == 0 and s.forfeits == 1
    rows = {r["pursuer"]: r for r in stored}
    hung = rows["pursuer/test_wrapping_hang"]
    assert hung["status"] == "forfeit" and hung["blame"] == "pursuer", hung["error"]
    assert "failed at reset: its clock ran out" in hung["error"]
    assert "then raised InvalidConfigError: cannot load the model file" in hung["error"]
    assert rows["pursuer/greedy"]["status"] == "ok", rows["pursuer/greedy"]["error"]


def test_a_worker_loads_its_models_before_its_first_match():
    # A model was loaded in its first reset (stable-baselines3, torch, the file: 2-3 s at
    # load 8), on its clock; an alarm interrupting the load left torch half imported and
    # every later match of a model in that process failed to load it ("module 'sympy' has
    # no attribute 'core'"), stored as errors.
    script = textwrap.dedent(
        """
        import sys
        from analysis.tournament import worker
        from analysis.tournament.spec import spec_from_dict
        roster = {"maps": ["open_room"], "evaders": ["evader/random"], "seeds": 1}
        plain = spec_from_dict({**roster, "pursuers": ["pursuer/greedy"]})
        worker.warm_up(worker.context_for(plain))
        before = "stable_baselines3" in sys.modules
        model = {"model": "zoo:ppo_pursuer_vs_straight_open_room", "label": "ppo"}
        ctx = worker.context_for(spec_from_dict({**roster, "pursuers": [model]}))
        worker.warm_up(ctx)
        loaded = [p.model is not None for p in worker._LEARNED.values()]
        print(before, loaded, worker.build_policy(ctx, ctx.policies["pursuer:ppo"]).model
              is not None)
        """
    )
    root = Path(__file__).resolve().parents[3]  # "-c" imports this checkout from its cwd
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                         cwd=root, timeout=120)  # fmt: skip
    assert out.stdout.split() == ["False", "[True]", "True"], out.stderr


def test_a_worker_forked_from_a_driver_that_ran_torch_loads_its_model(tmp_path):
    # A suite hung for ever in a forked worker's warm_up: the driver (a pytest worker that
    # had run torch on its OpenMP threads) forked it, and loading the model (its weights'
    # orthogonal init, a parallel region) waited for the threads the fork left behind.
    script = textwrap.dedent(
        f"""
        import torch
        torch.set_num_threads(2)
        torch.linalg.qr(torch.randn(600, 600))  # the driver's thread team is up
        from analysis.tournament import Store, run_tournament, spec_from_dict
        d = {{"maps": ["open_room"], "evaders": ["evader/random"], "seeds": 1,
              "pursuers": [{{"model": "zoo:ppo_pursuer_vs_straight_open_room",
                             "label": "ppo"}}], "env": {{"max_cycles": 5}}}}
        s = run_tournament(spec_from_dict(d), {str(tmp_path / "s.sqlite")!r},
                           backend="process", workers=1, progress=False)
        with Store({str(tmp_path / "s.sqlite")!r}) as db:
            print([r["status"] for r in db.rows(s.run_id)])
        """
    )
    root = Path(__file__).resolve().parents[3]  # "-c" imports this checkout from its cwd
    try:
        out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                             cwd=root, timeout=120)  # fmt: skip
    except subprocess.TimeoutExpired as exc:
        pytest.fail(f"the forked worker hung loading its model: {exc}")
    assert out.stdout.split() == ["['ok']"], out.stderr


def test_a_model_is_named_in_its_matches_as_the_spec_names_it(tmp_path):
    # A forfeit of a model read "pursuer 'pursuer/sb3:/tmp/surveil-models-x9p3cwoz/50fd76c7
    # ...b5b.zip' failed at reset: ...": the worker's copy of the file, not the model. The
    # same file under another label in a later run of the same process (the serial
    # backend's is the caller's: a suite, a notebook) kept the first run's name.
    for label in ("ppo", "ppo_again"):
        d = {
            "maps": ["open_room"],
            "pursuers": [{"model": "zoo:ppo_pursuer_vs_straight_open_room", "label": label}],
            "evaders": ["evader/random"],
            "seeds": 1,
            "start": "valid",
            "time_limit": 1e-9,  # the clock runs out in the first reset
            "env": {"max_cycles": 5},
        }  # fmt: skip
        store = tmp_path / f"{label}.sqlite"
        s = run_tournament(spec_from_dict(d), store, backend="serial", progress=False)
        with Store(store) as db:
            (row,) = db.rows(s.run_id)
        assert row["status"] == "forfeit" and row["blame"] == "pursuer"
        assert row["error"].startswith(f"pursuer '{label}' failed at reset: its clock ran out")
        assert "out: 0.00 s" not in row["error"]  # against the time limit of 1e-09 s


_SCRIPT = textwrap.dedent(
    """
    import sys, time
    from strategies.policies import register_policy
    from strategies.policies.baselines import RandomPolicy

    class SlowPursuer(RandomPolicy):
        def _decide(self, snap):
            time.sleep(0.002)
            return super()._decide(snap)

    register_policy("pursuer/test_slow", SlowPursuer, "test only")
    from analysis.cli import main
    sys.exit(main(sys.argv[1:]))
    """
)

_SPEC = textwrap.dedent(
    """
    name = "killme"
    maps = ["open_room", "corridor"]
    pursuers = ["pursuer/test_slow", "pursuer/greedy"]
    evaders = ["evader/straight", "evader/random"]
    seeds = 5
    start = "valid"
    [env]
    max_cycles = 80
    """
)


def _children(pid: int) -> set[int]:
    out = set()
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                stat = (entry / "stat").read_text()
            except OSError:
                continue
            if int(stat.rsplit(")", 1)[1].split()[1]) == pid:
                out.add(int(entry.name))
    return out


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


def _start(tmp_path: Path, store: Path) -> subprocess.Popen:
    (tmp_path / "driver.py").write_text(_SCRIPT)
    (tmp_path / "killme.toml").write_text(_SPEC)
    env = {**os.environ, "SDL_VIDEODRIVER": "dummy", "MPLBACKEND": "Agg"}
    return subprocess.Popen(
        [
            sys.executable,
            str(tmp_path / "driver.py"),
            "tournament",
            str(tmp_path / "killme.toml"),
            "--store",
            str(store),
            "--workers",
            "2",
            "--no-progress",
            "--no-report",
        ],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


def _wait_for_results(store: Path, k: int, proc: subprocess.Popen, timeout: float = 60) -> set:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        assert proc.poll() is None, proc.communicate()
        if store.exists():
            try:
                con = sqlite3.connect(store)
                n = con.execute("SELECT COUNT(*) FROM results").fetchone()[0]
                con.close()
            except sqlite3.Error:
                n = 0
            if n >= k:
                return _children(proc.pid)
        time.sleep(0.05)
    raise AssertionError("the driver stored too few results in time")


@pytest.fixture
def slow_spec(tmp_path, test_policies):
    (tmp_path / "killme.toml").write_text(_SPEC)
    from analysis.tournament import load_spec

    return load_spec(tmp_path / "killme.toml")


def test_sigkill_mid_run_then_resume_loses_nothing(tmp_path, slow_spec):
    store = tmp_path / "k.sqlite"
    proc = _start(tmp_path, store)
    workers = _wait_for_results(store, 6, proc)
    assert len(workers) == 2
    proc.kill()
    proc.wait(timeout=10)
    deadline = time.monotonic() + 5
    while any(_alive(w) for w in workers) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert not any(_alive(w) for w in workers), "orphaned workers after SIGKILL"
    with Store(store) as db:
        stored = len(db.rows(slow_spec.run_id))
    assert 6 <= stored < 40
    resumed = run_tournament(slow_spec, store, backend="process", workers=2, progress=False)
    assert resumed.reused == stored and resumed.played == 40 - stored
    whole = run_tournament(slow_spec, tmp_path / "whole.sqlite", backend="serial", progress=False)
    with Store(store) as a, Store(tmp_path / "whole.sqlite") as b:
        got, want = a.rows(slow_spec.run_id), b.rows(whole.run_id)
        assert a.conn.execute("SELECT COUNT(*) FROM results").fetchone()[0] == 40  # no duplicate
    assert comparable(got) == comparable(want)


def test_sigterm_stops_quickly_says_how_to_resume_and_leaves_no_orphans(tmp_path, slow_spec):
    store = tmp_path / "t.sqlite"
    proc = _start(tmp_path, store)
    workers = _wait_for_results(store, 3, proc)
    t0 = time.monotonic()
    proc.send_signal(signal.SIGTERM)
    out, err = proc.communicate(timeout=10)
    # "quickly": well before the remaining matches could finish (a functional bound, not
    # a speed figure: it read 3.9 s at load average 9 on 2 cores; the run stops short below)
    assert time.monotonic() - t0 < 8.0
    assert proc.returncode == 143
    assert "Traceback" not in err
    assert "to resume: surveil tournament" in out + err and str(store) in out + err
    assert not any(_alive(w) for w in workers)
    with Store(store) as db:
        assert db.run(slow_spec.run_id)["status"] == "interrupted"
        assert len(db.rows(slow_spec.run_id)) < 40  # it did not play the run out


_WARM = textwrap.dedent(
    """
    import sys
    from analysis.tournament import Store, run_tournament, spec_from_dict
    from analysis.tournament.executors import ProcessExecutor
    from strategies.policies import register_policy
    from strategies.policies.baselines import RandomPolicy

    class CountsImports(RandomPolicy):  # built on the match's clock, before the episode
        def __init__(self, **kwargs):
            super().__init__(**kwargs)
            self._modules = set(sys.modules)

        def _decide(self, snap):
            new = sorted(set(sys.modules) - self._modules)
            if self._steps == 0 and new:
                raise ImportError(f"imported on the match's clock: {new[:5]}")
            return super()._decide(snap)

    register_policy("evader/test_counts_imports", CountsImports, "test only")
    d = {"name": "warm", "maps": ["open_room"], "pursuers": ["pursuer/greedy"],
         "evaders": ["evader/test_counts_imports"], "seeds": 1, "start": "valid",
         "time_limit": 30, "env": {"max_cycles": 10}}
    s = run_tournament(spec_from_dict(d), sys.argv[1], executor=ProcessExecutor(1),
                       progress=False)
    with Store(sys.argv[1]) as db:
        (row,) = db.rows(s.run_id)
    print(row["status"], row["error"])
    """
)


def test_a_process_worker_imports_what_a_match_needs_before_its_first_match(tmp_path):
    # A forked worker of a fresh driver (`surveil tournament` imports no env before it
    # forks) imported the env, PettingZoo, the start sampler and the observers inside its
    # first match, on that match's clock (1.2 s at load 6 on 2 cores, against time limits a
    # short tournament sets to 1 s): the Ray workers' fault of 8a29b16, in the process
    # backend. A fresh interpreter: this test process has imported all of it long ago.
    script = tmp_path / "warm.py"
    script.write_text(_WARM)
    out = subprocess.run(
        [sys.executable, str(script), str(tmp_path / "w.sqlite")],
        capture_output=True, text=True, timeout=120, cwd=Path(__file__).resolve().parents[3],
    )  # fmt: skip
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.split() == ["ok", "None"], out.stdout


def test_a_worker_builds_each_maps_set_up_before_its_first_match(tmp_path, monkeypatch):
    # A worker's first match on a map built the map's geometry kernel and the start
    # sampler's room check in the harness's first stretch, on the match's watch (0.4 s on a
    # 1000-wall room at load 10, against a stretch of time_limit + 1 s): a short limit
    # could store a MatchTimeout error for a match that never hung.
    import numpy as np

    from analysis.tournament import worker
    from analysis.tournament.identity import plan
    from envs.geometry import kernel as kernel_module
    from envs.maps import Map
    from envs.maps.io import save_map

    paths = []
    for n, r in ((61, 9.71), (67, 8.93)):  # walls no other test draws: nothing cached
        a = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
        paths.append(tmp_path / f"round{n}.json")
        save_map(Map(np.c_[r * np.cos(a), r * np.sin(a)], [], name=f"round{n}"), paths[-1])
    spec = spec_from_dict(
        {"maps": [str(p) for p in paths], "pursuers": ["pursuer/greedy"],
         "evaders": ["evader/random"], "seeds": [3], "start": "valid",
         "env": {"max_cycles": 5}}
    )  # fmt: skip
    ctx = worker.context_for(spec)
    built = []
    kernel_init, free_region = kernel_module.Kernel.__init__, Map.free_region

    def counted_kernel(self, world):
        built.append(("kernel", world.name))
        kernel_init(self, world)

    def counted_region(self):
        built.append(("free region", self.name))  # what check_room buffers, once per map
        return free_region.fget(self)

    monkeypatch.setattr(kernel_module.Kernel, "__init__", counted_kernel)
    monkeypatch.setattr(Map, "free_region", property(counted_region))
    worker.warm_up(ctx)
    assert {what for what, _ in built} == {"kernel", "free region"}
    assert {name for _, name in built} == {"round61", "round67"}
    built.clear()
    outcomes = [worker.play(match, ctx) for match, _ in plan(spec)]
    assert [o["status"] for o in outcomes] == ["ok", "ok"], outcomes
    assert built == []  # all of it was on no match's watch


def test_a_worker_builds_the_judge_of_its_safe_starts_before_its_first_match(tmp_path, monkeypatch):
    # The warm-up drew a valid start only: a worker's first "safe" start on a map built
    # the judge's safety table (a decomposition pursuer's) in the harness's first stretch,
    # on the match's watch: 1.0 s on office at load 7, then 0.012 s. A spec with
    # time_limit = 0.05 stored that match as "MatchTimeout: the env or the harness gave
    # no answer for 1.05 s ... while no policy was deciding"; rerun, it played.
    import numpy as np

    from analysis.tournament import worker
    from analysis.tournament.identity import plan
    from envs.maps import Map
    from envs.maps.io import save_map
    from strategies.policies.safety import safety_table

    monkeypatch.setenv("SURVEIL_CACHE_DIR", str(tmp_path / "cache"))  # nothing on disk
    a = np.linspace(0.0, 2.0 * np.pi, 23, endpoint=False)  # walls no other test draws
    path = tmp_path / "round23.json"
    save_map(Map(np.c_[7.17 * np.cos(a), 7.17 * np.sin(a)], [], name="round23"), path)
    spec = spec_from_dict(
        {"maps": [str(path)], "pursuers": ["pursuer/greedy"], "evaders": ["evader/random"],
         "seeds": [3, 4], "start": ["safe", "valid"], "env": {"max_cycles": 5}}
    )  # fmt: skip
    ctx = worker.context_for(spec)
    assert ctx.starts == ("safe", "valid")
    worker.warm_up(ctx)
    built = safety_table.cache_info().misses
    outcomes = [worker.play(match, ctx) for match, _ in plan(spec)]
    assert [o["status"] for o in outcomes] == ["ok"] * 4, outcomes
    assert safety_table.cache_info().misses == built  # the judge's table: on no watch


def test_progress_in_a_log_is_a_line_per_tenth_of_the_matches(tmp_path, small_spec, capsys):
    # stderr not a terminal (nohup, a job's log): tqdm's bar wrote a redraw of ~100 bytes
    # a match, joined by carriage returns into one line (a week's run: megabytes of it)
    spec = spec_from_dict(small_spec)
    s = run_tournament(spec, tmp_path / "s.sqlite", backend="serial", progress=True)
    assert s.played == 24
    err = capsys.readouterr().err
    assert "\r" not in err
    lines = [x for x in err.splitlines() if x.startswith("small: ")]
    assert len(lines) == 10 and lines[-1].startswith("small: 24 of 24 matches stored (24 played")
    assert lines[0].startswith("small: 3 of 24 matches stored")
    run_tournament(spec, tmp_path / "s.sqlite", backend="serial", progress=False)
    assert capsys.readouterr().err == ""  # --no-progress: nothing
