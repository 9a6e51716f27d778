"""Adjacency across boundary pieces, from probe points on the exact curves, in batches.

Footnote 3 of the paper: cells on the two sides of a critical curve are adjacent iff
their free arcs overlap with positive length next to it. Each boundary piece is probed at
the exact middle of one of its edges, along the exact normal, a small offset to each
side; the free arcs there (all probes of a round at once,
:func:`~strategies.cspace._batch_arcs.free_arcs_batch`) must carry exactly the stop
pairs of the region on that side, which identifies each arc's cell. A side whose probe
does not match tries a smaller offset, then other edges of the piece (longest first),
then other points of those edges (``PROBE_AT``: the kernel's stops are not the exact ones
in cusps near some curve ends, which can cover a short piece's middle); across a sliver
(a face too thin to probe) it steps over the sliver and takes whichever region lies
beyond; a piece along a speck (a face collapsed to a point) is not probed: it separates
nothing. Sides are matched independently, round after round, until each is
matched or out of attempts; a piece whose sides never match falls back to matching
arcs by overlap and is counted as unresolved (never silently).

Stop-pair sets are compared through an order-independent 64-bit hash of their pairs
(:func:`signature_hashes`); a match is then confirmed on the pairs themselves.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import shapely

from envs.maps.map import Map
from envs.tolerances import ANGLE_TOL
from strategies.cspace._arcs import OVERLAP_TOL
from strategies.cspace._batch_arcs import ArcBatch, free_arcs_batch
from strategies.cspace._samples import _first_hits
from strategies.cspace.arrangement import Arrangement

__all__ = [
    "CUSP_MARGIN",
    "PROBE_AT",
    "PROBE_EDGES",
    "PROBE_FLOOR",
    "PROBE_SHRINK",
    "Probed",
    "probe_pieces",
    "signature_hashes",
]

PROBE_EDGES = 4
"""Edges of a piece tried (longest first)."""

PROBE_SHRINK = (1.0, 0.1, 0.01, 1e-3)
"""Probe offsets tried on an edge, times the first one."""

PROBE_AT = (0.5, 0.25, 0.75, 0.1, 0.9)
"""Points of an edge probed, as fractions of its parameter interval: the middle first
(every edge and offset), then the others, nearer and nearer to its ends."""

PROBE_FLOOR = 4.0
"""The smallest probe offset, in the kernel's length tolerances."""

_THIN_STEPS = (2.0, 4.0, 10.0, 30.0)  # offsets past a sliver, times the sliver tolerance
_TWO_PI = 2.0 * math.pi


@dataclass
class Probed:
    """One boundary piece, probed.

    Attributes:
        piece: index into ``Arrangement.pieces``.
        regions: ``(A, B)``.
        point: the probe point on the exact curve.
        normal: unit normal there, pointing into A.
        adjacent: pairs (cell of A, cell of B) whose arcs overlap across it.
        resolved: False if the sides were matched by overlap (not by stops).
    """

    piece: int
    regions: tuple[int, int]
    point: np.ndarray
    normal: np.ndarray
    adjacent: tuple[tuple[int, int], ...]
    resolved: bool = True


def _mix(x: np.ndarray) -> np.ndarray:
    """splitmix64 finaliser, vectorised (uint64, wrapping arithmetic)."""
    x = x.astype(np.uint64)
    x ^= x >> np.uint64(30)
    x *= np.uint64(0xBF58476D1CE4E5B9)
    x ^= x >> np.uint64(27)
    x *= np.uint64(0x94D049BB133111EB)
    x ^= x >> np.uint64(31)
    return x


def signature_hashes(batch: ArcBatch) -> np.ndarray:
    """Per point, an order-independent 64-bit hash of its set of stop pairs."""
    with np.errstate(over="ignore"):
        h = _mix(_mix(batch.code_lo.astype(np.uint64)) ^ batch.code_hi.astype(np.uint64))
        out = np.zeros(len(batch), dtype=np.uint64)
        counts = np.diff(batch.offsets)
        has = np.flatnonzero(counts)
        if len(has):
            out[has] = np.add.reduceat(h, batch.offsets[:-1][has])
    return out


def _offsets(
    tol, length: np.ndarray, width: np.ndarray, over: np.ndarray, at: float = 0.5
) -> np.ndarray:
    """(k, 7) offsets to try on one side of an edge probed at fraction ``at`` of it (NaN:
    none): a fraction of the edge (half the distance to its nearer end) and of the
    regions (``width``) shrinking to the kernel's resolution, then a few sliver widths;
    across a sliver (``over``) only the sliver widths."""
    floor = PROBE_FLOOR * tol.kernel
    reach = 0.5 * min(at, 1.0 - at) * length
    eps0 = np.maximum(np.minimum(np.minimum(tol.probe, reach), 0.25 * width), floor)
    shrink = np.maximum(eps0[:, None] * np.asarray(PROBE_SHRINK)[None, :], floor)
    shrink[:, 1:][shrink[:, 1:] == shrink[:, :-1]] = np.nan  # clamped to the floor: once
    thin = np.asarray(_THIN_STEPS[:3]) * tol.thin
    past = np.where(thin[None, :] > eps0[:, None], thin[None, :], np.nan)
    out = np.concatenate([shrink, past], axis=1)
    over_row = np.full(out.shape, np.nan)
    over_row[:, : len(_THIN_STEPS)] = np.asarray(_THIN_STEPS) * tol.thin
    return np.where(over[:, None], over_row, out)


def _arc_overlaps(lo1, hi1, full1, lo2, hi2, full2) -> np.ndarray:
    """Length of the overlap of closed arcs, elementwise (``_arcs.overlap``)."""
    best = np.full(len(lo1), -np.inf)
    for s in (-_TWO_PI, 0.0, _TWO_PI):
        best = np.maximum(best, np.minimum(hi1, hi2 + s) - np.maximum(lo1, lo2 + s))
    best = np.where(full1, hi2 - lo2, best)
    return np.where(full2 & ~full1, hi1 - lo1, best)


def probe_pieces(
    world: Map,
    arr: Arrangement,
    region_of_face: np.ndarray,
    sigs: list[frozenset],
    cells: list[dict],
    width: np.ndarray,
    region_hash: np.ndarray | None = None,
    sliver_hash: np.ndarray | None = None,
    curves: tuple | None = None,
) -> tuple[list[Probed], int]:
    """Probe every piece separating two regions (or a region and a sliver).

    Args:
        world: the map.
        arr: the arrangement.
        region_of_face: region of each face (-1 for slivers).
        sigs: per region, its set of stop-code pairs.
        cells: per region, stop-code pair -> cell id.
        width: per region, twice its area over its perimeter.
        region_hash: per region, :func:`signature_hashes` of its stop pairs (computed
            from ``sigs`` if not given).
        sliver_hash: per face, the hash of the stops inside it if it is a sliver: a probe
            that never gets out of the sliver (an end of it, seen along its length) means
            the piece is that end, which separates nothing once the sliver is collapsed.
        curves: the critical curves (``Piece.curves`` index them): a side of a type-4
            piece that no probe matched gets one more probe past the kernel's cusp
            (:func:`_cusp_offset`).

    Returns:
        The probed pieces and, per piece along a sliver that could not be resolved
        (dropped, counted), a point of it (k, 2).
    """
    tol = arr.tol
    L = tol.L
    if region_hash is None:
        region_hash = np.array([_set_hash(s) for s in sigs], dtype=np.uint64)
    sig_hash = np.asarray(region_hash, dtype=np.uint64)
    # the jobs: pieces between two different regions (or a region and a sliver)
    fa = np.array([p.faces[0] for p in arr.pieces], dtype=np.intp)
    fb = np.array([p.faces[1] for p in arr.pieces], dtype=np.intp)
    ra, rb = region_of_face[fa], region_of_face[fb]
    # (a piece of a speck separates nothing: the faces around it meet at a point)
    speck = arr.speck[fa] | arr.speck[fb]
    job = np.flatnonzero(~((ra < 0) & (rb < 0)) & (ra != rb) & ~speck)
    n_jobs = len(job)
    if not n_jobs:  # no piece separates two regions (the rod fits only in specks)
        return [], np.zeros((0, 2))
    # each job's edges, longest first (at most PROBE_EDGES)
    n_e = np.array([len(arr.pieces[i].edges) for i in job.tolist()], dtype=np.intp)
    e_all = np.concatenate([arr.pieces[i].edges for i in job.tolist()]) if n_jobs else n_e
    s_all = np.concatenate([arr.pieces[i].signs for i in job.tolist()]) if n_jobs else n_e
    owner = np.repeat(np.arange(n_jobs), n_e)
    order = np.lexsort((-arr.edge_length[e_all], owner))
    e_all, s_all, owner = e_all[order], s_all[order], owner[order]
    rank = np.arange(len(owner)) - np.repeat(np.cumsum(n_e) - n_e, n_e)
    keep = rank < PROBE_EDGES
    e_all, s_all, owner, rank = e_all[keep], s_all[keep], owner[keep], rank[keep]
    edge_tab = np.full((n_jobs, PROBE_EDGES), -1, dtype=np.intp)
    sign_tab = np.zeros((n_jobs, PROBE_EDGES))
    edge_tab[owner, rank], sign_tab[owner, rank] = e_all, s_all
    regs = np.stack([ra[job], rb[job]], axis=1)
    real_w = np.where(regs >= 0, width[np.maximum(regs, 0)], np.inf).min(axis=1)
    # attempts per (job, side), in order: per point along the edges (PROBE_AT), per edge
    # (PROBE_EDGES), 7 offsets. A probe must land where the kernel's stop labels are
    # those of the exact arrangement: not always so near a curve's end, where the kernel
    # takes a block narrower than ANGLE_TOL for a mere contact (e.g. beside a type-2 arc
    # near the end of a type-4 segment on it, a cusp about ANGLE_TOL * L**2 / d wide at
    # distance d from the end); on a piece a few 1e-6 L short (a wall edge within a few
    # 1e-6 L of L) that cusp can cover the side at the middle at every offset, so the
    # other points of the edge are tried before giving up.
    length = np.where(edge_tab >= 0, arr.edge_length[np.maximum(edge_tab, 0)], np.nan)
    offs = np.stack(
        [
            np.stack(
                [
                    _offsets(
                        tol,
                        length.ravel(),
                        np.repeat(real_w, PROBE_EDGES),
                        np.repeat(regs[:, side] < 0, PROBE_EDGES),
                        at,
                    ).reshape(n_jobs, PROBE_EDGES, -1)
                    for at in PROBE_AT
                ],
                axis=1,
            ).reshape(n_jobs, -1)
            for side in (0, 1)
        ],
        axis=1,
    )  # (job, side, attempt): attempt = (at * PROBE_EDGES + edge) * n_off + offset
    n_off = offs.shape[2] // (len(PROBE_AT) * PROBE_EDGES)
    found = np.full((n_jobs, 2), -2, dtype=np.intp)  # region matched, -1: a wall, -2: none
    inside = np.zeros((n_jobs, 2), dtype=bool)  # a probe stayed inside the sliver
    own = np.zeros((n_jobs, 2), dtype=np.uint64)
    if sliver_hash is not None:
        own = np.stack([sliver_hash[fa[job]], sliver_hash[fb[job]]], axis=1).astype(np.uint64)
    hits = []  # per round: (job, side, arcs: code_lo, code_hi, lo, hi, owner position)
    hit_p = np.full((n_jobs, 2, 2), np.nan)  # (job, side, xy)
    hit_n = np.full((n_jobs, 2, 2), np.nan)
    first_p = np.full((n_jobs, 2), np.nan)
    first_n = np.full((n_jobs, 2), np.nan)
    face_tree = shapely.STRtree(list(arr.faces))
    beyond = _Beyond(arr, region_of_face)
    sig_regions: dict[int, list[int]] = {}
    for r, h in enumerate(sig_hash.tolist()):
        sig_regions.setdefault(h, []).append(r)
    for attempt in range(offs.shape[2]):
        a, k = divmod(attempt // n_off, PROBE_EDGES)
        eps = offs[:, :, attempt]
        todo_j, todo_s = np.nonzero((found == -2) & np.isfinite(eps) & (edge_tab[:, k, None] >= 0))
        if len(todo_j) == 0:
            if not ((found == -2) & np.isfinite(offs[:, :, attempt:]).any(axis=2)).any():
                break
            continue
        p, n = arr.probes(edge_tab[todo_j, k], sign_tab[todo_j, k], PROBE_AT[a])
        fresh = np.isnan(first_p[todo_j, 0])
        first_p[todo_j[fresh]], first_n[todo_j[fresh]] = p[fresh], n[fresh]
        side_sign = np.where(todo_s == 0, 1.0, -1.0)
        q = p + (side_sign * eps[todo_j, todo_s])[:, None] * n
        batch = free_arcs_batch(world, q, L)
        h = signature_hashes(batch)
        r = regs[todo_j, todo_s]
        match = np.where((r >= 0) & (h == sig_hash[np.maximum(r, 0)]), r, -2)
        # across a sliver: a wall beyond, or a region near the probe with these stops
        for t in np.flatnonzero(r < 0).tolist():
            j, s = int(todo_j[t]), int(todo_s[t])
            if not shapely.contains_xy(world.prepared_free_region, *q[t]):
                found[j, s] = -1
                continue
            near = face_tree.query(
                shapely.Point(q[t]), predicate="dwithin", distance=eps[j, s] + 2 * tol.chord
            )
            cands = {int(region_of_face[f]) for f in near.tolist()} - {-1}
            cands |= beyond(int(fa[job[j]] if s == 0 else fb[job[j]]))
            keys = frozenset(batch.keys(t))
            m = [c for c in sig_regions.get(int(h[t]), ()) if c in cands and keys == sigs[c]]
            if m:
                match[t] = m[0]
            else:
                inside[j, s] |= bool(h[t] == own[j, s])
        got = np.flatnonzero(match >= 0)
        if len(got) == 0:
            continue
        jj, ss = todo_j[got], todo_s[got]
        found[jj, ss] = match[got]
        _keep_hits(batch, got, jj, ss, p, n, hits, hit_p, hit_n)
    if curves is not None:
        _past_cusps(world, arr, curves, job, regs, found, offs, edge_tab, sign_tab, sig_hash,
                    hits, hit_p, hit_n)  # fmt: skip
    found[(found == -2) & inside] = -1  # the end of a sliver: nothing beyond to adjoin
    return _finish(world, arr, job, regs, found, hits, hit_p, hit_n, first_p, first_n, cells)


CUSP_MARGIN = 2.0
"""A probe past a type-4 cusp sits this many times the cusp's half-width from the piece:
e's blocked arc is then twice ANGLE_TOL wide, kept and not tied with its neighbour's."""


def _cusp_offset(L: float, d: np.ndarray) -> np.ndarray:
    """Half-width of the kernel's cusp beside a type-4 segment at distance ``d`` from its
    vertex (``d < L``).

    At a point ``eps`` off the segment (the rod along edge e, its body on e's end v), e's
    blocked arc runs from the direction of v (distance d) to that of e's point at reach
    L, ``L - d`` past v: ``eps (L - d) / (d L)`` radians wide. The kernel drops a
    blocked arc narrower than ``ANGLE_TOL``, so it labels the stop by whatever lies
    beyond (the body on v, not the tip on e) within ``ANGLE_TOL d L / (L - d)`` of the
    segment: at ``L - d`` = 1e-6 and L = 3.5, 1.2e-5, wider than a probe of a piece
    2e-6 long may go. Beyond it the kernel's labels are the exact ones.
    """
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(d < L, ANGLE_TOL * d * L / (L - d), np.inf)


def _past_cusps(world, arr, curves, job, regs, found, offs, edge_tab, sign_tab, sig_hash,
                hits, hit_p, hit_n) -> None:  # fmt: skip
    """One more probe for each unmatched region side of a type-4 piece: at the middle of
    its longest edge, ``CUSP_MARGIN`` cusp half-widths off (:func:`_cusp_offset`), if
    that is farther than every offset tried and nearer than the first curve a ray from
    there along the normal meets (found on the exact curves, as faces' points are:
    the probe lies in the face on that side, however thin its polygon says it is).
    Matches are recorded as in the main rounds."""
    L = arr.tol.L
    todo_j, todo_s = np.nonzero((found == -2) & (regs >= 0) & (edge_tab[:, :1] >= 0))
    rows = []
    for j, s in zip(todo_j.tolist(), todo_s.tolist(), strict=True):
        vs = [c.features[0].index for c in (curves[k] for k in arr.pieces[job[j]].curves)
              if c.type == 4]  # fmt: skip
        if vs:
            rows.append((j, s, vs[0]))
    if not rows:
        return
    jj = np.array([r[0] for r in rows], dtype=np.intp)
    ss = np.array([r[1] for r in rows], dtype=np.intp)
    vv = np.array([r[2] for r in rows], dtype=np.intp)
    p, n = arr.probes(edge_tab[jj, 0], sign_tab[jj, 0], 0.5)
    d = np.hypot(*(p - world.vertices[vv]).T)
    eps = CUSP_MARGIN * _cusp_offset(L, d)
    tried = np.nanmax(np.where(np.isfinite(offs[jj, ss]), offs[jj, ss], 0.0), axis=1)
    ok = np.isfinite(eps) & (eps > tried)
    if not ok.any():
        return
    jj, ss, p, n, eps = jj[ok], ss[ok], p[ok], n[ok], eps[ok]
    out = np.where(ss == 0, 1.0, -1.0)[:, None] * n
    tol = arr.tol
    first = _first_hits(
        arr.curves, L, p - arr.origin, out, 2.0 * eps, tol.touch, tol.chord + tol.merge
    )
    ok = first > eps
    if not ok.any():
        return
    jj, ss, p, n, eps, out = jj[ok], ss[ok], p[ok], n[ok], eps[ok], out[ok]
    q = p + eps[:, None] * out
    batch = free_arcs_batch(world, q, L)
    got = np.flatnonzero(signature_hashes(batch) == sig_hash[regs[jj, ss]])
    if len(got) == 0:
        return
    jj, ss = jj[got], ss[got]
    found[jj, ss] = regs[jj, ss]
    _keep_hits(batch, got, jj, ss, p, n, hits, hit_p, hit_n)


class _Beyond:
    """The regions next to a sliver, found on the arrangement's pieces: those of the
    faces that share a piece with it or with a sliver joined to it by pieces (a probe
    across a chain of slivers lands in one of them). The faces' polygons cannot say
    it: a face narrower than the chord tolerance may have a polygon far off its exact
    curves (a face 1e-4 wide beside a 1.8 mm wall step, L = 1.86: its polygon 0.03
    away from the probe)."""

    def __init__(self, arr: Arrangement, region_of_face: np.ndarray) -> None:
        self._region = region_of_face
        self._sliver = arr.sliver
        self._nbrs: dict[int, list[int]] = {}
        for p in arr.pieces:
            a, b = p.faces
            if arr.sliver[a] or arr.sliver[b]:
                self._nbrs.setdefault(a, []).append(b)
                self._nbrs.setdefault(b, []).append(a)
        self._memo: dict[int, set[int]] = {}

    def __call__(self, face: int) -> set[int]:
        if face in self._memo:
            return self._memo[face]
        seen, stack, out = {face}, [face], set()
        while stack:
            for g in self._nbrs.get(stack.pop(), ()):
                if g in seen:
                    continue
                seen.add(g)
                if self._sliver[g]:
                    stack.append(g)
                elif self._region[g] >= 0:
                    out.add(int(self._region[g]))
        for g in seen:
            if self._sliver[g]:
                self._memo[g] = out
        return out


def _keep_hits(batch, got, jj, ss, p, n, hits, hit_p, hit_n) -> None:
    """Record the probes ``got`` of ``batch`` that found their region (piece ``jj``, side
    ``ss``): where they landed (``hit_p``, ``hit_n``) and their free arcs (``hits``)."""
    hit_p[jj, ss], hit_n[jj, ss] = p[got], n[got]
    cnt = np.diff(batch.offsets)[got]
    arc = np.repeat(batch.offsets[got], cnt) + _rank(np.repeat(np.arange(len(got)), cnt))
    hits.append(
        (np.repeat(jj, cnt), np.repeat(ss, cnt), batch.code_lo[arc], batch.code_hi[arc],
         batch.lo[arc], batch.hi[arc])
    )  # fmt: skip


def _rank(g: np.ndarray) -> np.ndarray:
    """Position of each element among the equal values before it (g grouped)."""
    if len(g) == 0:
        return g
    start = np.flatnonzero(np.concatenate([[True], g[1:] != g[:-1]]))
    return np.arange(len(g)) - np.repeat(start, np.diff(np.concatenate([start, [len(g)]])))


def _set_hash(keys: frozenset) -> int:
    codes = np.array(sorted(keys), dtype=np.int64).reshape(-1, 2)
    batch = ArcBatch(
        np.array([0, len(codes)]),
        np.zeros(len(codes)),
        np.zeros(len(codes)),
        codes[:, 0],
        codes[:, 1],
    )
    return int(signature_hashes(batch)[0])


def _finish(world, arr, job, regs, found, hits, hit_p, hit_n, first_p, first_n, cells):
    """Adjacency of the matched pieces (vectorised overlaps), fallbacks for the rest."""
    n_jobs = len(job)
    both = (found[:, 0] >= 0) & (found[:, 1] >= 0) & (found[:, 0] != found[:, 1])
    adjacent: dict[int, list] = {}
    if hits:
        hj, hs, clo, chi, lo, hi = (np.concatenate(x) for x in zip(*hits, strict=True))
        keep = both[hj]
        hj, hs, clo, chi, lo, hi = hj[keep], hs[keep], clo[keep], chi[keep], lo[keep], hi[keep]
        o = np.lexsort((hs, hj))
        hj, hs, clo, chi, lo, hi = hj[o], hs[o], clo[o], chi[o], lo[o], hi[o]
        na = np.bincount(hj[hs == 0], minlength=n_jobs)
        nb = np.bincount(hj[hs == 1], minlength=n_jobs)
        start = np.concatenate([[0], np.cumsum(na + nb)])[:-1]  # each job: A arcs, then B
        jobs = np.flatnonzero(na * nb > 0)
        per = (na * nb)[jobs]
        pj = np.repeat(jobs, per)
        kk = np.arange(per.sum()) - np.repeat(np.cumsum(per) - per, per)
        ia = start[pj] + kk // nb[pj]
        ib = start[pj] + na[pj] + kk % nb[pj]
        full_a = (clo[ia] == -1) & (chi[ia] == -1)
        full_b = (clo[ib] == -1) & (chi[ib] == -1)
        ov = _arc_overlaps(lo[ia], hi[ia], full_a, lo[ib], hi[ib], full_b)
        for t in np.flatnonzero(ov > OVERLAP_TOL).tolist():
            j = int(pj[t])
            a, b = int(ia[t]), int(ib[t])
            pair = (cells[found[j, 0]][(int(clo[a]), int(chi[a]))],
                    cells[found[j, 1]][(int(clo[b]), int(chi[b]))])  # fmt: skip
            adjacent.setdefault(j, []).append(pair)
    out = []
    lost = []
    for j in range(n_jobs):
        i = int(job[j])
        a, b = int(found[j, 0]), int(found[j, 1])
        if a >= 0 and b >= 0:
            if a != b:
                adj = tuple(sorted(set(adjacent.get(j, ()))))
                out.append(Probed(i, (a, b), hit_p[j, 0].copy(), hit_n[j, 0].copy(), adj))
            continue
        if a == -1 or b == -1:
            continue  # a sliver between a region and a wall, or its end: no boundary
        if regs[j, 0] < 0 or regs[j, 1] < 0:
            lost.append(first_p[j])
            continue
        pn = (first_p[j], first_n[j])
        out.append(_fallback(world, arr, i, (int(regs[j, 0]), int(regs[j, 1])), pn, cells))
    return out, np.array(lost, dtype=float).reshape(-1, 2)


def _fallback(world, arr, i, regions, pn, cells) -> Probed:
    """Match each side's arcs to the region's cells by overlap (counted as unresolved)."""
    from envs.geometry import kernel_for
    from strategies.cspace._batch_arcs import stop_code

    kernel = kernel_for(world)
    tol = arr.tol
    p, n = pn
    piece = arr.pieces[i]
    eps = min(tol.probe, 0.25 * float(arr.edge_length[piece.edges].max()))
    sides = []
    for sgn in (1.0, -1.0):
        fa = kernel.free_arcs(p + sgn * eps * n, tol.L)
        sides.append([((stop_code(a.stop_lo), stop_code(a.stop_hi)), a.lo, a.hi) for a in fa.arcs])
    adj = set()
    for ka, lo1, hi1 in sides[0]:
        for kb, lo2, hi2 in sides[1]:
            ca = _nearest_cell(cells[regions[0]], ka)
            cb = _nearest_cell(cells[regions[1]], kb)
            ov = _arc_overlaps(
                np.array([lo1]),
                np.array([hi1]),
                np.array([ka == (-1, -1)]),
                np.array([lo2]),
                np.array([hi2]),
                np.array([kb == (-1, -1)]),
            )[0]
            if ca is not None and cb is not None and ov > OVERLAP_TOL:
                adj.add((ca, cb))
    return Probed(i, regions, p, n, tuple(sorted(adj)), False)


def _nearest_cell(table: dict, key) -> int | None:
    """The region's cell with this stop pair, else with one stop in common, else none."""
    if key in table:
        return table[key]
    for k, c in table.items():
        if k[0] == key[0] or k[1] == key[1]:
            return c
    return None
