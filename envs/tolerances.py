"""Named numerical tolerances, one place for all of them.

Lengths are relative to a map's scale (its bounding-box diagonal) unless a name says
otherwise, so that translating or uniformly scaling a world changes no answer.
"""

from __future__ import annotations

REL_LENGTH_TOL = 1e-9
"""Relative length below which two points coincide and a polygon edge is degenerate."""

REL_GAP_TOL = 1e-7
"""Relative gap below which two obstacles (or an obstacle and the boundary) *touch*.

Touching polygons are where visibility code goes wrong (a zero-width slit between two
obstacles lets a segment through in one library and not in another), so a
:class:`~envs.maps.Map` rejects them unless built with ``merge=True``, which replaces
touching or overlapping obstacles by their union.
"""

COLLINEAR_TOL = 1e-10
"""|sin| of the turn angle below which a polygon vertex is straight and dropped."""

ANGLE_TOL = 1e-12
"""Angles (radians) closer than this are equal in arc arithmetic."""
