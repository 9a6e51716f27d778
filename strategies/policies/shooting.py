"""The shooting-based evader (Secs. 4-6): a combinatorial plan says where, shooting says how.

Each step, with the rod of length L_eff = L_min + body radius (the most capable pursuer,
Sec. 5 "minimax": its tip meets walls as if the rod were that long):

1. **Escapable cell** (the configuration lies in an escapable cell of the exact
   decomposition K_L): walk, inside the cell's region, to the nearest crossing of one of
   the cell's via pieces (a step from the piece's ends where it can, and landing in the
   region across) and land just across it (:mod:`strategies.policies.escape_plan`); the
   rank falls at every crossing whatever the pursuer does, until condition (a) breaks
   surveillance. The plan goes round the pieces the evader's disc cannot cross (closer
   to a wall than its body radius all along) wherever a route without them exists.
   Where none does (a rank of at least n_cells: the route counts a crossing the disc
   cannot make, so the rank promises nothing) the plan can end in a *dead end*, a cell
   whose every via is such a piece; from there on the evader shoots first (step 2) and
   takes the plan only where no shot has a positive margin, until it reaches a cell
   whose rank is a guarantee. Before any plan, while the rod is longer than the pursuer
   can close to L_min in a replan period, a shot goes first too: one whose straight path
   the evader's disc can follow, its margin against the rod's present length (the
   pursuer turns slower on a long rod, and a step past a wall's corner near the evader
   swings the far end of a long rod a long way).
2. **Shooting escape**: candidate endpoints (Fig. 13) are points the evader can reach in
   a straight line (probes on rays, and points just past each convex obstacle vertex in
   reach) where the current orientation is not safe. For each, the rotation the pursuer
   must make each way round to a safe orientation there (the safety table) is compared
   with the rotation it can make while the evader travels (eq. 6 integrated along the
   straight path). The best candidate with a positive margin (in line of sight, once
   an arc made no headway) is re-solved with the optimal escape arc of Sec. 6
   (:func:`strategies.control.evasion.solve_escape`, for the branch the pursuer would
   turn) and the evader follows that arc (where no bounded arc reaches the candidate,
   as near rho = 1 most do not, the straight path), replanning every ``replan`` steps.
   Where there is no plan and no such shot, while the rod is long (as in step 1), a
   shot the disc can follow, its margin against the rod's length, goes before steps 3-4.
3. **Witness region** (Prop. 2 holds on the map): from a region that is not one, walk a
   shortest grid path to a region whose cells are all escapable
   (``Decomposition.witness_regions``).
For rho > 1 it runs straight at the pursuer (footnote 4; see :meth:`ShootingEvader._decide`).

4. Otherwise **pressure**: move straight at the pursuer (Sec. 6.1, a heading
   minimising max |theta_dot|); against a wall, slide along it perpendicular to the rod,
   the way that does not press straight into the wall. After ``HERD_AFTER`` D / V_e of it
   (D the map's diameter), wherever the pursuer is, herd instead: get to the far side of
   the pursuer from the nearest concave corner for which that point is in sight (sliding
   along a wall it grazes), then charge, pinning it there; with no such corner, charge.
   Only corners whose walls turn by at least ``HERD_MIN_TURN`` count (a shallow notch is
   a wall to the pursuer).
"""

from __future__ import annotations

import math

import numpy as np

from envs import validation
from envs.geometry import kernel_for
from envs.geometry.segments import point_segment_distance, segment_distance
from strategies.control.evasion import capped_step, escape_path
from strategies.cspace.tolerances import diameter
from strategies.policies.base import (
    MAX_RAYS,
    BasePolicy,
    Snapshot,
    count_param,
    flag_param,
    positive_param,
    unit,
)
from strategies.policies.baselines import nearest_wall_point
from strategies.policies.escape_plan import escape_plan
from strategies.policies.lazy_table import LAZY_POINTS, LazySafetyTable
from strategies.policies.safety import NO_PATH, _points_at, safety_table

__all__ = ["ShootingEvader"]

_EULER = 8  # sub-steps of the straight-path rotation estimate
_N_BINS = 144  # orientation bins of the safety table (safety_table's default)
_WALL_TOL = 1e-9  # beyond the rounding of a distance to the walls
_PRESSING = 2.0 * math.sin(math.radians(80.0))  # see ShootingEvader._decide's slide
# the moves tried, in order, to keep a walk inside a region: the heading turned by 0, 5,
# ... 90 degrees either way, at a whole, half or quarter step, most progress first
_TURN_DEG = np.array([s * d for d in range(0, 91, 5) for s in ((1, -1) if d else (1,))])
_TURNS = np.array([(math.radians(a), f) for f in (1.0, 0.5, 0.25) for a in _TURN_DEG])
_TURNS = _TURNS[np.argsort(-_TURNS[:, 1] * np.cos(_TURNS[:, 0]), kind="stable")]


class ShootingEvader(BasePolicy):
    """Evader that follows guaranteed escape plans and optimal escape arcs.

    Args:
        resolution: grid spacing of the cspace tables (default L_min / 20).
        rays: candidate directions around the evader.
        probe_every: every k-th grid sample along a ray is a candidate.
        replan: steps between shooting re-plans.
        shoot: refine the chosen straight path with the optimal arc of Sec. 6.
        memory: keep what the evader learnt on the way (crossings excluded after a stall
            or a cycle, the piece it came through, the arc it follows). ``False``: decide
            each step from the state alone, as a fresh evader would (what
            :mod:`strategies.policies.plan_features` describes; a DAgger labeller whose
            labels do not depend on who steered before). It can loop where the evader
            with memory does not (issue 13).
        table: the safety table at L_eff: ``"distinct"`` (the whole map's, each distinct
            row stored once, built once per map and cached on disk), ``"lazy"``
            (:class:`~strategies.policies.lazy_table.LazySafetyTable`: a grid point is
            classified the first time a candidate lands on it; ready as soon as the
            decomposition is, memory grows with the area visited; the same entries, so
            the same decisions) or ``"auto"`` (distinct up to
            :attr:`DISTINCT_TABLE_POINTS` grid points, lazy above, as the decomposition
            pursuer's).
    """

    roles = ("evader",)
    # grid points above which "auto" fills the table lazily (the decomposition pursuer's
    # threshold): corner~x100 at L_min 2 has 115 million, whose distinct table took
    # minutes and gigabytes in reset (issue 13)
    DISTINCT_TABLE_POINTS = LAZY_POINTS

    def __init__(
        self,
        *,
        resolution: float | None = None,
        rays: int = 24,
        probe_every: int = 3,
        replan: int = 5,
        shoot: bool = True,
        memory: bool = True,
        table: str = "auto",
        name: str | None = None,
    ) -> None:
        super().__init__(name=name)
        self.resolution = None if resolution is None else positive_param("resolution", resolution)
        self.rays = count_param("rays", rays, 4, MAX_RAYS)
        self.probe_every = count_param("probe_every", probe_every, 1, MAX_RAYS)
        self.replan = validation.integer("replan", replan, minimum=1)
        self.shoot = flag_param("shoot", shoot)
        self.memory = flag_param("memory", memory)
        self.table_kind = validation.choice("table", table, ("auto", "distinct", "lazy"))

    STALL_STEPS = 10  # steps without getting closer to a crossing before giving it up
    FORGIVE_STEPS = 20  # steps without a crossing in an escapable cell before a retry
    # pressure time, in D / V_e (D the map's diameter, a similarity invariant), after which
    # it herds the pursuer into a corner instead, a last resort (issue 13). In game time, so
    # that it does not depend on dt or on how fast the evader is (2,500 steps, as it was,
    # were 3.3 D / V_e at rho 0.3 on random:star:11, 6.6 at dt 0.2 s, and more than the
    # 8 D / V_e horizon at rho 0.8). The charges that escape in the three evader benchmarks
    # take at most 2.5 D / V_e of it (office turned by 2.2 rad, rho 0.3: 2.50;
    # random:polygons:0, rho 0.5: 2.40); herding from 1 or 2 D / V_e slowed them (escape
    # times in the benchmarks' D / V_e: 2.92 -> 7.09 or 3.30, 5.98 -> 6.64 or 6.50), from
    # the first step it lost two (two_rooms at L_min 1, after 8 and 13 steps of charging)
    HERD_AFTER = 3.0
    # the least turn (degrees) between the walls of a concave corner the herd heads for
    # (an interior angle of at most 135 degrees). A random star's inner vertices can turn
    # by a few degrees: charged into one, the pursuer slid along the wall and the herd
    # picked the next such notch for the rest of the horizon (issue 13: held-out
    # random:star:2017, rho 0.3, seed 849, where they turn by 1.4-72 degrees: herding into
    # notches of 4.2, 7.8 and 20.3 degrees among others, held for 8 D / V_e; into
    # the room's four corners and two notches of 45.5 and 71.5 degrees, too close at
    # 5.08 D / V_e; 30 degrees escapes it too, 60 does not, and 85 loses unseen
    # random:star:11 seed 507: where a herd ends is path-dependent)
    HERD_MIN_TURN = 45.0
    # a fallback stall: within STALL_RADIUS L_min of its mean position for STALL_WINDOW
    # L_min / V_e of game time (2 L_min of travel); see _fallback_stalled
    STALL_WINDOW = 2.0
    STALL_RADIUS = 0.125
    # how much closer than the body radius (or the target's own distance) to a wall, in
    # body radii, a path may pass and still count as one the disc follows (the contact
    # solver lets a disc pressed to a wall overlap it; 0.089-0.095 from walls at radius
    # 0.1 on random:star:12). See _disc_reaches
    DISC_SLACK = 0.25
    # a pursuer that does not turn the rod itself: its velocity across the rod averaged
    # below RADIAL_SHARE V_e over at least RADIAL_STEPS steps (a radial follower: the
    # greedy pursuer, a tractrix, one standing still or leading the evader's position
    # moves along the rod, 0-0.03 V_e; the decomposition pursuer turns it, 0.55-0.71 V_p
    # across the rod on average at rho 0.3-0.5, 0.06-0.3 V_p = 0.3-1.5 V_e in the first
    # 500 steps at rho 0.2). Against it, a plan that promises nothing does not take over
    # from pressure (see _decide)
    RADIAL_SHARE = 0.1
    RADIAL_STEPS = 20

    def _reset(self) -> None:
        c = self.config
        self.L_eff = round(c.l_min + c.body_radius, 6)
        res = self.resolution if self.resolution is not None else c.l_min / 20.0
        # distinct rows: the eager table's lookups at every node, built in about a tenth of
        # the time (corridor at L_min 0.5: 22 s -> 2 s, issue 13); on larger maps filled
        # lazily, where the candidates land (_candidates)
        kind = self.table_kind
        if kind == "auto":
            points = _points_at(c.map.free_region.area, res)
            kind = "lazy" if points > self.DISTINCT_TABLE_POINTS else "distinct"
        self._lazy = kind == "lazy"
        if self._lazy:
            self.table = LazySafetyTable(c.map, self.L_eff, res, _N_BINS)
        else:
            self.table = safety_table(c.map, self.L_eff, res, _N_BINS, distinct=True)
        # a rotation table entry (uint8 bins) in radians, the whole turn for NO_PATH
        bins = np.arange(256).astype(float)
        self._radians = np.where(bins >= NO_PATH, 2 * math.pi, bins * self.table.bin_width)
        # (the lazy table's decomposition: not read again from the disk cache)
        held = self.table.decomposition if self._lazy else None
        self.plan = escape_plan(c.map, self.L_eff, res, c.body_radius, held)
        # the plan's crossings and region tests, built here rather than mid-episode
        # (margins: those of _new_witness)
        self.plan.prepare(c.body_radius, (c.v_evader * c.dt, 0.0))
        self.kernel = kernel_for(c.map)
        self.rho = c.rho
        omega_max = c.v_pursuer * (1.0 + min(self.rho, 1.0)) / c.l_min  # Sec. 6.1 maximum
        reach = c.v_evader * math.pi / omega_max + 2.0 * c.l_min
        h = self.table.resolution
        n_r = max(2, math.ceil(reach / h))
        # a ray stops at its first sample off the table's grid, and from a point of the
        # grid every sample past the grid's diagonal is off it (and so is every corner
        # farther): a slow pursuer's long reach adds only samples never reached
        n_r = min(n_r, math.ceil(math.hypot(*self.table.shape)) + 2)
        radii = h * np.arange(1, n_r + 1)
        ang = 2.0 * math.pi * np.arange(self.rays) / self.rays
        dirs = np.stack([np.cos(ang), np.sin(ang)], axis=1)
        self._offsets = (dirs[:, None, :] * radii[None, :, None]).reshape(-1, 2)
        # the probes' x and y offsets apart: e + offsets one coordinate at a time (the
        # same sums, without broadcasting a (2,) point over (n, 2) rows)
        self._off_x = self._offsets[:, 0].copy()
        self._off_y = self._offsets[:, 1].copy()
        self._n_r = n_r
        self._cols = np.arange(self.probe_every - 1, n_r, self.probe_every)
        # flat probe index of every candidate column of every ray, (rays, len(cols))
        self._col_index = np.arange(self.rays)[:, None] * n_r + self._cols[None, :]
        self._has_region = bool(self.plan.region.any())
        m = c.map
        idx = m.convex_vertices
        bis = m.edge_normal[m.vertex_prev_edge[idx]] + m.edge_normal[m.vertex_next_edge[idx]]
        bis = bis / np.maximum(np.linalg.norm(bis, axis=1, keepdims=True), 1e-12)
        self._corner_points = m.vertices[idx] + (c.body_radius + 2.0 * h) * bis
        self._corner_rows = self.table.rows(self._corner_points)
        # the corners pressure herds into: concave ones whose walls turn by at least
        # HERD_MIN_TURN (a notch a few degrees deep is a wall to a pursuer pinned there)
        self._concave = m.vertices[herd_corners(m, self.HERD_MIN_TURN)]
        # the pressure steps after which it herds (HERD_AFTER D / V_e of them)
        self._herd_after = self.HERD_AFTER * diameter(m) / (c.v_evader * c.dt)
        self._ban_radius = self.STALL_RADIUS * c.l_min
        # per convex corner, what a two-leg look from its point reads each time (filled
        # on the first look from there): see _corner_look
        self._corner_looks: dict[int, _CornerLook] = {}
        self.restart()

    def restart(self) -> None:
        """Forget the episode and keep the map's tables: the evader as :meth:`reset`
        leaves it (for a copy fed another episode's states,
        :class:`~strategies.policies.memory_features.MemoryFeatures`)."""
        self._prev, self._steps = None, 0
        self._rod = self.config.l_min  # the rod's length at the last decision (at least L_min)
        self._wall_last: tuple[float, float, float] | None = None  # (x, y, distance)
        self._forget()
        self.mode = "start"

    def _forget(self) -> None:
        """Clear what the evader learnt on the way (its memory)."""
        self._arc: tuple[np.ndarray, float, np.ndarray] | None = None  # (start, frame, path)
        self._arc_length: np.ndarray | None = None  # along the arc's path, from its start
        self._arc_age = 0
        self._shot: tuple[float, float, int] | None = None  # (x, y, step) of the last shot
        self._via_next = 0  # the step from which a two-leg shot is looked for again
        self._in_sight = False  # shoot only at probes in sight (until the plan resumes)
        self._plan_cell, self._plan_lost, self._witness = -1, False, None
        # progress toward the witness: a crossing the evader cannot reach (its disc
        # pressed to a corner on the way) or one that leads back where it came from is
        # excluded for that cell, and another is chosen
        self._excluded: dict[int, set[int]] = {}
        self._best_gap, self._stall = math.inf, 0
        self._came_through: tuple[int, int] | None = None  # (cell left, piece crossed)
        self._trail: list[tuple[int, int]] = []  # the last crossings (cell left, piece)
        self._no_way = 0  # steps in an escapable cell whose crossings are all excluded
        self._forgiven = 0  # retries so far (each waits twice as long as the last)
        self._pressed = 0  # pressure steps so far
        # the pursuer's speed across the rod (in V_e) summed over the steps so far, and
        # their number (see RADIAL_SHARE)
        self._across, self._across_n = 0.0, 0
        self._herding = False  # herding the pursuer into a corner (from then on)
        # the concave corner the herd headed for on the last step (-1: none, or that step
        # did not herd)
        self._herd_corner, self._herd_step = -1, -1
        # shots before the plan in cells whose rank guarantees nothing (from a dead end of
        # the plan until a shot has no candidate or the rank is a guarantee again)
        self._shoot_first = False
        # progress of the fallback (shots, pressure): the evader's positions since the
        # plan last steered, the shots' targets among them, and the targets given up
        # after a stall (a shot at a point near one of them is never made again)
        self._track: list[tuple[float, float]] = []
        self._track_targets: list[np.ndarray] = []
        self._banned = np.empty((0, 2))

    # ------------------------------------------------------------------ candidates
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

    # ------------------------------------------------------------------ decision
    def _decide(self, snap: Snapshot) -> np.ndarray:
        c = self.config
        e, theta = snap.evader, snap.theta
        self._rod = max(float(snap.L), c.l_min)
        if not self.memory:
            self._forget()
        if c.rho > 1.0:
            # footnote 4's trivial escape, in a bounded world: straight at the pursuer. The
            # rod is free (surveillance holds), so nothing blocks the way, and whatever
            # the pursuer does, dL/dt <= V_p - V_e < 0 until L < L_min ("too_close").
            # (Straight away, as the paper says, can end in a room corner.)
            self.mode = "toward"
            return c.v_evader * unit(snap.rod)
        u = unit(snap.rod)
        vp = snap.pursuer_velocity
        self._across += abs(float(u[0] * vp[1] - u[1] * vp[0])) / c.v_evader
        self._across_n += 1
        heading = self._plan_heading(e, theta)
        if (
            heading is not None
            and self.mode == "pressure"
            and self.plan.rank[self._plan_cell] >= len(self.plan.rank)
            and self._across_n >= self.RADIAL_STEPS
            and self._across < self.RADIAL_SHARE * self._across_n
        ):
            # a plan that promises nothing (rank at least n_cells) does not take over from
            # pressure against a pursuer that does not turn the rod (RADIAL_SHARE): each
            # plan step let it back off, and the charge that pins it began again. Against
            # pursuers nobody wrote it for (a lazy one, still while L is mid-band, and a
            # lead pursuer aiming at the evader's extrapolated position; random:star:12,
            # L in [2, 4], rho 0.2-0.5, seed 7004) the evader alternated the two ~30 times
            # and escaped at 4.3-5.0 D / V_e, the herd pinning it at last; charging on,
            # at 0.7-1.0 (the toward evader 0.54). The decomposition pursuer turns the
            # rod; against it the plan's walk is what escapes (letting pressure go on
            # there lost 7 escapes of the evader sets)
            heading = None
        if heading is not None and self.plan.rank[self._plan_cell] < len(self.plan.rank):
            self._shoot_first = False  # a rank below n_cells: a route the disc can take
        # while the rod is longer than the pursuer can close to L_min in a shot's replan
        # period (at V_p + V_e), a shot whose path the disc can follow, its margin against
        # the rod's present length, goes before the plan, whatever its rank: the pursuer on
        # a long rod turns slowly, and a step past a wall's corner near the evader swings
        # the rod's far end a long way. A plan whose rank is at least n_cells promises
        # nothing anyway (issue 13: random:polygons:7202, rho 0.2, L in [2, 6], from a start
        # the referee certifies an evader win within 3.9 s, walked a rank-1387 plan for
        # 428 s); a guaranteed plan can be slow (random:rectangles:7303, the same game, four
        # certified starts (1.3-2.6 s): a rank-8 plan walked cell by cell for 21-105 s,
        # a shot past a rectangle's corner occludes in 0.3-1.4 s). Only while the rod is
        # long: where it is near L_min the shot's margin is L_min's and the plan did at
        # least as well (two_rooms~rot2.2, rho 0.5, L in [1, 1.5], seed 619 vs
        # decomposition, the rod 1.12: a shot a step before the base's, occluded at
        # 24.44 s -> held)
        long_rod = self._long(self._rod)
        first = heading is not None and not self._shoot_first and long_rod
        if heading is not None and not self._shoot_first and not first:
            self.mode = "plan"
            self._arc, self._in_sight = None, False
            self._track.clear()
            self._track_targets.clear()
            return c.v_evader * heading
        if self._fallback_stalled(e):
            self._arc = None  # (its target is given up)
        if self._arc is not None and self._arc_age < self.replan:
            self._arc_age += 1
            return c.v_evader * self._arc_heading(e)
        # stuck: less than a step made good since the last shot, one arc ago (pressed
        # against a wall between the evader and its target): from then on until the plan
        # resumes, aim only at probes in sight
        last = self._shot
        if (
            last is not None
            and self._steps - last[2] <= self.replan
            and math.hypot(float(e[0]) - last[0], float(e[1]) - last[1]) < c.v_evader * c.dt
        ):
            self._in_sight = True
        best = self._best_candidate(
            e, theta, in_sight=self._in_sight, rod=self._rod if first else None
        )
        if best is None and heading is None and long_rod:
            # no plan and no shot at L_min's margins: on a long rod, a shot the disc can
            # follow with a positive margin against the rod's length before the witness
            # walk and pressure (issue 13: random:polygons:7302, the same game, starts the
            # referee certifies within 1.3 s, the rod 5.0 and 5.6 grazing the corner of
            # the obstacle beside the evader: pressure from the first step, held for
            # 8 D / V_e; a shot 0.3 m past the corner occludes at 0.51 and 1.19 s)
            best = self._best_candidate(e, theta, rod=self._rod)
        if (
            best is None
            and long_rod
            and (first or heading is None)
            and self._steps >= self._via_next
        ):
            # no shot in a straight line on a long rod: one in two legs, first to the point
            # beside a convex corner near the evader, then a shot from there (issue 13:
            # random:polygons:7306, rho 0.2, L in [2, 6], a start the referee certifies
            # within 11.7 s, its evader 0.25 m south then east under an obstacle's corner
            # 0.2 m away: every straight path past the corner grazes it closer than the
            # body radius, and the evader walked a plan that promises nothing for 130 s).
            # Where there is none, looked for again a replan period later, as a shot is
            # (the first 200 steps of a tenth of unseen-e's episodes: 855 of 864 looks
            # found none, 0.39 ms each)
            via = self._via_corner(e, theta, snap.pursuer, self._rod)
            if via is None:
                self._via_next = self._steps + self.replan
            else:
                self.mode = "shoot"
                self._shot = (float(e[0]), float(e[1]), self._steps)
                self._track_targets.append(via)
                return c.v_evader * self._straight_arc(e, via)
        if best is not None:
            self.mode = "shoot"
            self._shot = (float(e[0]), float(e[1]), self._steps)
            self._track_targets.append(best[0])
            return c.v_evader * self._start_arc(e, theta, *best)
        if heading is not None:
            # no shot: back to the plan (and to the plan first, until the next dead end)
            if first:
                # the plan steers: the fallback's track starts again (a stall is counted
                # over the shots and the pressure since the plan last steered, not over
                # the plan's own steps: random:star:2017, rho 0.3, seed 849 banned the
                # target it shot at from a void plan, and the herd that escaped at
                # 385 s never began)
                self._track.clear()
                self._track_targets.clear()
            self._shoot_first = False
            self.mode = "plan"
            self._arc, self._in_sight = None, False
            return c.v_evader * heading
        walk = None if self.plan.in_witness_region(self._plan_cell) else self._region_walk(e)
        if walk is not None:
            # (in a witness region already, the walk only steps onto a grid point inside
            # its polygon: alternated with pressure at a wall, it held the evader in place
            # for the whole horizon, issue 13: office x0.5)
            self.mode = "region"
            return c.v_evader * walk
        self.mode = "pressure"
        # charge: straight at the pursuer minimises its best rotation rate (Sec. 6.1, the
        # toward/away strategy) and, with bounded speeds, herds it backwards into walls and
        # dead ends (Sec. 5); running away only ever leads into a corner. (Choosing toward
        # or away by the best candidate's side, as before, flipped every step and left the
        # evader in place.)
        u = unit(snap.rod)
        self._pressed += 1
        if self._pressed > self._herd_after and len(self._concave):
            # the charge made no end of it: pin the pursuer into its nearest concave
            # corner, where it cannot back off (issue 13: random:star:11 at rho 0.3
            # against the decomposition pursuer, 4,700 steps of charging in the open).
            # Wherever the pursuer is: the herd began only from a step where it came
            # within L_max of a concave corner, and a charge that keeps it in the open
            # never brings it there (issue 13: unseen random:rectangles:16, rho 0.3,
            # L in [2, 3], seed 1019 against the decomposition pursuer, whose only
            # concave corners are the room's four: charged and walked a plan that
            # promises nothing for the whole 8 D / V_e, the pursuer at least 4.2 from
            # every corner after the first 3 D / V_e; herding from HERD_AFTER, too
            # close at 5.97 D / V_e, as the corner herder of
            # benchmarks/unseen_opponents.py is from the same start at 0.59).
            # The gate was for random:star:11 seed 507, where herding from farther off
            # dragged the pursuer round the map (occluded at 6.54 D / V_e, 5.54 from
            # within L_min); there it now starts 18 steps earlier than the gate let it
            # (step 3,567), too close at 5.22 D / V_e either way
            self._herding = True
            # (no corner whose far side is in sight: charge)
            h = self._herd(e, snap.pursuer, u, float(snap.L))
            if h is not None:
                if self._near_wall(e, c.body_radius + 2.0 * c.v_evader * c.dt):
                    # pressed to a wall, as the charge below, the push is lost: the
                    # herd's target (the far side of the pursuer from the corner) can lie
                    # across a wall. Slide along it (issue 13: office at half scale, rho
                    # 0.3, seed 909 with the longer trail, 270 s pressed to a wall below
                    # a door with the pursuer in the door, to the end of the horizon)
                    h = self._along_wall(e, h, u)
                return c.v_evader * h
        if self._near_wall(e, c.body_radius + 2.0 * c.v_evader * c.dt):
            # against a wall the push is lost: slide along it, perpendicular to the rod
            # (which turns the rod fastest); the other way round where this one presses
            # straight into the wall, within 10 degrees of its normal (a step this way
            # ends 2 sin(80 deg) steps nearer the wall than a step the other way). A rod
            # along the wall left the evader pressing in place for the whole horizon
            # (issue 13: random:rectangles:11, a pursuer copying the evader's moves);
            # turning the slide at 30 degrees already lost escapes the slide made
            s = np.array([-u[1], u[0]])
            h = c.v_evader * c.dt
            d = self.map.distance_to_walls(np.stack([e + h * s, e - h * s]))
            return c.v_evader * (-s if d[1] - d[0] > _PRESSING * h else s)
        return c.v_evader * u

    def _near_banned(self, points: np.ndarray) -> np.ndarray:
        """Per point (rows of ``points``), whether it lies within the ban radius of a
        target given up after a stall (:meth:`_fallback_stalled`)."""
        if not len(self._banned):
            return np.zeros(len(points), dtype=bool)
        near = points[:, None, :] - self._banned[None, :, :]
        return np.einsum("ijk,ijk->ij", near, near).min(axis=1) <= self._ban_radius**2

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

    def _long(self, rod: float) -> bool:
        """Whether a rod of length ``rod`` is longer than the pursuer can close to L_min in
        a shot's replan period (at V_p + V_e): then a shot the disc can follow, its margin
        against the rod's length, goes first (see :meth:`_decide`)."""
        c = self.config
        return rod - (c.v_pursuer + c.v_evader) * self.replan * c.dt > c.l_min

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

    def _plan_heading(self, e: np.ndarray, theta: float) -> np.ndarray | None:
        """Heading of the guaranteed escape plan, or ``None`` if the cell is not escapable
        (or its vias cannot be crossed by the evader's disc).

        The configuration's cell in K_L (exact; ``None`` on a critical curve, where the
        last plan, if any, is kept for one step) and, if escapable, the crossing of one
        of its vias nearest to the evader (kept while the cell stays the same). Within
        one step of the crossing the evader heads straight across the piece.
        """
        plan = self.plan
        last = self._plan_cell
        if last >= 0 and not self._plan_lost and plan.well_inside(plan.dec.cells[last].region, e):
            cell = last  # same region, same cell (it changes only across a boundary piece)
        else:
            cell = plan.cell_at(e, theta)
        if cell < 0:
            cell = self._plan_cell
            if cell < 0 or self._plan_lost:
                return None
            self._plan_lost = True
        else:
            self._plan_lost = False
        step = self.config.v_evader * self.config.dt
        if cell != last:
            if last >= 0:
                # crossed from `last` through its witness piece: never straight back. Left
                # without a witness (no reachable crossing) it is on the trail too, so that
                # a cell whose plan only leads into such a cell and back is caught (A -> B
                # -> A) rather than alternated with for the whole episode (issue 13)
                piece = -1 if self._witness is None else self._witness.boundary
                self._came_through = (last, piece)
                self._trail.append((last, piece))
                back = [i for i, (c_, _) in enumerate(self._trail[:-1]) if c_ == cell]
                if back:
                    # back in a cell left a few crossings ago (A -> B -> A: two pieces at a
                    # junction, or either side of a region thinner than a step; or A -> B
                    # -> C -> A round witness-less cells, office x10 vs the referee): no
                    # crossing of the cycle made progress, so all of them are out
                    for c_, b_ in self._trail[back[-1] :]:
                        self._excluded.setdefault(c_, set()).add(b_)
                # n_cells + 1 crossings: among that many in a row some cell is entered
                # twice (pigeonhole), so a cycle of any length is caught. (A fixed 4, then
                # 16, were outrun on random:polygons:0: longer cycles against the
                # decomposition pursuer, then an exact 21-crossing loop for the rest of
                # the horizon against a stronger pursuer, issue 13)
                del self._trail[: -(len(self.plan.rank) + 1)]
            self._plan_cell = cell
            self._new_witness(cell, e)
        elif self._witness is not None:
            gap = float(np.linalg.norm(self._witness.target - e))
            if gap < self._best_gap - 0.25 * step:
                self._best_gap, self._stall = gap, 0
            else:
                self._stall += 1
            if self._stall >= self.STALL_STEPS:  # not getting closer: that crossing is out
                self._excluded.setdefault(cell, set()).add(self._witness.boundary)
                self._new_witness(cell, e)
        if (
            self._witness is None
            and plan.rank[cell] >= 0
            and (cell in self._excluded or self._came_through)
        ):
            # an escapable cell whose every usable crossing is excluded (stalls and cycles
            # add up over an episode): the fallback alone made no progress there for the
            # whole horizon (issue 13: two_rooms turned by 2.2 rad at L_min 1, L_max 1.5,
            # rho 0.5: 4,600 steps of pressure). After FORGIVE_STEPS of it, forget this
            # cell's exclusions and the way back and try its plan again; the trail and the
            # other cells' exclusions stay (a cycle it re-enters is caught again), and each
            # retry waits twice as long as the last (a fallback that escapes keeps its time)
            self._no_way += 1
            if self._no_way >= self.FORGIVE_STEPS << self._forgiven:
                self._excluded.pop(cell, None)
                self._came_through = None
                self._new_witness(cell, e)
                self._no_way, self._forgiven = 0, self._forgiven + 1
        else:
            self._no_way = 0
        w = self._witness
        if (
            w is None
            and not self._shoot_first
            and plan.rank[cell] >= len(plan.rank)
            and plan.witness(cell, e, self.config.body_radius) is None
        ):
            # a dead end: the cell's rank counts a crossing the disc cannot make and no
            # crossing of its vias keeps the disc clear. Its plan (and that of the cells
            # ranked through it) promises nothing: shoot first from here on. (Falling back
            # to a shot here and back to the plan in the next cell, whose plan led straight
            # back, the evader went round the chain for the whole horizon, issue 13:
            # two_rooms~x1.6rot-2.5 at L_min 1.6, rho 0.5, against the decomposition
            # pursuer, every route through a corridor end closer to a door jamb than the
            # evader's body radius.)
            self._shoot_first = True
        if w is None:
            return None
        if np.linalg.norm(w.cross - e) <= step:
            # land just across the piece (slower if need be), not a step past it: the
            # region across can be thinner than a step (office: 0.03), and a step past
            # it lands in the next one, whose plan leads back (issue 13)
            to = w.target - e
            gap = float(np.linalg.norm(to))
            if gap > 1e-3 * step and float(to @ w.normal) > 0.0:  # not past it yet
                return to / max(gap, step)
            return w.normal.copy()
        u = unit(w.target - e)
        # keep the walk inside the region: a straight one can leave it across another
        # piece, into a cell of any rank (a sliver along the piece just crossed, or a
        # crossing out of sight, issue 13); turn the heading as little as keeps the next
        # step inside
        reg = self.plan.dec.cells[cell].region
        if self.plan.well_inside(reg, e + step * u):
            return u
        a, f = _TURNS[:, 0], _TURNS[:, 1]
        h = np.stack([np.cos(a) * u[0] - np.sin(a) * u[1], np.sin(a) * u[0] + np.cos(a) * u[1]], 1)
        move = f[:, None] * h
        ok = np.flatnonzero(self.plan.well_inside_many(reg, e + step * move))
        return move[ok[0]] if len(ok) else u

    def _new_witness(self, cell: int, e: np.ndarray) -> None:
        """Choose the crossing for ``cell``, leaving out excluded pieces and the way back."""
        exclude = set(self._excluded.get(cell, ()))
        if self._came_through is not None:
            # the piece just crossed, seen from the new side, leads back: skip it
            exclude.add(self._came_through[1])
        c = self.config
        # a crossing at least a step from the piece's ends if there is one: the last step,
        # from up to a step away, must cross that piece, not a neighbour (issue 13:
        # random:convex:1, along the normal from a piece's end into a rank-39 cell)
        exclude = frozenset(exclude)
        self._witness = self.plan.witness(
            cell, e, c.body_radius, exclude=exclude, margin=c.v_evader * c.dt
        ) or self.plan.witness(cell, e, c.body_radius, exclude=exclude)
        self._best_gap, self._stall = math.inf, 0

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
            step = capped_step(dist, L, self.rho) if dist > 0.0 else None
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


class _CornerLook:
    """A convex corner's point as the end of a two-leg shot's first leg: the candidates
    from there, their table rows, the clearance the second leg keeps
    (:meth:`ShootingEvader._disc_candidate`'s floor) and, per candidate, whether the
    evader's disc follows the straight path to it (-1 until asked)."""

    __slots__ = ("cand", "floor", "reached", "rows")

    def __init__(self, cand: np.ndarray, rows: np.ndarray, floor: float) -> None:
        self.cand, self.rows, self.floor = cand, rows, floor
        self.reached = np.full(len(cand), -1, dtype=np.int8)


def herd_corners(m, min_turn: float) -> np.ndarray:
    """Indices of ``m``'s concave vertices (``Map.vertex_convex`` false) whose two walls'
    normals turn by at least ``min_turn`` degrees: 90 at a rectangle's corner, 180 minus
    the interior angle in general."""
    idx = np.flatnonzero(~m.vertex_convex)
    a = m.edge_normal[m.vertex_prev_edge[idx]]
    b = m.edge_normal[m.vertex_next_edge[idx]]
    cos = np.clip(np.einsum("ij,ij->i", a, b), -1.0, 1.0)
    return idx[cos <= math.cos(math.radians(min_turn)) + 1e-12]


def _most_turn(closing: float, rod: float, l_min: float, t: float) -> float:
    """The most a rod of length ``rod`` turns in ``t`` seconds at eq. (6)'s largest rate,
    ``closing / L`` (``closing`` = V_p + V_e), the rod shortening at ``closing`` down to
    ``l_min``: ``ln(rod / L(t))`` while it shortens, ``closing / l_min`` a second after."""
    t_short = max(0.0, rod - l_min) / closing  # when it reaches l_min
    if t <= t_short:
        return math.log(rod / (rod - closing * t))
    return math.log(rod / l_min) + closing * (t - t_short) / l_min


def _row_norms(d: np.ndarray) -> np.ndarray:
    """``np.linalg.norm(d, axis=1)`` of real (n, 2) rows: the same floats (it computes
    ``sqrt(add.reduce(d * d, axis=1))``), without its dispatch."""
    return np.sqrt(np.add.reduce(d * d, axis=1))


def _arc_lengths(path: np.ndarray) -> np.ndarray:
    """Arc length along ``path`` at each of its points (0 at the first)."""
    return np.cumsum(np.concatenate(([0.0], _row_norms(np.diff(path, axis=0)))))
