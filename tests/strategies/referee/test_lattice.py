"""The discretisation: cells, certified lattice, moves, windows, stencils and erosions."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely

from envs.errors import InvalidConfigError
from strategies.referee import Resolution
from strategies.referee._fixpoint import erode, reach_rectangles, shifted
from strategies.referee.lattice import Lattice, segment_wall_distance
from tests.strategies.referee.conftest import dead_end, spec


def _stencil(rects):
    return {(i, j) for a, b in rects for i in range(-a, a + 1) for j in range(-b, b + 1)}


@pytest.mark.parametrize("r", [0.0, 0.4, 1.0, 1.5, 2.3, 4.1, 7.0])
def test_reach_rectangles_cover_exactly_the_cells_within_reach(r):
    exact = {
        (i, j)
        for i in range(-12, 13)
        for j in range(-12, 13)
        if max(abs(i) - 1, 0) ** 2 + max(abs(j) - 1, 0) ** 2 <= r * r + 1e-9
    }
    assert _stencil(reach_rectangles(r, 1.0, None)) == exact
    # the square-to-square distance is the reach: a brute force over cell points
    pts = np.linspace(-0.5, 0.5, 5)
    for i, j in [(2, 1), (0, 3), (1, 1)]:
        gap = min(math.hypot(i + a - b, j + c - d) for a in pts for b in pts for c in pts
                  for d in pts)  # fmt: skip
        assert ((i, j) in exact) == (gap <= r + 1e-9)


@pytest.mark.parametrize("r", [16.0, 40.0])
def test_large_stencils_are_covered_by_few_rectangles(r):
    few = reach_rectangles(r, 1.0)
    exact = _stencil(reach_rectangles(r, 1.0, None))
    assert len(few) <= 8
    got = _stencil(few)
    assert got >= exact  # a superset: the opponent is over-approximated, never missed
    assert len(got) <= 1.06 * len(exact)


def _old_reach_rectangles(r, max_rects):
    """reach_rectangles as it was before it stopped listing every row: the reference."""
    K = math.floor(r + 1e-9)
    widths = [math.floor(math.sqrt(max(r * r - k * k, 0.0)) + 1e-9) for k in range(K + 1)]
    exact = []
    for k, w in enumerate(widths):
        if exact and exact[-1][1] == w + 1:
            exact[-1] = (k + 1, w + 1)
        else:
            exact.append((k + 1, w + 1))
    if max_rects is None or len(exact) <= max_rects:
        return exact
    rows = sorted({min(K, round(r * math.sin(0.5 * math.pi * j / max_rects)))
                   for j in range(1, max_rects + 1)} | {K})  # fmt: skip
    out, prev = [], -1
    for k in rows:
        out.append((k + 1, widths[prev + 1] + 1))
        prev = k
    return out


def test_a_huge_reach_is_covered_without_listing_its_rows(monkeypatch):
    # surveil referee MAP --config '{"v_evader": 1e-9}': the evader bound's step is 2e9 s,
    # the pursuer's reach 4e9 cells, and the stencil listed 4e9 rows (67 s at rho 1e-5,
    # no answer in 5 min at 1e-9); beyond 4 (max_rects + 1) rows the exact union has more
    # than max_rects rectangles, so only the covering rows are computed
    from strategies.referee import _fixpoint

    calls = []

    class CountingMath:
        def __getattr__(self, name):
            return getattr(math, name)

        def sqrt(self, x):
            calls.append(x)
            assert len(calls) < 10_000, "listed every row of the stencil"
            return math.sqrt(x)

    monkeypatch.setattr(_fixpoint, "math", CountingMath())
    rects = reach_rectangles(2e9, 0.5)
    assert len(rects) == 8 and max(max(r) for r in rects) == 4_000_000_001
    monkeypatch.undo()
    rng = np.random.default_rng(0)
    for r in [*np.arange(0.0, 120.0, 0.05), *rng.uniform(0.0, 3e4, 300)]:
        for m in (1, 8, None):
            assert reach_rectangles(float(r), 1.0, m) == _old_reach_rectangles(float(r), m)


def test_erode_with_a_stencil_wider_than_the_window_filters_the_window_only(monkeypatch):
    # a half-side of 1e8 ran a min-filter 2e8 + 1 wide over a 9-cell axis (23 s)
    from strategies.referee import _fixpoint

    sizes = []
    real = _fixpoint.minimum_filter1d

    def recording(u, size, **kw):
        sizes.append(size)
        return real(u, size, **kw)

    monkeypatch.setattr(_fixpoint, "minimum_filter1d", recording)
    rng = np.random.default_rng(1)
    X = rng.random((4, 9, 9)) > 0.05
    st = _stencil([(12, 3), (2, 12)])  # 12 > 9: as wide as 1e8 on a 9-cell window
    for border in (True, False):
        got = erode(X, [(10**8, 3), (2, 10**8)], border)
        assert np.array_equal(got, _brute_erode(X, st, border))
    assert max(sizes) <= 2 * 9 + 1


def _brute_erode(X, st, border):
    """The erosion by definition: a cell stays when every stencil offset of it is set
    (``border`` outside the window)."""
    n, h, w = X.shape
    out = np.zeros_like(X, dtype=bool)
    for k in range(n):
        for a in range(h):
            for b in range(w):
                out[k, a, b] = all(
                    X[k, a + i, b + j] if (0 <= a + i < h and 0 <= b + j < w) else border
                    for i, j in st
                )
    return out


@pytest.mark.parametrize("border", [True, False])
def test_erode_matches_brute_force(border):
    rng = np.random.default_rng(0)
    X = rng.random((3, 15, 15)) > 0.08
    rects = reach_rectangles(2.2, 1.0, None)
    st = _stencil(rects)
    got = erode(X, rects, border)
    assert np.array_equal(got, _brute_erode(X, st, border))


def test_shifted_reads_the_offset_cell():
    Y = np.random.default_rng(1).random((2, 7, 7)) > 0.5
    out = shifted(Y, 2, -1, fill=True)
    for a in range(7):
        for b in range(7):
            src = (a - 2, b + 1)
            want = Y[:, src[0], src[1]] if (0 <= src[0] < 7 and 0 <= src[1] < 7) else True
            assert np.array_equal(out[:, a, b], np.broadcast_to(want, (2,)))


@pytest.fixture(scope="module")
def lattice():
    s = spec(dead_end(), 0.5)
    return Lattice(s, Resolution(cell=0.125, coarse=2, tau=0.5), "pursuer")


def test_open_cells_cover_the_opponent_region(lattice):
    s = lattice.spec
    rng = np.random.default_rng(4)
    x0, y0, x1, y1 = s.map.bounds
    pts = rng.uniform((x0, y0), (x1, y1), size=(4000, 2))
    inside = s.map.contains(pts) & (s.map.distance_to_walls(pts) >= s.opponent_clearance)
    assert lattice.cell_open_at(lattice.cell_of(pts[inside])).all()
    # and an open cell does meet the region (here: not more than a cell beyond it)
    centers = lattice.centers[lattice.cell_open]
    far = shapely.distance(lattice.opponent_region, shapely.points(centers))
    assert far.max() <= lattice.delta + 1e-9


def test_certified_points_and_moves_keep_the_body_radius(lattice):
    s = lattice.spec
    assert (s.map.distance_to_walls(lattice.points) >= s.body_radius).all()
    assert np.allclose((lattice.points - lattice.anchor) / lattice.spacing,
                       np.rint((lattice.points - lattice.anchor) / lattice.spacing))  # fmt: skip
    vec, targets = lattice.moves(0.5)
    assert tuple(vec[0]) == (0, 0) and (targets[:, 0] == np.arange(lattice.n_points)).all()
    assert (np.hypot(*vec.T) * lattice.h <= 0.5 + 1e-12).all()
    # symmetric under the square's symmetries (rotations, reflections)
    vs = {tuple(v) for v in vec}
    assert vs == {(-b, a) for a, b in vs} == {(b, a) for a, b in vs}
    walls = shapely.LinearRing(s.map.rings[0])
    for k in range(0, lattice.n_points, 7):
        for j, t in enumerate(targets[k]):
            if t < 0 or j == 0:
                continue
            seg = shapely.LineString([lattice.points[k], lattice.points[t]])
            assert walls.distance(seg) >= s.body_radius * (1 - 1e-9)
            assert np.allclose(lattice.points[t] - lattice.points[k], vec[j] * lattice.h)


def test_moves_that_would_cut_a_corner_are_refused(lattice):
    vec, targets = lattice.moves(0.5)
    A = np.repeat(lattice.points, len(vec), axis=0)
    B = A + np.tile(vec, (lattice.n_points, 1)) * lattice.h
    clear = segment_wall_distance(A, B, lattice.spec.map).reshape(lattice.n_points, -1)
    dest = lattice.point_index((lattice.point_cells[:, None, :] + vec[None]).reshape(-1, 2))
    allowed = (clear >= lattice.spec.body_radius * (1 - 1e-9)) & (dest.reshape(clear.shape) >= 0)
    allowed[:, 0] = True
    assert np.array_equal(targets >= 0, allowed)
    assert (~allowed).any()  # the corridor's mouth does refuse some


def test_segment_wall_distance_matches_shapely():
    world = dead_end()
    rng = np.random.default_rng(9)
    A = rng.uniform((-2.5, -2.5), (5, 2.5), size=(200, 2))
    B = A + rng.uniform(-1, 1, size=(200, 2))
    got = segment_wall_distance(A, B, world)
    walls = shapely.LinearRing(world.rings[0])
    want = shapely.distance(walls, shapely.linestrings(np.stack([A, B], axis=1)))
    assert got == pytest.approx(want, abs=1e-12)


def test_windows_gather_the_cells_around_each_point(lattice):
    grid = np.arange(lattice.nx * lattice.ny, dtype=float).reshape(lattice.nx, lattice.ny)
    win = lattice.windows(grid, -1.0)
    for k in (0, lattice.n_points // 2, lattice.n_points - 1):
        i, j = lattice.point_cells[k] - (lattice.i0, lattice.j0)
        for a, b in [(0, 0), (lattice.hw, lattice.hw), (lattice.W - 1, 3)]:
            gi, gj = i + a - lattice.hw, j + b - lattice.hw
            want = grid[gi, gj] if (0 <= gi < lattice.nx and 0 <= gj < lattice.ny) else -1.0
            assert win[k, a, b] == want
        # the window's centre is the point itself
        assert np.allclose(lattice.centers[i, j], lattice.points[k])


def test_too_fine_or_empty_lattices_are_refused():
    s = spec(dead_end(), 0.5)
    with pytest.raises(InvalidConfigError, match="too fine"):
        Lattice(s, Resolution(cell=1e-4), "pursuer")
    narrow = spec(dead_end(), 0.5, opponent_clearance=0.05)
    # "refine the resolution": a finer lattice can miss a narrow passage too
    with pytest.raises(InvalidConfigError, match=r"no lattice point .* try another resolution"):
        Lattice(
            type(narrow)(narrow.map, 5.0, 10.0, body_radius=2.4),
            Resolution(cell=0.5, coarse=3),
            "pursuer",
        )


def test_points_within_keeps_full_length_moves_from_float32_positions(lattice):
    # a policy's position is read from a float32 observation: a few 1e-7 off its point;
    # the moves of exactly the full length must stay available (without them the evader
    # of the pillar room stalled, its certified bound never decreasing)
    k = lattice.n_points // 2
    x = lattice.points[k]
    full = 2 * lattice.spacing
    exact = set(lattice.points_within(x, full).tolist())
    assert any(np.isclose(np.hypot(*(lattice.points[i] - x)), full) for i in exact)
    for off in ((4e-7, 0.0), (0.0, -4e-7), (-3e-7, 3e-7), (3e-7, 3e-7)):
        assert set(lattice.points_within(x + np.array(off), full).tolist()) >= exact
    near = lattice.points_within(x, full)
    d = np.hypot(*(lattice.points[near] - x).T)
    assert (np.diff(d) >= 0).all() and near[0] == k
