"""The computed cases behind the figures agree with independent computations."""

from __future__ import annotations

import math

import numpy as np
import pytest

from analysis.figures import cases, worlds
from strategies.control import shoot, solve_escape, theta_dot
from strategies.cspace import candidate_lengths, critical_lengths


@pytest.mark.parametrize(
    ("width", "matrix", "offset"),
    [
        (5.0, np.eye(2), (0.0, 0.0)),
        (3.0, [[0.6, -0.8], [0.8, 0.6]], (17.0, -4.0)),  # rotated, off-centre
    ],
)
def test_the_l_hall_event_is_the_triple_point_anywhere(width, matrix, offset):
    """Erratum E10: the hall changes at L = (2 - sqrt 2) w, a length no vertex-vertex or
    vertex-edge distance (nor half of one) explains, in any position."""
    world = worlds.l_hall(width).transformed(matrix, offset)
    star = (2.0 - math.sqrt(2.0)) * width
    lo, hi = star - 0.02 * width, star + 0.02 * width
    assert candidate_lengths(world, lo, hi) == ()
    found = critical_lengths(world, lo, hi, tol=1e-4 * width)
    assert found and min(abs(c - star) for c in found) < 2e-4 * width


def test_the_default_l_hall_event():
    ev = cases.l_hall_event()
    assert abs(ev.event - (8.0 - 4.0 * math.sqrt(2.0))) < 2e-4
    assert min(abs(c - ev.event) for c in ev.candidates) > 0.3


@pytest.mark.parametrize("which", ["a", "b"])
def test_fitted_rho_reproduces_the_printed_multipliers(which):
    """At the fitted rho the printed shot returns at x_e, and solve_escape (which shoots on
    the initial heading, not on the multipliers) finds the same k."""
    p = cases.PAPER_SHOTS[which]
    rho = cases.paper_shot_rho(which)
    arc = shoot(p["theta0"], p["lambda1"], p["lambda2_0"], L=1.0, rho=rho, x_max=3.0)
    assert arc.x_c == pytest.approx(p["x_e"], abs=1e-9)
    sol = solve_escape(p["theta0"], p["x_e"], L=1.0, rho=rho)
    assert sol.success
    assert sol.k == pytest.approx(p["lambda1"] / (1.0 + p["lambda2_0"]), rel=1e-6)
    assert abs(sol.arc.lambda2[-1]) < 1e-9  # transversality, E3c


def test_charge_rotation_closed_form_and_integration_agree():
    """Sec. 7.2's elliptic closed form gives the time at which eq. (6), integrated,
    reaches pi/2."""
    rot = cases.charge_rotation()
    assert rot.theta[0] == pytest.approx(math.pi)
    assert rot.theta[-1] == pytest.approx(0.5 * math.pi, abs=1e-8)
    assert np.all(np.diff(rot.theta) < 0)  # clockwise all along
    rate = theta_dot(math.pi, rot.theta, L=rot.L, v_p=rot.v_p, rho=rot.rho)[1]
    assert np.allclose(np.gradient(rot.theta, rot.t), rate, atol=1e-3)
    assert 0.0 < rot.recoil < rot.rho * rot.v_p * rot.T
    e, p = rot.positions((3.0, 0.0))
    assert np.allclose(np.hypot(*(p - e).T), rot.L)


def test_growth_is_monotone_in_l():
    """Prop. 3: a point whose cells are all escapable keeps only escapable cells as L
    grows (checked at every region's sample point of the shorter length)."""
    for case in cases.growth_cases():
        for r in case.before.regions:
            cells = [case.before.cells[c] for c in r.cells]
            if cells and all(c.escapable for c in cells):
                arcs = case.after.free_arcs(r.point)
                assert all(a.escapable is not False for a in arcs), (case.label, r.point)


def test_escape_chains_descend_through_adjacent_cells():
    dec = cases.corridor()
    for chain in (cases.corridor_chain(), cases.mouth_chain()):
        assert chain.ranks[-1] == 0 and list(chain.ranks) == sorted(chain.ranks, reverse=True)
        assert len(set(chain.ranks)) == len(chain.ranks)
        for a, b in zip(chain.cells, chain.cells[1:], strict=False):
            assert dec.graph.has_edge(a, b)
        assert all(dec.cells[c].escapable for c in chain.cells)
    first = dec.cells[cases.mouth_chain().cells[0]]
    assert cases.dead_end_side(dec, first.id)


def test_escape_cases_are_consistent():
    """The optimal arc starts at the evader and ends on the endpoint, and the verdict is
    the comparison of the rotations."""
    for case in (cases.vertex_escape(), cases.curve_escape()):
        assert np.allclose(case.evader_path[0], case.evader)
        assert np.allclose(case.pursuer_path[0], case.pursuer)
        assert np.allclose(case.evader_path[-1], case.target.position, atol=1e-6)
        assert case.evader_escapes == (case.achieved < case.needed)
