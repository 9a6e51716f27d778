"""The docstring examples of the configuration-space modules run (shapely does the same)."""

from __future__ import annotations

import doctest

import pytest

import strategies.cspace.tolerances

MODULES = [strategies.cspace.tolerances]


@pytest.mark.parametrize("module", MODULES, ids=lambda m: m.__name__)
def test_docstring_examples_run(module):
    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS)
    assert result.attempted > 0 and result.failed == 0
