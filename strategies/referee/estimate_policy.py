"""The estimate's evader strategy played in the env (not a certificate).

:func:`~strategies.referee.estimates.solve_estimate` records, for the order in which the
evader moves first, the sweep in which each state left the pursuer's set (its *rank*).
From a state of rank k > 0 the evader has a move after which every pursuer answer lands
in a state of rank < k or breaks surveillance within the step (the discrete game's
in-step checks). :class:`EstimateEvader` plays that strategy in the env: every env step
it snaps both real positions to the evader-win state (positive rank, not the pursuer's
"never left") nearest to them (within the six nearest lattice points of each), evaluates
every evader move against every pursuer answer with the game's own checks, and walks at
full speed towards the lattice point of the move whose worst answer has the lowest rank.
Where it finds no such state, or no allowed move, it charges the pursuer.

It is an estimate's strategy, not a certified one: the env's pursuer moves continuously
and off the lattice, so the rank need not fall every step.
"""

from __future__ import annotations

import numpy as np

from envs import validation as V
from envs.errors import InvalidConfigError, MemoryBudgetError
from envs.geometry import kernel_for
from strategies.policies.base import BasePolicy, Snapshot, unit
from strategies.referee.estimates import (
    EstimateSolution,
    _cached_solution,
    _in_triangle,
    _move_targets,
    _segment_origin_distance,
    heading_moves,
)
from strategies.referee.robust import convex_corners
from strategies.referee.spec import GameSpec, check_cells_per_lmin

__all__ = ["EstimateEvader"]

_SNAP = 6
"""Lattice points tried per player when snapping a real state to a ranked one."""


def _key(spec: GameSpec) -> tuple:
    return (spec.map.digest, spec.l_min, spec.l_max, spec.v_pursuer, spec.v_evader,
            spec.body_radius)  # fmt: skip


class EstimateEvader(BasePolicy):
    """Plays the estimate's evader-first strategy (module docstring).

    Args:
        solution: a solved :class:`EstimateSolution` of the env's game (with its ranks);
            None: solve (or load from the cache) the env's game at reset.
        cells_per_lmin: the resolution of that solve.
        steps: pursuer cells a step of that solve.
        headings: move directions of that solve.
        name: registry-style name.

    Attributes:
        decisions: decisions taken this episode.
        fallback_steps: of those, the ones that charged the pursuer (no ranked state or
            no move).
    """

    roles = ("evader",)

    def __init__(
        self,
        solution: EstimateSolution | None = None,
        *,
        cells_per_lmin: float = 6.0,
        steps: float = 4.0,
        headings: int = 16,
        name: str | None = None,
    ) -> None:
        super().__init__(name=name or "evader/estimate")
        if solution is not None and not isinstance(solution, EstimateSolution):
            raise InvalidConfigError(
                f"EstimateEvader: expected an EstimateSolution, got {type(solution).__name__}"
            )
        if solution is not None and solution.evader_first_rank is None:
            raise InvalidConfigError("EstimateEvader: the solution has no evader_first_rank")
        self.cells_per_lmin = check_cells_per_lmin(cells_per_lmin)
        self.steps = V.positive("steps", steps)
        self.headings = V.integer("headings", headings, minimum=4)
        self.solution = solution
        self._given = solution is not None
        self._tables: tuple | None = None
        self.decisions = 0
        self.fallback_steps = 0

    def _reset(self) -> None:
        spec = GameSpec.from_config(self.config)
        if not self._given and (self.solution is None or _key(self.solution.spec) != _key(spec)):
            # a policy has no memory_budget argument
            with MemoryBudgetError.naming(f"{self.name!r} with cells_per_lmin"):
                self.solution = _cached_solution(
                    spec, self.cells_per_lmin, self.steps, self.headings, True, None, False
                )
            self._tables = None
        if _key(self.solution.spec) != _key(spec):
            raise InvalidConfigError(
                f"policy {self.name!r}: the env's game (map {self.map.name!r}, range, speeds, "
                f"body radius) is not the solved game's (map {self.solution.spec.map.name!r})"
            )
        self._prepare()
        self.decisions = 0
        self.fallback_steps = 0

    def _prepare(self) -> None:
        """The solution's moves, their targets, the kernel and the convex vertices."""
        if self._tables is None:
            sol = self.solution
            lat = sol.lattice
            vp = heading_moves(sol.spec.v_pursuer * sol.tau, lat.h, sol.headings)
            ve = heading_moves(sol.spec.v_evader * sol.tau, lat.h, sol.headings)
            self._tables = (
                sol.tree, vp, ve, _move_targets(lat, vp), _move_targets(lat, ve),
                kernel_for(sol.spec.map), convex_corners(sol.spec.map)[0],
            )  # fmt: skip

    def _snap(self, pursuer: np.ndarray, evader: np.ndarray):
        """The lattice points (kp, ke) of an evader win (positive rank, not the pursuer's)
        nearest to the real positions (least summed distance), or None."""
        sol = self.solution
        lat, tree = sol.lattice, self._tables[0]
        dp, kp = tree.query(pursuer, k=_SNAP)
        de, ke = tree.query(evader, k=_SNAP)
        ab = lat.point_cells[ke][None, :, :] - lat.point_cells[kp][:, None, :] + lat.hw
        inside = ((ab >= 0) & (ab < lat.W)).all(axis=2)
        ab = np.where(inside[..., None], ab, 0)
        ranks = sol.evader_first_rank
        rank = np.where(inside, ranks[kp[:, None], ab[..., 0], ab[..., 1]], 0)
        # a state the pursuer wins (the rank that never left the set) has no move to rank
        # by: every move scores the same there, and the evader would play arbitrarily
        won = rank == np.iinfo(ranks.dtype).max
        cost = np.where((rank > 0) & ~won, dp[:, None] + de[None, :], np.inf)
        i, j = np.unravel_index(int(np.argmin(cost)), cost.shape)
        if not np.isfinite(cost[i, j]):
            return None
        return int(kp[i]), int(ke[j])

    def move_values(self, kp: int, ke: int) -> np.ndarray:
        """Per evader move (the solve's ``heading_moves``), the largest rank a pursuer
        answer reaches (0: every answer breaks surveillance within the step; inf: the move
        is not allowed), from the lattice state (pursuer at point kp, evader at ke)."""
        self._prepare()
        sol = self.solution
        _, vp, ve, tp, te, ker, verts = self._tables
        lat, h, spec = sol.lattice, sol.lattice.h, sol.spec
        P, E = lat.points[kp], lat.points[ke]
        r = E - P
        w = verts - P  # convex vertices relative to the pursuer's point
        de, dp = h * ve.astype(float), h * vp.astype(float)
        out = np.full(len(ve), np.inf)
        okp = tp[kp] >= 0
        for j in range(len(ve)):
            if te[ke, j] < 0:
                continue
            if len(w) and j and _in_triangle(w, np.zeros(2), r, r + de[j]).any():
                out[j] = 0.0  # the evader's move sweeps the rod over a corner
                continue
            if not ker.line_of_sight(P, E + de[j]):
                out[j] = 0.0
                continue
            mid = r + de[j]
            ok = okp & (_segment_origin_distance(np.broadcast_to(r, dp.shape), mid - dp)
                        >= spec.l_min)  # fmt: skip
            if len(w):
                hit = _in_triangle(w[None], mid[None, None], np.zeros((1, 1, 2)), dp[:, None])
                hit[0] = False
                ok &= ~hit.any(axis=1)
            m = np.flatnonzero(ok)
            ab = lat.point_cells[te[ke, j]][None] - lat.point_cells[tp[kp, m]] + lat.hw
            inside = ((ab >= 0) & (ab < lat.W)).all(axis=1)
            m, ab = m[inside], ab[inside]
            ranks = sol.evader_first_rank[tp[kp, m], ab[:, 0], ab[:, 1]]
            out[j] = float(ranks.max()) if len(ranks) else 0.0
        return out

    def _decide(self, snap: Snapshot) -> np.ndarray:
        self.decisions += 1
        v_e = float(self.config.v_evader)
        got = self._snap(snap.pursuer, snap.evader)
        if got is not None:
            kp, ke = got
            values = self.move_values(kp, ke)
            j = int(np.argmin(values))
            if np.isfinite(values[j]):
                if j == 0:
                    return np.zeros(2)
                lat = self.solution.lattice
                target = lat.points[ke] + lat.h * self._tables[2][j]
                return unit(target - snap.evader) * v_e
        self.fallback_steps += 1
        return unit(snap.pursuer - snap.evader) * v_e
