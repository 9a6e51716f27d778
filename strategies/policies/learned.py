"""Learned policies: a stable-baselines3 model zip behind the Policy protocol.

``make_policy("pursuer/sb3:models/ppo_pursuer.zip")`` builds an :class:`SB3Policy`; the
zip is loaded on the first :meth:`~SB3Policy.reset` (stable-baselines3 and torch are
imported only then). The algorithm is read from the zip's metadata unless given.
"""

from __future__ import annotations

import json
import zipfile
from pathlib import Path
from typing import Any

import numpy as np

from envs.errors import InvalidConfigError
from strategies.policies.base import BasePolicy

__all__ = ["SB3_ALGORITHMS", "SB3Policy"]

SB3_ALGORITHMS = ("A2C", "DDPG", "PPO", "SAC", "TD3")
"""Algorithms :class:`SB3Policy` can load (continuous actions)."""


def _algo_from_zip(path: Path) -> str:
    """The algorithm name recorded in an SB3 zip (its policy class's module path)."""
    try:
        with zipfile.ZipFile(path) as zf:
            data = json.loads(zf.read("data"))
    except (OSError, KeyError, zipfile.BadZipFile, json.JSONDecodeError) as exc:
        raise InvalidConfigError(f"{path}: not a stable-baselines3 model zip ({exc})") from exc
    text = json.dumps(data.get("policy_class", ""))
    for algo in SB3_ALGORITHMS:
        if f"stable_baselines3.{algo.lower()}." in text:
            return algo
    if "stable_baselines3.common.policies" in text:
        # PPO and A2C both save the shared ActorCriticPolicy; only PPO stores clip_range
        return "PPO" if "clip_range" in data else "A2C"
    raise InvalidConfigError(
        f"{path}: cannot tell the algorithm from the zip; pass algo= one of {SB3_ALGORITHMS}"
    )


class SB3Policy(BasePolicy):
    """A trained stable-baselines3 model playing one role.

    Args:
        path: the model zip.
        role: the role the model was trained for.
        algo: ``"PPO"``, ``"SAC"``... (``None``: read from the zip).
        deterministic: use the deterministic action.
    """

    uses_state = False

    def __init__(
        self,
        path: str | Path,
        *,
        role: str,
        algo: str | None = None,
        deterministic: bool = True,
        name: str | None = None,
    ) -> None:
        super().__init__(name=name or f"{role}/sb3:{path}")
        self.path = Path(path)
        self.roles = (role,)
        if algo is not None and algo.upper() not in SB3_ALGORITHMS:
            raise InvalidConfigError(f"algo must be one of {SB3_ALGORITHMS}, got {algo!r}")
        self.algo = algo.upper() if algo else None
        self.deterministic = bool(deterministic)
        self.model: Any = None

    def _reset(self) -> None:
        if self.model is None:
            if not self.path.is_file():
                raise InvalidConfigError(f"{self.name}: no model file at {self.path}")
            import stable_baselines3

            algo = self.algo or _algo_from_zip(self.path)
            self.model = getattr(stable_baselines3, algo).load(str(self.path), device="cpu")
        seed = int(self.rng.integers(2**31 - 1))
        self.model.set_random_seed(seed)

    def act(self, observation: np.ndarray) -> np.ndarray:
        """The model's action for one observation, clipped to [-1, 1]."""
        if self.role is None:
            raise InvalidConfigError(f"policy {self.name!r}: call reset() before act()")
        action, _ = self.model.predict(np.asarray(observation), deterministic=self.deterministic)
        return np.clip(np.asarray(action, dtype=np.float32), -1.0, 1.0)
