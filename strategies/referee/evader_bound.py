"""The evader bound: starts from which the evader provably breaks surveillance.

The discretisation favours the pursuer everywhere, so a win here is a win in the real
game against any pursuer:

* **Information.** The evader commits to a straight move for a step of ``tau``; the
  pursuer sees it before moving.
* **Evader.** It sits exactly on the certified lattice and moves along lattice vectors of
  length <= V_e tau whose paths keep ``body_radius`` from the walls (standing still
  included): a restriction, which only costs it.
* **Pursuer.** Located by its cell only (anywhere in it); in one step it may end in any
  open cell within V_p tau of its cell: a superset of what it can do.
* **Losing set, robust and only at step boundaries.** The evader wins a step only when
  surveillance is broken at its end for *every* pursuer position in the cell: the whole
  cell out of range, or every rod from the evader to the cell blocked. Breaks inside a
  step are ignored (they would only help the evader). Robust occlusion uses the fact of
  :mod:`strategies.referee.robust`: when the cell's free part is convex and no convex
  vertex lies in the hull of the evader and the cell's disc, all rods to the cell are
  blocked as soon as one is, and one is when the segment to a point of the cell crosses a
  wall properly.

The evader's winning set is the least fixed point (an attractor): broken states, then
states with a move all of whose pursuer successors are already winning. The round at which
a state enters is its *rank*: the evader breaks surveillance within ``rank`` steps from it.

**Blind spot (issue 13).** The pursuer moving after seeing the evader's whole step, an
evader that wins only by rounding a corner closely needs lattice points close to the corner
and a short step. On two_rooms (corridor 1 wide, L in [2, 4], rho = 0.5, 16 cells per
L_min) the default lattice of :func:`~strategies.referee.referee.solve` (coarse 4: spacing
0.5, one row in the corridor, tau 2 s) certifies 0.17 % of the live states and coarse 2
(spacing 0.25, tau 1 s) 100 %. The first state lost is not a bug: evader (0.5, 1.0) just
round the corner (0, 0.5), the pursuer's cell at (-1.125, -0.5) in the corridor, whose rod
passes 0.04 from the corner (a real pursuer there sees the evader); nor the lattice's phase
(shifting the cells' anchor by a quarter or half a spacing certifies 0.05 - 0.13 % of the
starts). :func:`~strategies.referee.referee.solve` therefore retries a default lattice
that certifies less than :data:`~strategies.referee.referee.EVADER_FALLBACK_SHARE` of its
live states (:meth:`EvaderBound.live_fraction`) at half the cells per spacing.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
from scipy import ndimage

from strategies.referee._bound import SolvedBound
from strategies.referee._budget import bound_size, check_budget
from strategies.referee._fixpoint import Worklist, erode, reach_rectangles
from strategies.referee.lattice import Lattice, segment_wall_distance
from strategies.referee.robust import (
    convex_corners,
    fan_hits_vertex,
    segment_crosses_walls,
    square_range,
)
from strategies.referee.spec import GameSpec, Resolution

__all__ = ["EvaderBound", "solve_evader_bound"]


@dataclass
class EvaderBound(SolvedBound):
    """The solved evader bound.

    Attributes:
        spec: the game.
        res: the resolution.
        lattice: cells and the evader's lattice.
        vectors: (n_moves, 2) evader moves in cells (row 0 is standing still).
        targets: (n_points, n_moves) point reached by each move, -1 if not allowed.
        win: (n_points, W, W) states (evader point, pursuer cell) the evader wins from.
        rank: (n_points, W, W) int32, the round at which a state became winning (0: broken
            already), -1 if it never did.
        choice: (n_points, W, W) int16, the move that made a state winning (-1: none).
        iterations: rounds of the fixed point.
        seconds: wall time of the build and of the fixed point.
        fallback_from: the resolution of the default lattice when it certified next to
            nothing and :func:`~strategies.referee.referee.solve` fell back to this bound's
            finer one (``evader_fallback``); None when this is the lattice asked for. Not
            cached.
    """

    role: ClassVar[str] = "evader"
    tables: ClassVar[dict[str, Any]] = {"win": bool, "rank": np.int32, "choice": np.int16}

    win: np.ndarray
    rank: np.ndarray
    choice: np.ndarray
    iterations: int
    seconds: dict[str, float]
    fallback_from: Resolution | None = None

    @property
    def reach(self) -> float:
        """How far the pursuer may get in one step, plus the margin: V_p tau + margin."""
        return self.spec.v_pursuer * self.res.tau + self.spec.margin

    def plan(self, pursuer, evader) -> tuple[np.ndarray, int] | None:
        """A certified next lattice point for the evader from the real positions.

        The evader moves straight to a lattice point at most V_e tau away (its path
        keeping the body radius from the walls); whatever the pursuer does, it ends in an
        open cell within V_p tau of its real position, and every such state must be
        winning. Among the certified moves, the one with the smallest worst rank wins.

        Returns:
            ``(target (2,), steps)``: the point and a bound on the referee steps left
            until surveillance breaks (including this one); None if no move is certified.
        """
        spec, lat = self.spec, self.lattice
        p = np.asarray(pursuer, dtype=float)
        e = np.asarray(evader, dtype=float)
        step = spec.v_evader * self.res.tau
        cand = lat.points_within(e, step)
        if len(cand) == 0:
            return None
        B = lat.points[cand]
        clear = segment_wall_distance(np.broadcast_to(e, B.shape), B, spec.map)
        cand = cand[clear >= spec.body_radius * (1.0 - 1e-9) - spec.margin]
        cells = lat.open_cells_within(p, self.reach)
        best: tuple[int, int] | None = None
        for k in cand.tolist():
            ab = lat.window_cell(np.array([k]), cells)
            inside = (ab[:, 0] >= 0) & (ab[:, 0] < lat.W) & (ab[:, 1] >= 0) & (ab[:, 1] < lat.W)
            r = self.rank[k, ab[inside, 0], ab[inside, 1]]
            if (r < 0).any():
                continue
            worst = int(r.max()) if len(r) else 0  # cells off the window: out of range
            if best is None or worst < best[1]:
                best = (k, worst)
        if best is None:
            return None
        return lat.points[best[0]].copy(), best[1] + 1

    def certifies(self, pursuer, evader) -> bool:
        """Whether the evader provably breaks surveillance from this real start."""
        return self.plan(pursuer, evader) is not None

    def escape_steps(self, pursuer, evader) -> int | None:
        """Referee steps within which the evader breaks surveillance (None: not certified)."""
        got = self.plan(pursuer, evader)
        return None if got is None else got[1]

    def fraction(self) -> float:
        """Fraction of the states (evader point, open pursuer cell possibly in range) won."""
        dom = self._domain()
        return float(self.win[dom].mean()) if dom.any() else 0.0

    def live_fraction(self) -> float:
        """Fraction of the live states (those of :meth:`fraction` where surveillance is not
        broken already: the pursuer's cell possibly in range and not robustly occluded)
        won: what the evader wins by moving, without the states it has won before moving,
        which are 0.1 - 2 % of :meth:`fraction`'s on the built-in maps at rho = 0.5."""
        live = self._domain() & (self.rank != 0)
        return float(self.win[live].mean()) if live.any() else 0.0

    def _domain(self) -> np.ndarray:
        lat = self.lattice
        open_w = lat.windows(lat.cell_open, False)
        return open_w & ~_range_broken(lat, self.spec)[None]


def _range_broken(lat: Lattice, spec: GameSpec) -> np.ndarray:
    """(W, W): window cells entirely out of range of the window's centre."""
    near, far = square_range(lat.offsets[..., 0], lat.offsets[..., 1], 0.5 * lat.h)
    m = spec.margin
    return (near > spec.l_max + m) | (far < spec.l_min - m)


def _occlusion_broken(lat: Lattice, spec: GameSpec, candidates: np.ndarray) -> np.ndarray:
    """(n_points, W, W): among ``candidates``, the states robustly occluded.

    A state (evader point e, pursuer cell c) is robustly occluded when cell ∩ F is convex,
    no rod from e to the cell's disc can graze a convex vertex
    (:func:`~strategies.referee.robust.fan_hits_vertex`), and the rod to one point of the
    cell crosses a wall properly. Neighbouring cells that lie inside free space and pass
    the grazing test share their visibility (the rods to their union vary without
    grazing), so the line of sight is tested once per connected group of them.
    """
    world = spec.map
    out = np.zeros(candidates.shape, dtype=bool)
    if not world.vertex_convex.any():
        return out  # a convex free region: no rod between two of its points is blocked
    convex, rep, interior = lat.convex_cells()
    cand = candidates & lat.windows(convex, False)
    R = lat.delta + spec.margin
    ox, oy = lat.offsets[..., 0], lat.offsets[..., 1]
    L2 = np.maximum(ox * ox + oy * oy, 1e-300)
    verts, din, dout = convex_corners(world)
    for v, di, do in zip(verts, din, dout, strict=True):
        rel = v[None, :] - lat.points
        near_pt = np.hypot(*rel.T) <= spec.l_max + R + lat.h
        for s in range(0, lat.n_points, 256):
            ks = np.arange(s, min(s + 256, lat.n_points))
            ks = ks[near_pt[ks]]
            if len(ks) == 0:
                continue
            vx = rel[ks, 0][:, None, None]
            vy = rel[ks, 1][:, None, None]
            # a rod from e through v to the disc passes within R of the centre's segment
            t = np.clip((vx * ox + vy * oy) / L2, 0.0, 1.0)
            near = (np.hypot(vx - t * ox, vy - t * oy) <= R + spec.margin) & cand[ks]
            k_i, a_i, b_i = np.nonzero(near)
            if len(k_i) == 0:
                continue
            hit = fan_hits_vertex(
                0.0,
                0.0,
                vx[k_i, 0, 0],
                vy[k_i, 0, 0],
                ox[a_i, b_i],
                oy[a_i, b_i],
                R,
                di,
                do,
                spec.margin,
            )
            cand[ks[k_i[hit]], a_i[hit], b_i[hit]] = False
    edges = (world.edge_start, world.edge_end)
    # groups of interior candidate cells, 4-connected within each window
    inner = cand & lat.windows(interior, False)
    structure = np.zeros((3, 3, 3), dtype=bool)
    structure[1] = [[0, 1, 0], [1, 1, 1], [0, 1, 0]]
    labels, n_groups = ndimage.label(inner, structure=structure)
    if n_groups:
        flat = labels.ravel()
        first = np.zeros(n_groups + 1, dtype=np.int64)
        nz = np.flatnonzero(flat)
        uniq, idx = np.unique(flat[nz], return_index=True)
        first[uniq] = nz[idx]
        k_i, a_i, b_i = np.unravel_index(first[1:], labels.shape)
        P = lat.points[k_i]
        Q = P + lat.offsets[a_i, b_i]  # an interior cell's centre is in free space
        crossed = np.concatenate([[False], segment_crosses_walls(P, Q, *edges)])
        out |= crossed[labels]
    # the cells meeting a wall, one by one through their free point
    k_i, a_i, b_i = np.nonzero(cand & ~inner)
    if len(k_i):
        Q = lat.windows(rep, np.nan)[k_i, a_i, b_i]
        ok = np.isfinite(Q).all(axis=1)
        crossed = np.zeros(len(k_i), dtype=bool)
        crossed[ok] = segment_crosses_walls(lat.points[k_i[ok]], Q[ok], *edges)
        out[k_i[crossed], a_i[crossed], b_i[crossed]] = True
    return out


def solve_evader_bound(
    spec: GameSpec, res: Resolution, *, progress: bool = False, memory_budget: object = None
) -> EvaderBound:
    """Solve the pursuer-favoured discrete game (see the module docstring).

    Args:
        spec: the game.
        res: the resolution.
        progress: print one line per round.
        memory_budget: bytes (or ``"2GB"``) the solve may take; default
            ``$SURVEIL_MEMORY_BUDGET`` or half the RAM (:mod:`strategies.referee._budget`).

    Returns:
        The :class:`EvaderBound`.

    Raises:
        InfeasibleError: the solve's estimated memory exceeds the budget (checked before
            anything is allocated; the message names the estimate and the knobs).
    """
    check_budget(
        f"solve_evader_bound(map {spec.map.name!r}, cell = {res.cell:g})",
        [bound_size(spec, res, "evader")],
        memory_budget,
    )
    t0 = time.perf_counter()
    lat = Lattice(spec, res, "evader")
    vectors, targets = lat.moves(spec.v_evader * res.tau)
    open_w = lat.windows(lat.cell_open, False)
    rbroken = _range_broken(lat, spec)[None]
    live = open_w & ~rbroken
    X = (open_w & rbroken) | _occlusion_broken(lat, spec, live)
    t1 = time.perf_counter()
    rank = np.where(X, 0, -1).astype(np.int32)
    choice = np.full(X.shape, -1, dtype=np.int16)
    closed = ~open_w  # the pursuer cannot be in closed cells: they never save it
    rects = reach_rectangles(spec.v_pursuer * res.tau + spec.margin, lat.h)
    # B(q, o): every pursuer successor of the cell at offset o from point q is won. The
    # evader's move shifts offsets by up to its step, which can leave q's window (the
    # evader walked away), so B is computed on a window padded by that much: cells off
    # the window are out of range (won), but the pursuer may walk back into range.
    pad = int(np.abs(vectors).max()) if len(vectors) else 0
    B = _erode_padded(X | closed, rects, pad)
    work = Worklist(targets)
    iterations = 0
    while True:
        iterations += 1
        ks = work.todo()
        gain, first = _gains(ks, X, B, open_w, vectors, targets, pad)
        changed = gain.any(axis=(1, 2))
        if progress:
            print(f"evader bound: round {iterations}, {int(gain.sum())} states won")
        if not changed.any():
            break
        kc = ks[changed]
        X[kc] |= gain[changed]
        rank[kc] = np.where(gain[changed], iterations, rank[kc])
        choice[kc] = np.where(gain[changed], first[changed], choice[kc])
        work.changed(kc)
        B[kc] = _erode_padded(X[kc] | closed[kc], rects, pad)
    t2 = time.perf_counter()
    return EvaderBound(
        spec=spec,
        res=res,
        lattice=lat,
        vectors=vectors,
        targets=targets,
        win=X,
        rank=rank,
        choice=choice,
        iterations=iterations,
        seconds={"build": t1 - t0, "solve": t2 - t1},
    )


def _erode_padded(X: np.ndarray, rects, pad: int) -> np.ndarray:
    """Erosion of X padded by ``pad`` won (out-of-range) cells on every side."""
    if pad == 0:
        return erode(X, rects, border=True)
    Xp = np.pad(X, ((0, 0), (pad, pad), (pad, pad)), constant_values=True)
    return erode(Xp, rects, border=True)


def _gains(ks, X, B, open_w, vectors, targets, pad, chunk: int = 256):
    """For points ``ks``: states not yet won that have a move whose every pursuer
    successor is won (B at the target, B padded by ``pad``), and the first such move."""
    if len(ks) > chunk:
        parts = [
            _gains(ks[s : s + chunk], X, B, open_w, vectors, targets, pad, chunk)
            for s in range(0, len(ks), chunk)
        ]
        return np.concatenate([p[0] for p in parts]), np.concatenate([p[1] for p in parts])
    W = X.shape[1]
    gain = np.zeros((len(ks), W, W), dtype=bool)
    first = np.full((len(ks), W, W), -1, dtype=np.int16)
    if len(ks) == 0:
        return gain, first
    todo = open_w[ks] & ~X[ks]
    for j, vec in enumerate(vectors):
        tj = targets[ks, j]
        valid = np.flatnonzero(tj >= 0)
        if len(valid) == 0:
            continue
        dx, dy = int(vec[0]), int(vec[1])
        g = B[tj[valid], pad - dx : pad - dx + W, pad - dy : pad - dy + W] & todo[valid]
        first[valid] = np.where(g & (first[valid] < 0), j, first[valid])
        gain[valid] |= g
    return gain, first
