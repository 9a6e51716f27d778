"""What a learned policy sees when it is built from the ``"state"`` observation.

A learner trained by imitation (:mod:`training.dagger`) is labelled by an analytic expert
that reads the ``"state"`` vector, while the learner itself may see something else: the
lidar vector the env would have given it at that instant, plus, optionally, *analytic
features*, numbers an analytic policy computes from the map that no observation of the
env carries. :class:`LearnerInputs` builds that input from the state, the same way in
training (the DAgger rollout) and in play (:class:`~strategies.policies.learned.SB3Policy`),
so a model sees in play exactly what it was fitted on.

Features (``LEARNER_FEATURES``):

``"safety_table"``
    The decomposition pursuer's turn choice, digested into 5 numbers
    (:mod:`strategies.policies.table_features`). A pursuer-only feature: it needs the map's
    safety table (built once per map, as the decomposition pursuer builds it) and the
    evader's position in map coordinates. A model fed it is a learned policy *with
    analytic features*, not a replacement for the analytic one.

``"escape_plan"``
    The shooting evader's plan, digested into 11 numbers
    (:mod:`strategies.policies.plan_features`): whether the configuration's cell is
    escapable and its rank, the direction and distance to the crossing of its nearest via,
    the walk to a witness region and the best shooting candidate, in the frame of the line
    of sight. An evader-only feature: it needs the map's exact decomposition and the
    shooting evader's safety table (built once per map) and both positions in map
    coordinates.

``"escape_memory"``
    What the shooting evader with memory holds, digested into 11 numbers
    (:mod:`strategies.policies.memory_features`): the crossing it keeps and how long it
    has stalled, whether every crossing of its cell is excluded, the mode it decides in
    and the escape arc it follows. An evader-only feature, and *stateful*: a shadow
    shooting evader fed the episode's states decides at each. :meth:`LearnerInputs.reset`
    restarts it at each episode start, and the learner must then be called **once per
    step, in order** (as the DAgger rollout and :class:`~strategies.policies.learned.SB3Policy`
    do): a state skipped or repeated changes what follows.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from gymnasium.spaces import Box

from envs.errors import InvalidConfigError
from strategies.policies.memory_features import MEMORY_FEATURES, MemoryFeatures
from strategies.policies.plan_features import PLAN_FEATURES, PlanFeatures
from strategies.policies.table_features import FLOOR, TABLE_FEATURES, TableFeatures

__all__ = ["LEARNER_FEATURES", "LearnerInputs", "check_features"]


@dataclasses.dataclass(frozen=True)
class _Feature:
    make: Any  # the class computing it: make(config, <role>=expert) or make(config, **params)
    expert: str  # the analytic policy whose parameters (and tables) it is computed with
    low: float  # the range of its numbers (the learner's observation space)
    high: float
    size: int
    stateful: bool = False  # restart()ed at each episode start, called once per step


_FEATURES = {
    "safety_table": _Feature(TableFeatures, "pursuer/decomposition", FLOOR, -FLOOR,
                             len(TABLE_FEATURES)),
    "escape_plan": _Feature(PlanFeatures, "evader/shooting", -1.0, 1.0, len(PLAN_FEATURES)),
    "escape_memory": _Feature(MemoryFeatures, "evader/shooting", -1.0, 1.0,
                              len(MEMORY_FEATURES), stateful=True),
}  # fmt: skip

LEARNER_FEATURES: dict[str, int] = {name: f.size for name, f in _FEATURES.items()}
"""Analytic features a learner may be given, and how many numbers each adds."""


def check_features(features: Any, *, role: str, expert: str | None, where: str) -> tuple[str, ...]:
    """Validate a learner's ``features`` list; returns it as a tuple.

    Args:
        features: a sequence of names from :data:`LEARNER_FEATURES`.
        role: the learner's role.
        expert: the expert the features take their parameters from (``None``: no
            expert, e.g. PPO from scratch, where no feature applies).
        where: what to name in the error.

    Raises:
        InvalidConfigError: not a list of known names, a repeated name, or a feature
            that does not fit the role or the expert.
    """
    if isinstance(features, str) or not isinstance(features, Sequence):
        raise InvalidConfigError(
            f"{where}: features = {features!r}: expected a list of names from "
            f"{sorted(LEARNER_FEATURES)}"
        )
    out = tuple(features)
    for name in out:
        if name not in LEARNER_FEATURES:
            raise InvalidConfigError(
                f"{where}: features: unknown feature {name!r}; expected one of "
                f"{sorted(LEARNER_FEATURES)}"
            )
        need = _FEATURES[name].expert
        if expert != need or role != need.partition("/")[0]:
            raise InvalidConfigError(
                f"{where}: feature {name!r} is computed by the {need!r} expert for a "
                f"{need.partition('/')[0]} learner; this run has role = {role!r}, "
                f"expert = {expert!r}"
            )
    if len(set(out)) != len(out):
        raise InvalidConfigError(f"{where}: features = {list(out)!r} repeats a name")
    return out


class LearnerInputs:
    """Build a learner's input vector from the ``"state"`` observation.

    Args:
        observation: the learner's observation options (``{"observation": "state"}``,
            ``{"observation": "lidar_track", "n_rays": 32}``...), as the env takes them.
        features: names from :data:`LEARNER_FEATURES`, appended in this order.
        expert_params: the expert's parameters (the features are computed with them).
    """

    def __init__(
        self,
        observation: Mapping[str, Any] | None = None,
        features: Sequence[str] = (),
        expert_params: Mapping[str, Any] | None = None,
    ) -> None:
        self.observation = dict(observation or {"observation": "state"})
        self.features = tuple(features)
        self.expert_params = dict(expert_params or {})
        self._encoder: Any = None
        self._made: dict[str, Any] = {}  # feature name -> its TableFeatures / PlanFeatures
        self._config: Any = None
        self._role: str | None = None

    @property
    def n_features(self) -> int:
        """How many numbers the features add."""
        return sum(LEARNER_FEATURES[f] for f in self.features)

    def reset(self, config: Any, role: str, expert: Any = None) -> None:
        """Prepare for an episode on ``config``'s map (a ``"state"`` env's config).

        Args:
            config: the env's config.
            role: the learner's role.
            expert: the features' expert (a decomposition pursuer for ``"safety_table"``,
                a shooting evader for ``"escape_plan"``) already reset on this map with
                the expert's parameters, whose tables the features then reuse (only
                stateless methods: its actions are unchanged).
        """
        if config is not self._config or role != self._role:
            self._encoder = None
            if self.observation.get("observation", "state") != "state":
                from envs.geometry import kernel_for
                from envs.surveillance.observations import LidarEncoder

                lidar = dataclasses.replace(config, **self.observation)
                self._encoder = LidarEncoder(lidar, role, kernel_for(config.map))
            self._config, self._role = config, role
            self._made = {}
        for name in self.features:
            f = _FEATURES[name]
            if expert is not None:  # TableFeatures(config, pursuer=...), PlanFeatures(evader=)
                self._made[name] = f.make(config, **{f.expert.partition("/")[0]: expert})
            elif name not in self._made:
                self._made[name] = f.make(config, **self.expert_params)
            elif f.stateful:  # made for an earlier episode on this map: forget it
                self._made[name].restart()

    def __call__(self, state: np.ndarray) -> np.ndarray:
        """The learner's input (float32) at the ``"state"`` vector ``state``.

        With a stateful feature (``"escape_memory"``) call it once per step of the
        episode, in order: each call feeds the state to the feature's shadow policy.
        """
        if self._config is None:
            raise InvalidConfigError("LearnerInputs: call reset() before encoding a state")
        seen = np.asarray(state, dtype=np.float32)
        out = seen
        if self._encoder is not None:
            out = self._encoder.encode_state(seen, self._config, self._role)
        if self._made:
            out = np.concatenate([out, *(self._made[name](seen) for name in self.features)])
        return out

    def space(self, base: Box) -> Box:
        """``base`` (the learner's env observation space) with the features' bounds added."""
        if not self.features:
            return base
        feats = [_FEATURES[name] for name in self.features]
        lo = [np.full(f.size, f.low, np.float32) for f in feats]
        hi = [np.full(f.size, f.high, np.float32) for f in feats]
        return Box(
            np.concatenate([base.low, *lo]), np.concatenate([base.high, *hi]), dtype=np.float32
        )
