"""Baseline policies: random, greedy follower, straight-line, toward/away and wall-hugging.

None of these uses the configuration-space theory; they are the yardsticks the analytic
policies are measured against. The greedy pursuer knows nothing of the map; the
straight-line and wall-hugging evaders use the map only to notice walls.
"""

from __future__ import annotations

import math

import numpy as np

from envs import validation
from envs.errors import InvalidConfigError
from strategies.policies.base import (
    BasePolicy,
    Snapshot,
    distance_target,
    flag_param,
    positive_param,
    unit,
)

__all__ = [
    "GreedyPursuer",
    "RandomPolicy",
    "StraightLineEvader",
    "TowardAwayEvader",
    "WallHuggingEvader",
    "nearest_wall_point",
    "step_gain",
]


def nearest_wall_point(world_map, point: np.ndarray) -> tuple[np.ndarray, int]:
    """Closest point on the map's walls to ``point`` and the index of its edge
    (``Map.nearest_wall_point``)."""
    return world_map.nearest_wall_point(point)


class RandomPolicy(BasePolicy):
    """Uniform random velocity in the speed disk, redrawn every ``hold`` steps.

    Args:
        hold: number of steps a drawn velocity is kept (1 = white noise).
    """

    def __init__(self, *, hold: int = 1, name: str | None = None) -> None:
        super().__init__(name=name)
        self.hold = validation.integer("hold", hold, minimum=1)
        self._current = np.zeros(2)

    def _decide(self, snap: Snapshot) -> np.ndarray:
        if self._steps % self.hold == 0:
            # uniform in the disk: radius ~ sqrt(U)
            r = math.sqrt(self.rng.random())
            a = self.rng.uniform(-math.pi, math.pi)
            self._current = self.v_max * r * np.array([math.cos(a), math.sin(a)])
        return self._current


def step_gain(gain: float, dt: float) -> float:
    """The proportional gain a step of ``dt`` applies: ``gain``, at most ``1 / dt``.

    A correction of ``gain * error`` per second held for one step moves ``gain * dt`` of
    the error: above 1 it overshoots the target and the distance chatters about it by
    up to a step's travel each step (greedy pursuer, gain 50, dt 0.1: +-0.1 about its
    target, the env's speed cap the only bound); ``1 / dt`` closes the error in one step.
    """
    return min(gain, 1.0 / dt)


class GreedyPursuer(BasePolicy):
    """Keep the evader at ``L_min`` by moving along the line of sight; no map knowledge.

    The pursuer's velocity is radial: it matches the evader's velocity component along
    the rod (so L holds) and adds a proportional correction of L toward the target
    distance, ``gain`` per second. The rod is never turned on purpose.

    Args:
        gain: rate (1/s) at which the distance error is corrected (at most ``1 / dt``
            is applied: :func:`step_gain`).
        target: target distance as a fraction of the way from L_min (plus the lag buffer
            of :func:`~strategies.policies.base.distance_target`) to L_max.
    """

    def __init__(self, *, gain: float = 4.0, target: float = 0.0, name: str | None = None) -> None:
        super().__init__(name=name)
        self.gain = positive_param("gain", gain)
        self.target = validation.real("target", target, minimum=0.0)
        if self.target >= 1.0:
            raise InvalidConfigError(f"target = {target!r}: expected a number in [0, 1)")

    def _decide(self, snap: Snapshot) -> np.ndarray:
        c = self.config
        low = distance_target(c)
        want = low + self.target * (c.l_max - low)
        u = unit(snap.rod)  # from evader to pursuer
        gain = step_gain(self.gain, c.dt)
        radial = float(np.dot(snap.evader_velocity, u)) - gain * (snap.L - want)
        return radial * u


class StraightLineEvader(BasePolicy):
    """Run at full speed on a straight line; pick a new random heading when blocked.

    Args:
        heading: initial heading in radians (``None``: drawn from the policy's RNG).
    """

    def __init__(self, *, heading: float | None = None, name: str | None = None) -> None:
        super().__init__(name=name)
        self.heading = None if heading is None else validation.real("heading", heading)

    def _reset(self) -> None:
        self._alpha = (
            float(self.heading) if self.heading is not None else self.rng.uniform(-math.pi, math.pi)
        )

    def _decide(self, snap: Snapshot) -> np.ndarray:
        d = np.array([math.cos(self._alpha), math.sin(self._alpha)])
        if self._steps > 0 and float(np.dot(snap.evader_velocity, d)) < 0.25 * self.v_max:
            # blocked by a wall (the physics slides us along it): turn into free space
            _, k = nearest_wall_point(self.map, snap.evader)
            n = self.map.edge_normal[k]
            a = self.rng.uniform(-0.5 * math.pi, 0.5 * math.pi)
            base = math.atan2(n[1], n[0])
            self._alpha = base + a
            d = np.array([math.cos(self._alpha), math.sin(self._alpha)])
        return self.v_max * d


class TowardAwayEvader(BasePolicy):
    """Move straight toward or away from the pursuer (Sec. 6.1).

    Moving along the rod minimises the largest rate ``max |theta_dot|`` the pursuer can
    impose (THEORY 4.1: the minimum of ``g(phi)`` is at ``phi = k pi``).

    Faster than the pursuer (``v_evader > v_pursuer``, rho > 1), ``"away"`` (and the
    away half of ``"alternate"``) flees along the walls and charges once it cannot flee:
    straight away it pressed into the first wall or corner and stood there while the
    pursuer kept L (rho 1.1, 12 worlds, six pursuers, safe and valid starts: 51 of 144
    escaped). Its heading's part into a wall within a step turns along that wall, and it
    flees while that heading opens L at least half its speed surplus faster than the
    pursuer can close it (``V_e cos > V_p + (V_e - V_p) / 2``) and its last step, if it
    fled, fled faster than ``V_p + (V_e - V_p) / 4``; otherwise (a wall head-on, a
    concave corner) it runs at the pursuer to the end of the episode, which closes L at
    least ``V_e - V_p`` a second (footnote 4: a faster evader always escapes at L_min).
    So ``"away"`` flees at most ``4 (L_max - L_min) / (V_e - V_p)`` seconds, then
    charges at most a quarter of that. ``pure=True`` runs straight away whatever the
    walls, as footnote 4 words the escape (a bounded world corners it: THEORY.md
    section 8; the reproduction report plays it so). At rho <= 1 every mode plays as it
    always did.

    Args:
        mode: ``"toward"``, ``"away"``, or ``"alternate"`` (switch every ``period`` s).
        period: switching period in seconds for ``"alternate"``.
        pure: straight along the rod at any rho (no flight along the walls, no charge).
    """

    MODES = ("toward", "away", "alternate")

    def __init__(
        self,
        *,
        mode: str = "toward",
        period: float = 4.0,
        pure: bool = False,
        name: str | None = None,
    ) -> None:
        super().__init__(name=name)
        self.mode = validation.choice("mode", mode, self.MODES)
        self.period = positive_param("period", period)
        self.pure = flag_param("pure", pure)

    def _reset(self) -> None:
        self._charging = False  # rho > 1: ran at the pursuer once it could not flee
        self._fled = False  # rho > 1: the last step fled

    def _decide(self, snap: Snapshot) -> np.ndarray:
        u = unit(snap.rod)
        toward = self.mode == "toward"
        if self.mode == "alternate":
            toward = int(snap.time // self.period) % 2 == 0
        if not (toward or self.pure) and self.config.v_evader > self.config.v_pursuer:
            return self._flee(snap, u)
        self._fled = False
        return self.v_max * (u if toward else -u)

    def _flee(self, snap: Snapshot, u: np.ndarray) -> np.ndarray:
        """rho > 1: away from the pursuer along the walls while that opens L, else (and
        from then on) straight at it."""
        v_e, v_p = self.v_max, float(self.config.v_pursuer)
        surplus = v_e - v_p
        if not self._charging:
            reach = self.config.body_radius + v_e * self.config.dt
            d = _slide(self.map, snap.evader, -u, reach, 1)
            fled = -float(snap.evader_velocity @ u)  # the last step's realised flight
            if v_e * float(d @ -u) > v_p + 0.5 * surplus and (
                not self._fled or fled > v_p + 0.25 * surplus
            ):
                self._fled = True
                return v_e * d
            self._charging = True
        self._fled = False
        return v_e * u


class WallHuggingEvader(BasePolicy):
    """Go to the nearest wall and follow it at distance ``offset``, wall on the right.

    Walls are rings with free space on their left, so walking along an edge's direction
    keeps the wall on the right; around convex corners the nearest wall point is the
    vertex and the same rule wraps the evader round it.

    Args:
        offset: distance kept from the walls.
        gain: rate (1/s) of the correction toward that distance (at most ``1 / dt``
            is applied: :func:`step_gain`).
    """

    def __init__(self, *, offset: float = 0.2, gain: float = 4.0, name: str | None = None) -> None:
        super().__init__(name=name)
        self.offset = positive_param("offset", offset)
        self.gain = positive_param("gain", gain)

    def _decide(self, snap: Snapshot) -> np.ndarray:
        c, k = nearest_wall_point(self.map, snap.evader)
        away = snap.evader - c
        dist = math.hypot(float(away[0]), float(away[1]))
        n = away / dist if dist > 1e-12 else self.map.edge_normal[k]
        tangent = np.array([n[1], -n[0]])  # n rotated by -90 degrees: wall on the right
        err = self.offset - dist
        radial = np.clip(step_gain(self.gain, self.config.dt) * err / self.v_max, -1.0, 1.0)
        v = radial * n + math.sqrt(max(0.0, 1.0 - radial * radial)) * tangent
        return self.v_max * v


class OrbitEvader(BasePolicy):
    """Circle the nearest obstacle at distance ``offset`` (an adversary for the pursuer).

    Darting round a pillar's convex corners is what a pursuer that probes the evader's
    reach along straight rays misses (issue 13). The evader walks round the obstacle
    nearest to it (the outer wall where the map has none), counter-clockwise with
    ``direction = 1``, clockwise with ``-1``, holding ``offset`` from it. Where a wall
    between them blocks the way (an obstacle seen past the end of a wall, as in the
    maze), the part of its velocity into that wall goes along it instead: heading
    straight at it, the evader stood still from 12.5 s to the end (maze, seeds 0 and 1).

    Args:
        offset: distance kept from the obstacle.
        direction: ``1`` (counter-clockwise round the obstacle) or ``-1``.
        gain: rate (1/s) of the correction toward that distance (at most ``1 / dt``
            is applied: :func:`step_gain`).
    """

    def __init__(
        self,
        *,
        offset: float = 0.5,
        direction: int = 1,
        gain: float = 4.0,
        name: str | None = None,
    ) -> None:
        super().__init__(name=name)
        self.offset = positive_param("offset", offset)
        self.direction = validation.choice("direction", direction, (1, -1))
        self.gain = positive_param("gain", gain)

    def _reset(self) -> None:
        m = self.map
        holes = m.edge_ring > 0
        self._edges = np.flatnonzero(holes) if holes.any() else np.arange(len(m.edge_ring))

    def _decide(self, snap: Snapshot) -> np.ndarray:
        m, e = self.map, snap.evader
        idx = self._edges
        rel = e[None, :] - m.edge_start[idx]
        t = np.clip(np.einsum("ej,ej->e", rel, m.edge_dir[idx]), 0.0, m.edge_length[idx])
        closest = m.edge_start[idx] + t[:, None] * m.edge_dir[idx]
        d2 = np.einsum("ej,ej->e", e - closest, e - closest)
        k = int(np.argmin(d2))
        away = e - closest[k]
        dist = math.sqrt(float(d2[k]))
        n = away / dist if dist > 1e-12 else m.edge_normal[idx[k]]
        # obstacles are rings with free space on their left: -90 degrees keeps the
        # obstacle on the right (clockwise round it), +90 counter-clockwise
        tangent = self.direction * np.array([-n[1], n[0]])
        gain = step_gain(self.gain, self.config.dt)
        radial = np.clip(gain * (self.offset - dist) / self.v_max, -1.0, 1.0)
        v = radial * n + math.sqrt(max(0.0, 1.0 - radial * radial)) * tangent
        reach = self.config.body_radius + self.v_max * self.config.dt
        return self.v_max * _slide(m, e, v, reach, self.direction)


def _slide(m, e: np.ndarray, v: np.ndarray, reach: float, sense: int) -> np.ndarray:
    """Unit heading ``v``, its part into the nearest wall turned along that wall when the
    wall is within ``reach`` (the body plus one step) and ``v`` heads into it: the same
    speed along the wall, toward the side ``v`` leans to, or ``sense`` (1: with the wall
    on the right) head-on (``v`` itself otherwise)."""
    q, _ = nearest_wall_point(m, e)
    d = math.hypot(float(e[0] - q[0]), float(e[1] - q[1]))
    if d >= reach or d <= 1e-12:
        return v
    w = (e - q) / d  # out of the wall
    into = float(v @ w)
    if into >= 0.0:
        return v
    along = v - into * w
    norm = math.hypot(float(along[0]), float(along[1]))
    if norm <= 1e-9:  # head-on
        return sense * np.array([-w[1], w[0]])
    return along / norm
