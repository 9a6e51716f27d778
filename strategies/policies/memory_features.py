"""What the shooting evader remembers, as features for a learner (issue 9).

The shooting evader (:mod:`strategies.policies.shooting`) keeps a memory on the way: the
crossing it heads for (kept while the cell stays the same), the crossings it excluded after
a stall (10 steps without getting closer) or a cycle of cells, and the escape arc it
follows for ``replan`` steps. :mod:`strategies.policies.plan_features` describes the plan a
*fresh* evader would pick from the state alone; the evader with memory escapes more (20
safe starts vs the decomposition pursuer, office 0.65 with memory, 0.25 without), and on
the states of its rollouts it keeps another crossing than a fresh one in 20 % of its plan
steps and has excluded every crossing of the cell in all its pressure steps. That memory
depends on the whole episode, not on the state.

These features come from a *shadow*: a shooting evader with memory, fed every state of
the episode once, in order (it decides at each, and its decision is thrown away). Fed the
same states as the labeller (the shooting evader with memory, which in a DAgger rollout
sees every state, whoever steers), it holds the same memory, so what the labeller does
because of its memory (a crossing given up after a stall while the learner steered, a
charge at the pursuer) is shown to the learner. The features are the shadow's memory
after its decision at the state, in the frame of the line of sight as
:data:`~strategies.policies.plan_features.PLAN_FEATURES` (``(d . u, d . n)``):

=============== ==============================================================================
feature         meaning
=============== ==============================================================================
kept_u          direction to the crossing the evader keeps (the target just across the
kept_n          piece, :meth:`~strategies.policies.escape_plan.EscapePlan.witness`; 0, 0 where
                it keeps none)
kept_dist       distance to it over L_max, clipped to [0, 1] (1 where it keeps none)
stall           steps without getting closer to it over the stall limit (10), in [0, 1]
all_excluded    1: the evader's cell is escapable but every crossing is excluded or
                unreachable (no plan: it shoots, walks to a region or presses), 0 otherwise
plan            1 in the mode the evader decided in at this state, 0 in the others
shoot           (``start`` and ``toward``, rho > 1: all 0)
region
pressure
arc_u           direction to the end of the escape arc it follows at the next step (its
arc_n           shooting candidate, kept for ``replan`` steps; 0, 0 where none)
=============== ==============================================================================

Not a feature: the pressure time so far, after which the evader herds the pursuer into a
corner instead of charging it (``ShootingEvader.HERD_AFTER`` D / V_e; issue 13). The
shipped ``training/zoo/models/dagger_evader_memory`` was trained on these 11 numbers, so a
12th would change its observation size; a learner given these features does not see when
the expert's charge turns into a herd (the ``pressure`` mode covers both). Nor whether it
shoots before the plan, as it does from a dead end of the plan until a shot has no
candidate or its cell's rank is a guarantee (``ShootingEvader._shoot_first``; the ``shoot``
mode shows the shots).

Stateful: call :meth:`MemoryFeatures.restart` at each episode start and the features once
per step, in order (:class:`~strategies.policies.learner_inputs.LearnerInputs` does both).
Each call costs one shooting decision.
"""

from __future__ import annotations

import copy
import math
from typing import Any

import numpy as np

from envs.errors import InvalidConfigError
from strategies.policies.observe import read_state
from strategies.policies.plan_features import line_of_sight_frame
from strategies.policies.shooting import ShootingEvader

__all__ = ["MEMORY_FEATURES", "MemoryFeatures"]

MEMORY_FEATURES = (
    "kept_u",
    "kept_n",
    "kept_dist",
    "stall",
    "all_excluded",
    "plan",
    "shoot",
    "region",
    "pressure",
    "arc_u",
    "arc_n",
)
"""The features, in order (all in [-1, 1])."""

_MODES = ("plan", "shoot", "region", "pressure")


class MemoryFeatures:
    """The :data:`MEMORY_FEATURES` of the ``"state"`` observations of one episode.

    Args:
        config: the env's ``EnvConfig``.
        evader: a :class:`ShootingEvader` already reset on this map, whose tables the
            shadow shares (``None``: build the shadow from ``expert_params``). It is
            copied, never called: its actions are unchanged.
        **expert_params: the shooting evader's parameters (the expert's). The shadow
            keeps its memory whatever ``memory`` says.
    """

    def __init__(
        self, config: Any, evader: ShootingEvader | None = None, **expert_params: Any
    ) -> None:
        if evader is None:
            evader = ShootingEvader(**{**expert_params, "memory": True})
            evader.reset(role="evader", map=config.map, config=config, seed=0)
        elif expert_params:
            raise InvalidConfigError("MemoryFeatures: pass an evader or its parameters, not both")
        # a shallow copy shares the map's tables (read only); restart() gives it its own
        # memory
        self.shadow = copy.copy(evader)
        self.shadow.memory = True
        self.config = config
        self.restart()

    def restart(self) -> None:
        """Forget the episode: the shadow as :meth:`ShootingEvader.reset` leaves it."""
        self.shadow.restart()

    def __call__(self, state: np.ndarray) -> np.ndarray:
        """The (11,) float32 features after the shadow's decision at ``state`` (the next
        state of the episode)."""
        sh = self.shadow
        sh.act(state)
        out = np.zeros(len(MEMORY_FEATURES), dtype=np.float32)
        out[2] = 1.0
        e, p, _, _ = read_state(state, self.config)
        rod = p - e
        dist = math.hypot(float(rod[0]), float(rod[1]))
        if sh.mode in _MODES:
            out[5 + _MODES.index(sh.mode)] = 1.0
        if dist <= 0.0:
            return out
        u = rod / dist

        w = sh._witness
        if w is not None:
            to = w.target - e
            out[0], out[1] = line_of_sight_frame(to, u)
            out[2] = min(math.hypot(float(to[0]), float(to[1])) / self.config.l_max, 1.0)
            out[3] = min(sh._stall / sh.STALL_STEPS, 1.0)
        cell = sh._plan_cell
        if w is None and cell >= 0 and int(sh.plan.rank[cell]) >= 0:
            out[4] = 1.0
        if sh._arc is not None and sh._arc_age < sh.replan:
            out[9], out[10] = line_of_sight_frame(sh._arc[2][-1] - e, u)
        return out
