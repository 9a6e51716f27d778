"""Big builds: refused up front over the memory budget (with the estimate), progress shown."""

from __future__ import annotations

import time
import tracemalloc

import numpy as np
import pytest

from envs.errors import InfeasibleError, InvalidConfigError, MemoryBudgetError
from envs.maps import Map
from strategies.cspace import decompose
from strategies.cspace._budget import estimate
from strategies.cspace.tolerances import diameter
from strategies.memory import memory_budget, physical_memory
from tests.strategies.cspace._oracle import corridor, hexagons


def test_a_build_over_budget_is_refused_at_once_with_the_estimate():
    t = time.perf_counter()
    with pytest.raises(InfeasibleError) as err:
        decompose(hexagons(), 3.3, memory_budget="1MB")
    assert time.perf_counter() - t < 1.0  # before any real work
    msg = str(err.value)
    assert "memory budget of 1 MB" in msg and "pairs" in msg  # was "of 0.0 GB"
    assert "memory_budget=" in msg and "SURVEIL_MEMORY_BUDGET" in msg and "shorter L" in msg


def _round_room(n: int) -> Map:
    t = 2 * np.pi * np.arange(n) / n
    return Map(np.stack([5 + 5 * np.cos(t), 5 + 5 * np.sin(t)], axis=1), name="round")


def test_a_round_room_s_diameter_takes_no_square_of_its_vertices_in_memory():
    # an 8,000-gon: the diameters built 8,000^2 x 2 arrays (1 GB and more each; 20,000
    # vertices took 6.4 GB and 74 s inside decompose, before its memory check)
    room = _round_room(8000)
    tracemalloc.start()
    try:
        assert diameter(room) == pytest.approx(10.0) and room.diameter == pytest.approx(10.0)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 100e6, peak


def test_a_round_room_s_diameter_is_not_quadratic_in_its_vertices():
    """A 20,000-gon: every pair of hull vertices took 11 s in Map.diameter and 23 s a call in
    tolerances.diameter (``surveil analyze`` 63 s before refusing the decomposition for its
    memory, 57 of them in the diameters); the rotating calipers take about 0.3 s."""
    room = _round_room(20000)
    t = time.perf_counter()
    assert room.diameter == pytest.approx(10.0) and diameter(room) == room.diameter
    assert time.perf_counter() - t < 5.0


def test_a_build_no_budget_on_this_machine_fits_is_said_so():
    # L = 4.9 in a round room of 8,000 vertices: 755 GB; the advice was
    # SURVEIL_MEMORY_BUDGET=1510GB, whatever the machine's memory
    room = _round_room(8000)
    need = estimate(room, 4.9).bytes
    if need <= physical_memory():  # pragma: no cover - a machine with terabytes of RAM
        pytest.skip(f"this machine has the {need / 1e9:.0f} GB")
    with pytest.raises(MemoryBudgetError) as err:
        decompose(room, 4.9)
    msg = str(err.value)
    assert "the decomposition would need about 754.9 GB" in msg
    assert "No budget on this machine fits it" in msg
    assert "SURVEIL_MEMORY_BUDGET" not in msg and "memory_budget=" not in msg
    assert "use a shorter L or a smaller map" in msg


def test_the_budget_comes_from_the_environment(monkeypatch):
    monkeypatch.setenv("SURVEIL_MEMORY_BUDGET", "2 MiB")
    assert memory_budget() == 2 * 2**20
    with pytest.raises(InfeasibleError, match="memory budget"):
        decompose(corridor(), 2.0)
    monkeypatch.setenv("SURVEIL_MEMORY_BUDGET", "lots")
    with pytest.raises(InvalidConfigError, match="SURVEIL_MEMORY_BUDGET"):
        decompose(corridor(), 2.0)


@pytest.mark.parametrize("bad", ["lots", -5, 0, True, float("nan"), "12 parsecs"])
def test_bad_budgets_are_named(bad):
    with pytest.raises(InvalidConfigError, match="memory_budget"):
        decompose(corridor(), 2.0, memory_budget=bad)


def test_estimates_grow_with_L_and_do_not_depend_on_units():
    small, big = estimate(hexagons(), 1.0), estimate(hexagons(), 3.3)
    assert small.pairs < big.pairs and small.bytes < big.bytes
    scaled = hexagons().transformed([[1e3, 0.0], [0.0, 1e3]])
    assert estimate(scaled, 3.3e3).pairs == big.pairs


def test_progress_bar_when_asked(capsys):
    decompose(corridor(), 2.0, progress=True)
    assert "decompose corridor" in capsys.readouterr().err
    decompose(corridor(), 2.0, progress=False)
    assert capsys.readouterr().err == ""
    with pytest.raises(InvalidConfigError, match="progress"):
        decompose(corridor(), 2.0, progress="yes")
