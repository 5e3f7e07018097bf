"""Shared fixtures: small nets written inline, and paths to the repository's data."""

from __future__ import annotations

from pathlib import Path

import pytest

from petriflow.io.yaml import loads_net

REPO = Path(__file__).resolve().parents[1]
NETS = REPO / "nets"
ORACLE = REPO.parent / "shared" / "oracle"

SEQUENCE_YAML = """
petriflow: 1
net: sequence
places: [{id: i, tokens: 1}, p, o]
transitions:
  - {id: a, in: [i], out: [p]}
  - {id: b, in: [p], out: {o: 2}}
final: {o: 2}
"""


@pytest.fixture
def sequence_net():
    """i -a-> p -b-> o (b puts two tokens in o)."""
    return loads_net(SEQUENCE_YAML)


@pytest.fixture
def oracle_dir() -> Path:
    """The shared folder of nets written by other tools, skipping when it is absent."""
    if not ORACLE.is_dir():
        pytest.skip("shared oracle nets not available")
    return ORACLE
