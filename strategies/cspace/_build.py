"""Building a :class:`~strategies.cspace.decomposition.Decomposition` (THEORY.md 1.3).

Faces of the curve arrangement get their cells from the free arcs at a sample point;
neighbouring faces with equal stop pairs are merged (an artefact of the polylines);
each boundary piece gets its adjacency from two probe points; the escapable cells are
the least fixed point of Sec. 4's definition, computed by a worklist.
"""

from __future__ import annotations

import math

import numpy as np
import shapely
import shapely.ops
from shapely.geometry import Polygon

from envs.geometry import kernel_for
from envs.geometry.types import Arc, FreeArcs
from envs.maps.map import Map
from strategies.cspace._arcs import OVERLAP_TOL, StopPair, overlap, pairs
from strategies.cspace.arrangement import SNAP_REL, Arrangement, Piece, arrange
from strategies.cspace.curves import critical_curves
from strategies.cspace.decomposition import (
    ADJ_EPS_REL,
    Boundary,
    Cell,
    Decomposition,
    Region,
)

__all__ = ["build_decomposition"]

_PROBE_SEGMENTS = 4  # segments of a piece tried before walking out along the normal


def _sample_point(poly: Polygon) -> np.ndarray:
    """A point far from the boundary of ``poly`` (pole of inaccessibility, coarse)."""
    scale = math.sqrt(poly.area)
    p = shapely.ops.polylabel(poly, tolerance=max(scale * 0.02, 1e-12))
    if not poly.contains(p):
        p = shapely.point_on_surface(poly)
    return np.array([p.x, p.y])


def _assign(fa: FreeArcs, table: dict, rep: dict, strict: bool) -> list[int | None] | None:
    """Cells of the arcs ``fa`` in a region (``table``: stop pair -> cell).

    Strict: the stop pairs must be exactly the region's, else ``None``. Otherwise an arc
    with unknown stops goes to the region's cell whose sample arc overlaps it most.
    """
    keys = pairs(fa)
    if set(keys) == set(table):
        return [table[k] for k in keys]
    if strict:
        return None
    out = []
    for k, arc in zip(keys, fa.arcs, strict=True):
        if k in table:
            out.append(table[k])
            continue
        best = max(rep, key=lambda c: overlap(arc, rep[c]), default=None)
        out.append(best if best is not None and overlap(arc, rep[best]) > OVERLAP_TOL else None)
    return out


def _adjacent(fa_a, ia, fa_b, ib) -> tuple[tuple[int, int], ...]:
    """Pairs of cells whose arcs overlap with positive length (footnote 3)."""
    adj = set()
    for x, ca in zip(fa_a.arcs, ia, strict=True):
        for y, cb in zip(fa_b.arcs, ib, strict=True):
            if ca is not None and cb is not None and overlap(x, y) > OVERLAP_TOL:
                adj.add((ca, cb))
    return tuple(sorted(adj))


def _walk(kernel, L, p, n, table, eps, reach) -> FreeArcs | None:
    """Free arcs at the first point ``p + s n`` (s = eps, 3 eps, ...) with the region's stops."""
    s = eps
    while s <= reach:
        fa = kernel.free_arcs(p + s * n, L)
        if set(pairs(fa)) == set(table):
            return fa
        s *= 3.0
    return None


def _boundary(bid, piece: Piece, curves, kernel, L, regions_cells, eps0, reach) -> Boundary:
    """Adjacency across a boundary piece from the free arcs at two probe points.

    The probes sit at ``+- eps`` along the normal of the piece's longest segments, at the
    exact curve point. When the stops there are not exactly the two regions' (a thin
    region the polylines do not resolve, within the chord tolerance), the probes walk
    out along the normal (up to ``reach``) to the first points with the regions' stops;
    failing that, arcs are matched to cells by overlap (``resolved=False`` either way).
    """
    a, b = piece.faces
    table_a, arcs_a = regions_cells[a]
    table_b, arcs_b = regions_cells[b]
    seg = piece.segments
    lens = np.hypot(*(seg[:, 1] - seg[:, 0]).T)
    probes = []
    for k in np.argsort(-lens)[:_PROBE_SEGMENTS].tolist():
        p0, p1 = seg[k]
        d = (p1 - p0) / lens[k]
        n = np.array([-d[1], d[0]])
        mid = 0.5 * (p0 + p1)
        if piece.curves:
            c = curves[piece.curves[0]]
            if c.shape != "segment":
                mid = c.evaluate(c.project(mid[None]))[0][0]
        eps = min(eps0, 1e-3 * lens[k])
        probes.append((mid, n, eps))
        for e in (eps, 1e-2 * eps):
            fp = kernel.free_arcs(mid + e * n, L)
            fm = kernel.free_arcs(mid - e * n, L)
            ia = _assign(fp, table_a, arcs_a, strict=True)
            ib = _assign(fm, table_b, arcs_b, strict=True)
            if ia is not None and ib is not None:
                return Boundary(bid, (a, b), piece.curves, seg, mid, n, _adjacent(fp, ia, fm, ib))
    mid, n, eps = probes[0]
    fp = _walk(kernel, L, mid, n, table_a, eps, reach)
    fm = _walk(kernel, L, mid, -n, table_b, eps, reach)
    if fp is None:
        fp = kernel.free_arcs(mid + eps * n, L)
    if fm is None:
        fm = kernel.free_arcs(mid - eps * n, L)
    ia = _assign(fp, table_a, arcs_a, strict=False)
    ib = _assign(fm, table_b, arcs_b, strict=False)
    return Boundary(bid, (a, b), piece.curves, seg, mid, n, _adjacent(fp, ia, fm, ib), False)


def _escapable(n_cells: int, boundaries: tuple[Boundary, ...], cell_region: list[int]):
    """Least fixed point of Sec. 4's definition; returns (flags, reason, via)."""
    # for each (cell, boundary of its region): the set of adjacent cells across it
    adj: dict[tuple[int, int], set[int]] = {}
    region_bounds: dict[int, list[int]] = {}
    for b in boundaries:
        for r in b.regions:
            region_bounds.setdefault(r, []).append(b.id)
    for c in range(n_cells):
        for bid in region_bounds.get(cell_region[c], ()):
            adj[(c, bid)] = set()
    for b in boundaries:
        for i, j in b.adjacent:
            adj[(i, b.id)].add(j)
            adj[(j, b.id)].add(i)
    esc = [False] * n_cells
    reason: list[str | None] = [None] * n_cells
    via: list[int | None] = [None] * n_cells
    count = {k: len(v) for k, v in adj.items()}
    watchers: dict[int, list[tuple[int, int]]] = {}
    for (c, bid), nbrs in adj.items():
        for x in nbrs:
            watchers.setdefault(x, []).append((c, bid))
    stack = []
    for (c, bid), n in sorted(count.items()):
        if n == 0 and not esc[c]:
            esc[c], reason[c], via[c] = True, "a", bid
            stack.append(c)
    while stack:
        x = stack.pop()
        for c, bid in watchers.get(x, ()):
            count[(c, bid)] -= 1
            if count[(c, bid)] == 0 and not esc[c]:
                esc[c], reason[c], via[c] = True, "b", bid
                stack.append(c)
    return esc, reason, via


def _merge_equal(arr: Arrangement, sigs: list[frozenset]) -> list[int]:
    """Group faces joined by a piece whose two sides have the same stop pairs.

    Crossing a semi-free critical curve always changes the stop pairs (THEORY.md 1.4),
    so two neighbouring faces with equal stop pairs are one noncritical region cut by an
    artefact of the polylines (a sliver where two curves are tangent).
    """
    parent = list(range(len(arr.faces)))

    def find(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    for piece in arr.pieces:
        a, b = piece.faces
        if sigs[a] == sigs[b]:
            ra, rb = find(a), find(b)
            if ra != rb:
                parent[max(ra, rb)] = min(ra, rb)
    roots = sorted({find(i) for i in range(len(parent))})
    index = {r: k for k, r in enumerate(roots)}
    return [index[find(i)] for i in range(len(parent))]


def build_decomposition(world: Map, L: float, chord_tol: float | None = None) -> Decomposition:
    """Compute the decomposition without touching any cache (see :func:`decompose`)."""
    curves = critical_curves(world, L, chord_tol=chord_tol)
    tol = next((c.tolerance for c in curves if c.tolerance > 0), chord_tol or 0.0)
    arr: Arrangement = arrange(world, curves)
    kernel = kernel_for(world)
    points = [_sample_point(f) for f in arr.faces]
    face_arcs = [kernel.free_arcs(p, L) for p in points]
    group = _merge_equal(arr, [frozenset(pairs(fa)) for fa in face_arcs])
    n_regions = max(group, default=-1) + 1
    members: list[list[int]] = [[] for _ in range(n_regions)]
    for f, g in enumerate(group):
        members[g].append(f)
    rep_face = [max(m, key=lambda f: arr.faces[f].area) for m in members]
    cells_tmp: list[tuple[int, StopPair, Arc]] = []
    region_cells: list[tuple[dict[StopPair, int], dict[int, Arc]]] = []
    region_ids: list[list[int]] = []
    for r in range(n_regions):
        fa = face_arcs[rep_face[r]]
        table, rep, ids = {}, {}, []
        for key, arc in zip(pairs(fa), fa.arcs, strict=True):
            cid = len(cells_tmp)
            cells_tmp.append((r, key, arc))
            table[key] = cid
            rep[cid] = arc
            ids.append(cid)
        region_cells.append((table, rep))
        region_ids.append(ids)
    pieces = [
        Piece((group[p.faces[0]], group[p.faces[1]]), p.curves, p.segments)
        for p in arr.pieces
        if group[p.faces[0]] != group[p.faces[1]]
    ]
    eps0 = ADJ_EPS_REL * world.scale
    reach = max(30.0 * tol, 1e-4 * world.scale)
    boundaries = tuple(
        _boundary(i, piece, curves, kernel, L, region_cells, eps0, reach)
        for i, piece in enumerate(pieces)
    )
    cell_region = [c[0] for c in cells_tmp]
    esc, reason, via = _escapable(len(cells_tmp), boundaries, cell_region)
    cells = tuple(
        Cell(i, r, key, arc, esc[i], reason[i], via[i]) for i, (r, key, arc) in enumerate(cells_tmp)
    )
    bounds_of: list[list[int]] = [[] for _ in range(n_regions)]
    for b in boundaries:
        for r in b.regions:
            bounds_of[r].append(b.id)
    grid = SNAP_REL * world.scale
    regions = tuple(
        Region(
            r,
            arr.faces[members[r][0]]
            if len(members[r]) == 1
            else shapely.union_all([arr.faces[f] for f in members[r]], grid_size=grid),
            points[rep_face[r]],
            tuple(region_ids[r]),
            tuple(bounds_of[r]),
        )
        for r in range(n_regions)
    )
    return Decomposition(world, L, curves, regions, cells, boundaries, tol)
