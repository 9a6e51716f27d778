"""The kernel's exact free arcs at many points at once, vectorised (for building).

:meth:`envs.geometry.Kernel.free_arcs` answers one point in tens of microseconds; a
large decomposition asks at hundreds of thousands of points (a sample per face, two
probes per boundary, check points). This module computes the same answer for a whole
batch with numpy: the same formulas as :mod:`envs.geometry.arcs` (clip each wall edge to
the disk of radius L, the blocked short arc, the complement on the circle, the stop
labels with the same ties), so the stop pairs it reports are the kernel's and the cells
built from them are found again by the kernel at query time (a test checks them point
by point). Points within the kernel's tolerance of a wall (the rod lying along a wall)
are left to the kernel itself.

Stops are encoded as integers: ``priority << 32 | feature index`` with the kernel's tie
priority (body on an edge 0, body on a vertex 1, tip at a vertex 2, tip on an edge 3),
so the smallest code is the kernel's choice among tied labels; -1 is "no stop" (the
full circle).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
import shapely

from envs.geometry import kernel_for
from envs.geometry.types import Arc, FreeArcs, Stop
from envs.maps.map import Feature, Map
from envs.tolerances import ANGLE_TOL
from strategies.cspace._candidates import wall_index

__all__ = ["ArcBatch", "WallCells", "free_arcs_batch", "free_arcs_few", "stop_code", "stop_of"]

TWO_PI = 2.0 * math.pi
_KINDS = (("body", "edge"), ("body", "vertex"), ("tip", "vertex"), ("tip", "edge"))
_PRI = {k: i for i, k in enumerate(_KINDS)}
_END_ON = 1e-9  # edges seen nearly end-on (tie-prone) are not merged into chains
_CHUNK = 600_000  # (point, edge) pairs per vectorised chunk (memory stays flat)


def stop_code(stop: Stop | None) -> int:
    """The integer code of a stop (-1 for ``None``)."""
    if stop is None:
        return -1
    return (_PRI[stop.kind, stop.feature.kind] << 32) | stop.feature.index


@functools.lru_cache(maxsize=1 << 16)
def stop_of(code: int) -> Stop | None:
    """The stop of an integer code (one shared immutable object per code)."""
    if code < 0:
        return None
    kind, feat = _KINDS[code >> 32]
    return Stop(kind, Feature(feat, code & 0xFFFFFFFF))


@dataclass
class ArcBatch:
    """Free arcs at many points.

    Attributes:
        offsets: arcs of point ``i`` are ``offsets[i]:offsets[i + 1]`` (none: no free
            orientation; one arc with codes -1: the full circle).
        lo, hi: arc bounds (``lo`` in ``[-pi, pi)``, sorted within a point).
        code_lo, code_hi: stop codes.
    """

    offsets: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    code_lo: np.ndarray
    code_hi: np.ndarray

    def __len__(self) -> int:
        return len(self.offsets) - 1

    def keys(self, i: int) -> tuple[tuple[int, int], ...]:
        """The stop-code pairs at point ``i``, in arc order."""
        s = slice(self.offsets[i], self.offsets[i + 1])
        return tuple(zip(self.code_lo[s].tolist(), self.code_hi[s].tolist(), strict=True))

    def arcs(self, i: int) -> tuple[Arc, ...]:
        """The kernel's :class:`Arc` objects at point ``i``."""
        s = slice(self.offsets[i], self.offsets[i + 1])
        return tuple(
            Arc(a, b, stop_of(x), stop_of(y))
            for a, b, x, y in zip(
                self.lo[s].tolist(),
                self.hi[s].tolist(),
                self.code_lo[s].tolist(),
                self.code_hi[s].tolist(),
                strict=True,
            )
        )


def _label_codes(world: Map, e, at_vertex, v, dist_v, L, eps):
    """Codes of clipped edge ends (THEORY.md 1.3 step 4, the kernel's ``_label``)."""
    tip_vertex = np.abs(dist_v - L) <= eps
    pri = np.where(~at_vertex, 3, np.where(tip_vertex, 2, 1)).astype(np.int64)
    feat = np.where(~at_vertex, e, v).astype(np.int64)
    return (pri << 32) | feat


def _blocks(
    world: Map,
    P: np.ndarray,
    L: float,
    eps: float,
    pid: np.ndarray,
    e: np.ndarray,
    cells: WallCells | None = None,
):
    """Blocked arcs of edges ``e`` seen from points ``P[pid]`` (pairs within reach: the
    wall index's query, or with ``cells`` the cells' candidates, of which the pairs the
    query would not report are dropped here: :meth:`WallCells.reported`)."""
    a = world.edge_start[e]
    u = world.edge_dir[e]
    length = world.edge_length[e]
    wx = a[:, 0] - P[pid, 0]
    wy = a[:, 1] - P[pid, 1]
    s = -(wx * u[:, 0] + wy * u[:, 1])
    sc = np.clip(s, 0.0, length)
    dist = np.hypot(wx + sc * u[:, 0], wy + sc * u[:, 1])
    keep = dist <= L + eps
    if cells is not None:
        cells.reported(P, pid, e, dist, keep)
    on = keep & (dist <= eps)
    ww = wx * wx + wy * wy
    disc = s * s - (ww - L * L)
    ok = keep & (disc >= 0.0)
    sq = np.sqrt(np.where(ok, disc, 0.0))
    t0 = np.maximum(s - sq, 0.0)
    t1 = np.minimum(s + sq, length)
    ok &= t0 <= t1
    ang_a = np.arctan2(wy + t0 * u[:, 1], wx + t0 * u[:, 0])
    # an end vertex inside the disk: its angle from the vertex itself, as the kernel
    # (the same float as the next edge's start, in every frame)
    end = world.vertices[world.edge_vertices[e, 1]]
    ang_b = np.where(
        t1 == length,
        np.arctan2(end[:, 1] - P[pid, 1], end[:, 0] - P[pid, 0]),
        np.arctan2(wy + t1 * u[:, 1], wx + t1 * u[:, 0]),
    )
    w = (ang_b - ang_a) % TWO_PI
    flip = w > math.pi
    w = np.where(flip, TWO_PI - w, w)
    start = np.where(flip, ang_b, ang_a)
    sel = np.flatnonzero(ok & (w > ANGLE_TOL))
    e_s = e[sel]
    la = _label_codes(world, e_s, t0[sel] <= eps, e_s, np.sqrt(ww[sel]), L, eps)
    vb = world.edge_vertices[e_s, 1]
    db = np.hypot(world.vertices[vb, 0] - P[pid[sel], 0], world.vertices[vb, 1] - P[pid[sel], 1])
    at_b = t1[sel] >= length[sel] - eps
    lb = _label_codes(world, e_s, at_b, vb, db, L, eps)
    f = flip[sel]
    code_lo = np.where(f, lb, la)
    code_hi = np.where(f, la, lb)
    g, lo, wid = pid[sel], start[sel], w[sel]
    # runs of consecutive wall edges wholly inside the disk become one blocked arc (more
    # than two a point: never with at most two blocked arcs a point)
    if len(g) <= 2 * len(P):
        return g, lo, wid, code_lo, code_hi, pid[on]
    inner = (
        (t0[sel] == 0.0)
        & (t1[sel] == length[sel])
        & (np.sqrt(ww[sel]) < L - eps)
        & (db < L - eps)
        & (wid > _END_ON)
    )
    if np.count_nonzero(inner) > 2 * len(P):
        k = np.flatnonzero(inner)
        merged, used = _chains(world, g[k], e_s[k], vb[k], ang_a[sel][k], ang_b[sel][k])
        rest = np.ones(len(g), dtype=bool)
        rest[k[used]] = False
        mg, mlo, mw, mcl, mch = merged
        g = np.concatenate([g[rest], mg])
        lo = np.concatenate([lo[rest], mlo])
        wid = np.concatenate([wid[rest], mw])
        code_lo = np.concatenate([code_lo[rest], mcl])
        code_hi = np.concatenate([code_hi[rest], mch])
        o = np.argsort(g, kind="stable")
        g, lo, wid, code_lo, code_hi = g[o], lo[o], wid[o], code_lo[o], code_hi[o]
    return g, lo, wid, code_lo, code_hi, pid[on]


def _chains(world: Map, g, e, vb, ang_a, ang_b):
    """Merge chains of consecutive wall edges wholly inside the disk (one point each).

    The blocked arcs of consecutive edges share their end angles, so a chain's union is
    one arc, from the least to the greatest of its vertices' angles unwrapped along the
    chain; its ends are body contacts with the vertices there (the least code among
    vertices tied within ANGLE_TOL, as the kernel picks among tied arcs). Chains that
    close on themselves (a whole obstacle inside the disk) are left alone.

    Returns:
        ``((g, lo, wid, code_lo, code_hi) of the merged arcs, indices of the edges used)``.
    """
    m = len(g)
    order = np.lexsort((e, g))
    gs, es = g[order], e[order]
    nxt = world.vertex_next_edge[vb[order]]
    link = (gs[1:] == gs[:-1]) & (es[1:] == nxt[:-1])  # k + 1 follows k along a wall ring
    start = np.concatenate([[True], ~link])
    run = np.cumsum(start) - 1
    heads = np.flatnonzero(start)
    tails = np.concatenate([heads[1:] - 1, [m - 1]])
    # a ring's last edges and its first edges are one chain (the numbering wraps): the
    # later run goes first; a run that closes on itself (a whole ring) is left alone
    # for each run, the run whose head follows its tail
    follow_key = gs[tails].astype(np.int64) * world.n_edges + nxt[tails]
    head_key = gs[heads].astype(np.int64) * world.n_edges + es[heads]
    pos = np.minimum(np.searchsorted(head_key, follow_key), len(heads) - 1)
    nxt_run = np.where(head_key[pos] == follow_key, pos, -1)
    closed = nxt_run == np.arange(len(heads))
    joined = (nxt_run >= 0) & ~closed
    # chain id of each run: a run joined before another takes that one's id
    chain_of_run = np.arange(len(heads))
    chain_of_run[joined] = nxt_run[joined]
    # order inside a chain: the joining run's elements first
    first_part = np.zeros(len(heads), dtype=bool)
    first_part[joined] = True
    idx_sorted = np.flatnonzero(~closed[run])
    ch = chain_of_run[run[idx_sorted]]
    part = np.where(first_part[run[idx_sorted]], 0, 1)
    o = np.lexsort((idx_sorted, part, ch))
    idx = order[idx_sorted[o]]
    head = ch[o]
    if len(idx) == 0:
        z = np.zeros(0, dtype=np.int64)
        return (z, np.zeros(0), np.zeros(0), z, z), z
    delta = (ang_b[idx] - ang_a[idx] + math.pi) % TWO_PI - math.pi  # each edge's short arc
    first = np.flatnonzero(np.concatenate([[True], head[1:] != head[:-1]]))
    sizes = np.diff(np.concatenate([first, [len(idx)]]))
    # per-chain running sums on a padded table (one global cumsum would lose digits)
    col = np.arange(len(idx)) - np.repeat(first, sizes)
    table = np.zeros((len(first), int(sizes.max())))
    row = np.repeat(np.arange(len(first)), sizes)
    table[row, col] = delta
    end = np.cumsum(table, axis=1)[row, col]  # angle of each edge's end, from the first vertex
    beg = end - delta
    lo_c = np.minimum.reduceat(np.minimum(beg, end), first)
    hi_c = np.maximum.reduceat(np.maximum(beg, end), first)
    chain = row
    big = np.iinfo(np.int64).max
    body = np.int64(1) << 32
    tol = ANGLE_TOL
    lo_e, hi_e = lo_c[chain], hi_c[chain]
    code_b, code_e = body | e[idx], body | vb[idx]
    cl = np.minimum(
        np.minimum.reduceat(np.where(np.abs(beg - lo_e) <= tol, code_b, big), first),
        np.minimum.reduceat(np.where(np.abs(end - lo_e) <= tol, code_e, big), first),
    )
    ch = np.minimum(
        np.minimum.reduceat(np.where(np.abs(beg - hi_e) <= tol, code_b, big), first),
        np.minimum.reduceat(np.where(np.abs(end - hi_e) <= tol, code_e, big), first),
    )
    # the raw angle of the vertex at the least end (as the kernel computes it)
    d_beg, d_end = np.abs(beg - lo_e), np.abs(end - lo_e)
    raw = np.where(d_beg <= d_end, ang_a[idx], ang_b[idx])
    at = np.minimum(d_beg, d_end)
    best = np.minimum.reduceat(at, first)
    hit = np.flatnonzero(at == best[chain])
    pick = hit[np.concatenate([[True], chain[hit][1:] != chain[hit][:-1]])]
    lo = raw[pick]
    return (g[idx[first]], lo, hi_c - lo_c, cl, ch), idx


def _complement(n: int, g, lo, wid, clo, chi):
    """Complements on the circle of each point's blocked arcs: the kernel's sweep, done on
    padded (point, arc) tables a chunk of points at a time (row-wise sorts, exact float
    arithmetic as in :func:`envs.geometry.arcs._complement`)."""
    full = np.zeros(n, dtype=bool)
    full[g[wid >= TWO_PI - ANGLE_TOL]] = True
    keep = ~full[g]
    g, lo, wid, clo, chi = g[keep], lo[keep], wid[keep], clo[keep], chi[keep]
    if len(g) > 1 and not np.all(g[1:] >= g[:-1]):  # the index query returns them sorted
        order = np.argsort(g, kind="stable")
        g, lo, wid, clo, chi = g[order], lo[order], wid[order], clo[order], chi[order]
    rank = _rank(g)
    heads = np.flatnonzero(np.concatenate([[True], g[1:] != g[:-1]])) if len(g) else g
    pts = g[heads]
    bounds = np.concatenate([heads, [len(g)]])
    per = max(1, 200_000 // (int(rank.max(initial=0)) + 1))
    out = []
    for k0 in range(0, len(pts), per):
        k1 = min(len(pts), k0 + per)
        sl = slice(bounds[k0], bounds[k1])
        out.append(_sweep(pts[k0:k1], g[sl], rank[sl], lo[sl], wid[sl], clo[sl], chi[sl]))
    if not out:
        z = np.zeros(0)
        return np.zeros(0, dtype=np.intp), z, z, z.astype(np.int64), z.astype(np.int64), full
    gg, a_lo, a_hi, code_lo, code_hi = (np.concatenate(x) for x in zip(*out, strict=True))
    return gg, a_lo, a_hi, code_lo, code_hi, full


def _sweep(pts, g, rank, lo, wid, clo, chi):
    """The kernel's gap sweep for one chunk of points, on padded (point, arc) tables."""
    big = np.iinfo(np.int64).max
    row = np.searchsorted(pts, g)
    shape = (len(pts), int(rank.max()) + 1)
    LO = np.full(shape, np.inf)
    W = np.zeros(shape)
    CL = np.full(shape, big)
    CH = np.full(shape, big)
    LO[row, rank], W[row, rank], CL[row, rank], CH[row, rank] = lo, wid, clo, chi
    valid = np.isfinite(LO)
    first = np.argmin(LO, axis=1)  # the first arc of least start, as the kernel's min()
    c = LO[np.arange(shape[0]), first]
    rel = np.where(valid, (np.where(valid, LO, 0.0) - c[:, None]) % TWO_PI, np.inf)
    rel[np.arange(shape[0]), first] = 0.0
    top = rel + W
    # extra items, compacted: arcs past 2 pi again one turn back, arcs at the cut again
    # one turn on (a few per point at most)
    wrap = valid & (top > TWO_PI)
    cut = valid & (rel <= ANGLE_TOL)
    er, ec = np.nonzero(wrap | cut)  # rows and columns of the arcs with extra items
    er2 = np.concatenate([er[wrap[er, ec]], er[cut[er, ec]]])
    ec2 = np.concatenate([ec[wrap[er, ec]], ec[cut[er, ec]]])
    shift = np.concatenate([np.full(int(wrap.sum()), -TWO_PI), np.full(int(cut.sum()), TWO_PI)])
    o = np.lexsort((ec2, er2))
    er2, ec2, shift = er2[o], ec2[o], shift[o]
    xr = _rank(er2)
    xw = int(xr.max()) + 1 if len(xr) else 0
    XR = np.full((shape[0], xw), np.inf)
    XH = np.full((shape[0], xw), -np.inf)
    XL = np.full((shape[0], xw), big)
    XC = np.full((shape[0], xw), big)
    XR[er2, xr] = rel[er2, ec2] + shift
    XH[er2, xr] = top[er2, ec2] + shift
    XL[er2, xr], XC[er2, xr] = CL[er2, ec2], CH[er2, ec2]
    R = np.concatenate([rel, XR], axis=1)
    H = np.concatenate([np.where(valid, top, -np.inf), XH], axis=1)
    CLs = np.concatenate([CL, XL], axis=1)
    CHs = np.concatenate([CH, XC], axis=1)
    o = np.argsort(R, axis=1, kind="stable")
    R = np.take_along_axis(R, o, axis=1)
    H = np.take_along_axis(H, o, axis=1)
    CLs = np.take_along_axis(CLs, o, axis=1)
    CHs = np.take_along_axis(CHs, o, axis=1)
    run = np.maximum.accumulate(H, axis=1)
    prev = np.concatenate([np.full((shape[0], 1), -np.inf), run[:, :-1]], axis=1)
    gr, gc = np.nonzero(np.isfinite(prev) & np.isfinite(R) & (R - prev > ANGLE_TOL))
    start, end = prev[gr, gc], R[gr, gc]
    code_lo = np.where(np.abs(H[gr] - start[:, None]) <= ANGLE_TOL, CHs[gr], big).min(axis=1)
    code_hi = np.where(np.abs(R[gr] - end[:, None]) <= ANGLE_TOL, CLs[gr], big).min(axis=1)
    a_lo = (c[gr] + start + math.pi) % TWO_PI - math.pi
    a_lo = np.where(a_lo >= math.pi, -math.pi, a_lo)
    a_hi = a_lo + (end - start)
    gg = pts[gr]
    o = np.lexsort((a_lo, gg))
    return gg[o], a_lo[o], a_hi[o], code_lo[o], code_hi[o]


def _rank(g: np.ndarray) -> np.ndarray:
    """Position of each element among the equal values before it (g sorted)."""
    if len(g) == 0:
        return g
    start = np.flatnonzero(np.concatenate([[True], g[1:] != g[:-1]]))
    first = np.repeat(start, np.diff(np.concatenate([start, [len(g)]])))
    return np.arange(len(g)) - first


def free_arcs_batch(world: Map, points: np.ndarray, L: float) -> ArcBatch:
    """The kernel's free arcs at each of (k, 2) points for rod length ``L``.

    Points are processed in chunks sized so that their (point, edge) pairs stay below a
    few million: the memory used does not grow with the number of points.
    """
    P = np.asarray(points, dtype=float).reshape(-1, 2)
    n = len(P)
    kernel = kernel_for(world)
    eps = kernel.eps
    tree = wall_index(world).tree
    inside = shapely.contains_xy(world.prepared_free_region, P[:, 0], P[:, 1])
    # edges per point: estimated from a sample, to size the chunks
    probe = P[:: max(1, n // 200)]
    k = len(tree.query(shapely.points(probe), predicate="dwithin", distance=L + eps)[0])
    per_point = max(1.0, k / max(1, len(probe)))
    step = max(1, int(_CHUNK / per_point))
    on = np.zeros(n, dtype=bool)
    has = np.zeros(n, dtype=bool)
    out = []
    for s0 in range(0, n, step):
        s1 = min(n, s0 + step)
        pid, e = tree.query(shapely.points(P[s0:s1]), predicate="dwithin", distance=L + eps)
        g, lo, wid, clo, chi, on_local = _blocks(world, P[s0:s1], L, eps, pid, e.astype(np.intp))
        on[s0 + on_local] = True
        has[s0 + g] = True
        gg, a_lo, a_hi, c_lo, c_hi, _ = _complement(s1 - s0, g, lo, wid, clo, chi)
        out.append((gg + s0, a_lo, a_hi, c_lo, c_hi))
    gg, a_lo, a_hi, c_lo, c_hi = (np.concatenate(x) for x in zip(*out, strict=True))
    # assemble: kernel fallback for points on walls, full circles, no arcs outside
    counts = np.bincount(gg, minlength=n)
    counts[~inside | on] = 0
    full_circle = inside & ~on & ~has
    counts[full_circle] = 1
    offsets = np.concatenate([[0], np.cumsum(counts)])
    out_lo = np.empty(offsets[-1])
    out_hi = np.empty(offsets[-1])
    out_cl = np.empty(offsets[-1], dtype=np.int64)
    out_ch = np.empty(offsets[-1], dtype=np.int64)
    use = inside[gg] & ~on[gg]
    pos = offsets[gg[use]] + _rank(gg[use])
    out_lo[pos], out_hi[pos], out_cl[pos], out_ch[pos] = a_lo[use], a_hi[use], c_lo[use], c_hi[use]
    fc = offsets[:-1][full_circle]
    out_lo[fc], out_hi[fc], out_cl[fc], out_ch[fc] = -math.pi, math.pi, -1, -1
    batch = ArcBatch(offsets, out_lo, out_hi, out_cl, out_ch)
    wall_pts = np.flatnonzero(on)
    if len(wall_pts):
        batch = _patch(batch, wall_pts, [kernel.free_arcs(P[i], L) for i in wall_pts])
    return batch


def _patch(batch: ArcBatch, idx: np.ndarray, arcs: list[FreeArcs]) -> ArcBatch:
    """Replace the arcs of points ``idx`` with the kernel's answers."""
    n = len(batch)
    counts = np.diff(batch.offsets)
    counts[idx] = [len(fa.arcs) for fa in arcs]
    offsets = np.concatenate([[0], np.cumsum(counts)])
    m = offsets[-1]
    lo, hi = np.empty(m), np.empty(m)
    cl, ch = np.empty(m, dtype=np.int64), np.empty(m, dtype=np.int64)
    mask = np.ones(n, dtype=bool)
    mask[idx] = False
    keep = np.flatnonzero(mask)
    old_c = np.diff(batch.offsets)[keep]
    src = np.repeat(batch.offsets[:-1][keep], old_c) + _rank(np.repeat(keep, old_c))
    dst = np.repeat(offsets[:-1][keep], old_c) + _rank(np.repeat(keep, old_c))
    lo[dst], hi[dst], cl[dst], ch[dst] = (
        batch.lo[src],
        batch.hi[src],
        batch.code_lo[src],
        batch.code_hi[src],
    )
    for i, fa in zip(idx.tolist(), arcs, strict=True):
        for k, arc in enumerate(fa.arcs):
            j = offsets[i] + k
            lo[j], hi[j] = arc.lo, arc.hi
            cl[j], ch[j] = stop_code(arc.stop_lo), stop_code(arc.stop_hi)
    return ArcBatch(offsets, lo, hi, cl, ch)


class WallCells:
    """The wall edges that may come within ``reach`` of a point of each square cell of a
    grid over a map (for its wall index's query ``dwithin`` at ``reach``, which costs a
    few microseconds a point, in a few numpy calls for a whole batch).

    :meth:`candidates` gives every pair (point, edge) of a batch whose edge is within
    ``reach`` plus the cell's half diagonal of the point's cell's centre: a superset of
    the pairs the index's query reports (plus a margin far above the rounding).
    :meth:`reported` drops the candidates the query would not report, given their
    distances by :func:`_blocks`' formula: those farther than ``reach`` by it (as
    :func:`_blocks` drops them anyway), and, of those within ``reach`` by less than
    ``_BORDER`` (where the query's own distance could round the other way), the ones
    the query itself does not report. Pairs the query would report farther than
    ``reach`` by :func:`_blocks`' formula are dropped in both (its ``keep``), so the
    blocked arcs are the query's.

    Args:
        world: the map.
        tree: its wall index (``wall_index(world).tree``: edge ``i`` is geometry ``i``).
        reach: ``L + eps``.
    """

    MAX_CELLS = 1 << 16

    def __init__(self, world: Map, tree, reach: float) -> None:
        self.tree = tree
        self.reach = float(reach)
        self.n_edges = world.n_edges
        xmin, ymin, xmax, ymax = (float(b) for b in world.bounds)
        w, h = xmax - xmin, ymax - ymin
        # cells of a third of the reach (a point's candidates a few more than its pairs), fewer
        # on a map so large that they would exceed MAX_CELLS
        side = max(self.reach / 3, math.sqrt(w * h / self.MAX_CELLS))
        self.side = side
        # the bounds and a reach round them (farther, a point has no pair: off the grid)
        pad = self.reach + side
        self.origin = np.array([xmin - pad, ymin - pad])
        self.shape = (int((w + 2 * pad) // side) + 2, int((h + 2 * pad) // side) + 2)
        nx, ny = self.shape
        scale = self.reach + max(abs(xmin), abs(ymin), abs(xmax), abs(ymax))
        self.border = _BORDER * scale
        # each edge against the cells of its box grown by the reach, kept where the cell's
        # centre is within the reach plus the cell's half diagonal of it (every point of
        # the cell then may be within the reach), with a margin far above the rounding
        r = self.reach + 1e3 * self.border
        a, b = world.edge_start, world.edge_end
        lo = np.floor((np.minimum(a, b) - r - self.origin) / side).astype(np.intp)
        hi = np.floor((np.maximum(a, b) + r - self.origin) / side).astype(np.intp)
        lo = np.maximum(lo, 0)
        hi = np.minimum(hi, np.array(self.shape) - 1)
        ni, nj = hi[:, 0] - lo[:, 0] + 1, hi[:, 1] - lo[:, 1] + 1
        cnt = ni * nj
        edge = np.repeat(np.arange(world.n_edges), cnt)
        k = np.arange(len(edge)) - np.repeat(np.cumsum(cnt) - cnt, cnt)
        ci = lo[edge, 0] + k // nj[edge]
        cj = lo[edge, 1] + k % nj[edge]
        cx = self.origin[0] + (ci + 0.5) * side - a[edge, 0]
        cy = self.origin[1] + (cj + 0.5) * side - a[edge, 1]
        u, length = world.edge_dir[edge], world.edge_length[edge]
        t = np.clip(cx * u[:, 0] + cy * u[:, 1], 0.0, length)
        near = np.hypot(cx - t * u[:, 0], cy - t * u[:, 1]) <= r + side * math.sqrt(0.5)
        cell, edge = ci[near] * ny + cj[near], edge[near]
        order = np.lexsort((edge, cell))
        self.edges = edge[order].astype(np.intp)
        counts = np.bincount(cell, minlength=nx * ny)
        self.start = np.zeros(nx * ny + 1, dtype=np.intp)
        np.cumsum(counts, out=self.start[1:])
        # a batch of at most this many points is one chunk of free_arcs_batch's whatever
        # its pairs (each point has at most the most candidates of a cell)
        self.points_one_chunk = _CHUNK // max(1, int(counts.max(initial=0)))

    def candidates(self, P: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
        """``(pid, e)``: the pairs of (k, 2) points and their cells' edges, by point (and
        by edge within a point), or None for a batch with a point off the cells' grid or
        more points than :attr:`points_one_chunk` (the query's then)."""
        n = len(P)
        if n > self.points_one_chunk:
            return None
        ij = np.floor((P - self.origin) / self.side).astype(np.intp)
        i, j = ij[:, 0], ij[:, 1]
        if not ((i.view(np.uintp) < self.shape[0]) & (j.view(np.uintp) < self.shape[1])).all():
            return None
        c = i * self.shape[1] + j
        s = self.start[c]
        cnt = self.start[c + 1] - s
        pid = np.repeat(np.arange(n), cnt)
        # each cell's edges laid end to end: the m-th of point p at s[p] + m
        at = np.arange(len(pid)) + np.repeat(s - (np.cumsum(cnt) - cnt), cnt)
        return pid, self.edges[at]

    def reported(
        self, P: np.ndarray, pid: np.ndarray, e: np.ndarray, dist: np.ndarray, keep: np.ndarray
    ) -> None:
        """Clear ``keep`` (the candidates within ``reach`` by ``dist``) where the wall
        index's query would not report the pair (see the class)."""
        border = keep & (dist > self.reach - self.border)
        if not border.any():
            return
        at = np.flatnonzero(border)
        pts = np.unique(pid[at])
        qp, qe = self.tree.query(shapely.points(P[pts]), predicate="dwithin", distance=self.reach)
        seen = pts[qp].astype(np.int64) * self.n_edges + qe
        keep[at] = np.isin(pid[at].astype(np.int64) * self.n_edges + e[at], seen)


_BORDER = 1e-9
"""Candidates within this (relative to the reach plus the map's coordinates) of the reach
by :func:`_blocks`' distance are the query's to decide: its distance (GEOS's) and that
one differ by a few units in the last place of the coordinates."""


def _one_chunk(n: int, pid: np.ndarray) -> bool:
    """Whether :func:`free_arcs_batch` takes ``n`` points in one chunk, from the pairs
    ``pid`` (point of each pair) of the points' one index query: its sizing probe is
    every ``n // 200``-th point, and its estimate of the pairs a point the probe's."""
    stride = max(1, n // 200)
    k = len(pid) if stride == 1 else int(np.count_nonzero(pid % stride == 0))
    per_point = max(1.0, k / max(1, len(range(0, n, stride))))
    return n <= max(1, int(_CHUNK / per_point))


def free_arcs_few(
    world: Map,
    points: np.ndarray,
    L: float,
    tree=None,
    eps=None,
    interior: bool = False,
    cells: WallCells | None = None,
) -> ArcBatch:
    """:func:`free_arcs_batch` of points it takes in one chunk (a lazy table's batches:
    tens to thousands of points), the same arrays bit for bit in a third of the numpy
    calls: a lazy table classifies a few dozen points a decision, most of them with no
    wall in reach, and the batch's per-call overhead was most of its cost (~0.25 ms on
    a 300-vertex floor plan).

    The pairs (one index query, the batch's sizing probe counted from them), their
    blocked arcs (:func:`_blocks`, chains merged alike) and the kernel's gap sweep on one
    padded table (:func:`_gaps_few`); points on a wall are the kernel's, as in the
    batch. ``tree`` and ``eps`` (the map's wall index and kernel tolerance) may be
    passed to skip their look-up, and ``interior=True`` when every point is known to lie
    in the free region (a lazy table's nodes, tested when first looked up) to skip that
    test. Points the batch would take in several chunks go to it. ``cells``
    (:class:`WallCells` of ``tree`` at ``L + eps``): the pairs are its candidates,
    filtered to the query's (the same pairs, without the query's per-point cost).
    """
    P = np.asarray(points, dtype=float).reshape(-1, 2)
    n = len(P)
    if eps is None:
        eps = kernel_for(world).eps
    if tree is None:
        tree = wall_index(world).tree
    if interior:
        inside = np.ones(n, dtype=bool)
    else:
        inside = shapely.contains_xy(world.prepared_free_region, P[:, 0], P[:, 1])
    pairs = cells.candidates(P) if cells is not None else None
    if pairs is None:
        cells = None
        pid, e = tree.query(shapely.points(P), predicate="dwithin", distance=L + eps)
        if not _one_chunk(n, pid):
            return free_arcs_batch(world, P, L)
        e = e.astype(np.intp)
    else:  # (at most WallCells.points_one_chunk points: one chunk, whatever the pairs)
        pid, e = pairs
    if len(pid):
        g, lo, wid, clo, chi, on_local = _blocks(world, P, L, eps, pid, e, cells)
    else:
        g = on_local = pid
    # the points with a free arc: gaps between blocked arcs, or the full circle
    gg, a_lo, a_hi, c_lo, c_hi = _gaps_few(n, g, lo, wid, clo, chi) if len(g) else (g,) * 5
    whole = inside.copy()
    whole[g] = False
    use = inside[gg]
    if len(on_local):
        on = np.zeros(n, dtype=bool)
        on[on_local] = True
        whole &= ~on
        use &= ~on[gg]
    fc = np.flatnonzero(whole)
    at = np.concatenate([gg[use], fc])
    o = np.argsort(at, kind="stable")  # gaps stay in order within a point
    nf = len(fc)
    out_lo = np.concatenate([a_lo[use], np.full(nf, -math.pi)])[o]
    out_hi = np.concatenate([a_hi[use], np.full(nf, math.pi)])[o]
    out_cl = np.concatenate([c_lo[use], np.full(nf, -1, dtype=np.int64)])[o]
    out_ch = np.concatenate([c_hi[use], np.full(nf, -1, dtype=np.int64)])[o]
    offsets = np.zeros(n + 1, dtype=np.int64)
    np.cumsum(np.bincount(at, minlength=n), out=offsets[1:])
    batch = ArcBatch(offsets, out_lo, out_hi, out_cl, out_ch)
    if len(on_local):
        wall_pts = np.flatnonzero(on)
        batch = _patch(batch, wall_pts, [kernel_for(world).free_arcs(P[i], L) for i in wall_pts])
    return batch


def _gaps_few(n: int, g, lo, wid, clo, chi):
    """:func:`_complement` on one padded (point, item) table: the same items (each
    blocked arc, again one turn back past 2 pi, again one turn on at the cut), the same
    running maximum and the same float arithmetic; the items' order among equal starts,
    which the sweep does not depend on, aside. An item is one row of floats (start, end,
    stop codes: the codes, below 2^53, are exact as floats). Returns the gaps as
    ``_complement`` does, without its ``full``."""
    blocked = wid >= TWO_PI - ANGLE_TOL  # a point blocked all round has no gap
    if blocked.any():
        keep = ~np.isin(g, g[blocked])
        g, lo, wid, clo, chi = g[keep], lo[keep], wid[keep], clo[keep], chi[keep]
        if not len(g):
            z = np.zeros(0)
            return g, z, z, z.astype(np.int64), z.astype(np.int64)
    c = np.full(n, np.inf)
    np.minimum.at(c, g, lo)  # each point's least start (the kernel's first arc)
    item = np.empty((len(g), 4))
    item[:, 0] = (lo - c[g]) % TWO_PI
    np.add(item[:, 0], wid, out=item[:, 1])
    item[:, 2], item[:, 3] = clo, chi
    wrap = item[:, 1] > TWO_PI
    cut = item[:, 0] <= ANGLE_TOL
    item = np.concatenate([item, item[wrap] + _BACK, item[cut] + _ON])
    gi = np.concatenate([g, g[wrap], g[cut]])
    o = np.lexsort((item[:, 0], gi))
    gi, item = gi[o], item[o]
    new = np.concatenate([[True], gi[1:] != gi[:-1]])
    row = np.cumsum(new) - 1  # rows: the points with items, each with one at column 0
    heads = np.flatnonzero(new)
    col = np.arange(len(gi)) - heads[row]
    table = np.full((len(heads), int(col.max()) + 1, 4), _PAD)
    table[row, col] = item
    R, H = table[:, :, 0], table[:, :, 1]
    # the running maximum before each item (finite past column 0; +inf there and -inf at
    # the padding: neither is a gap, and no inf - inf)
    prev = np.full(R.shape, np.inf)
    np.maximum.accumulate(H[:, :-1], axis=1, out=prev[:, 1:])
    gr, gc = np.nonzero(R - prev > ANGLE_TOL)
    start, end = prev[gr, gc], R[gr, gc]
    near = np.abs(H[gr] - start[:, None]) <= ANGLE_TOL
    code_lo = np.where(near, table[gr, :, 3], np.inf).min(axis=1).astype(np.int64)
    near = np.abs(R[gr] - end[:, None]) <= ANGLE_TOL
    code_hi = np.where(near, table[gr, :, 2], np.inf).min(axis=1).astype(np.int64)
    pt = gi[heads[gr]]
    a_lo = (c[pt] + start + math.pi) % TWO_PI - math.pi
    a_lo[a_lo >= math.pi] = -math.pi
    a_hi = a_lo + (end - start)
    o = np.lexsort((a_lo, pt))
    return pt[o], a_lo[o], a_hi[o], code_lo[o], code_hi[o]


_BACK = np.array([-TWO_PI, -TWO_PI, 0.0, 0.0])  # an item one turn back
_ON = np.array([TWO_PI, TWO_PI, 0.0, 0.0])  # an item one turn on
_PAD = np.array([-np.inf, -np.inf, np.inf, np.inf])  # no item
