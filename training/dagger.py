"""DAgger on stable-baselines3: imitate an analytic expert, the result an ordinary SB3 model.

Dataset aggregation (Ross, Gordon and Bagnell, 2011): roll out a mixture of the expert and
the learner (the expert acts with probability ``beta_i = beta ** i`` at iteration ``i``, so
iteration 0 is the expert alone), label every visited observation with the expert's action,
add it to the dataset, and fit the learner to the whole dataset by supervised regression.
The learner visits its own mistakes and is told what the expert would have done there,
which plain behaviour cloning never shows it.

Rollouts go through the shared episode runner (:func:`strategies.runner.run_episode`); the
learner is the policy network of an SB3 PPO model (``MlpPolicy``), fitted by mean squared
error between its action mean and the expert's action, so the result loads and plays like
any trained model (``ROLE/sb3:PATH``) and can be fine-tuned by PPO. Both read the
``"state"`` observation (the analytic experts need it; a lidar learner needs the expert to
label from the env's state, which this first version does not do).

The disagreement, the mean distance between the learner's and the expert's actions on the
states the learner's own rollouts visit, is recorded per iteration: DAgger's progress
measure, and what a test checks falls.

Example::

    from training.dagger import DaggerConfig, dagger
    result = dagger(DaggerConfig(role="pursuer", expert="pursuer/decomposition",
                                 opponent="evader/shooting", maps=("corridor",),
                                 output_dir="out/dagger/pursuer"))
    print(result.disagreement)  # one value per iteration, falling
"""

from __future__ import annotations

import json
import os
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from envs import validation
from envs.errors import InvalidConfigError
from strategies.policies import make_policy
from strategies.policies.base import check_role
from strategies.runner import run_episode

__all__ = ["DaggerConfig", "DaggerResult", "dagger"]


@dataclass(frozen=True)
class DaggerConfig:
    """One DAgger run: a role imitating an expert against a fixed opponent."""

    role: str
    expert: str
    opponent: str
    maps: tuple[str, ...] = ("open_room",)
    env: dict[str, Any] = field(default_factory=dict)
    iterations: int = 5
    episodes: int = 4
    max_cycles: int = 300
    beta: float = 0.5
    start: str = "valid"
    net_arch: tuple[int, ...] = (64, 64)
    epochs: int = 30
    batch_size: int = 256
    learning_rate: float = 1e-3
    seed: int = 0
    output_dir: str = "out/dagger"

    def __post_init__(self) -> None:
        where = "DaggerConfig"
        check_role(self.role)
        for name in ("expert", "opponent", "output_dir", "start"):
            validation.string(name, getattr(self, name), where=where)
        if not self.expert.startswith(self.role + "/"):
            raise InvalidConfigError(
                f"{where}: expert = {self.expert!r} does not play the {self.role}"
            )
        if not self.maps or not all(isinstance(m, str) and m for m in self.maps):
            raise InvalidConfigError(f"{where}: maps = {self.maps!r}: expected map names or files")
        validation.mapping("env", self.env, where=where)
        for name, lo in (("iterations", 1), ("episodes", 1), ("max_cycles", 1), ("epochs", 1),
                         ("batch_size", 1), ("seed", 0)):  # fmt: skip
            validation.integer(name, getattr(self, name), minimum=lo, where=where)
        validation.unit_interval("beta", self.beta, where=where, open=False)
        validation.positive("learning_rate", self.learning_rate, where=where)
        for i, n in enumerate(self.net_arch):
            validation.integer(f"net_arch[{i}]", n, minimum=1, where=where)


@dataclass
class DaggerResult:
    """What :func:`dagger` produced.

    Attributes:
        model_path: the SB3 PPO zip (with ``provenance.json`` beside it).
        disagreement: per iteration, the mean |learner - expert| action distance on the
            states visited that iteration (measured before refitting).
        samples: dataset size after each iteration.
        held: per iteration, the share of episodes the learner's role won.
        wall_seconds: total time.
        fit_error: per iteration, the mean |learner - expert| on the whole dataset after
            the fit (how well the network imitates what it was shown).
    """

    model_path: Path
    disagreement: list[float]
    samples: list[int]
    held: list[float]
    wall_seconds: float
    fit_error: list[float] = field(default_factory=list)


class _Rollout:
    """The policy that plays during a DAgger rollout: expert or learner, step by step.

    Both see every step (the expert keeps its internal state in sync); the action taken is
    the expert's with probability ``beta``; every observation is stored with the expert's
    action (its label) and the learner's (for the disagreement).
    """

    uses_state = True

    def __init__(self, expert, model, beta: float, seed: int) -> None:
        self.expert, self.model, self.beta = expert, model, beta
        self.rng = np.random.default_rng(seed)
        self.name = f"dagger({expert.name})"
        self.obs: list[np.ndarray] = []
        self.labels: list[np.ndarray] = []
        self.learned: list[np.ndarray] = []

    @property
    def roles(self):
        return self.expert.roles

    @property
    def role(self):
        return self.expert.role

    def reset(self, **kwargs):
        return self.expert.reset(**kwargs)

    def act(self, observation):
        label = np.asarray(self.expert.act(observation), dtype=np.float32)
        own, _ = self.model.predict(np.asarray(observation), deterministic=True)
        own = np.clip(np.asarray(own, dtype=np.float32), -1.0, 1.0)
        self.obs.append(np.asarray(observation, dtype=np.float32))
        self.labels.append(label)
        self.learned.append(own)
        return label if self.rng.random() < self.beta else own

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        return self.act(observation), state


def _fit(model, obs: np.ndarray, act: np.ndarray, cfg: DaggerConfig, rng) -> float:
    """Regress the policy's action mean onto the expert's actions (MSE); returns the loss."""
    import torch

    policy = model.policy
    opt = torch.optim.Adam(policy.parameters(), lr=cfg.learning_rate)
    x_all = torch.as_tensor(obs)
    y_all = torch.as_tensor(act)
    loss_value = float("nan")
    for _ in range(cfg.epochs):
        order = rng.permutation(len(obs))
        for s in range(0, len(order), cfg.batch_size):
            idx = torch.as_tensor(order[s : s + cfg.batch_size])
            dist = policy.get_distribution(x_all[idx])
            loss = torch.nn.functional.mse_loss(dist.distribution.mean, y_all[idx])
            opt.zero_grad()
            loss.backward()
            opt.step()
            loss_value = float(loss.detach())
    return loss_value


def dagger(cfg: DaggerConfig) -> DaggerResult:
    """Run DAgger; writes ``model.zip`` and ``provenance.json`` to ``cfg.output_dir``.

    Raises:
        InvalidConfigError: bad names, maps or env parameters (before any rollout).
    """
    import torch
    from stable_baselines3 import PPO

    from training.single_agent import SingleAgentEnv

    t0 = time.perf_counter()
    torch.manual_seed(cfg.seed)
    torch.set_num_threads(1)
    other = "evader" if cfg.role == "pursuer" else "pursuer"
    if not cfg.opponent.startswith(other + "/"):
        raise InvalidConfigError(f"DaggerConfig: opponent = {cfg.opponent!r} must play the {other}")
    env = SingleAgentEnv(cfg.role, cfg.opponent, map=cfg.maps[0], observation="state", **cfg.env)
    model = PPO(
        "MlpPolicy",
        env,
        policy_kwargs={"net_arch": list(cfg.net_arch)},
        seed=cfg.seed,
        device="cpu",
        verbose=0,
    )
    rng = np.random.default_rng(cfg.seed)
    data_obs: list[np.ndarray] = []
    data_act: list[np.ndarray] = []
    disagreement, samples, held, fit_loss = [], [], [], []
    for it in range(cfg.iterations):
        beta = cfg.beta**it
        wins, seen_l, seen_e = 0, [], []
        for ep in range(cfg.episodes):
            seed = cfg.seed * 100_003 + it * 1_009 + ep
            world = cfg.maps[(it * cfg.episodes + ep) % len(cfg.maps)]
            roll = _Rollout(make_policy(cfg.expert), model, beta, seed)
            pair = {cfg.role: roll, other: cfg.opponent}
            r = run_episode(world, pair["pursuer"], pair["evader"], seed, max_cycles=cfg.max_cycles,
                            overrides=cfg.env, start=cfg.start)  # fmt: skip
            wins += r.winner == cfg.role
            data_obs.extend(roll.obs)
            data_act.extend(roll.labels)
            seen_l.extend(roll.learned)
            seen_e.extend(roll.labels)
        d = np.linalg.norm(np.asarray(seen_l) - np.asarray(seen_e), axis=1)
        disagreement.append(float(d.mean()) if len(d) else float("nan"))
        held.append(wins / cfg.episodes)
        X, Y = np.asarray(data_obs), np.clip(np.asarray(data_act), -1, 1)
        _fit(model, X, Y, cfg, rng)
        pred, _ = model.predict(X, deterministic=True)
        fit_loss.append(float(np.linalg.norm(np.clip(pred, -1, 1) - Y, axis=1).mean()))
        samples.append(len(data_obs))
    out = Path(cfg.output_dir)
    out.mkdir(parents=True, exist_ok=True)
    model_path = out / "model.zip"
    tmp = out / "model.zip.tmp"
    model.save(str(tmp))
    os.replace(tmp, model_path)
    wall = time.perf_counter() - t0
    provenance = {
        "role": cfg.role,
        "opponent": cfg.opponent,
        "algo": "ppo",
        "method": "dagger",
        "expert": cfg.expert,
        "config": {k: (list(v) if isinstance(v, tuple) else v) for k, v in asdict(cfg).items()},
        "env_config": env.config.to_dict(),
        "disagreement": disagreement,
        "samples": samples,
        "held": held,
        "wall_seconds": round(wall, 3),
    }
    (out / "provenance.json").write_text(json.dumps(provenance, indent=2) + "\n")
    env.close()
    return DaggerResult(model_path, disagreement, samples, held, wall, fit_loss)
