"""Memory features (issue 9): the shadow fed the episode's states holds the memory of the
labeller fed the same states, whoever steers; reset forgets it."""

from __future__ import annotations

import numpy as np
import pytest

from strategies.policies import make_policy
from strategies.policies.learner_inputs import LearnerInputs
from strategies.policies.memory_features import MEMORY_FEATURES
from strategies.policies.shooting import ShootingEvader
from strategies.runner import run_episode


class _Labelled:
    """A DAgger-like evader: the shooting evader (with memory) labels every state, and a
    random heading is played instead on a third of the steps; the inputs are built from
    each state once, after the label (as training.dagger._Rollout does)."""

    uses_state = True
    roles = ("evader",)
    name = "labelled"

    def __init__(self, seed: int) -> None:
        self.expert = ShootingEvader()
        self.inputs = LearnerInputs({"observation": "state"}, ("escape_memory",))
        self.rng = np.random.default_rng(seed)
        self.feats: list[np.ndarray] = []
        self.states: list[np.ndarray] = []
        self.memories: list[tuple] = []
        self.actions: list[tuple[np.ndarray, np.ndarray]] = []

    @property
    def role(self):
        return self.expert.role

    def reset(self, *, role, map, config, seed):
        self.expert.reset(role=role, map=map, config=config, seed=seed)
        self.inputs.reset(config, role, expert=self.expert)

    def act(self, obs):
        label = self.expert.act(obs)
        shadow = self.inputs._made["escape_memory"].shadow
        self.feats.append(self.inputs(obs)[len(obs) :])
        self.states.append(np.array(obs))
        self.memories.append((_memory(self.expert), _memory(shadow)))
        self.actions.append(label)
        if self.rng.random() < 1 / 3:
            a = self.rng.uniform(-np.pi, np.pi)
            return np.array([np.cos(a), np.sin(a)], dtype=np.float32)
        return label

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        return self.act(observation), state


def _memory(ev: ShootingEvader) -> tuple:
    w = ev._witness
    arc = None if ev._arc is None else (ev._arc_age, ev._arc[2].tobytes())
    return (
        ev.mode,
        ev._plan_cell,
        None if w is None else (w.boundary, w.target.tobytes()),
        {k: sorted(v) for k, v in ev._excluded.items()},
        ev._stall,
        list(ev._trail),
        ev._came_through,
        arc,
    )


@pytest.fixture(scope="module")
def office_run():
    ev = _Labelled(seed=3)
    r = run_episode("office", "pursuer/decomposition", ev, 2, max_cycles=200, start="safe")
    return ev, r


def test_the_shadow_holds_the_labellers_memory_whoever_steers(office_run):
    ev, r = office_run
    assert len(ev.memories) == r.steps > 50
    for k, (expert, shadow) in enumerate(ev.memories):
        assert expert == shadow, k
    modes = {m[0][0] for m in ev.memories}
    assert {"plan", "pressure"} <= modes, modes
    f = np.asarray(ev.feats)
    assert f.shape == (r.steps, len(MEMORY_FEATURES)) and np.all(np.abs(f) <= 1.0)
    # one mode at a time, the one the labeller decided in
    assert np.all(f[:, 5:9].sum(axis=1) <= 1.0)
    for k, (expert, _) in enumerate(ev.memories):
        if expert[0] in ("plan", "shoot", "region", "pressure"):
            assert f[k, 5 + ("plan", "shoot", "region", "pressure").index(expert[0])] == 1.0
        kept = expert[2] is not None
        assert (f[k, 0:2] != 0).any() == kept and (f[k, 2] < 1.0) == kept, k
    # the memory shows: a stall counted, or every crossing of an escapable cell excluded
    assert f[:, 3].max() > 0.0 or f[:, 4].max() == 1.0


def test_reset_forgets_the_episode(office_run):
    """In play (no expert given) the shadow is made once per map and restarted at each
    episode: replaying the episode's states gives the same features both times, and the
    same as the shadow sharing the labeller's tables in training."""
    ev, _ = office_run
    config = ev.expert.config
    inputs = LearnerInputs({"observation": "state"}, ("escape_memory",))
    for _ in range(2):
        inputs.reset(config, "evader")
        shadow = inputs._made["escape_memory"].shadow
        assert shadow.mode == "start" and not shadow._excluded and shadow._witness is None
        got = np.asarray([inputs(s)[len(s) :] for s in ev.states])
        assert np.array_equal(got, np.asarray(ev.feats))
    # without the restart, the second pass would start from the first pass's memory
    inputs._made["escape_memory"].shadow._excluded.setdefault(0, set()).add(0)
    inputs.reset(config, "evader")
    assert not inputs._made["escape_memory"].shadow._excluded


def test_the_shadow_keeps_its_memory_whatever_the_experts_parameters():
    """A labeller without memory (the escape_plan recipe) still gives a shadow with memory;
    the labeller's own actions are unchanged by the shadow."""
    p = make_policy("evader/shooting", memory=False)
    inputs = LearnerInputs({"observation": "state"}, ("escape_memory",), {"memory": False})
    from strategies.runner import build_env

    config = build_env("two_rooms", {}).config
    p.reset(role="evader", map=config.map, config=config, seed=0)
    inputs.reset(config, "evader", expert=p)
    assert inputs._made["escape_memory"].shadow.memory and not p.memory
    inputs.reset(config, "evader")
    assert inputs._made["escape_memory"].shadow.memory
