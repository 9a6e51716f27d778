"""The referee's claims, checked: closed-form cases, consistency of the two bounds,
monotonicity in rho, in the sensor range and in resolution, symmetry, and the
decomposition theory's verdicts in the limit of a fast pursuer."""

from __future__ import annotations

import math

import numpy as np
import pytest

from envs.maps import Map
from strategies.cspace import decompose, surveillance_verdict
from strategies.referee import Referee, Resolution, solve, solve_evader_bound, solve_pursuer_bound
from strategies.referee.spec import GameSpec
from tests.strategies.referee.conftest import L_MAX, L_MIN, dead_end, open_room, spec

# rho = 0.5 on purpose: the pursuer bound's own warning is tested in test_vacuity
pytestmark = pytest.mark.filterwarnings("ignore::envs.errors.VacuousBoundWarning")


def _clearances(ref, starts):
    m = ref.spec.map
    return m.distance_to_walls(starts.pursuer), m.distance_to_walls(starts.evader)


def test_fast_evader_wins_everywhere_in_an_open_room(open_fast):
    # rho > 1: charging the pursuer shortens the rod at V_e - V_p > 0 wherever it flees to
    starts = open_fast.lattice_starts()
    assert len(starts) > 1000
    assert starts.counts()["evader"] == len(starts)
    assert (starts.escape_steps > 0).all()


def test_slow_evader_loses_from_every_start_with_margin_in_an_open_room(open_slow):
    starts = open_slow.lattice_starts()
    L = np.hypot(*(starts.pursuer - starts.evader).T)
    cp, ce = _clearances(open_slow, starts)
    margin = (L >= L_MIN + 0.25) & (L <= L_MAX - 0.25) & (cp >= 0.8) & (ce >= 0.8)
    assert margin.sum() > 10_000
    assert (starts.label[margin] == "pursuer").all()
    assert starts.counts()["evader"] == 0  # nothing the evader can force in a convex room
    assert starts.fractions()["pursuer"] > 0.85


def test_no_start_is_certified_for_both_players(corridor_half, open_slow, open_fast):
    for ref in (corridor_half, open_slow, open_fast):
        starts = ref.lattice_starts()  # raises if a start were certified both ways
        assert set(np.unique(starts.label)) <= {"pursuer", "evader", "unknown"}
        # and the single-start certificates agree with the state-level labels
        rng = np.random.default_rng(0)
        for i in rng.choice(len(starts), size=min(40, len(starts)), replace=False):
            p, e = starts.pursuer[i], starts.evader[i]
            got = ref.classify(p, e)
            assert not (ref.pursuer.certifies(p, e) and ref.evader.certifies(p, e))
            if starts.label[i] != "unknown":
                assert got == starts.label[i]


def test_pursuer_behind_the_evader_in_a_dead_end_is_lost(corridor_half):
    # the decomposition's "pursuer forced into a corner": deeper in a corridor narrower
    # than L_min, the pursuer can neither pass the evader nor turn the rod
    for p_x, e_x in [(-2.2, -0.9), (-2.0, -0.8), (-2.1, -0.6)]:
        assert corridor_half.classify((p_x, 0.0), (e_x, 0.0)) == "evader"
        t = corridor_half.escape_time((p_x, 0.0), (e_x, 0.0))
        assert t is not None and 0 < t < 30.0
    # the same rod the other way round (pursuer on the room side) is not an evader win
    assert corridor_half.classify((0.4, 0.0), (-0.9, 0.0)) != "evader"


def test_dead_end_starts_lie_in_escapable_cells_of_the_decomposition(corridor_half):
    # Prop. 2's escapable cells at the start's own L contain the certified evader wins in
    # the corridor (the limit V_p -> infinity the theory describes)
    for p_x, e_x in [(-2.2, -0.9), (-2.0, -0.8)]:
        L = abs(p_x - e_x)
        dec = decompose(corridor_half.spec.map, L)
        cell = dec.cell_at(e_x, 0.0, math.pi)
        assert cell is not None and cell.id in dec.escapable


@pytest.fixture(scope="module")
def two_rooms_small():
    """Fig. 6 in miniature: two 3 x 3 rooms and a corridor 0.5 wide, 4.5 long (> 2 L_max),
    where every cell is escapable even for an infinitely fast pursuer."""
    from envs.maps import Map

    return Map(
        [(0, 0), (3, 0), (3, 1.25), (7.5, 1.25), (7.5, 0), (10.5, 0), (10.5, 3), (7.5, 3),
         (7.5, 1.75), (3, 1.75), (3, 3), (0, 3)],
        name="two_rooms_small",
    )  # fmt: skip


def test_no_pursuer_certificate_where_the_theory_says_the_evader_wins(two_rooms_small):
    assert surveillance_verdict(two_rooms_small, L_MIN, L_MAX).evader_wins
    for rho in (0.1, 0.3):
        s = spec(two_rooms_small, rho)
        pb = solve_pursuer_bound(s, Resolution.for_role(s, "pursuer", 12, coarse=4))
        assert not pb.win.any()


def test_pursuer_bound_is_monotone_in_rho():
    world = open_room(5.0)
    res = Resolution(cell=1 / 15, coarse=4, tau=8 / 15)
    wins = [solve_pursuer_bound(spec(world, rho), res).win for rho in (0.1, 0.2, 0.25)]
    assert (wins[1] <= wins[0]).all() and (wins[2] <= wins[1]).all()
    assert wins[0].sum() > wins[2].sum()  # and not trivially


def test_evader_bound_is_monotone_in_rho():
    world = dead_end()
    res = Resolution(cell=1 / 10, coarse=4, tau=0.8)
    wins = [solve_evader_bound(spec(world, rho), res).win for rho in (0.3, 0.5, 0.8)]
    assert (wins[0] <= wins[1]).all() and (wins[1] <= wins[2]).all()
    assert wins[2].sum() > wins[0].sum()


def _labels_by_start(ref: Referee) -> dict:
    st = ref.lattice_starts()
    keys = map(tuple, np.round(np.hstack([st.pursuer, st.evader]), 9))
    return dict(zip(keys, st.label, strict=True))


def test_bounds_are_monotone_in_the_sensor_range():
    world = open_room(5.0)
    narrow = solve(spec(world, 0.2), 12, pursuer_coarse=4, evader_coarse=4, cache=False)
    wide_spec = type(narrow.spec)(world, L_MIN - 0.1, L_MAX + 0.2, 1.0, 0.2,
                                  body_radius=0.05)  # fmt: skip
    wide = solve(wide_spec, 12 * wide_spec.l_min / L_MIN, pursuer_coarse=4, evader_coarse=4,
                 cache=False)  # fmt: skip
    a, b = _labels_by_start(narrow), _labels_by_start(wide)
    common = a.keys() & b.keys()
    assert len(common) > 1000
    # a wider range helps the pursuer and hurts the evader, start by start
    assert all(b[k] == "pursuer" for k in common if a[k] == "pursuer")
    assert all(a[k] == "evader" for k in common if b[k] == "evader")
    assert sum(b[k] == "pursuer" for k in common) > sum(a[k] == "pursuer" for k in common)


def test_gap_shrinks_as_the_resolution_rises():
    s = spec(open_room(5.0), 0.2)
    gaps = [
        solve(s, cpl, pursuer_coarse=4, evader_coarse=2, cache=False).summary()["gap"]
        for cpl in (10, 12, 14)
    ]
    assert gaps[0] > gaps[1] > gaps[2]
    assert gaps[2] < 0.2


@pytest.mark.parametrize(
    "matrix", [((0, -1), (1, 0)), ((-1, 0), (0, -1)), ((1, 0), (0, -1))], ids=str
)
def test_labels_are_invariant_under_symmetries_of_the_lattice(matrix):
    # rotations by quarter turns and reflections about the bounding box's centre map the
    # cells and lattices onto themselves; with dyadic coordinates the answer is exact
    world = dead_end()
    R = np.array(matrix, dtype=float)
    c = np.array([1.25, 0.0])  # the bounding box's centre
    image = world.transformed(R, c - R @ c)
    kw = dict(pursuer_coarse=2, evader_coarse=2, cache=False)
    a = solve(spec(world, 0.5), 8, **kw)
    b = solve(spec(image, 0.5), 8, **kw)
    sa, sb = a.lattice_starts(), b.lattice_starts()
    f = lambda X: np.round(X @ R.T + (c - R @ c), 9)
    mapped = dict(zip(map(tuple, np.hstack([f(sa.pursuer), f(sa.evader)])), sa.label,
                      strict=True))  # fmt: skip
    other = dict(zip(map(tuple, np.round(np.hstack([sb.pursuer, sb.evader]), 9)), sb.label,
                     strict=True))  # fmt: skip
    assert mapped.keys() == other.keys()
    assert mapped == other
    assert set(mapped.values()) >= {"evader"}  # not a vacuous comparison


def test_safe_steps_never_break_under_the_env_kernels_sweep(open_slow):
    """An independent check of the pursuer bound's losing set: for states and moves it
    calls safe, random real evaders (anywhere in the cell, anywhere within reach at the
    step's end, moving straight as the env interpolates a step) never break surveillance
    under the geometry kernel's continuous sweep (the dead end: occlusion at its mouth)."""
    from envs.geometry import kernel_for
    from strategies.referee.pursuer_bound import _safe_tables, _unpack

    rng = np.random.default_rng(3)
    s = spec(dead_end(), 0.2)
    corridor = solve_pursuer_bound(s, Resolution.for_role(s, "pursuer", 16, coarse=4, steps=3))
    for pb in (corridor, open_slow.pursuer):
        lat, spec_ = pb.lattice, pb.spec
        ker = kernel_for(spec_.map)
        dom = pb._domain()
        safe = _safe_tables(lat, spec_, pb.res, pb.vectors, pb.targets, dom)
        g = spec_.v_evader * pb.res.tau
        checked = 0
        verts = spec_.map.vertices[spec_.map.vertex_convex]
        for j in rng.choice(len(pb.vectors), size=min(6, len(pb.vectors)), replace=False):
            ok = _unpack(safe[j], lat.W)
            k, a, b = np.nonzero(ok)
            if len(verts):  # mostly rods passing near a convex vertex: where occlusion is
                P, C = lat.points[k], lat.points[k] + lat.offsets[a, b]
                d = np.full(len(k), np.inf)
                for v in verts:
                    t = np.clip(np.einsum("ij,ij->i", v - P, C - P)
                                / np.einsum("ij,ij->i", C - P, C - P), 0, 1)  # fmt: skip
                    d = np.minimum(d, np.hypot(*(P + t[:, None] * (C - P) - v).T))
                near = np.flatnonzero(d < 0.5)
                k, a, b = k[near], a[near], b[near]
            for i in rng.choice(len(k), size=min(60, len(k)), replace=False):
                p0 = lat.points[k[i]]
                p1 = p0 + pb.vectors[j] * lat.h
                c = p0 + lat.offsets[a[i], b[i]]
                e0 = c + rng.uniform(-0.5, 0.5, 2) * lat.h
                angle = rng.uniform(0, 2 * np.pi)
                e1 = e0 + rng.uniform(0, g) * np.array([np.cos(angle), np.sin(angle)])
                ends = np.stack([e0, e1])
                clear = spec_.map.distance_to_walls(ends) >= spec_.opponent_clearance
                if not (clear.all() and spec_.map.contains(ends).all()):
                    continue  # not a real evader position
                if not ker.line_of_sight(p0, e0):
                    continue  # the step starts broken: not a state the pursuer is in
                event = ker.sweep(p0, e0, p1, e1, spec_.l_min, spec_.l_max)
                assert event is None, (p0, e0, p1, e1, event)
                checked += 1
        assert checked > 100


def test_broken_states_are_broken_for_every_pursuer_in_the_cell(corridor_half):
    """The evader bound's robust breaks, checked with the geometry kernel: every pursuer
    position in the cell is out of range or out of sight of the evader."""
    from envs.geometry import kernel_for
    from envs.surveillance.rules import surveillance_status

    eb = corridor_half.evader
    lat, spec = eb.lattice, corridor_half.spec
    ker = kernel_for(spec.map)
    live = eb._domain() & (eb.rank == 0)  # robustly broken, not merely out of range
    k, a, b = np.nonzero(live)
    assert len(k) > 50
    rng = np.random.default_rng(4)
    checked = 0
    for i in rng.choice(len(k), size=min(300, len(k)), replace=False):
        e = lat.points[k[i]]
        c = e + lat.offsets[a[i], b[i]]
        for _ in range(5):
            p = c + rng.uniform(-0.5, 0.5, 2) * lat.h
            if not spec.map.contains(p[None])[0]:
                continue
            if spec.map.distance_to_walls(p[None])[0] < spec.opponent_clearance:
                continue
            status = surveillance_status(ker, tuple(p), tuple(e), spec.l_min, spec.l_max)
            assert not status.holds, (p, e)
            checked += 1
    assert checked > 100


@pytest.mark.slow
def test_pursuer_bound_sees_past_a_jamb_an_evader_that_keeps_its_clearance():
    """Two 5 x 5 rooms joined by a corridor 3 long and 2 wide, L in [1, 2], rho = 0.3,
    16 cells per L_min: the evader leading the pursuer through the corridor could always
    hide round a mouth's jamb while its disc could lie on the wall (the bound certified no
    state); an evader that keeps ``opponent_clearance`` from the walls cannot stand on the
    rod's ray beside the wall, and the bound certifies most states (95.7 %)."""
    world = Map(
        [(-8, -2.5), (-3, -2.5), (-3, -1), (0, -1), (0, -2.5), (5, -2.5), (5, 2.5), (0, 2.5),
         (0, 1), (-3, 1), (-3, 2.5), (-8, 2.5)],
        name="two_small_rooms",
    )  # fmt: skip
    spec = GameSpec(world, 1.0, 2.0, 1.0, 0.3, body_radius=0.1)
    res = Resolution.for_role(spec, "pursuer", 16, coarse=4, steps=3, dt=0.1)
    pb = solve_pursuer_bound(spec, res)
    assert pb.fraction() > 0.9
