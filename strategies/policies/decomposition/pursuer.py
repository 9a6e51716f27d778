"""The decomposition-based pursuer (Secs. 4-5): keep the rod in admissible safe cells at L_min.

Per step (a table lookup plus a little arithmetic; a geometry kernel call only on the rare
steps the table reads the rod's own orientation as blocked, :func:`crossable_steps`):

1. From the :class:`~strategies.policies.safety.SafetyTable` (safe = free and not in an
   escapable cell at L_min, Sec. 4), the rotation each orientation bin needs to reach a
   safe orientation at every probe point the evader can reach soon: probes lie on rays
   from the evader, up to ``V_e T`` with ``T = pi / omega`` (the time to turn the rod half
   way round), and a ray stops at the first wall it meets. An evader hugging a wall
   toward a convex corner is probed round that corner too, on rays from where it rounds
   it, and round the next corner if the wall it rounds onto ends in one
   (:meth:`DecompositionPursuer._corners_in_reach`); an evader walking round an
   obstacle small enough to circle is probed round every corner of the walk within
   reach (:meth:`DecompositionPursuer._walk_corners`).
2. The value of each orientation (eqs. 2-3 with a straight-line evader and the pursuer
   turning at ``omega = (V_p / L_min) sqrt(1 - rho^2)``, the least rate the evader can
   impose, Sec. 6.1)::

       V(theta) = min over probes p of  t_e(p) - turn(theta -> safe(p)) / omega

   ``V = 0`` means admissible: the rod reaches a safe orientation at every probe before
   the evader does. The pursuer targets the bin maximising V within the *free arc* it is
   in (the rod can only rotate through free orientations), minus a small penalty for the
   rotation needed, and turns the shorter way round inside that arc.
3. The velocity is the evader's velocity plus the perpendicular component that realises the
   commanded rotation rate (eq. 5), plus a radial correction of L toward L_min, all within
   V_p (:func:`strategies.control.kinematics.pursuer_velocity_holding_range`).
4. While the evader closes in along the rod, the rotation keeps room to circle it
   (issue 13): charged, the pursuer holds L only by backing off, and turning as fast as
   it can it runs on a circle of radius ``L / sqrt(1 - rho^2)``. Where going on would
   leave no such circle free of walls, it turns hard round one that is (or nearly is),
   instead of being pushed into a wall or down a dead end and pinned closer than L_min
   (:meth:`DecompositionPursuer._keep_orbit`). Where no circle is even nearly free, it
   at least turns the way whose path stays clear of walls for a while, if the one it
   settled on meets one. An evader walking at the wall behind the pursuer without
   charging gets the same check (:meth:`DecompositionPursuer._avoid_pin`), unless it
   reversed its velocity on each of the last two steps: the check extrapolates that
   velocity, and such an evader keeps none (a herder at a corner's bisector). Against a
   charge, the wall-path check does not turn the rod back toward the normal of a wall
   within L when the rod lies within ``asin(rho)`` of it and the decomposition turns it
   away: there the charge closes in on a pursuer sliding along the wall
   (:meth:`DecompositionPursuer._off_the_normal`). A swing toward a circle does not
   either, at a straight wall, when the evader herded within the last second (crossed
   the rod toward that normal on a step it did not charge: its charge does not follow
   the rod into the circle), charges by pure pursuit now, and the slide through the
   normal would end closer than L_min while the near way would not.
5. Near a wall that faces it along the rod, it holds the distance longer by the
   evader's overlap with that wall, which the physics gives back in one step when the
   evader turns away (:meth:`DecompositionPursuer._wall_push`).
6. On a lap round an obstacle small enough to circle (a lap no longer than the rod's
   full turn), the rod turns the walk's way up to the far end of its free arc instead of
   idling at the decomposition's target (:meth:`DecompositionPursuer._walk_lead`).

This module holds the class: its parameters, its setup per map (``_reset``) and its
decision (``_decide``). The steps live beside it, each module a part of the class (a
base it inherits): the values and the target (steps 1-2,
:mod:`~strategies.policies.decomposition.values`), the corner probes and the lead on a lap
(1 and 6, :mod:`~strategies.policies.decomposition.corners`), orbit keeping (4,
:mod:`~strategies.policies.decomposition.orbit`), the wall and slide checks and the wall
push (4-5, :mod:`~strategies.policies.decomposition.walls`), the charge test (4,
:mod:`~strategies.policies.decomposition.charge`) and the grid's wall distances they read
(:mod:`~strategies.policies.decomposition.clearance`).
"""

from __future__ import annotations

import math
from collections import deque

import numpy as np

from envs import validation
from strategies.control.kinematics import _holding_range, _theta_dot_rates
from strategies.policies.base import (
    MAX_RAYS,
    BasePolicy,
    Snapshot,
    count_param,
    distance_ceiling,
    distance_target,
    nonnegative_param,
    positive_param,
    rounded_length,
)
from strategies.policies.decomposition.charge import _ChargeReading
from strategies.policies.decomposition.clearance import _clearance_grid, _Clearances, _room_field
from strategies.policies.decomposition.corners import (
    _corner_neighbours,
    _corner_starts,
    _CornerProbes,
    _rounding_corners,
    _small_obstacles,
)
from strategies.policies.decomposition.orbit import _OrbitKeeping
from strategies.policies.decomposition.values import _OrientationValues
from strategies.policies.decomposition.walls import _WallChecks
from strategies.policies.lazy_table import LAZY_POINTS, LazySafetyTable
from strategies.policies.safety import NO_PATH, SafetyTable, _points_at, safety_table

__all__ = ["DecompositionPursuer"]


class DecompositionPursuer(
    _OrientationValues,
    _CornerProbes,
    _OrbitKeeping,
    _WallChecks,
    _ChargeReading,
    _Clearances,
    BasePolicy,
):
    """Pursuer that keeps the configuration in admissible, non-escapable cells at L_min.

    Args:
        resolution: grid spacing of the safety table (default L_min / 20: no unit dependence).
        n_bins: orientation bins of the table.
        rays: probe rays around the evader.
        probe_every: use every k-th grid sample along a ray as a probe.
        hysteresis: weight of the rotation needed to reach a target, in units of V.
        distance_gain: rate (1/s) of the correction of L toward L_min; at most
            ``1 / dt`` is used (a larger rate corrects more than the error in one step).
        range_margin: extra distance held above the minimal one, as a fraction of
            ``L_max - L_min`` (default 0: ride at L_min plus a one-step buffer, as the
            paper). A margin trades some of the rod's freedom (a longer rod has fewer
            free orientations, Prop. 3) for slack against imprecise execution, e.g. for
            a learner imitating this policy. The distance held is at most L_max less
            the one-step buffer (``base.distance_ceiling``): with ``range_margin`` 1 it
            aimed beyond L_max.
        turn_rate: the rotation rate the evader is assumed to impose (eq. 6, Sec. 6.1):
            ``"both"``, ``(V_p / L) sqrt(1 - rho^2)``, the least rate when the rod may
            turn either way; ``"one"``, ``(V_p / L)(1 - rho)``, the least rate in one
            given direction (conservative: what the start sampler judges with).
        table: ``"eager"`` (the whole map's safety table, built once and cached on
            disk), ``"distinct"`` (the same table with each distinct row stored once,
            classified in vectorised batches: ``safety_table(..., distinct=True)``),
            ``"lazy"`` (classified around the evader as it goes, for large maps:
            ready at once, memory grows with the area visited) or ``"auto"``
            (distinct up to :attr:`DISTINCT_TABLE_POINTS` grid points, lazy above;
            eager up to :attr:`EAGER_TABLE_POINTS`, none by default). An eager build
            costs about 0.1 ms a point, a distinct one about 15 us, once per map and rod
            length (cached on disk); a lazy table
            classifies the points new to each step's probes, 5-8 ms a step on the
            built-in maps at L_min = 0.5, issue 13).
    """

    roles = ("pursuer",)
    # grid points up to which "auto" builds the point-by-point table: none, since the
    # distinct build gives the same rows about 13x faster in a tenth of the memory
    # (pillar room at L_min 1: 1.4 s, 6.5 MB against 18 s, 61 MB); "eager" stays on call
    EAGER_TABLE_POINTS = 0
    DISTINCT_TABLE_POINTS = LAZY_POINTS  # grid points above which "auto" fills it lazily
    CLOSING = 0.3  # share of V_p kept for closing in while L exceeds its target
    ORBIT_LOOKAHEAD = 1.0  # seconds of the charge a candidate rate is followed for
    ORBIT_REACH = 0.3  # a circle short of room by less than this x L is worth turning for
    CHARGE_ENTER = 0.5  # cos of the angle off the rod within which the evader charges
    CHARGE_EXIT = math.cos(math.radians(70.0))  # ... and, against a chatter, keeps charging
    CHATTER_ROD = math.radians(2.0)  # the rod "stands still" between two entries of the test
    CHATTER_HEADING = math.radians(0.25)  # the evader's heading "stands still" meanwhile
    LOOKAHEAD_STEPS = 4  # steps of the evader's probes a lazy table classifies ahead (below)
    CLEAR_BLOCK_BITS = 2  # a lazy table's clearances are measured 4 x 4 nodes at a time
    WALL_HORIZON = 2.0  # seconds the pursuer's path is checked for walls (no circle in reach)
    WALL_STEP = 0.1  # spacing in seconds of the points checked on that path
    CHARGE_PERSIST = 3.0  # seconds a charge has lasted before a slide's loss is believed
    CORNER_HUG = 2  # grid steps of clearance beyond its body within which the evader hugs a wall
    CORNER_HEADING = 0.9  # least cosine between the evader's heading and a corner it rounds
    LEAD_MARGIN = 4  # bins the rod keeps off its free arc's leading end on a lap (_walk_lead)

    def __init__(
        self,
        *,
        resolution: float | None = None,
        n_bins: int = 144,
        rays: int = 16,
        probe_every: int = 3,
        hysteresis: float = 0.25,
        distance_gain: float = 3.0,
        range_margin: float = 0.0,
        turn_rate: str = "both",
        table: str = "auto",
        name: str | None = None,
    ) -> None:
        super().__init__(name=name)
        self.resolution = None if resolution is None else positive_param("resolution", resolution)
        self.n_bins = count_param("n_bins", n_bins, 8, NO_PATH - 1)
        self.rays = count_param("rays", rays, 4, MAX_RAYS)
        self.probe_every = count_param("probe_every", probe_every, 1, MAX_RAYS)
        self.hysteresis = nonnegative_param("hysteresis", hysteresis)
        self.distance_gain = positive_param("distance_gain", distance_gain)
        self.range_margin = validation.unit_interval("range_margin", range_margin, open=False)
        self.turn_rate = validation.choice("turn_rate", turn_rate, ("both", "one"))
        self.table_kind = validation.choice("table", table, ("auto", "eager", "distinct", "lazy"))

    def _reset(self) -> None:
        c = self.config
        # no farther than the buffer below L_max (range_margin 1 aimed at L_max plus the
        # buffer; a band narrower than twice the buffer: at its middle, distance_target)
        self._L_ceiling = distance_ceiling(c)
        margin = self.range_margin * (c.l_max - c.l_min)
        self.L_target = min(distance_target(c) + margin, self._L_ceiling)
        # a correction of gain * (L - L_target) held for dt moves L by gain * dt times the
        # error: past 1 it overshoots, past 2 the error grows step by step (the default
        # gain 3 at dt 1: 26 of 48 valid starts lost, too close and too far by turns;
        # at 1 / dt: 3)
        self._gain = min(self.distance_gain, 1.0 / c.dt)
        # the pursuer's disc keeps its centre body_radius off the walls, so the rod tip
        # meets a wall as if the rod were that much longer (Prop. 3: fewer free arcs)
        self.table_length = rounded_length(self.L_target + c.body_radius)
        res = self.resolution if self.resolution is not None else c.l_min / 20.0
        kind = self.table_kind
        if kind == "auto":
            points = _points_at(c.map.free_region.area, res)
            kind = "eager" if points <= self.EAGER_TABLE_POINTS else "distinct"
            kind = "lazy" if points > self.DISTINCT_TABLE_POINTS else kind
        if kind == "lazy":
            self.table = LazySafetyTable(c.map, self.table_length, res, self.n_bins)
        else:
            self.table = safety_table(
                c.map, self.table_length, res, self.n_bins, distinct=kind == "distinct"
            )
        rho = c.rho
        # Sec. 6.1, eq. (6): the evader can hold the pursuer's rate down to
        # (V_p/L) sqrt(1 - rho^2) when the pursuer may turn either way (it takes the
        # faster), but to (V_p/L)(1 - rho) in one given direction: the rate to assume when
        # only one way round is safe ("one"; the start sampler's conservative judge)
        if self.turn_rate == "one":
            self.omega = c.v_pursuer * max(1.0 - rho, 0.05) / c.l_min
        else:
            self.omega = c.v_pursuer * math.sqrt(max(1.0 - rho * rho, 0.05)) / c.l_min
        self.horizon = horizon = math.pi / self.omega
        h = self.table.resolution
        n_r = max(2, math.ceil(c.v_evader * horizon / h))
        # a ray stops at its first sample off the table's grid, and from a point of the
        # grid every sample past the grid's diagonal is off it: a slow pursuer's long
        # horizon adds only samples never reached (v_pursuer = 1e-6: 150 GiB of them)
        n_r = min(n_r, math.ceil(math.hypot(*self.table.shape)) + 2)
        radii = h * np.arange(1, n_r + 1)
        ang = 2.0 * math.pi * np.arange(self.rays) / self.rays
        dirs = np.stack([np.cos(ang), np.sin(ang)], axis=1)
        self._offsets = (dirs[:, None, :] * radii[None, :, None]).reshape(-1, 2)
        self._dirs = dirs
        self._n_r = n_r
        self._probe_cols = np.arange(self.probe_every - 1, n_r, self.probe_every)
        self._t_e = (radii[self._probe_cols] / c.v_evader).astype(np.float32)
        self._bw = self.table.bin_width
        lut = np.arange(NO_PATH + 1) * self._bw / self.omega
        lut[NO_PATH] = math.pi / self.omega  # no safe orientation: half a turn
        lut[0] = -1e9
        self._turn_lut = lut.astype(np.float32)
        # one way round (the corner probes' ccw or cw counts, up to n_bins - 1 bins): no
        # safe orientation is a full turn, more than any turn that way, as NO_PATH is
        # more than any shorter-way turn above
        lut[NO_PATH] = 2.0 * math.pi / self.omega
        self._way_lut = lut.astype(np.float32)
        nb = self.table.n_bins
        # :meth:`_probe_values` takes the largest rotation over the probes at one radius
        # before the lookup: exact when each lookup is non-decreasing over the counts a
        # table holds (0 .. n_bins // 2 the shorter way round, 0 .. n_bins - 1 one way, or
        # NO_PATH), which it is unless rounding says otherwise; on an eager table with
        # one lookup of every ray sample (the fast path)
        held = self._turn_lut[np.r_[np.arange(nb // 2 + 1), NO_PATH]]
        way = self._way_lut[np.r_[np.arange(nb), NO_PATH]]
        self._monotone = bool(np.all(np.diff(held) >= 0) and np.all(np.diff(way) >= 0))
        self._fast = isinstance(self.table, SafetyTable) and self._monotone
        # the penalty of turning k bins, as _target's score needs it (same float ops)
        self._turn_penalty = self.hysteresis * np.arange(nb + 1.0) * self._bw / self.omega
        self.last_target: int | None = None
        # the orbit test (:meth:`_orbit_margins`), for rho < 1
        self._clear = None  # (nx, ny) wall distances of the grid nodes (eager tables)
        self._clear_memo: dict[tuple[int, int], float] | None = None  # the lazy ones'
        if rho < 1.0:
            if isinstance(self.table, SafetyTable):
                self._clear = _clearance_grid(c.map, self.table)
            else:
                self._clear_memo = {}
        root = math.sqrt(max(1.0 - rho * rho, 1e-12))
        self._orbit_k = rho / root  # radius of the evader's circle, per unit of L
        self._orbit_R = 1.0 / root  # radius of the pursuer's circle, per unit of L
        # the cone round a wall's normal where a charge closes in on a pursuer sliding
        # along the wall (:meth:`_off_the_normal`)
        self._cone = math.asin(min(rho, 1.0))
        # the evader's last ORBIT_LOOKAHEAD seconds of motion across the rod, on the steps
        # it did not charge: (rod orientation, across speed) (:meth:`_herded`)
        self._crossings: deque[tuple[float, float] | None] = deque(
            maxlen=max(1, round(self.ORBIT_LOOKAHEAD / c.dt))
        )
        # the evader's velocity estimates of the last two steps (:meth:`_chatters`)
        self._velocities: deque[tuple[float, float]] = deque(maxlen=2)
        self._orbit_pad = c.body_radius + h  # + a grid step: the margin is read on the grid
        # the geodesic distance of a circle's centre to room (:meth:`_keep_orbit`), at
        # the held distance; eager tables only (a lazy one has no whole-map grid)
        self._field = None
        self._stalled = False  # a ride round a circle short of room stalled (_keep_orbit)
        # the charge test's hysteresis against a walk the rod chatters across
        # (:meth:`_charge_test`): charging last step, the hysteresis armed, and the last
        # ORBIT_LOOKAHEAD seconds of (test passed, rod orientation, evader heading)
        self._charging = False
        self._charge_armed = False
        # steps the charge test has passed in a row, and how many make a long charge
        # (:meth:`_slide_through`)
        self._charge_run = 0
        self._decisions = 0  # decisions so far (the first has no velocity estimate)
        self._charge_persist = round(self.CHARGE_PERSIST / c.dt) + 1
        self._armed_heading = 0.0
        self._charge_log: deque[tuple[bool, float, float]] = deque(
            maxlen=max(1, round(self.ORBIT_LOOKAHEAD / c.dt))
        )
        # the ride's last ORBIT_LOOKAHEAD seconds: (turning ccw, the ridden circle's way
        # to room, the other circle's, the ridden circle's shortfall)
        self._ridden: deque[tuple[bool, float, float, float]] = deque(
            maxlen=max(2, round(self.ORBIT_LOOKAHEAD / c.dt) + 1)
        )
        if self._clear is not None:
            need = self._orbit_R * self.L_target + self._orbit_pad
            self._field = _room_field(c.map, self.table, round(need, 9))
        self._wall_times = np.arange(1, round(self.WALL_HORIZON / self.WALL_STEP) + 1) * (
            self.WALL_STEP
        )
        # probes round the corners (issue 13, :meth:`_corners_in_reach`)
        corners = _rounding_corners(c.map)
        self._corners, self._corner_vertex = _corner_starts(c.map, corners, c.body_radius)
        self._corner_next, self._corner_in = _corner_neighbours(c.map, corners)
        # obstacles small enough to circle, and their corners along the walk round them
        # (:meth:`_walk_corners`): within the evader's circle at the rod's least rate
        self._small = _small_obstacles(c.map, corners, 2.0 * math.pi * c.v_evader / self.omega)

    def _decide(self, snap: Snapshot) -> np.ndarray:
        c = self.config
        L = max(snap.L, 1e-9)
        ve = snap.evader_velocity
        speed = math.hypot(float(ve[0]), float(ve[1]))
        rot, _ = self._target(snap)
        alpha = math.atan2(float(ve[1]), float(ve[0])) if speed > 0 else snap.theta
        rate = min(speed / c.v_pursuer, 1.0)
        # eq. (6) and the command, on inputs checked already (theta_dot and
        # pursuer_velocity_holding_range without their argument checks)
        hi, lo = _theta_dot_rates(alpha - snap.theta, L, float(c.v_pursuer), rate)
        hi, lo = float(hi), float(lo)
        L_target = min(self.L_target + self._wall_push(snap), self._L_ceiling)
        closing = min(self._gain * (L - L_target), self.CLOSING * c.v_pursuer)
        if closing > 0.0:
            # the rod is longer than the table's (fewer free orientations, Prop. 3: the
            # table may call an orientation clear that is not): keep part of the speed
            # for closing in instead of spending it all on the rotation, which would let
            # L drift with the evader's radial motion. Eq. (6)'s interval and this one
            # are both centred on the rate that matches the evader's motion across the
            # rod; the narrower wins (this one when the evader is not charging)
            u = (math.cos(snap.theta), math.sin(snap.theta))
            along = float(ve[0]) * u[0] + float(ve[1]) * u[1]
            across = float(ve[1]) * u[0] - float(ve[0]) * u[1]
            budget = math.sqrt(max(c.v_pursuer**2 - (along - closing) ** 2, 0.0))
            hi = min(hi, (budget - across) / L)
            lo = max(lo, (-budget - across) / L)
        want = rot / (2.0 * c.dt)
        cmd_rate = min(max(want, lo), hi)
        if self._clear is not None or self._clear_memo is not None:
            u = (math.cos(snap.theta), math.sin(snap.theta))
            charging = self._charge_test(snap, float(ve[0]), float(ve[1]), speed)
            # the rod turns at -across / L from the evader's motion
            across = float(ve[1]) * u[0] - float(ve[0]) * u[1]
            self._crossings.append(None if charging or speed == 0.0 else (snap.theta, across))
            self._charge_run = self._charge_run + 1 if charging else 0
            self._decisions += 1
            if charging:  # it closes in
                cmd_rate = self._keep_orbit(snap, cmd_rate, hi, lo, L)
            else:
                self._stalled = False
                self._ridden.clear()
                if speed > 0.0:
                    cmd_rate = self._avoid_pin(snap, cmd_rate, hi, lo, L)
        self._velocities.append((float(ve[0]), float(ve[1])))
        cmd = _holding_range(
            np.asarray(ve, dtype=np.float64),
            snap.theta,
            cmd_rate,
            L,
            L_target,
            float(c.v_pursuer),
            self._gain,
        )
        return cmd.velocity
