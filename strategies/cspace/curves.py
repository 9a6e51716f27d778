"""Semi-free critical curves of types 0-5 for a rod of fixed length L (THEORY.md 1.2).

:func:`critical_curves` builds every candidate of :mod:`strategies.cspace._candidates`,
keeps the parts where the contact configuration is semi-free (the rod touches the
defining features and lies in the closed free region,
:func:`~strategies.cspace._rod.rods_semifree`),
and returns them as :class:`CriticalCurve` pieces with their exact geometry and a polyline.

Geometry: segments (types 0, 1, 3, 4) are exact; arcs (type 2) and conchoids (type 5)
carry a polyline whose vertices lie on the exact curve and whose chords stay within
``tolerance`` of it (:data:`CHORD_TOL_REL` times L by default).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from shapely.geometry import LineString

from envs.errors import InvalidConfigError
from envs.maps.map import Feature, Map
from envs.tolerances import REL_LENGTH_TOL
from strategies.cspace._candidates import _Cand, candidates, evaluate
from strategies.cspace._rod import rods_semifree

__all__ = ["CHORD_TOL_REL", "TYPE_NAMES", "CriticalCurve", "check_length", "critical_curves"]

CHORD_TOL_REL = 1e-4
"""Default polyline tolerance of arcs and conchoids, relative to the rod length L."""

TYPE_NAMES = {
    0: "wall (P on the boundary)",
    1: "tip on an edge, rod perpendicular",
    2: "tip at a vertex",
    3: "body on two convex vertices",
    4: "rod along an edge, body on its convex end",
    5: "body on a convex vertex, tip on an edge (conchoid)",
}
"""One-line description of each critical-curve type (THEORY.md 1.2)."""

_BISECT_STEPS = 52  # halvings of a grid cell: down to the double-precision floor


@dataclass(frozen=True, eq=False)
class CriticalCurve:
    """One semi-free piece of a critical curve.

    Attributes:
        type: 0-5 (THEORY.md 1.2).
        features: the wall features that define it (edge; vertex; two vertices;
            vertex and edge; vertex and edge).
        shape: ``"segment"``, ``"arc"`` or ``"conchoid"``.
        data: the exact parameters of the shape (see :mod:`strategies.cspace._candidates`).
        t0, t1: the piece's parameter interval.
        L: rod length.
        points: (m, 2) polyline; its vertices lie on the exact curve.
        tolerance: bound on the distance between the polyline and the exact curve (0 for
            segments).
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

    def evaluate(self, t: np.ndarray | float) -> tuple[np.ndarray, np.ndarray]:
        """Evader positions P (k, 2) and contact orientations theta (k,) at parameters t.

        For type 0 (a wall) theta is NaN: no rod contact defines it.
        """
        P, theta = evaluate(self.shape, np.asarray(self.data), np.atleast_1d(t), self.L)
        if self.type == 0:
            theta = np.full(len(theta), np.nan)
        return P, theta

    def project(self, points: np.ndarray) -> np.ndarray:
        """Parameters of the exact curve points nearest to ``points``.

        For conchoids: the point in line with ``points`` and the vertex.
        """
        p = np.atleast_2d(np.asarray(points, dtype=float))
        d = np.asarray(self.data)
        if self.shape == "segment":
            t = (p - d[0:2]) @ d[2:4]
        elif self.shape == "arc":
            ang = np.arctan2(p[:, 1] - d[1], p[:, 0] - d[0])
            t = self.t0 + (ang - self.t0) % (2 * math.pi)
            over = t > self.t1
            back = t - 2 * math.pi
            t = np.where(over & (self.t0 - back < t - self.t1), self.t0, t)
        else:  # conchoid: the tip Q where the line from p through v meets the edge
            v, a, u = d[0:2], d[2:4], d[4:6]
            w = v - p
            den = w[:, 0] * u[1] - w[:, 1] * u[0]
            num = (a - p)[:, 0] * w[:, 1] - (a - p)[:, 1] * w[:, 0]
            with np.errstate(divide="ignore", invalid="ignore"):
                t = np.where(np.abs(den) > 1e-300, num / den, self.t0)
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


def check_length(L: float, what: str = "L") -> float:
    """Return ``L`` as a float or raise :class:`InvalidConfigError` unless finite and > 0."""
    try:
        v = float(L)
    except (TypeError, ValueError) as exc:
        raise InvalidConfigError(
            f"{what}: expected a rod length (a number > 0), got {L!r}"
        ) from exc
    if not math.isfinite(v) or v <= 0:
        raise InvalidConfigError(f"{what}: expected a finite rod length > 0, got {L!r}")
    return v


def _check_map(world: object) -> Map:
    if not isinstance(world, Map):
        raise InvalidConfigError(f"map: expected an envs.maps.Map, got {type(world).__name__}")
    return world


# ------------------------------------------------------------------------ the clip
def _semifree(
    world: Map, L: float, cands: list[_Cand], idx: np.ndarray, t: np.ndarray
) -> np.ndarray:
    """Semi-free test of candidate ``idx[k]`` at parameter ``t[k]``, vectorised by shape."""
    out = np.zeros(len(t), dtype=bool)
    for shape in ("segment", "arc", "conchoid"):
        sel = np.flatnonzero(np.array([cands[i].shape == shape for i in idx], dtype=bool))
        if len(sel) == 0:
            continue
        data = np.array([cands[i].data for i in idx[sel]])
        P, theta = evaluate(shape, data, t[sel], L)
        Q = P + L * np.stack([np.cos(theta), np.sin(theta)], axis=1)
        out[sel] = rods_semifree(world, P, Q)
    return out


def _clip(world: Map, L: float, cands: list[_Cand]) -> list[tuple[_Cand, float, float]]:
    """Semi-free parameter intervals of every candidate."""
    xs_all, exact_all = [], []
    mid_idx, mid_t = [], []
    for i, c in enumerate(cands):
        span = c.t1 - c.t0
        if span <= 0:
            xs_all.append(np.zeros(0))
            exact_all.append(np.zeros(0, dtype=bool))
            continue
        b = c.breaks[(c.breaks > c.t0) & (c.breaks < c.t1)]
        grid = np.linspace(c.t0, c.t1, c.grid + 2)[1:-1] if c.grid else np.zeros(0)
        xs = np.concatenate([[c.t0, c.t1], b, grid])
        exact = np.concatenate([np.ones(2 + len(b), dtype=bool), np.zeros(len(grid), dtype=bool)])
        order = np.lexsort((~exact, xs))
        xs, exact = xs[order], exact[order]
        keep = np.concatenate([[True], np.diff(xs) > 1e-12 * max(span, 1.0)])
        xs, exact = xs[keep], exact[keep]
        xs_all.append(xs)
        exact_all.append(exact)
        mid_idx.append(np.full(len(xs) - 1, i))
        mid_t.append(0.5 * (xs[:-1] + xs[1:]))
    if not mid_t:
        return []
    midx = np.concatenate(mid_idx)
    mt = np.concatenate(mid_t)
    ok = _semifree(world, L, cands, midx, mt)
    # split per candidate, find runs, collect ends that need bisection
    pieces: list[list] = []
    tasks: list[tuple[int, int, float, float]] = []  # (piece, end 0/1, true t, false t)
    pos = 0
    for i, xs in enumerate(xs_all):
        m = len(xs) - 1
        if m <= 0:
            continue
        flags = ok[pos : pos + m]
        mids = mt[pos : pos + m]
        pos += m
        exact = exact_all[i]
        k = 0
        while k < m:
            if not flags[k]:
                k += 1
                continue
            j = k
            while j + 1 < m and flags[j + 1]:
                j += 1
            piece = [i, xs[k], xs[j + 1]]
            pieces.append(piece)
            if not exact[k]:
                tasks.append((len(pieces) - 1, 1, mids[k], mids[k - 1]))
            if not exact[j + 1]:
                tasks.append((len(pieces) - 1, 2, mids[j], mids[j + 1]))
            k = j + 1
    if tasks:
        pidx = np.array([pieces[p][0] for p, *_ in tasks])
        good = np.array([t[2] for t in tasks])
        bad = np.array([t[3] for t in tasks])
        for _ in range(_BISECT_STEPS):
            mid = 0.5 * (good + bad)
            f = _semifree(world, L, cands, pidx, mid)
            good = np.where(f, mid, good)
            bad = np.where(f, bad, mid)
        for (p, end, *_), g in zip(tasks, good.tolist(), strict=True):
            pieces[p][end] = g
    return [(cands[i], a, b) for i, a, b in pieces if b > a]


# ------------------------------------------------------------------------ polylines
def _polyline(c: _Cand, a: float, b: float, L: float, tol: float) -> np.ndarray:
    if c.shape == "segment":
        P, _ = evaluate(c.shape, np.asarray(c.data), np.array([a, b]), L)
        return P
    if c.shape == "arc":
        R = c.data[2]
        step = 2.0 * math.acos(max(-1.0, 1.0 - tol / R)) if tol < 2 * R else math.pi
        n = max(1, math.ceil((b - a) / step))
        t = np.linspace(a, b, n + 1)
        sp = [s for s in c.specials if a < s < b]
        if sp:
            t = np.unique(np.concatenate([t, sp]))
        return evaluate(c.shape, np.asarray(c.data), t, L)[0]
    # conchoid: adaptive subdivision until each chord's midpoint deviation is <= tol
    data = np.asarray(c.data)
    t = np.linspace(a, b, 9)
    for _ in range(30):
        P, _ = evaluate(c.shape, data, t, L)
        tm = 0.5 * (t[:-1] + t[1:])
        Pm, _ = evaluate(c.shape, data, tm, L)
        chord = 0.5 * (P[:-1] + P[1:])
        dev = np.hypot(*(Pm - chord).T)
        bad = dev > 0.25 * tol
        if not bad.any():
            break
        t = np.sort(np.concatenate([t, tm[bad]]))
    return evaluate(c.shape, data, t, L)[0]


def _walls(world: Map) -> list[CriticalCurve]:
    out = []
    for e in range(world.n_edges):
        a, u = world.edge_start[e], world.edge_dir[e]
        ln = float(world.edge_length[e])
        pts = np.stack([world.edge_start[e], world.edge_end[e]])
        out.append(
            CriticalCurve(
                0, (Feature("edge", e),), "segment", (*a, *u, math.nan), 0.0, ln, 0.0, pts
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
    cands = candidates(world, L)
    min_len = 10 * REL_LENGTH_TOL * world.scale
    out = _walls(world) if include_walls else []
    for c, a, b in sorted(_clip(world, L, cands), key=lambda x: x[0].type):
        pts = _polyline(c, a, b, L, tol)
        if float(np.hypot(*np.diff(pts, axis=0).T).sum()) <= min_len:
            continue
        out.append(
            CriticalCurve(
                c.type,
                c.features,
                c.shape,
                tuple(float(x) for x in c.data),
                float(a),
                float(b),
                L,
                pts,
                0.0 if c.shape == "segment" else tol,
            )
        )
    return tuple(out)
