"""The examples in the bus modules' docstrings run (agents/ is outside the doctest-collected
``petriflow/`` folder)."""

from __future__ import annotations

import doctest
import importlib

import pytest

MODULES = ["errors", "frames", "packet", "radio", "records", "buffer", "parameters", "rs485", "can", "zigbee",
           "network", "simulator", "channel", "nets", "cpg", "algorithms", "addressing", "plugin"]


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples_run(name):
    """doctest finds examples in the module and they all pass."""
    module = importlib.import_module(f"petriflow.agents.bus.{name}")
    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    assert result.attempted > 0
    assert result.failed == 0


def test_package_exports_resolve():
    """Every name in the package's ``__all__`` exists."""
    package = importlib.import_module("petriflow.agents.bus")
    assert all(hasattr(package, name) for name in package.__all__)
