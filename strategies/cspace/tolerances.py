"""Tolerances of the configuration-space decomposition, relative to the geometry.

Every length the decomposition compares is a multiple of the rod length L, floored by a
multiple of the geometry kernel's own tolerance (``REL_LENGTH_TOL`` times the map's
scale, :mod:`envs.tolerances`), below which the kernel cannot tell a point on a wall
from a point beside it. The map's scale (its bounding box's diagonal) changes when the
map is rotated, so the floor uses an upper bound that does not: ``sqrt(2)`` times the
map's diameter. Nothing depends on the map's units, position or orientation: a world
scaled by 1000 with L scaled by 1000 gets tolerances 1000 times larger and the same
answer, a rotated or translated world the same tolerances.

The decomposition is exact up to these tolerances:

* **curve geometry** is exact (closed forms, and roots polished to double precision);
  only pictures and region polygons use polylines within :data:`CHORD_TOL_REL` ``* L``;
* **vertices** of the arrangement (curve ends and intersections) closer than
  ``merge`` are one vertex: three curves through one point in exact arithmetic give
  three intersections a few ulps apart, and they must be one vertex;
* two curves that come closer than ``touch`` without crossing **touch**: their closest
  points become one vertex on both (a tangency in exact arithmetic, e.g. a type-1 line
  ending on the apex of a type-5 conchoid, must not depend on rounding);
* a face narrower than ``thin`` (twice its area over its perimeter) is a **sliver** of a
  near-degeneracy: it carries no cells, and a boundary piece along it is resolved by
  probing across it, to whichever region lies beyond;
* the two **probes** that decide adjacency across a boundary piece sit ``probe`` to each
  side of it (less on short pieces);
* a face whose perimeter is below twice ``collapse`` (so its diameter is below it) is a
  **speck**: a point where curves meet in exact arithmetic, pulled apart by a
  near-degeneracy (e.g. a wall edge within 1e-5 L of L, where type-4 segment ends,
  type-2 arcs and a type-3 segment come within ``|L - length|`` of one another). The
  kernel cannot resolve it: it compares angles to ``ANGLE_TOL``, so near the end of a
  type-4 segment on a type-2 arc its stops are not the exact ones in a cusp about
  ``ANGLE_TOL * L**2 / d`` wide at distance d from that end, i.e. within about
  ``sqrt(ANGLE_TOL) * L`` (1e-6 L) of it. A speck carries no cells and its boundary
  pieces separate nothing: the faces around it meet at a point, as they do when the
  degeneracy is exact. The rule reads a length (the face's perimeter) against L, never
  a coordinate, so it does not depend on the frame.

Example:
    >>> from envs.maps import Map
    >>> room = Map([(0, 0), (10, 0), (10, 10), (0, 10)])
    >>> tol = Tolerances.of(room, 2.0)
    >>> tol.chord == CHORD_TOL_REL * 2.0
    True
    >>> tol.merge >= MERGE_REL * 2.0 and tol.merge >= KERNEL_FLOOR["merge"] * tol.kernel
    True
    >>> big = Tolerances.of(room.transformed([[1e3, 0], [0, 1e3]]), 2e3)
    >>> round(big.merge / tol.merge, 9), round(big.probe / tol.probe, 9)
    (1000.0, 1000.0)
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import shapely

from envs.maps.map import Map
from envs.tolerances import REL_LENGTH_TOL

__all__ = [
    "CHORD_TOL_REL",
    "COLLAPSE_REL",
    "KERNEL_FLOOR",
    "MERGE_REL",
    "MIN_LENGTH_FLOOR",
    "PROBE_REL",
    "THIN_REL",
    "TOUCH_REL",
    "Tolerances",
    "diameter",
    "min_length",
]

CHORD_TOL_REL = 1e-4
"""Default polyline tolerance of arcs and conchoids, relative to L."""

MERGE_REL = 1e-7
"""Arrangement vertices closer than this (times L) are one vertex."""

TOUCH_REL = 1e-9
"""Curves closer than this (times L) at a local extremum of their distance touch."""

THIN_REL = 1e-7
"""Faces narrower than this (times L; width = twice area over perimeter) are slivers."""

PROBE_REL = 1e-5
"""Offset (times L) of the probe points on each side of a boundary piece."""

COLLAPSE_REL = 1e-5
"""Faces of a smaller half-perimeter (times L) are specks (collapsed to a point): ten
times the kernel's resolution ``sqrt(ANGLE_TOL)`` near a type-4 end (module docstring)."""

KERNEL_FLOOR = {"touch": 2.0, "merge": 20.0, "thin": 20.0, "probe": 200.0, "collapse": 200.0}
"""Each tolerance is at least this many times ``REL_LENGTH_TOL * sqrt(2) * diameter``, a
rotation-invariant bound on the kernel's tolerance ``REL_LENGTH_TOL * scale``."""

MIN_LENGTH_FLOOR = 2.0 * KERNEL_FLOOR["probe"]
"""The shortest rod the decomposition resolves, in the same units as
:data:`KERNEL_FLOOR`: below it the probes across a boundary piece and the speck size
(floored at ``KERNEL_FLOOR["probe"]`` and ``["collapse"]``) exceed half the rod, and the
answer is an artefact (the corridor, 16.9 across: 27 regions and 6 escapable cells at
every L from 1e-5 to 0.5; 9 regions and none at L = 2e-6; no region at 3e-7)."""


@dataclass(frozen=True)
class Tolerances:
    """Absolute tolerances of one decomposition (lengths in map units).

    Attributes:
        L: the rod length.
        chord: polyline tolerance of arcs and conchoids.
        merge: vertex merge radius.
        touch: tangency (touch) distance.
        thin: sliver width.
        probe: probe offset across a boundary piece.
        collapse: faces of a smaller half-perimeter are specks (a point).
        kernel: the geometry kernel's length tolerance (``REL_LENGTH_TOL * scale``).
    """

    L: float
    chord: float
    merge: float
    touch: float
    thin: float
    probe: float
    collapse: float
    kernel: float

    @classmethod
    def of(cls, world: Map, L: float, chord_tol: float | None = None) -> Tolerances:
        """The tolerances of ``world`` at rod length ``L`` (``chord_tol`` overrides the chord)."""
        k = REL_LENGTH_TOL * math.sqrt(2.0) * diameter(world)
        return cls(
            L=float(L),
            chord=CHORD_TOL_REL * L if chord_tol is None else float(chord_tol),
            merge=max(MERGE_REL * L, KERNEL_FLOOR["merge"] * k),
            touch=max(TOUCH_REL * L, KERNEL_FLOOR["touch"] * k),
            thin=max(THIN_REL * L, KERNEL_FLOOR["thin"] * k),
            probe=max(PROBE_REL * L, KERNEL_FLOOR["probe"] * k),
            collapse=max(COLLAPSE_REL * L, KERNEL_FLOOR["collapse"] * k),
            kernel=REL_LENGTH_TOL * world.scale,
        )


def min_length(world: Map) -> float:
    """The shortest rod length the decomposition of ``world`` resolves
    (:data:`MIN_LENGTH_FLOOR` kernel tolerances; about 5.7e-7 of the map's diameter)."""
    return MIN_LENGTH_FLOOR * REL_LENGTH_TOL * math.sqrt(2.0) * diameter(world)


def diameter(world: Map) -> float:
    """The largest distance between two points of the map (invariant under similarities).

    The map's bounding-box diagonal (``Map.scale``) lies between it and ``sqrt(2)`` times it.
    """
    hull = np.asarray(shapely.convex_hull(shapely.multipoints(world.rings[0])).exterior.coords)
    d = hull[:, None, :] - hull[None, :, :]
    return float(np.sqrt((d * d).sum(axis=2).max()))
