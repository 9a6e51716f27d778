"""The decomposition-based pursuer (Secs. 4-5): keep the rod in admissible safe cells at L_min.

Per step (table lookups plus a little arithmetic, no geometry kernel call):

1. From the :class:`~strategies.policies.safety.SafetyTable` (safe = free and not in an
   escapable cell at L_min, Sec. 4), the rotation each orientation bin needs to reach a
   safe orientation at every probe point the evader can reach soon: probes lie on rays
   from the evader, up to ``V_e T`` with ``T = pi / omega`` (the time to turn the rod half
   way round), and a ray stops at the first wall it meets.
2. The value of each orientation (eqs. 2-3 with a straight-line evader and the pursuer
   turning at ``omega = (V_p / L_min) sqrt(1 - rho^2)``, the least rate the evader can
   impose, Sec. 6.1)::

       V(theta) = min over probes p of  t_e(p) - turn(theta -> safe(p)) / omega

   ``V = 0`` means admissible: the rod reaches a safe orientation at every probe before
   the evader does. The pursuer targets the bin maximising V within the *free arc* it is
   in (the rod can only rotate through free orientations), minus a small penalty for the
   rotation needed, and turns the shorter way round inside that arc.
   The pursuer's own clearance enters as *retreat room*: per bin, the seconds before an
   evader charging along the rod pins the pursuer (body radius included) to the first wall
   on that ray (rays marched on the table's grid). A candidate's score is also bounded by
   the room of every bin passed on the way there, less the evader's drift toward it while
   the rod turns (``(V_e/omega) sin(phi)``), and a target with less room than the horizon
   is charged its shortfall (the turn away from it would come later, with less room).
3. The velocity is the evader's velocity plus the perpendicular component that realises the
   commanded rotation rate (eq. 5), plus a radial correction of L toward L_min, all within
   V_p (:func:`strategies.control.kinematics.pursuer_velocity_holding_range`).
"""

from __future__ import annotations

import math

import numpy as np

from envs.errors import InvalidConfigError
from strategies.control.kinematics import pursuer_velocity_holding_range, theta_dot
from strategies.policies.base import BasePolicy, Snapshot, distance_target
from strategies.policies.safety import NO_PATH, safety_table

__all__ = ["DecompositionPursuer"]


def _check_positive(name: str, value: float) -> float:
    v = float(value)
    if not (math.isfinite(v) and v > 0):
        raise InvalidConfigError(f"{name} must be a positive number, got {value!r}")
    return v


class DecompositionPursuer(BasePolicy):
    """Pursuer that keeps the configuration in admissible, non-escapable cells at L_min.

    Args:
        resolution: grid spacing of the safety table (map units).
        n_bins: orientation bins of the table.
        rays: probe rays around the evader.
        probe_every: use every k-th grid sample along a ray as a probe.
        hysteresis: weight of the rotation needed to reach a target, in units of V.
        distance_gain: rate (1/s) of the correction of L toward L_min.
    """

    roles = ("pursuer",)

    def __init__(
        self,
        *,
        resolution: float = 0.1,
        n_bins: int = 144,
        rays: int = 16,
        probe_every: int = 3,
        hysteresis: float = 0.25,
        distance_gain: float = 3.0,
        name: str | None = None,
    ) -> None:
        super().__init__(name=name)
        self.resolution = _check_positive("resolution", resolution)
        self.n_bins = int(n_bins)
        if not (isinstance(rays, int) and rays >= 4):
            raise InvalidConfigError(f"rays must be an integer >= 4, got {rays!r}")
        if not (isinstance(probe_every, int) and probe_every >= 1):
            raise InvalidConfigError(f"probe_every must be an integer >= 1, got {probe_every!r}")
        self.rays = rays
        self.probe_every = probe_every
        self.hysteresis = float(hysteresis)
        if not (math.isfinite(self.hysteresis) and self.hysteresis >= 0):
            raise InvalidConfigError(f"hysteresis must be >= 0, got {hysteresis!r}")
        self.distance_gain = _check_positive("distance_gain", distance_gain)

    def _reset(self) -> None:
        c = self.config
        self.L_target = distance_target(c)
        # the pursuer's disc keeps its centre body_radius off the walls, so the rod tip
        # meets a wall as if the rod were that much longer (Prop. 3: fewer free arcs)
        self.table_length = round(self.L_target + c.body_radius, 6)
        self.table = safety_table(c.map, self.table_length, self.resolution, self.n_bins)
        rho = c.rho
        # Sec. 6.1: the evader can hold the pursuer's best rate down to (V_p/L) sqrt(1 - rho^2)
        self.omega = c.v_pursuer * math.sqrt(max(1.0 - rho * rho, 0.05)) / c.l_min
        self.horizon = horizon = math.pi / self.omega
        h = self.table.resolution
        n_r = max(2, math.ceil(c.v_evader * horizon / h))
        radii = h * np.arange(1, n_r + 1)
        ang = 2.0 * math.pi * np.arange(self.rays) / self.rays
        dirs = np.stack([np.cos(ang), np.sin(ang)], axis=1)
        self._offsets = (dirs[:, None, :] * radii[None, :, None]).reshape(-1, 2)
        self._n_r = n_r
        self._probe_cols = np.arange(self.probe_every - 1, n_r, self.probe_every)
        self._t_e = (radii[self._probe_cols] / c.v_evader).astype(np.float32)
        self._bw = self.table.bin_width
        lut = np.arange(NO_PATH + 1) * self._bw / self.omega
        lut[NO_PATH] = math.pi / self.omega  # no safe orientation: half a turn
        lut[0] = -1e9
        self._turn_lut = lut.astype(np.float32)
        # retreat room along each orientation (Sec. 5 with the pursuer's own clearance):
        # rays from the evader on the table's grid, one per ``_room_step`` bins
        self._room_step = max(1, self.n_bins // 72)
        n_room = math.ceil(self.n_bins / self._room_step)
        reach = self.L_target + c.body_radius + c.v_evader * horizon + 2.0 * h
        radii_room = h * np.arange(1, math.ceil(reach / h) + 1)
        ang = self.table.bin_centre(np.arange(n_room) * self._room_step)
        dirs = np.stack([np.cos(ang), np.sin(ang)], axis=1)
        offs = (dirs[:, None, :] * radii_room[None, :, None]).reshape(-1, 2)
        self._room_di = np.rint(offs / h).astype(np.int64)  # grid steps from the evader's point
        self._room_radii = radii_room
        self._n_room = n_room
        # an evader charging along the rod while it turns by phi at omega has moved
        # (V_e / omega) sin(phi) toward the orientation reached (phi <= pi/2); in seconds:
        phi = np.minimum(np.arange(self.n_bins) * self._bw, 0.5 * math.pi)
        self._drift = np.sin(phi) / self.omega
        self.last_target: int | None = None

    # ------------------------------------------------------------------ decision
    def orientation_values(self, evader: np.ndarray) -> np.ndarray:
        """V(theta) for every orientation bin at evader position ``evader`` (seconds).

        The least time margin ``t_e(p) - turn(theta -> safe(p)) / omega`` over the probes
        ``p`` where ``theta`` is not safe; the horizon where no probe threatens ``theta``,
        and ``-turn / omega`` (negative) where ``theta`` is not safe at ``evader`` itself.
        """
        tab = self.table
        row = tab.row(evader)
        if row < 0:
            return np.zeros(tab.n_bins)
        value = np.full(tab.n_bins, self.horizon)
        rows = tab.rows(evader + self._offsets).reshape(self.rays, self._n_r)
        reach = np.cumsum(rows < 0, axis=1) == 0  # a ray stops at the first wall
        sub_rows = rows[:, self._probe_cols]
        sub_ok = reach[:, self._probe_cols]
        r = sub_rows[sub_ok]
        if r.size:
            t_e = np.broadcast_to(self._t_e, sub_rows.shape)[sub_ok]
            # lut: seconds to turn by a number of bins; a safe bin (0) never threatens
            v = t_e[:, None] - self._turn_lut[tab.need[r]]
            value = np.minimum(value, v.min(axis=0))
        need0 = tab.need[row]
        return np.where(need0 > 0, -self._turn_lut[need0], value)

    def retreat_times(self, evader: np.ndarray) -> np.ndarray:
        """Per bin, the seconds before a pursuer at ``L_target`` along it meets a wall while
        the evader charges straight at it (the rod's tip, plus the body radius, reaches the
        first wall the ray from the evader meets; the pair drifts along the rod at V_e).

        Capped at the horizon; negative where the pursuer cannot stand at ``L_target``.
        """
        tab = self.table
        c = self.config
        i0 = np.rint((np.asarray(evader, dtype=float) - tab.origin) / tab.resolution)
        ij = self._room_di + i0.astype(np.int64)
        nx, ny = tab.shape
        ok = (ij[:, 0] >= 0) & (ij[:, 0] < nx) & (ij[:, 1] >= 0) & (ij[:, 1] < ny)
        flat = np.where(ok, ij[:, 0] * ny + ij[:, 1], 0)
        wall = (~ok | (tab.cell.ravel()[flat] < 0)).reshape(self._n_room, -1)
        inside = np.cumsum(wall, axis=1) == 0
        n_in = inside.sum(axis=1)  # samples before the first wall
        d = np.where(n_in > 0, self._room_radii[np.maximum(n_in - 1, 0)], 0.0)
        d = np.where(n_in == len(self._room_radii), np.inf, d)
        t = (d - c.body_radius - self.L_target) / c.v_evader
        t = np.minimum(t, self.horizon)
        return np.repeat(t, self._room_step)[: tab.n_bins]

    def _target(self, snap: Snapshot) -> tuple[float, int]:
        """Signed rotation (radians) toward the best reachable orientation, and its bin.

        A candidate's score is the least of its value ``V`` (eqs. 2-3) and, along the way
        there, the retreat time of every bin passed minus the time to reach it: turning
        through orientations where a charging evader would pin the pursuer to a wall first
        is as bad as an unsafe target.
        """
        tab = self.table
        row = tab.row(snap.evader)
        b0 = tab.bin_of(snap.theta)
        if row < 0:
            return 0.0, b0
        value = self.orientation_values(snap.evader)
        room = self.retreat_times(snap.evader)
        free = tab.free[row]
        nb = tab.n_bins
        # bins reachable by turning through free orientations, each way round
        ccw_run = np.roll(free, -b0)
        cw_run = np.roll(free[::-1], b0 + 1)
        ccw_run[0] = cw_run[0] = True  # the current bin (the rod is free right now)
        n_ccw = int(np.argmin(ccw_run)) if not ccw_run.all() else nb
        n_cw = int(np.argmin(cw_run)) if not cw_run.all() else nb
        steps = np.arange(nb)
        ccw_bins = (b0 + steps[:n_ccw]) % nb
        cw_bins = (b0 - steps[:n_cw]) % nb
        drift = self._drift
        ccw_path = np.minimum.accumulate(room[ccw_bins] - drift[:n_ccw])
        cw_path = np.minimum.accumulate(room[cw_bins] - drift[:n_cw])
        cand_bins = np.concatenate([ccw_bins, cw_bins[1:]])
        cand_rot = np.concatenate([steps[:n_ccw], -steps[1:n_cw]]).astype(float)
        path = np.concatenate([ccw_path, cw_path[1:]])
        # a target the evader can still pin to a wall within the horizon is only a halt:
        # the turn from there comes later with less room, so its shortfall is charged now
        short = self.horizon - np.maximum(room[cand_bins], 0.0)
        score = np.minimum(value[cand_bins], path) - short
        score = score - self.hysteresis * np.abs(cand_rot) * self._bw / self.omega
        if self.last_target is not None:  # prefer keeping the previous goal on ties
            score = score + 1e-9 * (cand_bins == self.last_target)
        k = int(np.argmax(score))
        target = int(cand_bins[k])
        self.last_target = target
        if target == b0:
            return 0.0, target
        rot = cand_rot[k] * self._bw
        # aim at the bin centre, measured from the current angle
        centre = float(tab.bin_centre(target))
        offset = math.remainder(centre - snap.theta, 2.0 * math.pi)
        if rot > 0 and offset < 0:
            offset += 2.0 * math.pi
        elif rot < 0 and offset > 0:
            offset -= 2.0 * math.pi
        return offset, target

    def _decide(self, snap: Snapshot) -> np.ndarray:
        c = self.config
        L = max(snap.L, 1e-9)
        ve = snap.evader_velocity
        speed = math.hypot(float(ve[0]), float(ve[1]))
        rot, _ = self._target(snap)
        alpha = math.atan2(float(ve[1]), float(ve[0])) if speed > 0 else snap.theta
        rate = min(speed / c.v_pursuer, 1.0)
        hi, lo = theta_dot(alpha, snap.theta, L=L, v_p=c.v_pursuer, rho=rate)  # eq. (6)
        want = rot / (2.0 * c.dt)
        cmd_rate = min(max(want, lo), hi)
        cmd = pursuer_velocity_holding_range(
            ve,
            snap.theta,
            cmd_rate,
            L=L,
            L_target=self.L_target,
            v_p=c.v_pursuer,
            gain=self.distance_gain,
        )
        return cmd.velocity
