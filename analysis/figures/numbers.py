"""Every number ``docs/REPRODUCTION.md`` quotes, computed now from the library.

Each :class:`Number` has a key (``corridor.regions``), a one-line description and a
function computing it; :meth:`Number.text` formats it the way the report prints it. The
report tags each quoted number with its key (:mod:`analysis.figures.report`), and a test
recomputes them all, so the report cannot drift from the code. ``surveil figures
--numbers [PREFIX...]`` prints them.

The computations reuse the cases the figures draw (:mod:`analysis.figures.cases`).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from analysis.figures import cases, worlds
from envs.errors import UnknownNameError

__all__ = ["NUMBERS", "Number", "compute_numbers", "number"]


@dataclass(frozen=True)
class Number:
    """One quoted number.

    Attributes:
        key: its name in the report's tags, e.g. ``"corridor.regions"``.
        what: what it is, one line.
        compute: returns the value.
        fmt: a format string (``"{:.4f}"``) or a function value -> text.
    """

    key: str
    what: str
    compute: Callable[[], Any]
    fmt: str | Callable[[Any], str] = "{}"

    def text(self) -> str:
        """The value as the report prints it."""
        v = self.compute()
        return self.fmt(v) if callable(self.fmt) else self.fmt.format(v)


NUMBERS: dict[str, Number] = {}


def number(key: str, what: str, fmt: str | Callable[[Any], str] = "{}"):
    """Decorator registering a number."""

    def deco(fn: Callable[[], Any]) -> Callable[[], Any]:
        if key in NUMBERS:  # pragma: no cover - a programming error
            raise ValueError(f"number {key!r} registered twice")
        NUMBERS[key] = Number(key, what, fn, fmt)
        return fn

    return deco


def compute_numbers(prefixes: list[str] | None = None) -> dict[str, str]:
    """``{key: text}`` for every number (or those whose key starts with a prefix).

    Raises:
        UnknownNameError: a prefix matches no number.
    """
    keys = list(NUMBERS)
    if prefixes:
        for p in prefixes:
            if not any(k.startswith(p) for k in keys):
                raise UnknownNameError(f"no number starts with {p!r}; keys: {', '.join(keys)}")
        keys = [k for k in keys if any(k.startswith(p) for p in prefixes)]
    return {k: NUMBERS[k].text() for k in keys}


def _list(fmt: str) -> Callable[[Any], str]:
    return lambda xs: ", ".join(fmt.format(x) for x in xs)


def _yes(v: bool) -> str:
    return "yes" if v else "no"


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
number("two_rooms.evader_wins", "Prop. 4: the evader wins the two rooms", _yes)(
    lambda: cases.paper_verdict("two_rooms").evader_wins
)
number("corridor.evader_wins", "Prop. 4: the evader wins the corridor", _yes)(
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


number("stratified.critical", "critical lengths of the corridor in (2, 4)", _list("{:.4f}"))(
    lambda: cases.corridor_stratified().critical
)


@number(
    "stratified.off_candidates",
    "of them, not a distance or half-distance (Prop. 1 misses them, E10)",
    _list("{:.4f}"),
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
number("lhall.candidates", "Prop. 1's candidates in the searched range", _list("{:.4f}"))(
    lambda: cases.l_hall_event().candidates
)
number("lhall.found", "all critical lengths found in the range", _list("{:.4f}"))(
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


# ------------------------------------------------------------------ Sec. 5, Fig. 9
number("fig9a.T", "time to turn the rod by pi/2 against a charge (L = 2, rho = 0.5)", "{:.4f}")(
    lambda: cases.charge_rotation().T
)
number("fig9a.recoil", "how far the charge pushes the pursuer back meanwhile", "{:.4f}")(
    lambda: cases.charge_rotation().recoil
)


@number("fig9b.l_star", "corner: least evader-corner distance, rho L/(1 + rho), L = 2", "{:.4f}")
def _l_star_2() -> float:
    from envs.maps import builtin_info
    from strategies.control import corner_min_distance

    i = builtin_info("corner")
    return corner_min_distance(L=i.l_min, rho=i.rho)


@number("e8.relative", "L theta_dot with the evader crossing the rod, pursuer still", "{:.2f}")
def _e8() -> float:
    from strategies.control import theta_dot_from_velocities

    return float(theta_dot_from_velocities((0.0, 0.5), (0.0, 0.0), 0.0, L=1.0))


# ------------------------------------------------------------------ replays, footnote 4
def _play(key: str):
    return cases.play(cases.MATCHES[key])


for _k in ("corridor", "two_rooms", "corner_slow", "corner_fast", "charge", "run_away"):
    number(f"replay.{_k}.winner", f"winner of the {_k} replay")(lambda k=_k: _play(k).winner)
number("replay.two_rooms.time", "time of the two-rooms escape (s)", "{:.1f}")(
    lambda: _play("two_rooms").escape_time
)
number("replay.two_rooms.cause", "why surveillance broke")(lambda: _play("two_rooms").cause)
number("replay.two_rooms.feature", "the wall feature the rod hit")(
    lambda: _play("two_rooms").feature
)
number("replay.corner_fast.feature", "the wall feature the rod hit")(
    lambda: _play("corner_fast").feature
)
number("replay.corner_fast.time", "time of the fast corner escape (s)", "{:.1f}")(
    lambda: _play("corner_fast").escape_time
)
number("replay.corner_fast.cause", "why it broke")(lambda: _play("corner_fast").cause)
number("replay.charge.time", "time of the charge's escape (s)", "{:.2f}")(
    lambda: _play("charge").escape_time
)
number("replay.charge.cause", "why it broke")(lambda: _play("charge").cause)
for _k in cases.MATCHES:
    number(f"tally.{_k}", f"evader wins in seeds 0-9 of the {_k} match")(
        lambda k=_k: cases.evader_wins(k)
    )


@number("tally.corner_fast.on_corner", "of them, the rod occluded by the corner (5, 5)")
def _on_corner() -> int:
    return sum(
        cause == "occluded" and feature is not None and feature.endswith("(5, 5)")
        for _, cause, feature in cases.outcomes("corner_fast")
    )


# ------------------------------------------------------------------ Sec. 6.1
def _td(phi: float):
    from strategies.control import theta_dot

    return theta_dot(phi, 0.0, L=1.0, v_p=1.0, rho=0.5)


number("eq6.plus_pi6", "theta_dot+ at alpha - theta = pi/6 (rho = 0.5)", "{:.10f}")(
    lambda: _td(math.pi / 6)[0]
)
number("eq6.minus_pi6", "theta_dot- at alpha - theta = pi/6", "{:.10f}")(
    lambda: _td(math.pi / 6)[1]
)
number("eq6.plus_3pi2", "theta_dot+ at 3 pi/2", "{:.10f}")(lambda: _td(1.5 * math.pi)[0])


@number("e1.rho1", "theta_dot+ at rho = 1, alpha - theta = pi/2 (the paper: > 0)", "{:.1f}")
def _e1() -> float:
    from strategies.control import theta_dot

    return float(theta_dot(0.5 * math.pi, 0.0, L=1.0, v_p=1.0, rho=1.0)[0])


number("e2.minrate", "min over alpha of max |theta_dot| (rho = 0.5, L = V_p = 1)", "{:.4f}")(
    lambda: (
        __import__("strategies.control", fromlist=["x"])
        .min_max_theta_dot(0.0, L=1.0, v_p=1.0, rho=0.5)
        .rate
    )
)


def _g(phi, rho: float):
    from strategies.control import max_abs_theta_dot

    return np.asarray(max_abs_theta_dot(phi, 0.0, L=1.0, v_p=1.0, rho=rho))


@number(
    "e2.g2",
    "g''(0+) for rho = 0.5 by finite differences (closed form rho^2/sqrt(1-rho^2))",
    "{:.4f}",
)
def _e2_g2() -> float:
    h = 1e-5
    x = np.array([h, 2 * h, 3 * h])
    y = _g(x, 0.5)
    return float((y[0] - 2 * y[1] + y[2]) / h**2)


number("e2.g2_closed", "rho^2 / sqrt(1 - rho^2) at rho = 0.5", "{:.4f}")(
    lambda: 0.25 / math.sqrt(0.75)
)


def _inflection(rho: float) -> float:
    from scipy.optimize import brentq

    h = 1e-4

    def g2(x: float) -> float:
        y = _g(np.array([x - h, x, x + h]), rho)
        return float((y[0] - 2 * y[1] + y[2]) / h**2)

    return float(brentq(g2, 0.05, 1.2, xtol=1e-10))


for _rho in (0.3, 0.5, 0.9):
    number(f"e2.inflection_{_rho}", f"inflection of g on (0, pi/2), rho = {_rho}", "{:.5f}")(
        lambda r=_rho: _inflection(r)
    )


# ------------------------------------------------------------------ Sec. 6.2, Figs. 10-13
for _w in "ab":
    number(
        f"fig11{_w}.rho", f"the rho at which Fig. 11({_w})'s shot returns at x_e (L = 1)", "{:.4f}"
    )(lambda w=_w: cases.paper_shot_rho(w))
    number(f"fig11{_w}.k_printed", f"lambda1 / (1 + lambda2) printed in Fig. 11({_w})", "{:.4f}")(
        lambda w=_w: cases.PAPER_SHOTS[w]["lambda1"] / (1 + cases.PAPER_SHOTS[w]["lambda2_0"])
    )
    number(f"fig11{_w}.k_solved", f"k found by solve_escape for Fig. 11({_w})", "{:.4f}")(
        lambda w=_w: cases.paper_shot(w)[1].k
    )
    number(f"fig11{_w}.J", f"rotation J = theta(x_e) - theta0, Fig. 11({_w})", "{:.4f}")(
        lambda w=_w: cases.paper_shot(w)[0].J
    )
    number(
        f"fig11{_w}.lambdas",
        f"normalised (lambda1, lambda2(0)), lambda2(x_e) = 0, ({_w})",
        lambda v: f"({v[0]:.4f}, {v[1]:.4f})",
    )(lambda w=_w: (cases.paper_shot(w)[1].lambda1, cases.paper_shot(w)[1].lambda2_0))
    number(f"fig11{_w}.H_spread", f"max - min of H along the arc ({_w})", "{:.0e}")(
        lambda w=_w: float(np.ptp(cases.paper_shot(w)[0].H))
    )


@number("fig11a.xc_rho05", "Fig. 11(a)'s shot at L = 1, rho = 0.5: return abscissa", "{:.4f}")
def _xc05() -> float:
    from strategies.control import shoot

    p = cases.PAPER_SHOTS["a"]
    return shoot(p["theta0"], p["lambda1"], p["lambda2_0"], L=1.0, rho=0.5, x_max=4.0).x_c


@number("fig11a.H_rho05", "H along that arc (THEORY.md: 2.416242)", "{:.6f}")
def _h05() -> float:
    from strategies.control import shoot

    p = cases.PAPER_SHOTS["a"]
    return float(shoot(p["theta0"], p["lambda1"], p["lambda2_0"], L=1.0, rho=0.5, x_max=1.0).H[0])


@number("fig11b.unbounded_rho09", "Fig. 11(b)'s multipliers at rho = 0.9: H unbounded", _yes)
def _unb() -> bool:
    from strategies.control import shoot

    p = cases.PAPER_SHOTS["b"]
    return shoot(p["theta0"], p["lambda1"], p["lambda2_0"], L=1.0, rho=0.9, x_max=2.0).unbounded


@number(
    "fig10.step", "change of the return abscissa from step 1e-2 to 1e-3 (Fig. 10, RK4)", "{:.0e}"
)
def _step() -> float:
    from strategies.control import shoot

    p = cases.PAPER_SHOTS["a"]
    xs = [
        shoot(
            p["theta0"],
            p["lambda1"],
            p["lambda2_0"],
            L=1.0,
            rho=0.5,
            x_max=2.0,
            method="pmp",
            step=h,
        ).x_c
        for h in (1e-2, 1e-3)
    ]
    return abs(xs[0] - xs[1])


@number(
    "fig10.scale",
    "max |y| difference of the shots (-1, 0.41), (-2, 1.82), (-0.5, -0.295)",
    "{:.0e}",
)
def _scale() -> float:
    from strategies.control import shoot

    arcs = [
        shoot(math.pi, a, b, L=1.0, rho=0.5, x_max=1.0)
        for a, b in ((-1.0, 0.41), (-2.0, 1.82), (-0.5, -0.295))
    ]
    n = min(len(a.y) for a in arcs)
    return float(max(np.max(np.abs(a.y[:n] - arcs[0].y[:n])) for a in arcs))


@number("fig12.alpha", "greedy heading at theta = pi (rho = 0.5): -arctan rho", "{:.4f}")
def _ga() -> float:
    from strategies.control import greedy_heading

    return float(greedy_heading(math.pi, L=1.0, rho=0.5).alpha)


@number("fig12.f2", "its rate d theta/dx = (1 - rho^2)/(L rho)", "{:.4f}")
def _gf() -> float:
    from strategies.control import greedy_heading

    return float(greedy_heading(math.pi, L=1.0, rho=0.5).f2)


@number(
    "minus.alpha", "theta_dot- branch, greedy heading at theta = 0 (minimises |rotation|)", "{:.4f}"
)
def _ma() -> float:
    from strategies.control import greedy_heading

    return float(greedy_heading(0.0, L=1.0, rho=0.5, branch="-").alpha)


@number("minus.f2", "its rate (signed)", "{:.4f}")
def _mf() -> float:
    from strategies.control import greedy_heading

    return float(greedy_heading(0.0, L=1.0, rho=0.5, branch="-").f2)


@number(
    "minus.paper",
    "the paper's H for theta_dot-, (1 + lambda2) f2 at lambda2 = 0, "
    "at alpha = pi/2 - 1e-3: unbounded below",
    "{:.0f}",
)
def _mp() -> float:
    from strategies.control.hamiltonian import f2

    return float(f2(0.5 * math.pi - 1e-3, 0.0, L=1.0, rho=0.5, branch="-"))


for _c in ("vertex", "curve"):

    def _case(c=_c):
        return cases.vertex_escape() if c == "vertex" else cases.curve_escape()

    number(f"fig13.{_c}.needed", f"rotation needed ({_c} endpoint)", "{:.4f}")(
        lambda f=_case: f().needed
    )
    number(f"fig13.{_c}.achieved", f"rotation |J| the pursuer can effect ({_c})", "{:.4f}")(
        lambda f=_case: f().achieved
    )
    number(f"fig13.{_c}.escapes", f"the evader escapes ({_c})", _yes)(
        lambda f=_case: f().evader_escapes
    )


# ------------------------------------------------------------------ Sec. 7
@number(
    "tractrix.t1",
    "follower and theta at t = 1 (L = V_e = 1, theta0 = pi/2)",
    lambda v: f"({v[0]:.10f}, {v[1]:.10f}), {v[2]:.10f}",
)
def _tr() -> tuple[float, float, float]:
    from strategies.control import tractrix

    tr = tractrix([1.0])
    return float(tr.follower[0, 0]), float(tr.follower[0, 1]), float(tr.theta[0])


@number(
    "tractrix.rk4", "max distance closed form vs RK4 of the dragged follower, t in [0, 4]", "{:.0e}"
)
def _tr_rk4() -> float:
    from strategies.control import tractrix, tractrix_numeric

    t = np.linspace(0.0, 4.0, 17)
    return float(np.max(np.hypot(*(tractrix(t).follower - tractrix_numeric(t).follower).T)))


def _T(theta1: float) -> float:
    from strategies.control import straight_leader_time

    return straight_leader_time(0.5 * math.pi, theta1, alpha=0.0, L=1.0, v_p=1.0, rho=0.5)


number("e5.T_plus", "T from pi/2 to pi, rho = 0.5 (counter-clockwise)", "{:.10f}")(
    lambda: _T(math.pi)
)
number("e5.T_minus", "T from pi/2 to 0 (clockwise)", "{:.10f}")(lambda: _T(0.0))


@number("e5.quad", "largest |closed form - quadrature of L / theta_dot| over both", "{:.0e}")
def _quad() -> float:
    from scipy.integrate import quad

    from strategies.control import theta_dot

    out = 0.0
    for th1, k in ((math.pi, 0), (0.0, 1)):

        def f(th, k=k):
            return 1.0 / abs(theta_dot(0.0, th, L=1.0, v_p=1.0, rho=0.5)[k])

        lo, hi = sorted((0.5 * math.pi, th1))
        out = max(out, abs(quad(f, lo, hi, epsabs=1e-14, epsrel=1e-13)[0] - _T(th1)))
    return out


@number(
    "e6.speed60", "wall following: worst-case follower speed at theta = 60 deg (V_e = 1)", "{:.4f}"
)
def _w60() -> float:
    from strategies.control import wall_follow_max_speed

    return float(wall_follow_max_speed(math.radians(60.0), v_e=1.0))


@number("e6.feasible120", "feasible at theta = 120 deg, rho = 0.45 (|cos| = 0.5 >= rho)", _yes)
def _w120() -> bool:
    from strategies.control import wall_follow_feasible

    return bool(wall_follow_feasible(math.radians(120.0), rho=0.45))


@number("e7.l_star", "corner: rho L/(1 + rho) for L = 1, rho = 0.5", "{:.4f}")
def _l_star_1() -> float:
    from strategies.control import corner_min_distance

    return corner_min_distance(L=1.0, rho=0.5)


@number("e7.fd", "|finite-difference velocity of p = e + (L/l)(v - e) - the formula|", "{:.0e}")
def _fd() -> float:
    from strategies.control import corner_pursuer_position, corner_pursuer_velocity

    e, v, ev, h = np.array([-0.3, 0.4]), np.array([0.0, 0.0]), np.array([0.2, -0.45]), 1e-6
    num = (
        corner_pursuer_position(e + h * ev, v, L=1.0)
        - corner_pursuer_position(e - h * ev, v, L=1.0)
    ) / (2 * h)
    return float(np.max(np.abs(num - corner_pursuer_velocity(e, v, ev, L=1.0))))


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
