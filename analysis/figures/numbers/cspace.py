"""The numbers of Secs. 3-4 (regions, cells, escapes, Props. 1-4, erratum E10) and of the
corrections to THEORY.md (its section 8)."""

from __future__ import annotations

import math

import numpy as np

from analysis.figures import cases, worlds
from analysis.figures.numbers import fmt_list, number, yes_no


# ------------------------------------------------------------------ Sec. 3: corridor
def _corridor():
    return cases.corridor()


number("corridor.regions", "noncritical regions of the corridor at L = 2")(
    lambda: len(_corridor().regions)
)
number("corridor.cells", "free cells of the corridor at L = 2")(lambda: len(_corridor().cells))
number("corridor.adjacencies", "edges of G_L (corridor, L = 2)")(
    lambda: _corridor().graph.number_of_edges()
)
number("corridor.escapable", "escapable cells of the corridor at L = 2")(
    lambda: len(_corridor().escapable)
)
number("corridor.unresolved", "boundary pieces matched by arc overlap, not stops")(
    lambda: _corridor().unresolved
)
number("corridor.max_cells", "most cells above one region (the paper: at most two)")(
    lambda: max(len(r.cells) for r in _corridor().regions)
)
number("corridor.regions_3cells", "regions with three cells")(
    lambda: sum(len(r.cells) >= 3 for r in _corridor().regions)
)
number("corridor.mouth_cells", "cells above the mouth region (the paper's R5)")(
    lambda: len(_corridor().regions[cases.corridor_mouth_region()].cells)
)


@number("corridor.dead_end_cells", "cells with the pursuer on the dead-end side (kappa_iL)")
def _dead_end_cells() -> int:
    d = _corridor()
    return sum(cases.dead_end_side(d, c.id) for c in d.cells)


@number("corridor.dead_end_escapable", "of them escapable")
def _dead_end_escapable() -> int:
    d = _corridor()
    return sum(cases.dead_end_side(d, c.id) and c.escapable for c in d.cells)


@number("corridor.other_escapable", "escapable cells not on the dead-end side (room corners)")
def _other_escapable() -> int:
    d = _corridor()
    return sum(not cases.dead_end_side(d, c.id) and c.escapable for c in d.cells)


number("corridor.witnesses", "regions with only escapable cells (Prop. 2)")(
    lambda: len(_corridor().witness_regions)
)
number("corridor.mouth_chain", "cells on the escape from kappa_5L (reason (b) then (a))")(
    lambda: len(cases.mouth_chain().cells)
)
number("corridor.max_rank", "longest guaranteed escape (rounds of the fixed point)")(
    lambda: max(cases.corridor_chain().ranks)
)


# ------------------------------------------------------------------ Figs. 6-7
def _two():
    return cases.paper_verdict("two_rooms").decomposition


number("two_rooms.regions", "regions of the two-rooms world at L = 2")(lambda: len(_two().regions))
number("two_rooms.cells", "cells of the two-rooms world at L = 2")(lambda: len(_two().cells))
number("two_rooms.escapable", "escapable cells of the two-rooms world")(
    lambda: len(_two().escapable)
)
number("two_rooms.adjacencies", "edges of G_L (two rooms)")(lambda: _two().graph.number_of_edges())
number("two_rooms.evader_wins", "Prop. 4: the evader wins the two rooms", yes_no)(
    lambda: cases.paper_verdict("two_rooms").evader_wins
)
number("corridor.evader_wins", "Prop. 4: the evader wins the corridor", yes_no)(
    lambda: cases.paper_verdict("corridor").evader_wins
)


@number("prop4.verdicts", "Prop. 4 on every built-in world (over [L_min, L_max])")
def _verdicts() -> str:
    from envs.maps import builtin_info, builtin_names
    from strategies.cspace import surveillance_verdict

    out = []
    for n in builtin_names():
        i = builtin_info(n)
        v = surveillance_verdict(i.map, i.l_min, i.l_max)
        out.append(f"{n}: {'evader' if v.evader_wins else 'pursuer'}")
    return "; ".join(out)


number("stratified.critical", "critical lengths of the corridor in (2, 4)", fmt_list("{:.4f}"))(
    lambda: cases.corridor_stratified().critical
)


@number(
    "stratified.off_candidates",
    "of them, not a distance or half-distance (Prop. 1 misses them, E10)",
    fmt_list("{:.4f}"),
)
def _off() -> tuple[float, ...]:
    from strategies.cspace import candidate_lengths

    sg = cases.corridor_stratified()
    cand = candidate_lengths(sg.map, sg.l_min, sg.l_max)
    return tuple(c for c in sg.critical if min((abs(c - x) for x in cand), default=1.0) > 1e-6)


number("stratified.strata", "strata of G (corridor, L in [2, 4])")(
    lambda: len(cases.corridor_stratified().samples)
)
number("stratified.cells", "cells of G over all strata")(
    lambda: cases.corridor_stratified().graph.number_of_nodes()
)


@number("stratified.links", "edges of G between consecutive strata")
def _links() -> int:
    g = cases.corridor_stratified().graph
    return sum(1 for *_, k in g.edges(data="kind") if k == "length")


@number("stratified.unlinked", "cells of G_(i+1) linked to no cell of G_i (Prop. 3: none)")
def _unlinked() -> int:
    sg = cases.corridor_stratified()
    bad = 0
    for i in range(1, len(sg.strata)):
        for c in sg.strata[i].cells:
            if not any(n[0] == i - 1 for n in sg.graph.neighbors((i, c.id))):
                bad += 1
    return bad


# ------------------------------------------------------------------ Prop. 1, E10
number("lhall.event", "critical length found near (2 - sqrt 2) 4 by bisection", "{:.4f}")(
    lambda: cases.l_hall_event().event
)
number("lhall.expected", "8 - 4 sqrt 2", "{:.4f}")(lambda: cases.l_hall_event().expected)
number("lhall.error", "|found - expected|", "{:.0e}")(
    lambda: abs(cases.l_hall_event().event - cases.l_hall_event().expected)
)
number("lhall.candidates", "Prop. 1's candidates in the searched range", fmt_list("{:.4f}"))(
    lambda: cases.l_hall_event().candidates
)
number("lhall.found", "all critical lengths found in the range", fmt_list("{:.4f}"))(
    lambda: cases.l_hall_event().found
)


def _count(dec, t: int) -> int:
    return sum(c.type == t for c in dec.curves)


for _i, _lab in enumerate(("type3", "type5", "type2")):

    def _mk(i=_i):
        return cases.growth_cases()[i]

    number(f"growth.{_lab}.birth", f"Fig. 8 ({_lab}): the critical length", "{:.4f}")(
        lambda m=_mk: m().birth
    )
    number(
        f"growth.{_lab}.before",
        f"Fig. 8 ({_lab}): escapable cells below it",
        lambda v: f"{v[0]}/{v[1]}",
    )(lambda m=_mk: (len(m().before.escapable), len(m().before.cells)))
    number(
        f"growth.{_lab}.after",
        f"Fig. 8 ({_lab}): escapable cells above it",
        lambda v: f"{v[0]}/{v[1]}",
    )(lambda m=_mk: (len(m().after.escapable), len(m().after.cells)))
number("growth.type3.curves", "type-3 curves below / above sqrt 2", lambda v: f"{v[0]}/{v[1]}")(
    lambda: (_count(cases.growth_cases()[0].before, 3), _count(cases.growth_cases()[0].after, 3))
)
number(
    "growth.type5.curves",
    "type-5 curves below / above the vertex-edge distance",
    lambda v: f"{v[0]}/{v[1]}",
)(lambda: (_count(cases.growth_cases()[1].before, 5), _count(cases.growth_cases()[1].after, 5)))


# ------------------------------------------------------------------ THEORY.md section 8
def _arcs(world, p, L: float):
    from envs.geometry import kernel_for

    return kernel_for(world).free_arcs(p, L)


number(
    "s8.pocket_outside",
    "free arcs at (1.6, 1.6) of a square room, L = 2 (outside the corner's circle)",
)(lambda: len(_arcs(worlds.room_corner(6.0), (1.6, 1.6), 2.0)))
number("s8.pocket_inside", "free arcs at (1.2, 1.2) (inside the circle)")(
    lambda: len(_arcs(worlds.room_corner(6.0), (1.2, 1.2), 2.0))
)


def _type5_sides() -> tuple[int, int, str]:
    from strategies.cspace import critical_curves

    w = worlds.vertex_above_floor(1.2)
    c = next(c for c in critical_curves(w, 2.0) if c.type == 5)
    t = 0.5 * (c.t0 + c.t1)
    P = c.evaluate([t, t + 1e-4])[0]
    d = P[1] - P[0]
    n = np.array([-d[1], d[0]]) / math.hypot(*d)
    a, b = (_arcs(w, P[0] + s * 0.02 * n, 2.0) for s in (1.0, -1.0))
    new = (min((a, b), key=len) is a and b) or a
    thin = min(new.arcs, key=lambda x: x.width)
    return len(a), len(b), f"{thin.stop_lo.kind}/{thin.stop_hi.kind}"


number(
    "s8.type5_arcs",
    "free arcs on either side of a type-5 curve, obstacle on the far side",
    lambda v: f"{v[0]}/{v[1]}",
)(lambda: _type5_sides()[:2])
number("s8.type5_stops", "stops of the thin arc that opens")(lambda: _type5_sides()[2])


@number("s8.wall_stop", "stop labels at (3, 0) on a room's floor, L = 2")
def _wall_stop() -> str:
    fa = _arcs(worlds.room_corner(6.0), (3.0, 0.0), 2.0)
    kinds = sorted({f"{s.kind}-{s.feature.kind}" for a in fa for s in (a.stop_lo, a.stop_hi)})
    return "/".join(kinds)
