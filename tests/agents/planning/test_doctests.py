"""The examples in the planning modules' docstrings run and hold.

``agents/`` is outside pytest's doctest paths (it is installed as
``petriflow.agents``), so the examples are run here, on the installed modules.
"""

from __future__ import annotations

import doctest
import importlib

import pytest

MODULES = ["errors", "maps", "astar", "mazes", "tracking", "avoidance", "actions", "guards", "plugin"]


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples(name):
    """Every example in the module's docstrings gives the output shown."""
    module = importlib.import_module(f"petriflow.agents.planning.{name}")
    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    assert result.failed == 0
    if name != "errors":
        assert result.attempted > 0
