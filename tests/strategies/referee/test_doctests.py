"""The Examples sections of the referee's docstrings run (a wrong one fails here)."""

from __future__ import annotations

import doctest
import importlib
import pkgutil

import pytest

import strategies.referee

MODULES = [
    m.name for m in pkgutil.walk_packages(strategies.referee.__path__, prefix="strategies.referee.")
]


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples_run(name: str) -> None:
    module = importlib.import_module(name)
    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS, verbose=False)
    assert result.failed == 0, f"{result.failed} of {result.attempted} examples failed in {name}"
