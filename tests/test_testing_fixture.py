"""Testing one's own action: the test kit loads a net as `petriflow run` does (its run
configuration's action modules and world), says so when a firing outlives the test's
timeout, and the `petriflow_net` pytest fixture makes a user's test three lines."""

from __future__ import annotations

import subprocess
import sys
import textwrap

import pytest

from petriflow.testing import FiringTimeout, fire_one

NET = """petriflow: 1
run: run.yaml
places: [{id: parked, tokens: 1}, charged, docked]
transitions:
  - {id: charge, action: usertest.charge, params: {minutes: 0.5}, in: [parked], out: [charged]}
  - {id: dock, action: core.wait, params: {seconds: 1}, in: [charged], out: [docked]}
"""

MODULE = '''
from petriflow import ActionFailure, Param, action

@action("usertest.charge", params={"minutes": Param(float, 5.0), "stuck": Param(bool, False)})
def charge(ctx):
    while ctx.params["stuck"]:
        yield 60.0
    yield ctx.params["minutes"] * 60
    return {"battery": 1.0}
'''


@pytest.fixture
def folder(tmp_path, request):
    """The user's folder; the module gets a name of its own per test (one process
    imports a module name once)."""
    module = f"usermodule_{request.node.name.replace('-', '_')}"
    (tmp_path / "net.yaml").write_text(NET)
    (tmp_path / "run.yaml").write_text(f"actions: [{module}]\n")
    (tmp_path / f"{module}.py").write_text(MODULE.replace("usertest.charge", f"usertest.{module}"))
    (tmp_path / "net.yaml").write_text(NET.replace("usertest.charge", f"usertest.{module}"))
    return tmp_path


def test_fire_one_loads_the_run_configurations_action_modules(folder):
    """No hand import of the user's module: the configuration the net names brings it."""
    fired = fire_one(folder / "net.yaml", "charge")
    assert fired.outcome == "ok" and fired.result == {"battery": 1.0} and fired.time == 30.0
    fired = fire_one(folder / "net.yaml", "dock", {"charged": 1})
    assert fired.marking == {"docked": 1}


def test_a_firing_that_outlives_the_timeout_is_an_error_naming_it(folder):
    text = (folder / "net.yaml").read_text()
    (folder / "net.yaml").write_text(text.replace("minutes: 0.5}", "minutes: 0.5, stuck: true}"))
    with pytest.raises(FiringTimeout, match=r"transition 'charge' \(action usertest\.\w+\) was still running"
                                            r" after 600 s of simulated time"):
        fire_one(folder / "net.yaml", "charge", timeout=600)


def test_the_petriflow_net_fixture_is_three_lines(folder):
    """A user's test file beside their net, run by pytest in that folder: the fixture
    comes with petriflow (a pytest plugin), nothing to import."""
    (folder / "test_mine.py").write_text(textwrap.dedent('''
        def test_charge(petriflow_net):
            fired = petriflow_net("net.yaml").fire("charge")
            assert fired.outcome == "ok" and fired.result == {"battery": 1.0}
    '''))
    done = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-p", "no:randomly",
                           "test_mine.py"], cwd=folder, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
    assert "1 passed" in done.stdout
