"""Shared fixtures: small nets written inline, and paths to the repository's data."""

from __future__ import annotations

from pathlib import Path

import pytest

from petriflow.io.yaml import loads_net

REPO = Path(__file__).resolve().parents[1]
NETS = REPO / "nets"
ORACLE = REPO.parent / "shared" / "oracle"

def bench_module(name: str):
    """Import ``bench/NAME.py`` (bench/ is a folder of scripts, not a package)."""
    import importlib.util
    import sys

    if name in sys.modules:
        return sys.modules[name]
    spec = importlib.util.spec_from_file_location(name, REPO / "bench" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


def net_files() -> list[Path]:
    """The nets shipped under nets/ (YAML files with a 'petriflow:' version key, and PNML);
    world and run configuration files beside them are not nets."""
    found = []
    for path in sorted(NETS.rglob("*")):
        if path.suffix == ".pnml":
            found.append(path)
        elif path.suffix in {".yaml", ".yml"} and any(
            line.startswith("petriflow:") for line in path.read_text().splitlines()
        ):
            found.append(path)
    return found


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
