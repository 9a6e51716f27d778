"""The pursuer bound: starts from which the pursuer provably holds surveillance forever.

The discretisation favours the evader everywhere, so a win here is a win in the real
game (continuous time, any evader, and the env at any step that divides ``tau``):

* **Information.** The pursuer commits to a straight move for a whole step of ``tau``;
  the evader sees it and moves as it likes *during* the step (any path of speed <= V_e,
  re-planned continuously).
* **Pursuer.** It sits exactly on the certified lattice and moves along lattice vectors
  of length <= V_p tau whose paths keep ``body_radius`` from the walls: a restriction of
  the real pursuer (finite headings, including standing still), which only costs it.
* **Evader.** Located by its cell only (anywhere in it). Over a step it can be anywhere in
  the disc of radius ``delta + V_e tau t`` about its cell's centre (delta the cell's
  half-diagonal, plus :data:`~strategies.referee.spec.MARGIN_REL`), and it may end in any
  open cell within V_e tau of its cell: a superset of what it can do.
* **Losing set, checked continuously over the step.** The range test holds for every
  pursuer-evader pair the discs allow, at every instant (closed form). Occlusion: the rod
  is clear at the step's start (surveillance held so far); while neither end touches a
  wall, it can become blocked only by sweeping a convex obstacle vertex, and every rod of
  the step lies in the hull of the pursuer's path and the evader's disc
  (:func:`~strategies.referee.robust.sweep_hits_vertex`, ``sweep_pieces`` pieces per
  step). So no convex vertex in those hulls means no occlusion. The evader end keeps its
  ``opponent_clearance`` c' from the walls: beside a jamb (an obstacle angle of 90 degrees
  or more) the part of its disc within c' of the wall edge there is left out of the
  grazing test, so a pursuer looking past the jamb along the wall sees an evader that hugs
  that wall, as a real one does. Without it, two rooms joined by a corridor 2 or 2.5 wide
  and 6 long (L in [1, 2], rho = 0.3, 16 cells per L_min, the default lattice) certified
  no state, the evader always hiding round a mouth's jamb from the pursuer behind it; with
  it, 98.9 and 99.3 % (a corridor 1 wide, the office and random:polygons:4505 at L in
  [2, 3], rho = 0.2, still none: the real pursuer's window there is narrower than a cell).

The pursuer's winning set is the greatest fixed point ``W = {x : exists a safe move whose
every evader successor is in W}``, computed by iterating from the safe states, with a
worklist of the windows that changed.

**When it certifies nothing (issue 13).** Favouring the evader costs the pursuer twice per
step: the evader foresees the whole committed step of length V_p tau, and its position is
forgotten down to its cell, so it gains ``g = V_e tau`` plus up to ``h sqrt(2)`` of centre
displacement every step. Two regimes follow (:func:`vacuity` names them, and
:func:`~strategies.referee.referee.solve` raises a
:class:`~envs.errors.VacuousBoundWarning`):

* **The range band is used up** (a priori, a necessary condition checked exactly on the
  window, :func:`range_band`): after a step the evader's successor cells must all be in
  range of the pursuer's new point, which leaves a band of distances of width about
  ``(l_max - l_min) - 2 g - 3 sqrt(2) h`` (an estimate: it counts every successor
  centre as ``g + h sqrt(2)`` away). When no window offset passes both the end-of-step
  range test and the successors' range test, no start with the evader in open space can
  be certified (L in [2, 4], rho = 0.5, 8 cells per L_min, the default lattice: tau =
  1.5 s, estimate -0.56).
* **Measured to certify nothing** (empirical): then the evader herds the pursuer into a
  wall in the abstraction, from the walls inward, although a real pursuer keeps its range
  against a charging evader there by circling at ``L_min / sqrt(1 - rho^2)`` (whether it
  wins against every evader is what the referee cannot say). On the empty 10 m room with
  L in [2, 4] (fraction of (point, cell) states certified):

  ============  ===================================  ===========================
  rho           cells per L_min, coarse, tau          certified
  ============  ===================================  ===========================
  0.2 / 0.25    16, 4, 1.5 s (the default lattice)    99.1 / 98.6 %
  0.265 - 0.4   16, 4, 1.5 s                          0 %
  0.3 / 0.33    24, 6, 1.5 s (the default lattice)    0 %
  0.15 - 0.3    16, 2, 0.8 s                          98.2 - 99.8 %
  0.35          16, 2, 0.8 s; 16, 2, 0.5 s; 16, 1,    0 %
                0.5 s; 24, 2, 0.5 s (0.4: 16, 2, 0.5 s)
  0.5           12 lattices, tau 0.4 to 1.5 s         0 % (the open plane: 100 %
                                                      at some of them)
  ============  ===================================  ===========================

  So from ``rho >=`` :data:`VACUOUS_RHO` the bound is vacuous at every resolution
  tried; below it, it can be vacuous at some lattices (solve() also warns when the solved
  bound certifies no state at all). Its 0 % then means "unknown", not "the evader wins":
  only the evader bound certifies evader wins.

* **Narrow passages, far below** :data:`VACUOUS_RHO` (measured). Re-localised in its cell,
  the bound's evader may end every step in a neighbouring cell's far side: it covers
  ``(V_e tau + sqrt(2) h) / (V_p tau)`` of the pursuer's step (0.22 at rho = 0.1 at the
  default lattice, 0.13 at rho = 0.01), so the bound's pursuer cannot pass it where the
  real one passes it with little to spare. The evader then herds it into a dead end and
  the erosion spreads to every state. A real pursuer circling the evader at L_min passes
  it in a hall of width w (body radius r) whenever ``rho (pi / 2) L_min / (sqrt(1 -
  rho^2) - rho) <= (w - 2 r) / 2 - L_min`` (the evader gains at most that much across the
  hall during the quarter turn that brings the pursuer abreast): in the corner world's 5
  wide arms (L_min = 2, r = 0.1) up to rho = 0.112, at rho = 0.1 with 5 cm to spare. On
  the corner world at rho = 0.1 and 8 cells per L_min the first states lost are the
  pursuer's in a room corner, e.g. pursuer at (0.5, 0.5), evader's cell (2.75, 1.0): its
  only safe move is 1.5 up the wall, after which the evader's diagonal neighbour cell
  (2.5, 1.25), 0.35 from its cell although the evader moved 0.15, lies 2.14 from the
  pursuer, so its disc comes within L_min (a real pursuer sliding up the wall keeps its
  range). At 16 cells per L_min the losses run up each arm from its end, the evader's
  cells within about 0.75 of the arm's centre line beating every pursuer point between
  them and the dead end (sweeps 7-37); then the junction square falls and with it every
  state (82 sweeps). Which lattice certifies depends on where its rows fall against the
  walls and on its step (fraction of the states, :meth:`PursuerBound.fraction`, at 16
  cells per L_min unless said; L in [2, 4]):

  ========================  ============  ============================  ==============
  map                       rho           pursuer lattice: coarse, tau  certified
  ========================  ============  ============================  ==============
  corner (arms 5 wide)      0.01 - 0.05   4, 1.5 s (the default)        93.0 - 92.7 %
  corner                    0.1           4, 1.5 s (the default);       0 %
                                          5, 1.875 s; at 8 and 12
                                          cells per L_min coarse 1,
                                          2, 3, 4, 6 x 2 or 3
                                          spacings a step
  corner                    0.1           3, 1.125 s / 6, 2.25 s        93.2 / 91.8 %
  corner                    0.2           3, 4, 5, 6 (3 spacings)       0 %
  hall 14 x 5 (dead ends)   0.01 - 0.1    4, 1.5 s (the default)        0 %
  hall 14 x 6               0.01 / 0.05   4, 1.5 s (the default)        99.8 / 99.8 %
  hall 14 x 6 / 14 x 7      0.1           4, 1.5 s (the default)        0 / 99.7 %
  l_hall (2 m pillar 3      0.01 / 0.05   4, 1.5 s (the default)        97.2 / 96.9 %
  from two walls)
  l_hall                    0.1           4 (the default), 5, 6         0 %
  l_hall                    0.1           3, 1.125 s                    96.1 %
  l_hall                    0.2           3, 4, 5, 6 (3 spacings)       0 %
  20 m room, 2 m pillar     0.1           4, 1.5 s (the default)        0 % (3.5 from
  3 from a wall                                                         it: 98.2 %)
  maze, office, pillars,    0.1 / 0.2 /   4 (the default), 2, 3; at 8   0 %
  two_rooms (passages 1-3)  0.3           cells per L_min 2 (the
                                          default), 3
  pillars, the room grown   0.1           4, 1.5 s (the default)        92.5 % (by 1: 0 %)
  by 2 on every side
  maze scaled x3, L kept    0.1           8 cells per L_min, 2, 1.5 s   92.0 % (x2: 0 %)
  corridor / open_room      0.1           4, 1.5 s (the default)        97.4 / 99.7 %
  ========================  ============  ============================  ==============

  The four maps at the foot of the table are not one case (helper-107):

  * **two_rooms: the game's answer.** Its corridor (6 long, 1 wide, below L_min) lets the
    evader stand 3 deep; a pursuer within L_max = 4 must then follow it in, behind it, and
    the evader rounds a mouth corner within its body radius 0.1 of the vertex, where the
    pursuer would need ``V_e (L - l) / l`` = 1.9 V_p at rho = 0.1, L = 2 (it holds the
    contact only if ``l >= rho L / (1 + rho)``, 0.18; THEORY.md 3 and 5.4). The shooting
    evader escapes every two_rooms and office episode of the benchmarks (rho 0.3 - 0.95).
  * **office** (doors 2 wide in walls 0.3 thick): at rho = 0.3 consistent with the game
    (those episodes); at rho = 0.1 undecided.
  * **pillars: the blind spot.** Its pillars stand 2.5 - 3 from the walls (one pillar 3
    from a wall certifies nothing, 3.5 from it 98 %); grown by 2 on every side, the same
    pillars certify 92.5 %. The first states lost are the evader's cells near a pillar's
    vertex, e.g. pursuer (2.5, 6), evader's cell (2.5, 9.5), 0.5 below the diamond's left
    vertex: every move's successor cell (2.5, 9.75) holds the vertex in its disc (0.25
    from its centre, radius 0.18 + 0.15), and the wedge behind the vertex, from which no
    rod grazes it, is 2.8 away (two steps). The real evader needs three steps to reach
    the vertex. A pursuer strategy that holds at rho = 0.5 holds at 0.1 (the slower
    evader is one of the faster one's options): the decomposition pursuer holds 63 of
    bench (1)'s 64 pillars episodes at rho = 0.5.
  * **maze** (corridors 2.5 wide): narrower than ``2 L_min + 2 r``, so no pursuer, real
    or the bound's, passes the evader there; scaled x3 with L kept it certifies 92 %, and
    the decomposition pursuer holds 60 of bench (1)'s 64 maze episodes at rho = 0.5. Likely
    the blind spot; not proven.

  So 0 % on such a map at low rho is this abstraction's blind spot or the game's answer,
  never a finding by itself. :func:`~strategies.referee.referee.solve` falls back to
  ``pursuer_coarse`` one less when the default lattice certifies no state at ``rho <``
  :data:`VACUOUS_RHO` (``pursuer_fallback``, on by default; the bound it keeps names the
  default in ``fallback_from``). Measured (16 cells per L_min, dt = 0.1 as the policies
  and ``surveil referee`` solve, the pursuer bound's seconds on a shared machine):

  ===================  =====  ==================  =====================  ===========
  map                  rho    default: 4, 1.5 s   fallback: 3, 1.2 s     its solve /
                              (solve)             (solve)                the default's
  ===================  =====  ==================  =====================  ===========
  corner               0.1    0 % (5.2 s)         93.5 % (6.6 s), kept   1.26
  l_hall               0.1    0 % (10.4 s)        96.2 % (7.0 s), kept   0.67
  open_room            0.3    0 % (2.4 s)         98.1 % (1.5 s), kept   0.60
  corridor             0.3    0 % (3.3 s)         92.2 % (3.6 s), kept   1.10
  open_room, corridor  0.1    99.7, 97.4 %        not solved             0
  corner / l_hall      0.3    0 % (3.1 / 7.7 s)   0 % (6.6 / 17.5 s)     2.13 / 2.28
  two_rooms            0.1 /  0 % (6.9 / 5.6 s)   0 % (23.4 / 13.0 s)    3.40 / 2.30
                       0.3
  pillars              0.1 /  0 % (16.5 / 9.8)    0 % (46.9 / 20.4)      2.85 / 2.08
                       0.3
  maze                 0.1 /  0 % (22.3 / 20.1)   0 % (45.0 / 30.6)      2.02 / 1.53
                       0.3
  office               0.1 /  0 % (29.2 / 26.7)   0 % (60.9 / 46.2)      2.09 / 1.73
                       0.3
  every map            0.5    any (rho >= 0.35)   not solved             0
  ===================  =====  ==================  =====================  ===========

  So where it certifies it costs about the default's solve; where it does not, 1.5 - 3.4
  times it, once (both are cached). At 24 cells per L_min (:func:`solve`'s own default)
  it does not help the corner at rho = 0.1: coarse 6 (the default), 5 and 4 all certify
  0 %. From a default of 2 cells (8 cells per L_min) it is not tried: coarse 1 has four
  times the points, and its solve took 4 - 12 times the default's on the corner, l_hall,
  corridor and two_rooms (rho 0.1 / 0.3) for nothing; it certified only the open room at
  rho = 0.3 (98 %).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from envs.geometry import kernel_for
from strategies.referee._bound import SolvedBound
from strategies.referee._budget import bound_size, check_budget
from strategies.referee._fixpoint import Worklist, erode, reach_rectangles, shifted
from strategies.referee.lattice import Lattice, segment_wall_distance
from strategies.referee.robust import convex_corners, sweep_hits_vertex, sweep_range_ok
from strategies.referee.spec import GameSpec, Resolution

__all__ = ["VACUOUS_RHO", "PursuerBound", "range_band", "solve_pursuer_bound", "vacuity"]

VACUOUS_RHO = 0.35
"""From this rho on, the pursuer bound certified nothing in an empty room the pursuer wins,
at every resolution tried (the module docstring's table)."""


@dataclass
class PursuerBound(SolvedBound):
    """The solved pursuer bound.

    Attributes:
        spec: the game.
        res: the resolution.
        lattice: cells and the pursuer's lattice.
        vectors: (n_moves, 2) pursuer moves in cells (row 0 is standing still).
        targets: (n_points, n_moves) point reached by each move, -1 if not allowed.
        win: (n_points, W, W) states (pursuer point, evader cell) from which the pursuer
            provably holds.
        choice: (n_points, W, W) int16, a winning move of each winning state (-1 elsewhere).
        iterations: fixed-point sweeps until nothing changed.
        seconds: wall time of the build and of the fixed point.
        fallback_from: the resolution of the default lattice when it certified no state and
            :func:`~strategies.referee.referee.solve` fell back to this bound's finer one
            (``pursuer_fallback``); None when this is the lattice asked for. Not cached.
    """

    role: ClassVar[str] = "pursuer"
    tables: ClassVar[dict[str, Any]] = {"win": bool, "choice": np.int16}

    win: np.ndarray
    choice: np.ndarray
    iterations: int
    seconds: dict[str, float]
    fallback_from: Resolution | None = None

    # ------------------------------------------------------------------ queries
    @property
    def reach(self) -> float:
        """How far the evader may get in one step, plus the margin: V_e tau + margin."""
        return self.spec.v_evader * self.res.tau + self.spec.margin

    def state(self, pursuer: np.ndarray, evader: np.ndarray) -> tuple[int, int, int] | None:
        """The state ``(k, a, b)`` of a pursuer on the lattice and an evader anywhere, or
        None if the pursuer is not on a lattice point or the evader is out of the window."""
        lat = self.lattice
        p = np.asarray(pursuer, dtype=float)
        ij = np.rint((p - lat.anchor) / lat.h).astype(np.int64)
        if np.hypot(*(lat.anchor + lat.h * ij - p)) > self.spec.margin:
            return None
        k = int(lat.point_index(ij[None])[0])
        if k < 0:
            return None
        a, b = lat.window_cell(np.array([k]), lat.cell_of(np.asarray(evader, dtype=float)))[0]
        if not (0 <= a < lat.W and 0 <= b < lat.W):
            return None
        return k, int(a), int(b)

    def plan(self, pursuer, evader) -> np.ndarray | None:
        """A certified next lattice point for the pursuer from the real positions, or None.

        Checks the step from the *real* pursuer and evader positions (the evader's disc
        is centred on its real position, not its cell): a straight move to a lattice point
        at most V_p tau away whose path keeps the body radius, safe over the whole step,
        and whose every evader successor cell (within V_e tau of the real evader) is a
        winning state. Among the certified moves, the shortest is returned (standing still
        when it is certified).

        Args:
            pursuer: real (x, y) of the pursuer.
            evader: real (x, y) of the evader.

        Returns:
            The target point (2,), or None when no certified move exists.
        """
        spec, lat = self.spec, self.lattice
        p = np.asarray(pursuer, dtype=float)
        e = np.asarray(evader, dtype=float)
        step = spec.v_pursuer * self.res.tau
        cand = lat.points_within(p, step)
        if len(cand) == 0:
            return None
        B = lat.points[cand]
        clear = segment_wall_distance(np.broadcast_to(p, B.shape), B, spec.map)
        cand = cand[clear >= spec.body_radius * (1.0 - 1e-9) - spec.margin]
        if len(cand) == 0:
            return None
        g = spec.v_evader * self.res.tau
        m = spec.margin
        rel = e - p  # the evader relative to the pursuer's start
        d = lat.points[cand] - p
        ok = sweep_range_ok(rel[0], rel[1], d[:, 0], d[:, 1], m, g, spec.l_min, spec.l_max)
        ok &= ~_sweep_hits_any(spec, p, d, e, m, g, self.res.sweep_pieces)
        # successors: every open cell within V_e tau (+ margin) of the real evader
        cells = lat.open_cells_within(e, g + m)
        for i in np.flatnonzero(ok):
            k = int(cand[i])
            ab = lat.window_cell(np.array([k]), cells)
            inside = (ab[:, 0] >= 0) & (ab[:, 0] < lat.W) & (ab[:, 1] >= 0) & (ab[:, 1] < lat.W)
            if not inside.all():
                continue
            if self.win[k, ab[:, 0], ab[:, 1]].all():
                return lat.points[k].copy()
        return None

    def certifies(self, pursuer, evader) -> bool:
        """Whether the pursuer provably holds from this real start: surveillance holds at
        the start (range and line of sight) and :meth:`plan` finds a certified move."""
        spec = self.spec
        p = np.asarray(pursuer, dtype=float)
        e = np.asarray(evader, dtype=float)
        L = float(np.hypot(*(p - e)))
        if not (spec.l_min <= L <= spec.l_max):
            return False
        if not kernel_for(spec.map).line_of_sight(p, e):
            return False
        return self.plan(p, e) is not None

    def vacuity(self) -> str | None:
        """Why this bound's pursuer wins say nothing (:func:`vacuity`, or it won no state
        at all), None when it is informative."""
        reason = vacuity(self.spec, self.res)
        if reason is None and not self.win.any():
            spec, res = self.spec, self.res
            ratio = (spec.v_evader * res.tau + math.sqrt(2.0) * res.cell) / (
                spec.v_pursuer * res.tau
            )
            reason = (
                f"pursuer bound at rho = {spec.rho:.3g} (cell h = {res.cell:.4g}, step tau = "
                f"{res.tau:.4g} s) certified no state (the evader foresees each committed "
                f"step and is re-localised in its cell, covering {ratio:.2f} of the pursuer's "
                f"step per step; such bounds certified nothing even in an empty room they "
                f"certify at a lower rho or another lattice, see "
                f"strategies.referee.pursuer_bound); its 0 % pursuer wins mean 'unknown', "
                f"not 'evader wins'"
            )
        return reason

    def fraction(self) -> float:
        """Fraction of the states (pursuer point, open evader cell in range) that win."""
        dom = self._domain()
        return float(self.win[dom].mean()) if dom.any() else 0.0

    def _domain(self) -> np.ndarray:
        lat = self.lattice
        open_w = lat.windows(lat.cell_open, False)
        return open_w & _range0(lat, self.spec)[None]


def _range0(lat: Lattice, spec: GameSpec) -> np.ndarray:
    """(W, W): window cells whose whole disc is in range of the window's centre."""
    R0 = lat.delta + spec.margin
    dist = np.hypot(lat.offsets[..., 0], lat.offsets[..., 1])
    return (dist - R0 >= spec.l_min) & (dist + R0 <= spec.l_max)


def range_band(spec: GameSpec, res: Resolution) -> tuple[float, bool]:
    """The range band a step of the pursuer bound leaves, approximate and exact.

    Returns:
        ``(width, open)``: ``width = (l_max - l_min) - 2 g - 3 sqrt(2) h`` (g = V_e tau),
        an estimate of the band of pursuer-evader distances from which every evader
        successor cell is still in range (counting every successor centre as ``g + h
        sqrt(2)`` away, so it is pessimistic by up to about ``2 h``); and whether
        some window offset passes both tests the solver makes (the end-of-step range test
        of :func:`~strategies.referee.robust.sweep_range_ok` and every successor cell of
        the evader's one-step stencil in range). When ``open`` is False, no state whose
        evader successors are all open cells can be won.

    Examples:
        The default lattice of the 10 m room at L in [2, 4] and 8 cells per L_min
        (coarse 2, three spacings per step, tau = 1.5 s): open at rho = 0.2, used up at
        rho = 0.5. At 16 cells per L_min (coarse 4, tau = 1.5 s) the estimate is -0.03
        at rho = 0.5 but the exact test finds offsets: the band is open (and the bound
        still certifies nothing there, the second regime).

        >>> from envs.maps import Map
        >>> room = Map([(0, 0), (10, 0), (10, 10), (0, 10)])
        >>> for rho, cell, coarse in ((0.2, 0.25, 2), (0.5, 0.25, 2), (0.5, 0.125, 4)):
        ...     spec = GameSpec(room, 2.0, 4.0, 1.0, rho, body_radius=0.2)
        ...     w, ok = range_band(spec, Resolution(cell=cell, coarse=coarse, tau=1.5))
        ...     print(f"{w:+.2f} {ok}")
        +0.34 True
        -0.56 False
        -0.03 True
    """
    h, delta, m = res.cell, res.cell_radius, spec.margin
    g = spec.v_evader * res.tau
    width = (spec.l_max - spec.l_min) - 2.0 * g - 3.0 * math.sqrt(2.0) * h
    hw = math.ceil((spec.l_max + delta) / h) + 1  # the pursuer lattice's window
    w = np.arange(-hw, hw + 1) * h
    dist = np.hypot(*np.meshgrid(w, w, indexing="ij"))
    R0 = delta + m
    in_range = (dist - R0 >= spec.l_min) & (dist + R0 <= spec.l_max)
    successors = erode(in_range[None], reach_rectangles(g + m, h), border=False)[0]
    end = (dist - R0 - g >= spec.l_min) & (dist + R0 + g <= spec.l_max)
    return width, bool((successors & end).any())


def vacuity(spec: GameSpec, res: Resolution) -> str | None:
    """Why the pursuer bound of ``spec`` at ``res`` cannot certify a start, or was measured
    not to (see the module docstring), with the numbers; None when neither applies. Known
    before solving: :meth:`PursuerBound.vacuity` adds the solved bound's own emptiness."""
    h, tau, rho = res.cell, res.tau, spec.rho
    g = spec.v_evader * tau
    ratio = (g + math.sqrt(2.0) * h) / (spec.v_pursuer * tau)
    where = (
        f"pursuer bound at rho = {rho:.3g} (cell h = {h:.4g}, step tau = {tau:.4g} s, the "
        f"evader's step g = V_e tau = {g:.4g})"
    )
    unknown = (
        "its 0 % pursuer wins mean 'unknown', not 'evader wins' (only the evader bound "
        "certifies those)"
    )
    width, band_open = range_band(spec, res)
    if not band_open:
        return (
            f"{where}: the range band is used up ((l_max - l_min) - 2 g - 3 sqrt(2) h = "
            f"{width:+.3g}; no offset keeps every evader successor cell in [{spec.l_min:g}, "
            f"{spec.l_max:g}] after a step), so it certifies no start with the evader in open "
            f"space; {unknown}. A shorter step (pursuer_steps, pursuer_coarse) reopens it"
        )
    if rho >= VACUOUS_RHO:
        return (
            f"{where}: rho >= {VACUOUS_RHO:g}, where it was measured to certify nothing at "
            f"every resolution tried, even in the empty 10 m room (L in [2, 4]) it "
            f"certifies at rho = 0.2 (the evader foresees each committed step and is "
            f"re-localised in its cell: it covers {ratio:.2f} of the pursuer's step per "
            f"step); {unknown}"
        )
    return None


def _sweep_hits_any(spec, p, d, c, R0, g, pieces) -> np.ndarray:
    """For moves d (n, 2) of a pursuer at p and an evader disc D(c, R0 + g t): whether
    some convex vertex may be grazed during the step."""
    verts, din, dout = convex_corners(spec.map)
    lens = _corner_edge_lengths(spec.map)
    clear = spec.opponent_clearance - spec.margin
    hit = np.zeros(len(d), dtype=bool)
    rel = c - p
    for v, di, do, ln in zip(verts - p, din, dout, lens, strict=True):
        for q in range(pieces):
            t0, t1 = q / pieces, (q + 1) / pieces
            hit |= _hits_vertex(
                (t0 * d[:, 0], t0 * d[:, 1], t1 * d[:, 0], t1 * d[:, 1], v[0], v[1]),
                (rel[0], rel[1], R0 + g * t1),
                di,
                do,
                spec.margin,
                clear,
                ln,
            )
    return hit


def _hits_vertex(path, disc, din, dout, eta, clear, lengths) -> np.ndarray:
    """:func:`~strategies.referee.robust.sweep_hits_vertex` with the evader's clearance,
    evaluated only where the plain test hits (both are sound, so where both hit; the cut
    costs several times the plain test, and most rods never come near a vertex).

    Args:
        path: ``(ax, ay, bx, by, vx, vy)``, the pursuer's piece of path and the vertex.
        disc: ``(cx, cy, R)``, the evader's disc over that piece.
        din, dout, eta, clear, lengths: as ``sweep_hits_vertex``.
    """
    plain = sweep_hits_vertex(*path, *disc, din, dout, eta)
    idx = np.flatnonzero(plain)
    if len(idx) == 0 or clear <= 0.0:
        return plain
    sub = [
        np.broadcast_to(np.asarray(x, dtype=float), plain.shape).ravel()[idx]
        for x in (*path, *disc)
    ]
    out = plain.copy()
    out.ravel()[idx] = sweep_hits_vertex(*sub, din, dout, eta, clear=clear, lengths=lengths)
    return out


def _corner_edge_lengths(world) -> np.ndarray:
    """(n, 2): the lengths of the wall edges arriving at and leaving each convex vertex
    of :func:`~strategies.referee.robust.convex_corners`, in its order."""
    idx = world.convex_vertices
    lengths = world.edge_length
    arriving = lengths[world.vertex_prev_edge[idx]]
    leaving = lengths[world.vertex_next_edge[idx]]
    return np.stack([arriving, leaving], axis=1).reshape(-1, 2)


# ---------------------------------------------------------------------- the solver
def _safe_tables(lat: Lattice, spec: GameSpec, res: Resolution, vectors, targets, domain):
    """Packed (n_moves, n_points, W, packed W) tables: move j is safe from state (k, a, b)."""
    n, W = lat.n_points, lat.W
    h = lat.h
    R0 = lat.delta + spec.margin
    g = spec.v_evader * res.tau
    ox, oy = lat.offsets[..., 0], lat.offsets[..., 1]
    verts, din, dout = convex_corners(spec.map)
    lens = _corner_edge_lengths(spec.map)
    clear = spec.opponent_clearance - spec.margin
    dmax = float(np.max(np.hypot(*vectors.T))) * h if len(vectors) else 0.0
    # candidates per convex vertex: states whose every possible rod hull comes near it
    cand = []
    rad = max(dmax, R0 + g)
    for v, di, do, ln in zip(verts, din, dout, lens, strict=True):
        rel = v[None, :] - lat.points  # (n, 2): the vertex seen from each pursuer point
        reach = np.hypot(*rel.T) <= spec.l_max + R0 + g + dmax
        ks = np.flatnonzero(reach)
        for s in range(0, len(ks), 256):
            kk = ks[s : s + 256]
            vx = rel[kk, 0][:, None, None]
            vy = rel[kk, 1][:, None, None]
            # distance from v to the segment [0, o] (the pursuer-to-cell-centre rod)
            L2 = ox * ox + oy * oy
            with np.errstate(divide="ignore", invalid="ignore"):
                t = np.clip((vx * ox + vy * oy) / L2, 0.0, 1.0)
            near = np.hypot(vx - t * ox, vy - t * oy) <= rad
            near &= domain[kk]
            k_i, a_i, b_i = np.nonzero(near)
            cand.append((v, di, do, ln, kk[k_i], a_i, b_i))
    tables = []
    for j, vec in enumerate(vectors):
        d = vec.astype(float) * h
        ok = domain & (targets[:, j] >= 0)[:, None, None]
        ok &= sweep_range_ok(ox, oy, d[0], d[1], R0, g, spec.l_min, spec.l_max)[None]
        for v, di, do, ln, kk, aa, bb in cand:
            if len(kk) == 0:
                continue
            rx = v[0] - lat.points[kk, 0]
            ry = v[1] - lat.points[kk, 1]
            cx = ox[aa, bb]
            cy = oy[aa, bb]
            hit = np.zeros(len(kk), dtype=bool)
            for q in range(res.sweep_pieces):
                t0, t1 = q / res.sweep_pieces, (q + 1) / res.sweep_pieces
                hit |= _hits_vertex(
                    (t0 * d[0], t0 * d[1], t1 * d[0], t1 * d[1], rx, ry),
                    (cx, cy, R0 + g * t1),
                    di,
                    do,
                    spec.margin,
                    clear,
                    ln,
                )
            ok[kk[hit], aa[hit], bb[hit]] = False
        tables.append(np.packbits(ok, axis=-1))
    return np.stack(tables) if tables else np.zeros((0, n, W, (W + 7) // 8), np.uint8)


def _unpack(table: np.ndarray, W: int) -> np.ndarray:
    return np.unpackbits(table, axis=-1, count=W).view(bool)


def solve_pursuer_bound(
    spec: GameSpec, res: Resolution, *, progress: bool = False, memory_budget: object = None
) -> PursuerBound:
    """Solve the evader-favoured discrete game (see the module docstring).

    Args:
        spec: the game.
        res: the resolution.
        progress: print one line per fixed-point sweep.
        memory_budget: bytes (or ``"2GB"``) the solve may take; default
            ``$SURVEIL_MEMORY_BUDGET`` or half the RAM (:mod:`strategies.referee._budget`).

    Returns:
        The :class:`PursuerBound`.

    Raises:
        InfeasibleError: the solve's estimated memory exceeds the budget (checked before
            anything is allocated; the message names the estimate and the knobs).
    """
    check_budget(
        f"solve_pursuer_bound(map {spec.map.name!r}, cell = {res.cell:g})",
        [bound_size(spec, res, "pursuer")],
        memory_budget,
    )
    t0 = time.perf_counter()
    lat = Lattice(spec, res, "pursuer")
    vectors, targets = lat.moves(spec.v_pursuer * res.tau)
    open_w = lat.windows(lat.cell_open, False)
    domain = open_w & _range0(lat, spec)[None]
    safe = _safe_tables(lat, spec, res, vectors, targets, domain)
    t1 = time.perf_counter()
    W = lat.W
    n_moves = len(vectors)
    rects = reach_rectangles(spec.v_evader * res.tau + spec.margin, lat.h)
    # X: the current over-approximation of the winning set (decreases to the fixed point)
    X = np.zeros_like(domain)
    for j in range(n_moves):
        X |= _unpack(safe[j], W)
    closed = ~open_w  # cells the evader cannot occupy never constrain the pursuer
    A = erode(X | closed, rects, border=False)
    work = Worklist(targets)
    iterations = 0
    while True:
        iterations += 1
        ks = work.todo()
        new = _best_moves(ks, X, A, safe, vectors, targets, W)[0]
        changed = (new != X[ks]).any(axis=(1, 2))
        if progress:
            print(f"pursuer bound: sweep {iterations}, {int(changed.sum())} windows changed")
        if not changed.any():
            break
        X[ks] = new
        d = ks[changed]
        work.changed(d)
        A[d] = erode(X[d] | closed[d], rects, border=False)
    all_k = np.arange(lat.n_points)
    _, choice = _best_moves(all_k, X, A, safe, vectors, targets, W, want_choice=True)
    t2 = time.perf_counter()
    return PursuerBound(
        spec=spec,
        res=res,
        lattice=lat,
        vectors=vectors,
        targets=targets,
        win=X,
        choice=choice,
        iterations=iterations,
        seconds={"build": t1 - t0, "solve": t2 - t1},
    )


def _best_moves(ks, X, A, safe, vectors, targets, W, want_choice=False, chunk: int = 256):
    """For points ``ks``: which states of X have a safe move into A (the states all of
    whose evader successors are in X), and (``want_choice``) the first such move, -1 if
    none."""
    if len(ks) > chunk:
        parts = [
            _best_moves(ks[s : s + chunk], X, A, safe, vectors, targets, W, want_choice, chunk)
            for s in range(0, len(ks), chunk)
        ]
        new = np.concatenate([p[0] for p in parts])
        return new, (np.concatenate([p[1] for p in parts]) if want_choice else None)
    new = np.zeros((len(ks), W, W), dtype=bool)
    choice = np.full((len(ks), W, W), -1, dtype=np.int16) if want_choice else None
    if len(ks) == 0:
        return new, choice
    Xk = X[ks]
    for j, vec in enumerate(vectors):
        tj = targets[ks, j]
        valid = np.flatnonzero(tj >= 0)
        if len(valid) == 0:
            continue
        good = _unpack(safe[j][ks[valid]], W)
        good &= shifted(A[tj[valid]], int(vec[0]), int(vec[1]), False)
        good &= Xk[valid]
        if want_choice:
            sub = choice[valid]
            sub[good & (sub < 0)] = j
            choice[valid] = sub
        new[valid] |= good
    return new, choice
