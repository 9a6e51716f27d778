"""The pursuer bound says when its pursuer wins say nothing (issue 13): the range band is
used up, rho is where it was measured to certify nothing, or it certified no state."""

from __future__ import annotations

import dataclasses
import math
import warnings

import numpy as np
import pytest

from envs.errors import VacuousBoundWarning
from envs.maps import Map, builtin_map
from strategies.referee import GameSpec, Resolution, solve
from strategies.referee.pursuer_bound import VACUOUS_RHO, range_band, vacuity
from strategies.referee.referee import solve_role
from tests.strategies.referee.conftest import DT, open_room, spec

ROOM10 = Map([(0, 0), (10, 0), (10, 10), (0, 10)], name="room10")


def _default_pursuer_res(s: GameSpec, cpl: float) -> Resolution:
    """The pursuer resolution solve() picks by default (its lattice rule)."""
    cap = max(2, math.floor((s.l_max - s.l_min) * cpl / (4.0 * s.l_min)))
    coarse = int(min(12, cap, max(2, round(2.0 / s.rho))))
    return Resolution.for_role(s, "pursuer", cpl, coarse=coarse, steps=3.0, dt=DT)


def test_range_band_is_used_up_by_a_long_step_of_a_fast_evader():
    res = Resolution(cell=0.25, coarse=2, tau=1.5)
    w, ok = range_band(GameSpec(ROOM10, 2.0, 4.0, 1.0, 0.2, body_radius=0.2), res)
    assert ok and w == pytest.approx(2 - 2 * 0.3 - 3 * math.sqrt(2) * 0.25)
    w, ok = range_band(GameSpec(ROOM10, 2.0, 4.0, 1.0, 0.5, body_radius=0.2), res)
    assert not ok and w < 0
    why = vacuity(GameSpec(ROOM10, 2.0, 4.0, 1.0, 0.5, body_radius=0.2), res)
    assert "range band is used up" in why and "-0.561" in why and "tau = 1.5 s" in why
    # a shorter step reopens it (then only the measured regime remains)
    short = Resolution(cell=0.25, coarse=1, tau=0.5)
    assert range_band(GameSpec(ROOM10, 2.0, 4.0, 1.0, 0.5, body_radius=0.2), short)[1]


@pytest.mark.parametrize("cpl", [8, 12, 16, 24])
@pytest.mark.parametrize("rho", [0.1, 0.2, 0.25, 0.3, 0.35, 0.5, 0.9])
def test_vacuity_before_solving_at_the_default_lattice(rho, cpl):
    s = GameSpec(ROOM10, 2.0, 4.0, 1.0, rho, body_radius=0.2)
    why = vacuity(s, _default_pursuer_res(s, cpl))
    if rho < VACUOUS_RHO:
        assert why is None  # no warning where the bound can certify (rho 0.2: 99 %)
    else:
        assert why is not None and f"rho = {rho:g}" in why and "'unknown'" in why


def _solve(rho: float, cpl: float):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        ref = solve(spec(open_room(), rho), cpl, dt=DT, cache=False)
    return ref, [w for w in caught if issubclass(w.category, VacuousBoundWarning)]


def test_solve_warns_at_rho_half_and_not_at_rho_0_2():
    ref, caught = _solve(0.2, 10)
    assert caught == [] and ref.summary()["pursuer_bound"]["vacuous"] is None
    assert ref.pursuer.fraction() > 0.9  # an informative bound: no warning
    ref, caught = _solve(0.5, 10)
    assert len(caught) == 1
    msg = str(caught[0].message)
    tau = ref.pursuer.res.tau
    assert msg.startswith("map 'open5': pursuer bound at rho = 0.5") and f"tau = {tau:.4g} s" in msg
    assert ref.summary()["pursuer_bound"]["vacuous"] in msg
    assert ref.pursuer.fraction() == 0.0  # the warning is true: it certified nothing


def test_a_bound_that_won_nothing_says_so(open_slow):
    pb = open_slow.pursuer
    assert pb.vacuity() is None and open_slow.summary()["pursuer_bound"]["vacuous"] is None
    empty = dataclasses.replace(pb, win=np.zeros_like(pb.win))
    why = empty.vacuity()
    assert why is not None and "certified no state" in why and "rho = 0.2" in why


def test_narrow_passages_at_low_rho_and_the_lattice_that_certifies():
    """pursuer_bound's docstring and the README: far below VACUOUS_RHO the bound certifies
    nothing on the corner world (arms 5 wide, which a real pursuer circling the evader at
    L_min passes up to rho = 0.112) at rho = 0.1 at the default lattice, and warns so;
    pursuer_coarse=3 certifies 93 % of the states there (helper-105's measurements), and
    is what solve falls back to (pursuer_fallback, on by default)."""
    corner = GameSpec(builtin_map("corner"), 2.0, 4.0, 1.0, 0.1, body_radius=0.1)
    with pytest.warns(VacuousBoundWarning, match="certified no state"):
        default = solve_role(corner, "pursuer", 16, cache=False, pursuer_fallback=False)
    assert default.res.coarse == 4 and default.fraction() == 0.0
    with warnings.catch_warnings():
        warnings.simplefilter("error", VacuousBoundWarning)
        fallen = solve_role(corner, "pursuer", 16, cache=False)
    assert fallen.res.coarse == 3 and fallen.fallback_from == default.res
    assert fallen.fraction() == pytest.approx(0.932, abs=0.005)
