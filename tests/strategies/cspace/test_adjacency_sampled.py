"""Adjacency across boundary pieces, checked along each piece rather than at its one probe.

The decomposition decides which cells are adjacent across a boundary piece at one probe
point of the piece (footnote 3: arcs on the two sides overlapping with positive length).
Between the piece's ends nothing critical happens, so the same pairs must overlap
everywhere along it. Here the free arcs are sampled just off the piece on both sides at
nine points along it, each arc matched to a cell of its own side's region by its stop pair
(the cell key), and every pair overlapping by more than 1e-5 rad must be one the
decomposition lists. A missed pair is the dangerous error: it can make a cell look
escapable (Sec. 4, case (a)) when the pursuer can in fact swing the rod across.

Samples where a side's stop pair is not one of its region's keys are skipped: within
about 1e-6 L of a type 2 curve the kernel may name a stop by the feature on the other side
(the arc itself is the same), and thin regions put a side's sample outside its region.
About half the samples are readable on these worlds (1322 of 2547 on the triangles,
4014 of 9549 on random:polygons:7); the test asks for a third, so it cannot pass by
skipping everything.
"""

from __future__ import annotations

import numpy as np
import pytest

from envs.geometry import kernel_for
from envs.maps.io import load_map
from strategies.cspace._arcs import overlap
from tests.strategies.cspace._oracle import exact_decomposition, tilted_block, triangles

FRACTIONS = np.linspace(0.1, 0.9, 9)
OFFSET_REL = 1e-6
"""Distance of the samples from the piece, relative to L."""
MIN_OVERLAP = 1e-5
"""Overlaps (radians) above this are an adjacency for sure (the kernel's tolerances are
far smaller)."""


def _point_along(segments: np.ndarray, frac: float) -> np.ndarray:
    lengths = np.linalg.norm(segments[:, 1] - segments[:, 0], axis=1)
    cum = np.r_[0.0, np.cumsum(lengths)]
    s = frac * cum[-1]
    k = min(int(np.searchsorted(cum, s, side="right")) - 1, len(segments) - 1)
    t = (s - cum[k]) / lengths[k]
    return segments[k, 0] + t * (segments[k, 1] - segments[k, 0])


def _sampled_pairs(dec, kernel, boundary, frac):
    """Cell pairs (side A, side B) whose arcs overlap next to the piece at ``frac``, or
    ``None`` if the sample cannot be read (off the regions, or a stop pair no cell has)."""
    a_region, b_region = boundary.regions
    eps = OFFSET_REL * dec.L
    p = _point_along(boundary.segments, frac)
    sides = []
    for region, q in ((a_region, p + eps * boundary.normal), (b_region, p - eps * boundary.normal)):
        if dec.locate(q) != region:
            return None
        keys = {c.stops: c.id for c in dec.region_cells(region)}
        arcs = kernel.free_arcs(q, dec.L).arcs
        cells = [keys.get((arc.stop_lo, arc.stop_hi)) for arc in arcs]
        if None in cells:
            return None
        sides.append(list(zip(arcs, cells, strict=True)))
    return {
        (i, j): overlap(a, b)
        for a, i in sides[0]
        for b, j in sides[1]
        if overlap(a, b) > MIN_OVERLAP
    }


WORLDS = [
    (tilted_block, 3.0),
    (triangles, 2.0),
    (lambda: load_map("random:polygons:7"), 1.5),
]


@pytest.mark.parametrize(("world", "L"), WORLDS, ids=["tilted_block", "triangles", "polygons7"])
def test_every_overlap_along_a_piece_is_a_listed_adjacency(world, L):
    dec = exact_decomposition(world(), L)
    kernel = kernel_for(dec.map)
    usable = total = 0
    missed = []
    for boundary in dec.boundaries:
        listed = set(boundary.adjacent)
        for frac in FRACTIONS:
            total += 1
            pairs = _sampled_pairs(dec, kernel, boundary, frac)
            if pairs is None:
                continue
            usable += 1
            missed += [
                (boundary.id, frac, pair, ov) for pair, ov in pairs.items() if pair not in listed
            ]
    assert usable >= total / 3, f"only {usable} of {total} samples could be read"
    assert not missed, f"{len(missed)} overlaps not listed as adjacent, e.g. {missed[:5]}"
