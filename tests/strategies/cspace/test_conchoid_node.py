"""Two conchoids crossing close to one's vertex: both crossings in one sample interval.

Found by a random sweep (two triangles in a room, turned by 3.3096 rad, L = 3.8902:
"5 boundary pieces matched by overlap only; 1 dangling"; unturned it was exact). The
type-5 loop of vertex v (through v, tip on a far edge) was crossed twice by another
conchoid within 0.06 of each other, 0.03 from v, where the other conchoid ends on a wall
beside v. Near its vertex a conchoid's implicit function changes sign on two lines
through v, whatever the distance, so a curve passing close to v crosses both in a short
stretch: here inside one sample interval, with the same sign at both of its samples.
Both crossings were lost, and the conchoid's last piece had one face on both sides.
The samples of a curve followed against a conchoid are now refined about the conchoid's
vertex until each interval turns less than the angle between those lines.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from envs.maps import Map
from strategies.cspace._intersect import node_sweep, refine_about, sampled_roots
from strategies.cspace._shapes import CONCHOID, points
from tests.strategies.cspace._oracle import exact_decomposition, fingerprint, stops_constant

ROOM = [(0.0, 0.0), (11.10604969912589, 0.0), (11.10604969912589, 10.906834875630896),
        (0.0, 10.906834875630896)]  # fmt: skip
TRIANGLES = [
    [(4.907017766304227, 5.725285589209816), (7.019077701528101, 5.161349906301952),
     (6.451430361414899, 7.272415305975075)],
    [(3.8140485189010964, 2.175789236021928), (3.0995163017948637, 3.36993244825105),
     (2.422624052800808, 2.154057790300074)],
]  # fmt: skip
ANGLE = 3.309600274279494
L = 3.8902


def _turned(angle: float, scale: float = 1.0, offset=(0.0, 0.0)) -> Map:
    c, s = scale * math.cos(angle), scale * math.sin(angle)
    return Map(ROOM, TRIANGLES, name="two_triangles").transformed([[c, -s], [s, c]], offset)


@pytest.fixture(scope="module")
def base():
    return exact_decomposition(_turned(0.0), L)


def test_the_turned_world_is_exact(base):
    dec = exact_decomposition(_turned(ANGLE), L)
    assert fingerprint(dec) == fingerprint(base)
    n, bad = stops_constant(dec, np.random.default_rng(7), per_region=3)
    assert not bad, bad[:5]
    assert n > 2 * len(dec.regions)


@pytest.mark.parametrize(
    ("angle", "scale", "offset"),
    [(ANGLE, 1e-3, (0.0, 0.0)), (ANGLE, 1e3, (0.0, 0.0)), (ANGLE, 1.0, (1e6, -1e6)),
     (ANGLE + math.pi, 1.0, (0.0, 0.0)), (0.5 * math.pi, 1.0, (0.0, 0.0))],
)  # fmt: skip
def test_counts_are_invariant(base, angle, scale, offset):
    dec = exact_decomposition(_turned(angle, scale, offset), L * scale)
    assert fingerprint(dec) == fingerprint(base)


def test_both_crossings_near_the_vertex_are_found():
    """A conchoid passing 0.03 from another's vertex crosses its loop twice, 0.06 apart:
    both roots are found after the refinement (neither before)."""
    world = _turned(ANGLE)
    v9 = world.vertices[9]
    # conchoid A: vertex 7, tip on edge 3; conchoid B: vertex 9, tip on edge 2
    a_row = np.r_[world.vertices[7], world.edge_start[3], world.edge_dir[3]]
    b_row = np.r_[v9, world.edge_start[2], world.edge_dir[2]]
    lo, hi = 0.5892078654096538, 5.115962301812026
    end = points(CONCHOID, a_row, np.array([hi]), L)[0]
    assert np.hypot(*(end - v9)) < 0.04  # A ends on a wall beside B's vertex
    n = 32
    t = np.sort(np.r_[np.linspace(lo, hi, n + 1)])
    owner = np.zeros(len(t), dtype=np.intp)
    kind = np.array([CONCHOID])

    def roots(owner, t):
        _, tr, _ = sampled_roots(kind, a_row[None], owner, t, kind, b_row[None], L, 1e-12)
        return np.sort(tr[(tr > 5.0) & (tr < hi)])

    assert len(roots(owner, t)) == 0  # one interval holds both: the old miss
    sweep = node_sweep(b_row[None], L)
    o2, t2 = refine_about(kind, a_row[None], owner, t, v9[None], sweep, L, 1e-9)
    assert len(t2) > len(t)
    np.testing.assert_allclose(roots(o2, t2), [5.0335, 5.0933], atol=1e-3)
