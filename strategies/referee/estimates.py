"""The referee's *estimate*: issue 13's plain discrete game, solved at several resolutions.

Not a certificate. The bounds (:mod:`.pursuer_bound`, :mod:`.evader_bound`) are sound
but the pursuer bound certifies nothing from rho ~ 0.3; the estimate is what issue 13
literally asked for, "value iteration of the discrete-time reach-avoid game over a grid
of (pursuer, evader) positions, with the kernel's continuous occlusion and range test as
the losing set, with its resolution error bounded by comparing resolutions". It may be
wrong in either direction at a start; the share of starts on which its solutions
disagree (*contested*) is how wrong it may be, and nothing proves even that.

**The game at one resolution** (``cells_per_lmin`` = cpl, ``steps`` = s):

* Both players sit on one lattice: the points ``anchor + h (i, j)``, ``h = l_min / cpl``
  (the cells of :class:`~strategies.referee.lattice.Lattice` with ``coarse = 1``), that
  lie in free space at least ``body_radius`` from every wall.
* In a step of ``tau = s h / V_p`` each player makes one move: standing still or one of
  ``headings`` directions, of length V tau (``s`` cells for the pursuer, ``rho s`` for
  the evader), snapped to the nearest lattice vector. A move is allowed when it lands on
  a lattice point and its straight path keeps ``body_radius`` from every wall (no move
  through an obstacle, no body into a wall).
* Information orders. *Evader first*: the evader moves, the pursuer sees where it went
  and answers (for every evader move there is a pursuer move...). *Pursuer first*: the
  pursuer commits and the evader answers. Within the step the first mover's move is
  swept first, then the other's.
* Losing set, the env's rule (``envs.surveillance.rules``): the distance outside
  ``[l_min, l_max]`` or the segment P-E touching a wall (the kernel's
  ``line_of_sight``: touching a vertex blocks). Checked at the step's end and inside it:
  the distance along the joint straight motion of both players (its smallest value in
  closed form, its largest at an end by convexity); the rod at the step's end and
  between the two moves (the kernel); and the rods swept *during* each move: while one
  end moves along a straight path the rods sweep the triangle (fixed end, path start,
  path end), whose two sides from the fixed end are checked rods and whose third side is
  the path (``body_radius`` from the walls), so a wall can meet the triangle only as a
  whole obstacle inside it, which "no convex obstacle vertex in the closed triangle"
  catches exactly: a rod cannot jump a thin wall or a corner within a step.
* The pursuer's winning set in each order is the greatest fixed point of "surveillance
  holds now and the pursuer can keep the state in the set for one more step", by value
  iteration from the states where surveillance holds (whole-array sweeps, 8 states a
  byte, until nothing changes).

**The estimate** solves this game at two or more resolutions (:func:`estimate`). A start
(any real positions, each snapped to its nearest lattice point) is labelled
``"pursuer"`` when the pursuer wins it in every solution (every resolution, both orders),
``"evader"`` when it loses it in every solution, else ``"contested"``; the contested
share of the finest lattice's starts is the resolution error. Its solutions are cached
on disk like the bounds' (:mod:`.cache`, kind ``"estimate<headings>"``).

**Measured** (L in [2, 4], rho = 0.5, body 0.1, 16 headings, the default steps: tau =
1.33 s, the pursuer 4, 5.33 and 8 cells a step at 6, 8 and 12 cells per L_min; states where
surveillance holds, seconds to build + solve both orders, load ~2.5 on 2 cores):

=================  ===============  ===============  ================  ============
world              6 cells / L_min  8                12                contested
=================  ===============  ===============  ================  ============
open_room 10 x 10  176 k, 7 s       579 k, 12 s      2.99 M, 61 s      97.7 %
pillar room 12x8   138 k, 21 s      456 k, 56 s      2.37 M, 217 s     0 % (evader)
corner 14 x 14     169 k, 18 s      562 k, 37 s      -                 0 % (evader)
=================  ===============  ===============  ================  ============

The states grow as the fourth power of the resolution (cpl^4). In the open room the
pursuer wins 97 % of the states when it moves second and none when it moves first, at
every resolution: at rho = 0.5 a pursuer that commits its step before the evader answers
loses the whole room at these resolutions, so the estimate can only say ``"evader"`` or
``"contested"`` there. The snapping alone can decide a solution: the open room at rho =
0.4 is won by the pursuer moving first from 98 % of the states at 6 cells per L_min (the
evader's 1.6-cell moves snap to at most 2.24 cells) and from none at 8 (2.13 cells snap
to up to 2.83 on the diagonals): 98.5 % contested.

**Played.** The evader-first solve records each state's rank (the sweep in which it left
the pursuer's set), and :class:`~strategies.referee.estimate_policy.EstimateEvader`
plays the strategy that lowers it in the env. Against the env's pursuers from the safe
starts of seeds 0-7 (rho = 0.5, body radius 0.2, 600 steps; 6 / 8 cells per L_min, tau
1.33 / 1 s) it escapes the decomposition pursuer 4/8 / 8/8 on the corner world, where
every registered evader is held 48/48, and greedy 7/8 / 8/8; the decomposition pursuer
3/8 / 2/8 in the pillar room; 0/8 / 0/8 in the open room (contested); at 8 cells per
L_min also 4/8 on the corner at rho = 0.3 (the registered evaders 0/48). So the corner's
``"evader"`` label is backed by play, not only by the discretisation.
"""

from __future__ import annotations

import functools
import math
import os
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.spatial import cKDTree

from envs import validation as V
from envs.errors import InvalidConfigError
from envs.geometry import kernel_for
from envs.geometry.segments import cross2d
from strategies.referee._budget import check_budget, estimate_size
from strategies.referee._fixpoint import shifted
from strategies.referee.cache import load_arrays, save_arrays
from strategies.referee.lattice import Lattice, segment_wall_distance
from strategies.referee.robust import convex_corners
from strategies.referee.spec import GameSpec, Resolution, check_cells_per_lmin

__all__ = [
    "ESTIMATE_LABELS",
    "Estimate",
    "EstimateSolution",
    "check_cpls",
    "check_estimate",
    "estimate",
    "solve_estimate",
]

ESTIMATE_LABELS = ("pursuer", "evader", "contested")
"""What the estimate labels a start: who wins it in every solution, or contested."""

_CHUNK = 1 << 21


def heading_moves(length: float, h: float, headings: int) -> np.ndarray:
    """Standing still, then ``headings`` evenly spaced directions of ``length``, each
    snapped to the nearest lattice vector (cells; duplicates and (0, 0) dropped).

    Examples:
        >>> heading_moves(2.0, 1.0, 8).tolist()
        [[0, 0], [2, 0], [1, 1], [0, 2], [-1, 1], [-2, 0], [-1, -1], [0, -2], [1, -1]]
    """
    out = [(0, 0)]
    for k in range(headings):
        a = 2.0 * math.pi * k / headings
        v = (round(length / h * math.cos(a)), round(length / h * math.sin(a)))
        if v not in out:
            out.append(v)
    return np.array(out, dtype=np.int64)


def _move_targets(lat: Lattice, vec: np.ndarray) -> np.ndarray:
    """(n_points, n_moves) the lattice point each move reaches, -1 when it leaves the
    lattice or its straight path comes closer than ``body_radius`` to a wall."""
    n, k = lat.n_points, len(vec)
    dest = lat.point_cells[:, None, :] + vec[None, :, :]
    targets = lat.point_index(dest.reshape(-1, 2)).reshape(n, k)
    rows, cols = np.nonzero(targets >= 0)
    moving = np.any(vec[cols] != 0, axis=1)
    rows, cols = rows[moving], cols[moving]
    if len(rows):
        A = lat.points[rows]
        B = A + lat.h * vec[cols].astype(float)
        bad = segment_wall_distance(A, B, lat.spec.map) < lat.spec.body_radius * (1.0 - 1e-9)
        targets[rows[bad], cols[bad]] = -1
    targets[:, 0] = np.arange(n)
    return targets


def _segment_origin_distance(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance from the origin to the segments a-b (arrays (..., 2))."""
    d = b - a
    L2 = np.einsum("...j,...j->...", d, d)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = -np.einsum("...j,...j->...", a, d) / L2
    t = np.clip(np.nan_to_num(t), 0.0, 1.0)
    return np.hypot(*np.moveaxis(a + t[..., None] * d, -1, 0))


def _in_triangle(w, a, b, c) -> np.ndarray:
    """Whether the points w lie in the closed triangles (a, b, c) (arrays (..., 2))."""
    s1 = cross2d(b - a, w - a)
    s2 = cross2d(c - b, w - b)
    s3 = cross2d(a - c, w - c)
    return ((s1 >= 0) & (s2 >= 0) & (s3 >= 0)) | ((s1 <= 0) & (s2 <= 0) & (s3 <= 0))


@dataclass
class EstimateSolution:
    """The discrete game solved at one resolution.

    Attributes:
        spec: the game.
        cells_per_lmin: the resolution (``h = l_min / cells_per_lmin``).
        steps: cells the pursuer covers per step.
        headings: directions of the moves.
        lattice: the players' lattice (points, windows; ``coarse = 1``).
        tau: the step, ``steps h / V_p``.
        safe: (n, W, W) the states where surveillance holds (pursuer at point k, evader
            at window offset (a, b); see :mod:`.lattice`).
        evader_first: (n, W, W) the pursuer wins when the evader moves first each step
            (and the pursuer answers it).
        pursuer_first: (n, W, W) the pursuer wins when it moves first each step.
        iterations: sweeps of the fixed point.
        seconds: ``{"build": ..., "solve": ...}``.
        evader_first_rank: (n, W, W) the sweep of the evader-first iteration in which each
            state left the pursuer's set (uint8, or uint16 past 254 sweeps): 0 where
            surveillance fails, the dtype's largest value where the pursuer wins. From a
            state of rank k > 0 the evader has a move after which every pursuer answer
            ends in a state of rank < k (or breaks surveillance within the step): the
            evader's strategy (:class:`~strategies.referee.estimate_policy.EstimateEvader`).
            None when not recorded.
    """

    spec: GameSpec
    cells_per_lmin: float
    steps: float
    headings: int
    lattice: Lattice
    safe: np.ndarray
    evader_first: np.ndarray
    pursuer_first: np.ndarray
    iterations: int
    seconds: dict[str, float] = field(default_factory=dict)
    evader_first_rank: np.ndarray | None = None

    @property
    def tau(self) -> float:
        """The step, ``steps h / V_p``."""
        return self.steps * self.lattice.h / self.spec.v_pursuer

    @property
    def states(self) -> int:
        """Number of (pursuer, evader) states where surveillance holds."""
        return int(np.count_nonzero(self.safe))

    @functools.cached_property
    def tree(self) -> cKDTree:
        """A k-d tree of the lattice points (built on first use), to snap positions."""
        return cKDTree(self.lattice.points)

    def wins(self, pursuer: np.ndarray, evader: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Whether the pursuer wins each start, evader first and pursuer first.

        Each position is snapped to its nearest lattice point; a start whose snapped
        positions are not a state where surveillance holds is lost in both orders.

        Args:
            pursuer: (k, 2) positions.
            evader: (k, 2) positions.

        Returns:
            ``(evader_first, pursuer_first)``, each (k,) bool.
        """
        lat = self.lattice
        _, kp = self.tree.query(np.atleast_2d(pursuer))
        _, ke = self.tree.query(np.atleast_2d(evader))
        ab = lat.point_cells[ke] - lat.point_cells[kp] + lat.hw
        inside = (ab >= 0).all(axis=1) & (ab < lat.W).all(axis=1)
        a = np.zeros(len(kp), dtype=bool)
        b = np.zeros(len(kp), dtype=bool)
        i = np.flatnonzero(inside)
        a[i] = self.evader_first[kp[i], ab[i, 0], ab[i, 1]]
        b[i] = self.pursuer_first[kp[i], ab[i, 0], ab[i, 1]]
        return a, b

    def summary(self) -> dict[str, Any]:
        """Size, timing and the winning shares (over the states where surveillance holds)."""
        n = max(1, self.states)
        return {
            "cells_per_lmin": self.cells_per_lmin,
            "steps": self.steps,
            "cell": self.lattice.h,
            "tau": self.tau,
            "points": self.lattice.n_points,
            "states": self.states,
            "evader_first": np.count_nonzero(self.evader_first) / n,
            "pursuer_first": np.count_nonzero(self.pursuer_first) / n,
            "iterations": self.iterations,
            "seconds": dict(self.seconds),
        }


def _resolution(spec: GameSpec, cpl: float, steps: float) -> Resolution:
    h = spec.l_min / cpl
    return Resolution(cell=h, coarse=1, tau=steps * h / spec.v_pursuer, sweep_pieces=1)


def _discretise(spec: GameSpec, cpl: float, steps: float, headings: int):
    """``(resolution, lattice, pursuer moves, evader moves)``; the lattice's windows reach
    the offsets of the intermediate states (``l_max`` plus both moves)."""
    res = _resolution(spec, cpl, steps)
    vp = heading_moves(spec.v_pursuer * res.tau, res.cell, headings)
    ve = heading_moves(spec.v_evader * res.tau, res.cell, headings)
    reach = res.cell * float(np.max(np.hypot(*vp.T)) + np.max(np.hypot(*ve.T)))
    return res, Lattice(spec, res, "pursuer", reach=reach), vp, ve


def _clear_states(lat: Lattice, spec: GameSpec, lo: float, hi: float) -> np.ndarray:
    """(n, W, W): the evader on a lattice point at a distance in [lo, hi] from the pursuer's,
    and the segment between them clear (the kernel's ``line_of_sight``)."""
    free = np.zeros((lat.nx, lat.ny), dtype=bool)
    free[lat.point_cells[:, 0] - lat.i0, lat.point_cells[:, 1] - lat.j0] = True
    clear = lat.windows(free, False)
    d = np.hypot(lat.offsets[..., 0], lat.offsets[..., 1])
    clear &= ((d >= lo) & (d <= hi))[None]
    if len(spec.map.convex_vertices):
        ker = kernel_for(spec.map)
        idx = np.flatnonzero(clear)
        W2 = lat.W * lat.W
        off = lat.offsets.reshape(-1, 2)
        for s in range(0, len(idx), _CHUNK):
            i = idx[s : s + _CHUNK]
            P = lat.points[i // W2]
            ok = ker.line_of_sight_many(P, P + off[i % W2])
            clear.flat[i[~ok]] = False
    return clear


def _fan_blocked(lat: Lattice, clear: np.ndarray, vec: np.ndarray, mover: str) -> list[np.ndarray]:
    """Per move, the flat indices of the states in ``clear`` whose move sweeps a triangle
    holding a convex obstacle vertex (the rod touches a wall during the move).

    Relative to the pursuer's point, with r the evader's offset and d the move: the
    pursuer's move sweeps the triangle (r, 0, d), the evader's (0, r, r + d).
    """
    v, _, _ = convex_corners(lat.spec.map)
    out = [np.zeros(0, dtype=np.int64) for _ in vec]
    if len(v) == 0:
        return out
    idx = np.flatnonzero(clear)
    W2 = lat.W * lat.W
    off = lat.offsets.reshape(-1, 2)
    reach = float(np.max(np.hypot(off[:, 0], off[:, 1]))) + lat.h * float(np.max(np.hypot(*vec.T)))
    parts: list[list[np.ndarray]] = [[] for _ in vec]
    for s in range(0, len(idx), _CHUNK):
        i = idx[s : s + _CHUNK]
        P = lat.points[i // W2]
        r = off[i % W2]
        for vx in v:
            w = vx - P
            near = np.hypot(w[:, 0], w[:, 1]) <= reach
            if not near.any():
                continue
            iw, ww, rw = i[near], w[near], r[near]
            for m, d in enumerate(vec):
                if not d.any():
                    continue
                dd = np.broadcast_to(lat.h * d.astype(float), rw.shape)
                if mover == "pursuer":
                    hit = _in_triangle(ww, rw, np.zeros(2), dd)
                else:
                    hit = _in_triangle(ww, np.zeros(2), rw, rw + dd)
                parts[m].append(iw[hit])
    for m in range(len(vec)):
        if parts[m]:
            out[m] = np.unique(np.concatenate(parts[m]))
    return out


def _joint_range(off: np.ndarray, a: np.ndarray, b: np.ndarray, l_min: float) -> np.ndarray:
    """(W, W): the evader's offset moving linearly from ``off + a`` to ``off + b`` keeps
    at least ``l_min`` (the largest distance is at an end, by convexity)."""
    return _segment_origin_distance(off + a, off + b) >= l_min


def _shift2(R: np.ndarray, x: np.ndarray) -> np.ndarray:
    """``out[a, b] = R[a - x0, b - x1]`` (False off the window) for a (W, W) table."""
    return shifted(R[None], int(x[0]), int(x[1]), False)[0]


def solve_estimate(
    spec: GameSpec,
    cells_per_lmin: float,
    *,
    steps: float = 4.0,
    headings: int = 16,
    progress: bool = False,
    memory_budget: object = None,
) -> EstimateSolution:
    """Solve the discrete game (module docstring) at one resolution, in both orders.

    Args:
        spec: the game.
        cells_per_lmin: cells per L_min (> 0).
        steps: cells the pursuer covers per step (> 0; the evader ``rho`` times that).
        headings: directions of the moves (>= 4).
        progress: print each sweep.
        memory_budget: bytes (or ``"2GB"``) the solve may take; default
            ``$SURVEIL_MEMORY_BUDGET`` or half the RAM (:mod:`strategies.referee._budget`).

    Raises:
        InfeasibleError: the solve's estimated memory exceeds the budget (checked before
            anything is allocated; the message names the estimate and the knobs).
    """
    if not isinstance(spec, GameSpec):
        raise InvalidConfigError(f"solve_estimate: expected a GameSpec, got {type(spec).__name__}")
    cpl = check_cells_per_lmin(cells_per_lmin)
    steps = V.positive("steps", steps)
    headings = V.integer("headings", headings, minimum=4)
    check_budget(
        f"solve_estimate(map {spec.map.name!r}, {cpl:g} cells per L_min)",
        [estimate_size(spec, cpl, steps, headings)],
        memory_budget,
        resize=lambda c: [estimate_size(spec, c, steps * c / cpl, headings)],
        cells_per_lmin=cpl,
    )
    t0 = time.perf_counter()
    res, lat, vp, ve = _discretise(spec, cpl, steps, headings)
    h = res.cell
    sp = h * float(np.max(np.hypot(*vp.T)))
    se = h * float(np.max(np.hypot(*ve.T)))
    tp = _move_targets(lat, vp)
    te = _move_targets(lat, ve)
    W, n = lat.W, lat.n_points
    shape = (n, W, W)
    off = lat.offsets
    d = np.hypot(off[..., 0], off[..., 1])
    # rods that must be clear: at each step's end (safe) and between the two half-moves
    clear = _clear_states(lat, spec, max(0.0, spec.l_min - sp - se), spec.l_max + sp + se)
    safe = clear & ((d >= spec.l_min) & (d <= spec.l_max))[None]
    fan_p = _fan_blocked(lat, clear, vp, "pursuer")
    fan_e = _fan_blocked(lat, clear, ve, "evader")
    grid = np.full((lat.nx, lat.ny), -1, dtype=np.int64)
    grid[lat.point_cells[:, 0] - lat.i0, lat.point_cells[:, 1] - lat.j0] = np.arange(n)
    q = lat.windows(grid, -1)  # the evader's point per state
    cidx = np.flatnonzero(clear)
    # evader moves it cannot make from its point (into or through a wall): not available
    skip_e = [cidx[te[q.flat[cidx], m] < 0] for m in range(len(ve))]
    del q
    hv = [h * x.astype(float) for x in vp]
    he = [h * x.astype(float) for x in ve]
    # order 1, evader first: r -> r + e (rod p-e' clear, fan of e's move), then
    # r + e -> r + e - p (fan of p's move at the intermediate state); range along the
    # joint straight motion r -> r + e - p
    rng1 = [[_joint_range(off, 0.0, e - p, spec.l_min) for e in he] for p in hv]
    # ... as a function of the intermediate offset r'' = r + e (so one shift per e)
    rng1s = [[_shift2(rng1[m][j], ve[j]) for j in range(len(ve))] for m in range(len(vp))]
    # order 2, pursuer first, from the intermediate offset r' = r - p: r' + p -> r' + e
    rng2 = [[_joint_range(off, p, e, spec.l_min) for e in he] for p in hv]
    # the sweeps work on arrays packed 8 states a byte along the last window axis
    pack = lambda X: np.packbits(X, axis=2)
    unpack = lambda Y: np.unpackbits(Y, axis=2, count=W).view(bool)

    def masked(X: np.ndarray, false=(), true=()) -> np.ndarray:
        X = X.copy()
        for idx in false:
            X.flat[idx] = False
        for idx in true:
            X.flat[idx] = True
        return pack(X)

    ones = np.ones(shape, dtype=bool)
    clear_p = pack(clear)
    safe_p = pack(safe)
    rng1s = [[pack(np.broadcast_to(t, (1, W, W)))[0] for t in row] for row in rng1s]
    rng2 = [[pack(np.broadcast_to(t, (1, W, W)))[0] for t in row] for row in rng2]
    # evader first: its intermediate rod clear and no fan hit (or the move not available)
    mid_e = [masked(shifted(clear, -int(x[0]), -int(x[1]), False), (fan_e[j],), (skip_e[j],))
             for j, x in enumerate(ve)]  # fmt: skip
    nofan_p = [masked(ones, (fan_p[m],)) for m in range(len(vp))]
    nofan_e = [masked(ones, (fan_e[j],)) for j in range(len(ve))]
    skip = [masked(~ones, (), (skip_e[j],)) for j in range(len(ve))]
    t1 = time.perf_counter()

    def pursuer_step(X: np.ndarray, m: int) -> np.ndarray:
        """(k, r) -> X(target of move m from k, r - move), False where it is not allowed."""
        ok = tp[:, m] >= 0
        g = np.zeros(shape, dtype=bool)
        g[ok] = shifted(X[tp[ok, m]], int(vp[m][0]), int(vp[m][1]), False)
        return pack(g)

    sweeps = [0, 0]
    A = safe_p.copy()  # evader first
    # the sweep in which each state left the set; 255 (or 65535) where it never does
    rank = np.where(safe, np.uint16(_NEVER), np.uint16(0))
    prev = safe
    while True:
        sweeps[0] += 1
        Au = unpack(A)
        rank[prev & ~Au] = sweeps[0] - 1
        prev = Au.copy()
        # G[m] at the intermediate state (k, r''): p's move m from k allowed, no fan hit,
        # the rod p-e'' clear, A at the end
        G = [pursuer_step(Au, m) & nofan_p[m] & clear_p for m in range(len(vp))]
        An = safe_p.copy()
        for j, x in enumerate(ve):
            acc = np.zeros_like(A)
            for m in range(len(vp)):
                acc |= G[m] & rng1s[m][j][None]
            acc = pack(shifted(unpack(acc), -int(x[0]), -int(x[1]), False))
            An &= (acc & mid_e[j]) | skip[j]
        if progress:
            print(f"  estimate cpl {cpl:g} evader first: sweep {sweeps[0]}, "
                  f"{int(np.unpackbits(An).sum())} states won")  # fmt: skip
        if np.array_equal(An, A):
            break
        A = An
    B = safe_p.copy()  # pursuer first
    while True:
        sweeps[1] += 1
        Bu = unpack(B)
        SB = [pack(shifted(Bu, -int(x[0]), -int(x[1]), False)) & nofan_e[j]
              for j, x in enumerate(ve)]  # fmt: skip
        Bn = np.zeros_like(B)
        for m in range(len(vp)):
            T = clear_p.copy()  # intermediate rod p'-e clear
            for j in range(len(ve)):
                T &= (SB[j] & rng2[m][j][None]) | skip[j]
            Bn |= pursuer_step(unpack(T), m) & nofan_p[m]
        Bn &= safe_p
        if progress:
            print(f"  estimate cpl {cpl:g} pursuer first: sweep {sweeps[1]}, "
                  f"{int(np.unpackbits(Bn).sum())} states won")  # fmt: skip
        if np.array_equal(Bn, B):
            break
        B = Bn
    A = unpack(A).copy()
    B = unpack(B).copy()
    rank = _compact_rank(rank, sweeps[0])
    t2 = time.perf_counter()
    return EstimateSolution(
        spec=spec,
        cells_per_lmin=cpl,
        steps=steps,
        headings=headings,
        lattice=lat,
        safe=safe,
        evader_first=A,
        pursuer_first=B,
        iterations=sum(sweeps),
        seconds={"build": t1 - t0, "solve": t2 - t1},
        evader_first_rank=rank,
    )


_NEVER = np.iinfo(np.uint16).max


def _compact_rank(rank: np.ndarray, sweeps: int) -> np.ndarray:
    """uint8 ranks (255: never left) when the sweeps fit, else uint16 (65535)."""
    if sweeps < 255:
        out = rank.astype(np.uint8)
        out[rank == _NEVER] = 255
        return out
    return rank


def _cached_solution(
    spec, cpl, steps, headings, cache, cache_dir, progress, memory_budget=None
) -> EstimateSolution:
    res = _resolution(spec, cpl, steps)
    kind = f"estimate{headings}"
    names = ("safe", "evader_first", "pursuer_first", "iterations", "seconds", "rank")
    if cache:
        arrays = load_arrays(kind, spec, res, names, cache_dir)
        if arrays is not None:
            _, lat, _, _ = _discretise(spec, cpl, steps, headings)
            shape = (lat.n_points, lat.W, lat.W)
            unpack = lambda a: np.unpackbits(a, count=int(np.prod(shape))).reshape(shape)
            if arrays["safe"].size * 8 >= np.prod(shape):
                return EstimateSolution(
                    spec, float(cpl), float(steps), int(headings), lat,
                    unpack(arrays["safe"]).astype(bool),
                    unpack(arrays["evader_first"]).astype(bool),
                    unpack(arrays["pursuer_first"]).astype(bool),
                    int(arrays["iterations"]),
                    {"build": float(arrays["seconds"][0]), "solve": float(arrays["seconds"][1])},
                    arrays["rank"].reshape(shape),
                )  # fmt: skip
    sol = solve_estimate(
        spec, cpl, steps=steps, headings=headings, progress=progress, memory_budget=memory_budget
    )
    if cache:
        try:
            save_arrays(kind, spec, res, {
                "safe": np.packbits(sol.safe),
                "evader_first": np.packbits(sol.evader_first),
                "pursuer_first": np.packbits(sol.pursuer_first),
                "iterations": np.array(sol.iterations),
                "seconds": np.array([sol.seconds["build"], sol.seconds["solve"]]),
                "rank": sol.evader_first_rank.ravel(),
            }, cache_dir)  # fmt: skip
        except OSError:
            pass
    return sol


@dataclass
class Estimate:
    """The discrete game solved at several resolutions: an *estimate*, not a certificate.

    Attributes:
        spec: the game.
        solutions: one :class:`EstimateSolution` per resolution, coarsest first.
    """

    spec: GameSpec
    solutions: list[EstimateSolution]

    @property
    def cpls(self) -> tuple[float, ...]:
        """The resolutions (cells per L_min), coarsest first."""
        return tuple(s.cells_per_lmin for s in self.solutions)

    def labels(self, pursuer, evader) -> np.ndarray:
        """``"pursuer"``, ``"evader"`` or ``"contested"`` for each start (k, 2), (k, 2)."""
        P = np.atleast_2d(np.asarray(pursuer, dtype=float))
        E = np.atleast_2d(np.asarray(evader, dtype=float))
        every = np.ones(len(P), dtype=bool)
        none = np.ones(len(P), dtype=bool)
        for sol in self.solutions:
            for w in sol.wins(P, E):
                every &= w
                none &= ~w
        out = np.full(len(P), "contested", dtype=object)
        out[every] = "pursuer"
        out[none] = "evader"
        return out.astype(str)

    def classify(self, pursuer, evader) -> str:
        """The estimated label of one start: who wins it in every solution, or
        ``"contested"`` (the solutions disagree: within the resolution error).

        Examples:
            A slow evader in an open room: the pursuer wins in every solution. At rho =
            0.5 the pursuer wins when it moves after the evader, and loses when it moves
            first, at both resolutions: contested.

            >>> from envs.maps import Map
            >>> room = Map([(0, 0), (5, 0), (5, 5), (0, 5)])
            >>> spec = GameSpec(room, 1.0, 2.0, v_pursuer=1.0, v_evader=0.2, body_radius=0.05)
            >>> estimate(spec, cpls=(5, 6), steps=4, cache=False).classify((2.5, 4), (2.5, 2.5))
            'pursuer'
            >>> spec = GameSpec(room, 1.0, 2.0, v_pursuer=1.0, v_evader=0.5, body_radius=0.05)
            >>> estimate(spec, cpls=(4, 5), cache=False).classify((2.5, 4), (2.5, 2.5))
            'contested'
        """
        p = V.point("pursuer", pursuer)
        e = V.point("evader", evader)
        return str(self.labels(p[None], e[None])[0])

    def lattice_starts(self) -> tuple[np.ndarray, np.ndarray]:
        """The finest solution's states where surveillance holds, as (k, 2) positions."""
        sol = self.solutions[-1]
        lat = sol.lattice
        idx = np.flatnonzero(sol.safe)
        W2 = lat.W * lat.W
        P = lat.points[idx // W2]
        return P, P + lat.offsets.reshape(-1, 2)[idx % W2]

    def summary(self) -> dict[str, Any]:
        """The label shares over :meth:`lattice_starts` and each solution's summary.

        ``contested`` is the resolution error: the share of starts on which the solutions
        (resolutions and information orders) disagree.
        """
        P, E = self.lattice_starts()
        counts = dict.fromkeys(ESTIMATE_LABELS, 0)
        for s in range(0, len(P), _CHUNK):
            lab = self.labels(P[s : s + _CHUNK], E[s : s + _CHUNK])
            for k in ESTIMATE_LABELS:
                counts[k] += int(np.count_nonzero(lab == k))
        n = max(1, len(P))
        return {
            "map": self.spec.map.name,
            "rho": self.spec.rho,
            "starts": len(P),
            **{k: v / n for k, v in counts.items()},
            "solutions": [s.summary() for s in self.solutions],
        }


def check_cpls(cpls: Sequence[float]) -> list[float]:
    """The resolutions of :func:`estimate` as floats: at least two, all different.

    Raises:
        InvalidConfigError: otherwise (the resolution error is their disagreement).
    """
    values = [check_cells_per_lmin(c, "cpls") for c in cpls]
    if len(set(values)) < 2 or len(set(values)) < len(values):
        raise InvalidConfigError(
            f"cpls = {tuple(cpls)!r}: expected at least two different resolutions (the "
            "resolution error is their disagreement)"
        )
    return values


def estimate(
    spec: GameSpec,
    cpls: Sequence[float] = (6.0, 8.0),
    *,
    steps: float | Sequence[float] | None = None,
    headings: int = 16,
    cache: bool = True,
    cache_dir: str | os.PathLike | None = None,
    progress: bool = False,
    memory_budget: object = None,
) -> Estimate:
    """Solve (or load) the discrete game at each resolution in ``cpls`` (two or more).

    Args:
        spec: the game.
        cpls: cells per L_min of each resolution (at least two, each > 0, all different).
        steps: cells the pursuer covers per step at each resolution (one number for all,
            or one per entry of ``cpls``; ``tau = steps l_min / (cpl V_p)``); the evader
            covers ``rho steps`` cells. None: 4 at the coarsest resolution and
            proportionally more at the others (``4 cpl / min(cpls)``), so every solution
            has the same step ``tau = 4 l_min / (min(cpls) V_p)`` and the finer ones refine
            space and the snapping of the moves: at rho = 0.5 the evader's 16 headings of 2
            cells snap to lengths 1.41, 2 and 2.24, of 2.67 cells to 2.24, 2.83 and 3. With
            the same ``steps`` at every resolution every solution snaps alike and the
            contested share misses that error (an empty 12 x 8 room at rho = 0.5, 8 cells
            per L_min: the pursuer moving second wins 0 % of the states at 4 cells a step,
            49 % at 6); a longer step costs the pursuer that moves first (the evader
            answers a longer committed move). Below 2 evader cells a step the snapped moves
            are coarse (a move of one cell is 1 or sqrt(2) cells long: up to 41 % fast).
        headings: directions of the moves.
        cache: read and write the on-disk cache (:mod:`.cache`).
        cache_dir: cache directory (default ``$SURVEIL_CACHE_DIR`` or ``~/.cache/surveil``).
        progress: print the sweeps.
        memory_budget: bytes (or ``"2GB"``) the solves may take together (each solution
            is kept while the next is solved); default ``$SURVEIL_MEMORY_BUDGET`` or half
            the RAM. Checked before anything is solved or loaded.

    Raises:
        MemoryBudgetError: the estimated peak exceeds the budget (the message gives the
            estimate and the knobs: fewer or coarser ``cpls``, the budget).
    """
    values, order, per, headings, budget = _plan(spec, cpls, steps, headings, memory_budget)
    sols = [_cached_solution(spec, values[i], s, headings, cache, cache_dir, progress, budget)
            for i, s in zip(order, per, strict=True)]  # fmt: skip
    return Estimate(spec, sols)


def check_estimate(
    spec: GameSpec,
    cpls: Sequence[float] = (6.0, 8.0),
    *,
    steps: float | Sequence[float] | None = None,
    headings: int = 16,
    memory_budget: object = None,
) -> None:
    """Check :func:`estimate`'s arguments and memory budget without solving anything, so a
    caller can refuse them before its other long work (``surveil referee --estimate``).

    Raises:
        InvalidConfigError, MemoryBudgetError: as :func:`estimate`.
    """
    _plan(spec, cpls, steps, headings, memory_budget)


def _plan(spec, cpls, steps, headings, memory_budget):
    """:func:`estimate`'s checked arguments ``(values, order, per, headings, budget)``:
    the resolutions, their order (coarsest first), the steps in that order, the headings
    and the memory budget in bytes, after checking that the solves fit in it."""
    if not isinstance(spec, GameSpec):
        raise InvalidConfigError(f"estimate: expected a GameSpec, got {type(spec).__name__}")
    values = check_cpls(cpls)
    order = np.argsort(values, kind="stable")
    if steps is None:
        per = [4.0 * values[i] / values[order[0]] for i in order]
    elif isinstance(steps, Sequence):
        if len(steps) != len(values):
            raise InvalidConfigError(
                f"steps = {tuple(steps)!r}: expected one number, or one per resolution in "
                f"cpls = {tuple(cpls)!r}"
            )
        per = [V.positive("steps", steps[i]) for i in order]
    else:
        per = [V.positive("steps", steps)] * len(values)
    headings = V.integer("headings", headings, minimum=4)
    finest = values[order[-1]]

    def sizes(c: float) -> list:  # every resolution scaled by c / finest
        return [estimate_size(spec, values[i] * c / finest, s * c / finest, headings)
                for i, s in zip(order, per, strict=True)]  # fmt: skip

    budget = check_budget(
        f"estimate(map {spec.map.name!r}, cpls = {tuple(cpls)!r})",
        sizes(finest),
        memory_budget,
        resize=sizes,
        cells_per_lmin=finest,
        knob="the finest of cpls (the others in proportion)",
    )
    return values, order, per, headings, budget
