"""Configuration space of the surveillance problem (Secs. 3-4).

* :func:`critical_curves`: the semi-free critical curves of types 0-5 for a rod length L;
* :func:`decompose`: the cylindrical decomposition K_L with its regions, cells, the
  connectivity graph G_L and the escapable cells (Prop. 2 verdict, point queries);
* :func:`draw_decomposition`: the picture (the paper's Figs. 3, 5-8);
* :mod:`strategies.cspace.grid_oracle`: an independent grid computation of the verdict.
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

__all__ = [
    "CHORD_TOL_REL",
    "TYPE_NAMES",
    "Boundary",
    "Cell",
    "CellArc",
    "CriticalCurve",
    "Decomposition",
    "Region",
    "critical_curves",
    "decompose",
    "draw_decomposition",
]
