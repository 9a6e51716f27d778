"""The decomposition pursuer's orientation values and target: its use of the safety table.

Steps 1-2 of the decision (:mod:`strategies.policies.decomposition.pursuer`): from the
:class:`~strategies.policies.safety.SafetyTable` (safe = free and not in an escapable cell
at L_min, Sec. 4), the value of each orientation bin against a straight-line evader
(eqs. 2-3, the rod turning at the least rate the evader can impose, Sec. 6.1), the probes
on rays from the evader that it is the least margin over, and the target bin within the
rod's free arc (:func:`reachable_steps`), with the real rod's room where the table reads
the rod's own bin as blocked (:func:`crossable_steps`).
"""

from __future__ import annotations

import math

import numpy as np

from envs.geometry import kernel_for
from strategies.policies.base import Snapshot
from strategies.policies.lazy_table import LazySafetyTable


class _OrientationValues:
    """The value of every orientation (eqs. 2-3) and the target the rod turns to.

    A part of :class:`~strategies.policies.decomposition.pursuer.DecompositionPursuer`:
    it reads the pursuer's constants and the state its ``_reset`` sets.
    """

    def orientation_values(self, evader: np.ndarray) -> np.ndarray:
        """V(theta) for every orientation bin at evader position ``evader`` (seconds).

        The least time margin ``t_e(p) - turn(theta -> safe(p)) / omega`` over the probes
        ``p`` where ``theta`` is not safe; the horizon where no probe threatens ``theta``,
        and ``-turn / omega`` (negative) where ``theta`` is not safe at ``evader`` itself.
        """
        row = self.table.row(evader)
        if row < 0:
            return np.zeros(self.table.n_bins)
        return self._values(evader, row)

    def _values(
        self, evader: np.ndarray, row: int, velocity: np.ndarray | None = None
    ) -> np.ndarray:
        """:meth:`orientation_values` at a free grid row ``row`` of ``evader``; given the
        evader's ``velocity`` (the decision, :meth:`_target`), with the probes round the
        corners it is about to round (:meth:`_corners_in_reach`). Without it (the start
        sampler's judge, the learners' table features) the values are as before."""
        tab = self.table
        value = np.full(tab.n_bins, self.horizon)
        step = None if velocity is None else self.config.dt * np.asarray(velocity, dtype=float)
        value = np.minimum(value, self._probe_values(evader, step=step))
        if velocity is not None:
            for start, delay, shadow, sense in self._corners_in_reach(evader, velocity):
                value = np.minimum(value, self._probe_values(start, delay, shadow, sense))
        need0 = tab.need[row]
        return np.where(need0 > 0, -self._turn_lut[need0], value)

    def _probe_values(
        self,
        origin: np.ndarray,
        delay: float = 0.0,
        rays: np.ndarray | None = None,
        sense: int = 0,
        step: np.ndarray | None = None,
    ) -> np.ndarray:
        """The least margin over the probes on rays from ``origin`` (see above); the
        evader reaches ``origin`` itself after ``delay`` seconds (probes beyond the horizon
        then drop out), only the rays ``rays`` (bool, per ray) count if given, and the
        rotation is counted ccw (``sense`` > 0) or cw (< 0) only if given (a probe with
        no safe orientation then counts as a full turn, more than any turn that way).

        ``step``: the evader's displacement a step (a lazy table then classifies the
        probes of its next ``LOOKAHEAD_STEPS`` steps along it with this one's new nodes:
        the same values, fewer classification batches)."""
        tab = self.table
        offsets, n_rays, n_r = self._offsets, self.rays, self._n_r
        cols, t_e = self._probe_cols, self._t_e
        if delay:  # probes beyond the horizon drop out: only the samples up to the last
            # probe within it are looked up (a ray's reach there depends on those alone)
            t_e = t_e + np.float32(delay)
            n_in = int(np.count_nonzero(t_e <= self.horizon))  # t_e rises along a ray
            if not n_in:
                return np.full(tab.n_bins, self.horizon)
            cols, t_e = cols[:n_in], t_e[:n_in]
            n_r = int(cols[-1]) + 1
        if rays is not None or n_r < self._n_r:  # only those rays' samples (the others
            # would count as safe), up to n_r along each
            keep = slice(None) if rays is None else rays
            offsets = offsets.reshape(self.rays, self._n_r, 2)[keep, :n_r].reshape(-1, 2)
            n_rays = self.rays if rays is None else int(rays.sum())
        points = origin + offsets
        if self._fast:
            # eager table: one lookup of every ray sample serves as the wall test and
            # as the probes' rows
            rows = tab.rows(points).reshape(n_rays, n_r)
            reach = np.logical_and.accumulate(rows >= 0, axis=1)  # stop at the first wall
            sub_ok = reach[:, cols]
            if not sub_ok.any():
                return np.full(tab.n_bins, self.horizon)
            # the probes of one radius share t_e, and t_e - lut[k] falls as k grows (the
            # lookup is non-decreasing, rounding is monotone), so per radius only the
            # largest need over its reached probes counts; an unreached probe counts as
            # safe (need 0: t_e + 1e9, never below the first radius's value)
            needs = tab.need if not sense else (tab.ccw if sense > 0 else tab.cw)
            need = needs[rows[:, cols]]  # (rays, radii, bins)
            need[~sub_ok] = 0
            need = need.max(axis=0)
            v = t_e[:, None] - (self._way_lut if sense else self._turn_lut)[need]
            return v.min(axis=0)
        # a lazy table: the nodes of the next steps' probes along the evader's step join
        # the batches of this one's new nodes
        lazy = isinstance(tab, LazySafetyTable)
        ahead = (step, self.LOOKAHEAD_STEPS) if lazy and step is not None else ()
        if lazy:  # (with the points' grid nodes, for the probes' rows)
            inside, nodes = tab.inside(points, *ahead, nodes=True)
        else:
            inside, nodes = tab.inside(points), None
        # a ray stops at the first wall
        reach = np.logical_and.accumulate(inside.reshape(n_rays, n_r), axis=1)
        sub_ok = reach[:, cols]
        if not sub_ok.any():
            return np.full(tab.n_bins, self.horizon)
        at = np.arange(len(points)).reshape(n_rays, n_r)[:, cols][sub_ok]
        # only the probes' orientations are looked up (their nodes: the lookup's above)
        if nodes is None:
            r = tab.rows(points[at])
        else:
            r = tab.rows(points[at], *ahead, nodes=tab.nodes_at(nodes, at))
        # lut: seconds to turn by a number of bins; a safe bin (0) never threatens
        needs = tab.need if not sense else (tab.ccw if sense > 0 else tab.cw)
        lut = self._way_lut if sense else self._turn_lut
        if self._monotone:  # the largest rotation per radius, as the fast path
            need = np.zeros((*sub_ok.shape, tab.n_bins), dtype=needs.dtype)
            need[sub_ok] = needs[r]
            v = t_e[:, None] - lut[need.max(axis=0)]
            return v.min(axis=0)
        t_e = np.broadcast_to(t_e, sub_ok.shape)[sub_ok]
        v = t_e[:, None] - lut[needs[r]]
        return v.min(axis=0)

    def _target(self, snap: Snapshot) -> tuple[float, int]:
        """Signed rotation (radians) toward the best reachable orientation, and its bin.

        Where the table leaves the rod no room to turn one way at the evader's grid row,
        the orientations free at its row one step ahead (``E + v dt``) count as free too:
        the rod turns during the step while the evader walks on. Rounding a wall's end the
        evader opens the far side a row later, and the rod idled that step (maze, wall
        hugger, seed 4: at 9.0 s the clockwise arc was shut by the wall behind the
        pursuer and 82 bins open a step later; the swing over the end came about a degree
        short, occluded at 11.7 s). The row ahead at every step (alone, or added to the
        current one) changed other episodes: two pillar-room losses, or four escapes of
        the shooting evader on random:convex:1 that no longer happened.
        """
        tab = self.table
        row = tab.row(snap.evader)
        b0 = tab.bin_of(snap.theta)
        if row < 0:
            return 0.0, b0
        value = self._values(snap.evader, row, snap.evader_velocity)
        free = tab.free[row]
        nb = tab.n_bins
        room: list[tuple[float, float] | None] = []  # the real rod's room, computed once

        def steps_from(free: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            ccw, cw = reachable_steps(free, b0)
            if free[b0] or not ccw.size or not cw.size:
                return ccw, cw
            if not room:
                room.append(self._rod_room(snap))
            if room[0] is None:
                return ccw, cw
            return crossable_steps(ccw, cw, b0, snap.theta, self._bw, room[0])

        ccw_steps, cw_steps = steps_from(free)
        # pinned one way: no clockwise step, or no counter-clockwise one (ccw_steps also
        # holds 0, staying at b0, when b0 is free)
        if not cw_steps.size or not (ccw_steps > 0).any():
            ahead = tab.row(snap.evader + self.config.dt * snap.evader_velocity)
            if ahead >= 0 and ahead != row:  # pinned one way here: the row ahead as well
                free = free | tab.free[ahead]
                ccw_steps, cw_steps = steps_from(free)
        if not ccw_steps.size and not cw_steps.size:
            return 0.0, b0
        lead = self._walk_lead(snap, ccw_steps, cw_steps)
        if lead is not None:
            ccw_steps, cw_steps = lead
        cand_bins = np.concatenate([(b0 + ccw_steps) % nb, (b0 - cw_steps) % nb])
        steps = np.concatenate([ccw_steps, cw_steps])
        score = value[cand_bins] - self._turn_penalty[steps]
        if self.last_target is not None:  # prefer keeping the previous goal on ties
            score = score + 1e-9 * (cand_bins == self.last_target)
        k = int(np.argmax(score))
        target = int(cand_bins[k])
        self.last_target = target
        if target == b0:
            return 0.0, target
        rot = (1 if k < ccw_steps.size else -1) * float(steps[k]) * self._bw
        # aim at the bin centre, measured from the current angle
        centre = float(tab.bin_centre(target))
        offset = math.remainder(centre - snap.theta, 2.0 * math.pi)
        if rot > 0 and offset < 0:
            offset += 2.0 * math.pi
        elif rot < 0 and offset > 0:
            offset -= 2.0 * math.pi
        return offset, target

    def _rod_room(self, snap: Snapshot) -> tuple[float, float] | None:
        """How far (radians) the real rod can turn counter-clockwise and clockwise.

        The rod of the actual length ``L`` from the actual evader, up to its first
        contact each way (the kernel's free arcs, THEORY.md 1.3); ``None`` if the rod is
        already blocked. Called only on the rare steps the table reads the rod's bin as
        blocked.
        """
        arcs = kernel_for(self.config.map).free_arcs(snap.evader, max(snap.L, 1e-9))
        if arcs.is_full:
            return math.inf, math.inf
        i = arcs.arc_index(snap.theta)
        if i is None:
            return None
        arc = arcs.arcs[i]
        past_lo = (snap.theta - arc.lo) % (2.0 * math.pi)
        if past_lo > arc.width:  # theta within the tolerance before lo
            past_lo = 0.0
        return arc.width - past_lo, past_lo


def crossable_steps(
    ccw: np.ndarray,
    cw: np.ndarray,
    b0: int,
    theta: float,
    bw: float,
    room: tuple[float, float],
) -> tuple[np.ndarray, np.ndarray]:
    """Drop the way round whose table-blocked gap the real rod cannot sweep (issue 13).

    :func:`reachable_steps` crosses the bins the table calls blocked between the rod's
    bin ``b0`` and the first free bin on either side, trusting that the real rod (shorter
    than the table's) is clear there. A gap can be an obstacle's whole shadow: on
    rand:polygons:2006 (evader orbiting an obstacle, seed 101) the evader 0.05 off its
    table node put the rod's bin in the table's shadow at 32.4 s while the real rod was
    0.031 clear; counter-clockwise the gap was 0 bins, clockwise 59 (148 degrees), and
    the best bin's shorter way round was clockwise: the pursuer reversed into the corner
    and lost sight within the step. Here a gap counts as crossable only if the real rod's
    room that way (``room``, radians from ``theta``, :meth:`DecompositionPursuer._rod_room`)
    reaches the first free bin. When one way is crossable and the other is not, the other
    is dropped; when neither is, both stay (the table's verdict is all there is).

    Args:
        ccw, cw: :func:`reachable_steps`' candidates with the rod's bin blocked (both
            non-empty; the first of each is the first free bin that way).
        b0: the rod's bin; theta: its angle; bw: the bin width.
        room: the real rod's room counter-clockwise and clockwise from ``theta``.

    Returns:
        ``(ccw, cw)``, one of them possibly emptied.
    """
    two_pi = 2.0 * math.pi
    enter_ccw = (-math.pi + (b0 + int(ccw[0])) * bw - theta) % two_pi  # its lower edge
    enter_cw = (theta - (-math.pi + (b0 - int(cw[0]) + 1) * bw)) % two_pi  # its upper edge
    ok_ccw = room[0] >= enter_ccw
    ok_cw = room[1] >= enter_cw
    if ok_ccw and not ok_cw:
        return ccw, cw[:0]
    if ok_cw and not ok_ccw:
        return ccw[:0], cw
    return ccw, cw


def reachable_steps(free: np.ndarray, b0: int) -> tuple[np.ndarray, np.ndarray]:
    """Rotations (in bins) the decomposition pursuer weighs from bin ``b0``, each way round.

    The bins reachable by turning through free orientations. The table is built for the
    rod L_target + body radius; the real rod (shorter, e.g. with the pursuer pressed to a
    wall) is clear right now even where the table reads the current bin as blocked, so
    each scan starts from the nearest orientation the table calls free on its side (the
    bins in between are crossed, not targeted): otherwise no candidate is left and the
    pursuer stops turning. ``b0`` itself is a candidate only when free (counter-clockwise).

    Args:
        free: the table's free orientations for the evader's row, ``(n_bins,)`` bool.
        b0: the rod's current bin.

    Returns:
        ``(ccw, cw)``: step counts k such that bin ``b0 + k`` (``b0 - k``) is a candidate.
    """
    nb = len(free)
    twice = np.concatenate((free, free))
    ccw_run = twice[b0 : b0 + nb].copy()  # ccw_run[k]: bin b0 + k is free
    cw_run = twice[b0 + nb : b0 : -1].copy()  # cw_run[k]: bin b0 - k is free
    ccw_run[0] = cw_run[0] = True
    blocked = not free[b0] and free.any()
    gap_ccw = gap_cw = 0  # table-blocked bins crossed before the first free one
    if blocked:
        gap_ccw = int(np.argmax(ccw_run[1:]))
        gap_cw = int(np.argmax(cw_run[1:]))
        ccw_run[1 : gap_ccw + 1] = True
        cw_run[1 : gap_cw + 1] = True
    n_ccw = int(np.argmin(ccw_run)) if not ccw_run.all() else nb
    n_cw = int(np.argmin(cw_run)) if not cw_run.all() else nb
    ccw_from = gap_ccw + 1 if blocked else 0
    cw_from = gap_cw + 1
    return np.arange(ccw_from, max(n_ccw, ccw_from)), np.arange(cw_from, max(n_cw, cw_from))
