"""petriflow.testing: one transition of a real net, tested on its own."""

import math

import pytest

from petriflow.errors import NotEnabledError
from petriflow.io import load_net
from petriflow.io.yaml import loads_net
from petriflow.runtime.action import Status
from petriflow.runtime.registry import Registry, default_registry
from petriflow.testing import ScriptedAction, StubWorld, check_action, fire_one
from tests.conftest import NETS


@pytest.fixture
def passage():
    return load_net(NETS / "passage" / "passage.yaml")


@pytest.fixture
def world():
    from petriflow.world import load_world

    world = load_world(NETS / "passage" / "world.yaml")
    yield world
    world.close()


def test_red_approach_drives_red_to_its_waiting_point(passage, world):
    """Firing red_approach alone moves the red robot by its wheels to (-0.8, 0.5)."""
    fired = fire_one(passage, "red_approach", world=world)
    assert fired.outcome == "ok"
    assert fired.marking == {"red_waiting": 1, "blue_home": 1, "mutex": 1}
    x, y, _ = world.pose("red")
    assert math.hypot(x + 0.8, y - 0.5) < 0.05
    assert world.pose("blue")[:2] == pytest.approx((1.4, -1.0), abs=1e-3)  # blue did not move
    assert 1.0 < fired.time < 10.0


def test_enter_needs_the_mutex(passage, world):
    """red_enter is not enabled without the passage token."""
    with pytest.raises(NotEnabledError, match="mutex has 0, needs 1"):
        fire_one(passage, "red_enter", {"red_waiting": 1}, world=world)


def test_scripted_action_counts_its_lifecycle_calls():
    """A scripted double polls its statuses in order, once per tick."""
    Walk = ScriptedAction.script([Status.RUNNING, Status.RUNNING, Status.OK], result="arrived")
    registry = Registry(load_plugins=False)
    registry.register("test.walk", Walk)
    net = loads_net("""
petriflow: 1
places: [{id: a, tokens: 1}, b]
transitions: [{id: walk, action: test.walk, in: [a], out: [b]}]
""")
    fired = fire_one(net, "walk", registry=registry)
    assert (fired.outcome, fired.tokens) == ("ok", {"b": ["arrived"]})
    assert Walk.calls == {"setup": 1, "start": 1, "poll": 3, "cancel": 0, "teardown": 1}


def test_fire_one_reports_a_routed_failure():
    """A failed action's outcome and reason come back."""
    net = loads_net("""
petriflow: 1
places: [{id: a, tokens: 1}, ok, retry]
transitions: [{id: t, action: core.fail, params: {reason: blocked}, in: [a], out: [ok], outcomes: {failed: [retry]}}]
""")
    fired = fire_one(net, "t")
    assert (fired.outcome, fired.reason, fired.marking) == ("failed", "blocked", {"retry": 1})


@pytest.mark.parametrize("name", ["core.noop", "core.wait", "core.set"])
def test_core_actions_pass_the_conformance_check(name):
    """Every core action follows the lifecycle."""
    assert check_action(default_registry.resolve(name)) == []


def test_drive_goto_passes_the_conformance_check(world):
    """drive.goto follows the lifecycle on a real world."""
    cls = default_registry.resolve("drive.goto")
    assert check_action(cls, {"x": -1.2, "y": 1.0, "robot": "red"}, world=world) == []


def test_conformance_check_catches_a_bad_status():
    """An action whose poll returns something else than a Status is reported."""
    from petriflow.runtime.action import Action

    class Broken(Action):
        def poll(self, ctx):
            return True

    assert check_action(Broken) == ["poll() returned True, not a Status"]


def test_stub_world_gives_fixed_positions():
    """The stub world knows agent positions and distances, and counts steps."""
    world = StubWorld(positions={"a": (0, 0), "b": (3, 4)})
    world.step()
    assert (world.distance("a", "b"), world.steps) == (5.0, 1)
