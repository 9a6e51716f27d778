"""Building a :class:`~strategies.cspace.decomposition.Decomposition` (THEORY.md 1.3).

1. the exact arrangement of the critical curves (:mod:`strategies.cspace.arrangement`);
2. each face gets its cells from the free arcs at a point deep inside it (on its polygon
   when the face is wide, on the exact curves when it is thin); neighbouring faces with
   equal stop pairs are one noncritical region (a curve whose crossing changes nothing,
   counted in ``stats["merged_faces"]``);
3. every region is checked noncritical: at another point of each face the stop pairs
   must be the region's (failures are counted, named and warned about);
4. each boundary piece gets its adjacency from probe points on the exact curves
   (:mod:`strategies.cspace._probing`), matched to the two regions' cells by their stop
   pairs; a piece whose probes cannot be matched falls back to overlaps and is counted
   (``Decomposition.unresolved``) and warned about, never silent;
5. the escapable cells are the least fixed point of Sec. 4's definition (a worklist).

Free arcs are computed for all points of a step at once
(:func:`~strategies.cspace._batch_arcs.free_arcs_batch`, the kernel's answer vectorised).
"""

from __future__ import annotations

import warnings

import numpy as np
import shapely

from envs.maps.map import Map
from envs.tolerances import REL_LENGTH_TOL
from strategies.cspace._batch_arcs import ArcBatch, free_arcs_batch, stop_of
from strategies.cspace._probing import PROBE_FLOOR, probe_pieces, signature_hashes
from strategies.cspace._progress import Progress
from strategies.cspace.arrangement import Arrangement, arrange
from strategies.cspace.curves import _curves, _walls
from strategies.cspace.decomposition import Boundary, Cell, Decomposition, Region
from strategies.cspace.tolerances import RESOLVED_PASSAGE, Tolerances, diameter

__all__ = ["build_decomposition"]


def _sample_points(arr: Arrangement) -> np.ndarray:
    """A point deep inside each face: on its polygon when the face is wide (farther than
    four chord tolerances from the polygon's edges), on the exact curves otherwise."""
    faces = np.array(arr.faces, dtype=object)
    chord = arr.tol.chord
    out = np.full((len(faces), 2), np.nan)
    if len(faces) == 0:
        return out
    empty = shapely.is_empty(faces)
    pos = shapely.point_on_surface(faces)
    depth = np.where(empty, 0.0, shapely.distance(shapely.boundary(faces), pos))
    ok = ~empty & (depth > 4.0 * chord)
    out[ok] = shapely.get_coordinates(pos[ok])
    weak = np.flatnonzero(~ok & ~arr.sliver)
    if len(weak):
        pts, d = arr.exact_samples(weak)
        good = np.isfinite(d)
        out[weak[good]] = pts[good]
        rest = weak[~good & ~empty[weak]]
        out[rest] = shapely.get_coordinates(pos[rest])
    return out


def _check_points(arr: Arrangement, centre: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """One more point per wide face: halfway from its sample point to the farthest vertex
    of its polygon's ring, kept if it lies deep inside (the polygon is exact only to the
    chord tolerance)."""
    faces = np.array(arr.faces, dtype=object)
    margin = 2.0 * arr.tol.chord + arr.tol.probe
    ok = np.flatnonzero(~shapely.is_empty(faces) & np.isfinite(centre[:, 0]))
    if len(ok) == 0:
        return np.zeros(0, dtype=np.intp), np.zeros((0, 2))
    rings = shapely.get_exterior_ring(faces[ok])
    xy, idx = shapely.get_coordinates(rings, return_index=True)
    d = np.hypot(*(xy - centre[ok][idx]).T)
    far = np.zeros(len(ok), dtype=np.intp)
    order = np.lexsort((-d, idx))
    first = np.concatenate([[True], idx[order][1:] != idx[order][:-1]])
    far[idx[order][first]] = order[first]
    pts = 0.5 * (xy[far] + centre[ok])
    inside = shapely.contains_xy(faces[ok], pts[:, 0], pts[:, 1])
    deep = np.zeros(len(ok), dtype=bool)
    deep[inside] = (
        shapely.distance(shapely.boundary(faces[ok][inside]), shapely.points(pts[inside])) > margin
    )
    return ok[deep], pts[deep]


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


def _merge_equal(arr: Arrangement, sigs: list[frozenset | None]) -> tuple[np.ndarray, int]:
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
    return np.array([index.get(find(i), -1) for i in range(len(parent))], dtype=np.intp), merges


def _empty(world: Map, L: float, tol: Tolerances) -> Decomposition:
    """No segment of length L fits in the map: one region, no cell."""
    free = world.free_region
    rp = free.representative_point()
    region = Region(0, free, np.array([rp.x, rp.y]), (), ())
    return Decomposition(world, L, _walls(world), (region,), (), (), tol.chord, {})


def build_decomposition(
    world: Map, L: float, chord_tol: float | None = None, progress=None
) -> Decomposition:
    """Compute the decomposition without touching any cache (see :func:`decompose`).

    Args:
        world: the map.
        L: rod length.
        chord_tol: polyline tolerance (default ``CHORD_TOL_REL * L``).
        progress: optional :class:`strategies.cspace._progress.Progress`.
    """
    tol = Tolerances.of(world, L, chord_tol)
    if L >= diameter(world):
        return _empty(world, L, tol)
    progress = progress if progress is not None else Progress(False)
    step = progress.step
    step("critical curves")
    curves = _curves(world, L, tol.chord, True)
    step("arrangement", curves=len(curves))
    arr = arrange(world, curves, tol)
    faces = list(arr.faces)
    step("cells", faces=len(faces))
    points = _sample_points(arr)
    batch = free_arcs_batch(world, np.nan_to_num(points), L)
    keys = [None if arr.sliver[f] else batch.keys(f) for f in range(len(faces))]
    sigs = [None if k is None else frozenset(k) for k in keys]
    group, merged = _merge_equal(arr, sigs)
    n_regions = int(group.max(initial=-1)) + 1
    f_area = shapely.area(np.array(faces, dtype=object)) if faces else np.zeros(0)
    real = np.flatnonzero(group >= 0)
    rep_face = np.full(n_regions, -1, dtype=np.intp)
    order = real[np.lexsort((-f_area[real], group[real]))]
    firsts = np.concatenate([[True], group[order][1:] != group[order][:-1]]) if len(order) else []
    rep_face[group[order][firsts]] = order[firsts]
    # the noncritical check: another point of each face must show its stop pairs
    owner, extra = _check_points(arr, points)
    keep = group[owner] >= 0
    owner, extra = owner[keep], extra[keep]
    check = free_arcs_batch(world, extra, L) if len(owner) else None
    violations = []
    if check is not None:
        for t, f in enumerate(owner.tolist()):
            if frozenset(check.keys(t)) != sigs[f]:
                violations.append((int(group[f]), extra[t]))
    cells_tmp, region_cells, region_ids = _cells(batch, rep_face, keys)
    sig_r = [sigs[f] for f in rep_face.tolist()]
    f_perim = shapely.length(np.array(faces, dtype=object)) if faces else np.zeros(0)
    r_area = np.bincount(group[real], weights=f_area[real], minlength=n_regions)
    r_perim = np.bincount(group[real], weights=f_perim[real], minlength=n_regions)
    width = 2.0 * r_area / np.maximum(r_perim, 1e-300)
    step("boundaries", pieces=len(arr.pieces))
    r_hash = signature_hashes(batch)[rep_face]
    s_hash = np.zeros(len(faces), dtype=np.uint64)
    thin = np.flatnonzero(arr.sliver)
    if len(thin):
        at, _ = arr.exact_samples(thin)
        ok = np.isfinite(at[:, 0])
        if ok.any():
            s_hash[thin[ok]] = signature_hashes(free_arcs_batch(world, at[ok], L))
    probed, lost = probe_pieces(
        world, arr, group, sig_r, region_cells, width, r_hash, s_hash, curves
    )
    boundaries = tuple(
        Boundary(
            i,
            pr.regions,
            arr.pieces[pr.piece].curves,
            arr.pieces[pr.piece].segments,
            pr.point,
            pr.normal,
            pr.adjacent,
            pr.resolved,
        )
        for i, pr in enumerate(probed)
    )
    step("escapable cells", boundaries=len(boundaries))
    cell_region = [c[0] for c in cells_tmp]
    esc, reason, via = _escapable(len(cells_tmp), boundaries, cell_region)
    cells = tuple(
        Cell(i, r, key, arc, esc[i], reason[i], via[i]) for i, (r, key, arc) in enumerate(cells_tmp)
    )
    bounds_of: list[list[int]] = [[] for _ in range(n_regions)]
    for b in boundaries:
        for r in b.regions:
            bounds_of[r].append(b.id)
    members: list[list[int]] = [[] for _ in range(n_regions)]
    for f in real.tolist():
        members[group[f]].append(f)
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
    stats["slivers_unresolved"] = len(lost)
    stats["unresolved_passages"] = int(tol.unresolved)
    dec = Decomposition(world, L, curves, regions, cells, boundaries, tol.chord, stats)
    dec.timings = progress.close()
    _warn(dec, violations, lost, tol)
    return dec


def _cells(batch: ArcBatch, rep_face: np.ndarray, keys: list):
    """The cells above each region (one per free arc at its sample point)."""
    cells_tmp = []
    region_cells: list[dict] = []
    region_ids: list[list[int]] = []
    for r, f in enumerate(rep_face.tolist()):
        table, ids = {}, []
        for key, arc in zip(keys[f], batch.arcs(f), strict=True):
            cid = len(cells_tmp)
            cells_tmp.append((r, (stop_of(key[0]), stop_of(key[1])), arc))
            table[key] = cid
            ids.append(cid)
        region_cells.append(table)
        region_ids.append(ids)
    return cells_tmp, region_cells, region_ids


def _tip_ties(dec: Decomposition, points: list[np.ndarray]) -> tuple[np.ndarray, list[int]] | None:
    """The first point at which two or more wall vertices lie at distance L to within
    the smallest probe offset (``PROBE_FLOOR`` kernel length tolerances), and those
    vertices (None if no point has any). The kernel takes a vertex within its length
    tolerance of distance L for the rod's tip touching it (``envs.geometry``'s
    tip-at-vertex test), so near such a point it cannot tell which of them the tip
    touches, and the probes there (whose distances to the vertices change by less than
    their offsets) see tied stops, not the exact arrangement's."""
    world, L = dec.map, dec.L
    eps = PROBE_FLOOR * REL_LENGTH_TOL * world.scale
    for p in points:
        d = np.hypot(*(world.vertices - np.asarray(p)).T)
        tied = np.flatnonzero(np.abs(d - L) <= eps)
        if len(tied) >= 2:
            return np.asarray(p), tied.tolist()
    return None


def _problems(dec: Decomposition, tol: Tolerances, violations=()) -> list[str]:
    """What is not exact about ``dec``, read from its statistics (``violations``, the
    build's, name the first point)."""
    problems = []
    if dec.unresolved:
        problems.append(f"{dec.unresolved} boundary pieces matched by overlap only")
    if dec.stats.get("noncritical_violations"):
        first = ""
        if violations:
            r, p = violations[0]
            first = f" (first: region {r} at ({p[0]:.6g}, {p[1]:.6g}))"
        problems.append(
            f"{dec.stats['noncritical_violations']} points whose stops differ from their "
            f"region's{first}"
        )
    if dec.stats.get("dangling"):
        problems.append(f"{dec.stats['dangling']} dangling curve pieces")
    if dec.stats.get("slivers_unresolved"):
        problems.append(f"{dec.stats['slivers_unresolved']} pieces along slivers unresolved")
    if dec.stats.get("orphan_holes"):
        problems.append(f"{dec.stats['orphan_holes']} curve components outside every face")
    if tol.unresolved:
        wide = RESOLVED_PASSAGE * max(tol.probe, tol.collapse)
        problems.append(
            f"the map has a passage {tol.blocked:.2g} wide between its walls, narrower than "
            f"it resolves ({wide:.2g}: {RESOLVED_PASSAGE:g} times its probe offset, floored "
            "by the geometry kernel's length tolerance); a region there may be lost and the "
            f"verdict wrong. Widening that passage to over {wide:.2g} removes it"
        )
    return problems


def warn_cached(dec: Decomposition, tol: Tolerances, path: object) -> None:
    """The build's warning, for a decomposition read back from the cache file ``path``
    that is not exact (it loaded silently: only ``summary()`` said UNRELIABLE)."""
    problems = _problems(dec, tol)
    if not problems:  # not exact by a check this version does not name: say that much
        problems = ["an exactness check failed (see stats)"]
    warnings.warn(
        f"decompose({dec.map.name!r}, L={dec.L:g}): the arrangement is not exact: "
        + "; ".join(problems)
        + f" (read from the cache file {path}; building it warned the same, with the "
        "points where it failed)",
        RuntimeWarning,
        stacklevel=4,
    )


def _warn(dec: Decomposition, violations, lost: np.ndarray, tol: Tolerances) -> None:
    """One warning naming what went wrong, if anything did (never silent), and, where
    the cause is a tie the kernel cannot break at floating point, which one."""
    problems = _problems(dec, tol, violations)
    if not problems:
        return
    where = [b.point for b in dec.boundaries if not b.resolved]
    where += [np.asarray(p) for _, p in violations] + list(lost)
    tie = _tip_ties(dec, where)
    if tie is None:
        advice = "." if tol.unresolved and len(problems) == 1 else ". Please report this map and L."
    else:
        (x, y), tied = tie
        names = "vertices " + ", ".join(map(str, tied[:-1])) + f" and {tied[-1]}"
        gap = min(
            float(np.hypot(*(dec.map.vertices[a] - dec.map.vertices[b])))
            for a in tied
            for b in tied
            if a < b
        )
        advice = (
            f". Near ({x:.6g}, {y:.6g}) {names} lie at distance L from one point to within "
            f"{PROBE_FLOOR * REL_LENGTH_TOL * dec.map.scale:.2g} ({PROBE_FLOOR:g} times the "
            "geometry kernel's length tolerance): the kernel cannot tell which of them the "
            "rod's tip touches there (its stops tie), a degeneracy of this map at floating "
            "point, not a fault of the decomposition. Moving those vertices farther apart "
            f"(the nearest two are {gap:.2g} apart) removes it."
        )
    warnings.warn(
        f"decompose({dec.map.name!r}, L={dec.L:g}): the arrangement is not exact: "
        + "; ".join(problems)
        + advice,
        RuntimeWarning,
        stacklevel=3,
    )
