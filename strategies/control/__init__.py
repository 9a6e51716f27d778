"""Theory of Secs. 5-7 of the paper: rod kinematics, optimal evasion, cooperative motion.

Pure numpy/scipy: no environment, no physics. Equations cite the paper and the errata
numbers E1-E8 of ``THEORY.md``.
"""

from __future__ import annotations

from strategies.control.cooperative import (
    Tractrix,
    corner_feasible,
    corner_min_distance,
    corner_pursuer_position,
    corner_pursuer_velocity,
    corner_required_speed,
    straight_leader_time,
    tractrix,
    tractrix_numeric,
    wall_follow_feasible,
    wall_follow_max_speed,
    wall_follow_speed,
    wall_follow_theta_dot,
)
from strategies.control.evasion import (
    EscapeSolution,
    GreedyHeading,
    ShootResult,
    default_step,
    greedy_heading,
    shoot,
    solve_escape,
)
from strategies.control.hamiltonian import (
    HamiltonianMinimum,
    hamiltonian,
    is_unbounded,
    minimise_hamiltonian,
)
from strategies.control.kinematics import (
    MinMaxHeading,
    PursuerCommand,
    escape_trivial,
    max_abs_theta_dot,
    min_max_theta_dot,
    pursuer_velocity,
    pursuer_velocity_holding_range,
    theta_dot,
    theta_dot_feasible,
    theta_dot_from_velocities,
)
from strategies.control.targets import (
    EscapeTarget,
    critical_curve_escape_target,
    from_evader_frame,
    to_evader_frame,
    vertex_escape_target,
)

__all__ = [
    "EscapeSolution",
    "EscapeTarget",
    "GreedyHeading",
    "HamiltonianMinimum",
    "MinMaxHeading",
    "PursuerCommand",
    "ShootResult",
    "Tractrix",
    "corner_feasible",
    "corner_min_distance",
    "corner_pursuer_position",
    "corner_pursuer_velocity",
    "corner_required_speed",
    "critical_curve_escape_target",
    "default_step",
    "escape_trivial",
    "from_evader_frame",
    "greedy_heading",
    "hamiltonian",
    "is_unbounded",
    "max_abs_theta_dot",
    "min_max_theta_dot",
    "minimise_hamiltonian",
    "pursuer_velocity",
    "pursuer_velocity_holding_range",
    "shoot",
    "solve_escape",
    "straight_leader_time",
    "theta_dot",
    "theta_dot_feasible",
    "theta_dot_from_velocities",
    "to_evader_frame",
    "tractrix",
    "tractrix_numeric",
    "vertex_escape_target",
    "wall_follow_feasible",
    "wall_follow_max_speed",
    "wall_follow_speed",
    "wall_follow_theta_dot",
]
