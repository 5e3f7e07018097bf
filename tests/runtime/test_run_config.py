"""A net names its run configuration; a configuration imports the user's action modules."""

import pytest

from petriflow.cli import main
from petriflow.errors import NetFormatError
from petriflow.io import load_net, save_net
from petriflow.outcome import StopReason
from petriflow.runtime.session import prepare, run_files

TICKER = """petriflow: 1
run: {RUN}
places: [{id: p, tokens: 1}, count]
transitions:
  - {id: tick, action: core.wait, params: {seconds: 0.5}, in: [p], out: [p, count]}
"""


def write(tmp_path, name, text):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_the_net_names_its_run_inline(tmp_path):
    net = write(tmp_path, "ticker.yaml", TICKER.replace("{RUN}", "{until: 2, seed: 7}"))
    outcome = run_files(net)
    assert (outcome.result.reason, outcome.result.time, outcome.result.firings) == (StopReason.UNTIL, 2.0, 5)


def test_the_net_names_a_run_file_beside_it_and_options_override_it(tmp_path):
    write(tmp_path, "fast.yaml", "until: 1\n")
    write(tmp_path, "slow.yaml", "until: 3\n")
    net = write(tmp_path, "ticker.yaml", TICKER.replace("{RUN}", "fast.yaml"))
    assert run_files(net).result.time == 1.0
    assert run_files(net, config=tmp_path / "slow.yaml").result.time == 3.0
    assert run_files(net, until=2.5).result.time == 2.5


def test_a_missing_run_file_is_named(tmp_path, capsys):
    net = write(tmp_path, "ticker.yaml", TICKER.replace("{RUN}", "nowhere.yaml"))
    assert main(["run", str(net)]) == 2
    assert "run configuration 'nowhere.yaml' not found" in capsys.readouterr().err


def test_pnml_keeps_the_run_it_names(tmp_path):
    net = load_net(write(tmp_path, "ticker.yaml", TICKER.replace("{RUN}", "{until: 2, seed: 7}")))
    save_net(net, tmp_path / "ticker.pnml")
    back = load_net(tmp_path / "ticker.pnml")
    assert back.run == {"until": 2, "seed": 7} and back.structure() == net.structure()
    assert run_files(tmp_path / "ticker.pnml").result.time == 2.0


def test_the_world_of_the_named_run_is_used(tmp_path):
    """nets/smart/crossing.yaml names world-crossing.yaml (not run.yaml's world.yaml)."""
    from tests.conftest import NETS

    prepared = prepare(NETS / "smart" / "crossing.yaml")
    assert prepared.world.name == "world-crossing.yaml"
    assert prepare(NETS / "smart" / "smart.yaml").world.name == "world.yaml"


USER_MODULE = '''
from petriflow import Action, ActionFailure, Param, Status, action


@action("mine.gripper")
class Gripper(Action):
    params = {"force": Param(float, 1.0)}
    needs_world = False

    def setup(self, world):
        raise ActionFailure("gripper not calibrated")


@action("mine.report")
def report(ctx):
    return {"reported": ctx.token()}
'''

USER_NET = """petriflow: 1
run: {actions: [my_actions], until: 10}
places: [{id: i, tokens: 1}, held, trouble, o]
transitions:
  - {id: grab, action: mine.gripper, params: {force: 2}, in: [i], out: [held], outcomes: {failed: [trouble]}}
  - {id: report, action: mine.report, in: [trouble], out: [o]}
final: {o: 1}
"""


def test_a_run_configuration_imports_the_users_action_module(tmp_path, capsys):
    """The user's module beside the net registers its actions; its gripper's setup()
    raises, so grab fails and the net's failure route completes the run."""
    write(tmp_path, "my_actions.py", USER_MODULE)
    net = write(tmp_path, "cell.yaml", USER_NET)
    trace = tmp_path / "cell.jsonl"
    assert main(["run", str(net), "--trace", str(trace)]) == 0
    out = capsys.readouterr().out
    assert "final at t = 0 s after 2 firings" in out
    text = trace.read_text()
    assert '"reason":"setup() failed: gripper not calibrated"' in text
    assert main(["check", str(net)]) != 2          # check binds the same way (and analyses)


def test_an_action_module_that_does_not_import_is_one_line(tmp_path, capsys):
    net = write(tmp_path, "cell.yaml", USER_NET.replace("my_actions", "no_such_module"))
    assert main(["info", str(net), "--import-actions"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"petriflow: {net}: 'actions': cannot import action module 'no_such_module'")
    assert "ModuleNotFoundError" in err and len(err.splitlines()) == 1


def test_the_net_file_itself_never_imports(tmp_path):
    """Naming an action does not import anything: a module is imported only from a run
    configuration's actions list."""
    write(tmp_path, "my_actions.py", "raise SystemExit('imported!')\n")
    net = write(tmp_path, "cell.yaml", USER_NET.replace("{actions: [my_actions], until: 10}", "{until: 1}")
                .replace("mine.gripper", "my_actions.gripper"))
    with pytest.raises(NetFormatError, match="unknown action 'my_actions.gripper'"):
        prepare(net)
