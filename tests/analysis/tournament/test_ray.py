"""The Ray backend on a real local 2-CPU Ray instance (one test: Ray takes seconds to start)."""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from analysis.tournament import Store, run_tournament, spec_from_dict

from .conftest import comparable

ray = pytest.importorskip(
    "ray", reason="the ray extra is not installed (pip install 'surveil[ray]')"
)


def test_ray_backend_matches_the_serial_backend_and_ships_models(tmp_path, small_spec):
    from analysis.tournament.executors import RayExecutor
    from strategies.policies.model_files import zoo_dir

    model = zoo_dir() / "ppo_evader_vs_greedy_open_room" / "model.zip"
    d = {
        **small_spec,
        "maps": ["open_room"],
        "seeds": 2,
        "evaders": ["evader/straight", {"model": str(model), "label": "ppo"}],
    }
    spec = spec_from_dict(d)
    serial = run_tournament(spec, tmp_path / "serial.sqlite", backend="serial", progress=False)
    ex = RayExecutor(num_cpus=2)  # ray.init(num_cpus=2): a real local instance
    try:
        assert ray.is_initialized() and ray.cluster_resources()["CPU"] == 2
        assert ex.describe() == "ray (2 CPUs)"
        remote = run_tournament(spec, tmp_path / "ray.sqlite", executor=ex, progress=False)
    finally:
        ex.close()
    assert not ray.is_initialized()  # the instance it started is shut down
    assert remote.played == serial.played == 8 and remote.errors == 0
    with Store(tmp_path / "serial.sqlite") as a, Store(tmp_path / "ray.sqlite") as b:
        assert comparable(a.rows(serial.run_id)) == comparable(b.rows(remote.run_id))


def test_a_local_instance_of_no_cpus_is_refused_before_ray_starts():
    # ray.init(num_cpus=0) ran no task; every batch was stored as an overrun error
    from analysis.tournament.executors import RayExecutor
    from envs.errors import InvalidConfigError

    with pytest.raises(InvalidConfigError, match=r"workers = 0: expected an integer >= 1"):
        RayExecutor(num_cpus=0)
    assert not ray.is_initialized()


def test_a_policy_registered_by_the_driver_plays_in_ray_workers(tmp_path, monkeypatch):
    # Ray workers are fresh processes: a policy registered at run time (as the process
    # backend's forked workers see it) was an "unknown policy" error in every match
    from analysis.tournament.executors import RayExecutor
    from strategies.policies import registry
    from strategies.policies.baselines import RandomPolicy

    class Boom(RandomPolicy):  # defined here: Ray's cloudpickle ships it by value
        def _decide(self, snap):
            if self._steps == 3:
                raise ZeroDivisionError("boom at step 3")
            return super()._decide(snap)

    registry.policy_names()
    monkeypatch.setitem(
        registry._REGISTRY, "evader/boom", registry.PolicySpec("evader/boom", Boom, "raises")
    )
    d = {
        "name": "boom",
        "maps": ["open_room"],
        "pursuers": ["pursuer/greedy"],
        "evaders": ["evader/boom", "evader/random"],
        "seeds": 2,
        "start": "valid",
        "env": {"max_cycles": 60},
    }
    ex = RayExecutor(num_cpus=2)
    try:
        s = run_tournament(spec_from_dict(d), tmp_path / "r.sqlite", executor=ex, progress=False)
    finally:
        ex.close()
    assert s.played == 4 and s.forfeits == 2 and s.errors == 0
    with Store(tmp_path / "r.sqlite") as db:
        rows = db.rows(s.run_id)
    boom = [r for r in rows if r["evader"] == "evader/boom"]
    assert all(r["status"] == "forfeit" and r["blame"] == "evader" for r in boom)
    assert all("ZeroDivisionError: boom at step 3" in r["error"] for r in boom)


def test_a_match_queued_behind_a_hang_is_not_killed_as_an_overrun(
    tmp_path, test_policies, monkeypatch
):
    # The driver timed each Ray task from its submission: a task queued behind one whose
    # match hung until the alarm (time limit + 1 s) had KILL_GRACE = 5 s left for its own
    # match, and a 5.5 s match (time limit 6 s) was stored as an error, "killed: the Ray
    # task overran the time limit", though it never overran. The slow match keeps 3 s of its
    # limit for its own work (0.5 s was too little at load 14 on 2 cores: a forfeit), and
    # a deadline from submission (time limit + 6 s) still falls before the hang's time
    # limit + 1 s and the slow decision end.
    import threading

    from analysis.tournament.executors import RayExecutor
    from analysis.tournament.identity import plan
    from analysis.tournament.worker import context_for
    from strategies.policies import registry
    from strategies.policies.baselines import RandomPolicy

    class Slow(RandomPolicy):  # one 6 s decision: slow, within the time limit of 9 s
        def _decide(self, snap):
            if self._steps == 1:
                time.sleep(6.0)
            return super()._decide(snap)

    monkeypatch.setitem(
        registry._REGISTRY, "evader/slow", registry.PolicySpec("evader/slow", Slow, "slow")
    )
    d = {
        "maps": ["open_room"],
        "pursuers": ["pursuer/greedy"],
        "evaders": ["evader/test_hanging", "evader/slow"],
        "seeds": 1,
        "start": "valid",
        "time_limit": 9,
        "env": {"max_cycles": 20},
    }
    spec = spec_from_dict(d)
    matches = sorted((m for m, _ in plan(spec)), key=lambda m: m.evader != "evader/test_hanging")
    ex = RayExecutor(num_cpus=1)  # the second task waits in Ray's queue behind the first
    try:
        outs = {o["match_id"]: o for o in ex.run(matches, context_for(spec), threading.Event())}
    finally:
        ex.close()
    hung, slow = (outs[m.match_id] for m in matches)
    assert hung["status"] == "forfeit" and "time limit" in hung["error"], hung.get("error")
    assert slow["status"] == "ok", slow.get("error")


def test_a_deaf_hang_is_killed_and_the_match_queued_behind_it_plays(tmp_path, test_policies):
    # A hang with SIGALRM blocked is ended by the worker's watchdog, which posts a forfeit
    # of the role that was deciding (it was an error, charged to nobody: the driver killed
    # the task without knowing who decided); one with no policy deciding (a mixture's
    # pick) stays an error. The task queued for that CPU starts only then, in a new
    # worker, and was killed with it as an overrun (its clock had run since its submission).
    d = {
        "maps": ["open_room"],
        "pursuers": ["pursuer/greedy"],
        "evaders": ["evader/test_deaf", "evader/test_deaf_pick", "evader/random"],
        "seeds": 2,
        "start": "valid",
        "time_limit": 2,
        "env": {"max_cycles": 30},
    }
    from analysis.tournament.executors import RayExecutor

    ex = RayExecutor(num_cpus=2)
    try:
        s = run_tournament(spec_from_dict(d), tmp_path / "r.sqlite", executor=ex, progress=False)
    finally:
        ex.close()
    with Store(tmp_path / "r.sqlite") as db:
        rows = db.rows(s.run_id)
    deaf = [r for r in rows if r["evader"] == "evader/test_deaf"]
    assert len(deaf) == 2 and all(r["status"] == "forfeit" for r in deaf), deaf
    assert all(r["blame"] == "evader" and "evader killed" in r["error"] for r in deaf)
    picked = [r for r in rows if r["evader"] == "evader/test_deaf_pick"]
    assert len(picked) == 2 and all(r["status"] == "error" for r in picked), picked
    assert all("no policy was deciding" in r["error"] for r in picked)
    played = [r for r in rows if r["evader"] == "evader/random"]
    assert len(played) == 2 and all(r["status"] == "ok" for r in played), played


def test_workers_cap_the_cpus_used_on_an_instance_already_running():
    # with --address (or a Ray this process had started) --workers was ignored: every
    # CPU of the cluster was used
    from analysis.tournament.executors import RayExecutor

    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    try:
        ex = RayExecutor(num_cpus=1)
        assert ex.cpus == 1 and ex.describe() == "ray (1 of 2 CPUs)" and ex.max_inflight == 1
        assert RayExecutor().describe() == "ray (2 CPUs)"
        assert RayExecutor(num_cpus=5).cpus == 2
        ex.close()
        assert ray.is_initialized()  # not started by the executor: not shut down by it
    finally:
        ray.shutdown()


def test_a_slow_worker_start_is_not_counted_as_an_overrun(tmp_path, monkeypatch):
    # A fresh Ray worker imports surveil and unpickles the run's context before its first
    # match (1.2 s idle, several seconds at load 9 on 2 cores); the deadline counted that
    # against the match's KILL_GRACE = 5 s, and a 0.1 s match was stored as an overrun
    # (seen once in a full suite). Simulated: a context that takes 12 s to unpickle. At load
    # 14 the start took longer than the 30 s its deadline allowed from the task's submission
    # (23 s to start the worker, 14 s more into the unpickling): the driver now times a
    # match from its start, which the task reports. And the first match imported the env
    # (PettingZoo), the start sampler and the observers on its own clock (1.2 s at load 6,
    # time limit 1 s): "MatchTimeout: no answer within the time limit (+1 s)".
    import sys

    from analysis.tournament.executors import KILL_GRACE, RayExecutor
    from strategies.policies import registry
    from strategies.policies.baselines import RandomPolicy

    class CountsImports(RandomPolicy):  # built on the match's clock, before run_episode
        def __init__(self, **kwargs):
            super().__init__(**kwargs)
            self._modules = set(sys.modules)

        def _decide(self, snap):
            new = sorted(set(sys.modules) - self._modules)
            if self._steps == 0 and new:
                raise ImportError(f"imported on the match's clock: {new}")
            return super()._decide(snap)

    limit = 4.0  # the match's own time: ~0.04 s idle, past 1 s at load 14 (measured)
    delay = limit + 1.0 + KILL_GRACE + 2.0  # past a deadline from submission: fails before

    def slow_rebuild():
        time.sleep(delay)
        return CountsImports

    def _slow_factory(rebuild):  # local, like slow_rebuild: shipped by value
        cls = rebuild()

        def factory(**kwargs):
            return cls(**kwargs)

        return factory

    class SlowToShip:  # a factory slow to unpickle (cloudpickle ships it by value)
        def __call__(self, **kwargs):
            return RandomPolicy(**kwargs)

        def __reduce__(self):
            return (_slow_factory, (slow_rebuild,))

    registry.policy_names()
    monkeypatch.setitem(
        registry._REGISTRY,
        "evader/slow_ship",
        registry.PolicySpec("evader/slow_ship", SlowToShip(), "slow to unpickle"),
    )
    d = {
        "name": "slow_start",
        "maps": ["open_room"],
        "pursuers": ["pursuer/greedy"],
        "evaders": ["evader/slow_ship"],
        "seeds": 1,
        "start": "valid",
        "time_limit": limit,
        "env": {"max_cycles": 10},
    }
    ex = RayExecutor(num_cpus=1)
    try:
        s = run_tournament(spec_from_dict(d), tmp_path / "r.sqlite", executor=ex, progress=False)
    finally:
        ex.close()
    with Store(tmp_path / "r.sqlite") as db:
        (row,) = db.rows(s.run_id)
    assert row["status"] == "ok", row["error"]


def _session_names(sid: int) -> list[str]:
    names = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            with contextlib.suppress(OSError, IndexError):
                fields = (entry / "stat").read_text().rsplit(")", 1)[1].split()
                if int(fields[3]) == sid:  # the session id
                    names.append((entry / "comm").read_text().strip())
    return names


@pytest.mark.skipif(not Path("/proc").is_dir(), reason="reads processes from /proc")
def test_sigterm_while_ray_starts_stops_as_sigterm_does_elsewhere(tmp_path):
    """``ray.init`` sets its own SIGTERM handler (``sys.exit(15)``): a SIGTERM while Ray
    started (or before the run's handler was in place) ended ``surveil tournament`` with
    exit code 15 and not a word. It now stops as on any other SIGTERM: exit code 143,
    'stopped by SIGTERM', no traceback. (Ray's dashboard and runtime-env agents, started by
    the raylet, outlive an interrupted start by about a minute before they notice.)"""
    spec = tmp_path / "s.toml"
    spec.write_text(
        'name = "s"\nmaps = ["open_room"]\nseeds = 2\nstart = "valid"\n'
        'pursuers = ["pursuer/greedy"]\nevaders = ["evader/random"]\n'
    )
    root = Path(__file__).resolve().parents[3]
    command = [sys.executable, "-m", "analysis.cli", "tournament", str(spec), "--backend", "ray"]
    command += ["--workers", "1", "--store", str(tmp_path / "s.sqlite"), "--no-progress"]
    env = {**os.environ, "PYTHONPATH": str(root), "SDL_VIDEODRIVER": "dummy", "MPLBACKEND": "Agg"}
    proc = subprocess.Popen(
        [*command, "--no-report"],
        env=env,
        cwd=tmp_path,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )
    try:
        deadline = time.monotonic() + 120
        while "raylet" not in _session_names(proc.pid):  # Ray is starting
            assert proc.poll() is None and time.monotonic() < deadline, proc.communicate()
            time.sleep(0.05)
        proc.send_signal(signal.SIGTERM)
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:  # pragma: no cover - the assertion below says why
            os.killpg(proc.pid, signal.SIGKILL)
    assert "Traceback" not in err, err
    assert proc.returncode == 143, (proc.returncode, err)
    assert "surveil: stopped by SIGTERM" in err
    deadline = time.monotonic() + 30
    while {"raylet", "gcs_server"} & set(_session_names(proc.pid)):  # shut down, not left
        assert time.monotonic() < deadline, _session_names(proc.pid)
        time.sleep(0.1)


@pytest.mark.skipif(not Path("/proc").is_dir(), reason="reads processes from /proc")
def test_ctrl_c_while_ray_starts_leaves_no_process_and_a_resumable_store(tmp_path):
    """A Ctrl-C while ``ray.init(num_cpus=2)`` started (the raylet up, its agents starting):
    ``ray.shutdown`` ended the GCS and the raylet, but the raylet's dashboard and runtime-env
    agents lived on for about a minute (reparented to init), and the run stayed 'running'
    in the store. Now every process the start begat ends with it, and the run is marked
    interrupted and resumes."""
    spec = tmp_path / "s.toml"
    spec.write_text(
        'name = "s"\nmaps = ["open_room"]\nseeds = 2\nstart = "valid"\n'
        'pursuers = ["pursuer/greedy"]\nevaders = ["evader/random"]\n'
    )
    root = Path(__file__).resolve().parents[3]
    store = tmp_path / "s.sqlite"
    command = [sys.executable, "-m", "analysis.cli", "tournament", str(spec), "--backend", "ray"]
    command += ["--workers", "2", "--store", str(store), "--no-progress", "--no-report"]
    env = {**os.environ, "PYTHONPATH": str(root), "SDL_VIDEODRIVER": "dummy", "MPLBACKEND": "Agg"}
    proc = subprocess.Popen(command, env=env, cwd=tmp_path, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, start_new_session=True)  # fmt: skip
    try:
        deadline = time.monotonic() + 120
        while "raylet" not in _session_names(proc.pid):  # Ray is starting
            assert proc.poll() is None and time.monotonic() < deadline, proc.communicate()
            time.sleep(0.02)
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=60)
        deadline = time.monotonic() + 15  # the agents lived ~60 s; SIGKILL after 3 s now
        while _session_names(proc.pid):
            assert time.monotonic() < deadline, _session_names(proc.pid)
            time.sleep(0.1)
    finally:
        if proc.poll() is None:  # pragma: no cover - the assertion below says why
            os.killpg(proc.pid, signal.SIGKILL)
    assert "Traceback" not in err and proc.returncode == 130, (proc.returncode, err)
    with Store(store) as db:
        assert [r["status"] for r in db.runs()] == ["interrupted"]
    done = subprocess.run(command, env=env, cwd=tmp_path, capture_output=True, text=True,
                          timeout=300)  # fmt: skip
    assert done.returncode == 0 and "2 of 2 matches stored" in done.stdout, done


def test_a_local_instance_starts_beside_another_cluster(tmp_path):
    """``--backend ray`` without ``--address`` is a local instance, but ``ray.init``
    without an address joins the cluster ``/tmp/ray/ray_current_cluster`` names (a
    ``ray start --head`` running, or the stale file of one stopped by a signal), and with
    ``--workers`` it raised "When connecting to an existing cluster, num_cpus and num_gpus
    must not be provided": a traceback. Here the file names a cluster that is gone."""
    import shutil
    import tempfile

    spec = tmp_path / "s.toml"
    spec.write_text(
        'name = "s"\nmaps = ["open_room"]\nseeds = 2\nstart = "valid"\n'
        'pursuers = ["pursuer/greedy"]\nevaders = ["evader/random"]\n[env]\nmax_cycles = 20\n'
    )
    ray_tmp = Path(tempfile.mkdtemp(prefix="r", dir="/tmp"))  # short: Ray's socket paths
    try:
        (ray_tmp / "ray").mkdir()
        (ray_tmp / "ray" / "ray_current_cluster").write_text("127.0.0.1:1")
        root = Path(__file__).resolve().parents[3]
        command = [sys.executable, "-m", "analysis.cli", "tournament", str(spec)]
        command += ["--backend", "ray", "--workers", "1", "--store", str(tmp_path / "s.sqlite")]
        env = {**os.environ, "PYTHONPATH": str(root), "RAY_TMPDIR": str(ray_tmp),
               "SDL_VIDEODRIVER": "dummy", "MPLBACKEND": "Agg"}  # fmt: skip
        env.pop("RAY_ADDRESS", None)
        out = subprocess.run([*command, "--no-progress", "--no-report"], env=env, cwd=tmp_path,
                             capture_output=True, text=True, timeout=300)  # fmt: skip
    finally:
        shutil.rmtree(ray_tmp, ignore_errors=True)
    assert "Traceback" not in out.stderr and out.returncode == 0, out.stderr[-2000:]
    assert "2 of 2 matches stored" in out.stdout and "ray (1 CPUs)" in out.stdout, out.stdout
