"""The computed examples behind the figures and the report's numbers, each computed once.

A figure draws a case and :mod:`analysis.figures.numbers` quotes it, so what the report
says is what the picture shows. Everything is deterministic and built from the library's
public functions; results are cached per process (``functools.cache``).

* :mod:`~analysis.figures.cases.cspace`: decompositions of the paper's worlds, escape
  chains, the stratified graph, Fig. 8's births of escapable cells, the L-hall event (E10);
* :mod:`~analysis.figures.cases.control`: Fig. 9(a)'s charge, Fig. 11's printed shots,
  Fig. 13's escape endpoints;
* :mod:`~analysis.figures.cases.episodes`: the seeded matches of the replays.
"""

from analysis.figures.cases.control import (
    PAPER_SHOTS,
    SHOT_L,
    ChargeRotation,
    EscapeCase,
    charge_rotation,
    curve_escape,
    paper_shot,
    paper_shot_rho,
    vertex_escape,
)
from analysis.figures.cases.cspace import (
    EscapeChain,
    GrowthCase,
    LHallEvent,
    corridor,
    corridor_chain,
    corridor_mouth_region,
    corridor_stratified,
    dead_end_side,
    escape_chain,
    growth_cases,
    l_hall_event,
    mouth_chain,
    paper_decomposition,
    paper_verdict,
)
from analysis.figures.cases.episodes import (
    MATCHES,
    TALLY_SEEDS,
    Match,
    evader_wins,
    outcomes,
    play,
)

__all__ = [
    "MATCHES",
    "PAPER_SHOTS",
    "SHOT_L",
    "TALLY_SEEDS",
    "ChargeRotation",
    "EscapeCase",
    "EscapeChain",
    "GrowthCase",
    "LHallEvent",
    "Match",
    "charge_rotation",
    "corridor",
    "corridor_chain",
    "corridor_mouth_region",
    "corridor_stratified",
    "curve_escape",
    "dead_end_side",
    "escape_chain",
    "evader_wins",
    "growth_cases",
    "l_hall_event",
    "mouth_chain",
    "outcomes",
    "paper_decomposition",
    "paper_shot",
    "paper_shot_rho",
    "paper_verdict",
    "play",
    "vertex_escape",
]
