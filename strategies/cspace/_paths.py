"""Shortest evader paths in the closed free region (visibility graph over convex vertices)."""

from __future__ import annotations

import networkx as nx
import numpy as np

from envs.maps.map import Map
from strategies.cspace._rod import rods_semifree

__all__ = ["shortest_path"]


def shortest_path(world: Map, start: np.ndarray, goal: np.ndarray) -> np.ndarray:
    """The shortest path from ``start`` to ``goal`` in the closed free region.

    A shortest path among polygons bends only at convex obstacle vertices, so it is a
    shortest path in the visibility graph of ``{start, goal} + convex vertices``, whose
    edges are the segments lying in the closed free region (touching walls allowed).

    Args:
        world: the map.
        start: (2,) a point of the free region.
        goal: (2,) a point of the free region.

    Returns:
        (k, 2) the path's vertices from ``start`` to ``goal``.
    """
    nodes = np.vstack([start, goal, world.vertices[world.convex_vertices]])
    i, j = np.triu_indices(len(nodes), k=1)
    ok = rods_semifree(world, nodes[i], nodes[j])
    g = nx.Graph()
    g.add_nodes_from(range(len(nodes)))
    w = np.hypot(*(nodes[j] - nodes[i]).T)
    g.add_weighted_edges_from(zip(i[ok].tolist(), j[ok].tolist(), w[ok].tolist(), strict=True))
    route = nx.shortest_path(g, 0, 1, weight="weight")
    return nodes[route]
