"""The referee: a numerical solver of the bounded-speed surveillance game (Sec. 5).

The verdicts of Props. 2-4 assume an infinitely fast pursuer; with bounded speeds nobody,
the paper included, can say from which starts the pursuer can hold. The referee answers on
small worlds with two discrete games that *sandwich* the real one:

* the **pursuer bound** (:mod:`.pursuer_bound`) favours the evader in every respect (it
  moves after seeing the pursuer's move, its position is known only to a cell, it may do
  anything inside a step, the pursuer is restricted to a lattice and finite headings);
  a start it certifies is won by the pursuer in the real game;
* the **evader bound** (:mod:`.evader_bound`) favours the pursuer in every respect; a
  start it certifies is won by the evader, within a certified time.

The starts neither certifies are the resolution error; it shrinks as the resolution
rises. Both bounds are fixed points over (certified lattice point, opponent cell) states
with the geometry kernel's continuous occlusion semantics (a rod can become blocked only
by sweeping a convex obstacle vertex; :mod:`.robust`). Solutions are cached on disk
(:mod:`.cache`). :class:`RefereePursuer` and :class:`RefereeEvader` play the certified
strategies in the env; :func:`label_starts` and :func:`sample_starts` serve training
curricula; :func:`regret` and :func:`tournament_regret` report how often each policy
loses a start the referee certifies winnable; :func:`strategies.referee.draw.draw_referee`
draws the winning sets.

Beside the certificates, :func:`estimate` solves issue 13's plain discrete game (both
players on one lattice, finite headings, the env's losing set checked at each half-step's
end and continuously during it) at several resolutions and both information orders: an
*estimate*, not a certificate, whose labels are ``"pursuer"``, ``"evader"`` or
``"contested"`` (the solutions disagree: the resolution error) (:mod:`.estimates`);
:class:`EstimateEvader` plays its evader strategy in the env.

Example::

    spec = GameSpec(world, l_min=1.0, l_max=2.0, v_pursuer=1.0, v_evader=0.5)
    ref = solve(spec, cells_per_lmin=20)
    ref.classify((1.0, 1.0), (2.5, 1.0))      # "pursuer", "evader" or "unknown"
    ref.summary()["gap"]                       # share of lattice starts left unknown
"""

from strategies.referee.estimate_policy import EstimateEvader
from strategies.referee.estimates import (
    ESTIMATE_LABELS,
    Estimate,
    EstimateSolution,
    estimate,
    solve_estimate,
)
from strategies.referee.evader_bound import EvaderBound, solve_evader_bound
from strategies.referee.policy import RefereeEvader, RefereePursuer
from strategies.referee.pursuer_bound import PursuerBound, solve_pursuer_bound
from strategies.referee.referee import (
    LABELS,
    Referee,
    StartSet,
    cached_evader_bound,
    cached_pursuer_bound,
    label_starts,
    referee_for,
    sample_starts,
    solve,
)
from strategies.referee.regrets import Regret, regret, regret_table, tournament_regret
from strategies.referee.spec import MARGIN_REL, GameSpec, Resolution

__all__ = [
    "ESTIMATE_LABELS",
    "LABELS",
    "MARGIN_REL",
    "Estimate",
    "EstimateEvader",
    "EstimateSolution",
    "EvaderBound",
    "GameSpec",
    "PursuerBound",
    "Referee",
    "RefereeEvader",
    "RefereePursuer",
    "Regret",
    "Resolution",
    "StartSet",
    "cached_evader_bound",
    "cached_pursuer_bound",
    "estimate",
    "label_starts",
    "referee_for",
    "regret",
    "regret_table",
    "sample_starts",
    "solve",
    "solve_estimate",
    "solve_evader_bound",
    "solve_pursuer_bound",
    "tournament_regret",
]
