"""The leader-follower motions of Section 7 as pursuer policies (the evader leads).

* :class:`TractrixFollower` (Sec. 7.1): dragged by a string of length ``L``: it moves only
  along the rod, only when the string is taut; behind a straight-line leader its path is
  the tractrix.
* :class:`WallFollowingPursuer` (Sec. 7.3): slides along its nearest wall keeping the
  distance, ``x_p' = V_e cos(alpha - theta) / cos(theta)`` in the wall's frame; feasible
  while ``|cos theta| >= rho`` (erratum E6).
* :class:`CornerRoundingPursuer` (Sec. 7.4): when the rod passes close to a convex corner
  it pivots about a point just off the corner, ``p' = (I - (L/l) n n^T) e'`` with
  ``n = (sin theta, -cos theta)`` (the correct velocity formula; erratum E7 concerns the
  position relation), else it follows like the tractrix.

These are cooperative motions: none of them tries to keep the rod out of escapable
cells, which is why they make useful weak baselines for the adversarial game.
"""

from __future__ import annotations

import math

import numpy as np

from strategies.policies.base import BasePolicy, Snapshot, distance_target, nonnegative_param, unit
from strategies.policies.baselines import nearest_wall_point

__all__ = ["CornerRoundingPursuer", "TractrixFollower", "WallFollowingPursuer"]


class TractrixFollower(BasePolicy):
    """Follower dragged by a taut string toward ``L_min`` (Sec. 7.1).

    The velocity is along the rod, toward the evader, with speed
    ``max(0, e'·u + gain (L - L_min))`` where ``u`` points at the evader: the follower
    matches the leader's pull (the tractrix, THEORY 5.1) and never pushes back.

    Args:
        gain: rate (1/s) at which slack beyond ``L_min`` is taken in.
    """

    def __init__(self, *, gain: float = 1.0, name: str | None = None) -> None:
        super().__init__(name=name)
        self.gain = nonnegative_param("gain", gain)

    def _decide(self, snap: Snapshot) -> np.ndarray:
        u = -unit(snap.rod)  # pursuer -> evader
        pull = float(np.dot(snap.evader_velocity, u)) + self.gain * (
            snap.L - distance_target(self.config)
        )
        return max(0.0, pull) * u


class WallFollowingPursuer(BasePolicy):
    """Slide along the nearest wall while holding the distance at ``L_min`` (Sec. 7.3).

    With ``d = P - E`` and the wall tangent ``tau``, the pursuer velocity ``s tau`` keeps
    ``|d|`` changing at ``-gain (L - L_min)`` when ``s (d·tau) = d·e' - gain L (L - L_min)``
    (the general form of ``x_p' = V_e cos(alpha - theta)/cos(theta)``). Farther than
    ``reach`` from every wall it first heads for the nearest one.

    Args:
        gain: rate (1/s) of the distance correction.
        reach: distance from a wall within which the pursuer counts as on it.
    """

    def __init__(self, *, gain: float = 1.0, reach: float = 0.3, name: str | None = None) -> None:
        super().__init__(name=name)
        self.gain = nonnegative_param("gain", gain)
        self.reach = nonnegative_param("reach", reach)

    def _decide(self, snap: Snapshot) -> np.ndarray:
        c, k = nearest_wall_point(self.map, snap.pursuer)
        gap = float(np.linalg.norm(snap.pursuer - c))
        if gap > self.reach + self.config.body_radius:
            return self.v_max * unit(c - snap.pursuer)
        tau = self.map.edge_dir[k]
        d = snap.rod
        along = float(np.dot(d, tau))
        rhs = float(np.dot(d, snap.evader_velocity)) - self.gain * snap.L * (
            snap.L - distance_target(self.config)
        )
        if abs(along) < 1e-9:  # rod perpendicular to the wall: no tangential motion helps
            return np.zeros(2)
        s = float(np.clip(rhs / along, -self.v_max, self.v_max))
        return s * tau


class CornerRoundingPursuer(BasePolicy):
    """Pivot the rod about a point just off a nearby convex corner (Sec. 7.4).

    A convex obstacle vertex ``v`` engages when it is within ``engage`` of the rod and
    projects onto its interior; the pivot is ``c = v + clearance m`` with ``m`` the unit
    bisector of the two edge normals (into free space). With ``l = |c - E|`` the pursuer
    moves with ``(I - (L/l) n n^T) e'`` plus a correction toward ``E + L_min (c - E)/l``.
    Without an engaged corner it behaves like :class:`TractrixFollower`.

    Args:
        engage: distance from the rod at which a corner engages.
        clearance: offset of the pivot from the corner.
        gain: rate (1/s) of the position correction.
    """

    def __init__(
        self,
        *,
        engage: float = 0.5,
        clearance: float = 0.15,
        gain: float = 2.0,
        name: str | None = None,
    ) -> None:
        super().__init__(name=name)
        self.engage = nonnegative_param("engage", engage)
        self.clearance = nonnegative_param("clearance", clearance)
        self.gain = nonnegative_param("gain", gain)

    def _reset(self) -> None:
        m = self.map
        idx = m.convex_vertices
        self._corners = m.vertices[idx]
        bis = m.edge_normal[m.vertex_prev_edge[idx]] + m.edge_normal[m.vertex_next_edge[idx]]
        self._pivots = self._corners + self.clearance * bis / np.linalg.norm(
            bis, axis=1, keepdims=True
        )
        self._tractrix = TractrixFollower(gain=self.gain)
        self._tractrix.role, self._tractrix.config = self.role, self.config

    def _decide(self, snap: Snapshot) -> np.ndarray:
        e, d = snap.evader, snap.rod
        L2 = float(np.dot(d, d))
        if len(self._corners) and L2 > 0:
            t = (self._corners - e) @ d / L2
            foot = e + t[:, None] * d
            dist = np.linalg.norm(self._corners - foot, axis=1)
            ok = (t > 0) & (t < 1) & (dist < self.engage)
            if ok.any():
                j = int(np.flatnonzero(ok)[np.argmin(dist[ok])])
                c = self._pivots[j]
                l = float(np.linalg.norm(c - e))  # noqa: E741 - the paper's symbol
                if l > 1e-9:
                    th = math.atan2(c[1] - e[1], c[0] - e[0])
                    n = np.array([math.sin(th), -math.cos(th)])
                    L = snap.L
                    v = snap.evader_velocity - (L / l) * n * float(n @ snap.evader_velocity)
                    target = e + distance_target(self.config) * (c - e) / l
                    return v + self.gain * (target - snap.pursuer)
        return self._tractrix._decide(snap)
