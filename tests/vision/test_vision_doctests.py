"""Run the examples in petriflow.vision's docstrings (pytest collects tests/ and
petriflow/ only, and vision/ lives beside them)."""

from __future__ import annotations

import doctest
import importlib

import pytest

MODULES = ["capture", "markers", "pipeline", "plugin", "pose", "segment"]


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples(name):
    module = importlib.import_module(f"petriflow.vision.{name}")
    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS)
    assert result.attempted > 0, f"{name} has no examples"
    assert result.failed == 0
