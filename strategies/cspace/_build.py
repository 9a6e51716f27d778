"""Building a :class:`~strategies.cspace.decomposition.Decomposition` (THEORY.md 1.3).

1. the exact arrangement of the critical curves (:mod:`strategies.cspace.arrangement`);
2. each face gets its cells from the kernel's free arcs at a point deep inside it;
   neighbouring faces with equal stop pairs are one noncritical region (a curve whose
   crossing changes nothing, counted in ``stats["merged_faces"]``);
3. every region is checked noncritical: at more points of each of its faces the stop
   pairs must be the region's (failures are counted, named and warned about);
4. each boundary piece gets its adjacency from two probe points at the exact middle of
   one of its edges, along the exact normal, matched to the two regions' cells by their
   stop pairs; a piece whose probes cannot be matched (it should not happen) falls back
   to matching arcs by overlap and is counted (``Decomposition.unresolved``) and warned
   about, never silent;
5. the escapable cells are the least fixed point of Sec. 4's definition (a worklist).
"""

from __future__ import annotations

import warnings

import numpy as np
import shapely
from shapely.geometry import Polygon

from envs.geometry import kernel_for
from envs.geometry.types import Arc, FreeArcs
from envs.maps.map import Map
from strategies.cspace._arcs import OVERLAP_TOL, StopPair, overlap, pairs
from strategies.cspace.arrangement import Arrangement, Piece, arrange
from strategies.cspace.curves import _curves, _walls
from strategies.cspace.decomposition import Boundary, Cell, Decomposition, Region
from strategies.cspace.tolerances import Tolerances, diameter

__all__ = ["build_decomposition"]

_PROBE_EDGES = 4  # edges of a piece tried (longest first)
_PROBE_SHRINK = (1.0, 0.1, 0.01, 1e-3)  # probe offsets tried, times the first one
_CHECK_POINTS = 2  # extra points per face at which the stops are checked


def _sample_points(faces: list[Polygon], chord: float) -> np.ndarray:
    """A point deep inside each face (farther than the polyline error from its edges)."""
    if not faces:
        return np.zeros((0, 2))
    arr = np.array(faces, dtype=object)
    pos = shapely.point_on_surface(arr)
    depth = shapely.distance(shapely.boundary(arr), pos)
    area = shapely.area(arr)
    perim = shapely.length(arr)
    width = np.where(perim > 0, 2.0 * area / np.maximum(perim, 1e-300), 0.0)
    weak = np.flatnonzero(((depth < 0.25 * width) | (depth < 4.0 * chord)) & (area > 0))
    if len(weak):
        tol = np.maximum(0.01 * np.sqrt(area[weak]), 1e-3 * width[weak])
        mic = shapely.maximum_inscribed_circle(arr[weak], tol)
        centre = shapely.get_point(mic, 0)
        better = shapely.distance(shapely.boundary(arr[weak]), centre) > depth[weak]
        pos[weak[better]] = centre[better]
    out = np.full((len(faces), 2), np.nan)
    ok = ~shapely.is_empty(pos)
    out[ok] = shapely.get_coordinates(pos[ok])
    return out


def _depth(faces: list[Polygon], pts: np.ndarray) -> np.ndarray:
    """Distance from each point to its face's polygon boundary."""
    arr = np.array(faces, dtype=object)
    return shapely.distance(shapely.boundary(arr), shapely.points(pts))


def _check_points(
    faces: list[Polygon], centre: np.ndarray, k: int, margin: float
) -> tuple[np.ndarray, np.ndarray]:
    """Up to ``k`` more points per face, halfway from the sample point to its vertices,
    farther than ``margin`` from its polygon (which is exact only to the chord tolerance)."""
    owner, pts = [], []
    for f, (poly, c) in enumerate(zip(faces, centre, strict=True)):
        ring = np.asarray(poly.exterior.coords)[:-1]
        if len(ring) == 0:
            continue
        pick = ring[np.linspace(0, len(ring) - 1, k + 2).astype(int)[1:-1]]
        owner.append(np.full(len(pick), f))
        pts.append(0.5 * (pick + c))
    if not pts:
        return np.zeros(0, dtype=np.intp), np.zeros((0, 2))
    owner = np.concatenate(owner)
    pts = np.concatenate(pts)
    arr = np.array(faces, dtype=object)
    inside = shapely.contains_xy(arr[owner], pts[:, 0], pts[:, 1])
    owner, pts = owner[inside], pts[inside]
    deep = shapely.distance(shapely.boundary(arr[owner]), shapely.points(pts)) > margin
    return owner[deep], pts[deep]


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


def _offsets(tol: Tolerances, length: float, width: float) -> list[float]:
    """Probe offsets to try on one side of a piece: a fraction of the piece and of the
    regions (``width``), shrinking to the kernel's resolution, then, to step over a
    sliver merged into the region, up to a few sliver widths."""
    floor = 4.0 * tol.kernel
    eps0 = max(min(tol.probe, 0.25 * length, 0.25 * width), floor)
    out = [max(eps0 * s, floor) for s in _PROBE_SHRINK]
    out += [k * tol.thin for k in (2.0, 4.0, 10.0) if k * tol.thin > eps0]
    return list(dict.fromkeys(out))


def _side(kernel, L: float, p: np.ndarray, n: np.ndarray, offsets, cands, cells_of):
    """The first probe ``p + eps n`` whose stops are one of the candidate regions' (a
    tuple, or a function of the probe point and offset):
    ``(region, arcs, cells)``; ``(-1, ...)`` when the probes leave the free region (a
    wall beyond a sliver); ``None`` if nothing matches."""
    for eps in offsets:
        q = p + eps * n
        if not kernel.contains_point(float(q[0]), float(q[1])):
            return (-1, None, None)
        fa = kernel.free_arcs(q, L)
        for r in cands(q, eps) if callable(cands) else cands:
            table, rep = cells_of[r]
            cells = _assign(fa, table, rep, strict=True)
            if cells is not None:
                return r, fa, cells
    return None


def _boundary(
    piece: Piece,
    arr: Arrangement,
    kernel,
    L: float,
    cells_of,
    tol: Tolerances,
    width: float,
    cands: tuple,
    over: tuple[bool, bool],
) -> tuple | None:
    """Adjacency across a boundary piece from the free arcs at two exact probe points.

    The probes sit at the exact middle of one of the piece's edges (the longest first),
    along the exact normal, each side at the first offset of :func:`_offsets` where the
    stops are those of one of that side's candidate regions (its own; or, across a
    sliver, a function of the probe point giving the regions near it: ``over``).

    Returns:
        ``(regions, point, normal, adjacent, resolved)``; ``None`` when the piece
        separates nothing (a sliver between a region and itself, or a wall); ``"sliver"``
        when the far side of a sliver matched no region around it.
    """
    lens = arr.edge_length[piece.edges]
    first = None
    for k in np.argsort(-lens)[:_PROBE_EDGES].tolist():
        p, n = arr.probe(int(piece.edges[k]), int(piece.signs[k]), L)
        if first is None:
            first = (p, n)
        offs = _offsets(tol, float(lens[k]), width)
        found = []
        for side, sgn in ((0, 1.0), (1, -1.0)):
            o = [e for e in offs if e > tol.thin] if over[side] else offs
            found.append(_side(kernel, L, p, sgn * n, o, cands[side], cells_of))
        if found[0] is None or found[1] is None:
            continue
        (ra, fa, ia), (rb, fb, ib) = found
        if ra < 0 or rb < 0 or ra == rb:
            return None
        return (ra, rb), p, n, _adjacent(fa, ia, fb, ib), True
    if any(over):
        return "sliver"  # nothing beyond the sliver matches: counted, no adjacency
    p, n = first
    a, b = cands[0][0], cands[1][0]
    eps = min(tol.probe, 0.25 * float(lens.max()))
    fp = kernel.free_arcs(p + eps * n, L)
    fm = kernel.free_arcs(p - eps * n, L)
    ia = _assign(fp, *cells_of[a], strict=False)
    ib = _assign(fm, *cells_of[b], strict=False)
    return (a, b), p, n, _adjacent(fp, ia, fm, ib), False


def _escapable(n_cells: int, boundaries: tuple[Boundary, ...], cell_region: list[int]):
    """Least fixed point of Sec. 4's definition; returns (flags, reason, via)."""
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


def _merge_equal(arr: Arrangement, sigs: list[frozenset]) -> tuple[list[int], int]:
    """Group faces joined by a piece whose two sides have the same stop pairs.

    Crossing a critical curve changes the stop pairs (THEORY.md 1.4) unless the curve
    is not critical there; two neighbouring faces with equal stop pairs are one
    noncritical region. Returns the region of every face (-1 for slivers, whose
    signature is ``None``) and the number of merges.
    """
    parent = list(range(len(arr.faces)))

    def find(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    merges = 0
    for piece in arr.pieces:
        a, b = piece.faces
        if sigs[a] is not None and sigs[a] == sigs[b]:
            ra, rb = find(a), find(b)
            if ra != rb:
                parent[max(ra, rb)] = min(ra, rb)
                merges += 1
    roots = sorted({find(i) for i in range(len(parent)) if sigs[i] is not None})
    index = {r: k for k, r in enumerate(roots)}
    return [index.get(find(i), -1) for i in range(len(parent))], merges


def build_decomposition(world: Map, L: float, chord_tol: float | None = None) -> Decomposition:
    """Compute the decomposition without touching any cache (see :func:`decompose`)."""
    tol = Tolerances.of(world, L, chord_tol)
    if L >= diameter(world):  # no segment of length L fits in the map at all
        free = world.free_region
        rp = free.representative_point()
        region = Region(0, free, np.array([rp.x, rp.y]), (), ())
        return Decomposition(world, L, _walls(world), (region,), (), (), tol.chord, {})
    curves = _curves(world, L, tol.chord, True)
    arr = arrange(world, curves, tol)
    kernel = kernel_for(world)
    faces = list(arr.faces)
    points = _sample_points(faces, tol.chord)
    # prefer the exact samples, unless the polygon's is much deeper (a fat face)
    exact = np.isfinite(arr.depth) & ~(arr.depth < 0.1 * _depth(faces, points))
    points[exact] = arr.samples[exact]
    face_arcs = [
        None if thin else kernel.free_arcs(p, L) for p, thin in zip(points, arr.sliver, strict=True)
    ]
    sigs = [None if fa is None else frozenset(pairs(fa)) for fa in face_arcs]
    group, merged = _merge_equal(arr, sigs)
    n_regions = max(group, default=-1) + 1
    members: list[list[int]] = [[] for _ in range(n_regions)]
    for f, g in enumerate(group):
        if g >= 0:
            members[g].append(f)
    rep_face = [max(m, key=lambda f: faces[f].area) for m in members]
    # the noncritical check: more points per face must show the region's stop pairs
    owner, extra = _check_points(faces, points, _CHECK_POINTS, 2.0 * tol.chord + tol.probe)
    violations = [
        (int(group[f]), p)
        for f, p in zip(owner.tolist(), extra, strict=True)
        if sigs[f] is not None and frozenset(pairs(kernel.free_arcs(p, L))) != sigs[f]
    ]
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
    g_arr = np.asarray(group)
    real = g_arr >= 0
    f_area = np.array([f.area for f in faces])
    f_perim = np.array([f.length for f in faces])
    r_area = np.bincount(g_arr[real], weights=f_area[real], minlength=n_regions)
    r_perim = np.bincount(g_arr[real], weights=f_perim[real], minlength=n_regions)
    width = 2.0 * r_area / np.maximum(r_perim, 1e-300)
    tree = shapely.STRtree(faces)

    def near(q: np.ndarray, eps: float) -> list[int]:
        """Regions of the faces near ``q`` (beyond a sliver; polygons are exact only to
        the chord tolerance)."""
        hit = tree.query(shapely.Point(q), predicate="dwithin", distance=eps + 2 * tol.chord)
        return sorted({group[f] for f in hit.tolist() if group[f] >= 0})

    found = []
    lost = 0
    for piece in arr.pieces:
        fa_, fb_ = piece.faces
        ra, rb = group[fa_], group[fb_]
        if (ra < 0 and rb < 0) or ra == rb:
            continue
        ca = (ra,) if ra >= 0 else near
        cb = (rb,) if rb >= 0 else near
        w = min(width[r] for r in (ra, rb) if r >= 0)
        res = _boundary(piece, arr, kernel, L, region_cells, tol, w, (ca, cb), (ra < 0, rb < 0))
        if res == "sliver":
            lost += 1
        elif res is not None:
            found.append((res, piece))
    boundaries = tuple(
        Boundary(i, regs, piece.curves, piece.segments, p, n, adj, ok)
        for i, ((regs, p, n, adj, ok), piece) in enumerate(found)
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
    regions = tuple(
        Region(
            r,
            faces[members[r][0]]
            if len(members[r]) == 1
            else shapely.union_all([shapely.make_valid(faces[f]) for f in members[r]]),
            points[rep_face[r]],
            tuple(region_ids[r]),
            tuple(bounds_of[r]),
        )
        for r in range(n_regions)
    )
    stats = dict(arr.stats)
    stats["faces"] = len(faces)
    stats["merged_faces"] = merged
    stats["noncritical_violations"] = len(violations)
    stats["slivers_unresolved"] = lost
    dec = Decomposition(world, L, curves, regions, cells, boundaries, tol.chord, stats)
    _warn(dec, violations)
    return dec


def _warn(dec: Decomposition, violations) -> None:
    """One warning naming what went wrong, if anything did (never silent)."""
    problems = []
    if dec.unresolved:
        problems.append(f"{dec.unresolved} boundary pieces matched by overlap only")
    if violations:
        r, p = violations[0]
        problems.append(
            f"{len(violations)} points whose stops differ from their region's "
            f"(first: region {r} at ({p[0]:.6g}, {p[1]:.6g}))"
        )
    if dec.stats.get("dangling"):
        problems.append(f"{dec.stats['dangling']} dangling curve pieces")
    if dec.stats.get("slivers_unresolved"):
        problems.append(f"{dec.stats['slivers_unresolved']} pieces along slivers unresolved")
    if dec.stats.get("orphan_holes"):
        problems.append(f"{dec.stats['orphan_holes']} curve components outside every face")
    if problems:
        warnings.warn(
            f"decompose({dec.map.name!r}, L={dec.L:g}): the arrangement is not exact: "
            + "; ".join(problems)
            + ". Please report this map and L.",
            RuntimeWarning,
            stacklevel=3,
        )
