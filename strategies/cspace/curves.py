"""Semi-free critical curves of types 0-5 for a rod of fixed length L (THEORY.md 1.2).

:func:`critical_curves` builds every candidate of :mod:`strategies.cspace._candidates`,
keeps the parts where the contact configuration is semi-free (the rod touches the
defining features and lies in the closed free region,
:func:`~strategies.cspace._rod.rods_semifree_near`), and returns them as
:class:`CriticalCurve` pieces with their exact geometry and a polyline.

Every piece ends exactly at a breakpoint of its candidate (a closed form, or a root
polished to double precision), i.e. exactly where the rod gains or loses a contact,
which is a point of another critical curve or of a wall: nothing is left to a sampling
grid. Segments (types 0, 1, 3, 4) are exact; arcs (type 2) and conchoids (type 5) also
carry a polyline whose vertices lie on the exact curve and whose chords stay within
``tolerance`` of it (:data:`CHORD_TOL_REL` times L by default), for pictures and region
polygons only.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from shapely.geometry import LineString

from envs.errors import InvalidConfigError
from envs.maps.map import Feature, Map
from envs.tolerances import REL_LENGTH_TOL
from envs.validation import positive
from strategies.cspace._candidates import Candidates, candidates
from strategies.cspace._rod import rods_semifree_near
from strategies.cspace._shapes import (
    SEGMENT,
    SHAPE_CODES,
    SHAPE_NAMES,
    orientation,
    points,
    polyline_params,
    project,
)
from strategies.cspace.tolerances import CHORD_TOL_REL

__all__ = ["CHORD_TOL_REL", "TYPE_NAMES", "CriticalCurve", "check_length", "critical_curves"]

TYPE_NAMES = {
    0: "wall (P on the boundary)",
    1: "tip on an edge, rod perpendicular",
    2: "tip at a vertex",
    3: "body on two convex vertices",
    4: "rod along an edge, body on its convex end",
    5: "body on a convex vertex, tip on an edge (conchoid)",
}
"""One-line description of each critical-curve type (THEORY.md 1.2)."""

_PAIRS_PER_BATCH = 2_000_000  # (rod, edge) pairs tested per vectorised batch of the clip


@dataclass(frozen=True, eq=False)
class CriticalCurve:
    """One semi-free piece of a critical curve.

    Attributes:
        type: 0-5 (THEORY.md 1.2).
        features: the wall features that define it (edge; vertex; two vertices;
            vertex and edge; vertex and edge).
        shape: ``"segment"``, ``"arc"`` or ``"conchoid"``.
        data: the exact parameters of the shape (see :mod:`strategies.cspace._shapes`).
        t0, t1: the piece's parameter interval.
        L: rod length.
        points: (m, 2) polyline; its vertices lie on the exact curve.
        tolerance: bound on the distance between the polyline and the exact curve (0 for
            segments).
        params: (m,) the parameters of the polyline's vertices.
    """

    type: int
    features: tuple[Feature, ...]
    shape: str
    data: tuple[float, ...]
    t0: float
    t1: float
    L: float
    points: np.ndarray = field(repr=False)
    tolerance: float = 0.0
    params: np.ndarray | None = field(default=None, repr=False)

    @property
    def code(self) -> int:
        """The shape code of :mod:`strategies.cspace._shapes`."""
        return SHAPE_CODES[self.shape]

    @property
    def row(self) -> np.ndarray:
        """The exact data padded to six numbers (the vectorised layout)."""
        out = np.zeros(6)
        out[: len(self.data)] = self.data
        return out

    def evaluate(self, t: np.ndarray | float) -> tuple[np.ndarray, np.ndarray]:
        """Evader positions P (k, 2) and contact orientations theta (k,) at parameters t.

        For type 0 (a wall) theta is NaN: no rod contact defines it.
        """
        t = np.atleast_1d(np.asarray(t, dtype=float))
        P = points(self.code, self.row, t, self.L)
        if self.type == 0:
            return P, np.full(len(t), np.nan)
        return P, orientation(self.code, self.row, t, self.L)

    def project(self, points: np.ndarray) -> np.ndarray:
        """Parameters of the exact curve points nearest to ``points``, clipped to the piece.

        For conchoids: the point in line with ``points`` and the vertex.
        """
        p = np.atleast_2d(np.asarray(points, dtype=float))
        t = project(self.code, self.row, p, self.t0)
        if self.shape == "arc":  # past the end: back to whichever end is nearer
            over = t > self.t1
            back = t - 2 * math.pi
            t = np.where(over & (self.t0 - back < t - self.t1), self.t0, t)
        t = np.where(np.isfinite(t), t, self.t0)
        return np.clip(t, self.t0, self.t1)

    @property
    def length(self) -> float:
        """Length of the polyline."""
        return float(np.hypot(*np.diff(self.points, axis=0).T).sum())

    @property
    def geometry(self) -> LineString:
        """The polyline as a shapely LineString."""
        return LineString(self.points)

    @property
    def name(self) -> str:
        """Short label, e.g. ``"type 5 (vertex 3, edge 7)"``."""
        return f"type {self.type} (" + ", ".join(str(f) for f in self.features) + ")"


def check_length(L: object, what: str = "L") -> float:
    """Return ``L`` as a float or raise :class:`InvalidConfigError` unless a finite number > 0."""
    return positive(what, L)


def _check_map(world: object) -> Map:
    if not isinstance(world, Map):
        raise InvalidConfigError(f"map: expected an envs.maps.Map, got {type(world).__name__}")
    return world


# ------------------------------------------------------------------------ the clip
def _intervals(cand: Candidates) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Sub-intervals between consecutive breakpoints: (candidate, lo, hi), sorted."""
    live = np.flatnonzero(cand.t1 > cand.t0)
    bc, bt = cand.break_c, cand.break_t
    inside = np.isfinite(bt) & (bt > cand.t0[bc]) & (bt < cand.t1[bc])
    c = np.concatenate([live, live, bc[inside]])
    t = np.concatenate([cand.t0[live], cand.t1[live], bt[inside]])
    order = np.lexsort((t, c))
    c, t = c[order], t[order]
    if len(c) == 0:
        return c, t, t
    tol = 1e-12 * (np.abs(t) + (cand.t1 - cand.t0)[c] + 1.0)
    keep = np.concatenate([[True], (c[1:] != c[:-1]) | (np.diff(t) > tol[1:])])
    c, t = c[keep], t[keep]
    last = np.concatenate([c[1:] != c[:-1], [True]])
    t[last] = cand.t1[c[last]]  # each candidate's exact end
    same = c[1:] == c[:-1]
    return c[:-1][same], t[:-1][same], t[1:][same]


def _clip(world: Map, L: float, cand: Candidates) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Semi-free pieces ``(candidate, t_start, t_end)`` of every candidate."""
    ic, lo, hi = _intervals(cand)
    if len(ic) == 0:
        return ic, lo, hi
    ptr = np.searchsorted(cand.near_c, np.arange(len(cand) + 1))
    counts = ptr[ic + 1] - ptr[ic]
    ok = np.zeros(len(ic), dtype=bool)
    start = 0
    csum = np.cumsum(counts)
    while start < len(ic):
        base = csum[start - 1] if start else 0
        stop = int(np.searchsorted(csum, base + _PAIRS_PER_BATCH, side="right"))
        stop = max(stop, start + 1)
        sl = slice(start, stop)
        mid = 0.5 * (lo[sl] + hi[sl])
        k, d = cand.kind[ic[sl]], cand.data[ic[sl]]
        P = points(k, d, mid, L)
        th = orientation(k, d, mid, L)
        Q = P + L * np.stack([np.cos(th), np.sin(th)], axis=1)
        cnt = counts[sl]
        rod = np.repeat(np.arange(stop - start), cnt)
        first = np.repeat(ptr[ic[sl]], cnt)
        offs = np.arange(len(rod)) - np.repeat(np.cumsum(cnt) - cnt, cnt)
        edge = cand.near_e[first + offs]
        ok[sl] = rods_semifree_near(world, P, Q, rod, edge)
        start = stop
    # maximal runs of semi-free sub-intervals of one candidate
    prev_ok = np.concatenate([[False], ok[:-1] & (ic[1:] == ic[:-1])])
    next_ok = np.concatenate([ok[1:] & (ic[1:] == ic[:-1]), [False]])
    starts = np.flatnonzero(ok & ~prev_ok)
    ends = np.flatnonzero(ok & ~next_ok)
    return ic[starts], lo[starts], hi[ends]


# ------------------------------------------------------------------------ assembly
def _walls(world: Map) -> list[CriticalCurve]:
    out = []
    for e in range(world.n_edges):
        a, u = world.edge_start[e], world.edge_dir[e]
        ln = float(world.edge_length[e])
        pts = np.stack([world.edge_start[e], world.edge_end[e]])
        out.append(
            CriticalCurve(
                0,
                (Feature("edge", e),),
                "segment",
                (*a.tolist(), *u.tolist(), math.nan),
                0.0,
                ln,
                0.0,
                pts,
                0.0,
                np.array([0.0, ln]),
            )
        )
    return out


def critical_curves(
    map: Map, L: float, *, chord_tol: float | None = None, include_walls: bool = True
) -> tuple[CriticalCurve, ...]:
    """Every semi-free critical curve of types 0-5 for rod length ``L``.

    Args:
        map: the world.
        L: rod length (> 0).
        chord_tol: polyline tolerance of arcs and conchoids; default
            ``CHORD_TOL_REL * L``.
        include_walls: include the type-0 curves (the wall edges themselves).

    Returns:
        The curve pieces, walls first, then by type.

    Raises:
        InvalidConfigError: for a non-map or a bad ``L`` / ``chord_tol``.
    """
    world = _check_map(map)
    L = check_length(L)
    tol = CHORD_TOL_REL * L if chord_tol is None else check_length(chord_tol, "chord_tol")
    return _curves(world, L, tol, include_walls)


def _curves(world: Map, L: float, tol: float, include_walls: bool) -> tuple[CriticalCurve, ...]:
    eps = REL_LENGTH_TOL * world.scale
    cand = candidates(world, L, eps)
    ic, a, b = _clip(world, L, cand)
    order = np.lexsort((a, ic, cand.type[ic]))
    ic, a, b = ic[order], a[order], b[order]
    kind, data = cand.kind[ic], cand.data[ic]
    offsets, params = polyline_params(kind, data, a, b, L, tol)
    owner = np.repeat(np.arange(len(ic)), np.diff(offsets))
    pts = points(kind[owner], data[owner], params, L) if len(owner) else np.zeros((0, 2))
    seg_len = np.hypot(*np.diff(pts, axis=0).T) if len(pts) > 1 else np.zeros(0)
    inner = owner[1:] == owner[:-1] if len(owner) > 1 else np.zeros(0, dtype=bool)
    length = np.bincount(owner[1:][inner], weights=seg_len[inner], minlength=len(ic))
    min_len = 10 * eps
    out = _walls(world) if include_walls else []
    width = {SEGMENT: 5, 1: 3, 2: 6}
    for k in range(len(ic)):
        if length[k] <= min_len:
            continue
        sl = slice(offsets[k], offsets[k + 1])
        shape = int(kind[k])
        out.append(
            CriticalCurve(
                int(cand.type[ic[k]]),
                cand.features[ic[k]],
                SHAPE_NAMES[shape],
                tuple(float(x) for x in data[k, : width[shape]]),
                float(a[k]),
                float(b[k]),
                L,
                pts[sl],
                0.0 if shape == SEGMENT else tol,
                params[sl],
            )
        )
    return tuple(out)
