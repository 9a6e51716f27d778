"""The shooting evader's shots (Sec. 6, Fig. 13): candidate endpoints and their escape margins.

:class:`_Shots`: the candidate endpoints a straight line reaches (probes on rays up to the
first wall, and points just past each convex obstacle vertex in reach) where the rod's
orientation is not safe; per candidate, the rotation the pursuer needs each way round to a
safe orientation (the safety table) against the rotation it can make while the evader
gets there (eq. 6 integrated along the straight path, or the pursuer's reach from a long
rod); the best candidate with a positive margin, one the evader's disc can follow where
asked, and the first leg of a two-leg shot past a corner. The arc that follows a shot is
in :mod:`strategies.policies.shooting.arcs`.
"""

from __future__ import annotations

import math

import numpy as np

from envs.geometry.segments import point_segment_distance, segment_distance
from strategies.policies.shooting.arcs import _row_norms

_EULER = 8  # sub-steps of the straight-path rotation estimate


class _Shots:
    """The candidate endpoints, their escape margins and the shot chosen among them.

    A part of :class:`~strategies.policies.shooting.evader.ShootingEvader`: it reads the
    evader's constants and the state its ``_reset`` and ``_forget`` set.
    """

    def _candidates(self, e: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Probes on rays from ``e`` up to the first wall and their table rows, and the
        corner points in range (their line of sight from ``e`` not checked yet: see
        :meth:`_best_candidate`) and their rows."""
        tab = self.table
        # tab.rows(e + self._offsets), one coordinate at a time (the same operations)
        x = float(e[0]) + self._off_x
        y = float(e[1]) + self._off_y
        if self._lazy:
            # which probes are in the free region (memoised membership, no classification)
            # up to each ray's first one off it; only the candidates among them are
            # classified (LazySafetyTable.rows): the same probes and entries as a table of
            # the whole map
            off = ~tab.inside(np.stack([x, y], axis=1))
        else:
            ix = np.rint((x - tab.origin[0]) / tab.resolution).astype(np.int64)
            iy = np.rint((y - tab.origin[1]) / tab.resolution).astype(np.int64)
            nx, ny = tab.shape
            ok = (ix.view(np.uint64) < nx) & (iy.view(np.uint64) < ny)  # negatives wrap high
            rows = np.where(ok, tab.cell.reshape(-1).take(np.where(ok, ix * ny + iy, 0)), -1)
            off = rows < 0
        reach = np.cumsum(off.reshape(self.rays, self._n_r), axis=1) == 0
        pick = self._col_index[reach[:, self._cols]]
        cand = np.empty((len(pick), 2))
        cand[:, 0] = x[pick]
        cand[:, 1] = y[pick]
        picked = tab.rows(cand) if self._lazy else rows[pick].astype(np.int64)
        near = np.linalg.norm(self._corner_points - e, axis=1) <= self._n_r * tab.resolution
        return cand, picked, self._corner_points[near], self._corner_rows[near]

    def _best_candidate(
        self, e: np.ndarray, theta: float, in_sight: bool = False, rod: float | None = None
    ) -> tuple[np.ndarray, str] | None:
        """The candidate endpoint with the largest positive escape margin (the first such
        in the order rays, then visible corners), and the pursuer's branch there.

        Corners are candidates only in line of sight of ``e``. The margins do not depend
        on the other candidates, so only a corner that would beat every probe (and 0)
        needs its line of sight checked. With ``in_sight`` the probes too: a ray stops at
        its first grid point off the free region, and a wall thinner than the grid can
        lie across it (issue 13: random:convex:11, a spike's tip between the evader and
        the probe it ran at for the whole horizon).

        With ``rod`` (the rod's present length), only a candidate the evader's disc can
        follow the straight path to (:meth:`_disc_reaches`), the margins against that
        length (:meth:`_margins`' ``rod``): the shots that go before a plan, or instead of
        pressure, while the rod is long.
        """
        rays, ray_rows, corners, corner_rows = self._candidates(e)
        n = len(rays)
        rows = np.concatenate([ray_rows, corner_rows])
        margin, branch = self._margins(e, theta, np.concatenate([rays, corners]), rows, rod)
        # targets given up after a stall (_fallback_stalled), and points near them
        margin[self._near_banned(np.concatenate([rays, corners]))] = -np.inf
        if rod is not None:
            return self._disc_candidate(e, rays, corners, margin, branch)
        ex, ey = float(e[0]), float(e[1])
        ray, top = -1, 0.0  # the best probe (in sight if asked) and its margin
        if in_sight:
            for i in np.argsort(-margin[:n], kind="stable").tolist():
                if margin[i] <= 0.0:
                    break
                q = rays[i]
                if self.kernel.line_of_sight((ex, ey), (float(q[0]), float(q[1]))):
                    ray, top = i, float(margin[i])
                    break
        elif n and margin[:n].max() > 0:
            ray = int(np.argmax(margin[:n]))
            top = float(margin[ray])
        best = -1
        for i in np.flatnonzero(margin[n:] > top).tolist():
            q = corners[i]
            if (best < 0 or margin[n + i] > margin[best]) and self.kernel.line_of_sight(
                (ex, ey), (float(q[0]), float(q[1]))
            ):
                best = n + i
        if best < 0:
            best = ray
        if best < 0:
            return None
        return np.concatenate([rays, corners])[best], str(branch[best])

    def _disc_candidate(self, e, rays, corners, margin, branch) -> tuple[np.ndarray, str] | None:
        """The candidate with the largest positive margin whose straight path the disc can
        follow (:meth:`_disc_reaches`), and its branch; ``None`` if there is none."""
        if not len(margin) or margin.max() <= 0.0:
            return None
        cand = np.concatenate([rays, corners])
        # the clearance a path must keep from a wall: the body radius, or the evader's own
        # distance where it is pressed closer already (the contact solver lets the disc
        # overlap a wall a little)
        floor = min(self.config.body_radius, float(self.map.distance_to_walls(e[None])[0]))
        for i in np.argsort(-margin, kind="stable").tolist():
            if margin[i] <= 0.0:
                return None
            if self._disc_reaches(e, cand[i], floor):
                return cand[i], str(branch[i])
        return None

    def _disc_reaches(self, e: np.ndarray, q: np.ndarray, floor: float) -> bool:
        """Whether the evader's disc can follow the straight path from ``e`` to ``q``.

        Per wall edge near the path (:meth:`Kernel.edges_near_box`), the segment ``e``-``q``
        keeps at least ``floor`` from it, or as much as ``q`` itself does (a target closer
        to a wall than the body radius: the disc slides along that wall to beside it), up
        to ``DISC_SLACK`` body radii; a segment that crosses an edge is at 0 from it. A
        target past a wall's end or a spike's tip, in sight of the point, is not reached
        by the disc pressed to that end (issue 13: random:star:12, rho 0.3, seed 967 vs
        the decomposition pursuer: shots before a void plan at targets 0.08-0.1 from the
        walls, their paths grazing a tip at 0.001-0.027, held it for 8 D / V_e; walking
        the plan escapes at 16.25 s).
        """
        ex, ey, qx, qy = float(e[0]), float(e[1]), float(q[0]), float(q[1])
        pad = floor
        idx = self.kernel.edges_near_box(
            min(ex, qx) - pad, min(ey, qy) - pad, max(ex, qx) + pad, max(ey, qy) + pad
        )
        if not isinstance(idx, np.ndarray):
            idx = np.fromiter(idx, dtype=np.int64, count=len(idx))
        if not len(idx):
            return True
        m = self.map
        a, b = m.edge_start[idx], m.edge_end[idx]
        seg = segment_distance(e, q, a, b)
        end = point_segment_distance(q, a, b)
        slack = self.DISC_SLACK * self.config.body_radius
        return bool((seg > np.minimum(floor, end) - slack).all())

    def _margins(self, e: np.ndarray, theta: float, cand: np.ndarray, rows=None, rod=None):
        """Escape margin (radians) per candidate, and which way the pursuer would turn.

        The margin is ``-inf`` (and the branch meaningless) where it cannot be positive:
        the current orientation is safe at the candidate, the candidate is off the grid,
        or the pursuer turns far enough either way at its least rate (eq. 6 at
        ``alpha - theta = +-pi/2``: ``(V_p / L)(1 - rho)``, a lower bound of every
        rate of its branch) while the evader gets there.

        With ``rod`` (the rod's present length, at least L_min) the pursuer turns at the
        rate of eq. (6) for the shortest rod it can have by then, ``rod`` shortened at
        V_p + V_e down to L_min, rather than at L_min's throughout: from a long rod it
        turns slower (issue 13: random:polygons:7202 and random:convex:7204 at rho 0.2,
        L in [2, 6], starts the referee certifies evader wins within 1.3-5.2 s with the
        rod near L_max, held for 8 D / V_e).

        A rod longer than L_min also bounds the pursuer's reach: where the margin against
        that (:meth:`_reach_margins`) is the larger, it is the margin (each is the need
        less a bound on how far the pursuer can turn the rod by then; the larger holds
        against the tighter bound). From the rod's own direction to a corner beside the
        evader, eq. (6) lets the pursuer shorten the rod at V_p + V_e and turn it at the
        short rod's rate at once, which its speed does not allow (issue 13:
        random:convex:7308 at rho 0.2, L in [2, 6], a start the referee certifies within
        5.2 s, the rod 5.9: no margin was positive and the evader was held for 8 D / V_e;
        against the reach, a shot under the obstacle beside it occludes at 1.53 s).

        Args:
            rows: the candidates' table rows, if known.
            rod: the rod's length (``None``: L_min).
        """
        rows = self.table.rows(cand) if rows is None else rows
        margin, branch = self._rate_margins(e, theta, cand, rows, rod)
        if rod is not None and rod > self.config.l_min:
            reach, side = self._reach_margins(e, theta, cand, rows, rod)
            better = reach > margin
            if better.any():
                margin = np.where(better, reach, margin)
                branch = np.where(better, side, branch)
        return margin, branch

    def _reach_margins(
        self, e: np.ndarray, theta: float, cand: np.ndarray, rows, rod: float, p=None,
        lead: float = 0.0,
    ):  # fmt: skip
        """Escape margin per candidate against the pursuer's reach, and its branch.

        By the time the evader gets to a candidate ``q`` (``|q - e| / V_e``), the pursuer
        is within ``R = V_p |q - e| / V_e`` of where it is now (``e`` plus ``rod`` along
        ``theta``), so the rod's orientation at ``q`` is within ``asin(R / d)`` of the
        direction from ``q`` to the pursuer now (``d`` their distance; walls and the
        range only narrow that). The margin is the rotation each way from that direction
        to a safe orientation at ``q`` (the table's) less that angle, the smaller of the
        two; ``-inf`` where the direction is safe already, ``R >= d`` or ``q`` is off the
        grid.

        With ``p`` (the pursuer now) and ``lead`` (seconds), the evader is at ``e`` only
        ``lead`` from now (the first leg of a two-leg shot): the pursuer's reach grows by
        ``V_p lead``.
        """
        c, tab = self.config, self.table
        margin = np.full(len(cand), -np.inf)
        branch = np.full(len(cand), "-")
        if p is None:
            p = e + rod * np.array([math.cos(theta), math.sin(theta)])
        ok = np.flatnonzero(rows >= 0)
        to_p = p - cand[ok]
        d = _row_norms(to_p)
        reach = c.v_pursuer * (_row_norms(cand[ok] - e) / c.v_evader + lead)
        far = d > reach
        ok, to_p, d, reach = ok[far], to_p[far], d[far], reach[far]
        if not len(ok):
            return margin, branch
        beta = np.arctan2(to_p[:, 1], to_p[:, 0])
        # tab.bin_of of each direction
        b = (((beta + math.pi) % (2.0 * math.pi)) / tab.bin_width).astype(np.int64) % tab.n_bins
        r = rows[ok]
        bins_ccw, bins_cw = tab.ccw[r, b], tab.cw[r, b]
        live = (bins_ccw > 0) | (bins_cw > 0)
        turn = np.arcsin(reach / d)
        left = self._radians[bins_ccw] - turn
        right = self._radians[bins_cw] - turn
        margin[ok[live]] = np.minimum(left, right)[live]
        branch[ok[live]] = np.where(left < right, "+", "-")[live]
        return margin, branch

    def _rate_margins(
        self, e: np.ndarray, theta: float, cand: np.ndarray, rows, rod, less: float = 0.0
    ):  # fmt: skip
        """:meth:`_margins` by the rate of eq. (6) along the straight path.

        ``less``: what the caller takes off every margin (the first leg's turn of a
        two-leg shot): a candidate whose margin cannot exceed it is left at ``-inf``
        without integrating its rotation.
        """
        c, tab = self.config, self.table
        ok = rows >= 0
        margin = np.full(len(cand), -np.inf)
        branch = np.full(len(cand), "-")
        if not ok.any():  # (a lazy table may have no row yet to read a 0 from)
            return margin, branch
        b = tab.bin_of(theta)
        # bins to turn each way (0 off the grid), in radians through a lookup of the
        # 256 uint8 values: 2 pi for NO_PATH, else bins * bin width
        bins_ccw, bins_cw = tab.ccw[np.maximum(rows, 0), b], tab.cw[np.maximum(rows, 0), b]
        if not ok.all():
            bins_ccw, bins_cw = np.where(ok, bins_ccw, 0), np.where(ok, bins_cw, 0)
        need_ccw, need_cw = self._radians[bins_ccw], self._radians[bins_cw]
        live = np.flatnonzero((bins_ccw > 0) | (bins_cw > 0))
        if not len(live):
            return margin, branch
        d = cand[live] - e
        dist = _row_norms(d)
        rho = min(self.rho, 1.0)
        k = c.v_pursuer / c.l_min
        long = rod is not None and rod > c.l_min
        # the Euler rotation below is at least k (1 - rho) dist / V_e each way (up to
        # rounding, ~1e-14 rad; k at the longest rod it reckons with): a candidate
        # needing no more than that (and ``less``) has no margin
        least = (c.v_pursuer / rod if long else k) * (1.0 - rho) * dist / c.v_evader
        up = np.minimum(need_ccw[live], need_cw[live]) - least - less + 1e-9 > 0
        if not up.any():
            return margin, branch
        live, d, dist = live[up], d[up], dist[up]
        need_ccw, need_cw = need_ccw[live], need_cw[live]
        alpha = np.arctan2(d[:, 1], d[:, 0])
        dt = dist / c.v_evader / _EULER
        # eq. (6): the pursuer turns at its best rate each way (both ways in one array:
        # the first half counter-clockwise, the second clockwise)
        m = len(live)
        alpha2, dt2 = np.concatenate([alpha, alpha]), np.concatenate([dt, dt])
        sign = np.repeat([1.0, -1.0], m)
        th = np.full(2 * m, theta)
        shorten = (c.v_pursuer + c.v_evader) * dt2  # the most the rod shortens a sub-step
        for j in range(_EULER):
            phi = alpha2 - th
            if long:  # the shortest rod by the end of this sub-step
                k = c.v_pursuer / np.maximum(c.l_min, rod - (j + 1) * shorten)
            # (rho <= 1: |rho cos phi| <= 1 after rounding too, so the root's argument is
            # never negative)
            rate = k * (-rho * np.sin(phi) + sign * np.sqrt(1 - (rho * np.cos(phi)) ** 2))
            th = th + rate * dt2
        turned = np.abs(th - theta)
        left, right = need_ccw - turned[:m], need_cw - turned[m:]
        margin[live] = np.minimum(left, right)
        branch[live] = np.where(left < right, "+", "-")
        return margin, branch

    def _via_corner(
        self, e: np.ndarray, theta: float, p: np.ndarray, rod: float
    ) -> np.ndarray | None:
        """The first leg of a two-leg shot on a rod of length ``rod``: the point beside a
        convex corner (:attr:`_corner_points`, nearest first) that the evader's disc
        reaches in a straight line, from which a shot the disc can follow has a positive
        margin once the pursuer has used the first leg; ``None`` if there is none.

        From the corner's point the margins are those of a shot from there
        (:meth:`_margins` with the rod as short as the pursuer can make it by then),
        less the most the pursuer can turn the rod during the first leg (eq. 6's
        largest rate, ``(V_p + V_e) / L``, on that shortening rod), or, against its
        reach, the rotation from the direction to where the pursuer is now less the
        angle its reach over both legs covers (:meth:`_reach_margins`); the larger.
        Corners are tried while the first leg leaves the pursuer less than half a turn.

        Most looks find nothing (the first 200 steps of unseen-e's episodes: 1,461 of
        1,678 corner points had no positive margin), so a corner's margins come before
        the first leg's checks (line of sight, the disc's path from ``e``), all of them
        tests of the same corner; what does not depend on the evader (the candidates
        from the corner's point and whether the disc follows the second leg) is kept
        per corner (:meth:`_corner_look`).
        """
        c = self.config
        pts = self._corner_points
        if not len(pts):
            return None
        dist = _row_norms(pts - e)
        # the corners within a ray's reach, nearest first (ties in index order)
        near = np.flatnonzero(dist <= self._n_r * self.table.resolution)
        near = near[np.argsort(dist[near], kind="stable")]
        step = c.v_evader * c.dt
        floor = None  # the first leg's clearance (_disc_candidate's), once needed
        ex, ey = float(e[0]), float(e[1])
        for i in near.tolist():
            t1 = float(dist[i]) / c.v_evader
            turn1 = _most_turn(c.v_pursuer + c.v_evader, rod, c.l_min, t1)
            if turn1 >= math.pi:
                break
            q0 = pts[i]
            if dist[i] <= step or self._corner_rows[i] < 0:
                continue
            if self._near_banned(q0[None])[0]:
                continue
            look = self._corner_look(i)
            cand, rows = look.cand, look.rows
            rod1 = max(c.l_min, rod - (c.v_pursuer + c.v_evader) * t1)
            margin, _ = self._rate_margins(q0, theta, cand, rows, rod1, less=turn1)
            margin = margin - turn1
            # against the reach: every candidate q has |p - q| <= |p - q0| + |q - q0|,
            # while the pursuer's reach over both legs is V_p (|q - q0| / V_e + t1), no
            # less than |q - q0| + V_p t1 (rho <= 1): with |p - q0| short of V_p t1 (by
            # more than rounding) it can be at every candidate by then, and
            # _reach_margins would leave every margin -inf
            short = c.v_pursuer * t1 - math.hypot(float(p[0] - q0[0]), float(p[1] - q0[1]))
            if short <= 1e-9 * (1.0 + c.v_pursuer * t1):
                reach_margin, _ = self._reach_margins(q0, theta, cand, rows, rod, p=p, lead=t1)
                margin = np.maximum(margin, reach_margin)
            margin[self._near_banned(cand)] = -np.inf
            if not len(margin) or margin.max() <= 0.0:
                continue
            if not self.kernel.line_of_sight((ex, ey), (float(q0[0]), float(q0[1]))):
                continue
            if floor is None:
                floor = min(c.body_radius, float(self.map.distance_to_walls(e[None])[0]))
            if not self._disc_reaches(e, q0, floor):
                continue
            for k in np.argsort(-margin, kind="stable").tolist():
                if margin[k] <= 0.0:
                    break
                r = look.reached[k]
                if r < 0:
                    r = look.reached[k] = self._disc_reaches(q0, cand[k], look.floor)
                if r:
                    return q0.copy()
        return None

    def _corner_look(self, i: int) -> _CornerLook:
        """What a two-leg look reads from convex corner ``i``'s point whatever the state:
        the candidates from there (:meth:`_candidates`) and their rows, and whether the
        disc follows the straight path to each (:meth:`_disc_reaches`, answered once per
        candidate); kept per corner for the map."""
        look = self._corner_looks.get(i)
        if look is None:
            q0 = self._corner_points[i]
            rays, ray_rows, corners, corner_rows = self._candidates(q0)
            cand = np.concatenate([rays, corners])
            floor = min(self.config.body_radius, float(self.map.distance_to_walls(q0[None])[0]))
            look = _CornerLook(cand, np.concatenate([ray_rows, corner_rows]), floor)
            self._corner_looks[i] = look
        return look


class _CornerLook:
    """A convex corner's point as the end of a two-leg shot's first leg: the candidates
    from there, their table rows, the clearance the second leg keeps
    (:meth:`ShootingEvader._disc_candidate`'s floor) and, per candidate, whether the
    evader's disc follows the straight path to it (-1 until asked)."""

    __slots__ = ("cand", "floor", "reached", "rows")

    def __init__(self, cand: np.ndarray, rows: np.ndarray, floor: float) -> None:
        self.cand, self.rows, self.floor = cand, rows, floor
        self.reached = np.full(len(cand), -1, dtype=np.int8)


def _most_turn(closing: float, rod: float, l_min: float, t: float) -> float:
    """The most a rod of length ``rod`` turns in ``t`` seconds at eq. (6)'s largest rate,
    ``closing / L`` (``closing`` = V_p + V_e), the rod shortening at ``closing`` down to
    ``l_min``: ``ln(rod / L(t))`` while it shortens, ``closing / l_min`` a second after."""
    t_short = max(0.0, rod - l_min) / closing  # when it reaches l_min
    if t <= t_short:
        return math.log(rod / (rod - closing * t))
    return math.log(rod / l_min) + closing * (t - t_short) / l_min
