"""The SMART actions on their own: frames, guards, collision orders, path following
with reinsertion and re-planning, holding, pushing."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest
from petriflow.agents.smart.actions import Avoid, Follow, Send, frame_record, simplify
from petriflow.agents.smart.guards import help_needed
from petriflow.agents.smart.messages import ActionId, Command

from petriflow.errors import NetFormatError
from petriflow.io.yaml import loads_net
from petriflow.runtime.registry import default_registry
from petriflow.runtime.binding import bind
from petriflow.runtime.scheduler import Scheduler
from petriflow.testing import check_action, fire_one
from tests.agents.smart.conftest import place


def one(action: str, params: str, out: str = "b") -> str:
    return f"""
petriflow: 1
places: [{{id: a, tokens: 1}}, b, failed]
transitions: [{{id: t, action: {action}, params: {params}, in: [a], out: [{out}], outcomes: {{failed: [failed]}}}}]
"""


def pose(x, y):
    return SimpleNamespace(position=(x, y), area=5000.0, pixel=(0.0, 0.0), heading=0.0)


def scene(**robots):
    return SimpleNamespace(robots={c: pose(*xy) for c, xy in robots.items()}, label_map=np.zeros((4, 4)),
                           segmented=None, metres_per_pixel=None)


def test_plugin_registers_the_smart_actions_and_guard():
    names = set(default_registry.names())
    assert {"smart.capture", "smart.dispatch", "smart.send", "smart.follow", "smart.avoid",
            "smart.push"} <= names
    assert default_registry.guard("smart.help_needed") is help_needed


@pytest.mark.parametrize("cls", [Send, Avoid])
def test_world_free_actions_pass_the_conformance_check(cls):
    params = {Send: {"commands": [["STOP", "red"]]}, Avoid: {"priorities": {"yellow": 2, "blue": 1}}}[cls]
    assert check_action(cls, params) == []


def test_frame_record_shows_the_bytes_and_the_command():
    record = frame_record(Command(ActionId.MOVE_TO, 4, (37, 44)))   # '%' and ',' as parameters
    assert record["hex"] == "01 04 2c 25 2c 2c 25"
    assert (record["action"], record["robot"], record["params"]) == ("MOVE_TO", 4, [37, 44])


def test_send_encodes_its_commands():
    fired = fire_one(loads_net(one("smart.send", "{commands: [[HOLD, yellow], [move_to, 2, 10, 20]]}")), "t")
    assert fired.outcome == "ok"
    assert [f["hex"] for f in fired.result["frames"]] == ["06 04 25", "01 02 2c 0a 2c 14 25"]


@pytest.mark.parametrize("commands, match", [("[[JUMP, red]]", "JUMP"), ("[[STOP, purple]]", "purple"),
                                             ("[[MOVE_TO, red, 300, 1]]", "one byte")])
def test_send_rejects_bad_commands_when_the_net_is_bound(commands, match):
    with pytest.raises(NetFormatError, match=match):
        bind(loads_net(one("smart.send", f"{{commands: {commands}}}")))


def test_simplify_keeps_the_corners():
    square = [(0, 0), (0.5, 0), (1, 0), (1, 0.5), (1, 1), (0.5, 1.005), (0, 1)]
    assert simplify(square, 0.01) == [0, 2, 4, 6]


def test_help_needed_wants_the_helper_up_and_the_other_robot_down():
    labels = np.zeros((100, 100), np.uint8)
    labels[10:20, 10:40] = 2                                        # red, seen without its discs
    down = SimpleNamespace(robots={"yellow": pose(0, 0)}, segmented=labels, metres_per_pixel=0.01,
                           origin=(0, 0))
    assert help_needed({"P6": [down]}, {"helper": "yellow", "fallen": "red"})
    nobody = SimpleNamespace(robots={"yellow": pose(0, 0)}, segmented=np.zeros_like(labels),
                             metres_per_pixel=0.01, origin=(0, 0))
    assert not help_needed({"P6": [nobody]}, {"helper": "yellow", "fallen": "red"})


AVOID = """
petriflow: 1
places: [a, b, orders]
transitions: [{id: t, action: smart.avoid, params: {priorities: {yellow: 2, blue: 1}, step: 0.08, radius: 0.13,
               orders: orders}, in: [a, orders], out: [b, orders]}]
"""


def avoid_orders(*scenes):
    """Fire smart.avoid once per scene (one run: the avoidance keeps its state); the
    standing orders token at the end, and the custom events."""
    run = Scheduler(loads_net(AVOID), seed=1)
    run.set_tokens({"a": list(scenes), "orders": [None]})
    events = []
    run.on_event(events.append)
    result = run.run()
    assert result.firings == len(scenes)
    custom = [(e.data["name"], e.data["data"]) for e in events if e.kind == "custom"]
    return result.tokens["orders"][0], custom


def test_avoid_holds_the_lower_priority_robot_and_replans_the_other():
    """Closer than two steps: blue (priority 1) holds with a STOP frame, yellow (2)
    re-plans; the orders are the token of the orders place, given back updated."""
    orders, custom = avoid_orders(scene(yellow=(0.0, 0.0), blue=(1.0, 0.0)))
    assert orders == {"blue": {"order": "go", "others": [], "t": 0.0},
                      "yellow": {"order": "go", "others": [], "t": 0.0}}
    orders, custom = avoid_orders(scene(yellow=(0.0, 0.0), blue=(1.0, 0.0)),
                                  scene(yellow=(0.0, 0.0), blue=(0.40, 0.0)),
                                  scene(yellow=(0.0, 0.0), blue=(0.40, 0.0)))
    assert orders["blue"]["order"] == "hold" and orders["blue"]["others"] == ["yellow"]
    assert orders["yellow"]["order"] == "replan" and orders["yellow"]["id"] == 1
    assert [(d["action"], d["robot"]) for name, d in custom if name == "smart.frame"] == [("STOP", 3)]


def test_avoid_releases_the_held_robot_once_the_other_has_passed():
    """Once yellow has passed, blue is told to go; yellow's re-plan order stands (its
    walk obeys an order id once)."""
    orders, custom = avoid_orders(scene(yellow=(0.0, 0.0), blue=(0.40, 0.0)),
                                  scene(yellow=(-0.5, 0.3), blue=(0.40, 0.0)))
    assert orders["blue"]["order"] == "go"
    assert orders["yellow"]["order"] == "replan" and orders["yellow"]["id"] == 1
    assert [(d["robot"], d["order"]) for name, d in custom if name == "smart.order"] == [
        ("blue", "hold"), ("yellow", "replan"), ("blue", "go")]


def test_push_moves_a_body(arena):
    world = arena(settle=0.2)
    before = world.pose("robot3l")
    fired = fire_one(loads_net(one("smart.push", "{robot: robot3l, force: [0, 8, 0], duration: 0.3}")), "t",
                     world=world)
    assert fired.outcome == "ok" and fired.result["moved"] > 0.05
    assert world.pose("robot3l")[1] > before[1]


FOLLOW = one("smart.follow", "{robot: robot3l, colour: yellow, path: PATH, localise: world, radius: 0.15}")


@pytest.mark.slow
def test_follow_reinserts_a_robot_beside_its_path(arena):
    """The robot starts 0.11 m beside the path (dmin = 0.08 <= dc <= r = 0.15): the first
    check reinserts it at the farthest path point within reach; it rejoins the path and
    reaches the end."""
    world = arena(settle=0.2)
    place(world, "robot3l", -0.6, 0.0, 0.0)
    path = [[-0.6, -0.11], [-0.2, -0.11], [0.1, -0.11]]
    fired = fire_one(loads_net(FOLLOW.replace("PATH", str(path))), "t", world=world, timeout=60)
    assert fired.outcome == "ok", fired.reason
    first = fired.result["checks"][0]
    assert first["decision"] == "reinsert" and first["dc"] == pytest.approx(0.11, abs=0.01)
    assert math.dist(first["point"], first["position"]) == pytest.approx(0.16, abs=0.011)   # reach = 2 dmin
    assert first["point"][0] > first["position"][0]                                          # ahead, not back
    later = fired.result["checks"][1:]
    assert any(c["decision"] == "on_track" for c in later)
    assert math.dist(world.pose("robot3l")[:2], path[-1]) < 0.05


def test_follow_fails_for_a_replan_when_far_from_its_path(arena):
    """dc > r: the walk stops at once and fails with decision replan (the net's failure
    arc sends the robot back to its planner)."""
    world = arena(settle=0.2)
    fired = fire_one(loads_net(FOLLOW.replace("PATH", "[[-0.8, -0.2], [0.0, -0.2]]")), "t", world=world)
    assert fired.outcome == "failed" and "re-plan" in fired.reason
    assert fired.marking == {"failed": 1}
    assert fired.tokens["failed"][0]["decision"] == "replan"


def test_follow_holds_while_told_to(arena):
    """A hold order (smart.avoid's, in the place its orders port names) keeps the robot
    standing once its legs are in their posture (the first second); it does not walk."""
    world = arena(settle=0.2)
    net = loads_net("""
petriflow: 1
places: [{id: a, tokens: 1}, b, orders]
transitions:
  - {id: t, action: smart.follow, in: [a], out: [b],
     params: {robot: robot3l, colour: yellow, path: [[-0.8, -0.55], [-0.5, -0.2]], localise: world,
              orders: orders}}
""")
    run = Scheduler(net, world=world, seed=1)
    run.set_tokens({"a": [None], "orders": [{"yellow": {"order": "hold", "others": ["blue"]}}]})
    before = world.pose("robot3l")
    result = run.fire_one("t", timeout=4.0)
    assert result.reason == "until" and run.running() == ["t"]
    assert run.running_actions()["t"].held_for > 2.5
    assert math.dist(world.pose("robot3l")[:2], before[:2]) < 0.03


def test_follow_port_must_name_a_place_of_the_net():
    """The orders and scene ports are checked when the net is bound."""
    with pytest.raises(NetFormatError, match="port 'orders' names unknown place 'order'"):
        bind(loads_net(one("smart.follow", "{orders: order}")))


def test_follow_checks_its_parameters():
    with pytest.raises(NetFormatError, match="must be > 0"):
        bind(loads_net(one("smart.follow", "{step: 0}")))
    assert Follow.check_params({}, "t")["localise"] == "vision"
