"""Opponents the analytic policies were not developed against (``unseen_worlds.py``).

Issue 13's hidden tests play opponents nobody has seen; these stand in for them in
``benchmarks/unseen_worlds.py``. They are deliberately *not* in the policy registry
(the goals say "every evader in the registry", and registering them would change it).

Evaders (against the decomposition pursuer):

* :class:`ZigZag`: toward the pursuer at +-angle off the rod, flipping every period;
* :class:`Herder`: gets opposite the pursuer from its nearest wall (or concave corner),
  then charges: pins the pursuer to that wall;
* :class:`Darter`: rounds the nearest convex corner to the side away from the pursuer;
* :class:`Momentum`: a random walk with momentum, reflected off walls.

Pursuers (against the shooting evader): :class:`StandStill`, :class:`CentralPark`,
:class:`Shadow`, :class:`Mirror`.

:func:`make_opponent` turns a label into a policy: these classes, or a registered policy
with keyword arguments after colons (``evader/orbit:1:0.5``, ``greedy g1 t.6``).
"""

from __future__ import annotations

import math

import numpy as np

from strategies.policies import make_policy
from strategies.policies.base import BasePolicy, unit
from strategies.policies.baselines import nearest_wall_point

# ------------------------------------------------------------------ evaders


class ZigZag(BasePolicy):
    """Toward the pursuer at +-``angle`` off the rod, flipping every ``period`` s: it asks
    the rod to turn one way, then the other."""

    roles = ("evader",)

    def __init__(self, *, angle: float = 1.1, period: float = 1.0, name: str | None = None):
        super().__init__(name=name or f"zigzag:{angle:g}:{period:g}")
        self.angle, self.period = angle, period

    def _decide(self, snap):
        u = unit(snap.rod)
        s = 1 if int(snap.time // self.period) % 2 == 0 else -1
        a = math.atan2(u[1], u[0]) + s * self.angle
        return self.v_max * np.array([math.cos(a), math.sin(a)])


class Herder(BasePolicy):
    """Gets to the far side of the pursuer from the pursuer's nearest wall (with
    ``corner``: its nearest concave corner), then charges at it: pins it to that wall."""

    roles = ("evader",)

    def __init__(self, *, corner: bool = False, name: str | None = None):
        super().__init__(name=name or ("herder:corner" if corner else "herder"))
        self.corner = corner

    def _reset(self):
        self._concave = self.map.vertices[~self.map.vertex_convex]

    def _decide(self, snap):
        p, e = snap.pursuer, snap.evader
        q, _ = nearest_wall_point(self.map, np.asarray(p, float))
        if self.corner and len(self._concave):
            q = self._concave[int(np.argmin(np.linalg.norm(self._concave - p, axis=1)))]
        n = unit(np.asarray(q, float) - p)  # from the pursuer toward its wall
        target = p - n * max(snap.L, 1e-9)  # opposite the wall, at the current range
        u = unit(p - e)
        if float(np.dot(u, n)) > 0.95:  # the rod points at the wall: charge
            return self.v_max * u
        d = target - e
        if math.hypot(*d) < 1e-9:
            return self.v_max * u
        return self.v_max * unit(d)


class Darter(BasePolicy):
    """Darts round the nearest convex corner to the side away from the pursuer, then the
    next one, and so on (away from the pursuer when the map has no convex corner)."""

    roles = ("evader",)

    def __init__(self, *, offset: float = 0.35, name: str | None = None):
        super().__init__(name=name or "darter")
        self.offset = offset

    def _reset(self):
        m = self.map
        idx = np.flatnonzero(m.vertex_convex)
        b = m.edge_normal[m.vertex_prev_edge[idx]] + m.edge_normal[m.vertex_next_edge[idx]]
        self._idx = idx
        self._v = m.vertices[idx]
        self._b = b / np.maximum(np.linalg.norm(b, axis=1), 1e-12)[:, None]  # bisectors
        self._goal = None
        self._last = -1
        self._phase = 0
        self._t = 0

    def _decide(self, snap):
        e, p = snap.evader, snap.pursuer
        if not len(self._idx):
            return self.v_max * unit(e - p)
        if self._goal is None:
            d = np.linalg.norm(self._v - e, axis=1)
            if self._last >= 0 and len(d) > 1:
                d[self._last] = np.inf
            self._goal = int(np.argmin(d))
            self._phase, self._t = 0, 0
        k = self._goal
        c = self._v[k]
        self._t += 1
        if self._phase == 0:  # to the corner
            tgt = c + self._b[k] * (self.config.body_radius + self.offset)
            if np.linalg.norm(tgt - e) < 0.2 or self._t > 150:
                self._phase, self._t = 1, 0
        if self._phase == 1:  # round it, away from the pursuer
            tgt = c + unit(c - p) * 1.5 + self._b[k] * self.offset
            if np.linalg.norm(tgt - e) < 0.2 or self._t > 40:
                self._last, self._goal = k, None
        return self.v_max * unit(tgt - e)


class Momentum(BasePolicy):
    """A random walk with momentum: the heading diffuses (``sigma`` rad/sqrt(s)); at a
    wall it reflects."""

    roles = ("evader",)

    def __init__(self, *, sigma: float = 0.5, name: str | None = None):
        super().__init__(name=name or f"momentum:{sigma:g}")
        self.sigma = sigma

    def _reset(self):
        self._a = self.rng.uniform(-math.pi, math.pi)

    def _decide(self, snap):
        self._a += self.sigma * math.sqrt(self.config.dt) * self.rng.standard_normal()
        d = np.array([math.cos(self._a), math.sin(self._a)])
        q, k = nearest_wall_point(self.map, np.asarray(snap.evader, float))
        if math.hypot(*(snap.evader - q)) < self.config.body_radius * 1.5:
            n = self.map.edge_normal[k]
            if float(d @ n) < 0:
                d = d - 2 * float(d @ n) * n
                self._a = math.atan2(d[1], d[0])
        return self.v_max * d


# ------------------------------------------------------------------ pursuers


class StandStill(BasePolicy):
    """A pursuer that does not move."""

    roles = ("pursuer",)

    def _decide(self, snap):
        return np.zeros(2)


class CentralPark(BasePolicy):
    """Goes to the free point (two body radii from the walls) nearest the map's
    bounding-box centre, on a grid of spacing L_min / 10, and parks there."""

    roles = ("pursuer",)

    def _reset(self):
        m, c = self.map, self.config
        x0, y0, x1, y1 = m.bounds
        h = c.l_min / 10
        xs, ys = np.meshgrid(np.arange(x0, x1, h), np.arange(y0, y1, h))
        pts = np.stack([xs.ravel(), ys.ravel()], 1)
        pts = pts[m.contains(pts)]
        pts = pts[m.distance_to_walls(pts) > 2 * c.body_radius]
        ctr = np.array([(x0 + x1) / 2, (y0 + y1) / 2])
        self.goal = pts[np.argmin(np.linalg.norm(pts - ctr, axis=1))]

    def _decide(self, snap):
        d = self.goal - snap.pursuer
        n = float(np.linalg.norm(d))
        v = self.config.v_pursuer
        return d / n * min(v, n / self.config.dt) if n > 1e-9 else np.zeros(2)


class Shadow(BasePolicy):
    """Copies the evader's velocity and corrects the range toward 0.9 L_max."""

    roles = ("pursuer",)

    def _decide(self, snap):
        u = unit(snap.rod)  # evader -> pursuer
        return snap.evader_velocity - 3.0 * (snap.L - 0.9 * self.config.l_max) * u


class Mirror(BasePolicy):
    """Copies the evader's velocity (translates the rod), nothing else."""

    roles = ("pursuer",)

    def _decide(self, snap):
        return np.array(snap.evader_velocity, dtype=float)


def make_opponent(label: str):
    """The policy of an opponent label (see the module docstring)."""
    if label.startswith("zigzag:"):
        _, angle, period = label.split(":")
        return ZigZag(angle=float(angle), period=float(period))
    if label in ("herder", "herder:corner"):
        return Herder(corner=label.endswith("corner"))
    if label == "darter":
        return Darter()
    if label.startswith("momentum:"):
        return Momentum(sigma=float(label.split(":")[1]))
    if label.startswith("evader/toward_away:"):
        return make_policy("evader/toward_away", mode=label.split(":")[1])
    if label.startswith("evader/orbit:"):
        _, direction, offset = label.split(":")
        return make_policy("evader/orbit", direction=int(direction), offset=float(offset))
    pursuers = {"still": StandStill, "central": CentralPark, "shadow": Shadow, "mirror": Mirror}
    if label in pursuers:
        return pursuers[label]()
    if label == "greedy g1 t.6":
        return make_policy("pursuer/greedy", gain=1.0, target=0.6)
    if label == "greedy g12 t.3":
        return make_policy("pursuer/greedy", gain=12.0, target=0.3)
    return make_policy(label)
