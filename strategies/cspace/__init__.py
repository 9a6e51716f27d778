"""Configuration space of the surveillance problem (Secs. 3-4).

* :func:`critical_curves`: the semi-free critical curves of types 0-5 for a rod length L;
* :func:`decompose`: the cylindrical decomposition K_L with its regions, cells, the
  connectivity graph G_L and the escapable cells (Prop. 2 verdict, point queries);
* :func:`critical_lengths`, :func:`stratified_graph`, :func:`surveillance_verdict`: variable
  L (Prop. 1, Sec. 3's graph G, Prop. 4);
* :func:`draw_decomposition`: the picture (the paper's Figs. 3, 5-8);
* :mod:`strategies.cspace.grids`: regular grids of evader positions over a free region.

The independent grid computation of the verdict that the tests compare against lives
with the tests (``tests/oracles/grid_oracle.py``).
"""

from strategies.cspace.curves import CHORD_TOL_REL, TYPE_NAMES, CriticalCurve, critical_curves
from strategies.cspace.decomposition import (
    Boundary,
    Cell,
    CellArc,
    Decomposition,
    Region,
    decompose,
)
from strategies.cspace.draw import draw_decomposition
from strategies.cspace.stratified import (
    StratifiedGraph,
    SurveillanceVerdict,
    candidate_lengths,
    critical_lengths,
    first_sample_length,
    graph_signature,
    stratified_graph,
    surveillance_verdict,
)

__all__ = [
    "CHORD_TOL_REL",
    "TYPE_NAMES",
    "Boundary",
    "Cell",
    "CellArc",
    "CriticalCurve",
    "Decomposition",
    "Region",
    "StratifiedGraph",
    "SurveillanceVerdict",
    "candidate_lengths",
    "critical_curves",
    "critical_lengths",
    "decompose",
    "draw_decomposition",
    "first_sample_length",
    "graph_signature",
    "stratified_graph",
    "surveillance_verdict",
]
