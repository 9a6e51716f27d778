"""Guaranteed escape plans from the escapable-cell fixed point (Sec. 4, conditions (a)/(b)).

Every escapable cell (here a node of the cspace grid graph: a grid point and one free arc
at L) became escapable at some round of the least fixed point: round 0 by condition (a)
(some neighbouring point has no free arc overlapping it), round r by condition (b) (at
some neighbouring point every overlapping arc became escapable before round r). The
neighbouring point responsible is the node's *witness*. An evader in an escapable node
steps to its witness; whatever orientation the pursuer then picks among the overlapping
arcs, the new node has a smaller rank, and at rank 0 the step leaves no free
continuation: surveillance breaks (Sec. 4: "a guaranteed escape path").

Where some point carries only escapable nodes (Prop. 2, the *witness region*), an evader
in a safe node first walks there; :attr:`EscapePlan.region_next` gives the next grid
point on a shortest walk.
"""

from __future__ import annotations

import functools
import hashlib
import math
import os
from collections import deque
from dataclasses import dataclass

import numpy as np

from envs.maps import Map
from strategies.policies.safety import cache_dir, cspace_graph

__all__ = ["EscapePlan", "escape_plan"]

PLAN_VERSION = 1


@dataclass(frozen=True, eq=False)
class EscapePlan:
    """Ranks and witnesses of the escapable nodes of a cspace grid graph.

    Attributes:
        points: (n, 2) grid points (the rows of the matching ``SafetyTable``).
        node_ptr: (n + 1,) nodes of point i are ``node_ptr[i]:node_ptr[i + 1]``.
        node_lo, node_hi: (N,) each node's free arc ``[lo, hi]``.
        rank: (N,) round of the fixed point at which the node became escapable, -1 if safe.
        witness: (N,) neighbouring grid point to step to, -1 if safe.
        region_next: (n,) next grid point toward the nearest all-escapable point (-1 where
            none is reachable or the point is in the region).
        region: (n,) bool, every node at the point is escapable (Prop. 2).
    """

    points: np.ndarray
    node_ptr: np.ndarray
    node_lo: np.ndarray
    node_hi: np.ndarray
    rank: np.ndarray
    witness: np.ndarray
    region_next: np.ndarray
    region: np.ndarray

    def node_at(self, row: int, theta: float) -> int:
        """The node of grid point ``row`` whose arc contains ``theta`` (else the nearest)."""
        lo = self.node_lo[self.node_ptr[row] : self.node_ptr[row + 1]]
        hi = self.node_hi[self.node_ptr[row] : self.node_ptr[row + 1]]
        if lo.size == 0:
            return -1
        d = (theta - lo) % (2.0 * math.pi)
        inside = d <= hi - lo
        if inside.any():
            return int(self.node_ptr[row] + np.argmax(inside))
        gap = np.minimum(d - (hi - lo), 2.0 * math.pi - d)
        return int(self.node_ptr[row] + np.argmin(gap))


def _ranks(g) -> tuple[np.ndarray, np.ndarray]:
    """Least fixed point of (a)/(b) by rounds, recording each node's rank and witness."""
    edges, ptr = g.point_edges, g.node_ptr
    m = len(edges)
    src = np.concatenate([edges[:, 0], edges[:, 1]])
    dst = np.concatenate([edges[:, 1], edges[:, 0]])
    # one group per (node a at src, directed step): counts non-escapable overlaps at dst
    cnt = ptr[src + 1] - ptr[src]
    gstart = np.cumsum(cnt) - cnt
    total = int(cnt.sum())
    group_dst = np.repeat(dst, cnt)
    group_node = np.arange(total) - np.repeat(gstart, cnt) + np.repeat(ptr[src], cnt)
    a, b, e = g.overlap[:, 0], g.overlap[:, 1], g.overlap[:, 2]
    near = np.concatenate([a, b])
    far = np.concatenate([b, a])
    step = np.concatenate([e, e + m])
    pair_group = gstart[step] + (near - ptr[src[step]])
    count = np.bincount(pair_group, minlength=total)
    rank = np.full(g.n_nodes, -1, dtype=np.int64)
    witness = np.full(g.n_nodes, -1, dtype=np.int64)
    order = np.argsort(far, kind="stable")
    far_ptr = np.searchsorted(far[order], np.arange(g.n_nodes + 1))
    sorted_group = pair_group[order]
    done = np.flatnonzero(count == 0)
    r = 0
    while done.size:
        nodes = group_node[done]
        fresh = rank[nodes] < 0
        nodes, groups = nodes[fresh], done[fresh]
        nodes, first = np.unique(nodes, return_index=True)
        rank[nodes] = r
        witness[nodes] = group_dst[groups[first]]
        if not nodes.size:
            break
        lens = far_ptr[nodes + 1] - far_ptr[nodes]
        idx = np.arange(int(lens.sum())) - np.repeat(np.cumsum(lens) - lens, lens)
        idx += np.repeat(far_ptr[nodes], lens)
        hit = sorted_group[idx]
        np.subtract.at(count, hit, 1)
        done = np.unique(hit[count[hit] == 0])
        r += 1
    return rank, witness


def _region_next(g, region: np.ndarray) -> np.ndarray:
    """Next hop on a shortest grid walk to the region (breadth first from the region)."""
    n = g.n_points
    adj: list[list[int]] = [[] for _ in range(n)]
    for p, q in g.point_edges:
        adj[int(p)].append(int(q))
        adj[int(q)].append(int(p))
    nxt = np.full(n, -1, dtype=np.int64)
    seen = region.copy()
    queue = deque(int(i) for i in np.flatnonzero(region))
    while queue:
        u = queue.popleft()
        for v in adj[u]:
            if not seen[v]:
                seen[v] = True
                nxt[v] = u
                queue.append(v)
    return nxt


_FIELDS = ("points", "node_ptr", "node_lo", "node_hi", "rank", "witness", "region_next", "region")


@functools.lru_cache(maxsize=8)
def escape_plan(world: Map, L: float, resolution: float = 0.1) -> EscapePlan:
    """The :class:`EscapePlan` of ``world`` for a rod of length ``L`` (cached, also on disk)."""
    key = hashlib.sha256(f"{PLAN_VERSION}|{world.digest}|{L!r}|{resolution!r}".encode())
    path = cache_dir() / f"plan_{key.hexdigest()[:24]}.npz"
    if path.exists():
        try:
            with np.load(path) as z:
                return EscapePlan(**{k: z[k] for k in _FIELDS})
        except (OSError, KeyError, ValueError):
            pass  # a damaged cache file: rebuild it
    g = cspace_graph(world, L, resolution)
    rank, witness = _ranks(g)
    escapable = rank >= 0
    region = np.bincount(g.node_point[~escapable], minlength=g.n_points) == 0
    plan = EscapePlan(
        points=g.points,
        node_ptr=g.node_ptr,
        node_lo=g.node_lo,
        node_hi=g.node_hi,
        rank=rank,
        witness=witness,
        region_next=_region_next(g, region),
        region=region,
    )
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_suffix(f".{os.getpid()}.tmp.npz")
        np.savez_compressed(tmp, **{k: getattr(plan, k) for k in _FIELDS})
        os.replace(tmp, path)
    except OSError:
        pass  # read-only cache directory: keep the plan in memory only
    return plan
