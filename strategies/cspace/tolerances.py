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

All of these assume the map's passages are far wider: a face spanning a passage w wide
has a perimeter of about 2 w, so a passage narrower than the collapse tolerance was
collapsed to a point and its probes fell into the walls (a slit 2e-5 wide between two
blocks, at L = 1.5: the evader's escape through it was lost and the verdict flipped,
with every exactness check passing). So where the map's narrowest passage
(:func:`narrowest_passage`) is below :data:`PASSAGE_REL` ``* L``, the L-relative
tolerances shrink in proportion (the kernel floors stay); a passage too narrow even then
is reported (``Tolerances.unresolved``, and the decomposition is not ``exact``).

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

import dataclasses
import math
from dataclasses import dataclass

import numpy as np
import shapely

from envs.maps.map import Map
from envs.tolerances import REL_LENGTH_TOL

__all__ = [
    "CHORD_TOL_REL",
    "COLLAPSE_FLOOR_REL",
    "COLLAPSE_REL",
    "KERNEL_FLOOR",
    "MERGE_REL",
    "MIN_LENGTH_FLOOR",
    "PASSAGE_DETOUR",
    "PASSAGE_REL",
    "PROBE_REL",
    "RESOLVED_PASSAGE",
    "THIN_REL",
    "TOUCH_REL",
    "Tolerances",
    "diameter",
    "min_length",
    "narrowest_passage",
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

COLLAPSE_FLOOR_REL = 1e-6
"""The collapse tolerance never shrinks below this (times L): the kernel's resolution
``sqrt(ANGLE_TOL)`` near the end of a type-4 segment (module docstring)."""

PASSAGE_REL = 1e-3
"""A map whose narrowest passage (:func:`narrowest_passage`) is below this times L gets
its L-relative tolerances (chord, merge, touch, thin, probe, collapse) scaled by
``passage / (PASSAGE_REL * L)``, so the largest of them, the probe offset and the collapse
tolerance, stay 1/100 of the passage. On the 189 worlds of the benchmark sets (built-ins,
their transforms, junctions, random maps, floor plans) the narrowest passage is over 0.01
of the map's diameter, and L is below the diameter: their tolerances are the same as
without the rule."""

PASSAGE_DETOUR = 10.0
"""A wall vertex within d of a wall edge of its own ring bounds a passage if the walls
join them only more than this many times d away (:func:`narrowest_passage`)."""

RESOLVED_PASSAGE = 2.0
"""A passage narrower than this many times the probe offset or the collapse tolerance
(after their floors) is not resolved: a face across it (perimeter about twice its width)
may be collapsed to a point, a probe from a piece along its middle lands in a wall
(:attr:`Tolerances.unresolved`)."""

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
        passage: the map's narrowest passage when below ``PASSAGE_REL * L`` (the
            tolerances were shrunk for it), else ``inf``.
        blocked: the narrowest passage (thin dead ends and strips no longer than L
            aside) too narrow to resolve (:attr:`unresolved`), else ``inf``.
    """

    L: float
    chord: float
    merge: float
    touch: float
    thin: float
    probe: float
    collapse: float
    kernel: float
    passage: float = math.inf
    blocked: float = math.inf

    @classmethod
    def of(cls, world: Map, L: float, chord_tol: float | None = None) -> Tolerances:
        """The tolerances of ``world`` at rod length ``L`` (``chord_tol`` overrides the chord)."""
        k = REL_LENGTH_TOL * math.sqrt(2.0) * diameter(world)
        passage = narrowest_passage(world, PASSAGE_REL * L)
        rel = L * min(1.0, passage / (PASSAGE_REL * L))  # L, or less on a narrow map
        tol = cls(
            L=float(L),
            chord=CHORD_TOL_REL * rel if chord_tol is None else float(chord_tol),
            merge=max(MERGE_REL * rel, KERNEL_FLOOR["merge"] * k),
            touch=max(TOUCH_REL * rel, KERNEL_FLOOR["touch"] * k),
            thin=max(THIN_REL * rel, KERNEL_FLOOR["thin"] * k),
            probe=max(PROBE_REL * rel, KERNEL_FLOOR["probe"] * k),
            collapse=max(COLLAPSE_REL * rel, COLLAPSE_FLOOR_REL * L, KERNEL_FLOOR["collapse"] * k),
            kernel=REL_LENGTH_TOL * world.scale,
            passage=passage,
        )
        resolved = RESOLVED_PASSAGE * max(tol.probe, tol.collapse)
        # a strip holds pieces of its own (the type-1 lines L from its ends) once longer
        # than L; a shorter thin dead end (a notch) was seen to lose nothing
        blocked = narrowest_passage(world, resolved, dead_ends=False, strips_over=L)
        return dataclasses.replace(tol, blocked=blocked)

    @property
    def unresolved(self) -> bool:
        """Whether the map has a passage (thin dead ends and strips no longer than L
        aside) narrower than :data:`RESOLVED_PASSAGE` times the probe offset or the
        collapse tolerance: the decomposition may be wrong there (``blocked`` is its
        width)."""
        return math.isfinite(self.blocked)


def min_length(world: Map) -> float:
    """The shortest rod length the decomposition of ``world`` resolves
    (:data:`MIN_LENGTH_FLOOR` kernel tolerances; about 5.7e-7 of the map's diameter)."""
    return MIN_LENGTH_FLOOR * REL_LENGTH_TOL * math.sqrt(2.0) * diameter(world)


def diameter(world: Map) -> float:
    """The largest distance between two points of the map (invariant under similarities).

    The map's bounding-box diagonal (``Map.scale``) lies between it and ``sqrt(2)`` times it.
    """
    # the boundary's convex hull (envs.maps.map.convex_diameter): every pair of a round
    # room's 20,000 hull vertices took 23 s a call (two calls before decompose's memory
    # check could refuse it); rotating calipers beyond 2048 hull vertices
    return world.diameter


def narrowest_passage(
    world: Map, below: float, *, dead_ends: bool = True, strips_over: float = 0.0
) -> float:
    """The width of the map's narrowest passage, if below ``below``, else ``inf``.

    A passage is where a wall vertex faces a wall edge across free space ``d`` wide (on
    the edge's free side, within 60 degrees of its normal) and the walls join them only
    the long way round: on another ring, or more than :data:`PASSAGE_DETOUR` times ``d``
    away along their own ring (a slit between two obstacles, a pinch between a corner and
    a wall, a notch over four times deeper than wide). Two walls' least distance is
    reached at a vertex of one of them. A short edge, a shallow notch or a thin tooth is
    no passage: the faces it makes are near-degeneracies of its corners, which the sliver
    and speck rules handle. Walls that touch (``d`` within the kernel's length
    tolerance: ``Map(merge=True)`` blocks meeting at a corner) bound no passage either.
    A *strip* is one too: a wall edge at v running along e, its far end within ``2 d`` of
    e, for more than :data:`PASSAGE_DETOUR` times ``d`` (a room 10 long and 1e-5 wide,
    whose walls join at its short ends).

    Args:
        world: the map.
        below: passages this wide or wider are not looked for.
        dead_ends: count thin dead ends too: a passage on one ring whose shorter way
            round encloses, with the passage, less than twice its width times that way in
            area (a notch thin all along, with no room behind it).
        strips_over: without ``dead_ends``, count only the strips longer than this.

    Examples:
        >>> from envs.maps import Map
        >>> room = [(0, 0), (10, 0), (10, 10), (0, 10)]
        >>> blocks = [[(2, 2), (5, 2), (5, 8), (2, 8)], [(5.001, 2), (8, 2), (8, 8), (5.001, 8)]]
        >>> slit = Map(room, blocks)
        >>> round(narrowest_passage(slit, 0.01), 9), narrowest_passage(slit, 0.001)
        (0.001, inf)
        >>> step = Map(room, [[(2, 2), (5, 2), (5, 2.001), (5.001, 2.001), (5.001, 8), (2, 8)]])
        >>> narrowest_passage(step, 0.01)  # a short edge
        inf
    """
    a, b = world.edge_start, world.edge_end
    tree = shapely.STRtree(shapely.linestrings(np.stack([a, b], axis=1)))
    v, e = tree.query(shapely.points(world.vertices), predicate="dwithin", distance=below)
    if not len(v):
        return math.inf
    p, u = world.vertices[v] - a[e], world.edge_dir[e]
    t = np.clip(np.einsum("kj,kj->k", p, u), 0.0, world.edge_length[e])
    d = np.hypot(*(p - t[:, None] * u).T)
    # v faces e across free space: in front of it, within 60 degrees of its normal (not
    # beside its end, as a tooth's corner at the floor is, within rounding of its line)
    front = np.einsum("kj,kj->k", p, world.edge_normal[e]) >= 0.5 * d
    # the way round along the walls from v to its nearest point on e (same ring only)
    ring = world.vertex_ring
    start = np.zeros(len(world.rings), dtype=np.intp)
    start[1:] = np.cumsum([len(r) for r in world.rings])[:-1]
    along = np.zeros(world.n_edges)
    perimeter = np.zeros(len(world.rings))
    for k, s0 in enumerate(start.tolist()):
        lengths = world.edge_length[s0 : s0 + len(world.rings[k])]
        along[s0 : s0 + len(lengths)] = np.concatenate([[0.0], np.cumsum(lengths)[:-1]])
        perimeter[k] = lengths.sum()
    same = ring[v] == world.edge_ring[e]
    gap = along[e] + t - along[v]  # forward along the ring from v (mod its perimeter)
    gap = np.where(gap < 0.0, gap + perimeter[ring[v]], gap)
    way = np.where(same, np.minimum(gap, perimeter[ring[v]] - gap), np.inf)
    # strips: an edge at v whose far end is within 2 d of e, running along it
    strip = np.zeros(len(v))
    prev, nxt = world.vertex_prev_edge[v], world.vertex_next_edge[v]
    for far in (a[prev], b[nxt]):  # the other end of each edge at v
        q = far - a[e]
        tq = np.clip(np.einsum("kj,kj->k", q, u), 0.0, world.edge_length[e])
        near = np.hypot(*(q - tq[:, None] * u).T) <= 2.0 * d
        strip = np.maximum(strip, np.where(near, np.abs(tq - t), 0.0))
    strip = np.where(strip > PASSAGE_DETOUR * d, strip, 0.0)
    real = front & (d > REL_LENGTH_TOL * world.scale) & (d < below)
    ok = real & ((way > PASSAGE_DETOUR * d) | (strip > 0.0))
    for k in np.flatnonzero(ok)[np.argsort(d[ok])].tolist():
        if dead_ends or not same[k] or strip[k] > strips_over:
            return float(d[k])
        if way[k] <= PASSAGE_DETOUR * d[k]:
            continue  # a strip no longer than strips_over, not a passage round the walls
        # the shorter way round from v to its foot on e, closed by the passage
        r, i, j = int(ring[v[k]]), int(v[k]), int(e[k])
        n, s0 = len(world.rings[r]), int(start[r])
        foot = a[j] + t[k] * u[k]
        if gap[k] <= perimeter[r] - gap[k]:  # forward: v, v+1, ..., start of e, foot
            idx = s0 + (np.arange(i - s0, i - s0 + (j - i) % n + 1) % n)
            ring_pts = np.vstack([world.vertices[idx], foot])
        else:  # backward: foot, end of e, ..., v
            idx = s0 + (np.arange(j - s0 + 1, j - s0 + 1 + (i - j - 1) % n + 1) % n)
            ring_pts = np.vstack([foot, world.vertices[idx]])
        x, y = ring_pts[:, 0], ring_pts[:, 1]
        area = 0.5 * abs(float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y)))
        if area >= 2.0 * d[k] * way[k]:  # a room behind it, not a thin dead end
            return float(d[k])
    return math.inf
