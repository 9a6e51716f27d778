"""The geometry kernel: exact, shapely-free polygon geometry for the surveillance world.

Everything the env does per step (line of sight, the continuous-time sweep over a step,
lidar) and what the configuration-space theory asks at many points (free orientation
arcs with their stops, THEORY.md 1.3) lives here, precomputed once per
:class:`~envs.maps.Map`. Get the kernel of a map with :func:`kernel_for`.

Conventions: the evader is E, the pursuer P = E + L (cos theta, sin theta), the rod the
segment E-P (one meaning per letter, as in the env, the policies and the README; THEORY.md
section 0 follows the paper and writes the evader's point as P and the pursuer as Q).
Lower-case p, q name the two ends of any segment, whatever stands there.

Semantics, with one length tolerance ``eps = REL_LENGTH_TOL * map.scale``:

* :meth:`Kernel.line_of_sight` -- the open segment touches no wall. Crossing an edge,
  touching any wall vertex (within ``eps``), or running along an edge blocks; an end
  resting on a wall does not, if the segment leaves it into free space.
* :meth:`Kernel.sweep` -- the first ``t`` in [0, 1] at which, with both bodies moving
  linearly, the distance leaves ``[l_min, l_max]`` or the rod touches a convex obstacle
  vertex (including a vertex passed between two clear frames, and a tangent graze).
* :meth:`Kernel.free_arcs` -- closed arcs of semi-free orientations (the rod may touch a
  wall at the arc's ends, or at an isolated tangency inside it). Zero-width arcs are
  dropped. E on a wall blocks the obstacle side (stops ``("body", edge)``); E outside
  free space has no arc.
* :meth:`Kernel.ray_distances` -- lidar; a ray counts walls met from their free side.

Performance: a bucket grid finds the few walls near a query and plain Python tests
them (numpy when there are many), so a call costs about the same on a 12-edge and a
600-edge map; see ``benchmarks/geometry_kernel.py``.
"""

from envs.geometry.kernel import Kernel, kernel_for
from envs.geometry.types import Arc, FreeArcs, Stop, SweepEvent, wrap_angle

__all__ = ["Arc", "FreeArcs", "Kernel", "Stop", "SweepEvent", "kernel_for", "wrap_angle"]
