"""Issue 10: a rectilinear wall's end cap on the pole of a conchoid's implicit function.

``floor_plan(0, n_vertices=1000, size=200)`` at L = 3.2 warned "2 boundary pieces matched
by overlap only; 2 dangling": at a doorway, the conchoid of the end cap's upper corner
(tip on the wall above) ends at that corner, which lies on the vertical through the
lower corner, i.e. on the line through the other conchoid's vertex parallel to its edge
(a vertical wall below). The conchoids' implicit function was the distance along the
rod, infinite on that line, so the last sample before the end read ``inf``, the crossing
of the two conchoids in that last interval was never bracketed, and the two curves
crossed without a vertex (each then had the same face on both sides). The world below is
the doorway cropped to eight vertices; it reproduced at every translation and scale.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from envs.maps import Map
from strategies.cspace._shapes import CONCHOID, implicit, points
from tests.strategies.cspace._oracle import exact_decomposition, fingerprint, stops_constant

END_CAP = [
    (1.5, 2.75), (1.5, -3.5), (-0.26, -3.5), (-0.26, 0),
    (0, 0), (0, 0.25), (-3, 0.25), (-3, 2.75),
]  # fmt: skip
L = 3.2


def end_cap() -> Map:
    """A wall 0.25 thick ending at x = 0 (corners (0, 0) and (0, 0.25)), a wall above
    it 2.5 higher, and one going down from 0.26 left of its end."""
    return Map(END_CAP, name="end_cap")


@pytest.fixture(scope="module")
def base():
    return exact_decomposition(end_cap(), L)


def test_the_end_cap_is_exact(base):
    n, bad = stops_constant(base, np.random.default_rng(10), per_region=4)
    assert not bad, bad[:5]
    assert n > 2 * len(base.regions)


@pytest.mark.parametrize(
    ("scale", "offset"),
    [(1.0, (0.5, 0.0)), (1.0, (163.228212, 186.0125)), (1.0, (1e6, -1e6)),
     (1e-3, (0.0, 0.0)), (7.0, (-3.0, 2.0)), (1e3, (0.0, 0.0))],
)  # fmt: skip
def test_counts_are_invariant_under_translation_and_scaling(base, scale, offset):
    moved = exact_decomposition(
        end_cap().transformed([[scale, 0.0], [0.0, scale]], offset), L * scale
    )
    assert fingerprint(moved) == fingerprint(base)


@pytest.mark.parametrize("angle", [0.5 * math.pi, 0.7137])
def test_counts_are_invariant_under_rotation(base, angle):
    c, s = math.cos(angle), math.sin(angle)
    moved = exact_decomposition(end_cap().transformed([[c, -s], [s, c]]), L)
    assert fingerprint(moved) == fingerprint(base)


def test_conchoid_implicit_is_finite_on_its_pole_line():
    """On the line through v parallel to the edge, the rod never reaches the edge's line:
    the function stays finite there, with the sign it has on either side."""
    # v = (0, 0), tip on the vertical line x = -0.26 (u pointing down)
    data = np.array([0.0, 0.0, -0.26, 0.0, 0.0, -1.0])
    eps = 1e-9
    for y in (0.25, -0.25, 1.0, 3.0):
        f = implicit(CONCHOID, data, np.array([[0.0, y], [eps, y], [-eps, y]]), L)
        assert np.all(np.isfinite(f)), (y, f)
        assert np.sign(f[0]) == np.sign(f[1]) == np.sign(f[2]), (y, f)
    # it vanishes on the conchoid
    t = np.linspace(-5.0, 5.0, 41)
    p = points(np.full(len(t), CONCHOID), np.broadcast_to(data, (len(t), 6)), t, L)
    on = implicit(CONCHOID, np.broadcast_to(data, (len(t), 6)), p, L)
    assert np.all(np.abs(on) < 1e-12 * L)
