"""Tests of the grid oracle for the Section 4 verdict (tests/oracles/grid_oracle.py)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from shapely.geometry import LineString

from envs.errors import InvalidConfigError, InvalidPlacementError
from envs.maps import Map
from tests.oracles import grid_oracle as go

L = 2.0  # L = L_min = 2, corridor width 1 (THEORY 3)


# ------------------------------------------------------------------ the paper's worlds
def corridor_world() -> Map:
    """Fig. 3: room [0, 10] x [-5, 5] and a dead-end corridor [-6, 0] x [-0.5, 0.5]."""
    return Map(
        [(0, -5), (10, -5), (10, 5), (0, 5), (0, 0.5), (-6, 0.5), (-6, -0.5), (0, -0.5)],
        name="fig3",
    )


def two_rooms_world() -> Map:
    """Fig. 6: Fig. 3 with a second room [-16, -6] x [-5, 5] at the corridor's far end."""
    return Map(
        [
            (-16, -5),
            (-6, -5),
            (-6, -0.5),
            (0, -0.5),
            (0, -5),
            (10, -5),
            (10, 5),
            (0, 5),
            (0, 0.5),
            (-6, 0.5),
            (-6, 5),
            (-16, 5),
        ],
        name="fig6",
    )


def open_room() -> Map:
    return Map([(0, -5), (10, -5), (10, 5), (0, 5)], name="open")


def pocket_room() -> Map:
    """A room with a concave pocket [-1.5, 0] x [-0.5, 0.5]: narrower and shorter than L."""
    return Map(
        [(0, -5), (10, -5), (10, 5), (0, 5), (0, 0.5), (-1.5, 0.5), (-1.5, -0.5), (0, -0.5)],
        name="pocket",
    )


def random_rect_map(seed: int, size: float = 8.0) -> Map:
    """A square room with 1-3 seeded random rectangular pillars (retry on overlap)."""
    rng = np.random.default_rng(seed)
    while True:
        rects = []
        for _ in range(int(rng.integers(1, 4))):
            w, h = rng.uniform(0.5, 2.5, size=2)
            x, y = rng.uniform(0.6, size - 0.6 - w), rng.uniform(0.6, size - 0.6 - h)
            rects.append([(x, y), (x + w, y), (x + w, y + h), (x, y + h)])
        try:
            return Map([(0, 0), (size, 0), (size, size), (0, size)], rects, name=f"rnd{seed}")
        except ValueError:
            continue


# ------------------------------------------------------------------ helpers
def test_arcs_overlap_matches_sampling():
    rng = np.random.default_rng(0)
    n = 400
    lo1 = rng.uniform(-math.pi, math.pi, n)
    lo2 = rng.uniform(-math.pi, math.pi, n)
    hi1 = lo1 + rng.uniform(0, 2 * math.pi, n)
    hi2 = lo2 + rng.uniform(0, 2 * math.pi, n)
    got = go._arcs_overlap(lo1, hi1, lo2, hi2)
    th = np.linspace(-math.pi, math.pi, 20001)[:-1]

    def inside(lo, hi):
        return ((th[None] - lo[:, None]) % (2 * math.pi)) <= (hi - lo)[:, None]

    want = np.any(inside(lo1, hi1) & inside(lo2, hi2), axis=1)
    # sampling resolves overlaps wider than its step; skip the few borderline cases
    margin = np.minimum.reduce(
        [
            np.abs(((a - b + math.pi) % (2 * math.pi)) - math.pi)
            for a, b in [(lo1, hi2), (lo2, hi1), (lo1, lo2), (hi1, hi2)]
        ]
    )
    ok = margin > 1e-3
    assert ok.sum() > 350
    np.testing.assert_array_equal(got[ok], want[ok])


@pytest.mark.parametrize(
    ("a", "b", "expected"),
    [
        ((3.0, 3.5), (-3.1, -3.0), True),  # wraps across +pi
        ((-math.pi, math.pi), (1.0, 1.0 + 1e-6), True),  # full circle meets everything
        ((-math.pi, math.pi), (-math.pi, math.pi), True),
        ((0.0, 1.0), (1.0, 2.0), False),  # touching at a stop only
        ((2.0, 2 * math.pi - 1.0), (-1.0, 0.0), False),  # hi = pi + (pi - 1) touches -1 + 2pi
        ((2.0, 2 * math.pi - 0.9), (-1.0, 0.0), True),
        ((0.5, 0.5), (0.0, 1.0), False),  # a zero-width arc overlaps nothing
    ],
)
def test_arcs_overlap_cases(a, b, expected):
    assert bool(go._arcs_overlap(np.array(a[0]), np.array(a[1]), *map(np.array, b))) is expected
    assert bool(go._arcs_overlap(np.array(b[0]), np.array(b[1]), *map(np.array, a))) is expected


def test_steps_clear_matches_shapely():
    m = random_rect_map(3)
    rng = np.random.default_rng(1)
    pts = rng.uniform(0.01, 7.99, size=(4000, 2))
    pts = pts[m.contains(pts) & (m.distance_to_walls(pts) > 1e-6)]
    a, b = pts[: len(pts) // 2], pts[len(pts) // 2 : 2 * (len(pts) // 2)]
    # short steps like the grid's, and long ones that cross obstacles
    b_short = a + rng.uniform(-0.6, 0.6, size=a.shape)
    keep = m.contains(b_short) & (m.distance_to_walls(b_short) > 1e-6)
    for p, q in ((a, b), (a[keep], b_short[keep])):
        got = go._steps_clear(m, p, q)
        region = m.free_region
        want = np.array([region.covers(LineString([u, v])) for u, v in zip(p, q, strict=True)])
        np.testing.assert_array_equal(got, want)
    # steps through an obstacle from vertex to vertex (no proper crossing at all)
    sq = Map([(0, 0), (4, 0), (4, 4), (0, 4)], [[(1, 1), (2, 1), (2, 2), (1, 2)]])
    a = np.array([[0.5, 0.5], [0.5, 2.5], [0.5, 0.5]])
    b = np.array([[2.5, 2.5], [2.5, 0.5], [2.5, 0.5]])
    assert go._steps_clear(sq, a, b).tolist() == [False, False, True]
    # grazing along an obstacle edge or touching a corner is allowed for the evader
    a = np.array([[0.5, 1.0], [1.5, 2.5]])
    b = np.array([[2.5, 1.0], [2.5, 1.5]])
    assert go._steps_clear(sq, a, b).tolist() == [True, True]


def naive_fixed_point(g: go.GridGraph) -> np.ndarray:
    """The escapable-cell definition iterated literally until nothing changes."""
    overl = {}
    for a, b, _e in g.overlap.tolist():
        overl.setdefault(a, set()).add(b)
        overl.setdefault(b, set()).add(a)
    nbrs = {}
    for i, j in g.point_edges.tolist():
        nbrs.setdefault(i, []).append(j)
        nbrs.setdefault(j, []).append(i)
    esc = np.zeros(g.n_nodes, dtype=bool)
    changed = True
    while changed:
        changed = False
        for a in range(g.n_nodes):
            if esc[a]:
                continue
            p = int(g.node_point[a])
            for q in nbrs.get(p, []):
                at_q = [b for b in overl.get(a, ()) if g.node_point[b] == q]
                if all(esc[b] for b in at_q):  # (a) when at_q is empty, else (b)
                    esc[a] = True
                    changed = True
                    break
    return esc


@pytest.mark.parametrize("world", [corridor_world, pocket_room])
def test_worklist_equals_naive_fixed_point(world):
    g = go.grid_graph(world(), L, resolution=0.5)
    esc = g.escapable
    np.testing.assert_array_equal(esc, naive_fixed_point(g))
    assert 0 < esc.sum() < g.n_nodes


def test_graph_structure():
    m = corridor_world()
    g = go.grid_graph(m, L, resolution=0.5)
    assert np.all(m.contains(g.points)) and np.all(m.distance_to_walls(g.points) > 0)
    step = np.linalg.norm(g.points[g.point_edges[:, 0]] - g.points[g.point_edges[:, 1]], axis=1)
    assert np.allclose(step[step < 0.6], 0.5) and np.allclose(step[step >= 0.6], 0.5 * math.sqrt(2))
    # the thin wall between room and corridor blocks steps across it
    region = m.free_region
    for i, j in g.point_edges[:: max(1, len(g.point_edges) // 300)].tolist():
        assert region.covers(LineString([g.points[i], g.points[j]]))
    a, b, e = g.overlap.T
    assert np.all(g.node_point[a] == g.point_edges[e, 0])
    assert np.all(g.node_point[b] == g.point_edges[e, 1])
    g4 = go.grid_graph(m, L, resolution=0.5, neighbourhood=4)
    assert len(g4.point_edges) < len(g.point_edges)


# ------------------------------------------------------------------ the paper's verdicts
def test_fig3_corridor_pursuer_wins():
    m = corridor_world()
    v = go.grid_verdict(m, L, resolution=0.2)
    assert not v.evader_wins and v.witness_point is None
    assert 0 < v.n_escapable < v.n_nodes
    for x in (-3.5, -2.0, -0.5):  # more than L from the dead end, so theta = pi is free
        # pursuer on the dead-end side (kappa_iL): the evader walks out and turns a corner
        assert go.grid_escapable(m, L, (x, 0.0), math.pi, resolution=0.2)
        # pursuer on the room side (kappa_iR): safe ("never be on the dead-end side")
        assert not go.grid_escapable(m, L, (x, 0.0), 0.0, resolution=0.2)
    # the room's stop-free middle is safe
    assert len(go.grid_safe_arcs(m, L, (5.0, 0.0), resolution=0.2)) == 1


def test_fig6_two_rooms_evader_wins_everywhere():
    v = go.grid_verdict(two_rooms_world(), L, resolution=0.25)
    assert v.evader_wins and v.witness_point is not None
    assert v.n_escapable == v.n_nodes


def test_open_room_pursuer_wins():
    m = open_room()
    v = go.grid_verdict(m, L, resolution=0.2)
    assert not v.evader_wins and v.witness_point is None
    # the only escapable nodes are room-corner pockets (type 2 about a concave corner,
    # THEORY 1.4): P within L of both walls of a corner but farther than L from the corner
    # itself, the rod pointing into the corner; walking at the corner crushes the pocket
    g = go.grid_graph(m, L, resolution=0.2)
    corners = m.vertices
    pts = g.points[g.node_point[g.escapable]]
    d_corner = np.linalg.norm(pts[:, None] - corners[None], axis=2)
    mid = 0.5 * (g.node_lo + g.node_hi)[g.escapable]
    toward = np.arctan2(
        corners[None, :, 1] - pts[:, None, 1], corners[None, :, 0] - pts[:, None, 0]
    )
    aims = np.abs((mid[:, None] - toward + math.pi) % (2 * math.pi) - math.pi) < 0.5
    assert len(pts) > 0 and np.all(
        np.any(aims & (d_corner > L) & (d_corner < L * math.sqrt(2)), axis=1)
    )
    assert go.grid_escapable(m, L, (8.5, -3.5), -math.pi / 4, resolution=0.2)
    assert not go.grid_escapable(m, L, (8.5, -3.5), math.pi / 2, resolution=0.2)
    # the rod cannot fit anywhere (L beyond the diagonal): Prop. 5, vacuously all escapable
    v = go.grid_verdict(m, 15.0, resolution=0.5)
    assert v.evader_wins and v.n_nodes == 0 and v.n_points > 0


def test_pocket_forces_pursuer_into_corner():
    """A concave pocket narrower and shorter than L (Sec. 4, type-2 "forced into a corner")."""
    m = pocket_room()
    v = go.grid_verdict(m, L, resolution=0.2)
    assert not v.evader_wins and v.n_escapable > 0
    # pursuer inside the pocket: the evader walks at it and pushes it into the dead end
    assert go.grid_escapable(m, L, (0.8, 0.0), math.pi, resolution=0.2)
    assert not go.grid_escapable(m, L, (0.8, 0.0), 0.0, resolution=0.2)


@pytest.mark.parametrize(
    ("world", "res", "wins"),
    [(corridor_world, 0.4, False), (two_rooms_world, 0.4, True), (pocket_room, 0.4, False)],
)
def test_verdict_stable_as_resolution_halves(world, res, wins):
    m = world()
    verdicts = [go.grid_verdict(m, L, resolution=r).evader_wins for r in (res, res / 2)]
    assert verdicts == [wins, wins]


@pytest.mark.parametrize("seed", range(4))
def test_prop3_monotone_in_L(seed):
    """Prop. 3: arcs shrink as L grows, so escapability at L persists at every L' > L."""
    m = random_rect_map(seed)
    g1 = go.grid_graph(m, 1.5, resolution=0.35)
    g2 = go.grid_graph(m, 2.5, resolution=0.35)
    np.testing.assert_array_equal(g1.points, g2.points)
    assert g1.escapable.any()
    # each arc at L' lies inside an arc at L of the same point: it inherits escapability
    mid2 = 0.5 * (g2.node_lo + g2.node_hi)
    for b in range(g2.n_nodes):
        p = g2.node_point[b]
        nodes = np.arange(g1.node_ptr[p], g1.node_ptr[p + 1])
        d = (mid2[b] - g1.node_lo[nodes]) % (2 * math.pi)
        host = nodes[d <= g1.node_hi[nodes] - g1.node_lo[nodes] + 1e-9]
        assert len(host) == 1
        if g1.escapable[host[0]]:
            assert g2.escapable[b]
    assert np.all(g2.point_escapable[g1.point_escapable])
    if go.grid_verdict(m, 1.5, resolution=0.35).evader_wins:
        assert go.grid_verdict(m, 2.5, resolution=0.35).evader_wins


# ------------------------------------------------------------------ bad input
def test_bad_input():
    m = open_room()
    for bad in (0.0, -1.0, math.nan, math.inf):
        with pytest.raises(InvalidConfigError, match="L"):
            go.grid_verdict(m, bad, resolution=0.5)
        with pytest.raises(InvalidConfigError, match="resolution"):
            go.grid_verdict(m, L, resolution=bad)
    with pytest.raises(InvalidConfigError, match="neighbourhood"):
        go.grid_graph(m, L, resolution=0.5, neighbourhood=6)
    with pytest.raises(InvalidConfigError, match="grid points"):
        go.grid_graph(m, L, resolution=1e-4)
    with pytest.raises(InvalidPlacementError, match="free space"):
        go.grid_safe_arcs(m, L, (20.0, 0.0), resolution=0.5)
    with pytest.raises(InvalidPlacementError, match="point"):
        go.grid_safe_arcs(m, L, (1.0, math.nan), resolution=0.5)
    with pytest.raises(InvalidPlacementError, match="blocked"):
        go.grid_escapable(m, L, (0.5, 0.0), math.pi, resolution=0.5)  # the rod hits x = 0
    with pytest.raises(InvalidConfigError, match="Map"):
        go.grid_verdict("fig3", L, resolution=0.5)
