"""PPO fine-tuning of a cloned (DAgger/BC) policy that does not forget what it was taught.

Plain PPO started from a behaviour-cloned actor tends to collapse: its critic starts at random,
so the first advantages are noise and the first policy updates undo the cloning. Two standard
remedies, both here:

* **critic warm-up**: for the first ``critic_warmup`` rollouts only the value head (and the
  value branch of the MLP extractor) is fitted to the rollout returns; the actor is frozen;
* **a decaying behaviour-cloning term**: after each PPO update, ``bc_steps`` gradient steps
  of ``bc_coef * bc_decay**k`` times the MSE between the actor's action mean and the expert's
  labels on the DAgger dataset (``k`` the update's index), so the pull towards the expert
  fades as the policy improves on its own reward.

The result is an ordinary SB3 ``PPO`` model (saved and loaded as one).
"""

from __future__ import annotations

import os

import numpy as np
from stable_baselines3 import PPO

from envs import validation
from envs.errors import InvalidConfigError

__all__ = ["BCRegularisedPPO", "from_cloned", "model_inputs"]


class BCRegularisedPPO(PPO):
    """PPO with a critic warm-up and a decaying behaviour-cloning term.

    Args:
        *args: as :class:`stable_baselines3.PPO`.
        bc_obs: observations of the cloning dataset (``(n, obs_dim)``), or None for no BC.
        bc_act: the expert's actions on them (``(n, act_dim)``, in [-1, 1]).
        bc_coef: weight of the BC term at the first update.
        bc_decay: factor applied to the weight after every update (0 < bc_decay <= 1).
        bc_steps: BC gradient steps after each PPO update.
        critic_warmup: number of first rollouts during which only the critic learns.
        **kwargs: as :class:`stable_baselines3.PPO`.
    """

    def __init__(self, *args, bc_obs=None, bc_act=None, bc_coef: float = 1.0,
                 bc_decay: float = 0.7, bc_steps: int = 20, critic_warmup: int = 1,
                 **kwargs) -> None:  # fmt: skip
        where = "BCRegularisedPPO"
        validation.nonnegative("bc_coef", bc_coef, where=where)
        validation.unit_interval("bc_decay", bc_decay, where=where, open=False)
        validation.integer("bc_steps", bc_steps, minimum=0, where=where)
        validation.integer("critic_warmup", critic_warmup, minimum=0, where=where)
        self.bc_coef, self.bc_decay, self.bc_steps = float(bc_coef), float(bc_decay), bc_steps
        self.critic_warmup = critic_warmup
        self._bc_obs = None if bc_obs is None else np.asarray(bc_obs, dtype=np.float32)
        self._bc_act = None if bc_act is None else np.clip(np.asarray(bc_act, np.float32), -1, 1)
        self._rollouts_trained = 0
        self.bc_weights: list[float] = []
        super().__init__(*args, **kwargs)

    def _excluded_save_params(self) -> list[str]:
        return [*super()._excluded_save_params(), "_bc_obs", "_bc_act"]

    def _critic_parameters(self):
        p = self.policy
        params = list(p.value_net.parameters())
        params += list(p.mlp_extractor.value_net.parameters())
        if not p.share_features_extractor:
            params += list(p.vf_features_extractor.parameters())
        return params

    def _train_critic_only(self) -> None:
        import torch

        self.policy.set_training_mode(True)
        opt = torch.optim.Adam(self._critic_parameters(), lr=self.lr_schedule(1.0))
        for _ in range(self.n_epochs):
            for batch in self.rollout_buffer.get(self.batch_size):
                values = self.policy.predict_values(batch.observations).flatten()
                loss = torch.nn.functional.mse_loss(batch.returns, values)
                opt.zero_grad()
                loss.backward()
                opt.step()
        self.policy.set_training_mode(False)

    def _bc_step(self, weight: float) -> None:
        import torch

        if self._bc_obs is None or self.bc_steps == 0 or weight == 0.0:
            return
        self.policy.set_training_mode(True)
        rng = np.random.default_rng(self._rollouts_trained)
        n = len(self._bc_obs)
        for _ in range(self.bc_steps):
            idx = rng.integers(0, n, size=min(self.batch_size, n))
            x = torch.as_tensor(self._bc_obs[idx], device=self.device)
            y = torch.as_tensor(self._bc_act[idx], device=self.device)
            mean = self.policy.get_distribution(x).distribution.mean
            loss = weight * torch.nn.functional.mse_loss(mean, y)
            self.policy.optimizer.zero_grad()
            loss.backward()
            self.policy.optimizer.step()
        self.policy.set_training_mode(False)

    def train(self) -> None:
        """One update: critic only during the warm-up, else PPO then the decayed BC term."""
        if self._rollouts_trained < self.critic_warmup:
            self._train_critic_only()
            self.bc_weights.append(0.0)
        else:
            super().train()
            k = self._rollouts_trained - self.critic_warmup
            weight = self.bc_coef * self.bc_decay**k
            self._bc_step(weight)
            self.bc_weights.append(weight)
        self._rollouts_trained += 1


def from_cloned(path, env, **kwargs) -> BCRegularisedPPO:
    """A :class:`BCRegularisedPPO` on ``env`` whose policy starts as the SB3 PPO zip at ``path``.

    Only the policy's weights are copied (no optimizer state, no schedules); ``kwargs`` go to
    :class:`BCRegularisedPPO` (``bc_obs``, ``bc_act``, ``n_steps``, ``learning_rate``...).
    """
    old = PPO.load(str(path), device="cpu")
    want, got = old.observation_space.shape, env.observation_space.shape
    if want != got:
        raise InvalidConfigError(
            f"from_cloned: the model {os.fspath(path)!r} reads observations of shape {want}, "
            f"the env gives {got}; fine-tune on an env with the observation the model was "
            "trained on (a model trained with analytic features, DaggerConfig.features, "
            "reads more than any env observation: pass SingleAgentEnv(..., "
            "inputs=model_inputs(path, role)))"
        )
    kwargs.setdefault("policy_kwargs", old.policy_kwargs)
    new = BCRegularisedPPO("MlpPolicy", env, device="cpu", **kwargs)
    new.policy.load_state_dict(old.policy.state_dict())
    return new


def model_inputs(path, role: str):
    """The :class:`~strategies.policies.learner_inputs.LearnerInputs` of the model zip at
    ``path`` (from the ``provenance.json`` beside it), or ``None`` for a model that reads
    the env's own observation. Give them to :class:`training.single_agent.SingleAgentEnv`
    (``inputs=``) to fine-tune or evaluate a model trained with analytic features.

    Raises:
        InvalidConfigError: the provenance names another role or unknown features.
    """
    from strategies.policies.learned import SB3Policy

    return SB3Policy(path, role=role).inputs
