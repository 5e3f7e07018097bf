"""``info`` and ``check`` refuse what ``run`` refuses, without running the net's code.

A user's ``charger`` net names a core action and the user's own ``mycharger.charge``,
from the module ``mycharger.py`` its ``run.yaml`` lists. The module writes a marker file
and raises when imported: looking at the net must never import it (docs/security.md),
so the checks come from reading its source. A misspelt core action, a misspelt
parameter and a wrong type of the user's action are the same ``file:line`` errors,
exit 2, as ``run`` gives; a correct net passes with nothing left unchecked; what the
source cannot tell is listed as not checked, with the reason.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from petriflow.cli import main

NET = """petriflow: 1
run: run.yaml
places: [{id: home, tokens: 1}, docked, charged]
transitions:
  - id: settle
    action: core.wait
    params: {seconds: 1}
    in: [home]
    out: [docked]
  - id: charge
    action: mycharger.charge
    params:
      minutes: 2
    in: [docked]
    out: [charged]
final: {charged: 1}
"""

MODULE = '''
from pathlib import Path
Path(__file__).with_name("MARKER").write_text("imported")
if not __import__("os").environ.get("MYCHARGER_IMPORTABLE"):
    raise RuntimeError("mycharger must not be imported by a command that only looks")

from petriflow import Param, action

@action("mycharger.charge", params={"minutes": Param(float, 5.0, low=0)})
def charge(ctx):
    yield ctx.params["minutes"] * 60
    return {"battery": 1.0}

for side in ("left", "right"):
    action(f"mycharger.plug_{side}")(lambda ctx: None)
'''


@pytest.fixture
def charger(tmp_path: Path) -> Path:
    (tmp_path / "charger.yaml").write_text(NET)
    (tmp_path / "run.yaml").write_text("seed: 1\nactions: [mycharger]\n")
    (tmp_path / "mycharger.py").write_text(MODULE)
    return tmp_path


def _look(charger: Path, capsys, command: str, *options: str) -> tuple[int, str, str]:
    code = main([command, str(charger / "charger.yaml"), *options])
    out, err = capsys.readouterr()
    assert not (charger / "MARKER").exists(), f"{command} imported the action module"
    return code, out, err


TYPOS = [
    ("action: core.wait", "action: core.wiat", 6,
     "'settle': unknown action 'core.wiat' (did you mean 'core.wait'"),
    ("minutes: 2", "minuts: 2", 13,
     "'charge': action has no parameter 'minuts' (did you mean 'minutes'?) (it takes: minutes)"),
    ("minutes: 2", "minutes: two", 13, "'charge': parameter 'minutes' must be float, got 'two'"),
    ("minutes: 2", "minutes: -1", 13, "'charge': parameter 'minutes' must be >= 0, got -1.0"),
    ("action: mycharger.charge", "action: mycharger.chrage", 11,
     "'charge': unknown action 'mycharger.chrage' (did you mean 'mycharger.charge'?)"),
]


@pytest.mark.parametrize("command", ["check", "info"])
@pytest.mark.parametrize("right, wrong, line, error", TYPOS, ids=["core", "param", "type", "range", "user-name"])
def test_a_typo_is_the_error_run_gives(charger, capsys, command, right, wrong, line, error):
    (charger / "charger.yaml").write_text(NET.replace(right, wrong))
    code, _, err = _look(charger, capsys, command)
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 1, err
    assert lines[0].startswith(f"petriflow: {charger / 'charger.yaml'}:{line}: {error}"), err
    assert "provided by module" not in err and "Traceback" not in err


@pytest.mark.parametrize("command", ["check", "info"])
def test_a_correct_net_passes_with_nothing_unchecked(charger, capsys, command):
    code, out, err = _look(charger, capsys, command)
    assert code == 0 and err == "", err
    code, out, err = _look(charger, capsys, command, "--json")
    assert code == 0 and err == ""
    if command == "info":
        assert json.loads(out)["not_checked"] == []


def test_a_dynamically_declared_action_is_listed_unchecked_with_the_reason(charger, capsys):
    (charger / "charger.yaml").write_text(NET.replace("action: mycharger.charge\n    params:\n      minutes: 2",
                                                      "action: mycharger.plug_left\n    params: {any: 1}"))
    code, out, err = _look(charger, capsys, "info", "--json")
    assert code == 0, err
    notes = json.loads(out)["not_checked"]
    assert notes == [(f"{charger / 'charger.yaml'}:11: 'charge': action 'mycharger.plug_left' not checked:"
                      " mycharger.py:15 registers an action whose name is not a literal (it starts 'mycharger.plug_')"
                      f" (module 'mycharger.py' named in {charger / 'run.yaml'}:2 is not imported;"
                      " --import-actions to check)")]
    assert err.strip() == f"petriflow: note: {notes[0]}"
    code, _, err = _look(charger, capsys, "check")
    assert code == 0 and err.strip() == f"petriflow: note: {notes[0]}"


def test_a_core_name_is_never_said_to_come_from_the_users_module(charger, capsys):
    """The core namespace is closed even beside a module whose declarations are hidden."""
    (charger / "mycharger.py").write_text(MODULE + "\nfor n in NAMES:\n    action(n)(lambda ctx: None)\n")
    (charger / "charger.yaml").write_text(NET.replace("action: core.wait", "action: core.wiat"))
    code, _, err = _look(charger, capsys, "check")
    assert code == 2 and "unknown action 'core.wiat' (did you mean 'core.wait'" in err
    assert "mycharger" not in err


def test_what_run_and_import_actions_say_is_what_looking_says(charger):
    """The messages come from the same code: run (which imports the module) and
    --import-actions give, byte for byte, what check gives without importing it."""
    (charger / "charger.yaml").write_text(NET.replace("minutes: 2", "minuts: 2"))
    env = {**os.environ, "MYCHARGER_IMPORTABLE": "1"}
    said = {}
    for argv in (["check"], ["check", "--import-actions"], ["run"]):
        done = subprocess.run([sys.executable, "-m", "petriflow.cli", argv[0], "charger.yaml", *argv[1:]],
                              cwd=charger, capture_output=True, text=True, timeout=300, env=env, check=False)
        said[" ".join(argv)] = (done.returncode, done.stderr)
        assert (charger / "MARKER").exists() == (argv != ["check"])
    assert said["check"] == said["check --import-actions"] == said["run"]
    assert said["check"][0] == 2 and "charger.yaml:13: 'charge': action has no parameter 'minuts'" in said["check"][1]
