"""Collinear overlapping segments become shared pieces (walls and critical lines alike).

Several critical curves can lie on one line: the extension of an edge (type 4) along a
collinear edge of another obstacle (a wall, type 0) and the line through both corners
(type 3); a type-1 line on a wall exactly L away. The arrangement must see such overlaps
as one curve, or it would node two copies of a segment against each other. Overlapping
collinear segments are grouped; each group's line is split at every member's ends into
elementary pieces, each carrying the set of members that cover it. A piece covered by a
wall *is* a wall (one side is an obstacle).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import shapely
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

__all__ = ["Lines", "merge_collinear"]


@dataclass
class Lines:
    """Segments after merging overlaps (one row per elementary piece).

    Attributes:
        o, d: (m, 2) line origin and unit direction; the piece is ``o + t d``, ``t`` in
            ``[t0, t1]``.
        t0, t1: (m,) parameter range.
        sources: per piece, the input segments covering it.
        wall_sign: (m,) 0 if no wall covers the piece, +1 if a wall covers it with free
            space on the left of ``d``, -1 if on the right.
        group: (m,) collinear group id (-1 for a segment that overlaps nothing).
    """

    o: np.ndarray
    d: np.ndarray
    t0: np.ndarray
    t1: np.ndarray
    sources: list[tuple[int, ...]]
    wall_sign: np.ndarray
    group: np.ndarray


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def merge_collinear(
    o: np.ndarray,
    d: np.ndarray,
    t0: np.ndarray,
    t1: np.ndarray,
    is_wall: np.ndarray,
    tol: float,
) -> Lines:
    """Merge overlapping collinear segments ``o + t d``, ``t`` in ``[t0, t1]``.

    Args:
        o, d, t0, t1: the segments (``d`` unit; walls run with free space on their left).
        is_wall: (n,) which segments are walls.
        tol: distance below which points coincide (the arrangement's merge tolerance).

    Returns:
        The :class:`Lines`; pieces of segments that overlap nothing keep their row order
        first, then the groups' pieces.
    """
    n = len(o)
    a = o + t0[:, None] * d
    b = o + t1[:, None] * d
    length = t1 - t0
    group = np.full(n, -1)
    if n > 1:
        tree = shapely.STRtree(shapely.linestrings(np.stack([a, b], axis=1)))
        i, j = tree.query(shapely.linestrings(np.stack([a, b], axis=1)), "dwithin", tol)
        keep = i < j
        i, j = i[keep], j[keep]
        # the shorter of each pair lies on the longer's line and overlaps it
        longer = np.where(length[i] >= length[j], i, j)
        short = np.where(length[i] >= length[j], j, i)
        dl, ol = d[longer], o[longer]
        off_a = np.abs(_cross(dl, a[short] - ol))
        off_b = np.abs(_cross(dl, b[short] - ol))
        pa = ((a[short] - ol) * dl).sum(axis=1)
        pb = ((b[short] - ol) * dl).sum(axis=1)
        lo = np.maximum(np.minimum(pa, pb), t0[longer])
        hi = np.minimum(np.maximum(pa, pb), t1[longer])
        same = (off_a <= tol) & (off_b <= tol) & (hi - lo > tol)
        i, j = i[same], j[same]
        if len(i):
            g = coo_matrix((np.ones(len(i)), (i, j)), shape=(n, n))
            _, lab = connected_components(g, directed=False)
            members = np.bincount(lab, minlength=lab.max() + 1)
            grouped = members[lab] > 1
            group[grouped] = lab[grouped]
    alone = np.flatnonzero(group < 0)
    out_o, out_d, out_t0, out_t1 = [o[alone]], [d[alone]], [t0[alone]], [t1[alone]]
    sources: list[tuple[int, ...]] = [(int(k),) for k in alone]
    wall_sign = [np.where(is_wall[alone], 1, 0)]
    out_group = [np.full(len(alone), -1)]
    for gid in np.unique(group[group >= 0]).tolist():
        mem = np.flatnonzero(group == gid)
        walls = mem[is_wall[mem]]
        ref = int(walls[np.argmax(length[walls])] if len(walls) else mem[np.argmax(length[mem])])
        ro, rd = o[ref], d[ref]
        pa = (a[mem] - ro) @ rd
        pb = (b[mem] - ro) @ rd
        lo, hi = np.minimum(pa, pb), np.maximum(pa, pb)
        cuts = np.sort(np.concatenate([lo, hi]))
        cuts = cuts[np.concatenate([[True], np.diff(cuts) > tol])]
        for x0, x1 in zip(cuts[:-1].tolist(), cuts[1:].tolist(), strict=True):
            cover = (lo <= x0 + tol) & (hi >= x1 - tol)
            if not cover.any():
                continue
            cov = mem[cover]
            w = cov[is_wall[cov]]
            sign = 0 if len(w) == 0 else (1 if float(d[w[0]] @ rd) > 0 else -1)
            out_o.append(ro[None])
            out_d.append(rd[None])
            out_t0.append(np.array([x0]))
            out_t1.append(np.array([x1]))
            sources.append(tuple(int(k) for k in cov))
            wall_sign.append(np.array([sign]))
            out_group.append(np.array([gid]))
    return Lines(
        o=np.concatenate(out_o),
        d=np.concatenate(out_d),
        t0=np.concatenate(out_t0),
        t1=np.concatenate(out_t1),
        sources=sources,
        wall_sign=np.concatenate(wall_sign).astype(np.int8),
        group=np.concatenate(out_group),
    )
