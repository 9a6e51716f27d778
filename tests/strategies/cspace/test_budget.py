"""Big builds: refused up front over the memory budget (with the estimate), progress shown."""

from __future__ import annotations

import time

import pytest

from envs.errors import InfeasibleError, InvalidConfigError
from strategies.cspace import decompose
from strategies.cspace._budget import estimate
from strategies.memory import memory_budget
from tests.strategies.cspace._oracle import corridor, hexagons


def test_a_build_over_budget_is_refused_at_once_with_the_estimate():
    t = time.perf_counter()
    with pytest.raises(InfeasibleError) as err:
        decompose(hexagons(), 3.3, memory_budget="1MB")
    assert time.perf_counter() - t < 1.0  # before any real work
    msg = str(err.value)
    assert "memory budget" in msg and "GB" in msg and "pairs" in msg
    assert "memory_budget=" in msg and "SURVEIL_MEMORY_BUDGET" in msg and "shorter L" in msg


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
