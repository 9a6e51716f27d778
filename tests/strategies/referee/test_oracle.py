"""The referee as a test oracle for the analytic policies (issue 13).

From a start the referee certifies for the pursuer, the decomposition pursuer should hold
against every evader; from one it certifies for the evader, the shooting evader should
break surveillance against every pursuer, within a horizon proportional to the map's
diameter over V_e. A failure here is a weakness of the policy, not of the game: the
referee's own strategies win the same episodes (``test_policies.py``).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from strategies.policies.registry import make_policy, policy_names
from strategies.referee import RefereeEvader, RefereePursuer
from strategies.runner import run_episode
from tests.strategies.referee.conftest import DT, play

# rho = 0.5 on purpose: the pursuer bound's own warning is tested in test_vacuity
pytestmark = pytest.mark.filterwarnings("ignore::envs.errors.VacuousBoundWarning")


def _registered(role: str) -> list[str]:
    """The registered policies of ``role`` but the referee's own, which these tests add
    with the fixture's solved bound (the registered one would solve the game again)."""
    return [n for n in policy_names(role) if not n.endswith("/referee")]


def _diameter_time(ref) -> float:
    x0, y0, x1, y1 = ref.spec.map.bounds
    return math.hypot(x1 - x0, y1 - y0) / ref.spec.v_evader


def test_decomposition_pursuer_holds_from_certified_starts(open_slow):
    starts = open_slow.sample_starts(3, np.random.default_rng(5), kind="pursuer")
    evaders = [make_policy(n) for n in _registered("evader")] + [RefereeEvader(open_slow.evader)]
    for start in starts:
        for evader in evaders:
            winner, steps, cause = play(
                open_slow, make_policy("pursuer/decomposition"), evader, start, max_cycles=200
            )
            assert winner == "pursuer", (start, evader.name, steps, cause)


def test_decomposition_pursuer_holds_from_certified_starts_in_a_pillar_room():
    """An 8 x 8 room with a 1 x 1 pillar at rho = 0.1: the referee certifies ~90% of the
    starts for the pursuer; the decomposition pursuer holds them against every evader,
    the referee's charger included."""
    from envs.maps import Map
    from strategies.referee import solve
    from tests.strategies.referee.conftest import spec

    room = Map([(0, 0), (8, 0), (8, 8), (0, 8)], [[(3.5, 3.5), (4.5, 3.5), (4.5, 4.5),
                                                   (3.5, 4.5)]], name="pillar8")  # fmt: skip
    ref = solve(spec(room, 0.1), 16, dt=DT, cache=False)
    assert ref.summary()["pursuer"] > 0.8
    evaders = [make_policy(n) for n in _registered("evader")] + [RefereeEvader(ref.evader)]
    for start in ref.sample_starts(3, np.random.default_rng(7), kind="pursuer"):
        for evader in evaders:
            winner, steps, cause = play(ref, make_policy("pursuer/decomposition"), evader, start,
                                        max_cycles=300)  # fmt: skip
            assert winner == "pursuer", (start, evader.name, steps, cause)


@pytest.mark.filterwarnings("ignore::envs.errors.RhoAboveOneWarning")  # rho = 1.5: on purpose
@pytest.mark.parametrize("fixture", ["corridor_half", "open_fast"])
def test_shooting_evader_escapes_from_certified_starts(fixture, request):
    ref = request.getfixturevalue(fixture)
    starts = ref.sample_starts(3, np.random.default_rng(6), kind="evader")
    pursuers = [make_policy(n) for n in _registered("pursuer")] + [RefereePursuer(ref.pursuer)]
    horizon = round(2 * _diameter_time(ref) / DT)
    for start in starts:
        for pursuer in pursuers:
            winner, steps, _ = play(ref, pursuer, make_policy("evader/shooting"), start,
                                    max_cycles=horizon)  # fmt: skip
            assert winner == "evader", (start, pursuer.name, steps)


@pytest.fixture(scope="module")
def corner_referee():
    """The L-shaped hall of Fig. 9(b) at its recommended parameters (rho = 0.5): an arm
    5 wide is a dead end where a charger herds the pursuer (evader wins from ~7% of the
    lattice starts at this resolution, none for an infinitely fast pursuer)."""
    from envs.maps import builtin_info
    from envs.surveillance.config import EnvConfig
    from strategies.referee import referee_for

    info = builtin_info("corner")
    return referee_for(EnvConfig(map=info.map, **info.params()), 24)


def test_shooting_evader_escapes_from_certified_starts_in_the_corner_world(corner_referee):
    """Starts the referee certifies for the evader in the corner world (herding the pursuer
    into a dead-end arm, a bounded-speed escape Prop. 2 cannot see): the shooting evader's
    fallback charges and escapes from every one (issue 13; it was a strict xfail)."""
    from envs.maps import builtin_info

    info = builtin_info("corner")
    horizon = round(2 * _diameter_time(corner_referee) / 0.1)
    for i, start in enumerate(corner_referee.sample_starts(3, np.random.default_rng(0),
                                                            kind="evader")):  # fmt: skip
        r = run_episode(info.map, "pursuer/greedy", "evader/shooting", i, max_cycles=horizon,
                        overrides=info.params(), start=start)  # fmt: skip
        assert r.winner == "evader", (start, r.steps)


def test_referee_evader_wins_the_corner_worlds_certified_starts(corner_referee):
    """The same starts are won by the referee's evader, within its certified time bound."""
    from envs.maps import builtin_info

    info = builtin_info("corner")
    for i, start in enumerate(corner_referee.sample_starts(3, np.random.default_rng(0),
                                                            kind="evader")):  # fmt: skip
        bound = corner_referee.escape_time(**start)
        r = run_episode(info.map, "pursuer/greedy", RefereeEvader(corner_referee.evader), i,
                        max_cycles=round(bound / 0.1) + 5, overrides=info.params(),
                        start=start)  # fmt: skip
        assert r.winner == "evader" and r.escape_time <= bound + 1e-9
