"""solve()'s evader fallback (issue 13): where the default evader lattice certifies next to
nothing, the evader bound is solved once more at half the cells per spacing and kept when it
certifies more (and says so).

The world is two_rooms in small: two 3 x 3 rooms joined by a corridor 0.5 wide (half of
L_min) and 2 long. The evader wins by leading the pursuer into the corridor and rounding a
mouth corner closely; the default lattice (coarse 4: one row in the corridor, its room-side
points 0.25 from the corner) cannot, and the bound's pursuer, moving after seeing the
evader's step, always finds a cell whose rod grazes the corner."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from envs.errors import InvalidConfigError
from envs.maps import Map
from strategies.referee import solve
from strategies.referee.referee import (
    EVADER_FALLBACK_SHARE,
    evader_fallback_resolution,
    evader_fallback_size,
    solve_role,
)
from tests.strategies.referee.conftest import DT, spec
from tests.strategies.referee.test_policies import escapes_in_certified_time

pytestmark = pytest.mark.filterwarnings("ignore::envs.errors.VacuousBoundWarning")  # rho 0.5

CPL = 16


def small_two_rooms() -> Map:
    return Map(
        [(-5, -1.5), (-2, -1.5), (-2, -0.25), (0, -0.25), (0, -1.5), (3, -1.5), (3, 1.5),
         (0, 1.5), (0, 0.25), (-2, 0.25), (-2, 1.5), (-5, 1.5)],
        name="small_two_rooms",
    )  # fmt: skip


ROOMS = spec(small_two_rooms(), 0.5)


@pytest.fixture(scope="module")
def cache(tmp_path_factory):
    return tmp_path_factory.mktemp("evader_fallback_cache")


@pytest.fixture(scope="module")
def referee(cache):
    return solve(ROOMS, CPL, dt=DT, cache_dir=cache)


@pytest.fixture(scope="module")
def default(cache):
    return solve_role(ROOMS, "evader", CPL, dt=DT, cache_dir=cache, evader_fallback=False)


def test_the_fallback_certifies_where_the_default_evader_lattice_does_not(referee, default):
    assert default.res.coarse == 4 and default.live_fraction() < EVADER_FALLBACK_SHARE
    eb = referee.evader
    assert eb.res.coarse == 2 and eb.fallback_from == default.res
    assert eb.res.tau == pytest.approx(default.res.tau / 2)
    assert eb.live_fraction() > 0.95  # 100 %
    s = referee.summary()
    assert s["evader"] > 0.95  # of the lattice starts: 100 %, from 0.2 % at the default
    assert s["evader_bound"]["coarse"] == 2
    assert s["evader_bound"]["fallback_from"] == {"coarse": 4, "spacing": 0.25, "tau": 1.0}
    with_default = dataclasses.replace(referee, evader=default)
    assert with_default.summary()["evader"] < 0.01


def test_solve_role_falls_back_as_solve_does_and_a_lattice_asked_for_is_kept(
    referee, default, cache
):
    role = solve_role(ROOMS, "evader", CPL, dt=DT, cache_dir=cache)
    assert role.res == referee.evader.res and role.fallback_from == default.res
    assert np.array_equal(role.rank, referee.evader.rank)
    asked = solve_role(ROOMS, "evader", CPL, dt=DT, cache_dir=cache, evader_coarse=4)
    assert asked.res == default.res and asked.fallback_from is None
    ref = solve(ROOMS, CPL, dt=DT, cache_dir=cache, evader_fallback=False)
    assert ref.evader.res == default.res and ref.summary()["evader_bound"]["fallback_from"] is None


def test_when_the_evader_fallback_is_not_tried(referee, default, cache):
    assert evader_fallback_resolution(ROOMS, default, CPL, dt=DT).coarse == 2
    # the default certifies enough: kept
    assert evader_fallback_resolution(ROOMS, referee.evader, CPL, dt=DT) is None
    # a lattice asked for
    assert evader_fallback_resolution(ROOMS, default, CPL, dt=DT, evader_coarse=4) is None
    # from two cells (coarse 1: four times the points)
    two = dataclasses.replace(default, res=dataclasses.replace(default.res, coarse=2))
    assert evader_fallback_resolution(ROOMS, two, CPL, dt=DT) is None
    # both solves cached: nothing more to announce
    assert evader_fallback_size(ROOMS, CPL, cache_dir=cache, dt=DT) is None
    size = evader_fallback_size(ROOMS, CPL, cache=False, dt=DT)
    assert size.what == "evader bound's fallback" and size.tau == referee.evader.res.tau


@pytest.mark.parametrize("value", ["no", 1, None])
def test_a_bad_evader_fallback_is_refused_before_solving(value):
    with pytest.raises(InvalidConfigError, match="evader_fallback"):
        solve(ROOMS, CPL, evader_fallback=value, cache=False)
    with pytest.raises(InvalidConfigError, match="evader_fallback"):
        solve_role(ROOMS, "evader", CPL, evader_fallback=value, cache=False)


def test_the_fallback_s_evader_escapes_in_the_certified_time_against_every_pursuer(referee):
    """The fallback's certificate is played: the referee's evader on it, from certified
    starts with the pursuer behind it in the corridor or in a room, breaks surveillance
    within the certified time against every registered pursuer, every step certified."""
    starts = referee.sample_starts(2, np.random.default_rng(5), kind="evader")
    escapes_in_certified_time(referee, starts)


def test_an_evader_fallback_over_the_memory_budget_is_not_solved(cache):
    """A budget both default bounds fit and the finer evader lattice, held beside them,
    does not: the default evader bound stands, as without the fallback."""
    from strategies.referee._budget import bound_size, peak
    from strategies.referee.referee import _resolution

    sizes = [bound_size(ROOMS, _resolution(ROOMS, r, CPL, dt=DT), r) for r in ("pursuer", "evader")]
    alt = _resolution(ROOMS, "evader", CPL, dt=DT, evader_coarse=2)
    need = peak(sizes)[0]
    need_alt = peak([*sizes, bound_size(ROOMS, alt, "evader")])[0]
    assert need < need_alt
    ref = solve(ROOMS, CPL, dt=DT, cache_dir=cache, memory_budget=(need + need_alt) / 2)
    assert ref.evader.res.coarse == 4 and ref.evader.fallback_from is None
