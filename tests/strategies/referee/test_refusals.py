"""What the referee refuses, and how: no empty answer, no traceback, no hang.

Each case was found by trying every numeric parameter of ``solve``, ``GameSpec``,
``Resolution``, ``label_starts`` and ``sample_starts`` with NaN, inf, 0, negatives and
absurd sizes (helper-186's list): NaN, inf, 0 and negatives were refused already; these were
not.
"""

from __future__ import annotations

import time

import numpy as np
import pytest

from envs.errors import InfeasibleError, InvalidConfigError, MemoryBudgetError, NoStartError
from envs.maps import Map
from strategies.referee import (
    GameSpec,
    Resolution,
    cached_evader_bound,
    cached_pursuer_bound,
    label_starts,
    regret,
    sample_starts,
    solve,
)
from tests.strategies.referee.conftest import open_room, spec


def ring() -> Map:
    """A ring corridor 0.5 wide round a 9 x 9 block: at L in [2, 4] and agents of radius
    0.1, the referee's lattices at 16 cells per L_min miss it (19 holds a start)."""
    block = [(0.5, 0.5), (9.5, 0.5), (9.5, 9.5), (0.5, 9.5)]
    return Map([(0, 0), (10, 0), (10, 10), (0, 10)], obstacles=[block], name="ring")


@pytest.mark.parametrize("cpl", [1e-9, 0.5, 1e-300])
def test_a_resolution_with_no_lattice_start_is_refused_naming_one_that_has(cpl):
    """``solve(spec, cells_per_lmin=1e-9)`` returned a referee with 0 starts and "gap 0.0"
    (0.5 too: cells of L_max, the lattices' points 2 L_max apart); 1e-300 was an
    OverflowError from the memory estimate."""
    s = spec(open_room(6.0), 0.2)
    with pytest.raises(NoStartError) as info:
        solve(s, cpl, cache=False)
    # an InfeasibleError too: the scripts that label starts say "not solved" and go on
    assert isinstance(info.value, InfeasibleError)
    text = str(info.value)
    assert text.startswith(f"cells_per_lmin = {cpl:g}: the referee's lattices ")
    assert "hold no start with the players in range [1, 2]" in text and "'open6'" in text
    fit = text.split("the coarsest resolution with one is cells_per_lmin ")[1].split(" ")[0]
    assert solve(s, float(fit), cache=False).summary()["starts"] > 0


def test_the_message_names_the_knob_of_its_caller():
    s = spec(open_room(6.0), 0.2)
    with pytest.raises(NoStartError) as info:
        solve(s, 0.5, cache=False)
    named = str(info.value.named("--cells-per-lmin"))
    assert named.startswith("--cells-per-lmin = 0.5: ") and "is --cells-per-lmin 1" in named


@pytest.mark.parametrize(
    ("make", "expected"),
    [
        # an OverflowError ("int too large to convert to float") from the memory estimate
        (lambda: solve(GameSpec(open_room(6.0), 1.0, 1e200), 8, cache=False),
         MemoryBudgetError),
        # ZeroDivisionError (cells of 1e-300 m), OverflowError (a step of 1e300 s)
        (lambda: cached_pursuer_bound(spec(open_room(6.0), 0.2), Resolution(cell=1e-300),
                                      cache=False), MemoryBudgetError),
        (lambda: cached_evader_bound(spec(open_room(6.0), 0.2),
                                     Resolution(cell=0.125, tau=1e300), cache=False),
         MemoryBudgetError),
        (lambda: solve(spec(open_room(6.0), 0.2), 4, pursuer_steps=1e300, cache=False),
         MemoryBudgetError),
        (lambda: solve(spec(open_room(6.0), 0.2), 4, dt=1e300, cache=False),
         MemoryBudgetError),
        # hung (killed after 40 s): the evader bound's move table, 3e8 moves, was left out
        # of its estimate (a few MB)
        (lambda: solve(spec(open_room(6.0), 0.2), 4, evader_steps=1e4, cache=False),
         MemoryBudgetError),
        (lambda: cached_evader_bound(spec(open_room(6.0), 0.2),
                                     Resolution(cell=0.125, tau=1e4), cache=False),
         MemoryBudgetError),
    ],
)  # fmt: skip
def test_absurd_sizes_are_refused_for_their_memory_at_once(make, expected):
    t = time.perf_counter()
    with pytest.raises(expected, match="the solve would need about "):
        make()
    assert time.perf_counter() - t < 10.0


@pytest.mark.parametrize("v", [{"v_evader": 1e-300}, {"v_pursuer": 1e-300}])
def test_an_extreme_speed_ratio_solves(v):
    """rho = 1e-300 and 1e300: an OverflowError in the opponent's reach (r * r)."""
    s = GameSpec(open_room(6.0), 1.0, 2.0, **v, body_radius=0.05)
    assert solve(s, 4, cache=False).summary()["starts"] > 0


def test_sample_and_label_starts_refuse_what_they_cannot_use(open_slow):
    with pytest.raises(InvalidConfigError, match=r"rng = None: expected a numpy\.random"):
        sample_starts(open_slow, 3, None)  # an AttributeError
    with pytest.raises(InvalidConfigError, match=r"starts = None: expected an iterable"):
        label_starts(open_slow, None)  # a TypeError
    one = {"pursuer": (2.5, 4.0), "evader": (2.5, 2.5)}
    with pytest.raises(InvalidConfigError, match=r"expected an iterable .*a list of them"):
        label_starts(open_slow, one)  # "start 0 = 'pursuer'"
    assert label_starts(open_slow, [one]) == ["pursuer"]
    assert len(sample_starts(open_slow, 2, np.random.default_rng(0))) == 2


def test_a_referee_policy_on_a_map_its_lattice_misses_names_a_resolution(tmp_path, monkeypatch):
    """It raised the lattice's own "no lattice point of spacing 0.5 lies 0.1 from the walls
    of map 'ring'; try another resolution", naming no policy, parameter or resolution; the
    next episode solved (and failed) again."""
    from strategies.policies.registry import make_policy
    from strategies.referee import policy as referee_policy
    from strategies.runner import run_episode

    monkeypatch.setenv("SURVEIL_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(referee_policy, "_SOLVED", {})
    world = ring()

    def episode(name: str, seed: int, **params):
        me = make_policy(name, **params)
        if name.startswith("pursuer"):
            return run_episode(world, me, "evader/straight", seed, start="valid", max_cycles=5)
        return run_episode(world, "pursuer/greedy", me, seed, start="valid", max_cycles=5)

    for name in ("pursuer/referee", "evader/referee"):
        with pytest.raises(NoStartError) as info:
            episode(name, 0)
        text = str(info.value)
        assert text.startswith(f"policy {name!r}: cells_per_lmin = 16: the referee's lattices")
        assert "on map 'ring'" in text and "the next finer resolution with one is " in text
        finer = float(text.split("with one is cells_per_lmin ")[1].split(" ")[0])
        t = time.perf_counter()
        with pytest.raises(NoStartError):  # the second episode: refused at once
            episode(name, 1)
        assert time.perf_counter() - t < 1.0
        assert episode(name, 0, cells_per_lmin=finer).steps >= 1


def test_regret_counts_a_game_with_no_lattice_start_as_unknown():
    """A tournament's regret table solved every game played; one whose lattices hold no
    start now raises NoStartError: its matches are unknown, not a failed report."""
    world = open_room(6.0)
    match = {"map": world, "l_min": 1.0, "l_max": 2.0, "v_pursuer": 1.0, "v_evader": 0.2,
             "body_radius": 0.05, "dt": 0.1, "max_cycles": 10, "pursuer": "pursuer/x",
             "evader": "evader/y", "start": {"pursuer": (3.0, 4.5), "evader": (3.0, 3.0)},
             "winner": "pursuer"}  # fmt: skip
    rows = regret([match], cells_per_lmin=0.5, cache=False, progress=False)
    assert {(r.role, r.matches, r.unknown) for r in rows} == {("pursuer", 1, 1), ("evader", 1, 1)}
