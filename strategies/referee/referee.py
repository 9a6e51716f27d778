"""The referee: both bounds of one game, and what they are for.

* :func:`solve` (and :func:`referee_for` from an env config) computes, or loads from the
  on-disk cache, the pursuer bound and the evader bound at one resolution.
* :meth:`Referee.classify` labels a start ``"pursuer"`` (the pursuer provably holds),
  ``"evader"`` (the evader provably breaks surveillance, within a certified time) or
  ``"unknown"`` (between the bounds: the resolution error).
* :meth:`Referee.lattice_starts` and :meth:`Referee.sample_starts` enumerate and draw
  certified starts for test oracles and training curricula; :func:`label_starts` labels
  env starts given as ``{"pursuer": (x, y), "evader": (x, y)}``.
* :meth:`Referee.summary` reports the fractions of each label over all lattice starts and
  the gap between the bounds.
"""

from __future__ import annotations

import math
import os
import warnings
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from envs import validation as V
from envs.errors import (
    InvalidConfigError,
    InvalidPlacementError,
    LongRunWarning,
    MemoryBudgetError,
    NoStartError,
    VacuousBoundWarning,
)
from envs.geometry import kernel_for
from strategies.memory import byte_size, physical_memory
from strategies.memory import memory_budget as _memory_budget
from strategies.referee._budget import SolveSize, bound_size, check_budget, duration
from strategies.referee.cache import cache_path, load_arrays, save_arrays
from strategies.referee.evader_bound import EvaderBound, solve_evader_bound
from strategies.referee.pursuer_bound import VACUOUS_RHO, PursuerBound, solve_pursuer_bound
from strategies.referee.spec import GameSpec, Resolution, check_cells_per_lmin

__all__ = [
    "EVADER_FALLBACK_SHARE",
    "LABELS",
    "Referee",
    "StartSet",
    "cached_evader_bound",
    "cached_pursuer_bound",
    "check_solve_budget",
    "check_start",
    "coarsest_with_starts",
    "evader_fallback_resolution",
    "evader_fallback_size",
    "fallback_size",
    "finer_with_starts",
    "has_lattice_start",
    "label_starts",
    "pursuer_fallback_resolution",
    "referee_for",
    "sample_starts",
    "solve",
    "solve_role",
    "unsolved_sizes",
]

LABELS = ("pursuer", "evader", "unknown")
"""What a start can be labelled: who provably wins it, or unknown."""

SAMPLE_BYTES = 512
"""Memory a start drawn by :meth:`Referee.sample_starts` takes, in bytes, rounded up: its
dict of two coordinate pairs measured 400 (tracemalloc, 100,000 starts), plus the index
drawn for it."""


def check_sample_size(n: int, memory_budget: object = None) -> int:
    """``n``, after checking that ``n`` starts fit in the memory budget: the check
    :meth:`Referee.sample_starts` makes before drawing, for a caller that must refuse
    before a solve (``surveil referee --sample 1000000000`` solved, then died in numpy's
    ``MemoryError`` traceback).

    Raises:
        InvalidConfigError: ``n`` is not an integer >= 0, or the budget is no size.
        MemoryBudgetError: ``n`` starts need more than the budget (``$SURVEIL_MEMORY_BUDGET``
            or half the RAM); the message names the most that fit.
    """
    n = V.integer("n", n, minimum=0)
    limit = _memory_budget(memory_budget)
    need = n * SAMPLE_BYTES
    if need <= limit:
        return n
    more = (
        f", or raise the budget ({MemoryBudgetError.BUDGET})"
        if need <= physical_memory()
        else f" (this machine has {byte_size(physical_memory())} of memory)"
    )
    raise MemoryBudgetError(
        f"sample_starts: {MemoryBudgetError.KNOB} = {n} starts would take about "
        f"{byte_size(need)} ({SAMPLE_BYTES} bytes each), more than the memory budget of "
        f"{byte_size(limit)}; draw at most {int(limit // SAMPLE_BYTES)} at a time{more}",
        "n",
        MemoryBudgetError.ENV_BUDGET if memory_budget is None else MemoryBudgetError.PYTHON_BUDGET,
        f"{math.ceil(1.2 * need / 1e9)}GB",  # as check_budget advises
    )


EVADER_FALLBACK_SHARE = 0.1
""":func:`solve` retries the evader bound at a finer lattice when its default lattice
certifies less than this fraction of its live states (:meth:`EvaderBound.live_fraction`,
the states where surveillance still holds). At 16 cells per L_min (L in [2, 4], dt = 0.1)
the default certified 0.2 - 2.6 % of them where the finer lattice certifies 100 %
(two_rooms at rho = 0.5, 0.7, 0.9, the corridor at 0.9, the corner world at 0.7), 0.2 %
on the corner world at 0.5 (16 % finer), 0.07 - 0.9 % elsewhere at rho = 0.5 - 0.7 and
4 - 12 % on the maze.
"""


LONG_SOLVE_SECONDS = 120.0
"""A bound estimated (:func:`~strategies.referee._budget.bound_size`) to take longer than
this to solve warns (:class:`~envs.errors.LongRunWarning`) before it starts, when it is not
in the cache: a referee policy solves at its first reset, and at L_min = 0.5 the pursuer
bounds of the built-in worlds at the default 16 cells per L_min are estimated at 10 - 26
minutes, spent without a word. The estimate is an order of magnitude (the corridor's
pursuer bound at its defaults, estimated 43 s, took 9 s of wall time on a loaded machine:
at rho = 0.5 it certifies nothing and its fixed point ends early). At the built-in worlds'
defaults (L_min = 2) only the office's pursuer bound (148 s) passes two minutes."""


def _cached(kind, cls, solver, spec, res, cache, cache_dir, progress, memory_budget=None):
    """The bound ``kind`` of ``spec`` at ``res``: loaded from the cache, or solved and
    stored (a read-only or full disk only costs the recomputation next time)."""
    if cache:
        bound = _from_cache(kind, cls, spec, res, cache_dir)
        if bound is not None:
            return bound
    size = bound_size(spec, res, kind)
    # a solve the memory budget refuses (the solver checks it first) is not announced
    if size.seconds > LONG_SOLVE_SECONDS and size.bytes <= _memory_budget(memory_budget):
        where = "; it is cached for the next run" if cache else ""
        warnings.warn(
            f"solving the {kind} bound of map {spec.map.name!r} (L in [{spec.l_min:g}, "
            f"{spec.l_max:g}], cell {res.cell:g}): {size.describe()}, estimated to take "
            f"about {duration(size.seconds)}{where}; the time grows as "
            "(cells per L_min)^4, so a coarser resolution shortens it",
            LongRunWarning,
            stacklevel=3,
        )
    bound = solver(spec, res, progress=progress, memory_budget=memory_budget)
    if cache:
        try:
            save_arrays(kind, spec, res, bound.to_arrays(), cache_dir)
        except OSError:
            pass
    return bound


def _from_cache(kind, cls, spec, res, cache_dir):
    """The bound ``kind`` of ``spec`` at ``res`` read from the cache, or None (absent,
    stale or damaged)."""
    arrays = load_arrays(kind, spec, res, (*cls.tables, "iterations", "seconds"), cache_dir)
    if arrays is None:
        return None
    try:
        return cls.from_arrays(spec, res, arrays)
    except ValueError:
        return None


def cached_pursuer_bound(
    spec: GameSpec,
    res: Resolution,
    *,
    cache: bool = True,
    cache_dir: str | os.PathLike | None = None,
    progress: bool = False,
    memory_budget: object = None,
) -> PursuerBound:
    """The pursuer bound of ``spec`` at ``res``, from the cache or solved (and stored)."""
    return _cached("pursuer", PursuerBound, solve_pursuer_bound, spec, res, cache, cache_dir,
                   progress, memory_budget)  # fmt: skip


def cached_evader_bound(
    spec: GameSpec,
    res: Resolution,
    *,
    cache: bool = True,
    cache_dir: str | os.PathLike | None = None,
    progress: bool = False,
    memory_budget: object = None,
) -> EvaderBound:
    """The evader bound of ``spec`` at ``res``, from the cache or solved (and stored)."""
    return _cached("evader", EvaderBound, solve_evader_bound, spec, res, cache, cache_dir,
                   progress, memory_budget)  # fmt: skip


@dataclass(frozen=True)
class StartSet:
    """Starts with both players on their lattices, and their labels.

    Attributes:
        pursuer: (n, 2) pursuer positions.
        evader: (n, 2) evader positions.
        label: (n,) ``"pursuer"``, ``"evader"`` or ``"unknown"``.
        escape_steps: (n,) for evader-labelled starts, the certified bound on referee steps
            until surveillance breaks (-1 elsewhere).
    """

    pursuer: np.ndarray
    evader: np.ndarray
    label: np.ndarray
    escape_steps: np.ndarray

    def __len__(self) -> int:
        return len(self.label)

    def counts(self) -> dict[str, int]:
        """How many starts carry each label."""
        return {k: int(np.count_nonzero(self.label == k)) for k in LABELS}

    def fractions(self) -> dict[str, float]:
        """The share of each label (zeros when empty)."""
        n = max(1, len(self))
        return {k: v / n for k, v in self.counts().items()}


@dataclass
class Referee:
    """Both bounds of one game.

    Attributes:
        spec: the game.
        pursuer: the pursuer bound (certifies pursuer wins).
        evader: the evader bound (certifies evader wins).
    """

    spec: GameSpec
    pursuer: PursuerBound
    evader: EvaderBound

    # ------------------------------------------------------------------ single starts
    def classify(self, pursuer, evader) -> str:
        """``"pursuer"``, ``"evader"`` or ``"unknown"`` for one real start.

        Examples:
            A slow evader in an open room: the pursuer holds from a start in the middle.

            >>> from envs.maps import Map
            >>> room = Map([(0, 0), (5, 0), (5, 5), (0, 5)])
            >>> spec = GameSpec(room, 1.0, 2.0, v_pursuer=1.0, v_evader=0.2, body_radius=0.05)
            >>> ref = solve(spec, 12, cache=False)
            >>> ref.classify((2.5, 4.0), (2.5, 2.5))
            'pursuer'

        Raises:
            InvalidConfigError: a position is not a finite (x, y) point.
            InvalidPlacementError: surveillance does not hold at the start (out of range
                or occluded), so it is not a start of the game.
        """
        p, e = check_start(self.spec, pursuer, evader)
        if self.pursuer.certifies(p, e):
            return "pursuer"
        if self.evader.certifies(p, e):
            return "evader"
        return "unknown"

    def escape_time(self, pursuer, evader) -> float | None:
        """A certified bound on the time the evader needs to break surveillance from this
        start (None when the start is not certified for the evader)."""
        steps = self.evader.escape_steps(V.point("pursuer", pursuer), V.point("evader", evader))
        return None if steps is None else steps * self.evader.res.tau

    # ------------------------------------------------------------------ many starts
    def lattice_starts(self, *, margin: float = 0.0) -> StartSet:
        """Every start with the pursuer on the pursuer bound's lattice and the evader on the
        evader bound's lattice that surveillance holds at (range with ``margin`` inside it,
        line of sight), labelled by array lookups (the state-level certificates)."""
        spec = self.spec
        m = V.nonnegative("margin", margin)
        P = self.pursuer.lattice.points
        E = self.evader.lattice.points
        pi, ei = _pairs_in_range(P, E, spec.l_min + m, spec.l_max - m)
        ker = kernel_for(spec.map)
        if len(pi):
            clear = ker.line_of_sight_many(P[pi], E[ei])
            pi, ei = pi[clear], ei[clear]
        label = np.full(len(pi), "unknown", dtype=object)
        steps = np.full(len(pi), -1, dtype=np.int64)
        if len(pi):
            pw = _lookup(self.pursuer.lattice, self.pursuer.win, pi, E[ei], False)
            er = _lookup(self.evader.lattice, self.evader.rank, ei, P[pi], -1)
            ew = er >= 0
            label[ew] = "evader"
            steps[ew] = er[ew]  # rank n: surveillance breaks within n steps
            label[pw] = "pursuer"
            if np.any(pw & ew):  # both certified: impossible unless a bound is wrong
                raise AssertionError(
                    f"referee: {int(np.count_nonzero(pw & ew))} starts certified for both "
                    f"players on map {spec.map.name!r}"
                )
        return StartSet(P[pi], E[ei], label.astype(str), steps)

    def has_lattice_start(self) -> bool:
        """Whether :meth:`lattice_starts` (margin 0) holds a start, without listing them."""
        return _any_start(self.spec, self.pursuer.lattice.points, self.evader.lattice.points)

    def sample_starts(
        self,
        n: int,
        rng: np.random.Generator,
        *,
        kind: str = "pursuer",
        jitter: bool = True,
        margin: float = 0.0,
    ) -> list[dict[str, tuple[float, float]]]:
        """Draw ``n`` starts of one label, as env ``reset`` options.

        The certified player sits on its lattice point; with ``jitter`` the other one is
        moved uniformly inside its cell (its certificate covers the whole cell), keeping
        its clearance and the line of sight.

        Args:
            n: how many (>= 0); draws with replacement when fewer exist.
            rng: the only source of randomness.
            kind: ``"pursuer"``, ``"evader"`` or ``"unknown"``.
            jitter: move the uncertified player off its lattice point.
            margin: keep the start's distance this far inside [l_min, l_max].

        Raises:
            InvalidConfigError: bad ``kind``, ``n`` or ``rng``, or no start of that kind
                exists.
            MemoryBudgetError: ``n`` starts would not fit in the memory budget
                (:func:`check_sample_size`).
        """
        n = check_sample_size(n)
        kind = V.choice("kind", kind, LABELS)
        if not isinstance(rng, np.random.Generator):  # None was an AttributeError, after
            raise InvalidConfigError(  # enumerating every lattice start
                f"sample_starts: rng = {V.shown(rng)}: expected a numpy.random.Generator "
                f"(np.random.default_rng(seed)), got {type(rng).__name__}"
            )
        starts = self.lattice_starts(margin=margin)
        idx = np.flatnonzero(starts.label == kind)
        if len(idx) == 0:
            why = self.pursuer.vacuity() if kind == "pursuer" else None
            raise InvalidConfigError(
                f"sample_starts: no {kind!r}-labelled start on map {self.spec.map.name!r} "
                f"at this resolution (counts {starts.counts()})"
                + ("" if why is None else f"; which says nothing about the game: {why}")
            )
        pick = rng.choice(idx, size=n, replace=n > len(idx))
        out = []
        for i in pick.tolist():
            p, e = starts.pursuer[i].copy(), starts.evader[i].copy()
            if jitter and kind != "unknown":
                if kind == "pursuer":
                    e = self._jitter(e, p, self.pursuer.lattice.h, rng, margin)
                else:
                    p = self._jitter(p, e, self.evader.lattice.h, rng, margin)
            out.append(
                {"pursuer": (float(p[0]), float(p[1])), "evader": (float(e[0]), float(e[1]))}
            )
        return out

    def _jitter(self, x, other, h, rng, margin) -> np.ndarray:
        spec = self.spec
        ker = kernel_for(spec.map)
        for _ in range(16):
            y = x + rng.uniform(-0.5 * h, 0.5 * h, size=2) * (1.0 - 1e-9)
            L = float(np.hypot(*(y - other)))
            if not (spec.l_min + margin <= L <= spec.l_max - margin):
                continue
            if spec.map.distance_to_walls(y[None])[0] < spec.body_radius:
                continue
            if not spec.map.contains(y[None])[0] or not ker.line_of_sight(y, other):
                continue
            return y
        return x

    # ------------------------------------------------------------------ reports
    def summary(self, *, margin: float = 0.0) -> dict[str, Any]:
        """Sizes, timings and the label fractions over all lattice starts.

        ``gap`` is the fraction of starts neither bound certifies: the resolution error.
        ``pursuer_bound["vacuous"]`` says why the pursuer wins say nothing here (the range
        band is used up, rho is in the regime where the bound was measured to certify
        nothing, or it certified no state; :meth:`PursuerBound.vacuity`), None otherwise;
        ``pursuer_bound["fallback_from"]`` is the default lattice (``coarse, spacing,
        tau``) when it certified no state and :func:`solve` fell back to a finer one
        (``pursuer_fallback``), None otherwise; ``evader_bound["fallback_from"]`` likewise
        when the default evader lattice certified less than :data:`EVADER_FALLBACK_SHARE`
        of its live states and :func:`solve` kept a finer one (``evader_fallback``).
        """
        starts = self.lattice_starts(margin=margin)
        fr = starts.fractions()
        pb, eb = self.pursuer, self.evader
        return {
            "map": self.spec.map.name,
            "rho": self.spec.rho,
            "starts": len(starts),
            "pursuer": fr["pursuer"],
            "evader": fr["evader"],
            "gap": fr["unknown"],
            "pursuer_bound": {
                "cell": pb.res.cell,
                "spacing": pb.res.spacing,
                "tau": pb.res.tau,
                "states": int(pb.win.size),
                "iterations": pb.iterations,
                "seconds": dict(pb.seconds),
                "vacuous": pb.vacuity(),
                "coarse": pb.res.coarse,
                "fallback_from": _res_dict(pb.fallback_from),
            },
            "evader_bound": {
                "cell": eb.res.cell,
                "spacing": eb.res.spacing,
                "tau": eb.res.tau,
                "states": int(eb.win.size),
                "iterations": eb.iterations,
                "seconds": dict(eb.seconds),
                "coarse": eb.res.coarse,
                "fallback_from": _res_dict(eb.fallback_from),
            },
        }


def _res_dict(res: Resolution | None) -> dict[str, float] | None:
    """A fallen-back-from lattice as :meth:`Referee.summary` reports it."""
    if res is None:
        return None
    return {"coarse": res.coarse, "spacing": res.spacing, "tau": res.tau}


def _pairs_in_range(P: np.ndarray, E: np.ndarray, lo: float, hi: float):
    """Index pairs (i, j) with lo <= |P[i] - E[j]| <= hi."""
    from scipy.spatial import cKDTree

    tree = cKDTree(E)
    pi, ei = [], []
    for i, nbrs in enumerate(tree.query_ball_point(P, hi)):
        if not nbrs:
            continue
        nb = np.asarray(nbrs)
        d = np.hypot(*(E[nb] - P[i]).T)
        nb = nb[d >= lo]
        pi.append(np.full(len(nb), i))
        ei.append(nb)
    if not pi:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    return np.concatenate(pi).astype(np.int64), np.concatenate(ei).astype(np.int64)


def _lookup(lat, table: np.ndarray, k: np.ndarray, other: np.ndarray, fill):
    """``table[k, window cell of other]`` (``fill`` off the window)."""
    ab = lat.cell_of(other) - lat.point_cells[k] + lat.hw
    inside = (ab >= 0).all(axis=1) & (ab < lat.W).all(axis=1)
    out = np.full(len(k), fill, dtype=table.dtype)
    out[inside] = table[k[inside], ab[inside, 0], ab[inside, 1]]
    return out


def solve(
    spec: GameSpec,
    cells_per_lmin: float = 24.0,
    *,
    pursuer_coarse: int | None = None,
    evader_coarse: int | None = None,
    pursuer_steps: float = 3.0,
    evader_steps: float = 2.0,
    sweep_pieces: int = 2,
    dt: float | None = None,
    pursuer_fallback: bool = True,
    evader_fallback: bool = True,
    cache: bool = True,
    cache_dir: str | os.PathLike | None = None,
    progress: bool = False,
    memory_budget: object = None,
) -> Referee:
    """Solve (or load) both bounds of ``spec`` at one resolution.

    Each bound gets :meth:`Resolution.for_role` with the same cells; each certified
    player covers a few lattice spacings of its own lattice per step. The pursuer bound
    loses about a cell per step to the evader's unknown position within its cell, so the
    evader should cover several cells per step (a coarse pursuer lattice, a long step);
    but the evader also roams freely during the pursuer's committed step, which eats the
    sensor range from both ends (a short step). The default lattice, ``round(2 / rho)``
    cells (2 to 12), with the pursuer covering three spacings per step, lets the evader
    cover about six cells per step; three spacings rather than two also give the pursuer
    moves in 16 directions rather than 8, without which the bound collapses at some
    resolutions (the open room at rho = 0.2: 0% certified at 12 and 14 cells per L_min
    with two spacings, 88-90% with three). The evader bound loses the pursuer's
    foreknowledge of the evader's step (a short step is better: two spacings) but needs
    the evader to cover a few lattice spacings per step: its default lattice is
    ``round(8 rho)`` cells (2 to 8). Neither lattice is coarser than a quarter of the
    sensor range ``l_max - l_min``. Both share the cells' anchor, so a start with each
    player on its lattice can be certified either way.

    The pursuer bound is vacuous (it certifies nothing, although the real game may well be a
    pursuer win) when its range band is used up, from rho = 0.35 at every resolution
    tried, and at some lattices below that (the empty 10 m room at rho = 0.3: 0 % at the
    default lattice, tau = 1.5 s; 98 % with ``pursuer_coarse=2``, tau = 0.8 s), and far
    below it where the pursuer must pass the evader in a narrow passage (the corner world's
    5 m arms at rho = 0.1: 0 % at the default lattice, 93 % with ``pursuer_coarse=3``); see
    :mod:`strategies.referee.pursuer_bound`. When the default lattice certifies no state at
    rho < :data:`VACUOUS_RHO`, the pursuer bound is solved once more one cell finer
    (``pursuer_fallback``) and kept if it certifies some state: at 16 cells per L_min it
    recovers the corner and the l_hall at rho = 0.1 and the open room at rho = 0.3. A pursuer
    bound that still certifies nothing means "unknown", and
    :class:`~envs.errors.VacuousBoundWarning` says so, with the numbers.

    The evader bound has a blind spot of its own (issue 13): where the evader wins only by
    rounding a corner closely (two_rooms' corridor mouths, 1 wide), its default lattice
    at 16 cells per L_min (coarse 4: spacing 0.5, tau 2 s at rho = 0.5) keeps it 0.5 from
    the corner, and the bound's pursuer, moving after seeing the evader's step, always
    finds a cell whose rod grazes the corner: 0.05 % of the starts certified where coarse
    2 certifies 100 %. When the default evader lattice (3 cells or more) certifies less
    than :data:`EVADER_FALLBACK_SHARE` of its live states, the evader bound is solved once more
    at half the cells per spacing (:func:`evader_fallback_resolution`) and kept if it
    certifies a larger fraction (``evader_fallback``).

    Args:
        spec: the game.
        cells_per_lmin: opponent cells per L_min (the resolution; the gap shrinks as it
            grows, the states grow about as its third to fourth power, see
            ``benchmarks/referee_scaling.py``).
        pursuer_coarse: cells per spacing of the pursuer bound's lattice (None: auto).
        evader_coarse: cells per spacing of the evader bound's lattice (None: auto).
        pursuer_steps: lattice spacings the pursuer covers per step (pursuer bound).
        evader_steps: lattice spacings the evader covers per step (evader bound).
        sweep_pieces: pieces per step of the pursuer bound's sweep test.
        dt: round each ``tau`` up to a whole number of this env step (for referee policies).
        pursuer_fallback: when the default pursuer lattice (``pursuer_coarse=None``, 3
            cells or more) certifies no state at ``rho <`` :data:`VACUOUS_RHO`, solve the
            pursuer bound once more with ``pursuer_coarse`` one less (finer, a shorter step) and
            keep it if it certifies some state (:func:`pursuer_fallback_resolution`; its
            ``fallback_from`` names the default lattice). False: the default lattice only.
        evader_fallback: when the default evader lattice (``evader_coarse=None``, 3 cells
            or more) certifies less than :data:`EVADER_FALLBACK_SHARE` of its live states,
            solve the evader bound once more at half its cells per spacing (a finer
            lattice, a shorter step) and keep it if it certifies a larger fraction
            (:func:`evader_fallback_resolution`; its ``fallback_from`` names the default
            lattice). False: the default lattice only.
        cache: read and write the on-disk cache.
        cache_dir: cache directory (default ``$SURVEIL_CACHE_DIR`` or ``~/.cache/surveil``).
        progress: print the fixed points' progress.
        memory_budget: bytes (or ``"2GB"``) the two solves may take together; default
            ``$SURVEIL_MEMORY_BUDGET`` or half the RAM. Checked before anything is solved
            or loaded, from the lattice sizes (:mod:`strategies.referee._budget`).

    Raises:
        InfeasibleError: the estimated peak exceeds the budget; the message gives the
            estimate (memory, states, time) and the ``cells_per_lmin`` that would fit.
        NoStartError: the two lattices hold no start (no pair of points in range and in
            sight, e.g. cells longer than L_max, or a lattice that misses a narrow
            passage), so there is nothing to certify; the message names the next finer
            resolution with one, else the coarsest.

    Warns:
        VacuousBoundWarning: the pursuer bound's wins say nothing about the game
            (:meth:`PursuerBound.vacuity`, the reason and its numbers in the message).
    """
    if not isinstance(spec, GameSpec):
        raise InvalidConfigError(f"solve: expected a GameSpec, got {type(spec).__name__}")
    cells_per_lmin = check_cells_per_lmin(cells_per_lmin)
    pursuer_fallback = V.boolean("pursuer_fallback", pursuer_fallback)
    evader_fallback = V.boolean("evader_fallback", evader_fallback)
    knobs = dict(pursuer_coarse=pursuer_coarse, evader_coarse=evader_coarse,
                 pursuer_steps=pursuer_steps, evader_steps=evader_steps,
                 sweep_pieces=sweep_pieces, dt=dt)  # fmt: skip

    if cells_per_lmin < spec.l_min / spec.l_max:  # cells longer than L_max: no start
        raise _no_start(spec, cells_per_lmin, knobs)  # (cells_per_lmin = 1e-300 overflowed)
    budget = check_solve_budget(spec, cells_per_lmin, memory_budget=memory_budget, **knobs)
    rp = _resolution(spec, "pursuer", cells_per_lmin, **knobs)
    re = _resolution(spec, "evader", cells_per_lmin, **knobs)
    kw = dict(cache=cache, cache_dir=cache_dir, progress=progress, memory_budget=budget)
    try:
        pursuer, tried = _pursuer_bound(
            spec, rp, cells_per_lmin, knobs, kw, pursuer_fallback, [bound_size(spec, re, "evader")]
        )
        before = [bound_size(spec, pursuer.res, "pursuer")]
        evader = _evader_bound(spec, re, cells_per_lmin, knobs, kw, evader_fallback, before)
    except NoStartError:  # a lattice with no point at all
        raise _no_start(spec, cells_per_lmin, knobs) from None
    ref = Referee(spec=spec, pursuer=pursuer, evader=evader)
    if not ref.has_lattice_start():  # it returned 0 starts, "gap 0.0", without a word
        spacings = (pursuer.lattice.spacing, evader.lattice.spacing)
        raise _no_start(spec, cells_per_lmin, knobs, spacings)
    _warn_vacuous(spec, pursuer, tried)
    return ref


def check_solve_budget(
    spec: GameSpec, cells_per_lmin: float = 24.0, *, memory_budget: object = None, **knobs: Any
) -> float:
    """The memory budget in bytes, after checking that :func:`solve` with these arguments
    fits in it: the check :func:`solve` makes first, for a caller that must refuse before
    it says anything else (``surveil referee`` announced a solve of "up to about 1.08e+19
    h" and then refused it).

    Args:
        spec, cells_per_lmin, memory_budget: as :func:`solve`.
        **knobs: :func:`solve`'s ``pursuer_coarse, evader_coarse, pursuer_steps,
            evader_steps, sweep_pieces, dt``.

    Raises:
        MemoryBudgetError: as :func:`solve`.
    """
    cells_per_lmin = check_cells_per_lmin(cells_per_lmin)

    def sizes(cpl: float) -> list[SolveSize]:
        return [
            bound_size(spec, _resolution(spec, role, cpl, **knobs), role)
            for role in ("pursuer", "evader")
        ]

    return check_budget(
        f"solve(map {spec.map.name!r}, L in [{spec.l_min:g}, {spec.l_max:g}], "
        f"{cells_per_lmin:g} cells per L_min)",
        sizes(cells_per_lmin),
        memory_budget,
        resize=sizes,
        cells_per_lmin=cells_per_lmin,
    )


def pursuer_fallback_resolution(
    spec: GameSpec, bound: PursuerBound, cells_per_lmin: float, **knobs: Any
) -> Resolution | None:
    """The pursuer lattice :func:`solve` retries when ``bound``, solved at its default
    lattice, certified no state: ``pursuer_coarse`` one less (spacing ``(c - 1) h``, step
    ``tau`` shorter in proportion). None when no retry applies: ``knobs`` set
    ``pursuer_coarse`` (a lattice asked for is kept), the bound certified some state,
    ``rho >=`` :data:`VACUOUS_RHO` (where every lattice tried certified nothing), or the
    default lattice is two cells or fewer (coarse 1 has four times the points: at 8 cells
    per L_min its solve took 4 - 12 times the default's, and certified only the open room
    at rho = 0.2 / 0.3 of the built-in maps tried).

    Why one less: where the evader must be passed in a passage (the corner world's 5 m arms,
    the l_hall's pillar at rho = 0.1) or herds the pursuer in the open (the empty room at
    rho = 0.3), the default lattice certifies nothing and ``pursuer_coarse`` one less
    certifies 92-98 % at 16 cells per L_min, for about the default's solve time (0.6 -
    1.3 times it); maps where neither certifies pay 1.5 - 3.4 times it for nothing, once
    (:mod:`strategies.referee.pursuer_bound`'s tables).

    Args:
        spec, cells_per_lmin: as :func:`solve`.
        bound: the pursuer bound solved at the default lattice.
        **knobs: :func:`solve`'s ``pursuer_coarse, pursuer_steps, sweep_pieces, dt``.
    """
    if bound.win.any():
        return None
    return _fallback_resolution(spec, bound.res, cells_per_lmin, knobs)


def _fallback_resolution(
    spec: GameSpec, res: Resolution, cells_per_lmin: float, knobs: Mapping[str, Any]
) -> Resolution | None:
    """:func:`pursuer_fallback_resolution` whatever the default lattice certifies: the
    lattice retried after a default pursuer lattice ``res`` that certifies nothing."""
    if knobs.get("pursuer_coarse") is not None:
        return None
    if spec.rho >= VACUOUS_RHO or res.coarse <= 2:
        return None
    knobs = {**knobs, "pursuer_coarse": res.coarse - 1}
    return _resolution(spec, "pursuer", cells_per_lmin, **knobs)


def evader_fallback_resolution(
    spec: GameSpec, bound: EvaderBound, cells_per_lmin: float, **knobs: Any
) -> Resolution | None:
    """The evader lattice :func:`solve` retries when ``bound``, solved at its default
    lattice, certified less than :data:`EVADER_FALLBACK_SHARE` of its live states:
    ``evader_coarse`` halved (at least 2; the same spacings a step, so the step is shorter
    in proportion). None when no retry applies: ``knobs`` set ``evader_coarse`` (a lattice
    asked for is kept), the bound certified that share or more, or the default lattice is
    two cells or fewer (coarse 1 has four times the points).

    Why: the evader bound's pursuer moves after seeing the evader's whole step, so the
    evader wins a passage's mouth only by rounding its corner closer than a coarse lattice
    lets it (two_rooms at rho = 0.5: coarse 4, spacing 0.5, tau 2 s certifies 0.05 % of
    the starts, coarse 2 100 %; the corner world 0.05 % and 14.5 %). Both are
    certificates: the union of their certified starts is sound too, but the referee keeps
    one evader bound (the one its policy plays), so the finer one replaces the default.

    Args:
        spec, cells_per_lmin: as :func:`solve`.
        bound: the evader bound solved at the default lattice.
        **knobs: :func:`solve`'s ``evader_coarse, evader_steps, dt``.
    """
    if bound.live_fraction() >= EVADER_FALLBACK_SHARE:
        return None
    return _evader_fallback(spec, bound.res, cells_per_lmin, knobs)


def _evader_fallback(
    spec: GameSpec, res: Resolution, cells_per_lmin: float, knobs: Mapping[str, Any]
) -> Resolution | None:
    """:func:`evader_fallback_resolution` whatever the default lattice ``res`` certifies."""
    if knobs.get("evader_coarse") is not None or res.coarse <= 2:
        return None
    knobs = {**knobs, "evader_coarse": max(2, res.coarse // 2)}
    return _resolution(spec, "evader", cells_per_lmin, **knobs)


def _evader_bound(spec, res, cpl, knobs, kw, fallback, before=()):
    """The evader bound at ``res`` and, when it certifies next to nothing and
    ``fallback`` allows, at :func:`evader_fallback_resolution` (kept if it certifies a
    larger fraction of its live states). A fallback whose solve would exceed the memory budget
    with ``before`` (the sizes of the solves made before it, whose results are held) and the
    default is not solved."""
    bound = cached_evader_bound(spec, res, **kw)
    alt = evader_fallback_resolution(spec, bound, cpl, **knobs) if fallback else None
    if alt is None:
        return bound
    try:  # the default bound is held while the fallback is solved
        sizes = [*before, bound_size(spec, res, "evader"), bound_size(spec, alt, "evader")]
        check_budget("the evader bound's fallback", sizes, kw["memory_budget"])
    except MemoryBudgetError:  # the default stands, as without the fallback
        return bound
    try:
        other = cached_evader_bound(spec, alt, **kw)
    except NoStartError:  # the finer lattice misses a narrow passage: the default stands
        return bound
    if other.live_fraction() <= bound.live_fraction():
        return bound
    return replace(other, fallback_from=bound.res)


def _pursuer_bound(spec, res, cpl, knobs, kw, fallback, after=()):
    """The pursuer bound at ``res`` and, when it certifies nothing and ``fallback``
    allows, at :func:`pursuer_fallback_resolution` (kept if it certifies some state).

    Returns:
        ``(bound, tried)``: when the fallback was not kept, ``tried`` is its resolution and
        why (it certified nothing, or its solve would exceed the memory budget with
        ``after``, the sizes of the solves that follow it), else None.
    """
    bound = cached_pursuer_bound(spec, res, **kw)
    alt = pursuer_fallback_resolution(spec, bound, cpl, **knobs) if fallback else None
    if alt is None:
        return bound, None
    try:
        check_budget("the pursuer bound's fallback", [bound_size(spec, alt, "pursuer"), *after],
                     kw["memory_budget"])  # fmt: skip
    except MemoryBudgetError:  # the default's 0 % stands, as without the fallback
        return bound, (alt, "its solve would exceed the memory budget")
    try:
        other = cached_pursuer_bound(spec, alt, **kw)
    except NoStartError:  # the finer lattice misses a narrow passage
        return bound, (alt, "it has no lattice point")
    if not other.win.any():
        return bound, (alt, "it certified no state either")
    return replace(other, fallback_from=bound.res), None


def _warn_vacuous(spec: GameSpec, bound: PursuerBound, tried) -> None:
    reason = bound.vacuity()
    if reason is None:
        return
    if tried is not None:
        alt, why = tried
        reason += (
            f"; the fallback lattice (pursuer_coarse = {alt.coarse}, spacing "
            f"{alt.spacing:.4g}, step {alt.tau:.4g} s) was not kept: {why}"
        )
    warnings.warn(f"map {spec.map.name!r}: {reason}", VacuousBoundWarning, stacklevel=3)


def _resolution(
    spec: GameSpec,
    role: str,
    cpl: float,
    *,
    pursuer_coarse: int | None = None,
    evader_coarse: int | None = None,
    pursuer_steps: float = 3.0,
    evader_steps: float = 2.0,
    sweep_pieces: int = 2,
    dt: float | None = None,
) -> Resolution:
    """The resolution of ``role``'s bound in :func:`solve` (its docstring says why)."""
    # at least four lattice spacings across the sensor range [l_min, l_max]
    # (capped at 12 before the floor: L_max = 1e300 at 1e12 cells per L_min is an inf)
    cap = max(2, math.floor(min(12.0, (spec.l_max - spec.l_min) * cpl / (4.0 * spec.l_min))))
    if role == "pursuer":
        coarse = pursuer_coarse
        if coarse is None:
            coarse = int(min(12, cap, max(2, round(2.0 / spec.rho))))
        steps = pursuer_steps
    else:
        coarse = evader_coarse
        if coarse is None:
            coarse = int(min(8, cap, max(2, round(8.0 * spec.rho))))
        steps = evader_steps
    return Resolution.for_role(
        spec, role, cpl, coarse=coarse, steps=steps, sweep_pieces=sweep_pieces, dt=dt
    )


def unsolved_sizes(
    spec: GameSpec,
    cells_per_lmin: float = 24.0,
    *,
    cache: bool = True,
    cache_dir: str | os.PathLike | None = None,
    **knobs: Any,
) -> list[SolveSize]:
    """The estimated sizes (states, memory, time: :func:`~._budget.bound_size`) of the
    bounds :func:`solve` would solve with these arguments, leaving out those it would load
    from the cache: what a caller tells its user before a long solve (``surveil
    referee``, whose ``dt = 10`` on the corridor solved for many minutes without a word).

    Args:
        spec, cells_per_lmin, cache, cache_dir: as :func:`solve`.
        **knobs: :func:`solve`'s ``pursuer_coarse, evader_coarse, pursuer_steps,
            evader_steps, sweep_pieces, dt``.
    """
    cells_per_lmin = check_cells_per_lmin(cells_per_lmin)
    out = []
    for role in ("pursuer", "evader"):
        res = _resolution(spec, role, cells_per_lmin, **knobs)
        if cache and cache_path(role, spec, res, cache_dir).is_file():
            continue
        out.append(bound_size(spec, res, role))
    return out


def fallback_size(
    spec: GameSpec,
    cells_per_lmin: float = 24.0,
    *,
    cache: bool = True,
    cache_dir: str | os.PathLike | None = None,
    **knobs: Any,
) -> SolveSize | None:
    """The estimated size of the pursuer bound's retry one cell finer that :func:`solve`
    (``pursuer_fallback=True``) adds when the default pursuer lattice certifies no state
    (:func:`pursuer_fallback_resolution`), or None when no retry can happen with these
    arguments (an explicit ``pursuer_coarse``, ``rho >=`` :data:`VACUOUS_RHO`, a default
    of two cells or fewer), its result is cached, or the default's solve is cached and
    certifies some state (so :func:`solve` keeps it). Whether an unsolved default
    certifies nothing is known only after its solve: a caller announcing
    :func:`unsolved_sizes` adds this as what the solve *may* add (``surveil referee``'s
    announcement did not count it).

    Args:
        spec, cells_per_lmin, cache, cache_dir, knobs: as :func:`unsolved_sizes`.
    """
    cells_per_lmin = check_cells_per_lmin(cells_per_lmin)
    res = _resolution(spec, "pursuer", cells_per_lmin, **knobs)
    alt = _fallback_resolution(spec, res, cells_per_lmin, knobs)
    if alt is None or (cache and cache_path("pursuer", spec, alt, cache_dir).is_file()):
        return None
    if cache:  # a cached default that certifies is kept: no retry (it was announced)
        default = _from_cache("pursuer", PursuerBound, spec, res, cache_dir)
        if default is not None and default.win.any():
            return None
    return replace(bound_size(spec, alt, "pursuer"), what="pursuer bound's fallback")


def evader_fallback_size(
    spec: GameSpec,
    cells_per_lmin: float = 24.0,
    *,
    cache: bool = True,
    cache_dir: str | os.PathLike | None = None,
    **knobs: Any,
) -> SolveSize | None:
    """:func:`fallback_size` for the evader bound: the estimated size of its retry at half
    the cells per spacing (:func:`evader_fallback_resolution`), or None when no retry can
    happen with these arguments (an explicit ``evader_coarse``, a default of two cells or
    fewer), its result is cached, or the default's solve is cached and certifies
    :data:`EVADER_FALLBACK_SHARE` of its live states or more.

    Args:
        spec, cells_per_lmin, cache, cache_dir, knobs: as :func:`unsolved_sizes`.
    """
    cells_per_lmin = check_cells_per_lmin(cells_per_lmin)
    res = _resolution(spec, "evader", cells_per_lmin, **knobs)
    alt = _evader_fallback(spec, res, cells_per_lmin, knobs)
    if alt is None or (cache and cache_path("evader", spec, alt, cache_dir).is_file()):
        return None
    if cache:
        default = _from_cache("evader", EvaderBound, spec, res, cache_dir)
        if default is not None and default.live_fraction() >= EVADER_FALLBACK_SHARE:
            return None
    return replace(bound_size(spec, alt, "evader"), what="evader bound's fallback")


COARSEST_SCAN_STEP = 2.0**0.125
""":func:`coarsest_with_starts` scans resolutions in this ratio (eight per doubling)."""
COARSEST_SCAN_LIMIT = 64.0
"""... up to this many cells per L_min (the referee's solves at 64 take minutes to hours)."""


def _lattice_has_start(spec: GameSpec, cpl: float, dt: float | None, knobs) -> bool:
    """Some start with the pursuer on the pursuer bound's lattice and the evader on the
    evader bound's, at :func:`solve`'s resolutions for ``cpl``, is in range and in sight
    (what :meth:`Referee.lattice_starts` enumerates, without solving)."""
    from strategies.referee.lattice import Lattice

    try:
        P = Lattice(spec, _resolution(spec, "pursuer", cpl, dt=dt, **knobs), "pursuer").points
        E = Lattice(spec, _resolution(spec, "evader", cpl, dt=dt, **knobs), "evader").points
    except NoStartError:  # no lattice point at all
        return False
    return _any_start(spec, P, E)


def _any_start(spec: GameSpec, P: np.ndarray, E: np.ndarray, chunk: int = 256) -> bool:
    """Whether some pair ``(P[i], E[j])`` is in range and in sight: the pairs of
    :meth:`Referee.lattice_starts`, ``chunk`` pursuer points at a time, stopping at the
    first (the built-in maps' first chunk holds one)."""
    ker = kernel_for(spec.map)
    for k in range(0, len(P), chunk):
        part = P[k : k + chunk]
        pi, ei = _pairs_in_range(part, E, spec.l_min, spec.l_max)
        if len(pi) and ker.line_of_sight_many(part[pi], E[ei]).any():
            return True
    return False


def _no_start(
    spec: GameSpec,
    cpl: float,
    knobs: Mapping[str, Any],
    spacings: tuple[float, float] | None = None,
) -> NoStartError:
    """Why a resolution with no lattice start is refused, and the next finer resolution
    with one (where a map's passages are about as narrow as its agents, one resolution's
    lattice can miss them where a neighbour's does not), else the coarsest. ``knobs`` are
    :func:`solve`'s (``dt`` among them)."""
    K = NoStartError.KNOB
    scan = {k: v for k, v in knobs.items() if k != "dt"}
    dt = knobs.get("dt")
    fit = coarsest_with_starts(spec, dt=dt, **scan)  # cheap: the first coarse lattices hold one
    finer = finer_with_starts(spec, cpl, dt=dt, **scan) if fit is not None and cpl > fit else None

    def shown(found: float) -> str:  # short, and a resolution with a start as printed
        for digits in (3, 4, 6):
            text = f"{found:.{digits}g}"
            if _lattice_has_start(spec, float(text), dt, scan):
                return text
        return repr(found)

    if finer is not None:
        advice = (
            f"the next finer resolution with one is {K} {shown(finer)} (a lattice can miss "
            "passages about as narrow as the agents where a neighbour's does not)"
        )
    elif fit is not None:
        advice = (
            f"the coarsest resolution with one is {K} {shown(fit)} (scanning up from "
            f"L_min / L_max = {spec.l_min / spec.l_max:.3g})"
        )
    else:
        advice = f"no resolution up to {COARSEST_SCAN_LIMIT:g} cells per L_min has one"
    lattices = "the referee's lattices"
    if spacings is not None:
        lattices += f" (spacings {spacings[0]:.4g} and {spacings[1]:.4g})"
    return NoStartError(
        f"{K} = {cpl:g}: {lattices} hold no start with the players in range "
        f"[{spec.l_min:g}, {spec.l_max:g}], body_radius = {spec.body_radius:g} from the walls "
        f"and in sight on map {spec.map.name!r}, so there is nothing to certify; {advice}"
    )


def coarsest_with_starts(spec: GameSpec, *, dt: float | None = None, **knobs: Any) -> float | None:
    """The coarsest resolution (cells per L_min) whose lattices hold a start
    (:meth:`Referee.lattice_starts` not empty), or None up to :data:`COARSEST_SCAN_LIMIT`.

    Two points of the fine lattice are at least a cell ``h = l_min / cpl`` apart, so no
    start exists while ``h > l_max``: the scan begins at ``l_min / l_max`` and goes up in
    steps of :data:`COARSEST_SCAN_STEP`. At such coarse resolutions both of :func:`solve`'s
    lattices have spacing ``2 h``, so the built-in maps' first start is at exactly
    ``2 l_min / l_max`` (the spacing equal to ``l_max``). The lattices are not nested: a
    finer resolution than the one found can still hold none on a map with narrow passages.
    ``dt`` and ``knobs`` are :func:`solve`'s.
    """
    cpl = spec.l_min / spec.l_max
    while cpl <= COARSEST_SCAN_LIMIT * (1.0 + 1e-9):
        if _lattice_has_start(spec, cpl, dt, knobs):
            return cpl
        cpl *= COARSEST_SCAN_STEP
    return None


def has_lattice_start(
    spec: GameSpec, cells_per_lmin: float, *, dt: float | None = None, **knobs: Any
) -> bool:
    """Whether :func:`solve` at ``cells_per_lmin`` (and ``dt``, ``knobs``) would have a
    lattice start (:meth:`Referee.lattice_starts` not empty), without solving: seconds on
    the larger built-in maps at 16-48 cells per L_min (office at 16: 3 s, the open room at
    48: 19 s)."""
    return _lattice_has_start(spec, check_cells_per_lmin(cells_per_lmin), dt, knobs)


def finer_with_starts(
    spec: GameSpec, cells_per_lmin: float, *, dt: float | None = None, **knobs: Any
) -> float | None:
    """The first resolution finer than ``cells_per_lmin`` whose lattices hold a start,
    scanning up to twice it in steps of :data:`COARSEST_SCAN_STEP`, or None.

    The lattices are not nested: where a map's passages are about as narrow as its agents,
    one resolution's lattice points can all miss them while a neighbour's do not (a ring
    corridor 0.3 wide, agents of radius 0.1: a start at 9, 10, 12.3 and 20 cells per L_min,
    none at 8, 11, 12, 16 or 24), so "refine the resolution" is no advice there.
    """
    cpl = check_cells_per_lmin(cells_per_lmin)
    top = min(2.0 * cpl, COARSEST_SCAN_LIMIT) * (1.0 + 1e-9)
    cpl *= COARSEST_SCAN_STEP
    while cpl <= top:
        if _lattice_has_start(spec, cpl, dt, knobs):
            return cpl
        cpl *= COARSEST_SCAN_STEP
    return None


def solve_role(
    spec: GameSpec,
    role: str,
    cells_per_lmin: float = 24.0,
    *,
    dt: float | None = None,
    pursuer_fallback: bool = True,
    evader_fallback: bool = True,
    cache: bool = True,
    cache_dir: str | os.PathLike | None = None,
    progress: bool = False,
    memory_budget: object = None,
    **knobs: Any,
) -> PursuerBound | EvaderBound:
    """The one bound of :func:`solve` that ``role`` plays: the pursuer bound for
    ``"pursuer"``, the evader bound for ``"evader"`` (a referee policy needs no other),
    at the resolution :func:`solve` gives it, from the same cache.

    Args:
        spec, cells_per_lmin, dt, pursuer_fallback, evader_fallback, cache, cache_dir,
            progress: as :func:`solve` (each bound falls back as there).
        role: ``"pursuer"`` or ``"evader"``.
        memory_budget: as :func:`solve`, for this one solve.
        **knobs: :func:`solve`'s ``pursuer_coarse, evader_coarse, pursuer_steps,
            evader_steps, sweep_pieces``.

    Raises:
        MemoryBudgetError: the solve's estimated peak exceeds the budget (naming the
            ``cells_per_lmin`` that fits).
        NoStartError: the bound's lattice has no point clear of the walls (naming a
            resolution whose lattices hold a start, as :func:`solve`).

    Warns:
        VacuousBoundWarning: as :func:`solve`, for the pursuer bound.
    """
    if not isinstance(spec, GameSpec):
        raise InvalidConfigError(f"solve_role: expected a GameSpec, got {type(spec).__name__}")
    if role not in ("pursuer", "evader"):
        raise InvalidConfigError(f"role = {role!r}: expected 'pursuer' or 'evader'")
    cells_per_lmin = check_cells_per_lmin(cells_per_lmin)
    pursuer_fallback = V.boolean("pursuer_fallback", pursuer_fallback)
    evader_fallback = V.boolean("evader_fallback", evader_fallback)

    def sizes(cpl: float) -> list[SolveSize]:
        return [bound_size(spec, _resolution(spec, role, cpl, dt=dt, **knobs), role)]

    budget = check_budget(
        f"solve_role(map {spec.map.name!r}, {role!r}, L in [{spec.l_min:g}, "
        f"{spec.l_max:g}], {cells_per_lmin:g} cells per L_min)",
        sizes(cells_per_lmin),
        memory_budget,
        resize=sizes,
        cells_per_lmin=cells_per_lmin,
    )
    res = _resolution(spec, role, cells_per_lmin, dt=dt, **knobs)
    kw = dict(cache=cache, cache_dir=cache_dir, progress=progress, memory_budget=budget)
    try:
        if role == "evader":
            return _evader_bound(
                spec, res, cells_per_lmin, {**knobs, "dt": dt}, kw, evader_fallback
            )
        bound, tried = _pursuer_bound(
            spec, res, cells_per_lmin, {**knobs, "dt": dt}, kw, pursuer_fallback
        )
    except NoStartError:  # its lattice has no point: say which resolution has a start
        raise _no_start(spec, cells_per_lmin, {**knobs, "dt": dt}) from None
    _warn_vacuous(spec, bound, tried)
    return bound


def check_start(game: Any, pursuer: Any, evader: Any) -> tuple[np.ndarray, np.ndarray]:
    """The start as two points, if it is one of the game's (finite points, the range in
    ``[l_min, l_max]``, in line of sight); ``game`` is a :class:`GameSpec` or an env
    config (anything with ``map``, ``l_min``, ``l_max``), so a caller can check a start
    before solving.

    Raises:
        InvalidConfigError: a position is not a finite (x, y) point.
        InvalidPlacementError: out of range or occluded.
    """
    p = V.point("pursuer", pursuer)
    e = V.point("evader", evader)
    L = float(np.hypot(*(p - e)))
    where = f"start pursuer={tuple(p.tolist())}, evader={tuple(e.tolist())}"
    if not game.l_min <= L <= game.l_max:
        raise InvalidPlacementError(
            f"{where}: distance {L:.6g} outside [l_min, l_max] = [{game.l_min:g}, {game.l_max:g}]"
        )
    if not kernel_for(game.map).line_of_sight(p, e):
        raise InvalidPlacementError(f"{where}: occluded")
    return p, e


def referee_for(config: Any, cells_per_lmin: float = 24.0, **kwargs: Any) -> Referee:
    """:func:`solve` for the game an env config plays (its map, range, speeds, body
    radius), with each ``tau`` a whole number of the config's ``dt``."""
    spec = GameSpec.from_config(config)
    kwargs.setdefault("dt", config.dt)
    return solve(spec, cells_per_lmin, **kwargs)


def _as_referee(obj: Any, solve_kwargs: Mapping[str, Any]) -> Referee:
    """``obj`` itself when it is a :class:`Referee`, else :func:`referee_for` of it (an env
    config: anything with ``map, l_min, l_max, v_pursuer, v_evader, body_radius, dt``)."""
    if isinstance(obj, Referee):
        return obj
    if not all(hasattr(obj, k) for k in ("map", "l_min", "l_max", "v_pursuer", "v_evader")):
        raise InvalidConfigError(
            f"expected a Referee or an env config, got {type(obj).__name__} {obj!r:.80}"
        )
    return referee_for(obj, **solve_kwargs)


def label_starts(
    referee: Referee | Any, starts: Iterable[Mapping[str, Any]], **solve_kwargs: Any
) -> list[str]:
    """Labels of env starts ``{"pursuer": (x, y), "evader": (x, y)}`` (see
    :meth:`Referee.classify`).

    Args:
        referee: a solved :class:`Referee`, or an env config (solved with
            :func:`referee_for` and ``solve_kwargs``, cached on disk).
        starts: the starts.
        **solve_kwargs: for :func:`referee_for` (``cells_per_lmin``, ``cache_dir``...).

    Raises:
        InvalidConfigError: ``starts`` is not an iterable of such mappings.
        InvalidPlacementError: surveillance does not hold at a start.
    """
    if isinstance(starts, Mapping) or not isinstance(starts, Iterable):
        raise InvalidConfigError(  # None was a TypeError; one start, "start 0 = 'pursuer'"
            f"label_starts: starts = {V.shown(starts)}: expected an iterable of "
            "{'pursuer': (x, y), 'evader': (x, y)} (a list of them)"
        )
    ref = _as_referee(referee, solve_kwargs)
    out = []
    for i, s in enumerate(starts):
        if not isinstance(s, Mapping) or "pursuer" not in s or "evader" not in s:
            raise InvalidConfigError(
                f"label_starts: start {i} = {s!r}: expected {{'pursuer': (x, y), 'evader': (x, y)}}"
            )
        out.append(ref.classify(s["pursuer"], s["evader"]))
    return out


def sample_starts(
    referee: Referee | Any,
    n: int,
    rng: np.random.Generator,
    *,
    kind: str = "pursuer",
    jitter: bool = True,
    margin: float = 0.0,
    **solve_kwargs: Any,
) -> list[dict[str, tuple[float, float]]]:
    """Certified starts of one kind for training curricula (:meth:`Referee.sample_starts`),
    from a :class:`Referee` or an env config (solved and cached as in :func:`label_starts`).
    """
    ref = _as_referee(referee, solve_kwargs)
    return ref.sample_starts(n, rng, kind=kind, jitter=jitter, margin=margin)
