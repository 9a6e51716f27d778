"""How much memory and time a referee solve needs, estimated before it starts.

Every per-state array of a bound (:mod:`.pursuer_bound`, :mod:`.evader_bound`) or of the
estimate (:mod:`.estimates`) has the shape ``(n_points, W, W)``: the certified lattice's
points times the window of opponent cells. So the memory of a solve is

    bytes ~ BASE_BYTES + per_state * n_points * W^2

with ``W = 2 ceil((l_max + reach + h / sqrt(2)) / h) + 3`` exactly the lattice's, and
``n_points`` from the free region eroded by the body radius (its area over the spacing
squared plus half its perimeter over the spacing: 0-20 % above the lattice's count).
``per_state`` follows the solvers' arrays (the constants below say which), its figures
measured: peak resident memory of one solve in a fresh process (``/usr/bin/time -v``),
rho = 0.5, L in [1, 2], body radius 0.05, the resolutions :func:`~.referee.solve` picks,
one busy core, a fresh process per solve. The error is that of the
memory above the interpreter's 125 MB:

======================================  ========  ==========  ==========  ======
solve (map, cells per L_min)            states    measured    estimated   error
======================================  ========  ==========  ==========  ======
pursuer bound, empty 16 x 10 room, 16   11.7 M    336 MB      340 MB      +2 %
pursuer bound, empty 16 x 10 room, 24   57.2 M    1045 MB     1150 MB     +11 %
pursuer bound, ``pillars`` 20 x 14, 12  11.2 M    332 MB      334 MB      +1 %
evader bound, empty 16 x 10 room, 32    177 M     3275 MB     3399 MB     +4 %
evader bound, ``pillars``, 20           45.8 M    1583 MB     1813 MB     +16 %
estimate, empty 5 x 5 room, 12          15.6 M    645 MB      743 MB      +19 %
estimate, empty 16 x 10 room, 6         10.4 M    485 MB      540 MB      +15 %
estimate, 8 x 8 room and a pillar, 8    10.1 M    581 MB      849 MB      +59 %
estimate, ``pillars``, 4                4.9 M     419 MB      487 MB      +23 %
estimate, ``pillars``, 6                16.9 M    741 MB      1334 MB     +96 %
======================================  ========  ==========  ==========  ======

Smaller solves (0.5 to 5 M states, the empty 5 x 5 room and the 8 x 8 room with a pillar
at 8 to 20 cells per L_min): -23 % to +14 %, a few MB either way. The estimate's blocked
fans (int64 indices per move) are a smaller share of its states at finer resolutions, so
on maps with obstacles its figure errs large by up to 2x. The time varies far more (the
fixed points' sweeps depend on the game) and is given as an upper bound.

Solves run one after the other, and a :class:`~strategies.referee.referee.Referee` keeps
each solved bound while it solves the next, so the peak of several solves is the largest
of (a solve's peak plus what the solves before it keep).

The budget is the ``memory_budget`` argument, else ``$SURVEIL_MEMORY_BUDGET`` (bytes, or
``"1.5GB"``), else half the machine's physical memory: the decompositions' budget
(:func:`strategies.memory.memory_budget`). Issue 13's probe, ``pursuer/referee``
on a 16 x 10 room at L_min = 0.3 (133 M states per bound), is estimated at about 3 GB, up
to 45 min; it ran over 5 min and 1.8-3.8 GB before it was killed.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from envs.errors import MemoryBudgetError
from strategies.memory import byte_size, memory_budget, physical_memory
from strategies.referee.lattice import count_lattice_vectors, grid_shape, window_half_width
from strategies.referee.spec import GameSpec, Resolution

__all__ = [
    "SolveSize",
    "bound_size",
    "check_budget",
    "duration",
    "estimate_size",
    "memory_budget",
    "peak",
]

BASE_BYTES = 125e6
"""The interpreter with numpy, scipy and shapely loaded (measured: 121-124 MB)."""

PURSUER_BYTES_PER_STATE = 10.0
PURSUER_BYTES_PER_STATE_MOVE = 0.25
"""The pursuer bound: five bool arrays and the erosions' temporaries, plus its packed
safe-move tables (one bit a state per move, twice while they are stacked)."""
EVADER_BYTES_PER_STATE = 18.0
EVADER_OCCLUSION_BYTES_PER_STATE = 17.0
"""The evader bound: bool arrays, rank (int32) and choice (int16); on a map with a convex
obstacle vertex its robust occlusion test adds a representative point per state (two
float64) and the groups' labels (int32)."""
ESTIMATE_BYTES_PER_STATE = 30.0
ESTIMATE_BYTES_PER_STATE_MOVE = 0.25
ESTIMATE_OCCLUSION_BYTES_PER_STATE = 30.0
"""The estimate: int64 indices of the clear states, packed per-move masks; on a map with
a convex obstacle vertex the blocked fans' indices (int64) per move."""
KEPT_BYTES_PER_STATE = {"pursuer": 3.0, "evader": 7.0, "estimate": 4.0}
"""What a solved bound or estimate solution keeps: win (1) and choice (2); win, rank (4)
and choice; safe, both orders' wins and the rank (1 each)."""

MOVE_TABLE_BYTES_PER_POINT_MOVE = 70.0
MOVE_TABLE_SECONDS_PER_POINT_MOVE = 1e-5
"""The certified player's move table (:meth:`~.lattice.Lattice.moves`, both bounds):
each point's destination per move (two int64), its index (int64), the mask and the
tested paths' ends (float64), each path's clearance from the walls. Measured on an 8 x 8
room with a pillar, 504 points: 66 bytes and 7.8 us a point-move at 7213 moves, 9-12 us
at 49-797. The pursuer bound's per-state-move tables (``PURSUER_BYTES_PER_STATE_MOVE``)
cover it; the evader bound's per-state arrays do not grow with its moves, so a long
evader step (``evader_steps = 1e4``: 3e8 moves) hung in the table, estimated at a few MB."""

COUNT_LIMIT = 1e30
"""Counts of the estimate (points, window cells, moves) are clamped here, far beyond any
memory: an absurd resolution (cells of 1e-300 m, a step of 1e300 s, L_max = 1e200) is
estimated, and refused for its memory, instead of an OverflowError or a
ZeroDivisionError from the arithmetic."""

SECONDS_PER_STATE = {"pursuer": 2e-5, "evader": 4e-7, "estimate": 2.5e-5}
"""Build plus fixed point on one busy core, the most measured (the fixed points' sweeps
depend on the game: the pursuer bound took 0.65 us a state on the 16 x 10 room at 16
cells per L_min and 18 us at 24): an upper bound, said as "up to"."""

PURSUER_SECONDS_PER_STATE_MOVE = 6e-9
PURSUER_MOVES_POWER = 1.4
"""The pursuer bound's safe-move tables grow faster than its states when its step is long:
a table per move, each testing the moves' sweeps against the convex corners near them
(a longer move, more of them). A step is three lattice spacings (29 moves) unless an env's
``dt`` rounds it up (``dt = 10`` on the corridor: a 10 s step, 1257 moves), and then the
tables take nearly all of the time: CPU seconds on the corridor at 8 cells per L_min
(624 k states) 0.22, 0.38, 6.6 and 42.5 at 29, 49, 317 and 1257 moves (244 of 248 s wall
in the tables at 1257), 0.8 and 36 at 16 cells per L_min (2.17 M states), 29 and 317
moves: about ``3e-9 * states * moves ** 1.4``. The estimate is the larger of
:data:`SECONDS_PER_STATE` and twice that fit, so a default step keeps its estimate."""


@dataclass(frozen=True)
class SolveSize:
    """The estimated size of one solve.

    Attributes:
        what: ``"pursuer bound"``, ``"evader bound"`` or ``"estimate at CPL cells per
            L_min"``.
        kind: ``"pursuer"``, ``"evader"`` or ``"estimate"``.
        points: certified lattice points (estimated).
        window: W, the window side in cells.
        moves: the moves of the player(s) whose tables are stored per move.
        bytes: peak memory of the solve, the interpreter included.
        kept: memory the solved result keeps.
        seconds: build and fixed point, order of magnitude.
        tau: the step of a bound's certified player (``None`` for the estimate).
    """

    what: str
    kind: str
    points: int
    window: int
    moves: int
    bytes: float
    kept: float
    seconds: float
    tau: float | None = None

    @property
    def states(self) -> int:
        """``points * window^2``."""
        return self.points * self.window**2

    def describe(self) -> str:
        """``"pursuer bound: 27,641 points x 69^2 window cells = 132 M states"``."""
        big = lambda n: f"{n:,}" if n < 1e12 else f"{n:.3g}"  # not 40 digits
        return (
            f"{self.what}: {big(self.points)} points x {big(self.window)}^2 window cells = "
            f"{self.states / 1e6:.3g} M states"
        )


def _points(spec: GameSpec, spacing: float) -> int:
    """The certified lattice's points, from the area and perimeter of the region at
    least ``body_radius`` from the walls: a lattice of spacing s in a region of area A
    and perimeter P has about A / s^2 + P / (2 s) points (measured: 0-20 % more than the
    lattice's count, the most on small maps at coarse spacings)."""
    region = spec.map.free_region.buffer(-spec.body_radius)
    if region.is_empty:
        return 0
    return _count(region.area / spacing / spacing + region.length / (2.0 * spacing)) + 1


def _count(x: float) -> int:
    """``ceil(x)``, at most :data:`COUNT_LIMIT` (an overflowed ``inf`` included)."""
    return math.ceil(min(x, COUNT_LIMIT))


def _window(reach: float, h: float) -> int:
    """``2 window_half_width(reach, h) + 1``, at most about ``2 COUNT_LIMIT``."""
    if reach / h > COUNT_LIMIT:
        return 2 * _count(COUNT_LIMIT) + 1
    return 2 * window_half_width(reach, h) + 1


def _moves(length: float, spacing: float) -> int:
    """:func:`~.lattice.count_lattice_vectors`, at most :data:`COUNT_LIMIT`."""
    r = length / spacing
    if r > 1e15:  # the disc's area (count_lattice_vectors' own beyond 1e5), clamped
        return _count(math.pi * r * r)
    return count_lattice_vectors(length, spacing)


def _cells(spec: GameSpec, h: float) -> int:
    _, _, nx, ny = grid_shape(spec.map.bounds, h)
    return nx * ny


def bound_size(spec: GameSpec, res: Resolution, role: str) -> SolveSize:
    """The size of :func:`~strategies.referee.pursuer_bound.solve_pursuer_bound`
    (``role="pursuer"``) or :func:`~strategies.referee.evader_bound.solve_evader_bound`."""
    points = _points(spec, res.spacing)
    W = _window(spec.l_max, res.cell)
    moves = _moves(spec.speed(role) * res.tau, res.spacing)
    states = points * W * W
    seconds = SECONDS_PER_STATE[role] * states
    table = 0.0  # the move table, where the per-state figures do not cover it
    if role == "pursuer":
        per = PURSUER_BYTES_PER_STATE + PURSUER_BYTES_PER_STATE_MOVE * moves
        tables = PURSUER_SECONDS_PER_STATE_MOVE * states * moves**PURSUER_MOVES_POWER
        seconds = max(seconds, tables)
    else:
        per = EVADER_BYTES_PER_STATE
        if spec.map.vertex_convex.any():
            per += EVADER_OCCLUSION_BYTES_PER_STATE
        table = MOVE_TABLE_BYTES_PER_POINT_MOVE * points * moves
        seconds += MOVE_TABLE_SECONDS_PER_POINT_MOVE * points * moves
    return SolveSize(
        what=f"{role} bound",
        kind=role,
        points=points,
        window=W,
        moves=moves,
        bytes=BASE_BYTES + per * states + table,
        kept=KEPT_BYTES_PER_STATE[role] * states,
        seconds=seconds,
        tau=res.tau,
    )


def estimate_size(spec: GameSpec, cpl: float, steps: float, headings: int) -> SolveSize:
    """The size of :func:`~strategies.referee.estimates.solve_estimate` at one resolution."""
    from strategies.referee.estimates import _resolution, heading_moves

    res = _resolution(spec, cpl, steps)
    h = res.cell
    vp = heading_moves(spec.v_pursuer * res.tau, h, headings)
    ve = heading_moves(spec.v_evader * res.tau, h, headings)
    reach = h * (max(math.hypot(*v) for v in vp) + max(math.hypot(*v) for v in ve))
    points = _points(spec, h)
    W = _window(spec.l_max + reach, h)
    moves = len(vp) + len(ve)
    states = points * W * W
    per = ESTIMATE_BYTES_PER_STATE + ESTIMATE_BYTES_PER_STATE_MOVE * moves
    if spec.map.vertex_convex.any():
        per += ESTIMATE_OCCLUSION_BYTES_PER_STATE
    return SolveSize(
        what=f"estimate at {cpl:g} cells per L_min",
        kind="estimate",
        points=points,
        window=W,
        moves=moves,
        bytes=BASE_BYTES + per * states,
        kept=KEPT_BYTES_PER_STATE["estimate"] * states,
        seconds=SECONDS_PER_STATE["estimate"] * states,
    )


def peak(sizes: Sequence[SolveSize]) -> tuple[float, SolveSize]:
    """The peak memory of ``sizes`` solved in order, each result kept, and the solve at
    which it is reached."""
    kept, best, at = 0.0, -1.0, sizes[0]
    for s in sizes:
        if kept + s.bytes > best:
            best, at = kept + s.bytes, s
        kept += s.kept
    return best, at


def check_budget(
    call: str,
    sizes: Sequence[SolveSize],
    budget: object = None,
    *,
    resize: Callable[[float], Sequence[SolveSize]] | None = None,
    cells_per_lmin: float | None = None,
    knob: str = "cells_per_lmin",
) -> float:
    """The budget in bytes, after checking that ``sizes`` fit in it.

    Args:
        call: what is being solved, for the message (``"solve(map 'x', ...)"``).
        sizes: the solves, in the order they run.
        budget: ``memory_budget`` as given (None: ``$SURVEIL_MEMORY_BUDGET`` or half the
            physical memory).
        resize: the solves at another number of cells per L_min, to name one that fits.
        cells_per_lmin: the resolution asked for (with ``resize``).
        knob: the argument that sets it, for the message.

    Raises:
        MemoryBudgetError: the estimated peak exceeds the budget; the message names the
            estimate (memory, states, time) and the knobs that change it (``knob`` and
            ``memory_budget=``: a caller that sets them otherwise renames them,
            :meth:`~envs.errors.MemoryBudgetError.named`).
        InvalidConfigError: the budget is not a positive size.
    """
    limit = memory_budget(budget)
    need, at = peak(sizes)
    if need <= limit:
        return limit
    total_seconds = sum(s.seconds for s in sizes)
    ram = physical_memory()
    advice = []
    if need > ram:  # "SURVEIL_MEMORY_BUDGET=3712723138027099136GB": no budget can give it
        # said first and as a fact about the solve asked for: "Use --cells-per-lmin <= 57.6;
        # no budget on this machine fits" read as if 57.6 did not fit either (helper-143)
        asked = (f"{MemoryBudgetError.KNOB} = {cells_per_lmin:g}"
                 if cells_per_lmin is not None else "this solve")  # fmt: skip
        advice.append(f"{asked} fits no budget on this machine: it has {byte_size(ram)} of memory")
    if resize is not None and cells_per_lmin is not None:
        lo, hi = 0.0, float(cells_per_lmin)
        # the largest resolution that fits, to 1e-9 of it, or none >= 0.1 (named as 0 below):
        # 30 halvings of [0, asked] stopped at asked / 1e9, so from 1e12 asked every one
        # tried was over and the message said none fits ("even --cells-per-lmin = 0.1 needs
        # about 125 MB", with 12.6 GB)
        while hi >= 0.1 and hi - lo > 1e-9 * hi:
            mid = 0.5 * (lo + hi)
            if mid <= 0 or peak(resize(mid))[0] <= limit:
                lo = mid
            else:
                hi = mid
        fit = math.floor(lo * 10) / 10
        K = MemoryBudgetError.KNOB
        if fit > 0:
            advice.append(f"Use {K} <= {fit:g} (asked: {cells_per_lmin:g}), which fits the "
                          f"budget of {byte_size(limit)}")  # fmt: skip
        elif BASE_BYTES >= limit:  # the interpreter alone is over the budget
            advice.append(f"No {K} fits (the interpreter alone takes {byte_size(BASE_BYTES)})")
        else:  # a huge map: it said "the interpreter alone" there too
            coarsest = peak(resize(0.1))[0]
            advice.append(f"No {K} fits (even {K} = 0.1 needs about {byte_size(coarsest)})")
    more = math.ceil(1.2 * need / 1e9)
    if need <= ram:
        advice.append(f"{'raise' if advice else 'Raise'} the budget with "
                      f"{MemoryBudgetError.BUDGET}")  # fmt: skip
    advice.append("or solve a smaller map or a smaller L_max / L_min")
    default = ""  # where the budget came from, when nobody set it
    if budget is None and not os.environ.get("SURVEIL_MEMORY_BUDGET"):
        default = ", half of the machine's memory (the default)"
    first, *rest = advice
    if need > ram:  # a sentence of its own; the choices follow
        then = "; ".join(rest[:-1]) + (", " if rest[:-1] else "") + rest[-1]
        text = first + ". " + then[0].upper() + then[1:]
    else:
        text = "; ".join(advice[:-1]) + ", " + advice[-1]
    raise MemoryBudgetError(
        f"{call}: the solve would need about {byte_size(need)} at its peak, during the "
        f"{at.what} ({'; '.join(s.describe() for s in sizes)}; up to about "
        f"{duration(total_seconds)} in all), more than the memory budget of "
        f"{byte_size(limit)}{default}. " + text[0].upper() + text[1:],
        knob,
        size=f"{more}GB",
    )


def duration(seconds: float) -> str:
    """``seconds`` for a message: ``"40 s"``, ``"12 min"``, ``"2.3 h"``."""
    if seconds < 90:
        return f"{seconds:.0f} s"
    if seconds < 5400:
        return f"{seconds / 60:.0f} min"
    return f"{seconds / 3600:.3g} h"  # 1.08e+14 h, not 107916000064749.6 h


_duration = duration  # the name the hindsight module imports
