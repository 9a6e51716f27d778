"""The shooting-based evader (Secs. 4-6), in modules named for what they hold.

- :mod:`~strategies.policies.shooting.evader`: :class:`ShootingEvader`, its parameters,
  its setup per map and its decision (the overview of the policy).
- :mod:`~strategies.policies.shooting.plan`: the walk along a guaranteed escape plan.
- :mod:`~strategies.policies.shooting.shots`: the candidate endpoints of a shot and their
  escape margins (Fig. 13, eq. 6).
- :mod:`~strategies.policies.shooting.arcs`: the optimal escape arc (Sec. 6) or straight
  path a shot follows.
- :mod:`~strategies.policies.shooting.fallback`: the witness-region walk, the fallback's
  stall, the herd into a concave corner and the wall tests of the pressure.

The names imported from ``strategies.policies.shooting`` before the split are importable
from here still.
"""

from strategies.policies.shooting.arcs import _arc_lengths as _arc_lengths
from strategies.policies.shooting.arcs import _row_norms as _row_norms
from strategies.policies.shooting.evader import ShootingEvader
from strategies.policies.shooting.fallback import herd_corners as herd_corners
from strategies.policies.shooting.shots import _most_turn as _most_turn

__all__ = ["ShootingEvader"]
