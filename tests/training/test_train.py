"""Tiny SB3 runs: artefacts, loading back as a Policy, resume, determinism, CLI."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from stable_baselines3.common.callbacks import BaseCallback

from envs import surveillance_v1
from envs.errors import InvalidConfigError
from strategies.policies import make_policy
from training import cli_train, evaluate_model, latest_checkpoint, load_policy, train


class Interrupt(BaseCallback):
    """Raises once the model has seen ``at`` timesteps: a crash in the middle of a run."""

    def __init__(self, at: int) -> None:
        super().__init__()
        self.at = at

    def _on_step(self) -> bool:
        if self.num_timesteps >= self.at:
            raise KeyboardInterrupt(f"interrupted at {self.num_timesteps}")
        return True


def _params(path):
    import stable_baselines3

    model = stable_baselines3.PPO.load(str(path), device="cpu")
    return {k: v.numpy().copy() for k, v in model.policy.state_dict().items()}


def test_tiny_ppo_writes_model_and_provenance(tiny):
    result = train(tiny())
    assert result.timesteps == 256 and result.resumed_from is None
    out = result.output_dir
    assert (out / "model.zip").is_file() and (out / "config.toml").is_file()
    prov = json.loads((out / "provenance.json").read_text())
    assert prov["env_id"] == "surveillance_v1" and prov["timesteps"] == 256
    assert prov["config"]["role"] == "pursuer" and prov["algo"] == "ppo"
    assert prov["env_config"]["max_cycles"] == 40
    assert {"torch", "stable-baselines3", "gymnasium", "python"} <= set(prov["packages"])
    assert "git_sha" in prov and "git_dirty" in prov and prov["wall_seconds"] > 0
    ev = prov["evaluation"]
    assert ev["episodes"] == 2 and 0 <= ev["successes"] <= 2
    assert len(ev["escape_times"]) == sum(ev["causes"].values())
    assert (out / "model.zip").stat().st_size < 1_000_000
    # a second call finds the finished run and does not train again
    again = train(tiny())
    assert again.timesteps == 256 and again.wall_time == 0.0


def test_model_plays_as_a_registered_policy(tiny):
    result = train(tiny(eval_episodes=0))
    policy = make_policy("pursuer/sb3:" + str(result.model_path), algo="PPO")
    env = surveillance_v1.parallel_env(map="open_room", max_cycles=40)
    evader = make_policy("evader/straight")
    obs, _ = env.reset(seed=1)
    policy.reset(role="pursuer", map=env.config.map, config=env.config, seed=0)
    evader.reset(role="evader", map=env.config.map, config=env.config, seed=0)
    for _ in range(10):
        if not env.agents:
            break
        a = policy.act(obs["pursuer_0"])
        assert a.shape == (2,) and a.dtype == np.float32 and np.all(np.abs(a) <= 1)
        obs, *_ = env.step({"pursuer_0": a, "evader_0": evader.act(obs["evader_0"])})
    # deterministic: same observation, same action
    o = env.observation_space("pursuer_0").sample()
    assert np.array_equal(policy.act(o), policy.act(o))
    # the provenance-aware loader needs no algo
    loaded = load_policy(result.model_path)
    loaded.reset(role="pursuer", map=env.config.map, config=env.config, seed=3)
    assert loaded.algo == "PPO"
    assert np.array_equal(loaded.predict(o)[0], policy.act(o))


def test_sb3_name_without_algo_loads_ppo(tiny):
    result = train(tiny(eval_episodes=0, total_timesteps=64))
    policy = make_policy("pursuer/sb3:" + str(result.model_path))
    env = surveillance_v1.parallel_env(map="open_room")
    obs, _ = env.reset(seed=0)
    policy.reset(role="pursuer", map=env.config.map, config=env.config, seed=0)
    assert policy.act(obs["pursuer_0"]).shape == (2,)


def test_resume_after_interruption(tiny):
    config = tiny(eval_episodes=0)
    with pytest.raises(KeyboardInterrupt):
        train(config, callbacks=[Interrupt(at=150)])
    config_dir = Path(config.output_dir)
    assert not (config_dir / "model.zip").exists()
    done, ckpt = latest_checkpoint(config_dir)
    assert done == 128  # saved after the second rollout had been trained on
    result = train(config)
    assert result.resumed_from == ckpt
    assert result.timesteps == 256
    prov = json.loads(result.provenance_path.read_text())
    assert prov["resumed_at"] == 128 and prov["timesteps"] == 256
    # it continued from the checkpoint's weights: the result differs from a fresh run
    fresh = train(config.replace(output_dir=str(config_dir.parent / "fresh")))
    assert fresh.timesteps == 256
    a, b = _params(result.model_path), _params(fresh.model_path)
    assert any(not np.array_equal(a[k], b[k]) for k in a)


def test_same_seed_same_model_and_resume_guard(tiny, tmp_path):
    a = train(tiny(eval_episodes=0, total_timesteps=128, output_dir=str(tmp_path / "a")))
    b = train(tiny(eval_episodes=0, total_timesteps=128, output_dir=str(tmp_path / "b")))
    pa, pb = _params(a.model_path), _params(b.model_path)
    assert all(np.array_equal(pa[k], pb[k]) for k in pa)
    with pytest.raises(InvalidConfigError, match="seed"):
        train(tiny(eval_episodes=0, total_timesteps=128, seed=9, output_dir=str(tmp_path / "a")))
    # more timesteps in the same directory continue the finished run
    longer = train(tiny(eval_episodes=0, total_timesteps=192, output_dir=str(tmp_path / "a")))
    assert longer.timesteps == 192
    assert longer.resumed_from.name == "ckpt_128.zip"  # the finished run's final state


def test_tiny_sac_and_resume(tiny):
    config = tiny(
        role="evader",
        opponent="pursuer/greedy",
        algo="sac",
        total_timesteps=120,
        batch_size=16,
        checkpoint_freq=40,
        eval_episodes=1,
        algo_kwargs={"buffer_size": 500, "learning_starts": 20},
    )
    with pytest.raises(KeyboardInterrupt):
        train(config, callbacks=[Interrupt(at=90)])
    assert latest_checkpoint(config.output_dir)[0] >= 40
    result = train(config)
    assert result.resumed_from is not None and result.timesteps == 120
    policy = load_policy(result.model_path)
    assert policy.algo == "SAC" and result.evaluation.episodes == 1


def test_evaluate_model_reads_provenance(tiny):
    result = train(tiny(eval_episodes=0))
    ev = evaluate_model(result.model_path, "evader/toward_away", episodes=3, seed=5, start="valid")
    assert ev.role == "pursuer" and ev.episodes == 3 and ev.opponent == "evader/toward_away"
    assert ev.successes + len(ev.escape_times) == 3  # a pursuer wins iff nobody escapes
    assert math.isnan(ev.mean_escape_time) == (len(ev.escape_times) == 0)
    again = evaluate_model(
        result.model_path, "evader/toward_away", episodes=3, seed=5, start="valid"
    )
    assert again == ev
    with pytest.raises(InvalidConfigError, match="episodes"):
        evaluate_model(result.model_path, "evader/straight", episodes=0)


def test_cli_train(tmp_path, capsys):
    cfg = tmp_path / "c.toml"
    cfg.write_text(
        'role = "evader"\nopponent = "pursuer/greedy"\nn_steps = 64\nbatch_size = 32\n'
        "eval_episodes = 1\n[env]\nmax_cycles = 30\n"
    )
    assert cli_train([str(cfg), "--output-dir", str(tmp_path / "o"), "--timesteps", "64"]) == 0
    line = capsys.readouterr().out
    assert "PPO evader vs pursuer/greedy on open_room: 64 timesteps" in line
    assert (tmp_path / "o" / "model.zip").is_file()


def test_the_summary_names_maps_and_a_pool_as_a_user_writes_them(tiny):
    from training.cli import summary
    from training.train import TrainResult

    cfg = tiny(opponent=("evader/straight", "evader/random"), opponent_weights=(3.0, 1.0),
               map=("open_room", "corridor"))  # fmt: skip
    result = TrainResult(cfg, Path("o"), Path("o/model.zip"), Path("o/provenance.json"),
                         64, 1.0, None, None)  # fmt: skip
    # was "vs ('evader/straight', 'evader/random') on ('open_room', 'corridor')"
    assert summary(result) == (
        "PPO pursuer vs evader/straight (75%), evader/random (25%) on open_room, corridor: "
        "64 timesteps in 1.0 s -> o/model.zip"
    )
    result = TrainResult(tiny(opponent=("evader/straight", "evader/random")), Path("o"),
                         Path("o/model.zip"), Path("o/p.json"), 64, 1.0, None, None)  # fmt: skip
    assert summary(result).startswith("PPO pursuer vs evader/straight, evader/random on open_room:")


def test_a_rerun_of_a_finished_run_says_it_was_already_trained(tmp_path, capsys, monkeypatch):
    """Rerunning a finished ``surveil train`` (or a finished ``zoo reproduce``) returns
    the run as is, and said "PPO pursuer ...: 71680 timesteps in 0.0 s" ("trained 151552
    timesteps in 0.0 s"): as if it had trained in no time."""
    from training import zoo
    from training.zoo.__main__ import main as zoo_main

    cfg = tmp_path / "c.toml"
    cfg.write_text(
        'role = "pursuer"\nopponent = "evader/straight"\ntotal_timesteps = 128\nn_steps = 64\n'
        f'batch_size = 32\neval_episodes = 0\noutput_dir = "{tmp_path / "run"}"\n'
        "[env]\nmax_cycles = 20\n"
    )
    assert cli_train([str(cfg), "--no-progress"]) == 0
    first = capsys.readouterr().out
    assert " in " in first and "already trained" not in first
    assert cli_train([str(cfg), "--no-progress"]) == 0
    again = capsys.readouterr().out
    assert again.startswith("PPO pursuer vs evader/straight on open_room: 128 timesteps "
                            "(already trained) -> "), again  # fmt: skip
    monkeypatch.setattr(zoo, "MODELS_DIR", tmp_path / "zoo")
    zoo.install("tiny", tmp_path / "run")  # as a zoo model, reproduced twice
    cmd = ["reproduce", "tiny", "--output-dir", str(tmp_path / "again"), "--no-progress"]
    assert zoo_main(cmd) == 0 and capsys.readouterr().out.startswith("trained 128 timesteps in ")
    assert zoo_main(cmd) == 0
    assert capsys.readouterr().out.startswith("already trained: 128 timesteps -> ")


def test_cli_train_shows_its_progress_unless_told_not_to(tmp_path, capsys):
    """``surveil train`` / ``python -m training`` showed progress only given ``--progress``
    while ``python -m training.zoo reproduce`` shows it by default. Now both do: not a
    terminal here, so a plain line per tenth of the timesteps on stderr (no bar redraws
    or escape codes for a log), a line per DAgger episode and iteration; ``--no-progress``
    silences it and ``--progress`` is still accepted."""
    from training.dagger import DaggerConfig

    rl = tmp_path / "rl.toml"
    rl.write_text(
        'role = "pursuer"\nopponent = "evader/straight"\nn_steps = 32\nbatch_size = 32\n'
        "eval_episodes = 0\ncheckpoint_freq = 10000\n[env]\nmax_cycles = 30\n"
    )
    dag = tmp_path / "dag.toml"
    dag.write_text(DaggerConfig(role="pursuer", expert="pursuer/greedy",
                                opponent="evader/straight", maps=("open_room",), iterations=1,
                                episodes=1, max_cycles=10, epochs=1).to_toml())  # fmt: skip
    capsys.readouterr()
    assert cli_train([str(rl), "--output-dir", str(tmp_path / "a"), "--timesteps", "64"]) == 0
    err = capsys.readouterr().err
    lines = [line for line in err.splitlines() if line.startswith("ppo pursuer: ")]
    assert [line.split(" (")[0] for line in lines] == [
        f"ppo pursuer: {n} of 64 timesteps" for n in (7, 13, 20, 26, 32, 39, 45, 52, 58, 64)
    ], err
    assert "\r" not in err and "\x1b" not in err, err
    assert cli_train([str(dag), "--output-dir", str(tmp_path / "b")]) == 0
    got = capsys.readouterr()
    assert "dagger pursuer iteration 0 episode 1/1: " in got.err, got.err
    assert "iteration 0: " in got.out, got.out
    quiet = ["--no-progress", "--output-dir"]
    assert cli_train([str(rl), *quiet, str(tmp_path / "c"), "--timesteps", "64"]) == 0
    assert cli_train([str(dag), *quiet, str(tmp_path / "d")]) == 0
    got = capsys.readouterr()
    assert "timesteps (" not in got.err and "episode 1/1" not in got.err, got.err
    assert "iteration 0: " not in got.out, got.out
    assert cli_train([str(rl), "--output-dir", str(tmp_path / "e"), "--timesteps", "64",
                      "--progress"]) == 0  # fmt: skip


def test_the_largest_seed_trains_and_larger_ones_are_refused_by_the_config(tiny):
    # seed = 2**32 passed the config, and the run's first step raised numpy's 'Seed must be
    # between 0 and 2**32 - 1' (SB3 seeds the legacy generator) as a traceback
    MAX_SEED = 2**31 - 1  # training.config.MAX_SEED
    assert train(tiny(eval_episodes=0, total_timesteps=64, seed=MAX_SEED)).model_path.is_file()
    with pytest.raises(InvalidConfigError, match=r"seed = 4294967296: expected an integer in "
                       r"\[0, 2147483647\]"):  # fmt: skip
        tiny(seed=2**32)
    # a resumed run reseeds from seed + timesteps done
    with pytest.raises(InvalidConfigError, match=r"seed \+ total_timesteps = 4,294,967,296: "
                       r"expected at most 4,294,967,295"):  # fmt: skip
        tiny(seed=MAX_SEED, total_timesteps=2**31 + 1)
