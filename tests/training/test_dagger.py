"""DAgger's mechanics: labels, aggregation, the fit, and an ordinary SB3 model at the end."""

from __future__ import annotations

import json

import numpy as np
import pytest

from envs import surveillance_v1
from envs.errors import InvalidConfigError
from strategies.policies import make_policy
from tests.training.conftest import lock_held_elsewhere
from training.dagger import DaggerConfig, _Rollout, dagger
from training.train import ENV_ID, ENV_NAME


def _cfg(tmp_path, **kw):
    base = dict(role="pursuer", expert="pursuer/greedy", opponent="evader/straight",
                maps=("open_room",), iterations=2, episodes=2, max_cycles=60, epochs=300,
                output_dir=str(tmp_path / "dagger"))  # fmt: skip
    return DaggerConfig(**{**base, **kw})


def test_dagger_aggregates_expert_labels_and_fits_them(tmp_path):
    r = dagger(_cfg(tmp_path))
    assert len(r.disagreement) == len(r.samples) == len(r.fit_error) == 2
    assert r.samples[0] > 0 and r.samples[1] > r.samples[0]  # aggregated, not replaced
    # the network reproduces what it was shown (actions in [-1, 1]^2, so 0.1 is small)
    assert r.fit_error[-1] < 0.1
    prov = json.loads((r.model_path.parent / "provenance.json").read_text())
    assert prov["role"] == "pursuer" and prov["method"] == "dagger"
    # the env version it trained on, as an RL run records it (a model card names it)
    assert (prov["env_id"], prov["registry_id"]) == (ENV_NAME, ENV_ID)
    # an ordinary SB3 model: it loads by name, declares its observation and plays
    p = make_policy(f"pursuer/sb3:{r.model_path}")
    assert p.observation_options == {"observation": "state"}
    env = surveillance_v1.parallel_env(map="open_room")
    obs, _ = env.reset(seed=0)
    p.reset(role="pursuer", map=env.config.map, config=env.config, seed=0)
    assert p.act(obs["pursuer_0"]).shape == (2,)
    env.close()


def test_rollout_labels_every_visited_observation_with_the_expert():
    from stable_baselines3 import PPO

    from training.single_agent import SingleAgentEnv

    env = SingleAgentEnv("pursuer", "evader/straight", map="open_room", observation="state")
    model = PPO("MlpPolicy", env, seed=0, device="cpu")
    expert = make_policy("pursuer/greedy")
    twin = make_policy("pursuer/greedy")
    roll = _Rollout(expert, model, beta=0.0, seed=0)  # the learner acts, the expert labels
    penv = surveillance_v1.parallel_env(map="open_room", max_cycles=20)
    obs, _ = penv.reset(seed=3)
    for pol in (roll, twin):
        pol.reset(role="pursuer", map=penv.config.map, config=penv.config, seed=0)
    evader = make_policy("evader/straight")
    evader.reset(role="evader", map=penv.config.map, config=penv.config, seed=0)
    while penv.agents:
        a = roll.act(obs["pursuer_0"])
        assert np.allclose(roll.labels[-1], twin.act(obs["pursuer_0"]))
        assert np.allclose(a, roll.learned[-1])  # beta = 0: the learner's action is played
        obs, *_ = penv.step({"pursuer_0": a, "evader_0": evader.act(obs["evader_0"])})
    assert len(roll.obs) == len(roll.labels) == 20


@pytest.mark.parametrize(
    "bad",
    [
        {"expert": "evader/shooting"},
        {"iterations": 0},
        {"beta": 1.5},
        {"maps": ()},
        {"learning_rate": -1.0},
    ],
)
def test_bad_dagger_configs_name_the_field(tmp_path, bad):
    with pytest.raises(InvalidConfigError):
        _cfg(tmp_path, **bad)


# ------------------------------------------------------------------ lidar learners, pools, resume
def _lidar_cfg(tmp_path, name="run", **kw):
    base = dict(role="pursuer", expert="pursuer/greedy",
                opponent=("evader/straight", "evader/random"), maps=("open_room", "random:3"),
                observation={"observation": "lidar_track", "n_rays": 8}, iterations=2,
                episodes=2, max_cycles=40, epochs=20, output_dir=str(tmp_path / name))  # fmt: skip
    return DaggerConfig(**{**base, **kw})


def test_a_lidar_learner_is_shown_the_envs_lidar_and_plays_from_it(tmp_path):
    r = dagger(_lidar_cfg(tmp_path))
    with np.load(r.model_path.parent / "dataset.npz") as data:
        assert data["obs"].shape == (r.samples[-1], 8 + 8)  # lidar_track with 8 rays
        assert data["act"].shape == (r.samples[-1], 2)
    # both maps and both opponents were played
    played = [e for it in r.episodes for e in it]
    assert {e["map"] for e in played} == {"open_room", "random:3"}
    p = make_policy(f"pursuer/sb3:{r.model_path}")
    assert p.observation_options == {"observation": "lidar_track", "n_rays": 8}
    from strategies.runner import run_episode

    res = run_episode("random:5", p, "evader/straight", 0, max_cycles=10)  # a map never seen
    assert res.observations["pursuer"]["observation"] == "lidar_track"


def test_an_interrupted_run_resumes_to_the_same_model_bit_for_bit(tmp_path):
    import torch
    from stable_baselines3 import PPO

    whole = dagger(_lidar_cfg(tmp_path, "whole"))
    dagger(_lidar_cfg(tmp_path, "parts", iterations=1))  # "interrupted" after iteration 0
    parts = dagger(_lidar_cfg(tmp_path, "parts"))  # same config: continues at iteration 1
    assert parts.disagreement == whole.disagreement and parts.samples == whole.samples
    a = PPO.load(whole.model_path, device="cpu").policy.state_dict()
    b = PPO.load(parts.model_path, device="cpu").policy.state_dict()
    assert all(torch.equal(a[k], b[k]) for k in a)


def test_a_dagger_run_whose_map_file_changed_is_not_resumed(tmp_path):
    """The config names a map file by its path: a run stopped after iteration 0, the
    file's walls or recommended parameters edited, then rerun aggregated labels of the
    other game into the first one's dataset without a word (as surveil train did)."""
    from envs.maps import load_map, save_map

    world = tmp_path / "room.json"
    save_map(load_map("open_room"), world, metadata={"l_min": 1.5, "l_max": 3.0})
    dagger(_cfg(tmp_path, maps=(str(world),), iterations=1, epochs=5))
    progress = json.loads((tmp_path / "dagger" / "progress.json").read_text())
    assert progress["maps"][str(world)]["l_min"] == 1.5
    save_map(load_map("open_room"), world, metadata={"l_min": 1.0, "l_max": 3.0})
    changed = r"DAgger run on another game: map '.*room\.json' resolves to l_min = 1\.0 now, l_min"
    with pytest.raises(InvalidConfigError, match=changed):
        dagger(_cfg(tmp_path, maps=(str(world),), epochs=5))
    save_map(load_map("open_room"), world, metadata={"l_min": 1.5, "l_max": 3.0})
    assert len(dagger(_cfg(tmp_path, maps=(str(world),), epochs=5)).samples) == 2  # resumed


def test_a_dagger_run_in_a_busy_output_dir_is_refused(tmp_path):
    """As surveil train (5653e95): two DAgger runs in one output_dir at once both wrote
    dataset, models and progress.json over each other's."""
    out = tmp_path / "dagger"
    out.mkdir()
    with lock_held_elsewhere(out / "train.lock"):
        with pytest.raises(InvalidConfigError, match=r"is being trained by pid 4242 on "):
            dagger(_cfg(tmp_path, iterations=1, epochs=5))
        assert not (out / "progress.json").exists()
    assert len(dagger(_cfg(tmp_path, iterations=1, epochs=5)).samples) == 1


@pytest.mark.parametrize("where", ["savez_compressed", "_settle"])
def test_a_ctrl_c_while_an_iteration_is_written_resumes_to_the_same_model(
    tmp_path, monkeypatch, where
):
    # model_last.zip, dataset.npz and progress.json were replaced one by one: a Ctrl-C in
    # the dataset's write resumed with iteration 1's model and iteration 0's dataset, and
    # ended with samples [80, 141] instead of [80, 160] and another model, saying nothing
    import torch
    from stable_baselines3 import PPO

    import training.dagger as D

    whole = dagger(_lidar_cfg(tmp_path, "whole"))
    real = getattr(D.np, where) if where == "savez_compressed" else D._settle
    calls = []

    def interrupted(*args, **kwargs):
        calls.append(args)
        # savez: iteration 1's dataset (before the commit); _settle: iteration 1's, after
        # progress.json committed it (the first call is _resume's on a fresh directory)
        if len(calls) == (2 if where == "savez_compressed" else 3):
            raise KeyboardInterrupt
        return real(*args, **kwargs)

    if where == "savez_compressed":
        monkeypatch.setattr(D.np, where, interrupted)
    else:
        monkeypatch.setattr(D, where, interrupted)
    with pytest.raises(KeyboardInterrupt):
        dagger(_lidar_cfg(tmp_path, "parts"))
    monkeypatch.undo()
    parts = dagger(_lidar_cfg(tmp_path, "parts"))
    assert parts.samples == whole.samples and parts.disagreement == whole.disagreement
    a = PPO.load(whole.model_path, device="cpu").policy.state_dict()
    b = PPO.load(parts.model_path, device="cpu").policy.state_dict()
    assert all(torch.equal(a[k], b[k]) for k in a)
    assert not [p.name for p in (tmp_path / "parts").iterdir() if ".next-" in p.name]


def test_a_different_config_in_the_same_directory_is_refused(tmp_path):
    dagger(_lidar_cfg(tmp_path, iterations=1))
    with pytest.raises(InvalidConfigError, match="different config"):
        dagger(_lidar_cfg(tmp_path, iterations=1, learning_rate=0.5))


def test_dagger_configs_round_trip_through_toml(tmp_path):
    from training.config import load_any_config

    cfg = _lidar_cfg(tmp_path, expert_params={"hysteresis": 0.5}, expert="pursuer/decomposition",
                     opponent_weights=(2.0, 1.0))  # fmt: skip
    path = tmp_path / "recipe.toml"
    path.write_text(cfg.to_toml())
    assert load_any_config(path) == cfg
    path.write_text(cfg.to_toml().replace("hysteresis", "hysteresys"))
    with pytest.raises(InvalidConfigError, match="hysteresys"):
        load_any_config(path)


def test_a_curriculum_plays_its_stages_in_order_then_the_top_level_settings(tmp_path):
    """Escapable starts on a wide sensor range first, then safe starts at the map's own."""
    from training.config import load_any_config

    cfg = _lidar_cfg(tmp_path, maps=("corridor",), iterations=3, episodes=1, epochs=2,
                     curriculum=({"iterations": 1, "start": "escapable", "env": {"l_max": 6.0}},
                                 {"iterations": 1, "maps": ["open_room"]}),
                     start="safe")  # fmt: skip
    r = dagger(cfg)
    (a,), (b,), (c,) = r.episodes
    assert (a["map"], a["start"], a["l_max"]) == ("corridor", "escapable", 6.0)
    assert (b["map"], b["start"]) == ("open_room", "safe") and b["l_max"] != 6.0
    assert (c["map"], c["start"]) == ("corridor", "safe")
    path = tmp_path / "curriculum.toml"
    path.write_text(cfg.to_toml())
    assert load_any_config(path) == cfg
    with pytest.raises(InvalidConfigError, match="curriculum"):
        _lidar_cfg(tmp_path, curriculum=({"start": "safe"},))


def test_validation_keeps_the_best_iteration_and_a_resumable_last_one(tmp_path):
    """The learner plays alone after each fit; model.zip is the iteration that won most
    (the later on ties), model_last.zip the last, and both load as ordinary models."""
    import torch
    from stable_baselines3 import PPO

    r = dagger(_lidar_cfg(tmp_path, iterations=3, validation_episodes=3))
    assert len(r.validation) == 3 and all(0.0 <= v <= 1.0 for v in r.validation)
    best = max(i for i, v in enumerate(r.validation) if v == max(r.validation))
    assert r.best_iteration == best
    kept = PPO.load(r.model_path, device="cpu").policy.state_dict()
    last = PPO.load(r.model_path.parent / "model_last.zip", device="cpu").policy.state_dict()
    same = all(torch.equal(kept[k], last[k]) for k in kept)
    assert same == (best == 2)
    prov = json.loads((r.model_path.parent / "provenance.json").read_text())
    assert prov["validation"] == r.validation and prov["best_iteration"] == best


def test_validation_plays_the_named_opponent_on_the_named_maps(tmp_path, monkeypatch):
    """Selection against the opponent a model is meant to beat (issue 9's target is the
    shooting evader) while it trains against a wider pool; the fields round-trip in TOML
    and bad values are named."""
    import training.dagger as dagger_module
    from training.config import load_any_config

    played = []
    real = dagger_module.run_episode

    def spy(world, pursuer, evader, seed, **kw):
        played.append((world, evader))
        return real(world, pursuer, evader, seed, **kw)

    cfg = _lidar_cfg(tmp_path, iterations=1, validation_episodes=3,
                     validation_opponent="evader/toward_away",
                     validation_maps=("corridor", "l_hall"))  # fmt: skip
    monkeypatch.setattr(dagger_module, "run_episode", spy)
    dagger(cfg)
    assert played[-3:] == [("corridor", "evader/toward_away"), ("l_hall", "evader/toward_away"),
                           ("corridor", "evader/toward_away")]  # fmt: skip
    # the training episodes drew from the pool (an OpponentPool), not the named opponent
    assert len(played) == 2 + 3 and all(not isinstance(e, str) for _, e in played[:2])
    path = tmp_path / "validation.toml"
    path.write_text(cfg.to_toml())
    assert load_any_config(path) == cfg
    with pytest.raises(InvalidConfigError, match="validation_opponent"):
        _lidar_cfg(tmp_path, validation_opponent="pursuer/greedy")
    with pytest.raises(InvalidConfigError, match="validation_maps"):
        _lidar_cfg(tmp_path, validation_maps=("",))


# ------------------------------------------------------------------ analytic features
@pytest.mark.parametrize(
    "role, expert, feature, n, params, world, opponent",
    [
        ("pursuer", "pursuer/decomposition", "safety_table", 5, {"range_margin": 0.3},
         "corridor", "evader/straight"),
        ("evader", "evader/shooting", "escape_plan", 11, {}, "two_rooms", "pursuer/greedy"),
        ("evader", "evader/shooting", "escape_plan+escape_memory", 22, {}, "office",
         "pursuer/decomposition"),
    ],
    ids=["safety_table", "escape_plan", "escape_memory"],
)  # fmt: skip
def test_a_learner_with_features_sees_in_play_what_it_was_fitted_on(
    tmp_path, role, expert, feature, n, params, world, opponent
):
    """The rollout's stored inputs are the lidar vector plus the features, and the SB3Policy
    built from the zip computes the same vectors from the state: same seed, same opponent,
    the learner alone (beta 0) plays the same episode in training and in play."""
    from strategies.policies.learner_inputs import LearnerInputs
    from strategies.runner import run_episode

    cfg = _lidar_cfg(tmp_path, role=role, expert=expert, features=tuple(feature.split("+")),
                     expert_params=params,
                     maps=(world,), opponent=opponent, iterations=1, episodes=1, epochs=5,
                     max_cycles=30)  # fmt: skip
    r = dagger(cfg)
    with np.load(r.model_path.parent / "dataset.npz") as data:
        obs = data["obs"]
    assert obs.shape == (r.samples[-1], 8 + 8 + n)
    if feature == "safety_table":
        assert np.all(np.abs(obs[:, 16:]) <= 1.5) and np.any(obs[:, 16] != obs[:, 18])
    else:  # two_rooms: every cell escapable, office: most; a crossing to head for
        assert np.all(np.abs(obs[:, 16:]) <= 1.0) and np.any(obs[:, 18:20] != 0)
    if n == 22:  # the shadow decides in one mode at each step
        assert np.all(obs[:, 32:36].sum(axis=1) == 1.0)
    p = make_policy(f"{role}/sb3:{r.model_path}")
    assert p.observation_options == {"observation": "state"} and p.uses_state
    seen = []

    class Spy(LearnerInputs):  # records what the policy builds, calling it once a step
        def __call__(self, state):
            seen.append(super().__call__(state))
            return seen[-1]

    p._inputs.__class__ = Spy
    roll = _Rollout(make_policy(expert, **params), _load(r), 0.0, 5, cfg.observation, cfg.features)

    def play(learner):
        pair = (learner, opponent) if role == "pursuer" else (opponent, learner)
        return run_episode(world, *pair, 7, max_cycles=30, start="safe")

    a, b = play(roll), play(p)
    assert a.steps == b.steps and a.winner == b.winner
    assert np.array_equal(a.trajectory, b.trajectory)
    assert np.array_equal(np.asarray(seen), np.asarray(roll.obs))
    # a second episode in play: the stateful features start afresh (not from the first
    # episode's memory), so it plays the same again
    seen.clear()
    c = play(p)
    assert np.array_equal(c.trajectory, b.trajectory)
    assert np.array_equal(np.asarray(seen), np.asarray(roll.obs))


def _load(r):
    from stable_baselines3 import PPO

    return PPO.load(str(r.model_path), device="cpu")


@pytest.mark.parametrize(
    "bad",
    [
        {"features": ("no_such",)},
        {"features": "safety_table"},  # a string, not a list
        {"features": ("safety_table",)},  # the greedy expert has no table
        {"features": ("safety_table", "safety_table"), "expert": "pursuer/decomposition"},
        {"features": ("escape_plan",), "expert": "pursuer/decomposition"},  # an evader's
        {"features": ("escape_memory",), "expert": "pursuer/decomposition"},  # an evader's
        {
            "features": ("escape_memory", "escape_memory"),
            "role": "evader",
            "expert": "evader/shooting",
            "opponent": "pursuer/greedy",
        },
        {
            "features": ("escape_memry",),
            "role": "evader",
            "expert": "evader/shooting",
            "opponent": "pursuer/greedy",
        },
    ],
)
def test_bad_features_are_refused_naming_them(tmp_path, bad):
    with pytest.raises(InvalidConfigError, match="feature"):
        _lidar_cfg(tmp_path, **bad)


def test_the_largest_seed_runs_and_a_larger_one_is_refused_by_the_config(tmp_path):
    # seed = 2**32 passed the config and the run raised numpy's 'Seed must be between 0
    # and 2**32 - 1' from the learner's SB3 model (2**64: torch's 'Overflow when unpacking
    # long long') as a traceback
    MAX_SEED = 2**31 - 1  # training.config.MAX_SEED
    small = dict(iterations=1, episodes=1, max_cycles=20, epochs=1)
    assert dagger(_cfg(tmp_path, seed=MAX_SEED, **small)).model_path.is_file()
    for seed in (2**32, 2**64):
        with pytest.raises(InvalidConfigError, match=rf"seed = {seed}: expected an integer in "
                           r"\[0, 2147483647\]"):  # fmt: skip
            _cfg(tmp_path, seed=seed, **small)
