"""The Examples sections of the docstrings run (shapely's habit): a wrong one fails here."""

from __future__ import annotations

import doctest
import importlib
import pkgutil

import pytest

import envs
import strategies.control


def _modules(package) -> list[str]:
    return [
        m.name
        for m in pkgutil.walk_packages(package.__path__, prefix=package.__name__ + ".")
        if not m.name.endswith("__main__")
    ]


MODULES = [
    "envs",
    *_modules(envs),
    *_modules(strategies.control),
    "strategies.memory",
    "strategies.policies.base",
    "strategies.policies.model_files",
    "strategies.policies.registry",
    "strategies.referee.lattice",
    "analysis.arguments",
    "analysis.replay",
]


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples_run(name: str) -> None:
    module = importlib.import_module(name)
    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS, verbose=False)
    assert result.failed == 0, f"{result.failed} of {result.attempted} examples failed in {name}"
