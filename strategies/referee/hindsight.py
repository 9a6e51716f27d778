"""Hindsight: could *any* pursuer have held against a known evader path?

Issue 13's bounded-speed ground truth for *open-loop* evaders, whose path does not depend
on the pursuer (``evader/straight``, ``evader/wall_hugging``, ``evader/random``,
``evader/orbit``: they read the map and their own state only, and the env's two bodies
pass through each other). Against a known path E(t) the game is a reachability question
in the plane: with S_0 = {P_0},

    S_{k+1} = (S_k grown by V_p tau) ∩ Admissible(E_{k+1}),

Admissible(E) being the points P with clearance >= r from the walls, L_min <= |P - E| <=
L_max and the segment P-E clear. When S_k empties no pursuer could have held past t_k.
Two grids bracket the truth (cells of side h, radius delta = h / sqrt(2)):

* **Optimistic** (an over-approximation): a cell is kept when some point of its disc could
  be admissible (range widened by delta, clearance and sight relaxed by delta: a cell is
  dropped for occlusion only when one wall edge crosses *every* segment from E to its
  disc) and reachable. Reachability is tracked by a lower bound ``ell`` on each centre's
  distance to S_k, ``ell_{k+1} = max(ell_k - V_p tau, dist(c, kept centres) - delta)``,
  so the snapping to cells does not accumulate from step to step (a plain cell set grown
  by V_p tau + 2 delta gains 2 delta a step). Admissibility is checked at the frames only
  (fewer constraints: still an over-approximation). When it empties at t_k, the evader
  path **certainly** breaks surveillance by t_k against every pursuer.
* **Pessimistic** (an under-approximation): exact pursuer positions on the cell centres
  (the start is one), each reached from a centre kept at the previous frame by a straight
  lattice move of length <= V_p tau (the certified player of the referee's bounds,
  :mod:`.lattice`), the whole move checked in continuous time under the env's semantics
  (both bodies linear over a step): clearance along it (both ends >= sqrt(r^2 + (V_p
  tau / 2)^2) from the walls: a wall point within r of the segment is within that of an
  end), range along it (both ends in [L_min + sigma, L_max], sigma covering the chord's
  dip below its ends' radius; the first move, from the exact start, by the closed form
  of :func:`.robust.sweep_range_ok`), and sight by the continuity fact of :mod:`.robust`:
  the move is cut into ``pieces`` pieces and on each no rod from the evader's piece to
  the pursuer's (a disc of radius V_p tau / (2 pieces)) may graze a convex vertex, the
  rod having been clear at the previous frame. Each piece's test depends on one lattice
  point (of spacing h / pieces), so it is computed once per point and the moves combine
  the tests by shifted array lookups. When the set is still non-empty at t_k, **some**
  pursuer held until t_k: :attr:`Hindsight.witness` is one, replayable in the env.

Between them the truth is unknown at that resolution. The pessimistic lattice loses speed
to its directions only (the hull of the lattice moves: 5 % at V_p tau = 5 h, 3 % at 10 h,
2 % at 15 h, 1 % at 30 h) and erodes the set by about V_p tau / (2 pieces) near the visibility
boundaries; ``moves`` and ``pieces`` trade these against time.

:func:`record_evader_path` plays a seeded episode against one or more pursuers, checks that
the evader's path is the same against each (open loop), and returns the longest; with
``extend_to`` it replays the evader alone past the break (checked identical on the frames
the episodes played).
"""

from __future__ import annotations

import math
import time
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy import ndimage

from envs import validation
from envs.errors import (
    InvalidConfigError,
    InvalidPlacementError,
    LongRunWarning,
    MemoryBudgetError,
)
from envs.geometry import kernel_for
from envs.geometry.segments import point_in_walls
from strategies.memory import byte_size
from strategies.memory import memory_budget as _memory_budget
from strategies.referee._budget import BASE_BYTES, _duration
from strategies.referee.lattice import segment_wall_distance
from strategies.referee.robust import convex_corners, sweep_hits_vertex, sweep_range_ok
from strategies.referee.spec import MARGIN_REL

__all__ = ["HINDSIGHT_VERDICTS", "EvaderPath", "Hindsight", "hindsight", "record_evader_path"]

HINDSIGHT_VERDICTS = ("evader", "pursuer", "unknown")

_BYTES_PER_CELL = (700.0, 24.0)
"""Peak memory per cell of the grid, ``a + b pieces^2`` bytes (the full-grid arrays and
distance transforms, and the pessimistic sight tests on the lattice of spacing h /
pieces), measured as peak resident memory above the interpreter's (``ru_maxrss``): an
evader standing nearly still in ``open_room`` (so the pessimistic set's crop is most of
the grid), 30 frames, cell 0.01 (254 k cells): 381, 454, 779, 2257 and 4173 bytes per
cell at pieces 1, 2, 4, 8 and 12; cell 0.005 (960 k cells): 1072 at pieces 4, 2255 at 8.
The formula gives 724, 796, 1084, 2236 and 4156: within 2 % from 4 pieces up, and over
(never under) at fewer."""

_BYTES_PER_INSTANT = 96.0
"""Peak memory per instant of the subdivided evader paths: two float64 coordinates (16
bytes) for the optimistic path kept while the pessimistic one is interpolated (four such
arrays at once, 64), and the per-step counts (8 each)."""


_SECONDS_PER_INSTANT = 1e-3
_SECONDS_PER_OPTIMISTIC_CELL = 2e-6
_SECONDS_PER_PESSIMISTIC_CELL = 0.6e-6
"""The time model of :func:`_estimate_seconds`: per instant of either grid (its fixed
work: the walls near the evader, the crops), per cell of the optimistic set and instant,
and per cell of the pessimistic set and step, times ``pieces^2`` on a map with convex
corners (its sight tests run on a lattice of spacing h / pieces; none without corners).
Measured on ``hindsight_maze``'s path (the maze, wall_hugging, 60 and 300 frames;
``/work/scratch/s12/helper-75/hs_time.py``): 0.5-1 ms an instant with sets of a few
cells; 1.1-1.7 us (up to 4 at a few hundred cells) per optimistic cell; 0.6 us per
pessimistic cell at 1 piece, 6.7-9.3 us at 4 (0.42-0.58 x 16), cells 0.01-0.3, moves
5-20. With the set sizes bounded as :func:`_estimate_seconds` does, the estimate was 1.6
to 3.3 times the time taken there (cells 0.16-0.01, pieces 1 and 4) and 2 to 5.5 times in
``open_room`` (a slow evader, 4 s, cells 0.05-0.02): an upper bound, give or take the
machine's load. On the orbit losses of the random maps (``unseen_worlds.py --hindsight``,
60 s paths) it was far higher: at cell 0.02, under a load of 5 on 2 cores, 15 times the
time on rand:polygons:3004 (the pessimistic set died at 14.6 s) and 8 times on
rand:star:3007 (it lasted the 60 s); at cell 0.04 14 times on both (dead at 13.7 and
13.8 s); 20-45 times on an idle machine (helper-75). Both sets are bounded by the same
admissible area, which they fill to a half or less (at 0.04 on rand:polygons:3004 the
estimate counts 24 M optimistic and 12.1 M pessimistic cell-instants, the run met 3.1 M and
0.66 M; ``/work/scratch/s13/helper-78/hs_est.py``). The pessimistic set's death, the
larger part, is what the run computes, so the message names the estimate an upper bound
and says which share ends early rather than tighten the model."""

LONG_SECONDS = 600.0
"""An estimate above this warns (:class:`~envs.errors.LongRunWarning`) before the grids
are built: ten minutes, so that with the estimate up to 5.5 times high (the time model
above) the run still takes about two minutes or more (``hindsight_maze``'s finest
default cell, 0.01, takes 22 s)."""

_BAR_SECONDS = 10.0
"""By default (``progress=None``) a bar is shown, on a terminal, beyond this estimate."""


@dataclass(frozen=True)
class EvaderPath:
    """An evader's path as the env played it: positions at t = k dt (linear in between).

    Attributes:
        positions: (n + 1, 2) evader centres, one per frame.
        dt: frame period (the env's step).
        pursuer_start: (2,) where the pursuer started in the recorded episode.
        lengths: frames of the path against each pursuer it was recorded against.
    """

    positions: np.ndarray
    dt: float
    pursuer_start: np.ndarray
    lengths: dict[str, int]

    @property
    def horizon(self) -> float:
        """Time covered by the path, (n) dt."""
        return (len(self.positions) - 1) * self.dt


@dataclass(frozen=True)
class Hindsight:
    """What the two grids say about one evader path and pursuer start.

    Attributes:
        verdict: ``"evader"`` (the optimistic set empties: no pursuer holds to the
            horizon), ``"pursuer"`` (the pessimistic set lasts: some pursuer holds to the
            horizon) or ``"unknown"``.
        optimistic_empty: the first time (a multiple of ``tau``) at which the optimistic
            set is empty (no pursuer holds past it), ``None`` if it lasts to the horizon.
        pessimistic_until: the last time (a multiple of ``pessimistic_tau``) at which the
            pessimistic set is non-empty (a pursuer holds at least until then); the
            horizon if it lasts.
        horizon: time covered by the evader's path.
        cell: cell side h.
        tau: the optimistic time step (the path's dt / substeps).
        pessimistic_tau: the pessimistic time step.
        optimistic_cells: cells in the optimistic set per step of ``tau`` (0 after empty).
        pessimistic_cells: centres in the pessimistic set per step of ``pessimistic_tau``.
        seconds: wall-clock time of the computation.
        witness: (m, 2) a pursuer path the pessimistic set contains, one position per
            step of ``pessimistic_tau`` up to ``pessimistic_until`` (straight moves of
            length <= V_p pessimistic_tau in between, from the pursuer's start).
        optimistic_sets: with ``keep_sets``, the optimistic set's cell centres ((n, 2))
            at each step of ``tau`` until it empties (for drawing and diagnosis).
        estimated_seconds: the time estimated before the grids were built (an upper
            bound, give or take the machine's load: :func:`_estimate_seconds`).
    """

    verdict: str
    optimistic_empty: float | None
    pessimistic_until: float
    horizon: float
    cell: float
    tau: float
    pessimistic_tau: float
    optimistic_cells: np.ndarray
    pessimistic_cells: np.ndarray
    seconds: float
    witness: np.ndarray
    optimistic_sets: list[np.ndarray] | None = None
    estimated_seconds: float = math.nan


def _param(config: Any, name: str) -> float:
    value = getattr(config, name, None)
    if value is None:
        raise InvalidConfigError(f"config.{name}: expected a positive number, got None")
    return validation.positive(f"config.{name}", value)


def _points(name: str, value: Any) -> np.ndarray:
    """``value`` as a float array, or InvalidConfigError naming it (not numpy's error)."""
    try:
        return np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InvalidConfigError(
            f"{name} = {value!r:.60}: expected numbers (x, y), got {type(value).__name__}"
        ) from None


def _estimate_seconds(
    world,
    path: np.ndarray,
    P0: np.ndarray,
    V: float,
    dt: float,
    substeps: int,
    pes_substeps: int,
    h: float,
    l_min: float,
    l_max: float,
    pieces: int,
) -> tuple[float, float]:
    """``(seconds, cells, pessimistic)``: the time both grids may take (the model of
    :data:`_SECONDS_PER_INSTANT` and the per-cell constants), the most cells either set
    may hold, and the pessimistic grid's share of the time, estimated before anything is
    allocated. Both sets are assumed to last the whole path: the pessimistic grid stops
    where its set empties, which on a lost path is often early (below).

    A set at time t holds at most the cells within ``V t + 2 h`` of the start (the
    pursuer's reach) that are admissible against the evader: their area is measured at
    up to 65 frames of the path on a lattice of spacing ``max(h, l_max / 16)`` (points in
    the range annulus widened by the lattice's disc, inside the walls, not robustly
    occluded: an over-approximation, as the optimistic set's own test; the clearance
    test would cost ten times as much and took little off), each instant
    taking the larger of its two nearest measured frames.
    """
    n = len(path) - 1
    hc = max(h, l_max / 16.0)
    dc = hc / math.sqrt(2.0)
    g = np.arange(-math.ceil((l_max + dc) / hc), math.ceil((l_max + dc) / hc) + 1) * hc
    off = np.stack(np.meshgrid(g, g, indexing="ij"), axis=-1).reshape(-1, 2)
    d = np.hypot(off[:, 0], off[:, 1])
    ring = off[(d >= l_min - dc) & (d <= l_max + dc)]
    a, b, nrm = world.edge_start, world.edge_end, world.edge_normal
    frames = np.unique(np.linspace(0, n, min(n + 1, 65)).round().astype(int))
    area = np.empty(len(frames))
    for i, k in enumerate(frames):
        C = path[k] + ring
        C = C[point_in_walls(C, a, b) & (np.hypot(*(C - P0).T) <= V * k * dt + 2 * h + dc)]
        area[i] = hc * hc * np.count_nonzero(~_robustly_blocked(path[k], C, dc, a, b, nrm))

    def cells(m: int) -> np.ndarray:  # the bound at each of n m instants after the start
        t = np.arange(1, n * m + 1) * (dt / m)
        j = np.searchsorted(frames, t / dt)  # frames[j - 1] < t / dt <= frames[j]
        last = len(frames) - 1
        adm = np.maximum(area[np.clip(j - 1, 0, last)], area[np.clip(j, 0, last)])
        return np.minimum(adm, math.pi * (V * t + 2.0 * h) ** 2) / (h * h)

    opt, pes = cells(substeps), cells(pes_substeps)
    sight = pieces * pieces if len(world.convex_vertices) else 1  # no corner, no sight test
    pessimistic = _SECONDS_PER_INSTANT * len(pes) + _SECONDS_PER_PESSIMISTIC_CELL * sight * float(
        pes.sum()
    )
    seconds = (
        _SECONDS_PER_INSTANT * len(opt) + _SECONDS_PER_OPTIMISTIC_CELL * float(opt.sum())
    ) + pessimistic
    return seconds, float(max(opt.max(initial=1.0), pes.max(initial=1.0))), pessimistic


def _check_memory(
    lo: np.ndarray, hi: np.ndarray, h: float, pieces: int, instants: int, budget: object
) -> None:
    """Refuse (MemoryBudgetError) a grid over [lo, hi] of cells h, and ``instants`` of the
    evader's subdivided paths, whose estimated peak memory (:data:`_BYTES_PER_CELL`, and
    :data:`_BYTES_PER_INSTANT`) exceeds the budget, naming the cell side that fits."""
    limit = _memory_budget(budget)
    cells = float(np.prod(np.floor((hi - lo) / h) + 3))  # _Grid's count, up to rounding
    per_cell = _BYTES_PER_CELL[0] + _BYTES_PER_CELL[1] * pieces * pieces
    path_bytes = _BYTES_PER_INSTANT * instants
    need = BASE_BYTES + cells * per_cell + path_bytes
    if need <= limit:
        return
    room = limit - BASE_BYTES - path_bytes
    K = MemoryBudgetError.KNOB
    if room > 0:  # the cells scale as 1 / h^2
        fit = h * math.sqrt(cells * per_cell / room)
        advice = f"use {K} >= {fit:.2g} or fewer pieces, or"
    elif path_bytes > cells * per_cell:  # substeps ~ V_p dt / h: a larger cell, fewer
        advice = f"use a larger {K} (fewer substeps) or a shorter path, or"
    else:
        advice = f"no {K} fits (the interpreter alone takes {byte_size(BASE_BYTES)}):"
    raise MemoryBudgetError(
        f"hindsight(cell = {h:g}, pieces = {pieces}): the grid of {cells:,.0f} cells and "
        f"the evader's path at {instants:,} instants would need about {byte_size(need)} at "
        f"its peak, more than the memory budget of {byte_size(limit)}; {advice} raise the "
        f"budget with {MemoryBudgetError.BUDGET}",
        "cell",
        size=f"{math.ceil(1.2 * need / 1e9)}GB",
    )


def _point_wall_distance(X: np.ndarray, world) -> np.ndarray:
    """Distance from each point of X (k, 2) to the nearest wall edge."""
    return segment_wall_distance(X, X, world)


def _robustly_blocked(E: np.ndarray, C: np.ndarray, delta: float, a, b, n) -> np.ndarray:
    """Whether one wall edge crosses *every* segment from E to a point of D(c, delta).

    Segment E-p properly crosses edge a-b when E and p lie strictly on opposite sides of
    the edge's line and a, b strictly on opposite sides of the line E-p. Both hold for
    every p in the disc when c is more than delta beyond the edge's line, E strictly on
    the other side, and ``|cross(c - E, a - E)| > delta |a - E|`` (the same for b) with
    opposite signs (cross(p - E, a - E) moves by at most delta |a - E| as p leaves c).

    Args:
        E: (2,) the evader.
        C: (k, 2) cell centres.
        delta: the discs' radius.
        a, b, n: (m, 2) wall edges and their unit normals into free space.

    Returns:
        (k,) bool.
    """
    out = np.zeros(len(C), dtype=bool)
    if len(a) == 0:
        return out
    sE = (E[0] - a[:, 0]) * n[:, 0] + (E[1] - a[:, 1]) * n[:, 1]  # (m,)
    ax, ay = a[:, 0] - E[0], a[:, 1] - E[1]
    bx, by = b[:, 0] - E[0], b[:, 1] - E[1]
    la, lb = np.hypot(ax, ay), np.hypot(bx, by)
    chunk = max(1, 2_000_000 // len(a))
    for s in range(0, len(C), chunk):
        cx = C[s : s + chunk, 0:1] - E[0]
        cy = C[s : s + chunk, 1:2] - E[1]
        sc = (cx + E[0] - a[:, 0]) * n[:, 0] + (cy + E[1] - a[:, 1]) * n[:, 1]
        sides = ((sE > 0) & (sc < -delta)) | ((sE < 0) & (sc > delta))
        ca = cx * ay - cy * ax
        cb = cx * by - cy * bx
        apart = ((ca > delta * la) & (cb < -delta * lb)) | ((ca < -delta * la) & (cb > delta * lb))
        out[s : s + chunk] = (sides & apart).any(axis=1)
    return out


class _Grid:
    """Cells of side h whose centres include ``anchor``, covering the box [lo, hi], with
    lazily computed signed wall clearance of the centres."""

    def __init__(self, world, anchor: np.ndarray, lo: np.ndarray, hi: np.ndarray, h: float):
        self.world = world
        self.h = h
        i0 = np.floor((lo - anchor) / h).astype(int)
        i1 = np.ceil((hi - anchor) / h).astype(int)
        self.xs = anchor[0] + h * np.arange(i0[0], i1[0] + 1)
        self.ys = anchor[1] + h * np.arange(i0[1], i1[1] + 1)
        self.shape = (len(self.xs), len(self.ys))
        self.anchor_index = (int(-i0[0]), int(-i0[1]))
        self._clear = np.full(self.shape, np.nan, dtype=np.float32)

    def centres(self, idx: tuple[np.ndarray, np.ndarray]) -> np.ndarray:
        return np.stack([self.xs[idx[0]], self.ys[idx[1]]], axis=1)

    def clearance(self, idx: tuple[np.ndarray, np.ndarray]) -> np.ndarray:
        """Signed distance of the centres to the walls (negative outside free space;
        float32, so about 1e-6 relative: far below the margins it is compared with)."""
        have = self._clear[idx]
        todo = np.isnan(have)
        if todo.any():
            sub = (idx[0][todo], idx[1][todo])
            X = self.centres(sub)
            d = _point_wall_distance(X, self.world)
            free = point_in_walls(X, self.world.edge_start, self.world.edge_end)
            self._clear[sub] = np.where(free, d, -d)
            have = self._clear[idx]
        return have.astype(float)


def _subdivide(path: np.ndarray, n: int) -> np.ndarray:
    """The path at n instants per frame, linear in between (the env's semantics)."""
    s = np.arange(n) / n
    inner = path[:-1, None, :] * (1 - s)[None, :, None] + path[1:, None, :] * s[None, :, None]
    return np.concatenate([inner.reshape(-1, 2), path[-1:]])


def _crop(mask: np.ndarray, pad: int) -> tuple[slice, slice] | None:
    """The bounding box of ``mask``'s True cells grown by ``pad`` cells (clipped)."""
    rows = np.flatnonzero(mask.any(axis=1))
    if len(rows) == 0:
        return None
    cols = np.flatnonzero(mask.any(axis=0))
    return (
        slice(max(0, rows[0] - pad), min(mask.shape[0], rows[-1] + pad + 1)),
        slice(max(0, cols[0] - pad), min(mask.shape[1], cols[-1] + pad + 1)),
    )


def _distance_to(mask: np.ndarray, box: tuple[slice, slice], h: float) -> np.ndarray:
    """Euclidean distance from each centre in ``box`` to the nearest True centre of mask
    (all of which lie in ``box``)."""
    return ndimage.distance_transform_edt(~mask[box], sampling=h)


def hindsight(
    config: Any,
    evader_path: Any,
    pursuer_start: Any,
    cell: float,
    *,
    substeps: int | None = None,
    moves: float = 10.0,
    pieces: int = 4,
    clearance: float | None = None,
    dt: float | None = None,
    keep_sets: bool = False,
    memory_budget: object = None,
    progress: bool | None = None,
) -> Hindsight:
    """Bracket, on two grids, whether any pursuer could hold against an evader path.

    Args:
        config: the game: anything with ``map, l_min, l_max, v_pursuer, body_radius``
            (and ``dt`` unless given), e.g. an ``EnvConfig`` or a :class:`GameSpec`.
        evader_path: (n + 1, 2) evader positions at t = k dt, or an :class:`EvaderPath`.
        pursuer_start: (2,) the pursuer at t = 0 (must be admissible against the path's
            first point).
        cell: cell side h (> 0).
        substeps: optimistic steps per frame (E interpolated linearly, as the env moves
            it: more instants checked, a tighter set); ``None`` picks the smallest number
            with V_p tau <= 2 h.
        moves: the pessimistic step is the largest dt / n (n >= 1 an integer) with
            V_p tau_p <= ``moves`` h: its lattice moves reach ``moves`` cells (see the
            module docstring for the speed this costs).
        pieces: the pessimistic sight test cuts each move into this many pieces (>= 1;
            the pursuer's uncertainty in the test is V_p tau / (2 pieces)).
        clearance: the wall clearance the *optimistic* set assumes of the pursuer
            (default ``body_radius``; the env's physics can press a disc to
            ``body_radius / 2`` from a wall, so pass that for a certificate that covers
            it; no more than ``body_radius``). The pessimistic pursuer always keeps
            ``body_radius``.
        dt: frame period (default ``config.dt``; the path's own for an
            :class:`EvaderPath`).
        keep_sets: keep the optimistic set of every frame in the result.
        memory_budget: bytes (or ``"2GB"``) the computation may take; default
            ``$SURVEIL_MEMORY_BUDGET``, else half the physical memory (as the referee's
            solves). The grid's size is known before anything is allocated.
        progress: a bar per grid on standard error (``True``), none (``False``), or
            (``None``) one on a terminal when the time estimated up front exceeds
            :data:`_BAR_SECONDS`; the bars' titles give the estimate.

    Returns:
        The :class:`Hindsight`.

    Raises:
        InvalidConfigError: a bad parameter or path (named), or a bad budget.
        InvalidPlacementError: the pursuer start is not admissible at t = 0.
        MemoryBudgetError: the grid would need more memory than the budget (the message
            names the estimate and the cell that fits).

    Warns:
        LongRunWarning: the time estimated before the grids are built exceeds
            :data:`LONG_SECONDS` (the message names it and the knobs that shorten it).
    """
    t_start = time.perf_counter()
    world = getattr(config, "map", None)
    if world is None:
        raise InvalidConfigError(
            f"config = {config!r:.60}: expected the game (an EnvConfig or a GameSpec: "
            "map, l_min, l_max, v_pursuer, body_radius)"
        )
    l_min, l_max = _param(config, "l_min"), _param(config, "l_max")
    V = _param(config, "v_pursuer")
    r = _param(config, "body_radius")
    if isinstance(evader_path, EvaderPath):
        dt = evader_path.dt if dt is None else dt
        evader_path = evader_path.positions
    if dt is None:
        dt = _param(config, "dt")
    dt = validation.positive("dt", dt)
    h = validation.positive("cell", cell)
    path = _points("evader_path", evader_path)
    if path.ndim != 2 or path.shape[1] != 2 or len(path) < 2 or not np.isfinite(path).all():
        raise InvalidConfigError(
            f"evader_path of shape {path.shape}: expected finite (n + 1, 2) positions, n >= 1"
        )
    out = np.flatnonzero(~point_in_walls(path, world.edge_start, world.edge_end))
    if len(out):  # a path the env cannot play: a verdict on it would certify nothing
        k = int(out[0])
        raise InvalidConfigError(
            f"evader_path: position {k} {tuple(map(float, path[k]))} (and {len(out) - 1} "
            f"more) lies outside map {world.name!r}'s free space: expected a path the evader "
            "can play"
        )
    P0 = _points("pursuer_start", pursuer_start)
    if P0.shape != (2,) or not np.isfinite(P0).all():
        raise InvalidConfigError(f"pursuer_start = {pursuer_start!r}: expected a finite (x, y)")
    if substeps is None:  # V_p tau about 2 h: the optimistic set is checked every 2 cells
        substeps = max(1, math.ceil(V * dt / (2.0 * h) - 1e-9))
    substeps = validation.integer("substeps", substeps, minimum=1)
    moves = validation.real("moves", moves, minimum=1.0)
    pes_substeps = max(1, math.ceil(V * dt / (moves * h) - 1e-9))
    pieces = validation.integer("pieces", pieces, minimum=1)
    r_opt = r if clearance is None else validation.real("clearance", clearance, minimum=0.0)
    if r_opt > r:  # a larger one shrinks the set below the truth: no certificate
        raise InvalidConfigError(
            f"clearance = {clearance!r}: expected a value in [0, body_radius = {r:g}] (the "
            "optimistic set must contain every pursuer the env lets play)"
        )

    tau, tau_p = dt / substeps, dt / pes_substeps
    step, step_p = V * tau, V * tau_p
    horizon = dt * (len(path) - 1)
    delta = h / math.sqrt(2.0)
    margin = MARGIN_REL * world.scale

    kernel = kernel_for(world)
    E0 = path[0]
    d0 = float(np.hypot(*(P0 - E0)))
    cl0 = float(_point_wall_distance(P0[None], world)[0])
    if (
        not kernel.contains_point(*P0)
        or cl0 < r - margin
        or not (l_min <= d0 <= l_max)
        or not kernel.line_of_sight(P0, E0)
    ):
        raise InvalidPlacementError(
            f"pursuer_start = {tuple(map(float, P0))}: not a surveillance start against the "
            f"evader at {tuple(map(float, E0))} (distance {d0:.4g}, L in [{l_min}, {l_max}], "
            f"clearance {cl0:.4g} >= {r} and a clear rod expected)"
        )

    # the pursuer stays within V_p t of its start and L_max of the evader
    pad = 3 * h + max(step, step_p)
    lo = np.maximum(path.min(axis=0) - l_max, P0 - V * horizon) - pad
    hi = np.minimum(path.max(axis=0) + l_max, P0 + V * horizon) + pad
    instants = (len(path) - 1) * (substeps + pes_substeps)
    _check_memory(lo, hi, h, pieces, instants, memory_budget)
    estimated, most, pessimistic = _estimate_seconds(
        world, path, P0, V, dt, substeps, pes_substeps, h, l_min, l_max, pieces
    )
    about = f"up to about {_duration(estimated)}"
    if estimated > LONG_SECONDS:
        # an upper bound: said so, with the share that ends early on a lost path (the
        # orbit losses took 1/8 to 1/45 of it; see _SECONDS_PER_INSTANT)
        warnings.warn(
            f"hindsight(cell = {h:g}, pieces = {pieces}): estimated {about} if both sets "
            f"last the whole {horizon:g} s path ({instants:,} instants of sets of up to "
            f"{most:,.0f} cells), an upper bound: {_duration(pessimistic)} of it is the "
            "pessimistic grid's, which stops where its set empties (early when the pursuer "
            "cannot hold), and measured runs took 1/2 to 1/45 of the estimate; the time "
            "grows as 1 / cell^2, pieces^2 (pessimistic) and the path's length",
            LongRunWarning,
            stacklevel=2,
        )
    show = progress if progress is not None else (None if estimated > _BAR_SECONDS else False)
    E_o = _subdivide(path, substeps)
    E_p = _subdivide(path, pes_substeps)
    grid = _Grid(world, P0, lo, hi, h)  # P0 is a centre: the pessimistic pursuer may wait

    # ---- optimistic: lower bound ell on each centre's distance to S_k, stored shifted:
    # ell_k = shifted - k V tau (so ell_k - V tau costs nothing off the crop, where the
    # stale value stays a valid, weaker, bound)
    a, b, nrm = world.edge_start, world.edge_end, world.edge_normal
    mid = 0.5 * (a + b)
    half = 0.5 * world.edge_length
    shifted = np.hypot(grid.xs[:, None] - P0[0], grid.ys[None, :] - P0[1])
    opt = shifted <= delta
    opt_cells = np.zeros(len(E_o), dtype=int)
    opt_cells[0] = int(opt.sum())
    opt_empty: float | None = None
    opt_sets: list[np.ndarray] = [P0[None, :].copy()]
    # every centre within V tau + 2 delta of a kept centre lies in the kept set's bounding
    # box grown by opt_pad cells: the next candidates
    opt_pad = math.ceil((step + 2 * delta) / h) + 1
    box = _crop(opt, opt_pad)
    bar = _bar(show, len(E_o) - 1, f"hindsight cell {h:g} ({about}): optimistic")
    for k in range(len(E_o) - 1):
        bar.update(1)
        E1 = E_o[k + 1]
        near = np.hypot(mid[:, 0] - E1[0], mid[:, 1] - E1[1]) <= l_max + delta + half + margin
        # candidates: every centre within V tau + delta of S_k (ell is a lower bound),
        # all inside the crop of the last kept set
        sub = shifted[box] - k * step <= step + delta
        ii, jj = np.nonzero(sub)
        idx = (ii + box[0].start, jj + box[1].start)
        C = grid.centres(idx)
        dist = np.hypot(C[:, 0] - E1[0], C[:, 1] - E1[1])
        ok = (dist >= l_min - delta) & (dist <= l_max + delta)
        ok[ok] = grid.clearance((idx[0][ok], idx[1][ok])) >= r_opt - delta
        ok[ok] = ~_robustly_blocked(E1, C[ok], delta, a[near], b[near], nrm[near])
        opt_cells[k + 1] = int(ok.sum())
        if keep_sets:
            opt_sets.append(C[ok])
        if not ok.any():
            opt_empty = float(tau * (k + 1))
            break
        opt = np.zeros(grid.shape, dtype=bool)
        opt[idx[0][ok], idx[1][ok]] = True
        # ell_{k+1} = max(ell_k - V tau, dist(c, kept centres) - delta) on the crop that
        # holds the next candidates
        box = _crop(opt, opt_pad)
        bound = _distance_to(opt, box, h) - delta + (k + 1) * step
        np.maximum(shifted[box], bound, out=shifted[box])
    bar.close()

    # ---- pessimistic: exact centres, continuous-time moves
    ell_max = step_p + float(np.max(np.hypot(*np.diff(E_p, axis=0).T), initial=0.0))
    sigma = math.sqrt(l_min * l_min + 0.25 * ell_max * ell_max) - l_min
    rho_req = math.sqrt(r * r + 0.25 * step_p * step_p)
    first_clear = rho_req if cl0 >= rho_req else r + step_p  # see the module docstring
    e_seg_clear = segment_wall_distance(E_p[:-1], E_p[1:], world)
    corners = convex_corners(world)
    pes = np.zeros(grid.shape, dtype=bool)
    pes[grid.anchor_index] = True  # the start, exactly
    pes_cells = np.zeros(len(E_p), dtype=int)
    pes_cells[0] = 1
    pes_kept: list = []  # per frame after the first: kept indices, their predecessors
    pes_until = 0.0
    bar = _bar(show, len(E_p) - 1, f"hindsight cell {h:g}: pessimistic")
    for k in range(len(E_p) - 1):
        bar.update(1)
        if e_seg_clear[k] <= margin:  # the evader's own step touches a wall
            break
        kept = _pessimistic_step(
            grid, pes, k, P0, E_p[k], E_p[k + 1], step_p, margin, l_min, l_max, sigma,
            first_clear if k == 0 else rho_req, corners, pieces,
        )  # fmt: skip
        if kept is None:
            break
        pes, idx, pred = kept
        pes_cells[k + 1] = len(idx[0])
        pes_kept.append((idx, pred))
        pes_until = float(tau_p * (k + 1))
    bar.close()

    if opt_empty is not None:
        verdict = "evader"
    elif pes_until >= horizon - 1e-9 * dt:
        verdict = "pursuer"
    else:
        verdict = "unknown"
    return Hindsight(
        verdict=verdict,
        optimistic_empty=opt_empty,
        pessimistic_until=pes_until,
        horizon=float(horizon),
        cell=h,
        tau=tau,
        pessimistic_tau=tau_p,
        optimistic_cells=opt_cells,
        pessimistic_cells=pes_cells,
        seconds=time.perf_counter() - t_start,
        witness=_backtrack(grid, pes_kept, P0),
        optimistic_sets=opt_sets if keep_sets else None,
        estimated_seconds=estimated,
    )


def _bar(show: bool | None, total: int, desc: str):
    """A tqdm bar over ``total`` steps: shown (True), hidden (False) or on a terminal."""
    from tqdm import tqdm

    return tqdm(
        total=total, desc=desc, unit="step", disable=None if show is None else not show,
        leave=False,
    )  # fmt: skip


def _grazes(A, B, C: np.ndarray, R: float, verts, eta: float) -> np.ndarray:
    """Whether some rod from a point of the segment A-B to a point of the disc D(C[i], R)
    can graze a convex vertex (:func:`.robust.sweep_hits_vertex`).

    Only the vertices near the rod matter: a rod e-p (e on A-B, p in the disc) lies within
    ``max(|B - A| / 2, R)`` of the segment from A-B's middle to C[i] (compare
    ``e + t (p - e)`` with ``m + t (c - m)``), so the exact test runs on those pairs only.
    """
    v, din, dout = verts
    hit = np.zeros(len(C), dtype=bool)
    if len(v) == 0 or len(C) == 0:
        return hit
    A = np.asarray(A, dtype=float)
    B = np.asarray(B, dtype=float)
    m = 0.5 * (A + B)
    rho = max(0.5 * float(np.hypot(*(B - A))), R) + eta
    dx, dy = C[:, 0] - m[0], C[:, 1] - m[1]
    L2 = np.maximum(dx * dx + dy * dy, 1e-300)
    for n in range(len(v)):
        wx, wy = v[n, 0] - m[0], v[n, 1] - m[1]
        t = np.clip((wx * dx + wy * dy) / L2, 0.0, 1.0)
        near = np.flatnonzero(np.hypot(wx - t * dx, wy - t * dy) <= rho)
        near = near[~hit[near]]
        if len(near) == 0:
            continue
        c = C[near]
        hit[near] = sweep_hits_vertex(
            A[0], A[1], B[0], B[1], v[n, 0], v[n, 1], c[:, 0], c[:, 1], R, din[n], dout[n], eta
        )
    return hit


def _pessimistic_step(
    grid, pes, k, P0, Ek, E1, step, margin, l_min, l_max, sigma, need_clear, corners, pieces
):
    """The centres certified at frame k + 1 (see the module docstring), with the
    predecessor of each (a centre certified at frame k), or None.

    A move from c_i to c_j = c_i + o (a lattice vector, |o| <= V_p tau) is split at the
    times s = q / N (N = ``pieces``): around each, for |s - q / N| <= 1 / (2 N), the
    pursuer lies within V_p tau / (2 N) of P(q / N) = c_i + (q / N) o, a point of the
    lattice of spacing h / N, and the evader on its segment's piece. So the sight test of
    a move is the AND of N + 1 tests that each depend on one point only: c_i (q = 0),
    the points between (q = 1 .. N - 1) and c_j (q = N); each is computed once per
    point, and the moves combine them by shifted array lookups.
    """
    h = grid.h
    N = pieces
    tol = step * (1.0 + 1e-9)
    w = math.ceil(step / h) + 1
    box = _crop(pes, w)
    bx, by = box[0].stop - box[0].start, box[1].stop - box[1].start
    x0g, y0g = box[0].start, box[1].start
    src = pes[box]
    # candidates: centres within V tau of a certified one
    cand = ndimage.distance_transform_edt(~src, sampling=h) <= tol
    ii, jj = np.nonzero(cand)
    idx = (ii + x0g, jj + y0g)
    C = grid.centres(idx)
    d1 = np.hypot(C[:, 0] - E1[0], C[:, 1] - E1[1])
    ok = (d1 >= l_min + sigma + margin) & (d1 <= l_max - margin)
    ok[ok] = grid.clearance((idx[0][ok], idx[1][ok])) >= need_clear + margin
    if k == 0 and ok.any():  # range along the move from the exact start, exactly
        d = (C[ok] - P0) - (E1 - Ek)
        o = P0 - Ek
        ok[ok] = sweep_range_ok(
            o[0], o[1], -d[:, 0], -d[:, 1], 0.0, 0.0, l_min + margin, l_max - margin
        )
    v, din, dout = corners
    # a vertex on a rod lies within L_max of E(s), so within L_max + |E1 - Ek| of E1
    nv = np.hypot(v[:, 0] - E1[0], v[:, 1] - E1[1]) <= l_max + np.hypot(*(E1 - Ek)) + 2 * margin
    verts = (v[nv], din[nv], dout[nv])
    R = step / (2 * N) + 2 * margin
    E_at = lambda t: Ek + t * (E1 - Ek)
    if ok.any():  # the last piece, about c_j
        rows = np.flatnonzero(ok)
        ok[rows] = ~_grazes(E_at(1 - 0.5 / N), E1, C[rows], R, verts, margin)
    if not ok.any():
        return None
    target = np.zeros((bx, by), dtype=bool)
    target[ii[ok], jj[ok]] = True
    # the first piece, about c_i
    si, sj = np.nonzero(src)
    good = ~_grazes(Ek, E_at(0.5 / N), grid.centres((si + x0g, sj + y0g)), R, verts, margin)
    src = np.zeros((bx, by), dtype=bool)
    src[si[good], sj[good]] = True
    if not src.any():
        return None
    # the pieces between, about the points of the lattice of spacing h / N
    mids = []
    if N > 1:
        fx = grid.xs[x0g] + (h / N) * np.arange(N * (bx - 1) + 1)
        fy = grid.ys[y0g] + (h / N) * np.arange(N * (by - 1) + 1)
        # only the points a move can pass: within V tau of both ends, so their nearest
        # centre is within V tau + h of a certified and of a target centre
        zone = (ndimage.distance_transform_edt(~src, sampling=h) <= tol + h) & (
            ndimage.distance_transform_edt(~target, sampling=h) <= tol + h
        )
        near_cell = (
            np.rint(np.arange(len(fx)) / N).astype(int),
            np.rint(np.arange(len(fy)) / N).astype(int),
        )
        fz = np.nonzero(zone[near_cell[0][:, None], near_cell[1][None, :]])
        pts = np.stack([fx[fz[0]], fy[fz[1]]], axis=1)
        for q in range(1, N):
            g = np.zeros((len(fx), len(fy)), dtype=bool)
            g[fz] = ~_grazes(E_at((q - 0.5) / N), E_at((q + 0.5) / N), pts, R, verts, margin)
            mids.append(g)
    r = math.floor(step / h)
    a_, b_ = np.meshgrid(np.arange(-r, r + 1), np.arange(-r, r + 1), indexing="ij")
    keep = np.hypot(a_, b_) * h <= tol
    moves = sorted(
        zip(a_[keep].tolist(), b_[keep].tolist(), strict=True),
        key=lambda m: -(m[0] ** 2 + m[1] ** 2),
    )
    valid = np.zeros((bx, by), dtype=bool)
    pred_a = np.zeros((bx, by), dtype=int)
    pred_b = np.zeros((bx, by), dtype=int)
    for a, b in moves:
        x0, x1 = max(0, a), min(bx, bx + a)
        y0, y1 = max(0, b), min(by, by + b)
        if x0 >= x1 or y0 >= y1:
            continue
        m = src[x0 - a : x1 - a, y0 - b : y1 - b] & target[x0:x1, y0:y1] & ~valid[x0:x1, y0:y1]
        if not m.any():
            continue
        for q in range(1, N):
            f0x = N * x0 - (N - q) * a
            f0y = N * y0 - (N - q) * b
            m &= mids[q - 1][
                f0x : f0x + N * (x1 - x0 - 1) + 1 : N, f0y : f0y + N * (y1 - y0 - 1) + 1 : N
            ]
        valid[x0:x1, y0:y1] |= m
        pred_a[x0:x1, y0:y1][m] = a
        pred_b[x0:x1, y0:y1][m] = b
    vi, vj = np.nonzero(valid)
    if len(vi) == 0:
        return None
    new = np.zeros(grid.shape, dtype=bool)
    new[vi + x0g, vj + y0g] = True
    kept = (vi + x0g, vj + y0g)
    pred = (kept[0] - pred_a[vi, vj], kept[1] - pred_b[vi, vj])
    return new, kept, pred


def _backtrack(grid, kept: list, P0: np.ndarray) -> np.ndarray:
    """The witness path: from a centre kept at the last frame back through the recorded
    predecessors to the start."""
    if not kept:
        return P0[None, :].copy()
    ny = grid.shape[1]
    last = kept[-1][0]
    cur = (int(last[0][0]), int(last[1][0]))
    path = [grid.centres((np.array([cur[0]]), np.array([cur[1]])))[0]]
    for idx, pred in reversed(kept):
        key = idx[0].astype(np.int64) * ny + idx[1]
        row = int(np.flatnonzero(key == cur[0] * ny + cur[1])[0])
        cur = (int(pred[0][row]), int(pred[1][row]))
        path.append(grid.centres((np.array([cur[0]]), np.array([cur[1]])))[0])
    path[-1] = P0.copy()  # the start (a centre of the grid, by construction)
    return np.asarray(path[::-1])


def _evader_alone(
    map: Any, evader: Any, seed: int, overrides: Mapping[str, Any], placement, n_steps: int
) -> np.ndarray:
    """The evader's positions over ``n_steps`` env steps of episode ``seed`` with the
    pursuer standing still at its start, played on past any surveillance break (the
    env's agents are restored after it ends: the path is the evader's, not a game)."""
    from envs.surveillance.env import EVADER, PURSUER
    from strategies.policies import make_policy
    from strategies.runner import build_env, episode_seeds, observation_options

    s_env, _, _, s_e = episode_seeds(seed)
    pol = make_policy(evader) if isinstance(evader, str) else evader
    opts = observation_options(pol)
    if opts is not None and opts.get("observation", "state") != "state":
        raise InvalidConfigError(
            f"evader = {evader!r}: observes {opts!r}; expected a policy that reads the "
            "'state' observation"
        )
    env = build_env(map, {**overrides, "max_cycles": n_steps + 1})
    try:
        pol.reset(role="evader", map=env.config.map, config=env.config, seed=s_e)
        env.reset(seed=s_env, options=placement)
        out = [env.world.positions()[1]]
        still = np.zeros(2)
        for _ in range(n_steps):
            action = pol.act(env.state())
            env.step({PURSUER: still, EVADER: action})
            if not env.agents:  # surveillance broke: the evader's path goes on
                env.agents = list(env.possible_agents)
            out.append(env.world.positions()[1])
    finally:
        env.close()
    return np.asarray(out, dtype=float)


def record_evader_path(
    map: Any,
    evader: Any,
    seed: int,
    *,
    pursuers: Sequence[Any] = ("pursuer/decomposition", "pursuer/greedy"),
    overrides: Mapping[str, Any] | None = None,
    start: Any = "safe",
    max_cycles: int | None = None,
    extend_to: int | None = None,
) -> EvaderPath:
    """The path of an open-loop evader in a seeded episode (:func:`run_episode`).

    The episode is played against each pursuer of ``pursuers`` (same seed, so the same
    start and the same evader seed); the evader's positions must agree on their common
    frames (an open-loop evader's path does not depend on the pursuer). An episode ends
    when surveillance breaks, so the longest of these paths is what the episodes show.

    With ``extend_to`` (a number of steps), the evader is replayed alone from the same
    start and seeds, the pursuer standing still, on past the break, for that many steps;
    the replay must reproduce the episodes' paths exactly on their frames.

    Raises:
        InvalidConfigError: the paths differ (the evader is not open-loop, or the replay
            is not the episode), no pursuer given, or ``extend_to`` < 1.
    """
    from strategies.runner import run_episode

    if isinstance(pursuers, str):  # not its characters
        raise InvalidConfigError(
            f"pursuers = {pursuers!r}: expected a sequence of pursuers, e.g. ({pursuers!r},)"
        )
    if len(pursuers) < 1:
        raise InvalidConfigError("pursuers: expected at least one pursuer, got none")
    if extend_to is not None and not (
        validation.is_real(extend_to) and float(extend_to).is_integer() and extend_to >= 1
    ):
        raise InvalidConfigError(f"extend_to = {extend_to!r}: expected an integer >= 1")
    paths: dict[str, np.ndarray] = {}
    res = None
    for pursuer in pursuers:
        res = run_episode(
            map, pursuer, evader, seed, max_cycles=max_cycles, overrides=overrides, start=start
        )
        paths[res.pursuer] = res.trajectory[:, 1, :]
    assert res is not None
    p_start = np.asarray(res.start["pursuer"], dtype=float)
    if extend_to is not None:
        placement = {k: tuple(res.start[k]) for k in ("pursuer", "evader")}
        paths["(evader alone)"] = _evader_alone(
            map, evader, seed, dict(overrides or {}), placement, int(extend_to)
        )
    names = list(paths)
    ref = max(paths.values(), key=len)
    for name in names:
        other = paths[name]
        n = len(other)
        if not np.array_equal(ref[:n], other):
            gap = float(np.max(np.hypot(*(ref[:n] - other).T)))
            raise InvalidConfigError(
                f"evader = {evader!r}: its path against {name} differs from the longest "
                f"recorded by up to {gap:.3g}: expected an open-loop evader"
            )
    return EvaderPath(
        positions=ref.copy(),
        dt=float(res.dt),
        pursuer_start=p_start,
        lengths={k: len(p) for k, p in paths.items()},
    )
