"""THEORY.md 1.4: how each critical-curve crossing shows up in the free arcs and stops.

World: obstacle [-2, 0]^2 (convex vertex at the origin), L = 1, points 0.02 to each side
of a curve. Labels are compared as (kind, feature) pairs.
"""

from __future__ import annotations

import math

import numpy as np

from envs.geometry import FreeArcs, Stop, kernel_for
from envs.maps import Feature, Map
from tests.envs.geometry._maps import square_obstacle_map

L = 1.0
OFF = 0.02
SQUARE = [(-2, -2), (0, -2), (0, 0), (-2, 0)]


def _edge(world: Map, a, b) -> Feature:
    for e in range(world.n_edges):
        s, t = world.edge_start[e], world.edge_end[e]
        if {tuple(s), tuple(t)} == {tuple(map(float, a)), tuple(map(float, b))}:
            return Feature("edge", e)
    raise AssertionError(f"no edge {a}-{b}")


def _vertex(world: Map, v) -> Feature:
    i = np.flatnonzero(np.all(world.vertices == np.asarray(v, float), axis=1))
    assert len(i) == 1
    return Feature("vertex", int(i[0]))


def _stops(fa: FreeArcs) -> list[tuple[Stop | None, Stop | None]]:
    return [(a.stop_lo, a.stop_hi) for a in fa.arcs]


def _stop_set(fa: FreeArcs) -> set[Stop]:
    return {s for a in fa.arcs for s in (a.stop_lo, a.stop_hi) if s is not None}


def test_type1_line_above_the_top_edge():
    world = square_obstacle_map()
    k = kernel_for(world)
    top = _edge(world, (-2, 0), (0, 0))
    below = k.free_arcs((-1, 1 - OFF), L)
    above = k.free_arcs((-1, 1 + OFF), L)
    assert _stops(below) == [(Stop("tip", top), Stop("tip", top))]
    # the blocked part is centred straight down (theta = -pi/2), width 2 acos(0.98)
    blocked = 2 * math.pi - below.arcs[0].width
    assert math.isclose(blocked, 2 * math.acos(1 - OFF), rel_tol=1e-12)
    assert not below.contains(-math.pi / 2)
    assert above.is_full


def test_type2_convex_vertex_inside_the_normal_cone():
    world = square_obstacle_map()
    k = kernel_for(world)
    d = np.array([1.0, 1.0]) / math.sqrt(2)
    inside = k.free_arcs((L - OFF) * d, L)
    outside = k.free_arcs((L + OFF) * d, L)
    top = _edge(world, (-2, 0), (0, 0))
    right = _edge(world, (0, 0), (0, -2))
    assert len(inside.arcs) == 1
    assert _stop_set(inside) == {Stop("tip", top), Stop("tip", right)}
    assert outside.is_full


def test_type2_convex_vertex_outside_the_normal_cone_switches_one_stop():
    world = square_obstacle_map()
    k = kernel_for(world)
    d = np.array([-0.3, math.sqrt(1 - 0.09)])  # unit, above the top edge
    inside = k.free_arcs((L - OFF) * d, L)
    outside = k.free_arcs((L + OFF) * d, L)
    top = _edge(world, (-2, 0), (0, 0))
    v = _vertex(world, (0, 0))
    assert len(inside.arcs) == len(outside.arcs) == 1
    assert _stops(inside) == [(Stop("body", v), Stop("tip", top))]
    assert _stops(outside) == [(Stop("tip", top), Stop("tip", top))]


def test_type4_extension_of_an_edge_switches_one_stop():
    world = square_obstacle_map()
    k = kernel_for(world)
    top = _edge(world, (-2, 0), (0, 0))
    right = _edge(world, (0, 0), (0, -2))
    v = _vertex(world, (0, 0))
    above = k.free_arcs((0.5, OFF), L)
    below = k.free_arcs((0.5, -OFF), L)
    assert _stops(above) == [(Stop("tip", right), Stop("tip", top))]
    assert _stops(below) == [(Stop("tip", right), Stop("body", v))]
    # beyond the curve's end (more than L from the vertex) nothing changes
    far_above = k.free_arcs((1.5, OFF), L)
    far_below = k.free_arcs((1.5, -OFF), L)
    assert _stops(far_above) == _stops(far_below)


def test_type3_line_through_two_convex_vertices_pinches_an_arc():
    # v1 = (0, 0) of the square; v2 = (1, -0.5), the lower-left corner of a block above
    # the line through v1 and v2 (the square lies below it): the rod can slip between
    world = Map(
        [(-5, -5), (5, -5), (5, 5), (-5, 5)],
        [SQUARE, [(1, -0.5), (2, -0.5), (2, 0.5), (1, 0.5)]],
    )
    k = kernel_for(world)
    L3 = 1.5
    u = np.array([-1.0, 0.5]) / math.sqrt(1.25)  # from v2 through v1, onwards
    n = np.array([-u[1], u[0]])
    P = 0.2 * u
    v1, v2 = _vertex(world, (0, 0)), _vertex(world, (1, -0.5))
    a = k.free_arcs(P + OFF * n, L3)
    b = k.free_arcs(P - OFF * n, L3)
    pinched = {Stop("body", v1), Stop("body", v2)}
    with_pinch = [fa for fa in (a, b) if any({x.stop_lo, x.stop_hi} == pinched for x in fa.arcs)]
    assert len(with_pinch) == 1
    other = b if with_pinch[0] is a else a
    assert len(with_pinch[0].arcs) == len(other.arcs) + 1
    # the pinched arc points along the line from P through v1 to v2
    arc = next(x for x in with_pinch[0].arcs if {x.stop_lo, x.stop_hi} == pinched)
    assert arc.contains(math.atan2(-u[1], -u[0]), 0.05)
    assert arc.width < 0.1


def _conchoid_sides(world: Map, v, qx: float) -> tuple[FreeArcs, FreeArcs]:
    """Free arcs 0.02 to each side of the type-5 curve of vertex v and the wall y = -2.5."""
    k = kernel_for(world)
    v = np.asarray(v, float)

    def on_curve(x: float) -> np.ndarray:  # P = Q + L (v - Q) / |v - Q|, Q on the wall
        Q = np.array([x, -2.5])
        return Q + L * (v - Q) / np.linalg.norm(v - Q)

    P = on_curve(qx)
    tangent = on_curve(qx + 1e-6) - on_curve(qx - 1e-6)
    n = np.array([-tangent[1], tangent[0]]) / np.linalg.norm(tangent)
    return k.free_arcs(P + OFF * n, L), k.free_arcs(P - OFF * n, L)


def test_type5_conchoid_switches_one_stop():
    # a thin obstacle whose leftmost vertex v = (0, -2) lies h = 0.5 above the wall
    # y = -2.5, on the wall's side of the rod: the stop switches tip-on-edge <-> body-on-v
    room = [(-5, -2.5), (5, -2.5), (5, 5), (-5, 5)]
    world = Map(room, [[(0, -2), (0.6, -2.3), (0.9, -2.1)]])
    a, b = _conchoid_sides(world, (0, -2), -0.3)
    assert len(a.arcs) == len(b.arcs) == 1
    body = Stop("body", _vertex(world, (0, -2)))
    tip = Stop("tip", _edge(world, (-5, -2.5), (5, -2.5)))
    assert _stop_set(a) ^ _stop_set(b) == {body, tip}
    (sa_lo, sa_hi), (sb_lo, sb_hi) = _stops(a)[0], _stops(b)[0]
    assert (sa_lo == sb_lo) != (sa_hi == sb_hi)  # exactly one stop switches


def test_type5_conchoid_with_the_obstacle_across_the_rod_pinches_an_arc():
    # the square's corner v = (0, -2) above the wall y = -2.5, the square on the far side
    # of the rod from the wall: a sliver between body-on-v and tip-on-edge opens on one side
    world = Map([(-5, -2.5), (5, -2.5), (5, 5), (-5, 5)], [SQUARE])
    a, b = _conchoid_sides(world, (0, -2), -0.3)
    sliver = {
        Stop("body", _vertex(world, (0, -2))),
        Stop("tip", _edge(world, (-5, -2.5), (5, -2.5))),
    }
    has = [any({x.stop_lo, x.stop_hi} == sliver for x in fa.arcs) for fa in (a, b)]
    assert sorted(has) == [False, True]
    assert abs(len(a.arcs) - len(b.arcs)) == 1


def test_concave_room_corner_pocket():
    world = square_obstacle_map()
    k = kernel_for(world)
    corner = np.array([5.0, 5.0])
    d = np.array([-1.0, -1.0]) / math.sqrt(2)
    outside = k.free_arcs(corner + (L + OFF) * d, L)
    inside = k.free_arcs(corner + (L - OFF) * d, L)
    right = _edge(world, (5, -5), (5, 5))
    top = _edge(world, (5, 5), (-5, 5))
    assert len(outside.arcs) == 2 and len(inside.arcs) == 1
    pocket = min(outside.arcs, key=lambda a: a.width)
    assert {pocket.stop_lo, pocket.stop_hi} == {Stop("tip", right), Stop("tip", top)}
    assert pocket.contains(math.pi / 4)  # the rod points into the corner
    assert not inside.contains(math.pi / 4)
    # the pocket overlaps no arc across the curve
    assert not any(inside.contains(t) for t in np.linspace(pocket.lo, pocket.hi, 9))


def test_control_pair_crossing_no_curve_has_identical_stops():
    world = square_obstacle_map()
    k = kernel_for(world)
    a = k.free_arcs((-1.0, 0.5), L)
    b = k.free_arcs((-1.0 + OFF, 0.5 + OFF), L)
    assert _stops(a) == _stops(b)
    assert np.allclose([x.width for x in a.arcs], [x.width for x in b.arcs], atol=0.1)


def test_vertex_on_the_circle_is_a_tip_stop_and_just_inside_a_body_stop():
    world = square_obstacle_map()
    k = kernel_for(world)
    v = _vertex(world, (0, 0))
    top = _edge(world, (-2, 0), (0, 0))
    d = np.array([-0.6, 0.8])  # |d| = 1 = L: the top edge's clip ends exactly at v
    on = k.free_arcs(d, L)
    inside = k.free_arcs(d * (1 - 1e-6), L)
    outside = k.free_arcs(d * (1 + 1e-6), L)
    assert _stops(on) == [(Stop("tip", v), Stop("tip", top))]
    assert _stops(inside) == [(Stop("body", v), Stop("tip", top))]
    assert _stops(outside) == [(Stop("tip", top), Stop("tip", top))]
