"""Variable rod length: critical values of L (Prop. 1), the stratified graph G (Sec. 3)
and Prop. 4's verdict for a pursuer with unbounded speed.

* :func:`candidate_lengths`: Prop. 1's candidates, the vertex-vertex and vertex-edge
  distances d (a type-3 or type-5 curve appears) and their halves (two curves first meet).
* :func:`critical_lengths`: the values of L in [l_min, l_max] where G_L actually changes.
  The candidates are checked by comparing a structural hash of G_L on both sides, and the
  events Prop. 1 misses (tangencies, triple points, endpoint crossings; THEORY.md 1.3,
  erratum E10) are found by sampling each open interval and bisecting where the hash
  changes.
* :func:`stratified_graph`: G = union of the G_i (one sample length L_i^q per interval)
  plus Sec. 3's links between G_i and G_{i+1}: cells kappa (above R, at L_i^q) and kappa'
  (above R', at L_{i+1}^q) are linked iff R and R' overlap and, at a point of the
  overlap, the free arc of kappa' lies in that of kappa (lengthening the rod in place
  keeps it free).
* :func:`surveillance_verdict`: Prop. 4: at the smallest sample length L_1^q, a region
  whose cells are all escapable means no surveillance strategy exists, even for an
  infinitely fast pursuer; by Prop. 3 a larger L cannot help the pursuer.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field

import networkx as nx
import numpy as np
import shapely

from envs.errors import InvalidConfigError
from envs.geometry import kernel_for
from envs.maps.map import Map
from strategies.cspace._arcs import OVERLAP_TOL, overlap
from strategies.cspace._paths import shortest_path
from strategies.cspace.curves import _check_map, check_length
from strategies.cspace.decomposition import Decomposition, Region, decompose
from strategies.cspace.tolerances import diameter

__all__ = [
    "StratifiedGraph",
    "SurveillanceVerdict",
    "candidate_lengths",
    "critical_lengths",
    "first_sample_length",
    "graph_signature",
    "stratified_graph",
    "surveillance_verdict",
]

_REL_MERGE = 1e-9  # candidates closer than this (relative to the map's diameter) coincide
_CANDIDATE_PAIRS = 1 << 20
"""(vertex, vertex) and (vertex, edge) pairs :func:`candidate_lengths` measures at a time."""


def _check_range(world: Map, l_min: float, l_max: float) -> tuple[float, float]:
    lo = check_length(l_min, "l_min")
    hi = check_length(l_max, "l_max")
    if hi < lo:
        raise InvalidConfigError(f"l_max: expected l_max >= l_min = {lo:g}, got {hi!r}")
    return lo, hi


def candidate_lengths(map: Map, l_min: float, l_max: float) -> tuple[float, ...]:
    """Prop. 1's candidate critical values of L strictly inside ``(l_min, l_max)``.

    The vertex-vertex distances, the vertex-edge distances and the halves of both, sorted
    and with near-duplicates merged.
    """
    world = _check_map(map)
    lo, hi = _check_range(world, l_min, l_max)
    v = world.vertices
    # a length of the map's size: its diameter, the same in every frame (Map.scale, the
    # bounding box's diagonal, grows by up to sqrt(2) under a rotation)
    tol = _REL_MERGE * diameter(world)
    # a block of vertices at a time, each block's candidates in range kept as runs (first,
    # last) of values each within tol of the one before: every pair at once took n^2 x 24
    # bytes (a round room of 4,000 vertices 1.9 GB, 20,000 about 47 GB). The merge below
    # keeps a value iff it is more than tol above the one before it among them all, so a
    # run's first value and its span decide it, whatever the other blocks hold
    rows = max(1, _CANDIDATE_PAIRS // max(len(v), world.n_edges, 1))
    firsts, lasts = [], []
    for i in range(0, len(v), rows):
        w = v[i : i + rows]
        dvv = np.hypot(*(w[:, None, :] - v[None, :, :]).transpose(2, 0, 1))
        dvv = dvv[np.arange(len(w))[:, None] + i < np.arange(len(v))[None, :]]  # i < j
        rel = w[:, None, :] - world.edge_start[None, :, :]
        t = np.clip(np.einsum("vej,ej->ve", rel, world.edge_dir), 0.0, world.edge_length)
        foot = world.edge_start[None] + t[..., None] * world.edge_dir[None]
        dve = np.hypot(*(w[:, None, :] - foot).transpose(2, 0, 1)).ravel()
        d = np.concatenate([dvv, dve])
        d = d[d > tol]
        c = np.concatenate([d, 0.5 * d])
        # a candidate within tol of an end is that end, outside the open range: a rotated
        # or shifted copy rounds a distance equal to l_max (two pillars' corners 6 apart)
        # to either side of it, and (l_min, l_max) gained a candidate in one frame only
        u = np.unique(c[(c > lo + tol) & (c < hi - tol)])
        if len(u):
            cut = np.flatnonzero(np.diff(u) > tol)
            firsts.append(u[np.concatenate([[0], cut + 1])])
            lasts.append(u[np.concatenate([cut, [len(u) - 1]])])
    if not firsts:
        return ()
    first = np.concatenate(firsts)
    order = np.argsort(first, kind="stable")
    first = first[order]
    # the largest value below each run's first value is the largest last value before it
    top = np.maximum.accumulate(np.concatenate(lasts)[order])
    keep = np.concatenate([[True], first[1:] - top[:-1] > tol])
    return tuple(float(x) for x in first[keep])


def graph_signature(dec: Decomposition) -> str:
    """A hash of the structure of G_L that ignores geometry and the numbering of regions
    and cells (stops are named by the map's feature indices).

    Weisfeiler-Lehman hash of the graph of regions (labelled by their stop pairs), cells
    (labelled by their stops), region-cell membership, region neighbourhood and cell
    adjacency: equal for decompositions that differ only by a deformation.
    """
    g = nx.Graph()
    for r in dec.regions:
        lab = sorted(f"{a}|{b}" for a, b in (dec.cells[c].stops for c in r.cells))
        g.add_node(("r", r.id), label="R:" + ";".join(lab))
    for c in dec.cells:
        a, b = c.stops
        g.add_node(("c", c.id), label=f"K:{a}|{b}")
        g.add_edge(("r", c.region), ("c", c.id), label="in")
    for b in dec.boundaries:
        g.add_edge(("r", b.regions[0]), ("r", b.regions[1]), label="nb")
    for i, j in dec.graph.edges:
        g.add_edge(("c", i), ("c", j), label="adj")
    return nx.weisfeiler_lehman_graph_hash(g, node_attr="label", edge_attr="label", iterations=4)


def critical_lengths(
    map: Map,
    l_min: float,
    l_max: float,
    *,
    samples: int = 2,
    tol: float | None = None,
    chord_tol: float | None = None,
) -> tuple[float, ...]:
    """The critical values of L in ``(l_min, l_max)``: where the structure of G_L changes.

    Args:
        map: the world.
        l_min: smallest rod length.
        l_max: largest rod length.
        samples: sample lengths per interval between consecutive candidates (>= 1); an
            event between two samples whose hashes differ is located by bisection, so
            events off the candidates are found only with ``samples >= 2`` (and only
            when they change the hash between two samples).
        tol: bisection tolerance in L (default ``1e-4 * (l_max - l_min)``).
        chord_tol: passed to :func:`decompose`.

    Returns:
        Sorted critical values (Prop. 1's candidates at which G_L changes, plus the
        events found by bisection).
    """
    world = _check_map(map)
    lo, hi = _check_range(world, l_min, l_max)
    if samples < 1:
        raise InvalidConfigError(f"samples: expected an integer >= 1, got {samples!r}")
    if hi == lo:
        return ()
    tol = 1e-4 * (hi - lo) if tol is None else check_length(tol, "tol")
    cands = candidate_lengths(world, lo, hi)
    cache: dict[float, str] = {}

    def sig(L: float) -> str:
        if L not in cache:
            cache[L] = graph_signature(decompose(world, L, chord_tol=chord_tol))
        return cache[L]

    bounds = [lo, *cands, hi]
    found: list[float] = []
    prev_last: str | None = None
    for k in range(len(bounds) - 1):
        a, b = bounds[k], bounds[k + 1]
        xs = [a + (b - a) * (j + 1) / (samples + 1) for j in range(samples)]
        hs = [sig(x) for x in xs]
        if prev_last is not None and hs[0] != prev_last:
            found.append(a)  # the candidate at the interval's start changes G_L
        for x0, x1, h0, h1 in zip(xs, xs[1:], hs, hs[1:], strict=False):
            if h0 != h1:
                found.extend(_bisect(sig, x0, x1, h0, h1, tol))
        prev_last = hs[-1]
    return tuple(sorted(found))


def _bisect(sig, x0: float, x1: float, h0: str, h1: str, tol: float) -> list[float]:
    """Events between two lengths with different hashes (one, or several if found)."""
    if x1 - x0 <= tol:
        return [0.5 * (x0 + x1)]
    m = 0.5 * (x0 + x1)
    hm = sig(m)
    out = []
    if hm != h0:
        out += _bisect(sig, x0, m, h0, hm, tol)
    if hm != h1:
        out += _bisect(sig, m, x1, hm, h1, tol)
    return out


# ---------------------------------------------------------------------- the graph G
@dataclass(frozen=True, eq=False)
class StratifiedGraph:
    """Sec. 3's connectivity graph G over the strata of L.

    Attributes:
        map: the world.
        l_min, l_max: the range of L.
        critical: the critical values inside the range.
        samples: the sample length L_i^q of each stratum (one per open interval).
        strata: the decomposition at each sample length.
        graph: nodes ``(i, cell id)`` (stratum i), edges within each G_i (attribute
            ``kind="cell"``) and between G_i and G_{i+1} (``kind="length"``).
    """

    map: Map
    l_min: float
    l_max: float
    critical: tuple[float, ...]
    samples: tuple[float, ...]
    strata: tuple[Decomposition, ...] = field(repr=False)
    graph: nx.Graph = field(repr=False)


def _link_strata(a: Decomposition, b: Decomposition) -> list[tuple[int, int]]:
    """Pairs (cell of a, cell of b): regions overlap and b's arc lies in a's (Sec. 3)."""
    kernel = kernel_for(a.map)
    tree = shapely.STRtree([r.polygon for r in b.regions])
    links = set()
    for ra in a.regions:
        for rb_id in tree.query(ra.polygon, predicate="intersects").tolist():
            inter = ra.polygon.intersection(b.regions[rb_id].polygon)
            for part in getattr(inter, "geoms", [inter]):
                if part.geom_type != "Polygon" or part.area <= 1e-12 * a.map.scale**2:
                    continue
                p = shapely.point_on_surface(part)
                pt = np.array([p.x, p.y])
                fa, fb = kernel.free_arcs(pt, a.L), kernel.free_arcs(pt, b.L)
                ca = a._match(ra.id, fa)
                cb = b._match(rb_id, fb)
                for x, i in zip(fa.arcs, ca, strict=True):
                    for y, j in zip(fb.arcs, cb, strict=True):
                        if i is not None and j is not None and overlap(x, y) > OVERLAP_TOL:
                            links.add((i, j))
    return sorted(links)


def stratified_graph(
    map: Map,
    l_min: float,
    l_max: float,
    *,
    critical: tuple[float, ...] | None = None,
    chord_tol: float | None = None,
) -> StratifiedGraph:
    """Sec. 3's graph G: the G_i at one sample length per stratum, linked across L.

    Args:
        map: the world.
        l_min: smallest rod length.
        l_max: largest rod length (> l_min).
        critical: the critical lengths (default :func:`critical_lengths`).
        chord_tol: passed to :func:`decompose`.
    """
    world = _check_map(map)
    lo, hi = _check_range(world, l_min, l_max)
    if hi == lo:
        raise InvalidConfigError(f"l_max: expected l_max > l_min = {lo:g}, got {l_max!r}")
    crit = critical_lengths(world, lo, hi, chord_tol=chord_tol) if critical is None else critical
    crit = tuple(sorted(float(c) for c in crit if lo < c < hi))
    bounds = [lo, *crit, hi]
    samples = tuple(0.5 * (x + y) for x, y in itertools.pairwise(bounds))
    strata = tuple(decompose(world, L, chord_tol=chord_tol) for L in samples)
    g = nx.Graph()
    for i, dec in enumerate(strata):
        for c in dec.cells:
            g.add_node((i, c.id), L=dec.L, region=c.region, stops=c.stops, escapable=c.escapable)
        for x, y in dec.graph.edges:
            g.add_edge((i, x), (i, y), kind="cell")
    for i in range(len(strata) - 1):
        for x, y in _link_strata(strata[i], strata[i + 1]):
            g.add_edge((i, x), (i + 1, y), kind="length")
    return StratifiedGraph(world, lo, hi, crit, samples, strata, g)


# ---------------------------------------------------------------------- Prop. 4
@dataclass(frozen=True, eq=False)
class SurveillanceVerdict:
    """Prop. 4's answer for a pursuer with unbounded speed and L in [l_min, l_max].

    Attributes:
        pursuer_can_hold: no region at L_1^q carries only escapable cells (the paper's
            necessary condition for surveillance holds).
        L: the sample length L_1^q the verdict was computed at.
        decomposition: the decomposition at ``L``.
        witness_region: when the evader wins, a region whose cells are all escapable.
        witness_point: a point of that region.
        evader_path: when the evader wins, the shortest path from ``start`` to the
            witness point: by moving there the evader forces an escapable cell.
    """

    pursuer_can_hold: bool
    L: float
    decomposition: Decomposition = field(repr=False)
    witness_region: Region | None = field(default=None, repr=False)
    witness_point: np.ndarray | None = None
    evader_path: np.ndarray | None = field(default=None, repr=False)

    @property
    def evader_wins(self) -> bool:
        """The negation of ``pursuer_can_hold``."""
        return not self.pursuer_can_hold


def first_sample_length(world: Map, l_min: float, l_max: float) -> float:
    """L_1^q: ``l_min`` itself unless it is a candidate critical value, else just above it."""
    lo, hi = _check_range(world, l_min, l_max)
    tol = 1e3 * _REL_MERGE * world.scale
    near = candidate_lengths(world, max(lo - tol, tol), hi + tol)
    if not any(abs(c - lo) <= tol for c in near):
        return lo
    above = [c for c in near if c > lo + tol]
    gap = (above[0] if above else hi) - lo
    return lo + min(0.5 * gap, 1e-3 * lo) if gap > 0 else lo


def surveillance_verdict(
    map: Map,
    l_min: float,
    l_max: float,
    *,
    start=None,
    chord_tol: float | None = None,
    cache: bool = False,
) -> SurveillanceVerdict:
    """Prop. 4: can an infinitely fast pursuer keep surveillance with L in [l_min, l_max]?

    Args:
        map: the world.
        l_min: smallest surveillance distance.
        l_max: largest surveillance distance.
        start: the evader's start for the escape path (default: a point of the free
            region).
        chord_tol: passed to :func:`decompose`.
        cache: use the on-disk decomposition cache.

    Returns:
        The :class:`SurveillanceVerdict`.
    """
    world = _check_map(map)
    lo, hi = _check_range(world, l_min, l_max)
    L = first_sample_length(world, lo, hi)
    dec = decompose(world, L, chord_tol=chord_tol, cache=cache)
    w = dec.witness_region
    if w is None:
        return SurveillanceVerdict(True, L, dec)
    if start is None:
        rp = world.free_region.representative_point()
        start = (rp.x, rp.y)
    s = np.asarray(start, dtype=float)
    if s.shape != (2,) or not math.isfinite(float(s.sum())) or not world.contains([s])[0]:
        raise InvalidConfigError(f"start: expected a point of the free region, got {start!r}")
    path = shortest_path(world, s, w.point)
    return SurveillanceVerdict(False, L, dec, w, w.point.copy(), path)
