"""Training opponents take models as play, evaluate and tournaments do: ``zoo:NAME`` or a
``.zip`` path (``ROLE/sb3:PATH`` as before), in TrainConfig, DaggerConfig, pools and the
single-agent env."""

from __future__ import annotations

import json
import shutil

import pytest

from envs.errors import InvalidConfigError
from strategies.policies.model_files import zoo_dir
from training.config import load_config
from training.dagger import DaggerConfig
from training.pool import OpponentPool
from training.single_agent import SingleAgentEnv

EVADER = "zoo:ppo_evader_vs_greedy_open_room"
PURSUER = "zoo:ppo_pursuer_vs_straight_open_room"


def _zip_copy(tmp_path, name: str, provenance: bool = True):
    """A copy of a zoo model under tmp_path (with its provenance.json or without)."""
    src = zoo_dir() / name
    dst = tmp_path / name
    dst.mkdir()
    shutil.copy(src / "model.zip", dst / "model.zip")
    if provenance:
        shutil.copy(src / "provenance.json", dst / "provenance.json")
    return dst / "model.zip"


def test_a_train_config_takes_a_zoo_model_and_a_zip_and_keeps_the_name(tmp_path, tiny):
    path = _zip_copy(tmp_path, "ppo_evader_vs_greedy_open_room")
    cfg = tiny(opponent=(EVADER, str(path), "evader/straight"))
    assert cfg.opponent == (EVADER, str(path), "evader/straight")  # as the user wrote it
    out = tmp_path / "c.toml"
    out.write_text(cfg.to_toml())
    assert load_config(out) == cfg
    pool = cfg.opponent_policy()
    built = {pool.select(seed).name for seed in range(40)}
    assert f"evader/sb3:{zoo_dir() / 'ppo_evader_vs_greedy_open_room' / 'model.zip'}" in built
    assert f"evader/sb3:{path}" in built and "evader/straight" in built


def test_a_single_zoo_opponent_trains_and_its_name_is_the_provenances(tiny) -> None:
    from training.train import train

    result = train(tiny(opponent=EVADER, total_timesteps=64, checkpoint_freq=64))
    prov = json.loads((result.model_path.parent / "provenance.json").read_text())
    assert prov["opponent"] == EVADER and prov["config"]["opponent"] == EVADER
    assert result.evaluation.episodes == 2


@pytest.mark.parametrize(
    ("opponent", "match"),
    [
        ("zoo:nope", r"^opponent = 'zoo:nope': no zoo model 'nope'; known: \[.*'"),
        (PURSUER, r"trained as the pursuer .* cannot play the evader"),
        ("missing/model.zip", r"^opponent = 'missing/model.zip': no such file \("),
    ],
)
def test_a_bad_model_opponent_is_refused_naming_it(tiny, opponent, match) -> None:
    with pytest.raises(InvalidConfigError, match=match):
        tiny(opponent=opponent)


def test_a_zip_that_is_no_model_is_refused(tmp_path, tiny) -> None:
    notes = tmp_path / "notes.zip"
    notes.write_bytes(b"not a zip")
    with pytest.raises(InvalidConfigError, match="not a stable-baselines3 model zip"):
        tiny(opponent=str(notes))


def test_the_single_agent_env_takes_a_zoo_opponent() -> None:
    env = SingleAgentEnv("pursuer", EVADER, map="open_room", max_cycles=5)
    env.reset(seed=0)
    assert env.opponent.name.startswith("evader/sb3:") and env.opponent.roles == ("evader",)
    env.step(env.action_space.sample())
    with pytest.raises(InvalidConfigError, match="trained as the evader"):
        SingleAgentEnv("evader", EVADER, map="open_room")


def test_a_pool_learns_a_models_role_from_its_provenance_or_is_told(tmp_path) -> None:
    assert OpponentPool([EVADER, "evader/straight"]).role == "evader"
    with pytest.raises(InvalidConfigError, match="every member must play the evader"):
        OpponentPool(["evader/straight", PURSUER])
    bare = _zip_copy(tmp_path, "ppo_evader_vs_greedy_open_room", provenance=False)
    with pytest.raises(InvalidConfigError, match="cannot tell which role this model plays"):
        OpponentPool([str(bare)])
    pool = OpponentPool([str(bare)], role="evader")
    assert pool.select(0).name == f"evader/sb3:{bare}"


def test_a_dagger_config_takes_model_opponents(tmp_path) -> None:
    base = dict(role="pursuer", expert="pursuer/decomposition", output_dir=str(tmp_path))
    cfg = DaggerConfig(**base, opponent=[EVADER, "evader/straight"], validation_opponent=EVADER)
    assert cfg.pool == (EVADER, "evader/straight") and cfg.opponent_policy().role == "evader"
    one = DaggerConfig(**base, opponent=EVADER).opponent_policy()  # what run_episode is given
    assert one == f"evader/sb3:{zoo_dir() / 'ppo_evader_vs_greedy_open_room' / 'model.zip'}"
    with pytest.raises(InvalidConfigError, match="trained as the pursuer"):
        DaggerConfig(**base, opponent=PURSUER)
    with pytest.raises(InvalidConfigError, match="validation_opponent = 'zoo:nope': no zoo"):
        DaggerConfig(**base, opponent=EVADER, validation_opponent="zoo:nope")


def test_a_dagger_run_plays_a_zoo_opponent_in_training_and_validation(tmp_path) -> None:
    from training.dagger import dagger

    cfg = DaggerConfig(
        role="pursuer",
        expert="pursuer/greedy",
        opponent=EVADER,
        validation_opponent=EVADER,
        iterations=1,
        episodes=1,
        max_cycles=10,
        epochs=2,
        validation_episodes=1,
        output_dir=str(tmp_path / "run"),
    )
    r = dagger(cfg)
    assert r.samples[-1] > 0
    prov = json.loads((r.model_path.parent / "provenance.json").read_text())
    assert prov["opponent"] == EVADER


@pytest.mark.parametrize("learner_observation", ["state", "lidar"])
def test_a_model_opponent_sees_the_observation_it_was_trained_on(learner_observation) -> None:
    # The lidar-track generalists (most of the zoo) were given the learner's observation:
    # 'surveil train' of an evader on the state against zoo:dagger_pursuer_generalist failed
    # at its first step, "observation of shape (13,), but the model was trained on shape
    # (40,) (observation options {'observation': 'lidar_track', 'n_rays': 32})".
    env = SingleAgentEnv("evader", "zoo:dagger_pursuer_generalist", map="open_room",
                         max_cycles=30, observation=learner_observation)  # fmt: skip
    obs, _ = env.reset(seed=0)
    assert obs.shape == env.observation_space.shape
    assert env._opponent_obs.shape == (40,)  # lidar_track, 32 rays
    done, steps = False, 0
    while not done:
        obs, _, terminated, truncated, _ = env.step(env.action_space.sample())
        done, steps = terminated or truncated, steps + 1
        assert obs.shape == env.observation_space.shape
    assert steps > 1


def test_a_model_opponent_given_observations_of_another_shape_is_refused(tmp_path) -> None:
    # training (and python -m training.zoo evaluate --opponent) against a lidar model
    # without its provenance.json gave it the learner's state: InvalidObservationError at
    # the first step; now refused as the episode starts, before the model loads
    bare = _zip_copy(tmp_path, "dagger_pursuer_generalist", provenance=False)
    with pytest.warns(UserWarning, match="no provenance.json"):
        env = SingleAgentEnv("evader", str(bare), map="open_room", max_cycles=5)
    with pytest.raises(InvalidConfigError, match=r"takes observations of shape \(40,\), but "
                       r"the game's observation 'state' has shape \(13,\)"):  # fmt: skip
        env.reset(seed=0)
    assert env.opponent.model is None


def test_a_rerun_from_another_directory_plays_the_same_opponent_file(
    tmp_path, tiny, monkeypatch
) -> None:
    # config.toml kept a relative opponent path as written ('m/model.zip'): a rerun of
    # it from another directory looked for the file there (refused as no such file, or
    # trained on against another file of that name); now the run stores it absolute
    from training.train import train

    here, elsewhere = tmp_path / "here", tmp_path / "elsewhere"
    here.mkdir()
    elsewhere.mkdir()
    model = _zip_copy(here, "ppo_evader_vs_greedy_open_room")
    monkeypatch.chdir(here)
    relative = "ppo_evader_vs_greedy_open_room/model.zip"
    first = train(tiny(opponent=relative, total_timesteps=64, eval_episodes=0))
    monkeypatch.chdir(elsewhere)
    stored = load_config(first.model_path.parent / "config.toml", total_timesteps=128)
    assert stored.opponent == str(model)
    again = train(stored)
    assert again.resumed_from is not None and again.timesteps == 128
    prov = json.loads((again.model_path.parent / "provenance.json").read_text())
    assert prov["config"]["opponent"] == str(model)
    monkeypatch.chdir(here)  # the pools and DAgger's opponents alike
    base = dict(role="pursuer", expert="pursuer/decomposition", output_dir=str(tmp_path))
    cfg = DaggerConfig(**base, opponent=[relative, "evader/straight"],
                       validation_opponent=f"evader/sb3:{relative}")  # fmt: skip
    assert cfg.opponent == (str(model), "evader/straight")
    assert cfg.validation_opponent == f"evader/sb3:{model}"
    assert tiny(opponent=(relative, EVADER)).opponent == (str(model), EVADER)


def test_a_rerun_from_another_directory_plays_the_same_map_file(tmp_path, tiny, monkeypatch):
    # config.toml kept the opponent's model file absolute but a map file's path as written
    # ('f.json'): a rerun of it from another directory was refused ("map: f.json: no such
    # map file") or played a file of that name there; now the map's path is kept absolute
    # too (also under a transform, and in DAgger's maps, validation maps and curriculum)
    import numpy as np

    from envs.maps import Map
    from envs.maps.io import save_map
    from training.train import train

    here, elsewhere = tmp_path / "here", tmp_path / "elsewhere"
    here.mkdir()
    elsewhere.mkdir()
    square = np.array([[0.0, 0.0], [9.0, 0.0], [9.0, 9.0], [0.0, 9.0]])
    save_map(Map(square, [], name="f"), here / "f.json")
    monkeypatch.chdir(here)
    first = train(tiny(map="f.json", total_timesteps=64, eval_episodes=0))
    monkeypatch.chdir(elsewhere)
    stored = load_config(first.model_path.parent / "config.toml", total_timesteps=128)
    assert stored.map == str(here / "f.json")
    again = train(stored)
    assert again.resumed_from is not None and again.timesteps == 128
    monkeypatch.chdir(here)
    assert tiny(map=("f.json~x2", "corner", "random:3")).map == (
        f"{here / 'f.json'}~x2", "corner", "random:3")  # fmt: skip
    cfg = DaggerConfig(role="pursuer", expert="pursuer/decomposition",
                       opponent="evader/straight", maps=["f.json", "corner"],
                       validation_maps="f.json", output_dir=str(tmp_path),
                       curriculum=[{"iterations": 1, "maps": "f.json"}])  # fmt: skip
    absolute = str(here / "f.json")
    assert cfg.maps == (absolute, "corner") and cfg.validation_maps == (absolute,)
    assert cfg.curriculum[0]["maps"] == (absolute,)
