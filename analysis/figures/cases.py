"""The computed examples behind the figures and the report's numbers, each computed once.

A figure draws a case and :mod:`analysis.figures.numbers` quotes it, so what the report
says is what the picture shows. Everything is deterministic and built from the library's
public functions; results are cached per process (``functools.cache``).

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
from envs.maps import Feature, Map, builtin_info
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
    "MATCHES",
    "ChargeRotation",
    "EscapeCase",
    "EscapeChain",
    "GrowthCase",
    "LHallEvent",
    "Match",
    "charge_rotation",
    "corridor",
    "corridor_chain",
    "corridor_mouth_region",
    "corridor_stratified",
    "curve_escape",
    "dead_end_side",
    "evader_wins",
    "growth_cases",
    "l_hall_event",
    "mouth_chain",
    "outcomes",
    "paper_decomposition",
    "paper_shot",
    "paper_shot_rho",
    "paper_verdict",
    "play",
    "vertex_escape",
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


# --------------------------------------------------------------------------- Fig. 9
@dataclass(frozen=True)
class ChargeRotation:
    """Fig. 9(a): the evader charges straight at the pursuer (alpha = theta0 = pi) while the
    pursuer turns the rod clockwise at its extreme rate theta_dot- of eq. (6).

    Attributes:
        L, v_p, rho: parameters (the corridor's).
        T: time to turn the rod from pi to pi/2 (Sec. 7.2's closed form, E5/E5b).
        t, theta: the rotation, integrated from eq. (6).
        recoil: how far the pursuer is pushed back along the charge (max over t of
            x_p(0) - x_p(t)): closer than this to the corridor's mouth, it is pushed in.
    """

    L: float
    v_p: float
    rho: float
    T: float
    t: np.ndarray
    theta: np.ndarray
    recoil: float

    def positions(self, evader0) -> tuple[np.ndarray, np.ndarray]:
        """Evader and pursuer positions, the evader starting at ``evader0``."""
        e0 = np.asarray(evader0, dtype=float)
        e = e0 + np.outer(self.t, [-self.rho * self.v_p, 0.0])
        p = e + self.L * np.column_stack([np.cos(self.theta), np.sin(self.theta)])
        return e, p


@functools.cache
def charge_rotation() -> ChargeRotation:
    """The rotation of Fig. 9(a) with the corridor's parameters."""
    from scipy.integrate import solve_ivp

    from strategies.control import straight_leader_time, theta_dot

    info = builtin_info("corridor")
    L, v_p, rho = info.l_min, info.v_pursuer, info.rho
    T = straight_leader_time(math.pi, 0.5 * math.pi, alpha=math.pi, L=L, v_p=v_p, rho=rho)
    sol = solve_ivp(
        lambda _t, y: [theta_dot(math.pi, y[0], L=L, v_p=v_p, rho=rho)[1]],
        (0.0, T),
        [math.pi],
        dense_output=True,
        rtol=1e-11,
        atol=1e-12,
    )
    t = np.linspace(0.0, T, 801)
    theta = sol.sol(t)[0]
    xp = -rho * v_p * t + L * np.cos(theta)
    return ChargeRotation(L, v_p, rho, T, t, theta, float(xp[0] - xp.min()))


# --------------------------------------------------------------------------- Figs. 10-13
PAPER_SHOTS = {
    "a": {"theta0": math.pi, "lambda1": -1.0, "lambda2_0": 0.41, "x_e": 1.0},
    "b": {"theta0": math.pi / 6, "lambda1": 1.0, "lambda2_0": 0.608, "x_e": 0.5},
}
"""The initial values printed under Fig. 11 (L and rho are not given)."""

SHOT_L = 1.0
"""The rod length we draw Figs. 10-12 at (THEORY.md section 7's reference value)."""


@functools.cache
def paper_shot_rho(which: str) -> float:
    """The rho at which Fig. 11(``which``)'s printed multipliers, shot at L = 1, return to
    y = 0 exactly at the printed x_e (one equation: the figure's (L, rho) are a curve, not a
    point; at L = 1 this is the point)."""
    from scipy.optimize import brentq

    from strategies.control import shoot

    p = PAPER_SHOTS[which]

    def miss(rho: float) -> float:
        arc = shoot(
            p["theta0"], p["lambda1"], p["lambda2_0"], L=SHOT_L, rho=rho, x_max=6.0 * p["x_e"]
        )
        return (arc.x_c if arc.x_c is not None else 6.0 * p["x_e"]) - p["x_e"]

    grid = np.linspace(0.1, 0.95, 35)
    vals = [miss(float(r)) for r in grid]
    for a, b, fa, fb in zip(grid, grid[1:], vals, vals[1:], strict=False):
        if fa * fb < 0:
            return float(brentq(miss, a, b, xtol=1e-12))
    raise RuntimeError(f"no rho in (0.1, 0.95) fits Fig. 11({which})")  # pragma: no cover


@functools.cache
def paper_shot(which: str, rho: float | None = None):
    """Fig. 11(``which``)'s printed multipliers shot at L = 1 (rho: fitted by default),
    and the optimal escape to the printed x_e at the same (L, rho)."""
    from strategies.control import shoot, solve_escape

    p = PAPER_SHOTS[which]
    rho = paper_shot_rho(which) if rho is None else rho
    arc = shoot(
        p["theta0"],
        p["lambda1"],
        p["lambda2_0"],
        L=SHOT_L,
        rho=rho,
        x_max=4.0 * p["x_e"],
        stop_at_crossing=True,
    )
    sol = solve_escape(p["theta0"], p["x_e"], L=SHOT_L, rho=rho)
    return arc, sol


@dataclass(frozen=True)
class EscapeCase:
    """Fig. 13: an optimal escape to an endpoint in the corridor world (world frame).

    Attributes:
        kind: ``"vertex"`` or ``"critical_curve"``.
        evader, pursuer: start positions.
        target: the :class:`strategies.control.EscapeTarget`.
        branch: the pursuer's rotation sense compared (the one needing less rotation).
        solution: :func:`strategies.control.solve_escape` in the evader frame.
        evader_path, pursuer_path: the optimal arc mapped back to the world.
        curve: the critical curve(s) drawn dashed (list of (k, 2) polylines).
    """

    kind: str
    evader: np.ndarray
    pursuer: np.ndarray
    target: object
    branch: str
    solution: object
    evader_path: np.ndarray
    pursuer_path: np.ndarray
    curves: tuple[np.ndarray, ...]

    @property
    def needed(self) -> float:
        """Rotation the pursuer needs on ``branch`` to reach an admissible orientation."""
        return self.target.required_rotation(self.branch)

    @property
    def achieved(self) -> float:
        """Rotation it can effect while the evader runs the optimal arc, |J|."""
        return abs(self.solution.J)

    @property
    def evader_escapes(self) -> bool:
        """The pursuer cannot turn far enough in time (on this branch)."""
        return self.achieved < self.needed


def _escape_case(kind, evader, theta, target_fn, curves) -> EscapeCase:
    from strategies.control import from_evader_frame, solve_escape

    dec = corridor()
    e = np.asarray(evader, dtype=float)
    p = e + dec.L * np.array([math.cos(theta), math.sin(theta)])
    t = target_fn(e, p)
    branch = "+" if t.rotation_ccw <= t.rotation_cw else "-"
    sol = solve_escape(t.theta0, t.x_e, L=dec.L, rho=builtin_info("corridor").rho, branch=branch)
    ev = from_evader_frame(sol.arc.evader_path(), e, t.beta)
    pu = from_evader_frame(sol.arc.pursuer_path(), e, t.beta)
    return EscapeCase(kind, e, p, t, branch, sol, ev, pu, tuple(curves))


@functools.cache
def vertex_escape() -> EscapeCase:
    """Fig. 13 left: from (1.5, 1.5), rod at 120 deg, to the mouth's upper corner (0, 0.5),
    whose two type-4 curves bound the admissible orientations."""
    from strategies.control import vertex_escape_target

    dec = corridor()
    m = dec.map
    k = int(np.argmin(np.hypot(*(m.vertices - (0.0, 0.5)).T)))
    prev = m.edge_start[int(np.flatnonzero(np.all(m.edge_end == m.vertices[k], axis=1))[0])]
    nxt = m.edge_end[k]
    curves = [c.points for c in dec.curves if c.type == 4 and Feature("vertex", k) in c.features]
    return _escape_case(
        "vertex",
        (1.5, 1.5),
        math.radians(120.0),
        lambda e, p: vertex_escape_target(e, p, m.vertices[k], prev, nxt, L=dec.L),
        curves,
    )


@functools.cache
def curve_escape() -> EscapeCase:
    """Fig. 13 right: from (3, -3), rod at -135 deg, to the critical curve bounding the
    region of the room-corner pocket cell (an escapable cell, condition (a))."""
    from strategies.control import critical_curve_escape_target

    dec = corridor()
    e = np.array([3.0, -3.0])
    home = dec.locate(e)
    corner = dec.locate((1.7, -3.3))  # the pocket region of the room corner (0, -5)
    cell = next(dec.cells[c] for c in dec.regions[corner].cells if dec.cells[c].escapable)
    piece = next(b for b in dec.boundaries if set(b.regions) == {home, corner})
    pts = piece.segments.reshape(-1, 2)
    return _escape_case(
        "critical_curve",
        e,
        math.radians(-135.0),
        lambda e, p: critical_curve_escape_target(e, p, pts, cell.arc.lo, cell.arc.hi, L=dec.L),
        [pts],
    )


# --------------------------------------------------------------------------- replays
@dataclass(frozen=True)
class Match:
    """One seeded episode between two registered policies on a built-in world.

    Attributes:
        map: built-in map name (its recommended L_min, L_max and speeds apply).
        pursuer, evader: registered policy names.
        seed: the episode seed.
        overrides: env overrides as ``(key, value)`` pairs (e.g. ``(("v_evader", 1.5),)``).
        evader_params: the evader policy's parameters as ``(key, value)`` pairs.
    """

    map: str
    pursuer: str
    evader: str
    seed: int = 0
    overrides: tuple[tuple[str, float], ...] = ()
    evader_params: tuple[tuple[str, object], ...] = ()

    @property
    def command(self) -> str:
        """The ``surveil play`` command that replays it."""
        import json

        cmd = f"surveil play --map {self.map} --pursuer {self.pursuer} --evader {self.evader}"
        cmd += f" --seed {self.seed}"
        if self.evader_params:
            cmd += f" --evader-params '{json.dumps(dict(self.evader_params))}'"
        if self.overrides:
            cmd += f" --config '{json.dumps(dict(self.overrides))}'"
        return cmd


MATCHES = {
    "corridor": Match("corridor", "pursuer/decomposition", "evader/shooting", 0),
    "two_rooms": Match("two_rooms", "pursuer/decomposition", "evader/shooting", 1),
    "corner_slow": Match("corner", "pursuer/decomposition", "evader/wall_hugging", 3),
    "corner_fast": Match(
        "corner", "pursuer/decomposition", "evader/wall_hugging", 1, (("v_evader", 1.0),)
    ),
    "charge": Match(
        "open_room",
        "pursuer/decomposition",
        "evader/toward_away",
        0,
        (("v_evader", 1.5),),
        (("mode", "toward"),),
    ),
    "run_away": Match(
        "open_room",
        "pursuer/decomposition",
        "evader/toward_away",
        0,
        (("v_evader", 1.5),),
        (("mode", "away"),),
    ),
}
"""The episodes the replays show (and the report quotes)."""


@functools.cache
def play(match: Match):
    """Play ``match`` with the shared episode runner (deterministic: one seed drives env,
    start and both policies). A rho > 1 match is deliberate here, so its warning is not
    repeated."""
    import warnings

    from envs.errors import RhoAboveOneWarning
    from strategies.policies import make_policy
    from strategies.runner import run_episode

    evader = make_policy(match.evader, **dict(match.evader_params))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RhoAboveOneWarning)
        return run_episode(
            match.map, match.pursuer, evader, seed=match.seed, overrides=dict(match.overrides)
        )


TALLY_SEEDS = 10
"""Seeds each replay's match is also played with, so a replay is not a lucky pick."""


@functools.cache
def outcomes(key: str, seeds: int = TALLY_SEEDS) -> tuple[tuple[str, str | None, str | None], ...]:
    """``(winner, cause, feature)`` of ``MATCHES[key]`` played with seeds 0..``seeds - 1``."""
    m = MATCHES[key]
    out = []
    for s in range(seeds):
        r = play(Match(m.map, m.pursuer, m.evader, s, m.overrides, m.evader_params))
        out.append((r.winner, r.cause, r.feature))
    return tuple(out)


def evader_wins(key: str, seeds: int = TALLY_SEEDS) -> int:
    """In how many of seeds 0..``seeds - 1`` the evader of ``MATCHES[key]`` wins."""
    return sum(w == "evader" for w, _, _ in outcomes(key, seeds))
