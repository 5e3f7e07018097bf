"""Looking at a net never runs its code (docs/security.md).

A folder holds a net (YAML and PNML) whose run configuration names an action module
that writes a marker file when it is imported. Every command that only looks at the
net leaves no marker (``info`` and ``check`` read the module's declarations from its
source instead, and check the net against them fully); running it, and
``--import-actions``, import the module.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from petriflow.io import load_net, save_net

NET = """petriflow: 1
run: run.yaml
places: [{id: i, tokens: 1}, o]
transitions:
  - {id: dock, action: trusttest.charge, params: {minutes: 2}, in: [i], out: [o]}
final: {o: 1}
"""

MODULE = '''
from pathlib import Path
Path(__file__).with_name("MARKER").write_text("imported")
from petriflow import Param, action

@action("trusttest.charge", params={"minutes": Param(float, 5.0)})
def charge(ctx):
    yield ctx.params["minutes"] * 60
'''


@pytest.fixture
def folder(tmp_path: Path) -> Path:
    (tmp_path / "net.yaml").write_text(NET)
    (tmp_path / "run.yaml").write_text("actions: [trustmodule]\n")
    (tmp_path / "trustmodule.py").write_text(MODULE)
    # the PNML twin, written by petriflow itself (the run reference travels in toolspecific)
    save_net(load_net(tmp_path / "net.yaml"), tmp_path / "net.pnml")
    assert "run.yaml" in (tmp_path / "net.pnml").read_text()
    return tmp_path


def _petriflow(folder: Path, *argv: str) -> subprocess.CompletedProcess:
    """The command line in a fresh process (an import in this one would hide the effect)."""
    return subprocess.run([sys.executable, "-m", "petriflow.cli", *argv], cwd=folder, capture_output=True,
                          text=True, timeout=300)


#: Every command that only looks, run one after another in one fresh process (one
#: interpreter start for all of them); after each, whether the marker exists.
LOOK = """
import contextlib, io, json, sys
from pathlib import Path
from petriflow.cli import main
report = []
for argv in json.loads(sys.argv[1]):
    err = io.StringIO()
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
        code = main(argv)
    report.append({"argv": argv, "code": code, "err": err.getvalue(), "marker": Path("MARKER").exists()})
print(json.dumps(report))
"""

LOOKING = [["info"], ["info", "--json"], ["check"], ["export", "-o", "copy.yaml"],
           ["export", "-f", "dot", "-o", "n.dot"], ["simulate", "--steps", "5"], ["fire", "dock"]]


def test_commands_that_look_never_import_the_nets_code(folder):
    import json

    argv = [[command[0], net, *command[1:]] for net in ("net.yaml", "net.pnml") for command in LOOKING]
    done = subprocess.run([sys.executable, "-c", LOOK, json.dumps(argv)], cwd=folder, capture_output=True,
                          text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    for step in json.loads(done.stdout):
        command = step["argv"][0]
        assert step["code"] == 0, step
        assert not step["marker"], f"{' '.join(step['argv'])} imported the action module"
        if command in ("info", "check"):  # checked from the module's source: nothing left unchecked
            assert step["err"] == "", step


def test_replay_imports_nothing(folder):
    done = _petriflow(folder, "run", "net.yaml", "--trace", "t.jsonl")
    assert done.returncode == 0, done.stderr
    (folder / "MARKER").unlink()
    done = _petriflow(folder, "replay", "t.jsonl", "--net", "net.yaml", "--draw", "end.svg")
    assert done.returncode == 0, done.stderr
    assert not (folder / "MARKER").exists()


@pytest.mark.parametrize("net", ["net.yaml", "net.pnml"])
def test_import_actions_checks_them_fully(folder, net):
    done = _petriflow(folder, "info", net, "--import-actions")
    assert done.returncode == 0 and done.stderr == "", done.stderr
    assert (folder / "MARKER").exists()


def test_looking_finds_what_importing_finds(folder):
    """A misspelt parameter of a user action: looking (the module read, not imported)
    gives the same file:line error as --import-actions and as running."""
    (folder / "net.yaml").write_text(NET.replace("minutes: 2", "minuets: 2"))
    looked = _petriflow(folder, "check", "net.yaml")
    assert not (folder / "MARKER").exists()
    checked = _petriflow(folder, "check", "net.yaml", "--import-actions")
    ran = _petriflow(folder, "run", "net.yaml")
    error = "net.yaml:5: 'dock': action has no parameter 'minuets' (did you mean 'minutes'?)"
    for done in (looked, checked, ran):
        assert done.returncode == 2 and error in done.stderr, done.stderr
    assert looked.stderr == checked.stderr == ran.stderr


def test_an_action_no_module_could_provide_is_still_an_error(folder):
    (folder / "run.yaml").write_text("seed: 1\n")
    done = _petriflow(folder, "info", "net.yaml")
    assert done.returncode == 2 and "unknown action 'trusttest.charge'" in done.stderr
    assert not (folder / "MARKER").exists()


def test_running_imports_the_module(folder):
    done = _petriflow(folder, "run", "net.yaml")
    assert done.returncode == 0, done.stderr
    assert (folder / "MARKER").exists()


def test_the_python_api_imports_when_asked(folder):
    code = ("from petriflow.runtime.session import prepare; import sys;"
            "p = prepare('net.yaml', import_actions=sys.argv[1] == 'yes');"
            "print(len(p.binding.unchecked))")
    for asked, unchecked, marker in (("no", "0", False), ("yes", "0", True)):
        done = subprocess.run([sys.executable, "-c", code, asked], cwd=folder, capture_output=True, text=True,
                              timeout=300)
        assert done.returncode == 0, done.stderr
        assert done.stdout.strip() == unchecked
        assert (folder / "MARKER").exists() == marker
