"""The geometry kernel: precomputed per-map numpy arrays and the hot-path predicates.

One :class:`Kernel` per :class:`~envs.maps.Map` (get it with :func:`kernel_for`, which
caches it). Nothing here calls shapely.

Notation, one meaning per letter project-wide: E is the evader, P the pursuer, the rod
the segment E-P (THEORY.md section 0 writes them P and Q); lower-case p, q are the two
ends of any segment, whatever stands there.
"""

from __future__ import annotations

import hashlib
import math
import threading
from collections import OrderedDict
from collections.abc import Sequence

import numpy as np

from envs import validation
from envs.errors import InvalidConfigError
from envs.geometry.arcs import free_arcs_at
from envs.geometry.grid import Grid
from envs.geometry.segments import point_in_walls, scan_segment, segment_contacts
from envs.geometry.sweep import sweep_step
from envs.geometry.types import FreeArcs, Stop, SweepEvent
from envs.maps.map import Feature, Map
from envs.tolerances import REL_LENGTH_TOL

__all__ = ["Kernel", "kernel_for"]

ArrayLike = np.ndarray | Sequence[float]


# Input checks: the rule is envs.validation's (bools and strings are not numbers); the
# fast paths only skip it for plain Python floats, the per-step case.


def _xy(p: ArrayLike, what: str) -> tuple[float, float]:
    """``p`` as two finite floats (fast path for the per-step predicates)."""
    if type(p) is tuple and len(p) == 2:
        x, y = p
        if type(x) is float and type(y) is float and math.isfinite(x) and math.isfinite(y):
            return x, y
    x, y = validation.point(what, p).tolist()
    return x, y


def _finite(x: float, y: float, what: str) -> tuple[float, float]:
    """``(x, y)`` as two finite floats (fast path for the per-step predicates that take
    coordinates, not a point: NaN fell through their grid lookup as a bare ``ValueError``
    and ``contains_point(nan, y)`` read False)."""
    if type(x) is float and type(y) is float and math.isfinite(x) and math.isfinite(y):
        return x, y
    if isinstance(x, (list, tuple, np.ndarray)) or isinstance(y, (list, tuple, np.ndarray)):
        raise InvalidConfigError(
            f"{what}: expected two numbers x, y, got {validation.shown(x)} and "
            f"{validation.shown(y)}"
        )
    return _xy((x, y), what)


def _point(x: ArrayLike, what: str) -> np.ndarray:
    return validation.point(what, x)


def _points(x: ArrayLike, what: str) -> np.ndarray:
    """``x`` as a finite (k, 2) float array (a single (2,) point becomes (1, 2))."""
    arr = validation.points(what, x)
    if arr.ndim == 1:
        arr = arr[None, :]
    if arr.ndim != 2:
        raise InvalidConfigError(f"{what}: expected shape (k, 2), got shape {arr.shape}")
    return arr


def _length(x: float, what: str, *, positive: bool = True) -> float:
    if type(x) is float and (x > 0.0 if positive else x >= 0.0) and x < math.inf:
        return x  # the per-step case
    return validation.positive(what, x) if positive else validation.nonnegative(what, x)


class Kernel:
    """Exact polygon geometry for one map: visibility, sweeps, free arcs, lidar.

    Built once per map (use :func:`kernel_for`); immutable afterwards and safe to share
    between threads. Queries look up nearby walls in a uniform bucket grid and test them
    in plain Python when there are few (the common case: per-call numpy overhead would
    dominate), with numpy when there are many.

    Args:
        world: the map.

    Attributes:
        map: the map.
        eps: absolute length tolerance, ``REL_LENGTH_TOL * map.scale``. A wall vertex
            closer than ``eps`` to a segment touches it; a point closer than ``eps`` to a
            wall lies on it.
    """

    #: candidate counts above which a query switches from Python loops to numpy
    numpy_threshold: int = 48

    def __init__(self, world: Map) -> None:
        if not isinstance(world, Map):
            raise InvalidConfigError(f"Kernel: expected a Map, got {type(world).__name__}")
        self.map = world
        self.eps = eps = REL_LENGTH_TOL * world.scale
        a, b = world.edge_start, world.edge_end
        self._a = a
        self._b = b
        self._n = world.edge_normal
        self._recs = [
            (float(r[0]), float(r[1]), float(r[2]), float(r[3]), float(r[4]), float(r[5]))
            for r in np.concatenate([a, b, world.edge_normal], axis=1)
        ]
        self._dirs = [
            (float(u[0]), float(u[1]), float(n))
            for u, n in zip(world.edge_dir, world.edge_length, strict=True)
        ]
        self._vxy = [(float(v[0]), float(v[1])) for v in world.vertices]
        # stop labels are immutable: build each one once and share it
        n = world.n_vertices
        self._tip_edge = [Stop("tip", Feature("edge", e)) for e in range(n)]
        self._body_edge = [Stop("body", Feature("edge", e)) for e in range(n)]
        self._tip_vertex = [Stop("tip", Feature("vertex", v)) for v in range(n)]
        self._body_vertex = [Stop("body", Feature("vertex", v)) for v in range(n)]
        self._convex = world.convex_vertices
        self._exmin = np.minimum(a[:, 0], b[:, 0]) - eps
        self._exmax = np.maximum(a[:, 0], b[:, 0]) + eps
        self._eymin = np.minimum(a[:, 1], b[:, 1]) - eps
        self._eymax = np.maximum(a[:, 1], b[:, 1]) + eps
        x0, y0, x1, y1 = world.bounds
        self._bounds = (x0 - eps, y0 - eps, x1 + eps, y1 + eps)
        self.grid = Grid((x0, y0), (x1, y1), world.n_edges, eps)
        for e in range(world.n_edges):
            ax, ay, bx, by = self._recs[e][:4]
            self.grid.insert_segment(e, ax, ay, bx, by)
        self.grid.freeze()
        self.vgrid = Grid((x0, y0), (x1, y1), world.n_edges, eps)
        for v in self._convex.tolist():
            vx, vy = self._vxy[v]
            self.vgrid.insert_box(v, vx, vy, vx, vy)
        self.vgrid.freeze()
        self._build_cell_status()

    def _build_cell_status(self) -> None:
        """Pick a reference point per grid cell away from the walls and classify it."""
        g = self.grid
        h = g.h
        refs = g.cell_centers()
        # nudge reference points that lie near a wall of their cell (deterministic offsets)
        offsets = [(0.0, 0.0)] + [
            (0.31 * math.cos(2.4 * k) * h, 0.31 * math.sin(2.4 * k) * h) for k in range(1, 24)
        ]
        for c, cell in enumerate(g.cells):
            if not cell:
                continue  # no wall crosses the cell: its centre speaks for all of it
            cx, cy = refs[c]
            # the first offset point clear of the cell's walls, else the clearest one
            best, best_d = (cx, cy), -1.0
            for ox, oy in offsets:
                x, y = cx + ox, cy + oy
                d = min(self._distance(x, y, e) for e in cell)
                if d > 1e-6 * h:
                    best = (x, y)
                    break
                if d > best_d:
                    best, best_d = (x, y), d
            refs[c] = best
        self._refs = [(float(x), float(y)) for x, y in refs]
        self._ref_free = point_in_walls(refs, self._a, self._b).tolist()

    # ------------------------------------------------------------------ prefilters
    def edges_near_box(self, xmin: float, ymin: float, xmax: float, ymax: float):
        """Edges that may meet the box: a superset of those within ``eps`` of it.

        A small box reads the grid cells it overlaps (a tuple or set of indices); a box
        spanning many cells filters precomputed edge bounding boxes with numpy (an index
        array), which is cheaper than merging many cells.

        Raises:
            InvalidConfigError: a corner that is not two finite numbers (naming it).
        """
        xmin, ymin = _finite(xmin, ymin, "edges_near_box (xmin, ymin)")
        xmax, ymax = _finite(xmax, ymax, "edges_near_box (xmax, ymax)")
        return self._edges_near_box(xmin, ymin, xmax, ymax)

    def _edges_near_box(self, xmin: float, ymin: float, xmax: float, ymax: float):
        """:meth:`edges_near_box` on finite floats."""
        g = self.grid
        ncells = (g.ix(xmax) - g.ix(xmin) + 1) * (g.iy(ymax) - g.iy(ymin) + 1)
        if ncells <= 16:
            return g.query_box(xmin, ymin, xmax, ymax)
        m = (self._exmin <= xmax) & (self._exmax >= xmin)
        m &= (self._eymin <= ymax) & (self._eymax >= ymin)
        return np.flatnonzero(m)

    def _distance(self, x: float, y: float, e: int) -> float:
        """Distance from (x, y) to edge ``e``."""
        ax, ay = self._recs[e][0], self._recs[e][1]
        ux, uy, length = self._dirs[e]
        wx, wy = x - ax, y - ay
        s = min(max(wx * ux + wy * uy, 0.0), length)
        return math.hypot(wx - s * ux, wy - s * uy)

    def _near_wall(self, x: float, y: float, cand, tol: float) -> int | None:
        """An edge among ``cand`` within ``tol`` of (x, y), or None."""
        recs, dirs = self._recs, self._dirs
        for e in cand:
            ax, ay = recs[e][0], recs[e][1]
            ux, uy, length = dirs[e]
            wx, wy = x - ax, y - ay
            s = wx * ux + wy * uy
            s = 0.0 if s < 0.0 else (length if s > length else s)
            dx, dy = wx - s * ux, wy - s * uy
            if dx * dx + dy * dy <= tol * tol:
                return e
        return None

    def on_wall(self, x: float, y: float) -> int | None:
        """An edge within ``eps`` of (x, y), or None.

        Raises:
            InvalidConfigError: (x, y) is not two finite numbers (naming them).
        """
        x, y = _finite(x, y, "on_wall (x, y)")
        return self._on_wall(x, y)

    def _on_wall(self, x: float, y: float) -> int | None:
        """:meth:`on_wall` on finite floats (the kernel's own calls)."""
        return self._near_wall(x, y, self.grid.cells[self.grid.cell_of(x, y)], self.eps)

    def contains_point(self, x: float, y: float) -> bool:
        """Whether (x, y) lies in the closed free region (points on walls count as free).

        The parity of wall crossings on the segment from the cell's reference point,
        whose status was computed at construction, decides; only the cell's walls count.

        Raises:
            InvalidConfigError: (x, y) is not two finite numbers (naming them; NaN read
                as a point outside the map).
        """
        x, y = _finite(x, y, "contains_point (x, y)")
        return self._contains(x, y)

    def _contains(self, x: float, y: float) -> bool:
        """:meth:`contains_point` on finite floats (the kernel's own calls)."""
        x0, y0, x1, y1 = self._bounds
        if not (x0 <= x <= x1 and y0 <= y <= y1):
            return False
        c = self.grid.cell_of(x, y)
        cell = self.grid.cells[c]
        if not cell:
            return self._ref_free[c]
        if self._near_wall(x, y, cell, self.eps) is not None:
            return True
        rx, ry = self._refs[c]
        dx, dy = x - rx, y - ry
        inside = self._ref_free[c]
        recs = self._recs
        for e in cell:
            ax, ay, bx, by, nx, ny = recs[e]
            # half-open rule at the edge's ends: a vertex on the line counts as "left"
            sa = dx * (ay - ry) - dy * (ax - rx) >= 0.0
            sb = dx * (by - ry) - dy * (bx - rx) >= 0.0
            if sa == sb:
                continue
            hr = nx * (rx - ax) + ny * (ry - ay)
            hx = nx * (x - ax) + ny * (y - ay)
            if (hr > 0.0) != (hx > 0.0):
                inside = not inside
        return inside

    # ------------------------------------------------------------------ visibility
    def _scan(self, px: float, py: float, qx: float, qy: float, nearest: bool):
        cand = self.grid.query_segment(px, py, qx, qy)
        if len(cand) > self.numpy_threshold:
            return self._scan_numpy(np.fromiter(cand, dtype=np.intp), px, py, qx, qy)
        return scan_segment(self._recs, cand, px, py, qx, qy, self.eps, nearest)

    def _scan_numpy(self, idx: np.ndarray, px: float, py: float, qx: float, qy: float):
        """Nearest contact over many candidate edges, vectorised."""
        p = np.array([px, py])
        q = np.array([qx, qy])
        cross, t_cross, vhit, t_vertex, along = segment_contacts(
            p, q, self._a[idx], self._b[idx], self._n[idx], self.eps
        )
        best = None
        for mask, t, kind in ((vhit, t_vertex, "vertex"), (cross, t_cross, "edge")):
            if mask.any():
                j = np.flatnonzero(mask)
                k = j[np.argmin(t[j])]
                if best is None or float(t[k]) < best[0]:
                    best = (float(t[k]), kind, int(idx[k]))
        if along.any():
            # an edge the segment runs along is first met where their overlap begins, also
            # when the edge's start vertex lies on the segment further on (segment_contacts
            # gives the vertex's time there): as scan_segment does, or a segment along a
            # wall from a point on it was blamed on the vertex it reaches later
            j = np.flatnonzero(along)
            e = idx[j]
            dx, dy = qx - px, qy - py
            inv = 1.0 / (dx * dx + dy * dy)
            ta = ((self._a[e, 0] - px) * dx + (self._a[e, 1] - py) * dy) * inv
            tb = ((self._b[e, 0] - px) * dx + (self._b[e, 1] - py) * dy) * inv
            lo = np.maximum(np.minimum(ta, tb), 0.0)
            k = int(np.argmin(lo))
            if best is None or float(lo[k]) < best[0]:
                best = (float(lo[k]), "edge", int(e[k]))
        return best

    def _through_obstacle(self, px: float, py: float, qx: float, qy: float) -> bool:
        """For a segment whose open part touches no wall: does it lie outside free space?

        Only possible when both ends rest on walls; decided by the midpoint.
        """
        if self._on_wall(px, py) is None or self._on_wall(qx, qy) is None:
            return False
        return not self._contains(0.5 * (px + qx), 0.5 * (py + qy))

    def line_of_sight(self, p: ArrayLike, q: ArrayLike) -> bool:
        """Whether the segment p-q touches no wall.

        Crossing an edge, touching any wall vertex (within ``eps``) or running along an
        edge blocks. The ends may rest on walls provided the segment leaves them into free
        space. ``p`` and ``q`` are assumed to lie in the closed free region.

        Args:
            p: one end, (2,).
            q: the other end, (2,).

        Returns:
            True when the line of sight is clear.
        """
        px, py = _xy(p, "line_of_sight p")
        qx, qy = _xy(q, "line_of_sight q")
        return self._los(px, py, qx, qy)

    def _los(self, px: float, py: float, qx: float, qy: float) -> bool:
        """:meth:`line_of_sight` on validated floats."""
        if math.hypot(qx - px, qy - py) <= self.eps:
            return True
        if self._scan(px, py, qx, qy, False) is not None:
            return False
        return not self._through_obstacle(px, py, qx, qy)

    def line_of_sight_many(self, starts: ArrayLike, ends: ArrayLike) -> np.ndarray:
        """Vectorised :meth:`line_of_sight`: (k, 2), (k, 2) -> (k,) bool."""
        starts = _points(starts, "line_of_sight_many starts")
        ends = _points(ends, "line_of_sight_many ends")
        if starts.shape != ends.shape:
            raise InvalidConfigError(
                f"line_of_sight_many: starts and ends must have the same shape, got {starts.shape} "
                f"and {ends.shape}"
            )
        k = len(starts)
        if k == 0:
            return np.ones(0, dtype=bool)
        eps = self.eps
        if self.map.n_edges > self.numpy_threshold:
            # a big map: each segment meets few walls, the grid finds them faster than
            # a (k, n_edges) broadcast
            los = self._los
            return np.fromiter(
                (
                    los(p[0], p[1], q[0], q[1])
                    for p, q in zip(starts.tolist(), ends.tolist(), strict=True)
                ),
                dtype=bool,
                count=k,
            )
        out = np.ones(k, dtype=bool)
        a, b, n = self._a[None], self._b[None], self._n[None]
        chunk = max(1, 200_000 // self.map.n_edges)
        for s in range(0, k, chunk):
            p = starts[s : s + chunk, None, :]
            q = ends[s : s + chunk, None, :]
            cross, _, vhit, _, along = segment_contacts(p, q, a, b, n, eps)
            out[s : s + chunk] = ~(cross | vhit | along).any(axis=1)
        short = np.hypot(*(ends - starts).T) <= eps
        out[short] = True
        for i in np.flatnonzero(out & ~short).tolist():
            # nothing touched: blocked only if both ends rest on walls across an obstacle
            if self._through_obstacle(starts[i, 0], starts[i, 1], ends[i, 0], ends[i, 1]):
                out[i] = False
        return out

    def blocking_feature(self, p: ArrayLike, q: ArrayLike) -> Feature | None:
        """The wall feature nearest to ``p`` that blocks the segment p-q, or None if clear.

        A vertex touched by the segment is reported as the vertex; a crossed or grazed
        edge as the edge. When only the through-an-obstacle test blocks (both ends on
        walls), the edge under ``p`` is reported.
        """
        px, py = _xy(p, "blocking_feature p")
        qx, qy = _xy(q, "blocking_feature q")
        if math.hypot(qx - px, qy - py) <= self.eps:
            return None
        hit = self._scan(px, py, qx, qy, True)
        if hit is not None:
            return Feature(hit[1], hit[2])
        if self._through_obstacle(px, py, qx, qy):
            return Feature("edge", self._on_wall(px, py))
        return None

    # ------------------------------------------------------------------ sweep
    def sweep(
        self,
        p0: ArrayLike,
        e0: ArrayLike,
        p1: ArrayLike,
        e1: ArrayLike,
        l_min: float,
        l_max: float,
        *,
        start_clear: bool = False,
    ) -> SweepEvent | None:
        """First moment in a step where surveillance breaks, or None if it holds.

        The pursuer moves linearly ``p0 -> p1`` and the evader ``e0 -> e1`` as ``t`` runs
        over ``[0, 1]``. Surveillance holds while ``l_min <= |P - E| <= l_max`` (within
        ``eps``) and the rod E-P touches no wall (see :meth:`line_of_sight`).

        Args:
            p0: pursuer at the start of the step.
            e0: evader at the start of the step.
            p1: pursuer at the end of the step.
            e1: evader at the end of the step.
            l_min: minimum distance (>= 0).
            l_max: maximum distance (>= l_min).
            start_clear: the caller knows the rod e0-p0 is clear (the env does: the step
                starts where the previous one ended with surveillance held), which skips
                the line-of-sight test of the first frame.

        Returns:
            The earliest :class:`SweepEvent`, or None.
        """
        p0 = _xy(p0, "sweep p0")
        e0 = _xy(e0, "sweep e0")
        p1 = _xy(p1, "sweep p1")
        e1 = _xy(e1, "sweep e1")
        l_min = _length(l_min, "sweep l_min", positive=False)
        l_max = _length(l_max, "sweep l_max")
        if l_max < l_min:
            raise InvalidConfigError(f"sweep: expected l_min <= l_max, got {l_min} > {l_max}")
        return sweep_step(self, p0, e0, p1, e1, l_min, l_max, start_clear)

    # ------------------------------------------------------------------ free arcs
    def free_arcs(self, point: ArrayLike, L: float) -> FreeArcs:
        """Free orientations of a rod of length ``L`` with its evader end at ``point``.

        See :mod:`envs.geometry.arcs` for the method (THEORY.md 1.3) and the degenerate
        cases.
        """
        px, py = _xy(point, "free_arcs point")
        return free_arcs_at(self, px, py, _length(L, "free_arcs L"))

    def free_arcs_many(self, points: ArrayLike, L: float) -> list[FreeArcs]:
        """:meth:`free_arcs` at each of (k, 2) points."""
        pts = _points(points, "free_arcs_many points")
        L = _length(L, "free_arcs_many L")
        return [free_arcs_at(self, x, y, L) for x, y in pts.tolist()]

    # ------------------------------------------------------------------ lidar
    def ray_distances(self, origin: ArrayLike, angles: ArrayLike, max_range: float) -> np.ndarray:
        """Distance from ``origin`` to the first wall along each ray, capped at ``max_range``.

        A ray counts a wall only when it meets the wall from the free side, so an origin
        resting on a wall sees free space on that side; a ray pointing into the wall it
        rests on gets 0.

        Args:
            origin: (2,) ray origin, in the closed free region.
            angles: (k,) ray directions in radians.
            max_range: cap, > 0.

        Returns:
            (k,) float distances.
        """
        o = _point(origin, "ray_distances origin")
        ang = validation.finite_array("ray_distances angles", angles).reshape(-1)
        rmax = _length(max_range, "ray_distances max_range")
        eps = self.eps
        r = rmax + eps
        idx = self._edges_near_box(o[0] - r, o[1] - r, o[0] + r, o[1] + r)
        if not isinstance(idx, np.ndarray):
            idx = np.fromiter(idx, dtype=np.intp, count=len(idx))
        out = np.full(len(ang), rmax)
        if len(idx) == 0 or len(ang) == 0:
            return out
        a = self._a[idx]
        e = self._b[idx] - a
        nrm = self._n[idx]
        d = np.stack([np.cos(ang), np.sin(ang)], axis=1)  # (k, 2)
        ao = a - o  # (m, 2)
        # o + s d = a + u e  ->  s = cross(ao, e) / cross(d, e), u = cross(ao, d) / cross(d, e)
        den = d[:, None, 0] * e[None, :, 1] - d[:, None, 1] * e[None, :, 0]
        num_s = ao[None, :, 0] * e[None, :, 1] - ao[None, :, 1] * e[None, :, 0]
        num_u = ao[None, :, 0] * d[:, None, 1] - ao[None, :, 1] * d[:, None, 0]
        facing = (d @ nrm.T) < 0.0  # the ray meets the edge from its free side
        with np.errstate(divide="ignore", invalid="ignore"):
            s = num_s / den
            u = num_u / den
        elen = self.map.edge_length[idx][None, :]
        tol_u = eps / elen
        hit = facing & (u >= -tol_u) & (u <= 1.0 + tol_u) & (s >= -eps)
        s = np.where(hit, np.maximum(s, 0.0), np.inf)
        return np.minimum(s.min(axis=1), rmax)


_CACHE: OrderedDict[tuple[str, bytes], Kernel] = OrderedDict()
_CACHE_SIZE = 64
_LOCK = threading.Lock()


def kernel_for(world: Map) -> Kernel:
    """The kernel of ``world``, built once and cached (LRU of 64 maps).

    The key is the map's digest *and* its vertex numbering: equal digests do not imply
    equal numbering (the digest ignores where each ring starts), and the features a
    kernel reports index the arrays of the map it was built from. So the returned
    kernel's ``map`` may be another :class:`Map` object, but one whose ``vertices`` (and
    hence every feature index) equal ``world``'s.
    """
    if not isinstance(world, Map):
        raise InvalidConfigError(f"kernel_for: expected a Map, got {type(world).__name__}")
    key = (world.digest, hashlib.blake2b(world.vertices.tobytes(), digest_size=16).digest())
    with _LOCK:
        k = _CACHE.get(key)
        if k is not None:
            _CACHE.move_to_end(key)
            return k
    k = Kernel(world)
    with _LOCK:
        k = _CACHE.setdefault(key, k)
        _CACHE.move_to_end(key)
        while len(_CACHE) > _CACHE_SIZE:
            _CACHE.popitem(last=False)
    return k
