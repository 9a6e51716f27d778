"""The referee's claims, checked: closed-form cases, consistency of the two bounds,
monotonicity in rho, in the sensor range and in resolution, symmetry, and the
decomposition theory's verdicts in the limit of a fast pursuer."""

from __future__ import annotations

import math

import numpy as np
import pytest

from strategies.cspace import decompose, surveillance_verdict
from strategies.referee import Referee, Resolution, solve, solve_evader_bound, solve_pursuer_bound
from tests.strategies.referee.conftest import L_MAX, L_MIN, dead_end, open_room, spec


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
