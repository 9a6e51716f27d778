"""The geometry kernel: exact, numpy-only polygon geometry for the surveillance world.

Everything the env does per step (line of sight, the continuous-time sweep over a step,
lidar) and what the configuration-space theory asks at many points (free orientation
arcs with their stops, THEORY.md 1.3) lives here, precomputed once per
:class:`~envs.maps.Map`. Get the kernel of a map with :func:`kernel_for`.
"""

from envs.geometry.kernel import Kernel, kernel_for
from envs.geometry.types import Arc, FreeArcs, Stop, SweepEvent, wrap_angle

__all__ = ["Arc", "FreeArcs", "Kernel", "Stop", "SweepEvent", "kernel_for", "wrap_angle"]
