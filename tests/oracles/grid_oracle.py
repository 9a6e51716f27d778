"""A grid oracle for the Section 4 verdict: slow, approximate, independent of the exact cells.

The exact decomposition (THEORY.md 1.3) partitions the evader's plane into noncritical
regions bounded by critical curves and links the cells above neighbouring regions whose
free arcs overlap. This module computes the same verdict a second way, with no critical
curve at all:

* **nodes**: a grid of evader positions P with spacing ``resolution``, and at each the exact
  free arcs of the rod of length L (from the geometry kernel); a node is a pair
  (point, arc), the grid analogue of a cell kappa = (R, [s-, s+]);
* **edges**: between nodes of 8- (or 4-) neighbouring grid points, when the evader can
  walk the segment between the two points (it stays in the closed free region) and the
  pursuer can keep the rod in one arc at the start and end in the other: the arcs are
  followed along the step, bisecting it (exact free arcs at the midpoints) until every
  sub-step is settled by the overlap rule of the paper's footnote 3;
* **escapable nodes**: the least fixed point of the paper's recursive definition (Sec. 4):
  node (p, a) is escapable if for some neighbour p' of p (a) no arc at p' is connected to
  a or (b) every arc at p' connected to a is escapable;
* **verdict**: the evader wins if some grid point carries only escapable nodes (Prop. 2),
  which includes a point with no free orientation at all (Prop. 5, empty admissible set).

Discretisation, and which way the errors go:

1. *Near walls the arcs change fast.* At distance d from a convex vertex a body-contact
   stop turns by about ``resolution / d`` per grid step, so a narrow arc can turn past its
   own width between two grid points: plain overlap would call that an escape although
   the pursuer just follows the arc. Following the arcs along the step (bisection down to
   ``resolution / 2**_MAX_DEPTH``) removes that false escape.
2. *A thin critical feature between neighbours* (a sliver region, two arcs merging and
   splitting again): sub-steps with two or more arcs are resampled until no stop turns
   farther than half the narrowest gap between arcs, so a closing gap is seen.
3. *An arc that vanishes between two grid points* shrinks to zero width inside the step;
   the bisection closes in on the critical curve, and at the finest sub-step the overlap
   rule decides: a vanished arc overlaps nothing across (THEORY 1.3), which is an escape.

What remains is one-sided. A grid-escapable node is a real escape (the evader walks grid
steps, the pursuer's whole arc is tracked along each), up to the finest sub-step. But the
evader only walks grid steps, so an escape that needs a region narrower than the grid
spacing (a sliver next to a convex vertex, where an arc is pinched to nothing) can be
missed: an evader-wins verdict is trustworthy, a pursuer-wins verdict is a lower bound
that improves, not monotonically, as the resolution shrinks. Use it as a test oracle
("the grid's escapes are escapes"; "on maps without slivers, the verdicts agree"), not
as the product.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from envs.errors import InvalidConfigError, InvalidPlacementError
from envs.geometry import kernel_for
from envs.geometry.types import Arc
from envs.maps.map import Map
from envs.tolerances import REL_LENGTH_TOL
from strategies.cspace.grids import grid_axis

__all__ = [
    "OVERLAP_TOL",
    "GridGraph",
    "GridVerdict",
    "grid_escapable",
    "grid_graph",
    "grid_safe_arcs",
    "grid_verdict",
]

OVERLAP_TOL = 1e-9
"""Arcs overlapping by at most this many radians only touch: no edge (footnote 3)."""

MAX_GRID_POINTS = 4_000_000
"""Refuse grids with more candidate points than this (memory and hours of run time)."""

_TWO_PI = 2.0 * math.pi
_HALF_OFFSETS = {4: ((1, 0), (0, 1)), 8: ((1, 0), (0, 1), (1, 1), (1, -1))}
_CHUNK = 16_384
_MAX_TURN = 0.3  # rad: a step on which some stop turns farther than this is resampled
_MAX_DEPTH = 5  # bisections of a grid step: the finest sample spacing is resolution / 32


# --------------------------------------------------------------------------- validation
def _check(map_: Map, L: float, resolution: float, neighbourhood: int) -> tuple[float, float]:
    if not isinstance(map_, Map):
        raise InvalidConfigError(f"map: expected an envs.maps.Map, got {type(map_).__name__}")
    L = float(L)
    if not math.isfinite(L) or L <= 0:
        raise InvalidConfigError(f"L: expected a finite rod length > 0, got {L!r}")
    resolution = float(resolution)
    if not math.isfinite(resolution) or resolution <= 0:
        raise InvalidConfigError(f"resolution: expected a finite spacing > 0, got {resolution!r}")
    if neighbourhood not in _HALF_OFFSETS:
        raise InvalidConfigError(f"neighbourhood: expected 4 or 8, got {neighbourhood!r}")
    xmin, ymin, xmax, ymax = map_.bounds
    n = (math.floor((xmax - xmin) / resolution) + 1) * (math.floor((ymax - ymin) / resolution) + 1)
    if n > MAX_GRID_POINTS:
        raise InvalidConfigError(
            f"resolution: {resolution:g} gives {n} grid points on a map of bounds "
            f"{map_.bounds}, more than {MAX_GRID_POINTS}; use a coarser resolution"
        )
    return L, resolution


def _as_point(point: Sequence[float] | np.ndarray) -> np.ndarray:
    p = np.asarray(point, dtype=float)
    if p.shape != (2,) or not np.all(np.isfinite(p)):
        raise InvalidPlacementError(f"point: expected finite (x, y), got {point!r}")
    return p


# --------------------------------------------------------------------------- geometry
_axis = grid_axis  # the product's grid (strategies.cspace.grids), so both sample alike


def _clearance(map_: Map, points: np.ndarray) -> np.ndarray:
    """Distance from each point to the walls (chunked to bound memory)."""
    out = np.empty(len(points))
    for s in range(0, len(points), _CHUNK):
        out[s : s + _CHUNK] = map_.distance_to_walls(points[s : s + _CHUNK])
    return out


def _steps_clear(map_: Map, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Which segments ``a[k] -> b[k]`` (both ends in free space) stay in the closed free region.

    A segment leaves the free region iff it properly crosses a wall edge, or it passes
    through obstacle interior between two wall contacts (entering and leaving through
    vertices or along edges). The second case is caught by testing the midpoints between
    consecutive contact parameters; we test the midpoints of the pieces cut by every
    contact with a wall vertex, which covers it.
    """
    clear = np.ones(len(a), dtype=bool)
    s0, s1 = map_.edge_start, map_.edge_end
    vtx = map_.vertices
    eps = REL_LENGTH_TOL * map_.scale
    for s in range(0, len(a), _CHUNK):
        pa, pb = a[s : s + _CHUNK], b[s : s + _CHUNK]
        d = pb - pa  # (k, 2)
        e = s1 - s0  # (E, 2)
        cross = lambda u, v: u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]
        # orientation of wall endpoints w.r.t. the step, and of step endpoints w.r.t. walls
        o1 = cross(d[:, None, :], s0[None] - pa[:, None])
        o2 = cross(d[:, None, :], s1[None] - pa[:, None])
        o3 = cross(e[None], pa[:, None] - s0[None])
        o4 = cross(e[None], pb[:, None] - s0[None])
        len_d = np.linalg.norm(d, axis=1)[:, None]
        len_e = np.linalg.norm(e, axis=1)[None]
        tol1, tol3 = eps * len_d, eps * len_e
        proper = (((o1 > tol1) & (o2 < -tol1)) | ((o1 < -tol1) & (o2 > tol1))) & (
            ((o3 > tol3) & (o4 < -tol3)) | ((o3 < -tol3) & (o4 > tol3))
        )
        blocked = proper.any(axis=1)
        # contacts with wall vertices cut the step into pieces; each piece must be free
        rel = vtx[None] - pa[:, None]  # (k, V, 2)
        t = np.einsum("kvj,kj->kv", rel, d) / np.maximum(len_d**2, eps**2)
        dist = np.abs(cross(d[:, None, :], rel)) / np.maximum(len_d, eps)
        touch = (dist <= eps) & (t > 0) & (t < 1)
        rows = np.flatnonzero(touch.any(axis=1) & ~blocked)
        for r in rows:
            ts = np.concatenate(([0.0], np.sort(t[r, touch[r]]), [1.0]))
            mids = pa[r] + 0.5 * (ts[:-1] + ts[1:])[:, None] * d[r]
            if not np.all(map_.contains(mids)):
                blocked[r] = True
        clear[s : s + _CHUNK] = ~blocked
    return clear


def _arcs_overlap(lo1, hi1, lo2, hi2, tol: float = OVERLAP_TOL) -> np.ndarray:
    """Whether closed arcs ``[lo1, hi1]`` and ``[lo2, hi2]`` share a positive length.

    Arcs are ``lo`` in ``[-pi, pi)``, ``lo <= hi <= lo + 2 pi``; trying the shifts
    ``{-2 pi, 0, 2 pi}`` of the second arc covers every wrap-around at +-pi.
    """
    best = np.full(np.shape(lo1), -np.inf)
    for shift in (-_TWO_PI, 0.0, _TWO_PI):
        best = np.maximum(best, np.minimum(hi1, hi2 + shift) - np.maximum(lo1, lo2 + shift))
    return best > tol


def _concat_ranges(starts: np.ndarray, stops: np.ndarray) -> np.ndarray:
    """``concatenate([arange(a, b) for a, b in zip(starts, stops)])`` without a loop."""
    lens = stops - starts
    total = int(lens.sum())
    if total == 0:
        return np.zeros(0, dtype=np.int64)
    offsets = np.cumsum(lens) - lens
    return np.repeat(starts - offsets, lens) + np.arange(total)


def _arrays(arcs) -> tuple[np.ndarray, np.ndarray]:
    return np.array([a.lo for a in arcs], dtype=float), np.array([a.hi for a in arcs], dtype=float)


def _gaps_after(lo: np.ndarray, hi: np.ndarray, ptr: np.ndarray) -> np.ndarray:
    """Width of the blocked gap after each arc, up to the next arc of the same point."""
    nxt = np.arange(len(lo)) + 1
    last = ptr[1:][ptr[1:] > ptr[:-1]] - 1  # the last arc of each point with arcs
    nxt[last] = ptr[:-1][ptr[1:] > ptr[:-1]]
    return (lo[nxt] - hi) % _TWO_PI


def _plain_steps(
    lo_s, hi_s, lo_t, hi_t, gap_s, gap_t, hit, slot_s, slot_t, step, n_s, n_t
) -> np.ndarray:
    """Which steps the plain overlap rule (footnote 3) settles, vectorised over steps.

    Inputs describe every (arc at s, arc at t) pair of every step: the arcs' ends and the
    blocked gaps after them, whether they overlap (``hit``), the pair's slot among the
    step's arcs at s and at t, the step index, and the arc counts at both ends of each
    step. A step is settled when

    * an end has no arc (nothing can connect), or an end is the full circle (it meets
      every arc across; an arc born inside the step could only be over-connected), or
    * both ends have equally many arcs and the overlaps pair them one to one; with two
      arcs or more, also no stop of a pair turns by more than ``_MAX_TURN`` or than half
      the narrowest gap between arcs: each arc can only have become its partner, and no
      two arcs can have merged (letting the pursuer switch) and split again. With one arc
      a side, overlapping arcs are connected unless the arc died and another was born
      within the step, which only over-connects.

    Otherwise an arc may have turned past its own width (the pursuer follows it, yet the
    arcs at the two ends do not overlap) or arcs were born, died, split or merged on the
    way, and the step is resampled (:func:`_step_relation`).
    """
    n_steps = len(n_s)
    full = lambda lo, hi: hi - lo >= _TWO_PI - OVERLAP_TOL
    full_s = np.bincount(step, weights=full(lo_s, hi_s), minlength=n_steps) > 0
    full_t = np.bincount(step, weights=full(lo_t, hi_t), minlength=n_steps) > 0
    deg_s = np.bincount(slot_s[hit], minlength=int(n_s.sum()))
    deg_t = np.bincount(slot_t[hit], minlength=int(n_t.sum()))
    bad = np.zeros(n_steps, dtype=bool)
    bad[np.repeat(np.arange(n_steps), n_s)[deg_s != 1]] = True
    bad[np.repeat(np.arange(n_steps), n_t)[deg_t != 1]] = True
    wrap = lambda x: np.abs((x + math.pi) % _TWO_PI - math.pi)
    turn = np.maximum(wrap(lo_t - lo_s), wrap(hi_t - hi_s))
    # with two arcs or more a side, no stop may turn farther than half the narrowest gap
    gap = np.full(n_steps, 2.0 * _MAX_TURN)
    np.minimum.at(gap, step, np.minimum(gap_s, gap_t))
    multi = (n_s[step] > 1) | (n_t[step] > 1)  # one arc a side: overlapping is enough
    bad[step[hit & multi & (turn > 0.5 * gap[step])]] = True
    return (n_s == 0) | (n_t == 0) | full_s | full_t | ((n_s == n_t) & ~bad)


def _relation_once(s: tuple, t: tuple) -> tuple[np.ndarray, bool]:
    """The overlap relation of one step and whether :func:`_plain_steps` settles it."""
    ns, nt = len(s[1]), len(t[1])
    i, j = np.divmod(np.arange(ns * nt), max(nt, 1))
    hit = _arcs_overlap(s[1][i], s[2][i], t[1][j], t[2][j])
    gap_s = _gaps_after(s[1], s[2], np.array([0, ns]))
    gap_t = _gaps_after(t[1], t[2], np.array([0, nt]))
    zero = np.zeros(ns * nt, dtype=np.int64)
    n_s, n_t = np.array([ns]), np.array([nt])
    args = (s[1][i], s[2][i], t[1][j], t[2][j], gap_s[i], gap_t[j], hit, i, j, zero, n_s, n_t)
    settled = _plain_steps(*args)[0]
    return hit.reshape(ns, nt), bool(settled)


def _step_relation(kernel, L: float, s: tuple, t: tuple, depth: int) -> np.ndarray:
    """Which arcs at sample s connect to which at sample t along the segment s-t.

    ``s`` and ``t`` are ``(point, lo, hi)``. A step the overlap rule settles is its
    overlap relation; otherwise it is bisected (free arcs at the midpoint from the kernel)
    and the halves' relations are composed: a chain of arcs along the step. After
    ``depth`` bisections the overlap rule decides anyway: a critical curve lies in this
    sliver, and an arc that vanishes on it overlaps nothing across (THEORY 1.3).
    """
    rel, settled = _relation_once(s, t)
    if settled or depth == 0:
        return rel
    mid_point = 0.5 * (s[0] + t[0])
    mid = (mid_point, *_arrays(kernel.free_arcs(mid_point, L).arcs))
    first = _step_relation(kernel, L, s, mid, depth - 1).astype(np.int64)
    second = _step_relation(kernel, L, mid, t, depth - 1).astype(np.int64)
    return (first @ second) > 0


# --------------------------------------------------------------------------- the graph
@dataclass(frozen=True, eq=False)
class GridGraph:
    """The grid analogue of G_L (Sec. 3): nodes (point, free arc), edges along steps.

    Attributes:
        map: the world.
        L: rod length.
        resolution: grid spacing.
        neighbourhood: 4 or 8 (grid neighbours an evader step may reach).
        points: (n, 2) grid points in the open free region.
        point_arcs: the kernel's free arcs at each point.
        node_point: (N,) grid point of each node; nodes of a point are consecutive.
        node_ptr: (n + 1,) nodes of point i are ``node_ptr[i]:node_ptr[i + 1]``.
        node_lo, node_hi: (N,) the node's arc ``[lo, hi]``.
        point_edges: (M, 2) neighbouring grid points joined by a free segment.
        overlap: (K, 3) rows ``(a, b, e)``: node a at ``point_edges[e, 0]`` and node b at
            ``point_edges[e, 1]`` are connected along the step (the graph's edges).
    """

    map: Map
    L: float
    resolution: float
    neighbourhood: int
    points: np.ndarray
    point_arcs: tuple[tuple[Arc, ...], ...]
    node_point: np.ndarray
    node_ptr: np.ndarray
    node_lo: np.ndarray
    node_hi: np.ndarray
    point_edges: np.ndarray
    overlap: np.ndarray

    @property
    def n_points(self) -> int:
        """Number of grid points in free space."""
        return len(self.points)

    @property
    def n_nodes(self) -> int:
        """Number of nodes (point, arc)."""
        return len(self.node_point)

    @functools.cached_property
    def escapable(self) -> np.ndarray:
        """(N,) bool: the least fixed point of the escapable-cell definition (Sec. 4)."""
        return _least_fixed_point(self)

    @functools.cached_property
    def point_escapable(self) -> np.ndarray:
        """(n,) bool: every node at the point is escapable (vacuously true with no arc)."""
        safe = np.bincount(self.node_point[~self.escapable], minlength=self.n_points)
        return safe == 0


def grid_graph(map: Map, L: float, *, resolution: float, neighbourhood: int = 8) -> GridGraph:
    """Build the grid graph of a map for a rod of length L.

    Args:
        map: the world.
        L: rod length (the surveillance distance, > 0).
        resolution: grid spacing (> 0), in map units.
        neighbourhood: 8 (default) or 4 grid neighbours per point.

    Returns:
        The :class:`GridGraph`; its ``escapable`` property runs the fixed point.

    Raises:
        InvalidConfigError: L or resolution not positive and finite, a grid too large, or
            a neighbourhood other than 4 or 8.
    """
    map_ = map
    L, resolution = _check(map_, L, resolution, neighbourhood)
    xmin, ymin, xmax, ymax = map_.bounds
    xs, ys = _axis(xmin, xmax, resolution), _axis(ymin, ymax, resolution)
    gi, gj = np.meshgrid(np.arange(len(xs)), np.arange(len(ys)), indexing="ij")
    cand = np.stack([xs[gi.ravel()], ys[gj.ravel()]], axis=1)
    # the open free region: in free space and not on a wall (a type-0 point, THEORY 1.2)
    keep = np.zeros(len(cand), dtype=bool)
    for s in range(0, len(cand), _CHUNK):
        keep[s : s + _CHUNK] = map_.contains(cand[s : s + _CHUNK])
    idx = np.flatnonzero(keep)
    idx = idx[_clearance(map_, cand[idx]) > REL_LENGTH_TOL * map_.scale]
    points = cand[idx]
    index = np.full(gi.size, -1, dtype=np.int64)
    index[idx] = np.arange(len(idx))
    index = index.reshape(gi.shape)

    kernel = kernel_for(map_)
    point_arcs = (
        tuple(tuple(fa.arcs) for fa in kernel.free_arcs_many(points, L)) if len(points) else ()
    )
    counts = np.fromiter((len(a) for a in point_arcs), dtype=np.int64, count=len(points))
    node_ptr = np.concatenate(([0], np.cumsum(counts)))
    node_point = np.repeat(np.arange(len(points)), counts)
    node_lo = np.fromiter((a.lo for arcs in point_arcs for a in arcs), dtype=float)
    node_hi = np.fromiter((a.hi for arcs in point_arcs for a in arcs), dtype=float)

    # neighbouring grid points (each unordered pair once) joined by a free segment
    pairs = []
    nx, ny = index.shape
    for di, dj in _HALF_OFFSETS[neighbourhood]:  # di >= 0 always
        j0, j1 = max(0, -dj), ny - max(0, dj)
        a = index[: nx - di, j0:j1]
        b = index[di:, j0 + dj : j1 + dj]
        ok = (a >= 0) & (b >= 0)
        pairs.append(np.stack([a[ok], b[ok]], axis=1))
    edges = np.concatenate(pairs) if pairs else np.zeros((0, 2), dtype=np.int64)
    edges = edges[_steps_clear(map_, points[edges[:, 0]], points[edges[:, 1]])]

    # which arcs at one end the pursuer can keep the rod in while the evader walks the step:
    # every pair of arcs across every step, overlap-tested at once; the steps the plain
    # overlap rule does not settle are resampled one by one
    ci, cj = counts[edges[:, 0]], counts[edges[:, 1]]
    tot = ci * cj
    e_rep = np.repeat(np.arange(len(edges)), tot)
    k = np.arange(int(tot.sum())) - np.repeat(np.cumsum(tot) - tot, tot)
    ka, kb = np.divmod(k, np.maximum(cj[e_rep], 1))
    na, nb = node_ptr[edges[e_rep, 0]] + ka, node_ptr[edges[e_rep, 1]] + kb
    lo_a, hi_a, lo_b, hi_b = node_lo[na], node_hi[na], node_lo[nb], node_hi[nb]
    hit = _arcs_overlap(lo_a, hi_a, lo_b, hi_b)
    slot_a = np.repeat(np.cumsum(ci) - ci, tot) + ka
    slot_b = np.repeat(np.cumsum(cj) - cj, tot) + kb
    gaps = _gaps_after(node_lo, node_hi, node_ptr)
    settled = _plain_steps(
        lo_a, hi_a, lo_b, hi_b, gaps[na], gaps[nb], hit, slot_a, slot_b, e_rep, ci, cj
    )
    keep = hit & settled[e_rep]
    rows = [np.stack([na[keep], nb[keep], e_rep[keep]], axis=1)]
    for e in np.flatnonzero(~settled).tolist():
        i, j = edges[e]
        si, sj = slice(node_ptr[i], node_ptr[i + 1]), slice(node_ptr[j], node_ptr[j + 1])
        s_end = (points[i], node_lo[si], node_hi[si])
        t_end = (points[j], node_lo[sj], node_hi[sj])
        a, b = np.nonzero(_step_relation(kernel, L, s_end, t_end, _MAX_DEPTH))
        rows.append(np.stack([a + node_ptr[i], b + node_ptr[j], np.full(len(a), e)], axis=1))
    overlap = np.concatenate(rows).astype(np.int64)

    for arr in (points, node_point, node_ptr, node_lo, node_hi, edges, overlap):
        arr.setflags(write=False)
    return GridGraph(
        map=map_,
        L=L,
        resolution=resolution,
        neighbourhood=neighbourhood,
        points=points,
        point_arcs=point_arcs,
        node_point=node_point,
        node_ptr=node_ptr,
        node_lo=node_lo,
        node_hi=node_hi,
        point_edges=edges,
        overlap=overlap,
    )


def _least_fixed_point(g: GridGraph) -> np.ndarray:
    """Escapable nodes: least fixed point of conditions (a)/(b) of Sec. 4, by worklist.

    One *group* per (node a at p, neighbour p'), holding the count of not-yet-escapable
    nodes at p' that overlap a. A group at zero means (a) (it started at zero) or (b)
    (it reached zero): its node is escapable. Each overlap pair is processed once, when
    its far node becomes escapable, so the whole run is linear in the graph size.
    """
    edges, ptr = g.point_edges, g.node_ptr
    m = len(edges)
    src = np.concatenate([edges[:, 0], edges[:, 1]])  # directed steps p -> p'
    cnt = ptr[src + 1] - ptr[src]
    gstart = np.cumsum(cnt) - cnt
    group_node = _concat_ranges(ptr[src], ptr[src + 1])
    n_groups = len(group_node)
    a, b, e = g.overlap[:, 0], g.overlap[:, 1], g.overlap[:, 2]
    # directed overlap pairs (near node, far node, step): a->b on step e, b->a on e + m
    near = np.concatenate([a, b])
    far = np.concatenate([b, a])
    step = np.concatenate([e, e + m])
    pair_group = gstart[step] + (near - ptr[src[step]])
    count = np.bincount(pair_group, minlength=n_groups)

    esc = np.zeros(g.n_nodes, dtype=bool)
    esc[group_node[count == 0]] = True
    order = np.argsort(far, kind="stable")
    far_ptr = np.searchsorted(far[order], np.arange(g.n_nodes + 1))
    sorted_group = pair_group[order]
    frontier = np.flatnonzero(esc)
    while frontier.size:
        groups = sorted_group[_concat_ranges(far_ptr[frontier], far_ptr[frontier + 1])]
        np.subtract.at(count, groups, 1)
        done = np.unique(groups[count[groups] == 0])
        new = np.unique(group_node[done])
        frontier = new[~esc[new]]
        esc[frontier] = True
    return esc


@functools.lru_cache(maxsize=8)
def _cached_graph(map_: Map, L: float, resolution: float, neighbourhood: int) -> GridGraph:
    return grid_graph(map_, L, resolution=resolution, neighbourhood=neighbourhood)


# --------------------------------------------------------------------------- verdicts
@dataclass(frozen=True)
class GridVerdict:
    """The grid oracle's answer to Props. 2 and 5 at one rod length.

    Attributes:
        evader_wins: some grid point carries only escapable nodes (or no free arc).
        witness_point: such a point (the one farthest from the walls), else ``None``.
        n_points: grid points in free space.
        n_nodes: nodes (point, arc).
        n_escapable: escapable nodes.
        n_edges: graph edges (overlapping arcs of neighbouring points).
        resolution: grid spacing.
        L: rod length.
    """

    evader_wins: bool
    witness_point: tuple[float, float] | None
    n_points: int
    n_nodes: int
    n_escapable: int
    n_edges: int
    resolution: float
    L: float


def grid_verdict(map: Map, L: float, *, resolution: float, neighbourhood: int = 8) -> GridVerdict:
    """Decide, approximately, whether the evader wins at rod length L (Props. 2 and 5).

    Args:
        map: the world.
        L: rod length (> 0).
        resolution: grid spacing (> 0).
        neighbourhood: 8 (default) or 4.

    Returns:
        A :class:`GridVerdict`.

    Raises:
        InvalidConfigError: as :func:`grid_graph`.
    """
    L, resolution = _check(map, L, resolution, neighbourhood)
    g = _cached_graph(map, L, resolution, neighbourhood)
    winners = np.flatnonzero(g.point_escapable)
    witness = None
    if winners.size:
        best = winners[np.argmax(_clearance(map, g.points[winners]))]
        witness = (float(g.points[best, 0]), float(g.points[best, 1]))
    return GridVerdict(
        evader_wins=bool(winners.size),
        witness_point=witness,
        n_points=g.n_points,
        n_nodes=g.n_nodes,
        n_escapable=int(g.escapable.sum()),
        n_edges=len(g.overlap),
        resolution=resolution,
        L=L,
    )


def _probe(
    map_: Map, L: float, point: np.ndarray, resolution: float, neighbourhood: int
) -> tuple[tuple[Arc, ...], np.ndarray]:
    """Free arcs at an off-grid point and which are escapable, by one evader step.

    The point joins the grid as a source of steps only: arc a at the point is escapable
    if for some grid point p' within 1.5 resolution and in reach, (a) no arc at p' is
    connected to a along the step or (b) every connected arc is escapable in the grid's
    fixed point.
    """
    if not map_.contains(point[None])[0]:
        raise InvalidPlacementError(f"point: {tuple(point.tolist())} is not in free space")
    g = _cached_graph(map_, L, resolution, neighbourhood)
    kernel = kernel_for(map_)
    arcs = tuple(kernel.free_arcs(point, L).arcs)
    near = np.flatnonzero(np.linalg.norm(g.points - point, axis=1) <= 1.5 * resolution)
    near = near[_steps_clear(map_, np.repeat(point[None], len(near), axis=0), g.points[near])]
    esc = np.zeros(len(arcs), dtype=bool)
    here = (point, *_arrays(arcs))
    for p in near.tolist():
        nodes = np.arange(g.node_ptr[p], g.node_ptr[p + 1])
        there = (g.points[p], g.node_lo[nodes], g.node_hi[nodes])
        rel = _step_relation(kernel, L, here, there, _MAX_DEPTH)
        esc |= ~np.any(rel & ~g.escapable[nodes][None], axis=1)
    return arcs, esc


def grid_safe_arcs(
    map: Map,
    L: float,
    point: Sequence[float] | np.ndarray,
    *,
    resolution: float,
    neighbourhood: int = 8,
) -> tuple[Arc, ...]:
    """The free arcs at ``point`` that are not escapable in the grid's fixed point.

    Args:
        map: the world.
        L: rod length (> 0).
        point: the evader position (x, y), in free space; it need not be a grid point.
        resolution: grid spacing (> 0).
        neighbourhood: 8 (default) or 4.

    Returns:
        The safe arcs (a subset of the kernel's free arcs at ``point``), sorted by ``lo``.

    Raises:
        InvalidConfigError: as :func:`grid_graph`.
        InvalidPlacementError: ``point`` not finite or not in free space.
    """
    L, resolution = _check(map, L, resolution, neighbourhood)
    arcs, esc = _probe(map, L, _as_point(point), resolution, neighbourhood)
    return tuple(a for a, e in zip(arcs, esc, strict=True) if not e)


def grid_escapable(
    map: Map,
    L: float,
    point: Sequence[float] | np.ndarray,
    theta: float,
    *,
    resolution: float,
    neighbourhood: int = 8,
) -> bool:
    """Whether the configuration (point, theta) lies in an escapable node (Sec. 4).

    Args:
        map: the world.
        L: rod length (> 0).
        point: the evader position (x, y), in free space.
        theta: direction from evader to pursuer (radians, eq. 1); must be free.
        resolution: grid spacing (> 0).
        neighbourhood: 8 (default) or 4.

    Returns:
        True if every free arc containing theta is escapable.

    Raises:
        InvalidConfigError: as :func:`grid_graph`.
        InvalidPlacementError: ``point`` not in free space, or theta not finite or blocked.
    """
    L, resolution = _check(map, L, resolution, neighbourhood)
    if not math.isfinite(float(theta)):
        raise InvalidPlacementError(f"theta: expected a finite angle, got {theta!r}")
    arcs, esc = _probe(map, L, _as_point(point), resolution, neighbourhood)
    inside = [e for a, e in zip(arcs, esc, strict=True) if a.contains(theta)]
    if not inside:
        raise InvalidPlacementError(
            f"theta: {theta!r} is blocked at point {tuple(np.asarray(point).tolist())} for "
            f"L={L:g}; free arcs are {[(round(a.lo, 6), round(a.hi, 6)) for a in arcs]}"
        )
    return all(inside)
