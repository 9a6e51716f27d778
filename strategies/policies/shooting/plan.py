"""The shooting evader's walk along a guaranteed escape plan (Secs. 4-5, step 1 of its decision).

:class:`_PlanWalk`: the configuration's cell in the exact decomposition K_L at L_eff and,
in an escapable cell, the crossing of one of its via pieces it walks to
(:mod:`strategies.policies.escape_plan`), kept inside the cell's region and landing just
across the piece; the crossings excluded after a stall or a cycle, the retries after
``FORGIVE_STEPS``, and the dead ends from which the evader shoots first.
"""

from __future__ import annotations

import math

import numpy as np

from strategies.policies.base import unit

# the moves tried, in order, to keep a walk inside a region: the heading turned by 0, 5,
# ... 90 degrees either way, at a whole, half or quarter step, most progress first
_TURN_DEG = np.array([s * d for d in range(0, 91, 5) for s in ((1, -1) if d else (1,))])
_TURNS = np.array([(math.radians(a), f) for f in (1.0, 0.5, 0.25) for a in _TURN_DEG])
_TURNS = _TURNS[np.argsort(-_TURNS[:, 1] * np.cos(_TURNS[:, 0]), kind="stable")]


class _PlanWalk:
    """The heading of the guaranteed escape plan, and the crossing it walks to.

    A part of :class:`~strategies.policies.shooting.evader.ShootingEvader`: it reads the
    evader's constants and the state its ``_reset`` and ``_forget`` set.
    """

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
