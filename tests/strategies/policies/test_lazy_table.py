"""The lazily filled safety table answers exactly as the eager one, and the pursuer plays alike."""

from __future__ import annotations

import math

import numpy as np
import pytest

from envs.maps import builtin_map
from strategies.policies import make_policy
from strategies.policies.lazy_table import LazySafetyTable
from strategies.policies.safety import grid_points, safety_table
from strategies.runner import run_episode


def _world(name: str, angle: float):
    c, s = math.cos(angle), math.sin(angle)
    return builtin_map(name).transformed(np.array([[c, -s], [s, c]]), (3.0, -1.0))


@pytest.mark.parametrize(("name", "angle"), [("corridor", 0.0), ("l_hall", 0.61)])
def test_lazy_rows_equal_the_eager_tables(name, angle):
    world = _world(name, angle)
    eager = safety_table(world, 2.2, 0.25, 48, disk_cache=False)
    lazy = LazySafetyTable(world, 2.2, 0.25, 48)
    assert np.allclose(lazy.origin, eager.origin) and lazy.shape == eager.shape
    rng = np.random.default_rng(1)
    x0, y0, x1, y1 = world.bounds
    pts = rng.uniform((x0 - 1, y0 - 1), (x1 + 1, y1 + 1), size=(400, 2))
    assert np.array_equal(lazy.inside(pts), eager.rows(pts) >= 0)  # membership alone
    assert lazy.classified == 0  # ... classifies nothing
    rl, re = lazy.rows(pts), eager.rows(pts)
    assert np.array_equal(rl < 0, re < 0)  # the same nodes are in the free region
    ok = re >= 0
    assert ok.sum() > 100
    for name_ in ("free", "safe", "guaranteed", "ccw", "cw", "need"):
        assert np.array_equal(getattr(lazy, name_)[rl[ok]], getattr(eager, name_)[re[ok]]), name_
    # only what was looked up is classified
    assert lazy.classified == len(np.unique(rl[ok])) < len(eager.free)
    for p in pts[:20]:  # row() looks around points just outside, as the eager one does
        r1, r2 = lazy.row(p), eager.row(p)
        assert (r1 < 0) == (r2 < 0)
        if r2 >= 0:
            assert np.array_equal(lazy.free[r1], eager.free[r2])


def test_the_pursuer_plays_the_same_episode_with_either_table():
    world = _world("corridor", 0.3)
    runs = []
    for table in ("eager", "lazy"):
        p = make_policy("pursuer/decomposition", table=table)
        r = run_episode(world, p, "evader/shooting", 4, max_cycles=150, start="safe")
        assert type(p.table).__name__ == ("LazySafetyTable" if table == "lazy" else "SafetyTable")
        runs.append(r)
    assert np.array_equal(runs[0].trajectory, runs[1].trajectory)
    assert runs[0].winner == runs[1].winner


@pytest.mark.parametrize("p", [0.0, 0.03, 0.5, 1.0])
def test_rotation_distances_against_brute_force(p):
    from strategies.policies.safety import NO_PATH, _circular_distance

    rng = np.random.default_rng(2)
    safe = rng.random((40, 36)) < p
    for step in (1, -1):
        got = _circular_distance(safe, step)
        for i in range(len(safe)):
            for b in range(36):
                ks = [k for k in range(36) if safe[i, (b + step * k) % 36]]
                assert got[i, b] == (ks[0] if ks else NO_PATH)


@pytest.mark.parametrize("nb", [36, 144, 300])
def test_both_rotation_distances_at_once_are_the_circular_distances(nb):
    from strategies.policies.lazy_table import _both_ways
    from strategies.policies.safety import _circular_distance

    rng = np.random.default_rng(nb)
    safe = np.vstack([rng.random((50, nb)) < p for p in (0.0, 0.01, 0.3, 0.9, 1.0)])
    ccw, cw = _both_ways(safe)
    assert ccw.dtype == cw.dtype == np.uint8
    assert np.array_equal(ccw, _circular_distance(safe, 1))
    assert np.array_equal(cw, _circular_distance(safe, -1))


@pytest.fixture
def batches(monkeypatch):
    """The sizes of the lazy tables' classification batches, in order (classify_points
    counted, then called as before)."""
    import strategies.policies.lazy_table as lt

    sizes: list[int] = []
    classify = lt.classify_points

    def counted(dec, pts, step, centres, **kw):
        sizes.append(len(pts))
        return classify(dec, pts, step, centres, **kw)

    monkeypatch.setattr(lt, "classify_points", counted)
    return sizes


def test_rows_classify_the_nodes_ahead_with_the_new_ones(monkeypatch, batches):
    """rows(points, step, steps): the new nodes of ``points + k step`` (k = 1 .. steps)
    join a batch that ``points`` needs anyway (a batch cost ~0.2 ms however few its
    points), with the same entries as when they are looked up on their own; nothing
    ahead is classified when ``points`` need no batch. inside() likewise tests the
    nodes ahead with the new ones."""

    tests = []

    def tested(self, ix, iy, flat):
        tests.append(len(ix))
        return membership(self, ix, iy, flat)

    membership = LazySafetyTable._membership
    monkeypatch.setattr(LazySafetyTable, "_membership", tested)
    world = _world("l_hall", 0.61)
    rng = np.random.default_rng(4)
    x0, y0, x1, y1 = world.bounds
    here = rng.uniform((x0, y0), (x1, y1), size=(120, 2))
    step = np.array([0.3, 0.1])
    ahead = np.vstack([here + step * k for k in (1, 2, 3, 4)])
    plain, early = LazySafetyTable(world, 2.2, 0.1, 48), LazySafetyTable(world, 2.2, 0.1, 48)
    assert np.array_equal(early.inside(here, step, 4), plain.inside(here))
    assert len(tests) == 2 and tests[0] > tests[1]  # one membership batch with the nodes ahead
    assert np.array_equal(early.inside(ahead), plain.inside(ahead))
    assert len(tests) == 3  # the nodes ahead were known (the plain table's batch)
    r_plain, r_early = plain.rows(here), early.rows(here, step, 4)
    assert len(batches) == 2 and batches[1] > batches[0]  # one batch with the nodes ahead
    a_early, a_plain = early.rows(ahead), plain.rows(ahead)
    assert len(batches) == 3  # the nodes ahead were ready (the plain table's batch)
    for got, want in ((r_early, r_plain), (a_early, a_plain)):
        ok = want >= 0
        assert np.array_equal(got < 0, ~ok) and ok.sum() > 30
        for name in ("free", "safe", "guaranteed", "ccw", "cw", "need"):
            assert np.array_equal(getattr(early, name)[got[ok]], getattr(plain, name)[want[ok]])
    n = early.classified
    early.rows(here, step + 5.0, 4)  # nothing new here: nothing classified ahead either
    early.inside(here, step + 5.0, 4)
    assert early.classified == n and len(batches) == 3 and len(tests) == 3


def test_a_row_on_new_ground_is_classified_with_the_nodes_around_it(batches):
    """row() of a point whose node is not classified yet (the pursuer's look-up of the
    evader's node, on new ground) classifies the unknown nodes within _AROUND nodes of it
    in the same batch: the evader's next nodes need no batch of one each (~0.3 ms
    apiece). Their entries are the eager table's; nodes outside the free region and the
    points off it are answered as before."""
    import strategies.policies.lazy_table as lt

    world = _world("corridor", 0.0)
    eager = safety_table(world, 2.2, 0.1, 48, disk_cache=False)
    lazy = LazySafetyTable(world, 2.2, 0.1, 48)
    p = np.array([5.0, 0.3])
    assert lazy.row(p) >= 0
    side = 2 * lt._AROUND + 1
    assert lt._AROUND >= 1 and batches == [side * side] and lazy.classified == side * side
    h = lazy.resolution
    near = p + h * np.array([[1, 0], [1, 1], [-lt._AROUND, lt._AROUND], [0, -1]])
    for q in near:  # the evader's next nodes: no batch
        r = lazy.row(q)
        assert np.array_equal(lazy.free[r], eager.free[eager.row(q)])
        assert np.array_equal(lazy.need[r], eager.need[eager.row(q)])
    assert len(batches) == 1
    rng = np.random.default_rng(5)
    x0, y0, x1, y1 = world.bounds
    for q in rng.uniform((x0 - 1, y0 - 1), (x1 + 1, y1 + 1), size=(40, 2)):
        r1, r2 = lazy.row(q), eager.row(q)
        assert (r1 < 0) == (r2 < 0)
        if r2 >= 0:
            for name in ("free", "safe", "guaranteed", "ccw", "cw", "need"):
                assert np.array_equal(getattr(lazy, name)[r1], getattr(eager, name)[r2]), name


def test_rows_of_points_whose_nodes_inside_found_are_the_rows_looked_up_again():
    """inside(points, nodes=True) also gives the points' grid nodes, and rows() of some
    of the points with those nodes (nodes_at: the pursuer's probes, among the ray
    samples it tested) classifies and returns exactly what rows() of the same points
    finds itself, the nodes ahead included, with points off the grid among them."""
    world = _world("l_hall", 0.61)
    rng = np.random.default_rng(9)
    x0, y0, x1, y1 = world.bounds
    step = np.array([0.2, -0.15])
    given, found = LazySafetyTable(world, 2.2, 0.1, 48), LazySafetyTable(world, 2.2, 0.1, 48)
    off = 0
    for _ in range(12):
        centre = rng.uniform((x0, y0), (x1, y1))
        pts = centre + rng.normal(0.0, 4.0, size=(300, 2))  # some beyond the grid
        inside, nodes = given.inside(pts, step, 3, nodes=True)
        assert np.array_equal(inside, found.inside(pts, step, 3))
        ok = nodes[3]
        off += int((~ok).sum())
        assert len(ok) == len(pts) and len(nodes[0]) == len(nodes[2]) == ok.sum()
        for at in (np.flatnonzero(inside), rng.choice(len(pts), 40, replace=False)):
            rows = given.rows(pts[at], step, 3, nodes=given.nodes_at(nodes, at))
            assert np.array_equal(rows, found.rows(pts[at], step, 3))
    assert off > 100 and given.classified == found.classified > 1000
    for name in ("free", "safe", "guaranteed", "ccw", "cw", "need"):
        assert np.array_equal(getattr(given, name), getattr(found, name)), name


def test_the_lazy_pursuer_classifies_the_evaders_probes_ahead(monkeypatch, batches):
    """The pursuer passes its probes LOOKAHEAD_STEPS steps on along the evader's
    velocity: one classification batch every few decisions instead of one a decision
    (floor_plan:0:110 at L_min 2: 1.03 batches a decision -> 0.27, mean decision time
    1.3-1.6 -> 0.81-0.85 ms, decision_time.py --clock cpu), and the same episode."""
    from strategies.policies.decomposition import DecompositionPursuer

    world = _world("corridor", 0.3)
    runs, counts = [], []
    for steps in (0, DecompositionPursuer.LOOKAHEAD_STEPS):
        monkeypatch.setattr(DecompositionPursuer, "LOOKAHEAD_STEPS", steps)
        batches.clear()
        p = make_policy("pursuer/decomposition", table="lazy")
        runs.append(run_episode(world, p, "evader/shooting", 4, max_cycles=150, start="safe"))
        counts.append(len(batches))
    assert np.array_equal(runs[0].trajectory, runs[1].trajectory)
    assert runs[0].winner == runs[1].winner
    assert DecompositionPursuer.LOOKAHEAD_STEPS > 0 and 3 * counts[1] < 2 * counts[0], counts


def test_a_grid_beyond_the_memory_budget_is_refused_before_it_is_allocated(monkeypatch):
    """``surveil play --pursuer-params '{"resolution": 1e-6}'`` ended in a numpy
    MemoryError traceback (582 TiB for the corridor's grid); now a MemoryBudgetError
    names the estimate and a resolution that fits, and that resolution builds."""
    from envs.errors import MemoryBudgetError

    monkeypatch.setenv("SURVEIL_MEMORY_BUDGET", "500MB")  # the decomposition fits
    world = builtin_map("corridor")
    with pytest.raises(MemoryBudgetError, match=r"resolution = 1e-06\): its grid of "
                       r"16,000,000 x 10,000,000 nodes .* use resolution >= ") as err:  # fmt: skip
        LazySafetyTable(world, 2.2, 1e-6, 36)
    fit = float(str(err.value).split("use resolution >= ")[1].split(",")[0])
    assert "SURVEIL_MEMORY_BUDGET=" in str(err.value) and "memory_budget=" not in str(err.value)
    table = LazySafetyTable(world, 2.2, fit, 36)
    assert 5 * table.shape[0] * table.shape[1] <= 500e6


def test_a_huge_map_is_refused_before_its_grid_axes_are_made(monkeypatch):
    """A 1e9 m square map (``surveil play --map huge.json``): the grid's axes alone asked
    numpy for 75 GiB (a MemoryError traceback) before the grid's check."""
    from envs.errors import MemoryBudgetError
    from envs.maps import Map

    made = []
    monkeypatch.setattr("strategies.policies.lazy_table.grid_axis",
                        lambda *a: made.append(a) or np.zeros(1))  # fmt: skip
    huge = Map([(0, 0), (1e9, 0), (1e9, 1e9), (0, 1e9)], name="huge")
    with pytest.raises(MemoryBudgetError, match=r"10,000,000,000 x 10,000,000,000 nodes"):
        LazySafetyTable(huge, 2.0, 0.1, 36)
    assert made == []


def test_the_shooting_evader_shoots_the_same_with_a_lazy_table():
    """The shooting evader's lazy table (maps above ``DISTINCT_TABLE_POINTS``: it
    tabulated the whole map, corner~x100 at L_min 2 spent minutes and gigabytes in its
    reset) reads the same entries as its distinct table: the same episode, shots included
    (l_hall at rho 0.9, seed 0: 25 shots against the decomposition pursuer)."""
    world = builtin_map("l_hall")
    runs, modes = [], []
    for table in ("distinct", "lazy"):
        ev = make_policy("evader/shooting", table=table)
        seen: list[str] = []
        modes.append(seen)

        def record(_, seen=seen, ev=ev):
            seen.append(ev.mode)

        r = run_episode(world, "pursuer/decomposition", ev, 0, max_cycles=150, start="safe",
                        overrides={"v_evader": 0.9}, on_step=record)  # fmt: skip
        runs.append(r)
        assert type(ev.table).__name__ == ("LazySafetyTable" if table == "lazy" else "SafetyTable")
    assert modes[0].count("shoot") >= 10 and modes[0] == modes[1]
    assert np.array_equal(runs[0].trajectory, runs[1].trajectory)
    assert runs[0].winner == runs[1].winner == "evader"
    lazy = ev.table  # classified only where candidates landed (here 54 % of a small map)
    assert 0 < lazy.classified < len(grid_points(world, lazy.resolution)[2])


def test_the_shooting_evaders_table_is_lazy_above_the_pursuers_threshold(monkeypatch):
    from envs.surveillance.config import EnvConfig
    from strategies.policies.shooting import ShootingEvader

    assert ShootingEvader.DISTINCT_TABLE_POINTS == 1_000_000  # the pursuer's threshold
    config = EnvConfig(map=builtin_map("corner"))
    kinds = []
    for limit in (1_000_000, 1000):
        monkeypatch.setattr(ShootingEvader, "DISTINCT_TABLE_POINTS", limit)
        ev = make_policy("evader/shooting")
        ev.reset(role="evader", map=config.map, config=config, seed=0)
        kinds.append(type(ev.table).__name__)
    assert kinds == ["SafetyTable", "LazySafetyTable"]


def test_a_lazy_tables_grid_is_allocated_where_it_is_looked_up():
    """The per-node arrays (5 bytes a node) were allocated for the whole grid: 0.98 GB on
    corner~x100 at L_min 2 for each policy, whatever the evader visits. Now a tile at a
    time where lookups land (corner~x30 at 0.1: 88 MB of per-node arrays, 94 MB at the
    peak before, 6 MB now), with the same answers across many tiles."""
    import tracemalloc

    from envs.maps import load_map

    world = load_map("corner~x30")
    LazySafetyTable(world, 2.2, 1.0, 36)  # its decomposition made (and kept) first
    rng = np.random.default_rng(0)
    pts = rng.uniform((30, 30), (40, 40), size=(2000, 2))
    tracemalloc.start()
    try:
        lazy = LazySafetyTable(world, 2.2, 0.1, 36)
        rows = lazy.rows(pts)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert (rows >= 0).all() and peak < 0.15 * 5 * lazy.shape[0] * lazy.shape[1]
    # the same entries as the distinct table over a grid of many tiles (rotated l_hall:
    # 5 x 4 tiles of 64 x 64 nodes), membership alone first
    world = _world("l_hall", 0.61)
    lazy, ref = (
        LazySafetyTable(world, 2.2, 0.1, 48),
        safety_table(world, 2.2, 0.1, 48, distinct=True),
    )
    x0, y0, x1, y1 = world.bounds
    pts = rng.uniform((x0 - 1, y0 - 1), (x1 + 1, y1 + 1), size=(3000, 2))
    assert np.array_equal(lazy.inside(pts), ref.rows(pts) >= 0)
    rl, rr = lazy.rows(pts), ref.rows(pts)
    assert np.array_equal(rl < 0, rr < 0) and (rr >= 0).sum() > 1000
    for name_ in ("free", "safe", "guaranteed", "ccw", "cw"):
        assert np.array_equal(getattr(lazy, name_)[rl[rl >= 0]], getattr(ref, name_)[rr[rr >= 0]])


def test_a_lazy_table_builds_its_point_location_at_reset():
    # the region grid and the cells' stop-code index were built by the first
    # classification: ~60 ms of the pursuer's first decision on a 300-vertex floor plan
    lazy = LazySafetyTable(_world("l_hall", 0.61), 2.2, 0.25, 48)
    dec = lazy.decomposition
    assert dec._grid is not None and "_batch_cell_keys" in dec.__dict__
    assert lazy.classified == 0  # (nothing classified yet)


def test_the_pursuers_batched_wall_clearances_are_the_node_by_node_ones():
    world = _world("corridor", 0.3)
    r = run_episode(world, "pursuer/decomposition", "evader/shooting", 4, max_cycles=2)
    pols = []
    for table in ("lazy", "lazy", "eager"):
        p = make_policy("pursuer/decomposition", table=table)
        p.reset(role="pursuer", map=world, config=r.config, seed=0)
        pols.append(p)
    batched, single, eager = pols
    nx, ny = eager.table.shape
    rng = np.random.default_rng(3)
    i = rng.integers(0, nx, 300)
    j = rng.integers(0, ny, 300)
    i[-20:], j[-20:] = i[:20], j[:20]  # repeated nodes, memoised in the same call
    got = batched._memo_clearances(i, j)
    want = [single._memo_clearance(int(a), int(b)) for a, b in zip(i, j, strict=True)]
    assert got.tolist() == want  # the same floats
    assert np.array_equal(got, eager._clear[i, j])  # as the eager table's grid
    assert (got == 0.0).any() and (got > 0.0).any()  # nodes off and in the free region
    assert batched._memo_clearances(i[:0], j[:0]).shape == (0,)


def test_a_maps_later_lazy_tables_share_its_decomposition_and_answer_alike():
    # Each episode's new table read the decomposition back from the disk cache and built
    # its point location again: 0.6 s of the shooting evader's 0.72 s of CPU a reset on a
    # 200 m floor plan after its first. The later tables share the first one's; they
    # answer as a table of a decomposition read afresh.
    from strategies.cspace import decompose
    from strategies.policies.lazy_table import _decomposition

    world = _world("l_hall", 0.37)
    first, later = LazySafetyTable(world, 2.2, 0.25, 48), LazySafetyTable(world, 2.2, 0.25, 48)
    assert later.decomposition is first.decomposition
    _decomposition.cache_clear()
    fresh = LazySafetyTable(world, 2.2, 0.25, 48)
    assert fresh.decomposition is not first.decomposition
    assert len(fresh.decomposition.cells) == len(decompose(world, 2.2, cache=True).cells)
    pts = np.random.default_rng(3).uniform(world.bounds[:2], world.bounds[2:], size=(300, 2))
    a, b = later.rows(pts), fresh.rows(pts)
    assert np.array_equal(a < 0, b < 0) and (a >= 0).sum() > 50
    for name in ("free", "safe", "guaranteed", "ccw", "cw", "need"):
        assert np.array_equal(getattr(later, name)[a[a >= 0]], getattr(fresh, name)[b[b >= 0]])


def test_membership_asks_the_wall_tolerance_only_near_walls(monkeypatch):
    """A node in the polygon is a member unless a wall passes within the map's length
    tolerance of it: GEOS answered that for every such node (~1 us a node, 0.07 of ~1.05
    ms a decision on floor_plan:1:110). A new tile now measures its 8 x 8 blocks'
    centres once, and only nodes of blocks a wall passes near are asked (here a third):
    the same membership on every node of the grid, and no node left unasked lies within
    the tolerance of a wall."""
    import strategies.policies.lazy_table as lt

    world = _world("l_hall", 0.61)
    lazy = LazySafetyTable(world, 2.2, 0.1, 48)
    ref = safety_table(world, 2.2, 0.1, 48, distinct=True)
    asked = []
    dwithin = lt.shapely.dwithin

    def counted(a, b, distance):
        if distance == lazy._eps:
            asked.append(len(b))
        return dwithin(a, b, distance)

    monkeypatch.setattr(lt.shapely, "dwithin", counted)
    xs, ys = np.meshgrid(lazy._xs, lazy._ys, indexing="ij")
    nodes = np.stack([xs.ravel(), ys.ravel()], axis=1)
    inside = lazy.inside(nodes)
    assert np.array_equal(inside, ref.rows(nodes) >= 0)
    polygon = lt.shapely.contains_xy(world.prepared_free_region, nodes[:, 0], nodes[:, 1])
    assert polygon.sum() > 10_000 and 0 < sum(asked) < 0.5 * polygon.sum()
    near = lazy._near.reshape(-1)[lazy._slots(*lazy._nodes(nodes)[:2])]
    unasked = nodes[polygon & ~near]
    assert (lt.shapely.distance(lazy._walls, lt.shapely.points(unasked)) > lazy._eps).all()


def test_a_lazy_batch_does_not_test_its_nodes_against_the_polygon_again(monkeypatch):
    """A lazy table classifies nodes its membership test put inside the polygon, and
    each batch tested them again (a GEOS call a batch): ``interior=True`` skips that,
    with the same bins."""
    import shapely

    import strategies.cspace._batch_arcs as ba
    from strategies.policies._batch_classify import classify_points

    lazy = LazySafetyTable(_world("l_hall", 0.61), 2.2, 0.1, 48)
    x0, y0, x1, y1 = lazy.map.bounds
    pts = np.random.default_rng(5).uniform((x0, y0), (x1, y1), size=(400, 2))
    pts = pts[lazy.inside(pts)]
    tested = []
    contains = shapely.contains_xy
    monkeypatch.setattr(ba.shapely, "contains_xy", lambda *a: tested.append(1) or contains(*a))
    args = (lazy.decomposition, pts, lazy.resolution, lazy._centres)
    free, safe = classify_points(*args, interior=True)
    assert tested == [] and len(pts) > 100
    want = classify_points(*args)
    assert tested == [1]
    assert np.array_equal(free, want[0]) and np.array_equal(safe, want[1])
    assert free.any(axis=1).all() and safe.any() and not safe.all()


def test_the_lazy_pursuers_probes_count_the_largest_rotation_per_radius():
    """On a lazy table the probes' values took a turn lookup per probe and bin; they take
    the largest rotation over a radius's probes first, as the eager table's fast path
    (exact: the lookups rise with the rotation), and give the same floats, every way
    of counting the turn, with and without a delay or a subset of the rays."""
    world = _world("l_hall", 0.61)
    r = run_episode(world, "pursuer/decomposition", "evader/shooting", 4, max_cycles=2)
    p = make_policy("pursuer/decomposition", table="lazy")
    p.reset(role="pursuer", map=world, config=r.config, seed=0)
    assert p._monotone and isinstance(p.table, LazySafetyTable)
    rng = np.random.default_rng(7)
    x0, y0, x1, y1 = world.bounds
    origins = rng.uniform((x0, y0), (x1, y1), size=(30, 2))
    rays = rng.random(p.rays) < 0.5
    cases = [{}, {"sense": 1}, {"sense": -1}, {"delay": 0.4, "rays": rays, "sense": 1},
             {"step": np.array([0.05, -0.02])}]  # fmt: skip
    seen = 0
    for o in origins:
        if not p.table.inside(o[None])[0]:
            continue
        for kw in cases:
            p._monotone = True
            fast = p._probe_values(o, **kw)
            p._monotone = False
            slow = p._probe_values(o, **kw)
            assert np.array_equal(fast, slow) and fast.dtype == slow.dtype
            seen += (fast < p.horizon).any()
    assert seen > 10


def test_the_lazy_pursuers_clearances_are_measured_a_block_at_a_time(monkeypatch):
    """On a lazy table the pursuer's clearances (its path ahead, the orbits' centres) move
    on by a node or two a step; each new node's whole block of 4 x 4 nodes is measured
    with it, in one call (a third of the calls of the nodes alone on floor_plan:1:110),
    and every value is still the node's own: the wall distance against every edge, 0 off
    the free region, on a floor plan whose distances go through the map's cells."""
    import envs.maps.map as map_module
    from envs.maps import floor_plan

    world = floor_plan(3, n_vertices=200, size=(40.0, 40.0))
    assert world.n_edges >= map_module._NEAR_EDGES  # (the cells' distances)
    r = run_episode(world, "pursuer/decomposition", "evader/shooting", 4, max_cycles=2)
    p = make_policy("pursuer/decomposition", table="lazy")
    p.reset(role="pursuer", map=world, config=r.config, seed=0)
    tab = p.table
    calls = []
    measure = map_module.Map.distance_to_walls

    def counted(self, points):
        calls.append(len(points))
        return measure(self, points)

    monkeypatch.setattr(map_module.Map, "distance_to_walls", counted)
    rng = np.random.default_rng(5)
    i = rng.integers(4, tab.shape[0] - 4, 200)
    j = rng.integers(4, tab.shape[1] - 4, 200)
    got = p._memo_clearances(i, j)
    bi, bj = int(i[0]) >> 2 << 2, int(j[0]) >> 2 << 2
    assert all((bi + a, bj + b) in p._clear_memo for a in range(4) for b in range(4))
    n = len(p._clear_memo)  # (blocks off the grid's edges: 16 nodes each)
    assert len(calls) == 1 and n == 16 * len({(a >> 2, b >> 2) for a, b in zip(i, j, strict=True)})
    p._memo_clearance(int(i[0]) ^ 1, int(j[0]) ^ 1)  # a node of a measured block: no call
    assert len(calls) == 1 and len(p._clear_memo) == n
    monkeypatch.undo()
    monkeypatch.setattr(map_module, "_NEAR_EDGES", 10**9)  # every edge
    keys = list(p._clear_memo)
    nodes = tab.origin + tab.resolution * np.array(keys, dtype=float)
    inside = tab.inside(nodes)
    want = np.where(inside, world.distance_to_walls(nodes), 0.0)
    assert np.array_equal(np.array([p._clear_memo[k] for k in keys]), want)  # the same floats
    assert got.tolist() == [p._clear_memo[k] for k in zip(i.tolist(), j.tolist(), strict=True)]
    assert inside.any() and not inside.all()
