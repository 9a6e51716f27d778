"""What the decomposition pursuer decides its turn from, as features for a learner (issue 9).

The decomposition pursuer (:mod:`strategies.policies.decomposition`, Secs. 4-5) turns the rod
toward the orientation bin that maximises ``V(theta) - turn penalty`` among the bins it can
reach by turning through free orientations, counter-clockwise or clockwise from its current
bin. ``V`` (eqs. 2-3) comes from the safety table over the whole map, so lidar alone does not
carry it, and a learner imitating the pursuer from lidar turns the wrong way round in about
a fifth of its turns (issue 9). These features give the learner that choice, digested: per
direction, the best score and how far round it lies:

=============== ==============================================================================
feature         meaning
=============== ==============================================================================
best_ccw        max over bins reachable counter-clockwise of ``(V - hysteresis turn / omega)``
                over the horizon ``pi / omega``, clipped to [-1.5, 1.5] (``FLOOR``: none)
steps_ccw       the rotation to that bin, in bins over ``n_bins / 2``, clipped to [0, 1]
best_cw         as best_ccw, clockwise
steps_cw        as steps_ccw, clockwise
ccw_better      sign(best_ccw - best_cw) (0 on a tie)
=============== ==============================================================================

A learner fed these is a learned policy with analytic features: it needs the map's safety
table and the evader's position in map coordinates, and each step costs one
:meth:`~strategies.policies.decomposition.DecompositionPursuer.orientation_values` call. The
last-target tie-break of the pursuer (its hidden state) is left out.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from envs.errors import InvalidConfigError
from strategies.policies.decomposition import DecompositionPursuer, reachable_steps
from strategies.policies.observe import read_state

__all__ = ["FLOOR", "TABLE_FEATURES", "TableFeatures"]

TABLE_FEATURES = ("best_ccw", "steps_ccw", "best_cw", "steps_cw", "ccw_better")
"""The features, in order."""

FLOOR = -1.5
"""``best_*`` where no bin is reachable that way (and the clip of the scores)."""


class TableFeatures:
    """The :data:`TABLE_FEATURES` of ``"state"`` observations on one map.

    Args:
        config: the env's ``EnvConfig`` (its map, L range and speeds).
        pursuer: a :class:`DecompositionPursuer` already reset on this map, whose table
            and parameters to use (``None``: build one from ``expert_params``).
        **expert_params: the decomposition pursuer's parameters (the expert's: its
            ``range_margin`` sets the rod length of the table).
    """

    def __init__(
        self, config: Any, pursuer: DecompositionPursuer | None = None, **expert_params: Any
    ) -> None:
        if pursuer is None:
            pursuer = DecompositionPursuer(**expert_params)
            pursuer.reset(role="pursuer", map=config.map, config=config, seed=0)
        elif expert_params:
            raise InvalidConfigError("TableFeatures: pass a pursuer or its parameters, not both")
        self.pursuer = pursuer
        self.config = config
        self._inv_horizon = 1.0 / self.pursuer.horizon

    def __call__(self, state: np.ndarray) -> np.ndarray:
        """The (5,) float32 features at a ``"state"`` observation."""
        evader, pursuer, _, _ = read_state(state, self.config)
        p = self.pursuer
        tab = p.table
        out = np.array([FLOOR, 0.0, FLOOR, 0.0, 0.0], dtype=np.float32)
        row = tab.row(evader)
        if row < 0:
            return out
        rod = pursuer - evader
        b0 = tab.bin_of(math.atan2(float(rod[1]), float(rod[0])))
        value = p.orientation_values(evader)
        nb = tab.n_bins
        for k, (steps, sign) in enumerate(
            zip(reachable_steps(tab.free[row], b0), (1, -1), strict=True)
        ):
            if steps.size:
                score = (
                    value[(b0 + sign * steps) % nb] - p._turn_penalty[steps]
                ) * self._inv_horizon
                j = int(np.argmax(score))
                out[2 * k] = min(max(float(score[j]), FLOOR), -FLOOR)
                out[2 * k + 1] = min(float(steps[j]) / (nb / 2), 1.0)
        if out[0] != out[2]:
            out[4] = 1.0 if out[0] > out[2] else -1.0
        return out
