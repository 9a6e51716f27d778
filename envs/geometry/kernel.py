"""The geometry kernel: precomputed per-map numpy arrays and the hot-path predicates.

One :class:`Kernel` per :class:`~envs.maps.Map` (get it with :func:`kernel_for`, which
caches by the map's digest). Nothing here calls shapely.
"""

from __future__ import annotations

import math
import threading
from collections import OrderedDict
from collections.abc import Sequence

import numpy as np

from envs.errors import InvalidConfigError
from envs.geometry.arcs import free_arcs_at
from envs.geometry.segments import endpoint_on_edge, point_in_walls, segment_contacts
from envs.geometry.sweep import sweep_step
from envs.geometry.types import FreeArcs, SweepEvent
from envs.maps.map import Feature, Map
from envs.tolerances import REL_LENGTH_TOL

__all__ = ["Kernel", "kernel_for"]

ArrayLike = np.ndarray | Sequence[float]


def _point(x: ArrayLike, what: str) -> np.ndarray:
    arr = np.asarray(x, dtype=float)
    if arr.shape != (2,) or not np.all(np.isfinite(arr)):
        raise InvalidConfigError(f"{what}: expected a finite (x, y) point, got {x!r}")
    return arr


def _points(x: ArrayLike, what: str) -> np.ndarray:
    arr = np.asarray(x, dtype=float)
    if arr.ndim == 1 and arr.shape == (2,):
        arr = arr[None, :]
    if arr.ndim != 2 or arr.shape[1] != 2 or not np.all(np.isfinite(arr)):
        raise InvalidConfigError(
            f"{what}: expected a finite (k, 2) array of points, got shape {arr.shape}"
        )
    return arr


def _length(x: float, what: str, *, positive: bool = True) -> float:
    try:
        v = float(x)
    except (TypeError, ValueError) as exc:
        raise InvalidConfigError(f"{what}: expected a number, got {x!r}") from exc
    if not math.isfinite(v) or v < 0 or (positive and v == 0):
        need = "a finite number > 0" if positive else "a finite number >= 0"
        raise InvalidConfigError(f"{what}: expected {need}, got {x!r}")
    return v


class Kernel:
    """Exact polygon geometry for one map: visibility, sweeps, free arcs, lidar.

    Args:
        world: the map.

    Attributes:
        map: the map.
        eps: absolute length tolerance, ``REL_LENGTH_TOL * map.scale``.
    """

    def __init__(self, world: Map) -> None:
        if not isinstance(world, Map):
            raise InvalidConfigError(f"Kernel: expected a Map, got {type(world).__name__}")
        self.map = world
        self.eps = REL_LENGTH_TOL * world.scale
        a, b = world.edge_start, world.edge_end
        self._a = a
        self._b = b
        self._n = world.edge_normal
        self._exmin = np.minimum(a[:, 0], b[:, 0])
        self._exmax = np.maximum(a[:, 0], b[:, 0])
        self._eymin = np.minimum(a[:, 1], b[:, 1])
        self._eymax = np.maximum(a[:, 1], b[:, 1])
        self._all_edges = np.arange(world.n_edges)
        self._convex = world.convex_vertices
        self._cv = world.vertices[self._convex]

    # ------------------------------------------------------------------ prefilters
    def edges_in_box(self, xmin: float, ymin: float, xmax: float, ymax: float) -> np.ndarray:
        """Indices of the edges whose bounding boxes meet the given box."""
        m = (
            (self._exmin <= xmax)
            & (self._exmax >= xmin)
            & (self._eymin <= ymax)
            & (self._eymax >= ymin)
        )
        return np.flatnonzero(m)

    def convex_in_box(self, xmin: float, ymin: float, xmax: float, ymax: float) -> np.ndarray:
        """Indices (into ``map.vertices``) of the convex obstacle vertices in the box."""
        v = self._cv
        m = (v[:, 0] >= xmin) & (v[:, 0] <= xmax) & (v[:, 1] >= ymin) & (v[:, 1] <= ymax)
        return self._convex[m]

    def contains_point(self, x: float, y: float) -> bool:
        """Whether ``(x, y)`` lies in the closed free region (walls count as free)."""
        p = np.array([[x, y]])
        if float(self.map.distance_to_walls(p)[0]) <= self.eps:
            return True
        return bool(point_in_walls(p, self._a, self._b)[0])

    # ------------------------------------------------------------------ visibility
    def _contacts(self, p: np.ndarray, q: np.ndarray):
        eps = self.eps
        lo = np.minimum(p, q) - eps
        hi = np.maximum(p, q) + eps
        idx = self.edges_in_box(lo[0], lo[1], hi[0], hi[1])
        a, b, n = self._a[idx], self._b[idx], self._n[idx]
        return idx, segment_contacts(p, q, a, b, n, eps)

    def _through_obstacle(self, p: np.ndarray, q: np.ndarray) -> bool:
        """For a segment whose open part touches no wall: does it lie outside free space?

        Only possible when both ends rest on walls; decided by the midpoint.
        """
        m = self.map
        ends = np.stack([p, q])
        on = endpoint_on_edge(
            ends[:, None, :],
            self._a[None],
            m.edge_dir[None],
            self._n[None],
            m.edge_length[None],
            self.eps,
        ).any(axis=1)
        if not on.all():
            return False
        mid = 0.5 * (p + q)
        return not bool(point_in_walls(mid[None], self._a, self._b)[0])

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
        p = _point(p, "line_of_sight p")
        q = _point(q, "line_of_sight q")
        if float(np.hypot(*(q - p))) <= self.eps:
            return True
        _, (cross, _, vhit, _, along) = self._contacts(p, q)
        if cross.any() or vhit.any() or along.any():
            return False
        return not self._through_obstacle(p, q)

    def line_of_sight_many(self, P: ArrayLike, Q: ArrayLike) -> np.ndarray:
        """Vectorised :meth:`line_of_sight`: (k, 2), (k, 2) -> (k,) bool."""
        P = _points(P, "line_of_sight_many P")
        Q = _points(Q, "line_of_sight_many Q")
        if P.shape != Q.shape:
            raise InvalidConfigError(
                f"line_of_sight_many: P and Q must have the same shape, got {P.shape} and {Q.shape}"
            )
        k = len(P)
        out = np.ones(k, dtype=bool)
        chunk = max(1, 200_000 // max(1, self.map.n_edges))
        a, b, n = self._a[None], self._b[None], self._n[None]
        for s in range(0, k, chunk):
            p = P[s : s + chunk, None, :]
            q = Q[s : s + chunk, None, :]
            cross, _, vhit, _, along = segment_contacts(p, q, a, b, n, self.eps)
            out[s : s + chunk] = ~(cross | vhit | along).any(axis=1)
        short = np.hypot(*(Q - P).T) <= self.eps
        out[short] = True
        for i in np.flatnonzero(out & ~short):
            # both ends on walls and nothing touched: rare, check through the obstacle
            if self._ends_on_walls(P[i], Q[i]) and self._through_obstacle(P[i], Q[i]):
                out[i] = False
        return out

    def _edge_distances(self, p: np.ndarray) -> np.ndarray:
        """Distance from point ``p`` to every wall edge."""
        m = self.map
        rel = p - self._a
        t = np.clip(np.einsum("ej,ej->e", rel, m.edge_dir), 0.0, m.edge_length)
        return np.hypot(*(rel - t[:, None] * m.edge_dir).T)

    def _ends_on_walls(self, p: np.ndarray, q: np.ndarray) -> bool:
        d = self.map.distance_to_walls(np.stack([p, q]))
        return bool((d <= self.eps).all())

    def blocking_feature(self, p: ArrayLike, q: ArrayLike) -> Feature | None:
        """The wall feature nearest to ``p`` that blocks the segment p-q, or None if clear.

        A vertex touched by the segment is reported as the vertex; a crossed or grazed
        edge as the edge. When only the through-an-obstacle test blocks (both ends on
        walls), the edge under ``p`` is reported.
        """
        p = _point(p, "blocking_feature p")
        q = _point(q, "blocking_feature q")
        if float(np.hypot(*(q - p))) <= self.eps:
            return None
        idx, (cross, t_cross, vhit, t_vertex, along) = self._contacts(p, q)
        best_t = math.inf
        best: Feature | None = None
        if vhit.any():
            j = np.flatnonzero(vhit)
            k = j[np.argmin(t_vertex[j])]
            best_t, best = float(t_vertex[k]), Feature("vertex", int(idx[k]))
        if cross.any():
            j = np.flatnonzero(cross)
            k = j[np.argmin(t_cross[j])]
            if float(t_cross[k]) < best_t:
                best_t, best = float(t_cross[k]), Feature("edge", int(idx[k]))
        along_only = along & ~vhit
        if along_only.any():
            j = np.flatnonzero(along_only)
            k = j[np.argmin(t_vertex[j])]
            if float(t_vertex[k]) < best_t:
                best_t, best = float(t_vertex[k]), Feature("edge", int(idx[k]))
        if best is None and self._through_obstacle(p, q):
            best = Feature("edge", int(np.argmin(self._edge_distances(p))))
        return best

    # ------------------------------------------------------------------ sweep
    def sweep(
        self,
        p0: ArrayLike,
        e0: ArrayLike,
        p1: ArrayLike,
        e1: ArrayLike,
        l_min: float,
        l_max: float,
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

        Returns:
            The earliest :class:`SweepEvent`, or None.
        """
        p0 = _point(p0, "sweep p0")
        e0 = _point(e0, "sweep e0")
        p1 = _point(p1, "sweep p1")
        e1 = _point(e1, "sweep e1")
        l_min = _length(l_min, "sweep l_min", positive=False)
        l_max = _length(l_max, "sweep l_max")
        if l_max < l_min:
            raise InvalidConfigError(f"sweep: expected l_min <= l_max, got {l_min} > {l_max}")
        return sweep_step(self, p0, e0, p1, e1, l_min, l_max)

    # ------------------------------------------------------------------ free arcs
    def free_arcs(self, point: ArrayLike, L: float) -> FreeArcs:
        """Free orientations of a rod of length ``L`` with its evader end at ``point``.

        See :mod:`envs.geometry.arcs` for the method (THEORY.md 1.3) and the degenerate
        cases.
        """
        return free_arcs_at(self, _point(point, "free_arcs point"), _length(L, "free_arcs L"))

    def free_arcs_many(self, points: ArrayLike, L: float) -> list[FreeArcs]:
        """:meth:`free_arcs` at each of (k, 2) points."""
        pts = _points(points, "free_arcs_many points")
        L = _length(L, "free_arcs_many L")
        return [free_arcs_at(self, p, L) for p in pts]

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
        ang = np.asarray(angles, dtype=float).reshape(-1)
        if not np.all(np.isfinite(ang)):
            raise InvalidConfigError(f"ray_distances: angles must be finite, got {angles!r}")
        rmax = _length(max_range, "ray_distances max_range")
        eps = self.eps
        r = rmax + eps
        idx = self.edges_in_box(o[0] - r, o[1] - r, o[0] + r, o[1] + r)
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


_CACHE: OrderedDict[str, Kernel] = OrderedDict()
_CACHE_SIZE = 64
_LOCK = threading.Lock()


def kernel_for(world: Map) -> Kernel:
    """The kernel of ``world``, built once and cached by the map's digest (LRU of 64)."""
    if not isinstance(world, Map):
        raise InvalidConfigError(f"kernel_for: expected a Map, got {type(world).__name__}")
    key = world.digest
    with _LOCK:
        k = _CACHE.get(key)
        if k is not None:
            _CACHE.move_to_end(key)
            return k
    k = Kernel(world)
    with _LOCK:
        _CACHE[key] = k
        _CACHE.move_to_end(key)
        while len(_CACHE) > _CACHE_SIZE:
            _CACHE.popitem(last=False)
    return k
