"""The escape plan (ranks, vias, witness crossings) against the exact decomposition.

* Ranks: an independent naive iteration of Sec. 4's definition over ``dec.graph`` (round
  r: the cells with a boundary piece of their region across which every graph neighbour
  has rank < r) gives the same ranks, and the escapable set is exactly
  ``dec.escapable``.
* Witnesses: from a point of an escapable cell's region, the crossing lies on a via piece,
  the target just across it lies outside the region, and at the target the configuration
  has no continuation in a cell adjacent to the cell (condition (a)) or only in cells of
  lower rank (condition (b)), checked with ``dec.free_arcs`` and the kernel's arcs.
* An evader with a body: the pieces its disc cannot cross (shapely distances to the
  walls) cost more than any route without one; the escapable set is the same, every via
  still lowers the rank, the plan of a cell that has a route without them takes none,
  and on random:polygons:0 cells whose every point-plan via is too close to a wall get
  a crossing the disc can make (issue 13).
* Prop. 2 for a disc: the regions whose cells all escape without a narrow piece are
  those of an independent fixed point that never crosses one (sets, not ranks); at
  clearance 0 they are the decomposition's witness regions.
* The witness-region walk: every hop is a grid neighbour joined by a wall-free segment
  (shapely) and the walk is a shortest one (networkx breadth first search).
"""

from __future__ import annotations

import dataclasses
import itertools
import math

import networkx as nx
import numpy as np
import pytest
import shapely
from shapely.geometry import LineString, Point

from envs.maps import builtin_map, load_map
from strategies.cspace._arcs import overlap
from strategies.policies.escape_plan import (
    CROSS_REL,
    _clear_within,
    _narrow,
    _region_next,
    _samples,
    body_witness_regions,
    escape_plan,
    escape_ranks,
)
from strategies.policies.safety import grid_points, safety_table

L = 2.1
MAPS = ["corridor", "two_rooms", "maze", "l_hall", "pillars", "corner"]


def _naive_ranks(dec) -> tuple[np.ndarray, list[set[int]]]:
    """Sec. 4 by rounds, from the graph's edges and the regions' boundary lists."""
    n = len(dec.cells)
    rank = np.full(n, -1)
    vias: list[set[int]] = [set() for _ in range(n)]
    r = 0
    while True:
        new = {}
        for c in dec.cells:
            if rank[c.id] >= 0:
                continue
            for b in dec.regions[c.region].boundaries:
                nbrs = [
                    x
                    for x in dec.graph.neighbors(c.id)
                    if b in dec.graph.edges[c.id, x]["boundaries"]
                ]
                if all(0 <= rank[x] < r for x in nbrs) and (r > 0 or not nbrs):
                    new.setdefault(c.id, set()).add(b)
        if not new:
            return rank, vias
        for c, bs in new.items():
            rank[c], vias[c] = r, bs
        r += 1


@pytest.mark.parametrize("name", MAPS)
def test_ranks_reproduce_the_decomposition(name):
    plan = escape_plan(builtin_map(name), L)
    dec = plan.dec
    assert {int(c) for c in np.flatnonzero(plan.rank >= 0)} == set(dec.escapable)
    rank, vias = _naive_ranks(dec)
    assert np.array_equal(plan.rank, rank)
    assert [set(v) for v in plan.vias] == vias
    for c in dec.cells:  # the decomposition's own reasons: round 0 is condition (a)
        assert (c.reason == "a") == (plan.rank[c.id] == 0), c
        if c.reason == "a":
            assert c.via in plan.vias[c.id], c


def test_rank_one_cells_escape_into_rank_zero_cells():
    """Condition (b) at round 1: across a via every adjacent cell has rank 0."""
    dec = escape_plan(builtin_map("corridor"), L).dec
    rank, vias = escape_ranks(dec)
    one = [c for c in range(len(rank)) if rank[c] == 1]
    assert one  # the corridor has a rank-1 cell
    for c in one:
        for b in vias[c]:
            nbrs = [x for x in dec.graph.neighbors(c) if b in dec.graph.edges[c, x]["boundaries"]]
            assert nbrs and all(rank[x] == 0 for x in nbrs)


def _cell_arc(dec, point, cell):
    return next((ca.arc for ca in dec.free_arcs(point) if ca.cell == cell), None)


@pytest.mark.parametrize("name", ["corridor", "two_rooms", "maze", "pillars"])
def test_witness_crossings_leave_the_cell(name):
    world = builtin_map(name)
    plan = escape_plan(world, L)
    dec = plan.dec
    eps = CROSS_REL * L
    rng = np.random.default_rng(0)
    cells = np.flatnonzero(plan.rank >= 0)
    cells = rng.choice(cells, size=min(60, len(cells)), replace=False)
    checked = reached = 0
    for c in cells.tolist():
        reg = dec.regions[dec.cells[c].region]
        start = reg.point
        w = plan.witness(c, start)
        assert w is not None and w.boundary in plan.vias[c]
        seg = dec.boundaries[w.boundary].segments
        on = min(LineString(s).distance(Point(w.cross)) for s in seg if np.ptp(s, axis=0).any())
        assert on < 1e-9 * world.scale + 1e-12
        assert math.isclose(float(np.linalg.norm(w.normal)), 1.0)
        assert np.allclose(w.target, w.cross + eps * w.normal)
        inner = w.cross - eps * w.normal
        assert (
            not reg.polygon.contains(Point(w.target))
            or reg.polygon.exterior.distance(Point(w.target)) < 2 * dec.chord_tol
        )
        reached += reg.polygon.buffer(4 * dec.chord_tol + eps).covers(LineString([start, w.cross]))
        arc = _cell_arc(dec, inner, c)
        there = dec.free_arcs(w.target)
        if arc is None or any(ca.cell is None for ca in there):
            continue  # on a critical curve's polyline tolerance: not identifiable
        checked += 1
        nbrs = set(dec.graph.neighbors(c))
        if plan.rank[c] == 0:  # condition (a): no continuation
            assert not any(ca.cell in nbrs for ca in there), (c, w)
            assert all(overlap(arc, ca.arc) < 0.05 for ca in there), (c, w)
        else:  # condition (b): every continuation has a lower rank
            for ca in there:
                if overlap(arc, ca.arc) > 0.05:
                    assert 0 <= plan.rank[ca.cell] < plan.rank[c], (c, ca, w)
    assert checked >= 0.8 * len(cells), (checked, len(cells))
    assert reached >= 0.8 * len(cells), (reached, len(cells))


def test_witness_of_a_safe_cell_is_none():
    plan = escape_plan(builtin_map("corridor"), L)
    safe = int(np.flatnonzero(plan.rank < 0)[0])
    assert plan.witness(safe, plan.dec.regions[plan.dec.cells[safe].region].point) is None


def test_witness_keeps_clearance_from_walls():
    world = builtin_map("maze")
    plan = escape_plan(world, L)
    dec = plan.dec
    walls = world.free_region.boundary
    seen = {True: 0, False: 0}
    for c in np.flatnonzero(plan.rank >= 0).tolist():
        w = plan.witness(c, dec.regions[dec.cells[c].region].point, clearance=0.1)
        if w is None:  # then no part of any via piece keeps the clearance (shapely)
            for b in plan.vias[c]:
                piece = shapely.MultiLineString([s for s in dec.boundaries[b].segments])
                assert walls.buffer(0.1 - 1e-6).covers(piece), (c, b)
        else:
            assert walls.distance(Point(w.cross)) >= 0.1 - 1e-9, (c, w)
        seen[w is None] += 1
    assert seen[False] > 20


def test_disc_plan_avoids_the_pieces_its_disc_cannot_cross():
    world, radius = load_map("random:polygons:0"), 0.1
    point = escape_plan(world, L, 0.5)  # (a coarse walk grid: not used here)
    disc = escape_plan(world, L, 0.5, radius)
    dec = disc.dec
    n = len(dec.cells)
    walls = world.free_region.boundary
    narrow = _narrow(dec, radius)
    samples = [_samples(b.segments, dec.chord_tol)[4] for b in dec.boundaries]
    owner = np.repeat(np.arange(len(samples)), [len(s) for s in samples])
    clear = shapely.distance(shapely.points(np.concatenate(samples)), walls)
    far = np.full(len(samples), -np.inf)
    np.maximum.at(far, owner, clear)
    # no sample of a narrow piece keeps the radius (shapely)
    assert set(np.flatnonzero(far < radius).tolist()) == narrow
    assert narrow
    assert np.array_equal(point.rank >= 0, disc.rank >= 0)
    across = {}
    for b in dec.boundaries:
        for i, j in b.adjacent:
            across.setdefault((i, b.id), []).append(j)
            across.setdefault((j, b.id), []).append(i)
    for c in np.flatnonzero(disc.rank >= 0).tolist():
        assert disc.vias[c]
        for b in disc.vias[c]:  # every crossing of a via still lowers the rank
            assert all(0 <= disc.rank[x] < disc.rank[c] for x in across.get((c, b), ()))
            # ranks below n_cells: a route round every narrow piece, whatever the pursuer
            assert disc.rank[c] >= n or b not in narrow, (c, b)
    # cells the point plan leaves to a disc without a crossing (every via narrow) that
    # the disc plan routes round them (cell 568, rank 0 -> 2, took the evader out of
    # the loop against the decomposition pursuer, seed 0)
    fixed = [
        c
        for c in np.flatnonzero(point.rank >= 0).tolist()
        if set(point.vias[c]) <= narrow and disc.rank[c] < n
    ]
    assert len(fixed) >= 5, fixed
    for c in fixed:
        start = dec.regions[dec.cells[c].region].point
        assert point.witness(c, start, radius) is None
        w = disc.witness(c, start, radius)
        assert w is not None and w.boundary not in narrow
        assert shapely.distance(shapely.Point(w.cross), walls) >= radius


def _escape_without(dec, narrow) -> set[int]:
    """The cells that escape crossing no piece of ``narrow``: Sec. 4's fixed point on sets,
    with the pairs across a narrow piece left out."""
    out: set[int] = set()
    grew = True
    while grew:
        grew = False
        for c in dec.cells:
            if c.id in out:
                continue
            for b in dec.regions[c.region].boundaries:
                if b in narrow:
                    continue
                nbrs = [
                    x
                    for x in dec.graph.neighbors(c.id)
                    if b in dec.graph.edges[c.id, x]["boundaries"]
                ]
                if all(x in out for x in nbrs):
                    out.add(c.id)
                    grew = True
                    break
    return out


@pytest.mark.parametrize(
    ("name", "length", "kind"),
    [("two_rooms", 1.1, "none"), ("two_rooms", 2.1, "all"), ("random:rectangles:0", 2.1, "some")],
)
def test_body_witness_regions_are_prop_2_for_the_disc(name, length, kind):
    """two_rooms at L_min 1 + 0.1: four pieces too near the walls for the 0.1 disc block
    every region's escape (Prop. 2 holds for a point evader only); at L_min 2 none is
    narrow; random:rectangles:0 at 2.1: 34 narrow pieces take 16 of its 317 witness
    regions from the disc."""
    world = builtin_map(name) if ":" not in name else load_map(name)
    dec = escape_plan(world, length, 0.5).dec
    assert body_witness_regions(dec, 0.0) == dec.witness_regions
    ok = _escape_without(dec, _narrow(dec, 0.1))
    want = [r.id for r in dec.regions if all(c in ok for c in r.cells)]
    got = body_witness_regions(dec, 0.1)
    assert sorted(got) == sorted(want)
    areas = [dec.regions[r].area for r in got]  # largest first, ties (1e-9) in id order
    assert all(a >= b - 1e-9 * areas[0] for a, b in itertools.pairwise(areas))
    n = len(dec.witness_regions)
    assert n  # Prop. 2 holds for the point evader on all three
    assert {"none": len(got) == 0, "all": got == dec.witness_regions,
            "some": 0 < len(got) < n}[kind]  # fmt: skip


def test_plan_grid_is_the_safety_tables():
    world = builtin_map("two_rooms")  # a map with witness regions (a walk to them)
    plan = escape_plan(world, L, 0.25)
    assert plan.region.any()
    tab = safety_table(world, L, 0.25, 36, disk_cache=False)
    assert np.array_equal(tab.rows(plan.points), np.arange(len(plan.points)))
    # plan.row answers as the eager table's row (the plan's rows), also just outside the
    # free region, where both look around (issue 13: the shooting evader looked its plan
    # up with its distinct table's rows, which are numbered otherwise)
    rng = np.random.default_rng(3)
    x0, y0, x1, y1 = world.bounds
    pts = np.concatenate([rng.uniform((x0, y0), (x1, y1), (300, 2)), world.vertices + 0.01])
    assert [plan.row(p) for p in pts] == [tab.row(p) for p in pts]
    distinct = safety_table(world, L, 0.25, 36, disk_cache=False, distinct=True)
    assert [distinct.row(p) for p in pts] != [tab.row(p) for p in pts]


def test_a_map_without_witness_regions_has_no_walk_grid():
    # nothing walks to a witness region there: the grid was 8 of the shooting evader's
    # 8.6 s reset on the corridor at L_min 0.2 (issue 13)
    plan = escape_plan(builtin_map("corridor"), L, 0.25)
    assert not plan.dec.witness_regions
    assert len(plan.points) == len(plan.region) == len(plan.region_next) == 0
    assert plan.row(np.array([5.0, 0.0])) == -1


def test_region_walk_is_a_shortest_wall_free_grid_walk():
    world = builtin_map("pillars")
    h = 0.25
    _origin, cell, pts = grid_points(world, h)
    region = np.hypot(pts[:, 0] - pts[0, 0], pts[:, 1] - pts[0, 1]) < 1.0  # a patch
    nxt = _region_next(world, cell, pts, h, region)
    free = world.free_region
    clear = np.array([free.exterior.distance(Point(p)) for p in pts])
    for ring in free.interiors:
        clear = np.minimum(clear, [ring.distance(Point(p)) for p in pts])
    g = nx.Graph()
    g.add_nodes_from(range(len(pts)))
    index = {tuple(ij): int(cell[tuple(ij)]) for ij in np.argwhere(cell >= 0)}
    for (i, j), a in index.items():
        for di, dj in ((1, 0), (0, 1), (1, 1), (1, -1)):
            b = index.get((i + di, j + dj))
            half = 0.5 * h * math.hypot(di, dj)
            if b is not None and clear[a] > half and clear[b] > half:
                g.add_edge(a, b)
    g.add_edges_from(("R", int(i)) for i in np.flatnonzero(region))
    dist = nx.single_source_shortest_path_length(g, "R")
    for i in range(len(pts)):
        if region[i]:
            assert nxt[i] == -1
        elif i not in dist:
            assert nxt[i] == -1
        else:
            j = int(nxt[i])
            assert j >= 0 and dist[j] == dist[i] - 1
            assert free.covers(LineString([pts[i], pts[j]]))


def _scipy_region_next(world, cell, pts, h, region):
    """The walk as it was computed: the joined grid neighbours and the region's points
    (joined to a source node n) as a sparse graph, scipy's breadth first order from n,
    each point's predecessor its next hop."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import breadth_first_order

    n = len(pts)
    clear = world.distance_to_walls(pts)
    src, dst = [np.flatnonzero(region)], [np.full(int(region.sum()), n)]
    for (i, j), a in np.ndenumerate(cell):
        for di, dj in ((1, 0), (0, 1), (1, 1), (1, -1)):
            ii, jj = i + di, j + dj
            if a < 0 or not (0 <= ii < cell.shape[0] and 0 <= jj < cell.shape[1]):
                continue
            b = cell[ii, jj]
            half = 0.5 * h * math.hypot(di, dj)
            if b >= 0 and clear[a] > half and clear[b] > half:
                src.append([a])
                dst.append([b])
    src, dst = np.concatenate(src), np.concatenate(dst)
    g = coo_matrix((np.ones(len(src)), (src, dst)), shape=(n + 1, n + 1)).tocsr()
    _, pred = breadth_first_order(g, n, directed=False, return_predecessors=True)
    nxt = pred[:n].astype(np.int64)
    nxt[(nxt == n) | (nxt < 0)] = -1
    nxt[region] = -1
    return nxt


@pytest.mark.parametrize("name", ["pillars", "two_rooms", "office"])
def test_region_walk_takes_scipys_breadth_first_hops(name):
    """The level-at-a-time search over the grid's offsets picks the hops scipy's breadth
    first order picked on the sparse graph (the plan's decisions are unchanged), for
    patches of several sizes, a single point and two far apart patches."""
    world = builtin_map(name)
    h = 0.2
    _origin, cell, pts = grid_points(world, h)
    rng = np.random.default_rng(7)
    for radius in (0.3, 1.0, 3.0, 0.0, -1.0):
        c = pts[rng.integers(len(pts))]
        if radius == 0.0:
            region = np.arange(len(pts)) == rng.integers(len(pts))
        elif radius < 0:
            d = np.minimum(np.hypot(*(pts - pts[0]).T), np.hypot(*(pts - pts[-1]).T))
            region = d < 1.0
        else:
            region = np.hypot(*(pts - c).T) < radius
        want = _scipy_region_next(world, cell, pts, h, region)
        assert (want >= 0).sum() > len(pts) // 2
        assert np.array_equal(_region_next(world, cell, pts, h, region), want)


def test_region_walk_holds_no_graph_over_the_grid(monkeypatch):
    """The search holds a few arrays over the points, not a sparse graph of their joins
    (its arrays and scipy's copies: 364 MB, 218 bytes a point, on a 200 m floor plan at
    L_min 3 with 1.7 million points, the shooting evader's peak)."""
    import tracemalloc

    import strategies.policies.escape_plan as ep

    world = builtin_map("office")
    h = 0.05
    _origin, cell, pts = grid_points(world, h)
    clear = _clear_within(world, pts, 0.5 * h * math.hypot(1, 1))
    monkeypatch.setattr(ep, "_clear_within", lambda *a: clear)
    region = np.hypot(*(pts - pts[0]).T) < 1.0
    tracemalloc.start()
    try:
        nxt = _region_next(world, cell, pts, h, region)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert (nxt >= 0).sum() > len(pts) // 2
    assert peak < 48 * len(pts), peak / len(pts)


def _witness_direct(plan, cell, p, clearance, exclude, margin):
    """:meth:`EscapePlan.witness` computed directly: every via's projection and samples
    from scratch, each candidate's clearance by ``distance_to_walls`` (the method caches
    the per-piece part and skips the distances the 1-Lipschitz bound settles)."""
    dec = plan.dec
    reg = dec.cells[cell].region
    cands = []
    for b in plan.vias[cell]:
        if b in exclude:
            continue
        p0, d, ln, u, s, seg = _samples(dec.boundaries[b].segments, dec.chord_tol)
        if not len(ln):
            continue
        nrm = np.stack([-u[:, 1], u[:, 0]], axis=1)
        sign = 1.0 if dec.boundaries[b].regions[1] == reg else -1.0
        lo, hi = 0.0, 1.0
        ok = dec.map.distance_to_walls(s) >= clearance
        if margin > 0.0:
            cum = np.r_[0.0, np.cumsum(ln)]
            arc_lo, arc_hi = margin, cum[-1] - margin
            if arc_hi < arc_lo:
                arc_lo = arc_hi = 0.5 * cum[-1]
            lo = np.clip((arc_lo - cum[:-1]) / ln, 0.0, 1.0)
            hi = np.clip((arc_hi - cum[:-1]) / ln, 0.0, 1.0)
            pos = cum[seg] + np.einsum("ij,ij->i", s - p0[seg], d[seg]) / ln[seg]
            ok &= (pos >= arc_lo - 1e-12) & (pos <= arc_hi + 1e-12)
        t = np.clip(np.einsum("ij,ij->i", p - p0, d) / ln**2, lo, hi)
        q = p0 + t[:, None] * d
        dist = np.hypot(q[:, 0] - p[0], q[:, 1] - p[1])
        if margin > 0.0:
            dist = np.where((cum[:-1] <= arc_hi) & (cum[1:] >= arc_lo), dist, np.inf)
        k = int(np.argmin(dist))
        cands.append((float(dist[k]), b, q[k], sign * nrm[k]))
        ds = np.hypot(s[:, 0] - p[0], s[:, 1] - p[1])
        ok = np.flatnonzero(ok)
        cands.extend(
            (float(ds[i]), b, s[i], sign * nrm[seg[i]]) for i in ok[np.argsort(ds[ok])[:8]]
        )
    cands.sort(key=lambda c: c[0])
    clear = dec.map.distance_to_walls(np.array([c[2] for c in cands])) if cands else []
    cands = [c for c, cl in zip(cands, clear, strict=True) if cl >= clearance]
    if plan.rank[cell] < 0 or not cands:
        return None
    step = CROSS_REL * dec.L
    poly = plan._inside(reg)

    def lands(c):
        pair = dec.boundaries[c[1]].regions
        return plan.inside(pair[0] if pair[1] == reg else pair[1], c[2] + step * c[3])

    def direct(c):
        return c[0] == 0.0 or shapely.covers(poly, LineString([p, c[2]]))

    fallback = None
    for c in cands:
        if lands(c):
            if direct(c):
                break
            fallback = fallback or c
    else:
        c = fallback or next((c for c in cands if direct(c)), cands[0])
    return c[1], c[2], c[3]


@pytest.mark.parametrize("name", ["two_rooms", "maze"])
def test_witness_is_the_direct_computation(name):
    # bit for bit (the shooting evader's actions must not change), also where a
    # projection lies nearer the walls than the clearance or within a margin of an end
    plan = escape_plan(builtin_map(name), L)
    rng = np.random.default_rng(3)
    cells = np.flatnonzero(plan.rank >= 0)
    dropped = 0
    for _ in range(400):
        c = int(rng.choice(cells))
        reg = plan.dec.regions[plan.dec.cells[c].region]
        x0, y0, x1, y1 = reg.polygon.bounds
        p = rng.uniform([x0, y0], [x1, y1])
        clearance = float(rng.choice([0.0, 0.1, 0.3]))
        margin = float(rng.choice([0.0, 0.05, 0.2]))
        exclude = frozenset(b for b in plan.vias[c] if rng.random() < 0.3)
        got = plan.witness(c, p, clearance, exclude=exclude, margin=margin)
        want = _witness_direct(plan, c, p, clearance, exclude, margin)
        if want is None:
            assert got is None
            dropped += 1
            continue
        assert got.boundary == want[0]
        assert got.cross.tobytes() == want[1].tobytes()
        assert got.normal.tobytes() == want[2].tobytes()
    assert dropped < 200


@pytest.mark.parametrize("name", ["maze", "pillars"])
def test_clear_within_measures_every_point_near_a_wall(name):
    world = builtin_map(name)
    _origin, _cell, pts = grid_points(world, 0.1)
    reach = 0.3
    got = _clear_within(world, pts, reach)
    want = world.distance_to_walls(pts)
    measured = np.isfinite(got)
    assert np.array_equal(got[measured], want[measured])  # the same values
    assert (want[~measured] > reach).all()
    assert measured.any() and not measured.all()


def test_prepare_builds_what_witness_would_build():
    # the shooting evader prepares its plan at reset (issue 13: no set-up mid-episode);
    # the batch gives the same spans, bit for bit, and witness then builds nothing more
    plan = escape_plan(builtin_map("two_rooms"), L)
    ready, lazy = dataclasses.replace(plan), dataclasses.replace(plan)
    clearance, margins = 0.1, (0.05, 0.0)
    ready.prepare(clearance, margins)
    built = {k: len(v) for k, v in ready.__dict__.items() if k.startswith("_")}
    assert built["_spans"] == 2 * len(
        {b for c in np.flatnonzero(plan.rank >= 0) for b in plan.vias[c]}
    )
    for key, want in ready._spans.items():
        got = lazy._span(*key)
        assert (got is None) == (want is None)
        for g, w in zip(got or (), want or (), strict=True):
            assert np.asarray(g).tobytes() == np.asarray(w).tobytes()
    rng = np.random.default_rng(5)
    cells = np.flatnonzero(plan.rank >= 0)
    for _ in range(200):
        c = int(rng.choice(cells))
        x0, y0, x1, y1 = plan.dec.regions[plan.dec.cells[c].region].polygon.bounds
        p = rng.uniform([x0, y0], [x1, y1])
        margin = float(rng.choice(margins))
        got = ready.witness(c, p, clearance, margin=margin)
        want = lazy.witness(c, p, clearance, margin=margin)
        assert (got is None) == (want is None)
        if got is not None:
            assert got.boundary == want.boundary
            assert got.cross.tobytes() == want.cross.tobytes()
        ready.well_inside(plan.dec.cells[c].region, p)
    assert {k: len(v) for k, v in ready.__dict__.items() if k.startswith("_")} == built


def _count_measures(monkeypatch) -> list[int]:
    """The number of points of each ``Map.distance_to_walls`` call from now on (until
    ``monkeypatch.undo()``), in a list filled as they come."""
    from envs.maps import Map

    calls = []
    measure = Map.distance_to_walls

    def counted(self, points):
        calls.append(len(points))
        return measure(self, points)

    monkeypatch.setattr(Map, "distance_to_walls", counted)
    return calls


def test_prepare_measures_each_segment_end_once(monkeypatch):
    """A via piece's segments share their ends (one's end is the next one's start):
    prepare measured both, twice the points (285,892 for 140,122 on a 200 m floor plan at
    L_min 3, 2.7 s of the shooting evader's reset); the distances are the same
    (test_prepare_builds_what_witness_would_build)."""
    plan = escape_plan(load_map("random:polygons:0"), L, 0.5, 0.1)
    vias = sorted({b for c in np.flatnonzero(plan.rank >= 0) for b in plan.vias[c]})
    ends = np.concatenate(
        [x for b in vias for x in (plan._piece(b)[0], plan._piece(b)[0] + plan._piece(b)[1])]
    )
    calls = _count_measures(monkeypatch)
    dataclasses.replace(plan).prepare(0.1, (0.05, 0.0))
    monkeypatch.undo()
    assert len(np.unique(ends, axis=0)) in calls
    assert len(ends) not in calls and len(ends) > 1.5 * len(np.unique(ends, axis=0))


def test_narrow_pieces_are_measured_in_one_call(monkeypatch):
    """_narrow measured each near piece's samples in its own call, below the walls'
    spatial index's batch size: 22 s of the shooting evader's 74 s reset on a 200 m floor
    plan at L_min 3. One call for all of them now; the same pieces as the shapely oracle
    of test_disc_plan_avoids_the_pieces_its_disc_cannot_cross finds."""
    world, radius = load_map("random:polygons:0"), 0.1
    dec = escape_plan(world, L, 0.5).dec
    calls = _count_measures(monkeypatch)
    narrow = _narrow(dec, radius)
    monkeypatch.undo()
    assert len(calls) == 2 and calls[1] > 100  # the pieces' middles, then their samples
    # of the middles only those near a wall's box (every piece's was measured: 0.8 s of
    # the shooting evader's reset on a 60 x 56 room with 210 pillars)
    assert calls[0] < len(dec.boundaries) / 2, (calls, len(dec.boundaries))
    walls = world.free_region.boundary
    expect = {
        b.id
        for b in dec.boundaries
        if shapely.distance(shapely.points(_samples(b.segments, dec.chord_tol)[4]), walls).max()
        < radius
    }
    assert narrow == expect and narrow
