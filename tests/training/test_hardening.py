"""Training's files and entry points under damage and bad input (issue 11, training side).

A damaged newest checkpoint falls back to an intact older one with a warning naming it;
a rerun with a smaller budget leaves the finished run's config.toml alone; provenance
keeps every segment of a resumed run; no SB3 logger folder lands in the temp directory;
models check their role and observation on load; both ``python -m`` entry points turn
every user error into one line and exit code 2.
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import pytest

from envs import surveillance_v1
from envs.errors import InvalidConfigError, InvalidObservationError
from strategies.policies import make_policy
from tests.training.conftest import lock_held_elsewhere
from tests.training.test_train import Interrupt
from training.cli import cli_train
from training.config import TrainConfig
from training.train import (
    CheckpointWarning,
    evaluate_model,
    latest_checkpoint,
    read_provenance,
    train,
)
from training.zoo.__main__ import main as zoo_main

ROOT = Path(__file__).resolve().parents[2]


def test_a_damaged_newest_checkpoint_falls_back_to_an_older_one(tiny):
    config = tiny(eval_episodes=0)
    with pytest.raises(KeyboardInterrupt):
        train(config, callbacks=[Interrupt(at=150)])
    out = Path(config.output_dir)
    ckpts = sorted((out / "checkpoints").glob("ckpt_*.zip"))
    assert [p.name for p in ckpts] == ["ckpt_128.zip", "ckpt_64.zip"]
    newest = out / "checkpoints" / "ckpt_128.zip"
    newest.write_bytes(newest.read_bytes()[:200])  # truncated by a crash
    with pytest.warns(CheckpointWarning, match="ckpt_128.zip"):
        result = train(config)
    assert result.resumed_from.name == "ckpt_64.zip" and result.timesteps == 256


def test_provenance_keeps_the_history_and_a_smaller_rerun_keeps_the_config(tiny):
    config = tiny(eval_episodes=0, total_timesteps=128)
    train(config)
    longer = train(config.replace(total_timesteps=192))
    prov = json.loads(longer.provenance_path.read_text())
    assert [h["timesteps"] for h in prov["history"]] == [128, 192]
    assert prov["history"][1]["resumed_at"] == 128
    toml = (Path(config.output_dir) / "config.toml").read_text()
    assert "total_timesteps = 192" in toml
    again = train(config.replace(total_timesteps=64))  # finished already: returned as is
    assert again.timesteps == 192
    assert (Path(config.output_dir) / "config.toml").read_text() == toml


def test_training_leaves_no_logger_folder_in_the_temp_directory(tiny, monkeypatch):
    monkeypatch.delenv("SB3_LOGDIR", raising=False)
    before = set(Path(tempfile.gettempdir()).glob("SB3-*"))
    train(tiny(eval_episodes=0, total_timesteps=64))
    assert set(Path(tempfile.gettempdir()).glob("SB3-*")) == before


def test_a_model_checks_its_role_and_observation(tiny):
    result = train(tiny(eval_episodes=0, total_timesteps=64))
    with pytest.raises(InvalidConfigError, match="trained as the pursuer"):
        make_policy(f"evader/sb3:{result.model_path}")
    policy = make_policy(f"pursuer/sb3:{result.model_path}")
    assert policy.observation_options == {"observation": "state"}
    env = surveillance_v1.parallel_env(map="open_room", observation="lidar", n_rays=8)
    obs, _ = env.reset(seed=0)
    with pytest.raises(InvalidConfigError, match=r"shape \(13,\), but the game's observation "
                       r"'lidar' with n_rays = 8 has shape \(14,\)"):  # fmt: skip
        policy.reset(role="pursuer", map=env.config.map, config=env.config, seed=0)
    assert policy.model is None  # refused before it loaded
    state = surveillance_v1.parallel_env(map="open_room").config
    policy.reset(role="pursuer", map=state.map, config=state, seed=0)
    with pytest.raises(InvalidObservationError, match="trained on shape"):
        policy.act(obs["pursuer_0"])  # act() still checks what it is given
    env.close()


def test_a_damaged_model_file_names_the_file(tmp_path):
    bad = tmp_path / "model.zip"
    bad.write_bytes(b"PK\x03\x04 not really a zip")
    policy = make_policy(f"pursuer/sb3:{bad}", algo="PPO")
    env = surveillance_v1.parallel_env(map="open_room")
    with pytest.raises(InvalidConfigError, match=str(bad)):
        policy.reset(role="pursuer", map=env.config.map, config=env.config, seed=0)


@pytest.mark.parametrize("model", ["ppo_evader_vs_greedy_open_room", "dagger_evader_memory"])
@pytest.mark.parametrize(
    ("bad", "message"),
    [
        ("nan", r"observation: expected finite values, got nan at index 3 \(1 non-finite of 13\)"),
        ("inf", r"observation: expected finite values, got inf at index 3"),
        ("short", r"\(5,\)"),
        ("text", r"observation: expected an array of real numbers, got str"),
    ],
)
def test_a_model_refuses_an_observation_that_is_no_finite_vector_by_name(model, bad, message):
    # a NaN reached torch ('Expected parameter loc ... to satisfy the constraint Real()') or,
    # for a model of analytic features, int() ('cannot convert float NaN to integer'); a
    # short state vector was decode_state's bare ValueError: not the InvalidObservationError
    # the analytic policies raise
    from strategies.policies.model_files import model_policy_name

    env = surveillance_v1.parallel_env(map="open_room")
    env.reset(seed=0)
    state = env.state()
    obs = {"nan": state.copy(), "inf": state.copy(), "short": state[:5], "text": "abc"}[bad]
    if bad in ("nan", "inf"):
        obs[3] = float(bad)
    policy = make_policy(model_policy_name(f"zoo:{model}", "evader", "evader"))
    policy.reset(role="evader", map=env.config.map, config=env.config, seed=0)
    with pytest.raises(InvalidObservationError, match=message):
        policy.act(obs)
    assert np.all(np.isfinite(policy.act(state)))  # the policy plays on


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        ("[algo_kwargs]\nn_epochs = 0\n", "n_epochs = 0: expected an integer >= 1"),
        ('[algo_kwargs]\nent_coef = "abc"\n', "ent_coef = 'abc': expected a number >= 0"),
        ("[algo_kwargs]\ngae_lambda = 2\n", "gae_lambda = 2: expected a number >= 0 and <= 1"),
        ('seed = "x"\n', "seed"),
        ("[env]\nfoo = 1\n", "unknown key"),
    ],
)
def test_python_m_training_reports_bad_configs_in_one_line(tmp_path, capsys, extra, message):
    cfg = tmp_path / "c.toml"
    head = 'role = "pursuer"\nopponent = "evader/straight"\ntotal_timesteps = 64\n'
    head += f'output_dir = "{tmp_path / "run"}"\n'
    if extra.startswith("seed"):
        head, extra = head + extra, ""
    cfg.write_text(head + extra)
    assert cli_train([str(cfg)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("python -m training: error:") and message in err
    assert "Traceback" not in err and err.count("\n") == 1


@pytest.mark.parametrize("under", [False, True])
def test_an_output_dir_that_is_a_file_is_refused_before_training(tmp_path, capsys, under):
    (tmp_path / "notes.json").write_text("{}")
    out = tmp_path / "notes.json" / "run" if under else tmp_path / "notes.json"
    cfg = tmp_path / "c.toml"
    cfg.write_text(
        'role = "pursuer"\nopponent = "evader/straight"\ntotal_timesteps = 64\n'
        f'output_dir = "{out}"\n'
    )
    assert cli_train([str(cfg)]) == 2
    err = capsys.readouterr().err
    assert f"output_dir = '{out}': '{tmp_path / 'notes.json'}' is a file" in err
    assert err.count("\n") == 1


@pytest.mark.skipif(not Path("/proc/self").is_dir(), reason="needs Linux's /proc")
@pytest.mark.parametrize("method", ["ppo", "dagger"])
def test_an_output_dir_that_cannot_be_written_is_refused_before_training(tmp_path, capsys, method):
    # procfs takes no new file, for root too: the run loaded its config and torch, then
    # failed at the mkdir with "python -m training: error: /proc/...: No such file or
    # directory", naming no field
    out = "/proc/surveil-test/run"
    cfg = tmp_path / "c.toml"
    body = {
        "ppo": 'role = "pursuer"\nopponent = "evader/straight"\ntotal_timesteps = 64\n',
        "dagger": 'method = "dagger"\nrole = "pursuer"\nexpert = "pursuer/greedy"\n'
        'opponent = "evader/straight"\nmaps = ["open_room"]\n',
    }[method]
    cfg.write_text(body + f'output_dir = "{out}"\n')
    assert cli_train([str(cfg)]) == 2
    err = capsys.readouterr().err
    assert err == (
        f"python -m training: error: output_dir = '{out}': cannot write in '/proc' (No such "
        "file or directory); expected a directory you can write\n"
    )


def zoo_dir_model(name):
    from training import zoo

    return zoo.model_path(name)


def test_python_m_training_zoo_reports_bad_input_in_one_line(capsys):
    assert zoo_main(["info", "no_such_model"]) == 2
    assert "unknown zoo model 'no_such_model'" in capsys.readouterr().err
    name = "ppo_pursuer_vs_straight_open_room"
    assert zoo_main(["evaluate", name, "--opponent", "evader/nope", "--episodes", "1"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("python -m training.zoo: error:") and "evader/nope" in err
    # --seed -3 was numpy's ValueError traceback; --episodes 0 said "episodes"
    for flag, value, expected in [("--seed", "-3", ">= 0"), ("--episodes", "0", ">= 1")]:
        argv = ["evaluate", name, "--opponent", "evader/straight", "--episodes", "1"]
        assert zoo_main([*argv, flag, value]) == 2
        err = capsys.readouterr().err
        assert (
            err
            == f"python -m training.zoo: error: {flag} = {value}: expected an integer {expected}\n"
        )
    with pytest.raises(InvalidConfigError, match="seed = -1: expected an integer >= 0"):
        evaluate_model(zoo_dir_model(name), "evader/straight", episodes=1, seed=-1)


def test_the_entry_points_run_as_modules(tmp_path):
    """The real ``python -m`` processes: exit code 2, one line, no traceback."""
    cfg = tmp_path / "c.toml"
    cfg.write_text('role = "pursuer"\nopponent = "evader/straight"\n[algo_kwargs]\nn_epochs = 0\n')
    for args in (["-m", "training", str(cfg)], ["-m", "training.zoo", "info", "x"]):
        r = subprocess.run([sys.executable, *args], capture_output=True, text=True, cwd=ROOT)
        assert r.returncode == 2 and "Traceback" not in r.stderr, r.stderr
        assert r.stderr.count("\n") == 1


def test_config_values_are_checked_before_sb3_sees_them():
    for kw in ({"n_epochs": 0}, {"ent_coef": "abc"}, {"clip_range": -1.0}, {"use_sde": 1}):
        with pytest.raises(InvalidConfigError, match=next(iter(kw))):
            TrainConfig(role="pursuer", opponent="evader/straight", algo_kwargs=kw)
    TrainConfig(role="evader", opponent="pursuer/greedy", algo="sac",
                algo_kwargs={"ent_coef": "auto_0.1"})  # fmt: skip
    assert latest_checkpoint(Path("/nonexistent")) is None


@pytest.mark.parametrize(
    ("flags", "message"),
    [
        (["--timesteps", "0"], "--timesteps = 0: expected an integer >= 1"),
        (["--seed", "-3"], "--seed = -3: expected an integer >= 0"),
        (["--self-play", "-1"], "--self-play = -1: expected an integer >= 1"),
        (["--self-play", "0"], "--self-play = 0: expected an integer >= 1"),  # ran one run
    ],
)
def test_a_bad_flag_is_named_as_the_flag_not_as_a_config_field(tmp_path, capsys, flags, message):
    """Was 'config.toml: total_timesteps = 0' (a file the user never wrote) or 'c.toml:
    seed = -3' (a value not in that file)."""
    cfg = tmp_path / "c.toml"
    cfg.write_text(f'role = "pursuer"\nopponent = "evader/straight"\noutput_dir = "{tmp_path}/r"\n')
    assert cli_train([str(cfg), *flags]) == 2
    err = capsys.readouterr().err
    assert err == f"python -m training: error: {message}\n"


def test_an_unknown_opponent_leaves_no_config_that_refuses_the_fixed_rerun(tmp_path, capsys):
    """A misspelt opponent wrote output_dir/config.toml before failing, so the corrected
    command was refused ('holds a run with a different config')."""
    out = tmp_path / "run"
    cfg = tmp_path / "c.toml"
    body = 'role = "pursuer"\ntotal_timesteps = 64\nn_steps = 32\nbatch_size = 32\n'
    body += f'output_dir = "{out}"\n'
    cfg.write_text(body + 'opponent = "evader/nope"\n')
    assert cli_train([str(cfg)]) == 2
    assert "unknown policy 'evader/nope'" in capsys.readouterr().err
    assert not (out / "config.toml").exists()
    cfg.write_text(body + 'opponent = "evader/straight"\n')
    assert cli_train([str(cfg)]) == 0


@pytest.mark.parametrize(
    ("body", "field"),
    [
        ('role = "pursuer"\nopponent = ["evader/straight", "evader/nope"]\n', "opponent"),
        (
            'method = "dagger"\nrole = "pursuer"\nexpert = "pursuer/greedy"\n'
            'opponent = "evader/straight"\nvalidation_opponent = "evader/nope"\n',
            "DaggerConfig: validation_opponent",
        ),
    ],
)
def test_an_unknown_opponent_is_refused_as_a_field_of_the_file(tmp_path, capsys, body, field):
    """A misspelt registered opponent was refused only when the first env was built, without
    the file or the field ('unknown policy 'evader/nope'; known policies: ...'), after
    output_dir and its train.lock had been made."""
    out = tmp_path / "run"
    cfg = tmp_path / "c.toml"
    cfg.write_text(body + f'output_dir = "{out}"\n')
    assert cli_train([str(cfg)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(
        f"python -m training: error: {cfg}: {field} = 'evader/nope': unknown policy 'evader/nope'"
    ), err
    assert not out.exists()


def test_warnings_are_one_line_each_shown_once(tmp_path):
    """python -m training (and python -m training.zoo) showed warnings in Python's own
    format, the file and source line included ('/.../base.py:217: UnseenParametersWarning:
    ...' then '  self._reset()'), the same one three times over, where surveil shows
    'surveil: warning: ...' once."""
    cfg = tmp_path / "c.toml"
    cfg.write_text(
        'role = "pursuer"\nopponent = "zoo:ppo_evader_vs_greedy_open_room"\nmap = "open_room"\n'
        'start = "valid"\ntotal_timesteps = 64\nn_steps = 32\nbatch_size = 32\nn_envs = 2\n'
        f'eval_episodes = 0\noutput_dir = "{tmp_path / "run"}"\n'
        "[env]\nmax_cycles = 20\nv_evader = 0.4\n"
    )
    run = subprocess.run(
        [sys.executable, "-m", "training", str(cfg), "--no-progress"],
        capture_output=True, text=True, cwd=ROOT, timeout=300,
    )  # fmt: skip
    assert run.returncode == 0, run.stderr
    lines = run.stderr.splitlines()
    unseen = [line for line in lines if "this model plays a game it was not trained at" in line]
    assert len(unseen) == 1, run.stderr
    assert unseen[0].startswith("python -m training: warning: "), run.stderr
    assert all(line.startswith("python -m training: warning: ") for line in lines), run.stderr


def test_an_opponent_model_that_fails_to_load_does_not_refuse_the_fixed_rerun(tmp_path, capsys):
    """An opponent model that passes the config's checks (a zip with SB3's 'data') but
    fails at the first reset (here its weights cut short) stopped the run after it wrote
    config.toml: the corrected command was refused ('holds a run with a different
    config') though nothing had been learned."""
    import zipfile

    from training import zoo

    damaged = tmp_path / "damaged.zip"
    with (
        zipfile.ZipFile(zoo.model_path("ppo_evader_vs_greedy_open_room")) as src,
        zipfile.ZipFile(damaged, "w") as dst,
    ):
        for item in src.infolist():
            data = src.read(item.filename)
            dst.writestr(item, data[: len(data) // 2] if item.filename == "policy.pth" else data)
    out = tmp_path / "run"
    cfg = tmp_path / "c.toml"
    body = 'role = "pursuer"\ntotal_timesteps = 64\nn_steps = 32\nbatch_size = 32\n'
    body += f'eval_episodes = 0\noutput_dir = "{out}"\n[env]\nmax_cycles = 20\n'
    cfg.write_text(f'opponent = "{damaged}"\n' + body)
    assert cli_train([str(cfg)]) == 2
    assert "cannot load the model file" in capsys.readouterr().err
    cfg.write_text('opponent = "evader/straight"\n' + body)
    assert cli_train([str(cfg)]) == 0, capsys.readouterr().err
    assert (out / "model.zip").is_file()


def test_a_run_with_a_checkpoint_still_refuses_another_config(tiny):
    """The other side of the test above: once something is learned, a rerun of another
    config is refused, naming the field."""
    train(tiny(total_timesteps=64, eval_episodes=0))
    with pytest.raises(InvalidConfigError, match=r"different config \(fields \['seed'\]"):
        train(tiny(total_timesteps=128, eval_episodes=0, seed=5))


def test_an_interrupted_run_says_what_it_kept_and_the_rerun_resumes(tmp_path, capsys, monkeypatch):
    # Ctrl-C said only "interrupted": not that the run resumes, nor from where
    import re

    import training.cli

    cfg = tmp_path / "c.toml"
    cfg.write_text(
        'role = "pursuer"\nopponent = "evader/straight"\nmap = "open_room"\nstart = "valid"\n'
        "total_timesteps = 256\nn_steps = 64\nbatch_size = 32\ncheckpoint_freq = 64\n"
        f'eval_episodes = 2\neval_start = "valid"\noutput_dir = "{tmp_path / "run"}"\n'
        "[env]\nmax_cycles = 40\n[algo_kwargs]\nn_epochs = 2\n"
    )
    real = training.cli.train
    monkeypatch.setattr(training.cli, "train", lambda c, **kw: real(c, callbacks=[Interrupt(150)]))
    assert cli_train([str(cfg)]) == 130
    err = capsys.readouterr().err
    kept = re.search(r"stopped: (\d+) of 256 timesteps are in (\S+); rerun the same command", err)
    assert kept, err
    assert Path(kept.group(2)).name == f"ckpt_{kept.group(1)}.zip"
    monkeypatch.setattr(training.cli, "train", real)
    assert cli_train([str(cfg)]) == 0
    assert f"(resumed from ckpt_{kept.group(1)}.zip)" in capsys.readouterr().out


def test_sac_resumes_an_older_checkpoint_with_its_own_replay_buffer(tiny):
    # one replay_buffer.pkl served every checkpoint: resumed from ckpt_40 (ckpt_80
    # damaged), SAC read the buffer of 80 steps, transitions its state had not seen
    from stable_baselines3.common.callbacks import BaseCallback

    class BufferAtStart(BaseCallback):
        def _on_training_start(self) -> None:
            seen.append(self.model.replay_buffer.size())

        def _on_step(self) -> bool:
            return True

    config = tiny(role="evader", opponent="pursuer/greedy", algo="sac", total_timesteps=120,
                  batch_size=16, checkpoint_freq=40, eval_episodes=0,
                  algo_kwargs={"buffer_size": 500, "learning_starts": 20})  # fmt: skip
    with pytest.raises(KeyboardInterrupt):
        train(config, callbacks=[Interrupt(at=90)])
    ckdir = Path(config.output_dir) / "checkpoints"
    newest = ckdir / "ckpt_80.zip"
    newest.write_bytes(newest.read_bytes()[:200])  # truncated by a crash
    seen: list[int] = []
    with pytest.warns(CheckpointWarning, match="ckpt_80.zip"):
        result = train(config, callbacks=[BufferAtStart()])
    assert result.resumed_from.name == "ckpt_40.zip" and seen == [40]
    assert sorted(p.name for p in ckdir.glob("replay_buffer*")) == [
        "replay_buffer_120.pkl",
        "replay_buffer_80.pkl",
    ]  # the buffers of the two checkpoints kept


def test_interrupted_dagger_and_self_play_say_a_rerun_resumes(tmp_path, capsys, monkeypatch):
    # both printed only "interrupted", though both resume (per iteration, per stage)
    import training.cli
    import training.dagger

    rl = tmp_path / "rl.toml"
    rl.write_text(
        f'role = "pursuer"\nopponent = "evader/straight"\noutput_dir = "{tmp_path / "sp"}"\n'
    )
    dag = tmp_path / "dag.toml"
    dag.write_text(
        'method = "dagger"\nrole = "pursuer"\nexpert = "pursuer/greedy"\n'
        f'opponent = "evader/straight"\niterations = 5\noutput_dir = "{tmp_path / "dg"}"\n'
    )

    def stop(*args, **kwargs):
        raise KeyboardInterrupt

    def stop_after_two(cfg, **kwargs):
        out = Path(cfg.output_dir)
        out.mkdir(parents=True, exist_ok=True)
        (out / "progress.json").write_text('{"samples": [10, 20]}')
        raise KeyboardInterrupt

    monkeypatch.setattr(training.cli, "self_play", stop)
    assert cli_train([str(rl), "--self-play", "2"]) == 130
    assert "stopped: rerun the same command to resume" in capsys.readouterr().err
    monkeypatch.setattr(training.dagger, "dagger", stop_after_two)
    assert cli_train([str(dag)]) == 130
    err = capsys.readouterr().err
    assert f"stopped: 2 of 5 iterations are in {tmp_path / 'dg'}; rerun the same" in err


def test_an_extension_interrupted_in_its_evaluation_leaves_model_and_provenance_matched(
    tiny, monkeypatch
):
    # model.zip was replaced before the evaluation: a Ctrl-C there left the 256-step model
    # beside the 128-step provenance, and a rerun at 128 returned it as the 128-step model
    import hashlib
    import importlib

    T = importlib.import_module("training.train")
    first = train(tiny(total_timesteps=128, eval_episodes=2))

    def digest():
        return hashlib.sha256(first.model_path.read_bytes()).hexdigest()

    before = digest()

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(T, "evaluate_model", interrupted)
    with pytest.raises(KeyboardInterrupt):
        train(tiny(total_timesteps=256, eval_episodes=2))
    monkeypatch.undo()
    assert digest() == before and read_provenance(first.model_path)["timesteps"] == 128
    assert train(tiny(total_timesteps=128, eval_episodes=2)).timesteps == 128
    assert digest() == before
    longer = train(tiny(total_timesteps=256, eval_episodes=2))  # resumes the final checkpoint
    assert longer.timesteps == 256 and digest() != before
    assert read_provenance(first.model_path)["timesteps"] == 256
    assert not (first.model_path.parent / "model.next.zip").exists()


def _interrupted_on_a_map_file(tiny, tmp_path):
    """A run on the map file room.json (open_room, l_min 1.5, l_max 3.0) interrupted after
    150 steps: (the file, the config, its output dir)."""
    from envs.maps import load_map, save_map

    world = tmp_path / "room.json"
    save_map(load_map("open_room"), world, metadata={"l_min": 1.5, "l_max": 3.0})
    config = tiny(map=str(world))
    with pytest.raises(KeyboardInterrupt):
        train(config, callbacks=[Interrupt(at=150)])
    return world, config, Path(config.output_dir)


def test_a_resumed_run_whose_map_file_changed_is_refused(tiny, tmp_path):
    """config.toml names a map file by its path: a run interrupted, its file's geometry or
    recommended parameters (metadata) edited, then rerun trained on on the other game
    without a word. The resolved env configs are kept in env.json and compared."""
    from envs.maps import load_map, save_map

    world, config, out = _interrupted_on_a_map_file(tiny, tmp_path)
    recorded = json.loads((out / "env.json").read_text())
    assert (recorded[str(world)]["l_min"], recorded[str(world)]["l_max"]) == (1.5, 3.0)
    save_map(load_map("open_room"), world, metadata={"l_min": 1.0, "l_max": 3.0})
    # the map as the config names it (it read 'open_room', the map's own name), and only
    # what changed, as DAgger says it (one check for both: training.config.check_same_maps)
    with pytest.raises(InvalidConfigError, match=re.escape(
            f"holds a run on another game: map {str(world)!r} resolves to l_min = 1.0 now, "
            "l_min = 1.5 when the run started")):  # fmt: skip
        train(config)
    save_map(load_map("corner"), world, metadata={"l_min": 1.5, "l_max": 3.0})
    with pytest.raises(InvalidConfigError, match=r"resolves to digest = '"):
        train(config)
    save_map(load_map("open_room"), world, metadata={"l_min": 1.5, "l_max": 3.0})
    assert train(config).timesteps == 256  # the same game again: resumed


def test_a_run_of_an_older_surveil_is_still_checked_by_its_maps_geometry(tiny, tmp_path):
    """An env.json written before the one check (a list of resolved env configs) is read
    for its maps' geometry: the same walls resume, other walls are refused."""
    from envs.maps import load_map, save_map

    world, config, out = _interrupted_on_a_map_file(tiny, tmp_path)
    old = [{"map": "open_room", "map_digest": load_map("open_room").digest, "l_min": 1.5}]
    (out / "env.json").write_text(json.dumps(old))
    save_map(load_map("corner"), world, metadata={"l_min": 1.5, "l_max": 3.0})
    with pytest.raises(InvalidConfigError, match=r"map '.*room\.json' resolves to digest = "):
        train(config)
    save_map(load_map("open_room"), world, metadata={"l_min": 1.5, "l_max": 3.0})
    (out / "env.json").write_text(json.dumps(old))
    assert train(config).timesteps == 256


def test_a_second_run_in_a_busy_output_dir_is_refused_naming_the_first(tiny):
    """Two runs in one output_dir at once both trained, each writing checkpoints, model and
    provenance over the other's (the tournament store has had a lock)."""
    config = tiny()
    out = Path(config.output_dir)
    out.mkdir(parents=True)
    with lock_held_elsewhere(out / "train.lock"):  # another process training there
        with pytest.raises(InvalidConfigError, match=r"is being trained by pid 4242 on "
                           r"elsewhere since 2026-01-01 00:00:00; wait for that run"):  # fmt: skip
            train(config)
        assert not (out / "config.toml").exists()  # nothing written
    assert train(config).timesteps == 256  # the lock is released with its holder
    assert (out / "train.lock").read_text() == ""  # and ours when the run ends


_DISCARDED_CTRL_C = """if True:
    import gc, signal, sys, weakref
    # as a terminal's foreground job: a test run started in the background ignores
    # SIGINT, and so would this child
    signal.signal(signal.SIGINT, signal.default_int_handler)
    import {module} as target

    real = target.{name}

    class Thing:
        pass

    def patched(*args, **kwargs):  # SIGINT delivered in a weakref callback, as in imports
        thing = Thing()
        keep = weakref.ref(thing, lambda ref: signal.raise_signal(signal.SIGINT))
        del thing
        gc.collect()
        return real(*args, **kwargs)

    target.{name} = patched
    sys.exit({main}({argv!r}))
"""


@pytest.mark.parametrize(
    ("module", "name", "main", "prog", "argv"),
    [
        ("training.cli", "load_any_config", "target.cli_train", "python -m training",
         ["CONFIG", "--no-progress"]),
        ("training.zoo.__main__", "CommandParser.parse_args", "target.main",
         "python -m training.zoo",
         ["evaluate", "ppo_evader_vs_greedy_open_room", "--opponent", "pursuer/greedy",
          "--episodes", "1"]),
    ],
)  # fmt: skip
def test_a_ctrl_c_cpython_discards_while_it_imports_still_stops_the_command(
    tmp_path, module, name, main, prog, argv
):
    """A Ctrl-C whose KeyboardInterrupt is raised inside a weakref callback (as importlib's
    module-lock callbacks run during the seconds of imports before a run) is discarded by
    CPython ("Exception ignored in ...") and the command ran on: training trained, the zoo
    played. surveil records such a Ctrl-C and honours it (analysis.cli.main); python -m
    training and python -m training.zoo now do too. Reproduced without the timing."""
    out = tmp_path / "run"
    cfg = tmp_path / "c.toml"
    cfg.write_text(
        'role = "pursuer"\nopponent = "evader/straight"\ntotal_timesteps = 64\nn_steps = 32\n'
        f'batch_size = 32\neval_episodes = 0\noutput_dir = "{out}"\n[env]\nmax_cycles = 20\n'
    )
    argv = [str(cfg) if a == "CONFIG" else a for a in argv]
    script = _DISCARDED_CTRL_C.format(module=module, name=name, main=main, argv=argv)
    run = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, cwd=ROOT, timeout=300
    )
    assert "Exception ignored" in run.stderr  # the KeyboardInterrupt CPython discarded
    assert run.returncode == 130, run.stderr
    assert run.stderr.endswith(f"{prog}: interrupted\n")
    assert run.stdout == "" and not out.exists()  # nothing played, nothing trained


def test_a_checkpoint_that_does_not_fit_is_named_and_leaves_no_partial_file(tmp_path):
    """A checkpoint written on a full disk (a file-size limit on the run's process: its
    writes fail with "File too large"): one line naming the checkpoint, no partial file
    left in the run's folder. Before: "python -m training: error: [Errno 27] File too
    large", naming no file, and checkpoints/ckpt_64.zip.tmp left behind."""
    import resource

    def limited() -> None:  # the config and env files fit, a model zip does not
        resource.setrlimit(resource.RLIMIT_FSIZE, (20_000, 20_000))

    cfg = tmp_path / "c.toml"
    out = tmp_path / "run"
    cfg.write_text(
        'role = "pursuer"\nopponent = "evader/straight"\nmap = "open_room"\nstart = "valid"\n'
        "total_timesteps = 128\nn_steps = 64\nbatch_size = 32\ncheckpoint_freq = 64\n"
        f'eval_episodes = 0\noutput_dir = "{out}"\n[env]\nmax_cycles = 20\n'
    )
    run = subprocess.run(
        [sys.executable, "-m", "training", str(cfg), "--no-progress"],
        capture_output=True, text=True, cwd=ROOT, timeout=300, preexec_fn=limited,
    )  # fmt: skip
    assert "Traceback" not in run.stderr, run.stderr
    assert run.returncode == 2, run.stderr
    lines = run.stderr.strip().splitlines()
    assert len(lines) == 1, run.stderr
    ckpt = out / "checkpoints" / "ckpt_64.zip"
    assert lines[0].startswith(
        f"python -m training: error: training output = {str(ckpt)!r}: could not write it "
        "(File too large)"
    ), run.stderr
    assert sorted(p.name for p in (out / "checkpoints").iterdir()) == []
