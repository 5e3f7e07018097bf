"""Declared, checked needs: the world capabilities an action uses and the settings it reads."""

from __future__ import annotations

import pytest

from petriflow.capabilities import Cameras, Distances, Physics, Poses, missing
from petriflow.errors import NetFormatError, PetriflowError
from petriflow.io.yaml import loads_net
from petriflow.runtime.action import Action, InstantAction
from petriflow.runtime.binding import bind
from petriflow.runtime.config import RunConfig
from petriflow.runtime.loading import read_run
from petriflow.runtime.registry import Registry
from petriflow.runtime.scheduler import Scheduler
from petriflow.runtime.settings import Section, Setting
from petriflow.runtime.validation import check_run, validate
from petriflow.testing import StubWorld

NET = """\
petriflow: 1
places: [{id: i, tokens: 1}, o]
transitions:
  - id: look
    action: demo.look
    in: [i]
    out: [o]
"""

ARENA = Section("arena", {
    "floor": Setting(str, "white", "the floor's colour", choices=("white", "grey")),
    "speed": Setting(float, 0.5, "cruise speed (m/s)", low=0),
    "markers": Setting(list, [], "one per robot", items=Setting(dict, fields={
        "robot": Setting(str, doc="the robot's body"), "colour": Setting(str, "red")})),
})


class Look(InstantAction):
    """Uses the world's cameras."""

    uses = (Cameras,)

    def run(self, ctx):
        return sorted(ctx.world.cameras)


class Near(InstantAction):
    """Uses distances only: what a stub world gives."""

    uses = (Distances,)

    def run(self, ctx):
        return ctx.world.distance("a", "b")


class Read(InstantAction):
    """Reads the arena settings."""

    settings = ARENA

    def run(self, ctx):
        return dict(ctx.settings)


def registry_with(action: type[Action]) -> Registry:
    made = Registry(load_plugins=False)
    made.register("demo.look", action)
    return made


class Flatland:
    """A world made in code: it steps, and has a meta of a world file."""

    dt = 0.1
    path = "flat.yaml"

    def __init__(self, meta=None) -> None:
        self.meta = meta or {}

    def step(self) -> None:
        pass


def test_the_core_world_provides_every_capability():
    from petriflow.world import World

    for capability in (Cameras, Poses, Physics):
        assert missing(World, capability) == []


def test_a_world_lacking_a_used_capability_is_refused_with_the_transition_line():
    net = loads_net(NET, path="look.yaml")
    with pytest.raises(NetFormatError) as caught:
        Scheduler(net, registry=registry_with(Look), world=Flatland())
    assert str(caught.value) == ("look.yaml:5: 'look': action demo.look uses the world's cameras (Cameras), which"
                                 " this run's world (Flatland) lacks: cameras, camera")


def test_a_run_without_a_world_is_refused_for_an_action_that_uses_one():
    net = loads_net(NET, path="look.yaml")
    with pytest.raises(NetFormatError, match="look.yaml:5: 'look': action demo.look needs a world"):
        validate(net, RunConfig(), registry=registry_with(Look), world=None)


def test_a_world_file_provides_what_actions_use():
    """A world file is a petriflow World: checked by its class, before it is built."""
    net = loads_net(NET, path="look.yaml")
    assert validate(net, RunConfig(), registry=registry_with(Look), world=True).checked


def test_an_action_calls_what_it_declared_without_probing():
    net = loads_net(NET)
    world = StubWorld(positions={"a": (0.0, 0.0), "b": (3.0, 4.0)})
    result = Scheduler(net, registry=registry_with(Near), world=world).run()
    assert result.tokens == {"o": [5.0]}


def test_settings_are_read_with_their_defaults():
    net = loads_net(NET)
    world = Flatland({"arena": {"speed": 2, "markers": [{"robot": "r1"}]}, "other": "left alone"})
    result = Scheduler(net, registry=registry_with(Read), world=world).run()
    assert result.tokens["o"] == [{"floor": "white", "speed": 2.0, "markers": [{"robot": "r1", "colour": "red"}]}]


def test_a_run_without_a_world_reads_the_defaults():
    result = Scheduler(loads_net(NET), registry=registry_with(Read)).run()
    assert result.tokens["o"][0]["speed"] == 0.5


@pytest.mark.parametrize("meta, line, message", [
    ("  arena:\n    speed: fast\n", 5, "'meta.arena': setting 'speed' must be float, got 'fast'"),
    ("  arena:\n    floor: white\n    sped: 1\n", 6, "'meta.arena': unknown setting 'sped' (did you mean 'speed'?)"),
    ("  arena:\n    markers:\n      - {robot: r1, colour: 3}\n", 6,
     "'meta.arena.markers[0]': setting 'colour' must be str, got 3"),
    ("  arena:\n    markers:\n      - {colour: red}\n", 6, "'meta.arena.markers[0]': missing setting 'robot'"),
    ("  arena: [1, 2]\n", 4, "meta.arena is a mapping of settings"),
])
def test_a_bad_setting_fails_when_the_world_file_is_loaded_naming_its_line(tmp_path, meta, line, message):
    (tmp_path / "net.yaml").write_text(NET)
    (tmp_path / "world.yaml").write_text(f"dt: 0.01\nplane: false\nmeta:\n{meta}")
    files = read_run(tmp_path / "net.yaml", world=tmp_path / "world.yaml")
    with pytest.raises(NetFormatError) as caught:
        check_run(files, registry=registry_with(Read))
    assert str(caught.value).startswith(f"{tmp_path / 'world.yaml'}:{line}: ") and message in str(caught.value)


def test_the_world_file_settings_are_checked_and_kept_for_the_run(tmp_path):
    (tmp_path / "net.yaml").write_text(NET)
    (tmp_path / "world.yaml").write_text("plane: false\nmeta:\n  arena: {floor: grey}\n  notes: anything\n")
    checked = check_run(read_run(tmp_path / "net.yaml", world=tmp_path / "world.yaml"), registry=registry_with(Read))
    assert checked.settings == {"arena": {"floor": "grey", "speed": 0.5, "markers": []}}


def test_one_section_has_one_declaration():
    other = Section("arena", {"floor": Setting(str, "black")})
    made = registry_with(Read)
    made.register("demo.other", type("Other", (InstantAction,), {"settings": other, "run": lambda s, c: None}))
    net = loads_net(NET + "  - {id: again, action: demo.other, in: [o], out: [i]}\n", path="two.yaml")
    with pytest.raises(NetFormatError, match="two.yaml:8: 'again': action demo.other reads the world's settings"
                                             " 'arena' declared otherwise by the action of 'look'"):
        bind(net, made)


def test_settings_are_only_for_an_action_that_declares_them():
    made = registry_with(Near)
    made.register("demo.read", type("Undeclared", (InstantAction,), {"run": lambda self, ctx: ctx.settings}))
    net = loads_net(NET.replace("demo.look", "demo.read"))
    result = Scheduler(net, registry=made).run()
    assert "the action declares no world settings" in result.error


def test_a_context_outside_a_run_says_what_it_lacks():
    from petriflow.runtime.action import ActionContext

    ctx = ActionContext("t", None, {}, {}, None, 0, 0.0, action=Read)
    for use in (lambda: ctx.state, lambda: ctx.settings, lambda: ctx.link("p")):
        with pytest.raises(PetriflowError, match="'t': no run to"):
            use()
    assert ctx.running("anyone") is True


def test_a_resource_reads_the_settings_it_declares():
    """A scenario's resource declares its section: a run whose actions use the resource
    reads and checks it, and the factory gets the values."""
    made = Registry(load_plugins=False)
    made.register_resource("demo.arena", lambda context: context.settings["arena"]["floor"], settings=ARENA)
    made.register("demo.look", type("Floor", (InstantAction,), {"resources": {"arena": "demo.arena"},
                                                              "run": lambda self, ctx: ctx.resource("arena")}))
    result = Scheduler(loads_net(NET), registry=made, world=Flatland({"arena": {"floor": "grey"}})).run()
    assert result.tokens["o"] == ["grey"]
    with pytest.raises(NetFormatError, match="'meta.arena': setting 'floor' must be one of"):
        Scheduler(loads_net(NET), registry=made, world=Flatland({"arena": {"floor": "pink"}}))
