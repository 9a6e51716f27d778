"""The registered policies: every name :func:`make_policy` knows.

Importing this module registers them; :mod:`strategies.policies.registry` imports it
lazily on first use.
"""

from __future__ import annotations

from strategies.policies.baselines import (
    GreedyPursuer,
    OrbitEvader,
    RandomPolicy,
    StraightLineEvader,
    TowardAwayEvader,
    WallHuggingEvader,
)
from strategies.policies.cooperative import (
    CornerRoundingPursuer,
    TractrixFollower,
    WallFollowingPursuer,
)
from strategies.policies.decomposition import DecompositionPursuer
from strategies.policies.registry import register_policy
from strategies.policies.shooting import ShootingEvader
from strategies.referee.policy import RefereeEvader, RefereePursuer

register_policy("pursuer/random", RandomPolicy, "uniform random velocity (baseline)")
register_policy("evader/random", RandomPolicy, "uniform random velocity (baseline)")
register_policy(
    "pursuer/greedy",
    GreedyPursuer,
    "keeps the evader at L_min moving along the line of sight; no map knowledge",
)
register_policy(
    "evader/straight",
    StraightLineEvader,
    "full speed on a straight line, new random heading when a wall blocks it",
)
register_policy(
    "evader/toward_away",
    TowardAwayEvader,
    "straight toward or away from the pursuer: minimises max |theta_dot| (Sec. 6.1)",
)
register_policy(
    "evader/wall_hugging",
    WallHuggingEvader,
    "goes to the nearest wall and follows it, wall on the right",
)
register_policy(
    "evader/orbit",
    OrbitEvader,
    "circles the nearest obstacle (pillar) at a fixed distance: darts round its corners",
)
register_policy(
    "pursuer/tractrix",
    TractrixFollower,
    "follower dragged by a taut string toward L_min: the tractrix (Sec. 7.1)",
)
register_policy(
    "pursuer/wall_following",
    WallFollowingPursuer,
    "slides along its nearest wall holding L_min (Sec. 7.3)",
)
register_policy(
    "pursuer/corner_rounding",
    CornerRoundingPursuer,
    "pivots the rod about nearby convex corners (Sec. 7.4), else tractrix",
)
register_policy(
    "pursuer/decomposition",
    DecompositionPursuer,
    "keeps the rod in admissible safe cells at L_min (Secs. 4-5): table lookup per step",
)
register_policy(
    "evader/shooting",
    ShootingEvader,
    "escape plans through escapable cells, optimal escape arcs (Sec. 6), else pressure",
)
register_policy(
    "pursuer/referee",
    RefereePursuer,
    "the bounded-speed referee's certified pursuer (solves the game at reset, cached); "
    "keeps mid-range where nothing is certified",
)
register_policy(
    "evader/referee",
    RefereeEvader,
    "the bounded-speed referee's certified evader (solves the game at reset, cached); "
    "charges the pursuer where nothing is certified",
)
