"""solve()'s pursuer fallback (issue 13): where the default pursuer lattice certifies no
state at rho < VACUOUS_RHO, the pursuer bound is solved once more with pursuer_coarse one
less, and kept when it certifies some state (and says so)."""

from __future__ import annotations

import dataclasses
import warnings

import numpy as np
import pytest

from envs.errors import InvalidConfigError, VacuousBoundWarning
from envs.maps import builtin_map
from strategies.policies.registry import make_policy, policy_names
from strategies.referee import GameSpec, RefereePursuer, solve
from strategies.referee.pursuer_bound import VACUOUS_RHO
from strategies.referee.referee import pursuer_fallback_resolution, solve_role
from strategies.runner import run_episode
from tests.strategies.referee.conftest import DT

# the built-in open room (its L in [2, 4], body radius 0.1) at rho = 0.3, 16 cells per
# L_min: the default lattice (coarse 4, tau 1.5 s) certifies nothing, coarse 3 98 %
OPEN = GameSpec(builtin_map("open_room"), 2.0, 4.0, 1.0, 0.3, body_radius=0.1)
CPL = 16


@pytest.fixture(scope="module")
def cache(tmp_path_factory):
    return tmp_path_factory.mktemp("fallback_cache")


@pytest.fixture(scope="module")
def referee(cache):
    with warnings.catch_warnings():
        warnings.simplefilter("error", VacuousBoundWarning)  # the fallback certifies: no warning
        return solve(OPEN, CPL, dt=DT, cache_dir=cache)


def test_the_fallback_certifies_where_the_default_lattice_does_not(referee, cache):
    with pytest.warns(VacuousBoundWarning, match="certified no state"):
        default = solve_role(OPEN, "pursuer", CPL, dt=DT, cache_dir=cache, pursuer_fallback=False)
    assert default.res.coarse == 4 and default.fraction() == 0.0
    pb = referee.pursuer
    assert pb.res.coarse == 3 and pb.fallback_from == default.res
    assert pb.fraction() > 0.95  # 98.1 %
    s = referee.summary()["pursuer_bound"]
    assert s["vacuous"] is None and s["coarse"] == 3
    assert s["fallback_from"] == {"coarse": 4, "spacing": 0.5, "tau": 1.5}
    assert referee.summary()["pursuer"] > 0.85  # of the lattice starts: 89.6 %
    # the policies' bound is the same (solve_role falls back as solve does)
    with warnings.catch_warnings():
        warnings.simplefilter("error", VacuousBoundWarning)
        role = solve_role(OPEN, "pursuer", CPL, dt=DT, cache_dir=cache)
    assert role.res == pb.res and role.fallback_from == default.res
    assert np.array_equal(role.win, pb.win)
    # a lattice asked for is kept, however little it certifies
    with pytest.warns(VacuousBoundWarning, match="certified no state"):
        asked = solve_role(OPEN, "pursuer", CPL, dt=DT, cache_dir=cache, pursuer_coarse=4)
    assert asked.res == default.res and asked.fallback_from is None


def test_no_fallback_from_vacuous_rho_or_from_a_bound_that_certifies(referee):
    default = dataclasses.replace(
        referee.pursuer, res=referee.pursuer.fallback_from, win=np.zeros((1, 1, 1), bool)
    )
    assert pursuer_fallback_resolution(OPEN, default, CPL, dt=DT).coarse == 3
    fast = dataclasses.replace(OPEN, v_evader=VACUOUS_RHO)
    assert pursuer_fallback_resolution(fast, default, CPL, dt=DT) is None
    assert pursuer_fallback_resolution(OPEN, referee.pursuer, CPL, dt=DT) is None
    assert pursuer_fallback_resolution(OPEN, default, CPL, dt=DT, pursuer_coarse=4) is None
    # not from two cells to one (8 cells per L_min): four times the points, 4-12 times the time
    two = dataclasses.replace(default, res=dataclasses.replace(default.res, coarse=2))
    assert pursuer_fallback_resolution(OPEN, two, 8, dt=DT) is None


@pytest.mark.parametrize("value", ["no", 1, None, 0.0])
def test_a_bad_pursuer_fallback_is_refused_before_solving(value):
    with pytest.raises(InvalidConfigError, match="pursuer_fallback"):
        solve(OPEN, CPL, pursuer_fallback=value, cache=False)
    with pytest.raises(InvalidConfigError, match="pursuer_fallback"):
        solve_role(OPEN, "pursuer", CPL, pursuer_fallback=value, cache=False)


def test_the_fallback_s_pursuer_holds_from_certified_starts(referee):
    """The fallback's certificate is played: the referee's pursuer on it, from certified
    starts, against every registered evader (the referee's own on this referee's evader
    bound), holds surveillance with every step certified."""
    from strategies.referee import RefereeEvader

    starts = referee.sample_starts(2, np.random.default_rng(3), kind="pursuer")
    assert len(starts) == 2
    overrides = {"l_min": OPEN.l_min, "l_max": OPEN.l_max, "v_pursuer": OPEN.v_pursuer,
                 "v_evader": OPEN.v_evader, "body_radius": OPEN.body_radius, "dt": DT}  # fmt: skip
    names = [n for n in policy_names("evader") if not n.endswith("/referee")]
    for start in starts:
        for name in [*names, "evader/referee"]:
            ev = RefereeEvader(referee.evader) if name == "evader/referee" else make_policy(name)
            pu = RefereePursuer(referee.pursuer)
            r = run_episode(OPEN.map, pu, ev, 0, max_cycles=150, overrides=overrides, start=start)
            assert (r.winner, pu.uncertified_steps) == ("pursuer", 0), (start, name, r.cause)


def test_a_fallback_over_the_memory_budget_is_not_solved(referee, cache):
    """A budget the default lattice fits and the finer one does not: the default's 0 %
    stands (as without the fallback), and the warning says why the fallback was not kept."""
    from strategies.referee._budget import bound_size, peak
    from strategies.referee.referee import _resolution

    default_res = _resolution(OPEN, "pursuer", CPL, dt=DT)
    alt = _resolution(OPEN, "pursuer", CPL, dt=DT, pursuer_coarse=3)
    need = peak([bound_size(OPEN, default_res, "pursuer")])[0]
    need_alt = peak([bound_size(OPEN, alt, "pursuer")])[0]
    assert need < need_alt
    with pytest.warns(VacuousBoundWarning, match="not kept: its solve would exceed the memory"):
        b = solve_role(
            OPEN, "pursuer", CPL, dt=DT, cache_dir=cache, memory_budget=(need + need_alt) / 2
        )
    assert b.res == default_res and b.fallback_from is None and b.fraction() == 0.0
