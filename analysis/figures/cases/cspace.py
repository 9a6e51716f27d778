"""The configuration-space cases (Secs. 3-4, Prop. 1 and erratum E10) the figures draw.

The paper's worlds are the built-in maps (THEORY.md section 3) at their recommended
parameters (:func:`envs.maps.builtin_info`: L_min = 2, L_max = 4, rho = 0.5).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
import shapely

from analysis.figures import worlds
from envs.maps import Map, builtin_info
from strategies.cspace import (
    Decomposition,
    StratifiedGraph,
    candidate_lengths,
    critical_lengths,
    decompose,
    stratified_graph,
    surveillance_verdict,
)
from strategies.policies.escape_plan import escape_ranks

__all__ = [
    "EscapeChain",
    "GrowthCase",
    "LHallEvent",
    "corridor",
    "corridor_chain",
    "corridor_mouth_region",
    "corridor_stratified",
    "dead_end_side",
    "escape_chain",
    "growth_cases",
    "l_hall_event",
    "mouth_chain",
    "paper_decomposition",
    "paper_verdict",
]


@functools.cache
def paper_decomposition(name: str, L: float | None = None) -> Decomposition:
    """The decomposition of a built-in world at ``L`` (default: its L_min)."""
    info = builtin_info(name)
    return decompose(info.map, info.l_min if L is None else L)


def corridor() -> Decomposition:
    """The corridor world of Fig. 3 at L = L_min."""
    return paper_decomposition("corridor")


@functools.cache
def paper_verdict(name: str):
    """Prop. 4's verdict on a built-in world over [L_min, L_max], the evader starting in
    the middle of the (first) room at (5, 0)."""
    info = builtin_info(name)
    return surveillance_verdict(info.map, info.l_min, info.l_max, start=(5.0, 0.0))


def corridor_mouth_region(dec: Decomposition | None = None) -> int:
    """The paper's R5: the region just outside the corridor's mouth (it holds (L/4, 0)),
    with one cell whose rod points into the corridor (kappa_5L) and one into the room."""
    dec = corridor() if dec is None else dec
    r = dec.locate((0.25 * dec.L, 0.0))
    if r is None:  # pragma: no cover - the built-in corridor has its mouth at x = 0
        raise RuntimeError("the corridor's mouth region was not found")
    return r


@dataclass(frozen=True)
class EscapeChain:
    """A guaranteed escape path through escapable cells (Sec. 4, conditions (a)/(b)).

    Attributes:
        cells: cell ids, from the start to the last cell, which has no continuation
            (condition (a)) across ``final_boundary``.
        ranks: their ranks in the least fixed point (strictly decreasing, last 0).
        final_boundary: the boundary piece across which surveillance breaks.
    """

    cells: tuple[int, ...]
    ranks: tuple[int, ...]
    final_boundary: int


def escape_chain(dec: Decomposition, start: int) -> EscapeChain:
    """Follow the escape from escapable cell ``start``: cross one of its vias into the
    adjacent cell of highest rank (the pursuer's best reply) until rank 0."""
    rank, vias = escape_ranks(dec)
    if rank[start] < 0:
        raise ValueError(f"cell {start} is not escapable")
    cells, ranks = [start], [int(rank[start])]
    c = start
    while rank[c] > 0:
        best = None
        for b in vias[c]:
            bd = dec.boundaries[b]
            nxt = [j if i == c else i for i, j in bd.adjacent if c in (i, j)]
            nxt = [x for x in nxt if x != c]
            if nxt:
                cand = max(nxt, key=lambda x: (rank[x], -x))
                if best is None or rank[cand] > rank[best]:
                    best = cand
        if best is None:  # pragma: no cover - a via of rank > 0 has adjacent cells
            break
        c = best
        cells.append(c)
        ranks.append(int(rank[c]))
    return EscapeChain(tuple(cells), tuple(ranks), vias[c][0])


@functools.cache
def corridor_chain() -> EscapeChain:
    """The escape of the paper's kappa_1L: from the dead-end-side cell (rod pointing into
    the corridor) of highest rank, i.e. the longest guaranteed escape, to a cell with no
    continuation."""
    dec = corridor()
    rank, _ = escape_ranks(dec)
    deep = [c for c in dec.cells if c.escapable and math.cos(c.arc.mid) < -0.5]
    start = max(deep, key=lambda c: (rank[c.id], -dec.regions[c.region].point[0], -c.id))
    return escape_chain(dec, start.id)


@functools.cache
def mouth_chain() -> EscapeChain:
    """The escape of the paper's kappa_5L: from the mouth region's cell whose rod points
    into the corridor, out of the mouth and round a corner (kappa_5L -> kappa_6L -> R7)."""
    dec = corridor()
    cells = [dec.cells[c] for c in dec.regions[corridor_mouth_region(dec)].cells]
    left = min(cells, key=lambda c: math.cos(c.arc.mid))
    return escape_chain(dec, left.id)


def dead_end_side(dec: Decomposition, cell: int) -> bool:
    """Whether a corridor cell is one of the paper's kappa_iL: at its region's sample point
    the rod points left and puts the pursuer inside the corridor (x < 0)."""
    c = dec.cells[cell]
    p = dec.regions[c.region].point + dec.L * np.array([math.cos(c.arc.mid), math.sin(c.arc.mid)])
    return bool(math.cos(c.arc.mid) < 0.0 and p[0] < 0.0)


@functools.cache
def corridor_stratified() -> StratifiedGraph:
    """Sec. 3's stratified graph G of the corridor over [L_min, L_max]."""
    info = builtin_info("corridor")
    return stratified_graph(info.map, info.l_min, info.l_max)


# --------------------------------------------------------------------------- Fig. 8
@dataclass(frozen=True)
class GrowthCase:
    """A world where escapable cells appear when L crosses a critical value (Fig. 8).

    Attributes:
        label: the curve type whose appearance is shown.
        world: the world.
        birth: the critical length at which the curve appears (or the event happens).
        before, after: decompositions just below and just above it.
        window: the zoom window ``(xmin, xmax, ymin, ymax)`` of the figure.
    """

    label: str
    world: Map
    birth: float
    before: Decomposition
    after: Decomposition
    window: tuple[float, float, float, float]


def _tips() -> Map:
    """Two wedges pointing at each other, tips sqrt(2) apart: a type-3 curve at L > sqrt 2."""
    return Map(
        [(0, 0), (15, 0), (15, 13), (0, 13)],
        [[(4, 7.6), (7, 7), (4, 6.4)], [(8, 6), (11, 6.6), (11, 5.4)]],
        name="two_tips",
    )


def _wedges() -> Map:
    """Two triangles, the lower one's apex below the upper one's base: type-5 curves."""
    return Map(
        [(0, 0), (16, 0), (16, 12), (0, 12)],
        [[(6, 7), (8, 7), (7, 9)], [(8, 3), (10, 3), (9, 5.8)]],
        name="apex_under_base",
    )


@functools.cache
def growth_cases() -> tuple[GrowthCase, ...]:
    """The three rows of Fig. 8: a type-3 birth, a type-5 birth, and type-2 corner
    pockets taking over a square room once L exceeds half its width."""
    out = []
    tips = _tips()
    d = float(np.hypot(1.0, 1.0))  # the tips (7, 7) and (8, 6)
    out.append(
        GrowthCase(
            "type 3",
            tips,
            d,
            decompose(tips, d - 0.06),
            decompose(tips, d + 0.06),
            (2.5, 12.5, 2.5, 10.5),
        )
    )
    wedges = _wedges()
    apex = shapely.Point(9.0, 5.8)  # the lower triangle's apex, under the upper one's base
    birth = float(apex.distance(shapely.Polygon([(6, 7), (8, 7), (7, 9)])))
    out.append(
        GrowthCase(
            "type 5",
            wedges,
            birth,
            decompose(wedges, birth - 0.02),
            decompose(wedges, birth + 0.03),
            (3.0, 13.0, 1.0, 11.0),
        )
    )
    room = worlds.room_corner(6.0)
    half = 3.0
    out.append(
        GrowthCase(
            "type 2",
            room,
            half,
            decompose(room, half - 0.1),
            decompose(room, half + 0.1),
            (-0.3, 6.3, -0.3, 6.3),
        )
    )
    return tuple(out)


# --------------------------------------------------------------------------- E10
@dataclass(frozen=True)
class LHallEvent:
    """The critical length of the L-shaped hall that Prop. 1's candidates miss (E10).

    Attributes:
        world: the hall (arms 4 wide).
        expected: ``(2 - sqrt 2) * width``, i.e. 8 - 4 sqrt 2: the type-1 lines x = L and
            y = L meet on the type-2 circle of radius L about the convex corner.
        found: the critical lengths :func:`critical_lengths` reports in ``(lo, hi)``.
        event: the reported length(s) nearest to ``expected``, averaged.
        candidates: Prop. 1's candidates in ``(lo, hi)`` (distances and their halves).
        lo, hi: the searched range.
    """

    world: Map
    expected: float
    found: tuple[float, ...]
    event: float
    candidates: tuple[float, ...]
    lo: float
    hi: float

    @property
    def nearest_candidate(self) -> float:
        """Prop. 1's candidate closest to the event."""
        return min(self.candidates, key=lambda c: abs(c - self.event))


@functools.cache
def l_hall_event(width: float = 4.0) -> LHallEvent:
    """Search (1.5, 2.9) x width/4 for G_L changes of the L-shaped hall and keep the ones
    next to (2 - sqrt 2) width."""
    world = worlds.l_hall(width)
    lo, hi = 0.375 * width, 0.725 * width
    found = critical_lengths(world, lo, hi)
    expected = (2.0 - math.sqrt(2.0)) * width
    tol = 1e-3 * width
    near = [c for c in found if abs(c - expected) <= tol]
    event = float(np.mean(near)) if near else math.nan
    return LHallEvent(world, expected, found, event, candidate_lengths(world, lo, hi), lo, hi)
