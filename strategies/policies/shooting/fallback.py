"""The shooting evader's fallback without a plan or a shot: region walk, stalls, herd, walls.

:class:`_Fallback`: the grid walk to a witness region (Prop. 2); the stall of the
fallback's shots and pressure and the targets it gives up; the herd that pins the pursuer
into a concave corner after ``HERD_AFTER`` D / V_e of pressure (the corners,
:func:`herd_corners`); and the wall tests of the pressure's slide.
"""

from __future__ import annotations

import math

import numpy as np

from strategies.policies.base import unit
from strategies.policies.baselines import nearest_wall_point
from strategies.policies.shooting.arcs import _row_norms

_WALL_TOL = 1e-9  # beyond the rounding of a distance to the walls


class _Fallback:
    """The witness-region walk, the fallback's stall, the herd and the wall tests.

    A part of :class:`~strategies.policies.shooting.evader.ShootingEvader`: it reads the
    evader's constants and the state its ``_reset`` and ``_forget`` set.
    """

    def _near_banned(self, points: np.ndarray) -> np.ndarray:
        """Per point (rows of ``points``), whether it lies within the ban radius of a
        target given up after a stall (:meth:`_fallback_stalled`)."""
        if not len(self._banned):
            return np.zeros(len(points), dtype=bool)
        near = points[:, None, :] - self._banned[None, :, :]
        return np.einsum("ijk,ijk->ij", near, near).min(axis=1) <= self._ban_radius**2

    def _fallback_stalled(self, e: np.ndarray) -> bool:
        """Record ``e`` as a fallback position and tell whether the fallback stalled: over
        the last ``STALL_WINDOW`` L_min / V_e of game time it kept within ``STALL_RADIUS``
        L_min of the window's mean position. On a stall, the targets the window shot at
        more than once (within ``STALL_RADIUS`` L_min of another of its targets) are given
        up (no shot lands within ``STALL_RADIUS`` L_min of them again: see
        :meth:`_best_candidate`) and a new window starts.

        Shots and pressure each undo the other: a shot at a point its disc cannot reach
        (the point past a wall's end in sight, the disc against the end) and a slide
        along the wall back, the pursuer's turns keeping the margin of that one shot
        alternately positive and not (issue 13: office~x0.8rot-1.4off(6,2), rho 0.2,
        L_max 3 L_min, seed 8, the decomposition pursuer: in a 0.09 x 0.05 m box from
        30 s to the 1,320 s horizon, at the tip of a wall).
        """
        c = self.config
        self._track.append((float(e[0]), float(e[1])))
        n = max(2, math.ceil(self.STALL_WINDOW * c.l_min / (c.v_evader * c.dt)))
        if len(self._track) < n:
            return False
        del self._track[:-n]
        pts = np.array(self._track)
        r = self.STALL_RADIUS * c.l_min
        if float(_row_norms(pts - pts.mean(axis=0)).max()) > r:
            return False
        if len(self._track_targets) > 1:
            # the targets shot at more than once in the window (near one another): a shot
            # made once and left for pressure is pressure's stall, which herding handles
            # (random:star:2017, rho 0.3, seed 849: banning a single shot's target there
            # changed where the herd began, held for 8 D / V_e instead of escaping)
            t = np.array(self._track_targets)
            d = t[:, None, :] - t[None, :, :]
            again = (np.einsum("ijk,ijk->ij", d, d) <= self._ban_radius**2).sum(axis=1) > 1
            if again.any():
                self._banned = np.concatenate([self._banned, t[again]])
        self._track.clear()
        self._track_targets.clear()
        return True

    def _region_walk(self, e: np.ndarray) -> np.ndarray | None:
        """Heading of the grid walk from ``e`` to a witness region (Prop. 2), or ``None``
        (no witness region, ``e`` off the grid or in one, or none reachable).

        The walk's arrays are the plan's grid points: looked up with the plan's rows
        (:meth:`EscapePlan.row`), not the safety table's (a distinct table numbers its
        rows otherwise: issue 13, on office the table's row gave the wrong answer to "in
        a witness region?" at 1,526 of the 35,214 grid points, and the walk headed for
        unrelated grid points).
        """
        if not self._has_region:
            return None
        plan = self.plan
        row = plan.row(e)
        if row < 0 or plan.region[row]:
            return None
        nxt = plan.region_next[row]
        return unit(plan.points[nxt] - e) if nxt >= 0 else None

    def _herd(self, e: np.ndarray, p: np.ndarray, u: np.ndarray, L: float) -> np.ndarray | None:
        """Heading that pins the pursuer at ``p`` into a concave corner: toward the point at
        range ``L`` on the far side of the pursuer from the corner, and straight at the
        pursuer (``u``) once the rod points within 18 degrees of the corner. The nearest
        corner for which that point is in sight of ``e``; ``None`` if none is.

        A point out of sight is across a wall: heading for it pressed the evader to the
        wall for the rest of the horizon (issue 13: office at half scale, rho 0.3, seed
        909, the pursuer in a door and the evader against the wall beside it).

        The corner the herd headed for on the step before comes first while its point is
        in sight: the nearest corner changes where the pursuer crosses the bisector of
        two, and a herd pushing it toward one corner's far side pushed it across that
        bisector, so a nearest-first choice each step flipped between the two and held
        the pursuer on the bisector, away from both (issue 13: the same episode with the
        decomposition pursuer of b78a617, from 560 s to the horizon on the midline of a
        room between (12, 5.075) and (12, 8), the target flipping every 3 steps; keeping
        the corner escaped at 538.9 s). A step that did not herd forgets it.
        """
        d = self._concave - p
        order = np.argsort(np.einsum("ij,ij->i", d, d), kind="stable").tolist()
        if self._herd_step != self._steps - 1:
            self._herd_corner = -1
        self._herd_step = self._steps
        if self._herd_corner >= 0:
            order.remove(self._herd_corner)
            order.insert(0, self._herd_corner)
        for i in order:
            self._herd_corner = i
            n = unit(d[i])
            if float(u @ n) > 0.95:
                return u
            q = p - L * n
            to = q - e
            if math.hypot(float(to[0]), float(to[1])) <= 1e-9:
                return u
            if self.kernel.line_of_sight((float(e[0]), float(e[1])), (float(q[0]), float(q[1]))):
                return unit(to)
        self._herd_corner = -1
        return None

    def _along_wall(self, e: np.ndarray, h: np.ndarray, u: np.ndarray) -> np.ndarray:
        """Heading ``h`` with its component into the nearest wall removed (``e`` within a
        step or two of it); where nothing is left (``h`` along the wall's normal), the
        pressure's slide perpendicular to the rod ``u``."""
        q, _ = nearest_wall_point(self.map, e)
        n = unit(e - q)
        into = float(h @ n)
        if into >= 0.0:
            return h
        s = h - into * n
        ns = math.hypot(float(s[0]), float(s[1]))
        if ns > 1e-9:
            return s / ns
        s = np.array([-u[1], u[0]])
        return s if float(s @ n) >= 0.0 else -s

    def _near_wall(self, e: np.ndarray, r: float) -> bool:
        """Whether ``e`` lies within ``r`` of a wall (``Map.distance_to_walls``), from the
        last distance computed when it settles the answer (the distance is 1-Lipschitz:
        it changed by at most the distance moved since)."""
        if self._wall_last is not None:
            x, y, dist = self._wall_last
            moved = math.hypot(float(e[0]) - x, float(e[1]) - y)
            if dist - moved > r + _WALL_TOL:
                return False
            if dist + moved < r - _WALL_TOL:
                return True
        dist = float(self.map.distance_to_walls(e[None])[0])
        self._wall_last = (float(e[0]), float(e[1]), dist)
        return dist <= r


def herd_corners(m, min_turn: float) -> np.ndarray:
    """Indices of ``m``'s concave vertices (``Map.vertex_convex`` false) whose two walls'
    normals turn by at least ``min_turn`` degrees: 90 at a rectangle's corner, 180 minus
    the interior angle in general."""
    idx = np.flatnonzero(~m.vertex_convex)
    a = m.edge_normal[m.vertex_prev_edge[idx]]
    b = m.edge_normal[m.vertex_next_edge[idx]]
    cos = np.clip(np.einsum("ij,ij->i", a, b), -1.0, 1.0)
    return idx[cos <= math.cos(math.radians(min_turn)) + 1e-12]
