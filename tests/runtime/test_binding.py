"""Binding at load: every action, parameter, port and guard resolved before anything
runs; check, info and run report a bad one as file:line with close matches, exit 2."""

import pytest

from petriflow.cli import main
from petriflow.errors import NetFormatError
from petriflow.io import load_net
from petriflow.io.yaml import loads_net
from petriflow.runtime import registry as registry_module
from petriflow.runtime.binding import bind
from petriflow.runtime.registry import Registry

BAD_ACTION = """petriflow: 1
places: [{id: a, tokens: 1}, b]
transitions:
  - id: t
    action: core.wiat
    params: {seconds: 2}
    in: [a]
    out: [b]
"""

BAD_PARAM = """petriflow: 1
places: [{id: a, tokens: 1}, b]
transitions:
  - id: t
    action: core.wait
    params:
      seconds: 2
      secnds: 3
    in: [a]
    out: [b]
"""


@pytest.mark.parametrize("command", ["check", "info", "run"])
def test_unknown_action_is_one_line_with_file_line_and_close_match(tmp_path, capsys, command):
    path = tmp_path / "net.yaml"
    path.write_text(BAD_ACTION)
    assert main([command, str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert err == (f"petriflow: {path}:5: 't': unknown action 'core.wiat' (did you mean 'core.wait'"
                   " or 'core.set' or 'core.fail'?)")


@pytest.mark.parametrize("command", ["check", "info", "run"])
def test_misspelt_parameter_names_its_own_line(tmp_path, capsys, command):
    path = tmp_path / "net.yaml"
    path.write_text(BAD_PARAM)
    assert main([command, str(path)]) == 2
    err = capsys.readouterr().err
    assert f"{path}:8: 't': action has no parameter 'secnds' (did you mean 'seconds'?)" in err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1


def test_unknown_guard_names_the_guard_line():
    net = loads_net("petriflow: 1\nplaces: [a]\ntransitions:\n  - id: t\n    guard: nope\n    in: [a]\n",
                    path="g.yaml")
    with pytest.raises(NetFormatError, match=r"^g.yaml:5: 't': unknown guard 'nope'"):
        bind(net)


def test_pnml_errors_name_the_transition_line(tmp_path, capsys):
    """A PNML net binds the same way, naming the line of its <action> element."""
    from petriflow.io.pnml import dumps_pnml

    text = dumps_pnml(loads_net(BAD_ACTION))
    path = tmp_path / "net.pnml"
    path.write_text(text)
    line = next(n for n, row in enumerate(text.splitlines(), 1) if "core.wiat" in row)
    assert main(["check", str(path)]) == 2
    assert f"{path}:{line}: 't': unknown action 'core.wiat'" in capsys.readouterr().err


def test_port_must_name_a_place(tmp_path):
    net = loads_net("""petriflow: 1
places: [{id: a, tokens: 1}, b, scene]
transitions:
  - {id: plan, action: planning.astar, params: {robot: red, scene: scen}, in: [a], out: [b]}
""", path="p.yaml")
    with pytest.raises(NetFormatError, match="p.yaml:4: 'plan': port 'scene' names unknown place 'scen'"
                                             r" \(did you mean 'scene'\?\)"):
        bind(net)


def test_a_plugin_that_fails_to_load_is_named_when_a_name_is_missing(monkeypatch):
    """An action plugin whose import fails does not hide the others; asking for a name
    nothing provides reports the plugin's error."""

    class Broken:
        name = "robots"

        def load(self):
            raise ModuleNotFoundError("No module named 'robot_sdk'")

    monkeypatch.setattr(registry_module, "entry_points", lambda group: [Broken()])
    registry = Registry()
    with pytest.raises(Exception, match="unknown action 'arm.grab' \\(plugin 'robots' failed to load: "
                                        "ModuleNotFoundError: No module named 'robot_sdk'\\)"):
        registry.resolve("arm.grab")


def test_a_lazy_target_that_fails_to_import_is_reported_with_its_error():
    registry = Registry(load_plugins=False)
    registry.register("arm.grab", "robot_sdk.actions:Grab")
    net = loads_net("petriflow: 1\nplaces: [a]\ntransitions: [{id: t, action: arm.grab, in: [a]}]\n",
                    path="n.yaml")
    with pytest.raises(NetFormatError, match="n.yaml:3: 't': action 'arm.grab': cannot load "
                                             "'robot_sdk.actions:Grab': No module named 'robot_sdk'"):
        bind(net, registry)


def test_every_shipped_net_binds_with_its_lines_kept():
    """The loader keeps the line of each transition, for errors found later."""
    from tests.conftest import NETS

    net = load_net(NETS / "passage" / "passage.yaml")
    assert net.lines["red_enter"] > net.lines["red_approach"] > 0
    assert set(bind(net).actions()) == set(net.actions())
