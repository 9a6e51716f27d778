"""A face thinner than its polylines can show is a face, not a hole (random:star:2019).

At L = 1.1 the type-1 line of one edge ends on the type-2 arc about its vertex, tangent
to it, and 8e-4 along the line the type-2 arc about the previous vertex crosses both:
between the line and the tangent arc lies a lens 8e-4 long and at most 3e-7 wide, below
the merge tolerance (6e-7 here). On the polylines its boundary cycle had a negative area
(clockwise), so it was taken for a hole and given to the face around its first vertex,
the open full-circle region, which then bordered two small regions across the lens with
no matching arcs: 2 pieces "matched by overlap only", the open region's cell escapable
by condition (a) and every cell after it, and Prop. 2 said the evader wins. At every
neighbouring L it says the pursuer wins, and so does the grid oracle (resolution 0.1).

A connected component of the planar graph has one outer (clockwise) cycle, the one of
least signed area; every other cycle bounds a face whatever its polyline area.
"""

from __future__ import annotations

import math
import warnings

import pytest

from envs.maps import load_map
from strategies.cspace._build import build_decomposition


@pytest.mark.parametrize("L", [1.09, 1.1, 1.11])
def test_tangent_lens_is_not_a_hole(L):
    world = load_map("random:star:2019")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        dec = build_decomposition(world, L)
    assert dec.exact
    assert dec.unresolved == 0
    assert not dec.evader_wins
    open_cells = [c for c in dec.cells if c.stops == (None, None)]
    assert open_cells and not any(c.escapable for c in open_cells)


def test_tangent_lens_in_a_rotated_and_scaled_frame():
    c, s, k = math.cos(1.1), math.sin(1.1), 1e3
    world = load_map("random:star:2019").transformed([[k * c, -k * s], [k * s, k * c]])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        dec = build_decomposition(world, 1.1 * k)
    assert dec.exact and not dec.evader_wins
    assert (len(dec.regions), len(dec.cells), len(dec.escapable)) == (373, 455, 20)


def test_summary_flags_a_verdict_from_an_inexact_arrangement():
    dec = build_decomposition(load_map("random:star:2019"), 1.09)
    assert "UNRELIABLE" not in dec.summary()
    dec.stats["dangling"] = 1  # as if a curve end lay on no other curve
    assert not dec.exact
    verdict = [line for line in dec.summary().splitlines() if "verdict" in line]
    assert verdict and verdict[0].startswith("  verdict (UNRELIABLE: not exact")
