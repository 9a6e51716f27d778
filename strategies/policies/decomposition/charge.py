"""What the decomposition pursuer reads from the evader's motion (issue 13).

:class:`_ChargeReading`: whether the evader charges (its velocity within 60 deg of the
rod, with a hysteresis against a chatter, :meth:`_ChargeReading._charge_test`), charges
by pure pursuit now (:meth:`_ChargeReading._pure_charge`), herded within the last
``ORBIT_LOOKAHEAD`` seconds (:meth:`_ChargeReading._herded`) or reversed its velocity on
each of the last two steps (:meth:`_ChargeReading._chatters`).
"""

from __future__ import annotations

import math

import numpy as np

from strategies.policies.base import Snapshot


class _ChargeReading:
    """The charge test and the other readings of the evader's motion.

    A part of :class:`~strategies.policies.decomposition.pursuer.DecompositionPursuer`:
    it reads the pursuer's constants and the state its ``_reset`` sets.
    """

    def _charge_test(self, snap: Snapshot, vx: float, vy: float, speed: float) -> bool:
        """Whether the evader charges: its velocity within 60 deg of the rod (its speed
        along the rod above ``CHARGE_ENTER`` of its speed), with a hysteresis against a
        chatter between :meth:`_keep_orbit` and the rules for a walk that does not charge.

        An evader that walks a fixed heading about 60 deg off the rod sits on the test:
        the orbit keeper turns the rod hard one way, off the heading, the test fails, the
        decomposition's turn (or :meth:`_avoid_pin`'s) brings the rod back, the test
        passes again, and the rod stands still while the range falls (holds-bench
        pillars, straight evader, seed 7: the test entered every 3-4 steps from 10.2 s,
        the rod between 95.8 and 100.5 deg, too close at 11.9 s). So when the test
        enters with the rod within ``CHATTER_ROD`` of where it stood at the test's last
        entry (within ``ORBIT_LOOKAHEAD`` seconds) and the evader's heading has stayed
        within ``CHATTER_HEADING`` of today's since then, the charge is kept while the
        velocity stays within 70 deg of the rod (``CHARGE_EXIT``) and its heading within
        ``CHATTER_HEADING`` of the heading at that entry: the orbit keeper's turn is
        carried through. Without the last condition a herder armed it at rho 0.3
        (unseen pillar_centre, combo 1: its heading stood still between two entries,
        then turned 1.7 deg a step with the held turn; lost at 27.7 s). Both stand-still
        conditions are needed: a hysteresis on every charge (exit at 70 deg, or two
        steps' hold) lost 11 and 19 herder episodes of the sets for 6 and 11 won, and
        one armed by the rod alone lost 9 for 7 won: a herder heads for a point beyond
        the pursuer, so its heading turns with the rod (about 2 deg a step) and its
        charge test is no chatter.

        The constants, measured at every entry of the test on the base trajectories
        of the nine pursuer sets and of the evader sets' episodes against this pursuer
        (helper-138): the straight walker departs from its heading by 0.00 deg between
        two entries, the darter by 0.00 or 0.67 deg and more, the orbiter by 0.00 to
        0.97 deg, the shooting evader by 0.00 or 0.14 to 0.94 deg, every herder and
        momentum walker by 0.71 deg or more. ``CHATTER_HEADING`` (about a third of
        that) arms no herder; from 0.25 to 1 deg the sets play alike (at 1 deg herders
        armed it in 16 episodes, no winner changed), at 2 deg it lost pillar_centre's
        herder again. With the heading fixed the test's edge is fixed and the test
        enters on the first step inside it, so two entries lie within one step's return
        turn of each other (0.5 to 1.4 deg): ``CHATTER_ROD`` from 1 to 8 deg arms nearly
        the same episodes. ``CHARGE_EXIT`` from 65 to 80 deg plays the armed episodes
        alike; at 90 deg (held while the evader closes in at all) it lost holds-bench
        corner's straight walk, seed 6.
        """
        u0, u1 = math.cos(snap.theta), math.sin(snap.theta)
        along = vx * u0 + vy * u1
        passed = along > self.CHARGE_ENTER * speed
        head = math.atan2(vy, vx)
        log = self._charge_log
        if passed and log and not log[-1][0]:  # the test enters
            entries = [k for k, e in enumerate(log) if e[0] and (k == 0 or not log[k - 1][0])]
            if entries:
                k = entries[-1]
                rod_still = abs(math.remainder(snap.theta - log[k][1], math.tau)) < self.CHATTER_ROD
                heading_still = all(
                    abs(math.remainder(head - e[2], math.tau)) < self.CHATTER_HEADING
                    for e in list(log)[k:]
                )
                if rod_still and heading_still:
                    self._charge_armed = True
                    self._armed_heading = head
        charging = passed or (
            self._charging
            and self._charge_armed
            and along > self.CHARGE_EXIT * speed
            # the heading still stands: a herder's turns once the rod swings
            and abs(math.remainder(head - self._armed_heading, math.tau)) < self.CHATTER_HEADING
        )
        if not charging:
            self._charge_armed = False
        log.append((passed, snap.theta, head))
        self._charging = charging
        return charging

    def _pure_charge(self, snap: Snapshot, L: float) -> bool:
        """Whether the evader charges by pure pursuit: its velocity (one step old) lies
        along the rod up to the rod's largest turn in one step, ``V_p dt / L`` (as in
        :meth:`_off_the_normal`)."""
        c = self.config
        ve = snap.evader_velocity
        speed = math.hypot(float(ve[0]), float(ve[1]))
        u = (math.cos(snap.theta), math.sin(snap.theta))
        along = float(ve[0]) * u[0] + float(ve[1]) * u[1]
        across = float(ve[1]) * u[0] - float(ve[0]) * u[1]
        lag = math.sin(min(c.v_pursuer * c.dt / L, 0.5 * math.pi))
        return along > 0.0 and abs(across) <= speed * lag

    def _herded(self, normal: float) -> bool:
        """Whether the evader herded within the last ``ORBIT_LOOKAHEAD`` seconds: on a
        step it did not charge (the test of :meth:`_decide`: its velocity within 60 deg
        of the rod), its motion across the rod turned the rod toward the wall normal of
        direction ``normal`` (from the pursuer to its wall; the rod angles are read
        against this one normal)."""
        for x in self._crossings:
            if x is not None and x[1] * math.remainder(x[0] - normal, 2.0 * math.pi) > 0.0:
                return True
        return False

    def _chatters(self, ve: np.ndarray) -> bool:
        """Whether the evader reversed its velocity on each of the last two steps: the
        one-step estimates ``ve`` (now) and the two before it have negative dot products
        in turn. A zig-zag that flips its heading every period reverses it on one step,
        not on two running; a walk that keeps its velocity not at all."""
        if len(self._velocities) < 2:
            return False
        (a0, a1), (b0, b1) = self._velocities
        v0, v1 = float(ve[0]), float(ve[1])
        return a0 * b0 + a1 * b1 < 0.0 and b0 * v0 + b1 * v1 < 0.0
