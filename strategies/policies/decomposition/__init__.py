"""The decomposition-based pursuer (Secs. 4-5), in modules named for what they hold.

- :mod:`~strategies.policies.decomposition.pursuer`: :class:`DecompositionPursuer`, its
  parameters, its setup per map and its decision (the overview of the policy).
- :mod:`~strategies.policies.decomposition.values`: the orientation values (eqs. 2-3)
  from the safety table and the target in the rod's free arc (:func:`reachable_steps`,
  :func:`crossable_steps`).
- :mod:`~strategies.policies.decomposition.corners`: the probes round the corners an
  evader rounds, and the lead on a lap round a small obstacle.
- :mod:`~strategies.policies.decomposition.clearance`: wall distances and the way to
  room on the table's grid.
- :mod:`~strategies.policies.decomposition.orbit`: orbit keeping against a charge.
- :mod:`~strategies.policies.decomposition.walls`: the wall and slide checks.
- :mod:`~strategies.policies.decomposition.charge`: the charge test and the other
  readings of the evader's motion.

The names imported from ``strategies.policies.decomposition`` before the split are
importable from here still.
"""

from strategies.policies.decomposition.clearance import _clearance_grid as _clearance_grid
from strategies.policies.decomposition.clearance import _room_field as _room_field
from strategies.policies.decomposition.pursuer import DecompositionPursuer
from strategies.policies.decomposition.values import crossable_steps, reachable_steps
from strategies.policies.decomposition.walls import _slide_floor as _slide_floor

__all__ = ["DecompositionPursuer", "crossable_steps", "reachable_steps"]
