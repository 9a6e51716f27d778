"""What the shooting evader decides from, as features for a learner (issue 9).

The shooting evader (:mod:`strategies.policies.shooting`, Secs. 4-6) heads where a
whole-map plan says: in an escapable cell of the exact decomposition K_L, to the crossing
of one of the cell's vias (:mod:`strategies.policies.escape_plan`); else along a shooting
arc to the candidate endpoint with the best escape margin (the safety table, eq. 6); else
toward a witness region (Prop. 2); else it presses on the pursuer. The cell, its rank and
vias, and the table come from the whole map, so lidar alone does not carry them, and a
lidar learner imitating the evader does not know where the crossing lies (issue 9). These
features give the learner the plan, digested. Directions are in the evader's frame along
the line of sight: ``(d . u, d . n)`` for a unit direction ``d``, with ``u`` the unit
vector from the evader to the pursuer (eq. 1's orientation theta) and ``n`` ``u`` turned
a quarter counter-clockwise:

=============== ==============================================================================
feature         meaning
=============== ==============================================================================
escapable       +1: the configuration's cell of K_L is escapable; -1: it is not; 0: no cell
                is identified (on a critical curve, or the rod is not free)
closeness       ``1 / (1 + rank)`` of an escapable cell (1 at rank 0: one crossing breaks
                surveillance), 0 otherwise
cross_u         direction to the crossing point just across the nearest usable via
cross_n         (:meth:`~strategies.policies.escape_plan.EscapePlan.witness`, chosen as the
                evader chooses a fresh one; 0, 0 where there is none)
cross_dist      distance to that point over L_max, clipped to [0, 1] (1 where there is none)
region_u        direction to the next grid point of the walk to a witness region, where
region_n        the evader is outside one (its grid point and its cell's region) and the
                walk exists (0, 0 otherwise)
shot_u          direction to the shooting candidate with the largest positive escape margin
shot_n          (0, 0 where none has a positive margin); on a rod longer than the pursuer
                can close to L_min in a replan period, the one the evader's disc can follow
                with the largest margin against the rod's length where the evader shoots
                there (before a plan; with no plan, where no candidate has a margin at
                L_min's rate)
shot_margin     that margin (radians the pursuer lacks, eq. 6 or its reach) over pi,
                clipped to [0, 1]
shot_branch     the way the pursuer would turn there: +1 counter-clockwise, -1 clockwise, 0
=============== ==============================================================================

The evader's memory (crossings excluded after a stall or a cycle, the piece it came
through, the arc it is following) is left out: the features are a function of the state.
A learner fed these is a learned policy with analytic features: it needs the map's
decomposition and safety table and both positions in map coordinates, and each step costs
one cell location, one witness search and one candidate scan (most of a shooting decision).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from envs.errors import InvalidConfigError
from strategies.policies.observe import read_state
from strategies.policies.shooting import ShootingEvader

__all__ = ["PLAN_FEATURES", "PlanFeatures", "line_of_sight_frame"]

PLAN_FEATURES = (
    "escapable",
    "closeness",
    "cross_u",
    "cross_n",
    "cross_dist",
    "region_u",
    "region_n",
    "shot_u",
    "shot_n",
    "shot_margin",
    "shot_branch",
)
"""The features, in order (all in [-1, 1])."""


def line_of_sight_frame(d: np.ndarray, u: np.ndarray) -> tuple[float, float]:
    """``(d . u, d . n) / |d|``: the unit direction of ``d`` in the frame of the line of
    sight ``u`` (a unit vector) and ``n``, ``u`` turned a quarter counter-clockwise;
    ``(0, 0)`` for ``d = 0``."""
    n = math.hypot(float(d[0]), float(d[1]))
    if n <= 0.0:
        return 0.0, 0.0
    return (
        float(d[0] * u[0] + d[1] * u[1]) / n,
        float(-d[0] * u[1] + d[1] * u[0]) / n,
    )


class PlanFeatures:
    """The :data:`PLAN_FEATURES` of ``"state"`` observations on one map.

    Args:
        config: the env's ``EnvConfig`` (its map, L range, speeds and body radius).
        evader: a :class:`ShootingEvader` already reset on this map, whose plan, table and
            candidates to use (``None``: build one from ``expert_params``). Only its
            stateless methods are called: its actions are unchanged.
        **expert_params: the shooting evader's parameters (the expert's).
    """

    def __init__(
        self, config: Any, evader: ShootingEvader | None = None, **expert_params: Any
    ) -> None:
        if evader is None:
            evader = ShootingEvader(**expert_params)
            evader.reset(role="evader", map=config.map, config=config, seed=0)
        elif expert_params:
            raise InvalidConfigError("PlanFeatures: pass an evader or its parameters, not both")
        self.evader = evader
        self.config = config
        self._step = config.v_evader * config.dt

    def __call__(self, state: np.ndarray) -> np.ndarray:
        """The (11,) float32 features at a ``"state"`` observation."""
        e, p, _, _ = read_state(state, self.config)
        out = np.zeros(len(PLAN_FEATURES), dtype=np.float32)
        out[4] = 1.0
        rod = p - e
        dist = math.hypot(float(rod[0]), float(rod[1]))
        if dist <= 0.0:
            return out
        u = rod / dist
        theta = math.atan2(float(u[1]), float(u[0]))
        ev, plan, c = self.evader, self.evader.plan, self.config

        cell = plan.cell_at(e, theta)
        w = None
        if cell >= 0:
            rank = int(plan.rank[cell])
            out[0] = 1.0 if rank >= 0 else -1.0
            if rank >= 0:
                out[1] = 1.0 / (1.0 + rank)
                # as ShootingEvader._new_witness with nothing excluded
                w = plan.witness(cell, e, c.body_radius, margin=self._step) or plan.witness(
                    cell, e, c.body_radius
                )
                if w is not None:
                    to = w.target - e
                    out[2], out[3] = line_of_sight_frame(to, u)
                    out[4] = min(math.hypot(float(to[0]), float(to[1])) / c.l_max, 1.0)
        # the plan's own rows (a distinct table numbers its rows otherwise)
        row = plan.row(e) if plan.region.any() else -1
        if (
            row >= 0
            and plan.region.any()
            and not plan.region[row]
            and not plan.in_witness_region(cell)
        ):
            nxt = int(plan.region_next[row])
            if nxt >= 0:
                out[5], out[6] = line_of_sight_frame(plan.points[nxt] - e, u)
        # the shot the evader takes: on a long rod, one its disc can follow with a margin
        # against the rod's length, before the plan, or where there is neither a plan nor
        # a shot at L_min's margins (ShootingEvader._decide)
        planned = w is not None
        rod_len = max(dist, c.l_min)
        long_rod = ev._long(rod_len)
        best, against = None, None
        if planned and long_rod:
            best, against = ev._best_candidate(e, theta, rod=rod_len), rod_len
        if best is None:
            best, against = ev._best_candidate(e, theta), None
        if best is None and not planned and long_rod:
            best, against = ev._best_candidate(e, theta, rod=rod_len), rod_len
        if best is not None:
            q, branch = best
            margin, _ = ev._margins(e, theta, q[None], rod=against)
            out[7], out[8] = line_of_sight_frame(q - e, u)
            out[9] = min(max(float(margin[0]) / math.pi, 0.0), 1.0)
            out[10] = 1.0 if branch == "+" else -1.0
        return out
