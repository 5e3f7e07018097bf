"""The examples in the legged modules' docstrings run (agents/ is not under the
doctest-collected ``petriflow/`` folder)."""

from __future__ import annotations

import doctest
import importlib

import pytest

MODULES = ["kinematics", "robots", "stability", "gait", "control", "righting", "actions", "plugin"]


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples_run(name):
    """doctest finds examples in the module and they all pass."""
    module = importlib.import_module(f"petriflow.agents.legged.{name}")
    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    assert result.attempted > 0
    assert result.failed == 0
