"""Probes round the corners an evader rounds, for the decomposition pursuer (issue 13).

Straight probe rays (eqs. 2-3) stop at the first wall; an evader hugging a wall toward a
convex corner, or walking round an obstacle small enough to circle (a lap no longer than
the evader's circle at the rod's least rate, Sec. 6.1), threatens orientations behind the
corner that no straight probe sees in time. :class:`_CornerProbes` probes round them and
leads the rod on such a lap; the map's corners, their neighbours along the walls and the
small obstacles' hulls are computed once per map (:func:`_rounding_corners`,
:func:`_corner_starts`, :func:`_corner_neighbours`, :func:`_small_obstacles`).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from strategies.policies.base import Snapshot


class _CornerProbes:
    """The probes round the corners the evader is about to round, and the lead on a lap.

    A part of :class:`~strategies.policies.decomposition.pursuer.DecompositionPursuer`:
    it reads the pursuer's constants and the state its ``_reset`` sets.
    """

    def _corners_in_reach(
        self, evader: np.ndarray, velocity: np.ndarray
    ) -> list[tuple[np.ndarray, float, np.ndarray, int]]:
        """The convex corners a wall-hugging evader is about to round, for :meth:`_target`.

        Straight probe rays stop at the first wall, so an evader walking along a wall
        toward a convex vertex threatens orientations behind that vertex (the rod would
        sweep it) that no probe sees until the evader is there, too late to swing the rod
        round: the pillar room's triangle, the L-hall's pillar, maze walls (issue 13).
        Where the evader touches a wall (its clearance within ``CORNER_HUG`` grid steps
        of its body radius) and walks toward a corner (cosine at least
        ``CORNER_HEADING``) it reaches in a straight free line within the horizon, the
        nearest such corner is probed too: rays from the point where the evader's centre
        rounds it, only those turning round it (into the shadow of the walk), with
        ``t_e = (|corner - e| + r) / V_e``, a path the evader can walk (eq. 2's
        straight-line times, with one bend). Without the two conditions the corners'
        threats turned the rod against evaders that do not round them (maze, straight
        evader, seed 1) and cost more decision time.

        If the wall it rounds onto ends in another convex corner within reach in a
        straight free line (the end of a thin maze wall), that corner is probed as well,
        on the walk's far side, with ``t_e`` over both legs; so is the far corner of an
        evader rounding a corner now (within ``CORNER_HUG`` steps of its body from it),
        whose heading no longer points at either. Behind that second corner the rod
        cannot take the shorter way round to a safe orientation (it would sweep the wall
        the evader walked round); it has to turn the way the walk turns, so its probes
        count the table's rotation that way (``ccw`` or ``cw``, not ``need``). With the
        shorter way the rod swung too late (maze, wall hugger, seeds 6 and 7); counting
        the turn's way for the first corner too lost the maze's wall-hugger seeds 0, 1
        and 5.

        Returns:
            ``[(start, delay, rays, sense)]`` (or ``[]``): the rays' origin, the
            evader's time to it, which of the probe rays (bool) count, and the way the
            rod must turn there (+1 ccw, -1 cw; 0: the shorter way).
        """
        starts = self._corners
        if not len(starts) or (self._clear is None and self._clear_memo is None):
            return []
        if not len(self._t_e):  # a slow evader: no probe within the horizon's reach
            return []
        c = self.config
        vx, vy = float(velocity[0]), float(velocity[1])
        speed = math.hypot(vx, vy)
        ex, ey = float(evader[0]), float(evader[1])
        h = self.table.resolution
        if speed == 0.0 or self._clearance_at(ex, ey) > c.body_radius + self.CORNER_HUG * h:
            return []
        dx, dy = starts[:, 0] - ex, starts[:, 1] - ey
        d = np.hypot(dx, dy)
        reach = c.v_evader * (self.horizon - float(self._t_e[0]))
        near = np.flatnonzero(d <= c.body_radius + self.CORNER_HUG * h)
        for k in near[np.argsort(d[near], kind="stable")]:
            # rounding corner k now: probe round the one at the far end of the wall it
            # rounds onto, if any (the nearest corner at hand only)
            j = self._corner_after(k, vx, vy)
            nxt = self._corner_probe(j, evader, 0.0, reach) if j >= 0 else None
            if nxt is not None:
                return [nxt, *self._walk_corners(evader, vx, vy, speed, reach, [j])]
            break
        out: list[tuple[np.ndarray, float, np.ndarray, int]] = []
        done: list[int] = []  # the corners probed so far
        ahead = (d < reach) & (dx * vx + dy * vy >= self.CORNER_HEADING * speed * d)
        for k in np.flatnonzero(ahead)[np.argsort(d[ahead], kind="stable")]:
            first = self._corner_probe(k, evader, 0.0, reach)
            if first is None:  # no straight free walk
                continue
            out.append((*first[:3], 0))
            done.append(int(k))
            j = self._corner_after(k, float(dx[k]), float(dy[k]))
            nxt = self._corner_probe(j, starts[k], float(d[k]), reach) if j >= 0 else None
            if nxt is not None:
                out.append(nxt)
                done.append(j)
            break
        return out + self._walk_corners(evader, vx, vy, speed, reach, done)

    def _walk_corners(
        self, evader: np.ndarray, vx: float, vy: float, speed: float, reach: float, done: list
    ) -> list[tuple[np.ndarray, float, np.ndarray, int]]:
        """Probes round every corner of a small obstacle the evader walks round (issue 13).

        Small: the obstacle's convex hull is no longer than the circle the evader runs on
        while the rod turns at its least rate ``omega`` (radius ``V_e / omega``, Sec. 6.1;
        a convex obstacle inside that circle is no longer than it), so a lap round it
        takes about as long as the rod's full turn, or less. Circling one, the evader
        keeps turning its heading, and the corners it rounds next threaten orientations a
        straight-line evader never reaches (eqs. 2-3): the rod idled at a near target for
        5-7 s while only the next corner was probed (:meth:`_corners_in_reach`), then the
        best orientation jumped about 120 degrees ahead and the rod, turning at its
        limit, fell behind (the orbit at 0.25 on rand:star:3007 and rand:polygons:3005,
        rho 0.5, occluded at 14.0 s and 17.0 s; both hulls 7.0 and 6.1 against 7.26).
        A larger obstacle (the maze's walls, the pillars of the built-in worlds) is left
        alone: a lap round it takes longer than the rod's full turn.

        Where the evader hugs such an obstacle (within ``CORNER_HUG`` grid steps of its
        body from a wall) and walks round it (its heading within ``CORNER_HEADING`` of
        the hull's tangent), each hull corner along the walk within ``reach`` (the walk's
        length along the hull) is probed from where its centre rounds it, with
        ``t_e = walk / V_e``, on the rays turning round it, and the rotation counted the
        way the walk turns (as the second corner of :meth:`_corners_in_reach`), except the
        ``done`` corners that method probes already.
        """
        walk = self._walk(evader, vx, vy, speed)
        if walk is None:
            return []
        small, c = self._small, self.config
        ring, s, forward = walk
        lap = small.perimeter[ring]
        pos = small.corner_pos[ring]
        walk = (pos - s) % lap if forward else (s - pos) % lap
        out = []
        for i in np.argsort(walk, kind="stable"):
            w = float(walk[i])
            if w >= reach:
                break
            k = int(small.corners[ring][i])
            if k in done:
                continue
            start = self._corners[k]
            fx, fy = (float(v) for v in small.arrive[ring][i, 0 if forward else 1])
            wx = float(self._corner_vertex[k, 0] - start[0])
            wy = float(self._corner_vertex[k, 1] - start[1])
            side = fx * wy - fy * wx  # > 0: the obstacle left of the walk
            cross = fx * self._dirs[:, 1] - fy * self._dirs[:, 0]
            sense = 1 if side > 0 else -1
            out.append((start, w / c.v_evader, cross * side > 0.0, sense))
        return out

    def _walk(
        self, evader: np.ndarray, vx: float, vy: float, speed: float
    ) -> tuple[int, float, bool] | None:
        """The walk round a small obstacle :meth:`_walk_corners` probes: ``(ring, s,
        forward)``, the obstacle's ring, the evader's place along its hull (the hull's
        arc length) and whether it walks the hull's way (the map's rings' orientation,
        free space on the left: clockwise round the obstacle); None where the evader does
        not hug a small obstacle (within ``CORNER_HUG`` grid steps of its body) walking
        round it (its heading within ``CORNER_HEADING`` of the hull's tangent)."""
        small = self._small
        if small is None or speed == 0.0:
            return None
        c = self.config
        e, dist, _, _ = _nearest_edge(evader, small.wall)
        if dist > c.body_radius + self.CORNER_HUG * self.table.resolution:
            return None
        ring = int(small.wall.ring[e])
        hull = small.hull[ring]
        e, _, t, g = _nearest_edge(evader, hull)
        # the walk's tangent, forward along the hull (oriented as the map's rings, free
        # space on its left): away from the hull turned by -90 degrees outside it, the
        # hull edge's direction on it or inside it (in a pocket of the obstacle)
        gn = math.hypot(*g)
        hdir = hull.dir[e]
        if gn > 1e-9 and g[1] * hdir[0] - g[0] * hdir[1] >= 0.0:
            tx, ty = g[1] / gn, -g[0] / gn
        else:
            tx, ty = float(hdir[0]), float(hdir[1])
        along = vx * tx + vy * ty
        if abs(along) < self.CORNER_HEADING * speed:
            return None
        return ring, float(hull.pos[e]) + t, along > 0.0

    def _corner_after(self, k: int, vx: float, vy: float) -> int:
        """The corner at the far end of the wall an evader walking ``(vx, vy)`` along a
        wall of corner ``k`` rounds onto (-1: that end is no corner)."""
        din = self._corner_in[k]
        forward = vx * din[0, 0] + vy * din[0, 1] >= vx * din[1, 0] + vy * din[1, 1]
        return int(self._corner_next[k, 0 if forward else 1])

    def _corner_probe(
        self, k: int, origin: np.ndarray, walked: float, reach: float
    ) -> tuple[np.ndarray, float, np.ndarray] | None:
        """Probe rays round corner ``k`` for an evader at ``origin`` having walked
        ``walked`` already: (start, delay, shadow rays), or None if it cannot walk there
        straight within ``reach``."""
        start = self._corners[k]
        fx, fy = float(start[0] - origin[0]), float(start[1] - origin[1])
        f = math.hypot(fx, fy)
        if walked + f >= reach:
            return None
        n = max(2, math.ceil(f / self.table.resolution))
        seg = origin + (np.arange(1, n + 1)[:, None] / n) * (start - origin)
        if not bool(np.all(self.table.rows(seg) >= 0)):
            return None
        wx = float(self._corner_vertex[k, 0] - start[0])
        wy = float(self._corner_vertex[k, 1] - start[1])
        side = fx * wy - fy * wx  # > 0: the wall left of the walk
        cross = fx * self._dirs[:, 1] - fy * self._dirs[:, 0]
        sense = 1 if side > 0 else -1  # the walk turns ccw round it (wall on the left)
        return start, (walked + f) / self.config.v_evader, cross * side > 0.0, sense

    def _walk_lead(
        self, snap: Snapshot, ccw: np.ndarray, cw: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray] | None:
        """On a lap round a small obstacle, the one candidate: the far end of the rod's
        free arc the way the walk turns, less ``LEAD_MARGIN`` bins (issue 13).

        Small (:meth:`_walk_corners`): a lap takes about as long as the rod's full turn at
        its least rate, or less, so the rod cannot keep pace with the walk for ever; it
        must turn the walk's way at the lap's rate on average, and each second it idles
        the evader's heading runs ahead of it. The decomposition's target is the best bin
        against a straight-line evader; reached, the rod stood still while the walk went
        on (rand:convex:2005:3.5, orbit:1:0.25, from hindsight's pursuer at 6 s: the rod
        led the walk by 15 degrees, turned back 20 to its target and idled 2 s while the
        walk's heading turned 90; occluded at 14.9 s where hindsight's pursuer held to
        23.7). Leading as far as the rod is free keeps the lead a pursuer has once the
        walk's way is known (19.6 s there). Returns ``(ccw, cw)`` candidates for
        :meth:`_target`, or None off a lap (its own candidates stand).
        """
        ve = snap.evader_velocity
        vx, vy = float(ve[0]), float(ve[1])
        walk = self._walk(snap.evader, vx, vy, math.hypot(vx, vy))
        if walk is None:
            return None
        sense = -1 if walk[2] else 1
        way = ccw if sense > 0 else cw
        if not way.size:
            return None
        k = max(int(way.max()) - self.LEAD_MARGIN, 0)
        k = min(k, self.table.n_bins // 2)
        if k == 0:
            return np.array([0]), cw[:0]
        one = np.array([k])
        return (one, cw[:0]) if sense > 0 else (ccw[:0], one)


def _rounding_corners(world) -> list[int]:
    """The convex obstacle vertices an evader can round: those whose walls' normals do
    not cancel (their bisector is defined). The corners of :func:`_corner_starts` and
    :func:`_corner_neighbours`, in this order."""
    keep = []
    for i in world.convex_vertices:
        b = (
            world.edge_normal[world.vertex_prev_edge[i]]
            + world.edge_normal[world.vertex_next_edge[i]]
        )
        if float(np.hypot(b[0], b[1])) >= 1e-9:
            keep.append(int(i))
    return keep


class _Edges(NamedTuple):
    """Segments in order along rings: starts, unit directions, lengths, each one's
    ring, and its start's distance along its ring."""

    start: np.ndarray
    dir: np.ndarray
    length: np.ndarray
    ring: np.ndarray
    pos: np.ndarray


def _nearest_edge(
    point: np.ndarray, edges: _Edges
) -> tuple[int, float, float, tuple[float, float]]:
    """The nearest of ``edges`` to ``point``: (its index, the distance, the nearest
    point's distance along the edge, and the offset (x, y) of ``point`` from it)."""
    rel = point[None, :] - edges.start
    t = np.clip(np.einsum("ej,ej->e", rel, edges.dir), 0.0, edges.length)
    g = rel - t[:, None] * edges.dir
    d2 = np.einsum("ej,ej->e", g, g)
    e = int(np.argmin(d2))
    gx, gy = float(g[e, 0]), float(g[e, 1])
    return e, math.sqrt(float(d2[e])), float(t[e]), (gx, gy)


def _edges(points: list[np.ndarray], rings: list[int]) -> _Edges:
    """:class:`_Edges` of closed polylines ``points`` (each (n, 2), in order)."""
    start, end, ring, pos = [], [], [], []
    for pts, k in zip(points, rings, strict=True):
        nxt = np.roll(pts, -1, axis=0)
        length = np.hypot(*(nxt - pts).T)
        start.append(pts)
        end.append(nxt)
        ring.append(np.full(len(pts), k))
        pos.append(np.concatenate(([0.0], np.cumsum(length)[:-1])))
    st, en = np.concatenate(start), np.concatenate(end)
    length = np.hypot(*(en - st).T)
    unit = (en - st) / length[:, None]
    return _Edges(st, unit, length, np.concatenate(ring), np.concatenate(pos))


class _SmallObstacles(NamedTuple):
    """The obstacles small enough to circle (:func:`_small_obstacles`)."""

    wall: _Edges  # their walls
    hull: dict[int, _Edges]  # ring -> its convex hull, oriented as the ring
    perimeter: dict[int, float]  # ring -> the hull's perimeter
    corners: dict[int, np.ndarray]  # ring -> indices into the corners on the hull
    corner_pos: dict[int, np.ndarray]  # ring -> their distances along the hull
    arrive: dict[int, np.ndarray]  # ring -> (m, 2, 2) directions a walk along the hull
    # arrives at each of those corners in (forward, then backward)


def _small_obstacles(world, corners: list[int], budget: float) -> _SmallObstacles | None:
    """The obstacles of ``world`` whose convex hull's perimeter is at most ``budget``,
    with the ``corners`` (indices into them) on their hulls; None if there are none."""
    index = {v: k for k, v in enumerate(corners)}
    walls, hulls, per, on, at, arrive, rings = [], {}, {}, {}, {}, {}, []
    for ring in range(1, len(world.rings)):
        ids = np.flatnonzero(world.vertex_ring == ring)  # in ring order
        pts = world.vertices[ids]
        hull_at = _hull(pts)
        hp = pts[hull_at]
        hl = float(np.hypot(*(np.roll(hp, -1, axis=0) - hp).T).sum())
        if hl > budget:
            continue
        rings.append(ring)
        walls.append(pts)
        h = _edges([hp], [ring])
        hulls[ring], per[ring] = h, hl
        keep = [i for i, v in enumerate(ids[hull_at]) if int(v) in index]
        on[ring] = np.array([index[int(ids[hull_at][i])] for i in keep], dtype=np.int64)
        at[ring] = h.pos[keep]
        fwd = h.dir[np.array(keep, dtype=np.int64) - 1]  # the hull edge ending there
        back = -h.dir[keep]  # the one starting there, walked backward
        arrive[ring] = np.stack([fwd, back], axis=1).reshape(-1, 2, 2)
    if not rings:
        return None
    return _SmallObstacles(_edges(walls, rings), hulls, per, on, at, arrive)


def _hull(pts: np.ndarray) -> np.ndarray:
    """Indices of the convex hull's vertices of a closed ring ``pts``, in the ring's own
    order (a subsequence of it: the hull of a simple polygon visits its vertices in the
    polygon's order), collinear points left out (monotone chain)."""
    order = np.lexsort((pts[:, 1], pts[:, 0]))

    def half(seq):
        out: list[int] = []
        for i in seq:
            while len(out) >= 2:
                a, b = pts[out[-2]], pts[out[-1]]
                c = pts[i]
                if (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]) > 0:
                    break
                out.pop()
            out.append(int(i))
        return out

    keep = set(half(order)[:-1] + half(order[::-1])[:-1])
    return np.array(sorted(keep), dtype=np.int64)


def _corner_starts(world, corners: list[int], pad: float) -> tuple[np.ndarray, np.ndarray]:
    """(k, 2) points ``pad`` off the ``corners`` of ``world``, along the bisector of their
    walls' normals (where the centre of an evader of radius ``pad`` rounding one passes),
    and (k, 2) those vertices."""
    out, vert = [], []
    for i in corners:
        b = (
            world.edge_normal[world.vertex_prev_edge[i]]
            + world.edge_normal[world.vertex_next_edge[i]]
        )
        b = b / float(np.hypot(b[0], b[1]))
        out.append(world.vertices[i] + b * pad)
        vert.append(world.vertices[i])
    return (
        np.asarray(out, dtype=np.float64).reshape(-1, 2),
        np.asarray(vert, dtype=np.float64).reshape(-1, 2),
    )


def _corner_neighbours(world, corners: list[int]) -> tuple[np.ndarray, np.ndarray]:
    """For the ``corners`` (indices into them): (k, 2) the corners at the far ends of
    their two walls (-1: that end is not one of them), and (k, 2, 2) the directions in
    which a walk along each wall arrives at the corner (the walk then goes on toward the
    neighbour over the other wall)."""
    index = {v: k for k, v in enumerate(corners)}
    nxt = np.full((len(corners), 2), -1, dtype=np.int64)
    din = np.zeros((len(corners), 2, 2))
    for k, i in enumerate(corners):
        e_in, e_out = int(world.vertex_prev_edge[i]), int(world.vertex_next_edge[i])
        # arriving along the wall before it (forward): go on to the next vertex
        din[k, 0] = world.edge_dir[e_in]
        nxt[k, 0] = index.get(int(world.edge_vertices[e_out, 1]), -1)
        # arriving along the wall after it (backward): go on to the previous vertex
        din[k, 1] = -world.edge_dir[e_out]
        nxt[k, 1] = index.get(int(world.edge_vertices[e_in, 0]), -1)
    return nxt, din
