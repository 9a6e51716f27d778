"""The path a shot follows: the optimal escape arc of Sec. 6, or the straight path.

:class:`_Arcs` solves the optimal escape arc to a shot's target
(:func:`strategies.control.evasion.escape_path`, for the branch the pursuer would turn),
falls back to the straight path its margin was computed on where no bounded arc reaches
the target (near rho = 1 most do not, THEORY §4.3), and heads for the path's point one
step ahead of the evader's progress until the replan.
"""

from __future__ import annotations

import math

import numpy as np

from strategies.control.evasion import capped_step, escape_path
from strategies.policies.base import unit


class _Arcs:
    """The arc (or straight path) a shot follows, and its heading each step.

    A part of :class:`~strategies.policies.shooting.evader.ShootingEvader`: it reads the
    evader's constants and the state its ``_reset`` and ``_forget`` set.
    """

    # rho from which a shot follows the straight path its margin was computed on without
    # solving the optimal arc (Sec. 6) first. Near rho = 1 the extremals wander: a solve
    # integrated arcs ~6 times the target's distance at 1,024 fine RK4 steps per distance,
    # 20-70 ms a replan (issue 13, under 1 ms a decision: random:star:9203, rho 0.99, L_min
    # 5 against a shadowing pursuer, a mean of 5.7 ms of thread CPU a decision; 8 of the
    # 477 rho-0.95 episodes of unseen-e and heldout-e above 1 ms, up to 3.7), and most
    # solves fail there anyway (the extremals turn back first, THEORY 4.3), leaving the
    # straight path, whose margin is what chose the shot. Those 477 episodes without the
    # solves: the same winners, 63 escapes sooner and 14 later (2,349 -> 2,308 s in all),
    # every mean under 1 ms (the evader's CPU time over them halved)
    ARC_RHO_MAX = 0.9

    def _straight_arc(self, e: np.ndarray, target: np.ndarray) -> np.ndarray:
        """Follow the straight path from ``e`` to ``target`` like an arc (until the
        replan or its end); its first heading."""
        d = target - e
        n = 1 + math.ceil(math.hypot(d[0], d[1]) / (self.config.v_evader * self.config.dt))
        f = np.linspace(0.0, 1.0, n + 1)[:, None]
        self._arc = (e.copy(), math.atan2(d[1], d[0]), e + f * d)
        self._arc_length = _arc_lengths(self._arc[2])
        self._arc_age = 1
        return self._arc_heading(e)

    def _start_arc(
        self, e: np.ndarray, theta: float, target: np.ndarray, branch: str
    ) -> np.ndarray:
        """Solve the optimal escape arc to ``target`` (Sec. 6) and return its first heading."""
        d = target - e
        frame = math.atan2(d[1], d[0])
        dist = math.hypot(d[0], d[1])
        self._arc, self._arc_age = None, 0
        if self.shoot and 0.0 < self.rho < 1.0:
            # at most 1,024 RK4 steps (never coarser than the trust limit): near rho = 1
            # the default step shrinks with the natural length (issue 13: 100-150 ms a
            # solve at rho 0.99); where it is the default step, the default's arc
            L = self.config.l_min
            # from ARC_RHO_MAX on, no solve: the straight path (as where no arc reaches)
            solve = dist > 0.0 and self.rho < self.ARC_RHO_MAX
            step = capped_step(dist, L, self.rho) if solve else None
            path = None
            if step is not None:
                path = escape_path(theta - frame, dist, L=L, rho=self.rho, branch=branch, step=step)
            if path is not None:
                rot = np.array(
                    [[math.cos(frame), -math.sin(frame)], [math.sin(frame), math.cos(frame)]]
                )
                self._arc = (e.copy(), frame, path @ rot.T + e)
            else:
                # no optimal arc reaches the target (the extremals turn back first: near
                # rho = 1 most do, THEORY §4.3): the shot is the straight path its margin
                # was computed on, followed like an arc until the replan. Re-solved every
                # step, the same failure (a new problem each step, as the evader moves)
                # cost a solve per step: 100-150 ms at rho 0.99 on the corridor, where
                # nearly every solve fails (issue 13). Sampled at least every step, as an
                # arc's nodes are, so that _arc_heading follows it the same way
                n = 1 + math.ceil(dist / (self.config.v_evader * self.config.dt))
                f = np.linspace(0.0, 1.0, n + 1)[:, None]
                self._arc = (e.copy(), frame, e + f * d)
            self._arc_length = _arc_lengths(self._arc[2])
            self._arc_age = 1
            return self._arc_heading(e)
        return unit(d)

    def _arc_heading(self, e: np.ndarray) -> np.ndarray:
        """Heading toward the stored arc's point one step ahead of the evader's progress."""
        _, _, path = self._arc
        k = int(np.argmin(_row_norms(path - e)))
        ahead = self.config.v_evader * self.config.dt
        s = self._arc_length  # of this arc (_start_arc)
        j = int(np.searchsorted(s, s[k] + ahead))
        if j >= len(path):
            self._arc = None
            return unit(path[-1] - e)
        return unit(path[j] - e)


def _row_norms(d: np.ndarray) -> np.ndarray:
    """``np.linalg.norm(d, axis=1)`` of real (n, 2) rows: the same floats (it computes
    ``sqrt(add.reduce(d * d, axis=1))``), without its dispatch."""
    return np.sqrt(np.add.reduce(d * d, axis=1))


def _arc_lengths(path: np.ndarray) -> np.ndarray:
    """Arc length along ``path`` at each of its points (0 at the first)."""
    return np.cumsum(np.concatenate(([0.0], _row_norms(np.diff(path, axis=0)))))
