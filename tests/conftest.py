"""Shared fixtures: small nets written inline, and paths to the repository's data."""

from __future__ import annotations

from pathlib import Path

import os

import pytest
from hypothesis import HealthCheck, settings

from petriflow.io.yaml import loads_net

# Hypothesis profiles: "ci" (the default) keeps the fuzzers at a few hundred examples
# each; HYPOTHESIS_PROFILE=nightly runs thousands (see docs/limits.md). Tests that set
# their own max_examples keep it.
settings.register_profile("ci", max_examples=150, deadline=None,
                          suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
settings.register_profile("nightly", max_examples=5000, deadline=None,
                          suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))

REPO = Path(__file__).resolve().parents[1]
NETS = REPO / "nets"
#: Real-world nets with known answers, copied into the tests (see its README for licences).
ORACLE = Path(__file__).resolve().parent / "data" / "oracle"
#: The fuller corpus beside the project, when there is one: it also holds nets whose
#: licence does not allow copying them here.
SHARED_ORACLE = REPO.parent / "shared" / "oracle"
#: The folders of the shared corpus that are not copied here, by their path under it.
NOT_COPIED = ("workflow/hagen-Beispiel-01", "workflow/hagen-Beispiel-Deadlock", "workflow/hagen-Beispiel-Fehler-01",
              "workflow/hagen-Beispiel-Fehler-02", "workflow/hagen-Beispiel-Kontakt-01")


def oracle_cases(legal_only: bool = False) -> list:
    """Every oracle folder (with its ``answer.json``), as pytest params: the copied
    corpus, then the shared one's extra folders, or for each of those a param that
    skips saying why."""
    cases = [pytest.param(p.parent, id=f"{p.parent.parent.name}/{p.parent.name}")
             for p in sorted(ORACLE.glob("*/*/answer.json"))]
    for name in NOT_COPIED:
        folder = SHARED_ORACLE / name
        if (folder / "answer.json").is_file():
            cases.append(pytest.param(folder, id=name))
        else:
            cases.append(pytest.param(None, id=name, marks=pytest.mark.skip(
                reason=f"{name} is not copied into tests/data (its repository states no licence);"
                       " it runs when ../shared/oracle is beside the project")))
    if legal_only:
        cases = [c for c in cases if "illegal" not in c.id]
    return cases

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
    """The folder of nets written by other tools (copied into the tests)."""
    return ORACLE


def pytest_collection_modifyitems(config, items):
    """The smoke tests of the benchmarks (files named ``test_bench*`` or ``*bench_smoke*``)
    are ``slow``: they run each benchmark end to end. The default run leaves ``slow``
    tests out; ``scripts/test.sh`` runs them too under CI (see README)."""
    for item in items:
        name = item.path.name
        if name.startswith("test_bench") or "bench_smoke" in name:
            item.add_marker(pytest.mark.slow)


def pytest_unconfigure(config):
    """Name the random test order's seed on the very last line, where ``-q`` leaves it (it
    hides the header pytest-randomly prints it in): the same order runs again with it."""
    seed = getattr(config.option, "randomly_seed", None)
    reporter = config.pluginmanager.get_plugin("terminalreporter")
    if reporter is not None and config.pluginmanager.hasplugin("randomly") and isinstance(seed, int):
        reporter.write_line(f"random test order seed {seed}: rerun this order with"
                            f" bash scripts/test.sh --randomly-seed={seed}")
