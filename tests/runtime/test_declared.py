"""Declarations read from a module's source (petriflow.runtime.declared) and a net bound
against them without importing the module (bind(..., unimported=[...]))."""

from __future__ import annotations

import re
import sys
from pathlib import Path

import pytest

from petriflow.errors import NetFormatError
from petriflow.io.yaml import loads_net
from petriflow.runtime.action import ActionFailure, Port
from petriflow.runtime.binding import bind, closed_namespaces
from petriflow.runtime.declared import find_source, read_declarations

#: first line of every module here: importing it would fail the test
NEVER = "raise RuntimeError('imported')\n"


def _net(transitions: str, subnets: str = "") -> object:
    """A net of places ``a`` (marked), ``b``, ``box`` and ``transitions`` (YAML list items);
    with ``subnets`` (the head of one subnet), the transitions are that subnet's."""
    if subnets:
        indented = "".join(f"  {line}\n" for line in transitions.splitlines())
        return loads_net(f"petriflow: 1\nplaces: [{{id: a, tokens: 1}}, b, box]\nsubnets:\n{subnets}"
                         f"    transitions:\n{indented}", path="n.yaml")
    return loads_net(f"petriflow: 1\nplaces: [{{id: a, tokens: 1}}, b, box]\ntransitions:\n{transitions}",
                     path="n.yaml")


def _module(folder: Path, source: str, name: str = "shop.py") -> Path:
    path = folder / name
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(NEVER + source)
    return path


CLASSES = """
from petriflow import Action, Param, Port, action
from petriflow.runtime.action import InstantAction
from petriflow.runtime.registry import default_registry as registry

FORCE = 5.0

class Base(InstantAction):
    params = {"force": Param(float, FORCE, low=0), "side": Param(str, "left", choices=("left", "right"))}

class Grab(Base):
    params = {**Base.params, "box": Port(required=True)}
    requires = frozenset({"agent"})

@action("shop.look")
class Look(Action):
    params = dict(zoom=Param(int, 1), mode=Param((str, type(None)), None))

registry.register("shop.grab", Grab)
"""


def test_classes_their_bases_ports_and_requirements_are_read(tmp_path):
    found = read_declarations([str(_module(tmp_path, CLASSES))])
    grab = found.actions["shop.grab"]
    assert sorted(grab.params) == ["box", "force", "side"] and grab.gaps == []
    assert isinstance(grab.params["box"], Port) and grab.requires == {"agent"}
    assert grab.params["side"].choices == ("left", "right") and grab.params["force"].default == 5.0
    assert found.actions["shop.look"].params["mode"].type == (str, type(None))
    module = [str(tmp_path / "shop.py")]
    agent = "  - id: r1\n"
    bound = bind(_net("  - {id: t, action: shop.grab, params: {box: box}, in: [a], out: [b]}\n",
                      subnets=agent), unimported=module)
    assert bound.transitions["t"].ports == {"box": "box"} and bound.unchecked == ()
    assert bound.transitions["t"].params == {"force": 5.0, "side": "left", "box": "box"}
    for params, error in [("{box: bx}", "port 'box' names unknown place 'bx' (did you mean 'box'"),
                          ("{box: box, side: up}", "parameter 'side' must be one of ['left', 'right'], got 'up'"),
                          ("{}", "missing required parameter 'box'")]:
        with pytest.raises(NetFormatError, match=r"^n.yaml:\d+: 't': " + re.escape(error)):
            bind(_net(f"  - {{id: t, action: shop.grab, params: {params}, in: [a], out: [b]}}\n", subnets=agent),
                 unimported=module)
    with pytest.raises(NetFormatError, match="action shop.grab runs as an agent: put the transition in an agent"):
        bind(_net("  - {id: t, action: shop.grab, params: {box: box}, in: [a], out: [b]}\n"), unimported=module)


def test_a_declared_action_cannot_run(tmp_path):
    cls = read_declarations([str(_module(tmp_path, CLASSES))]).actions["shop.look"].action_class()
    with pytest.raises(ActionFailure, match=r"checked from its source \(shop.py:\d+\) without importing it"):
        cls({}).setup(None)


def test_a_package_and_what_it_imports_relatively_are_read(tmp_path):
    _module(tmp_path, "from . import tools\nfrom .more import extra\n", "kit/__init__.py")
    _module(tmp_path, "from petriflow import Param, action\n"
                      "@action('kit.drill', params={'depth': Param(float)})\ndef drill(ctx): pass\n", "kit/tools.py")
    _module(tmp_path, "from petriflow import guard\n@guard('kit.sharp')\ndef sharp(t, p): return True\n",
            "kit/more.py")
    found = read_declarations([str(tmp_path / "kit")])
    assert set(found.actions) == {"kit.drill"} and set(found.guards) == {"kit.sharp"}
    assert found.hidden == {} and found.unread == []


def test_a_module_name_is_found_without_importing_its_package(tmp_path, monkeypatch):
    _module(tmp_path, "", "corp/__init__.py")  # importing the package would raise
    _module(tmp_path, "from petriflow import action\n@action('corp.arm')\ndef arm(ctx): pass\n",
            "corp/robots.py")
    monkeypatch.syspath_prepend(str(tmp_path))
    assert find_source("corp.robots") == (tmp_path / "corp" / "robots.py", "")
    assert find_source("corp.nothing")[0] is None
    assert set(read_declarations(["corp.robots"]).actions) == {"corp.arm"}
    assert "corp" not in sys.modules and "corp.robots" not in sys.modules


def test_what_the_source_cannot_tell_is_listed_with_its_reason(tmp_path):
    module = _module(tmp_path, """
from petriflow import Param, action
from .units import Minutes
import numpy

@action("shop.charge", params={"minutes": Param(Minutes, 5)})
def charge(ctx): pass

for name in ("a", "b"):
    action("loop." + name)(lambda ctx: None)

if __name__ == "__main__":
    action("shop.main_only")(lambda ctx: None)
""")
    net = _net("  - {id: t, action: shop.charge, params: {minutes: two}, in: [a], out: [b]}\n"
               "  - {id: u, action: loop.a, params: {anything: 1}, in: [b], out: [a]}\n"
               "  - {id: v, action: tool.x, in: [a], out: [b]}\n")
    bound = bind(net, unimported=[str(module)])
    notes = {item.transition: item.describe() for item in bound.unchecked}
    assert notes["t"] == ("action 'shop.charge' partly checked: parameter 'minutes': its type 'Minutes' (shop.py:7)"
                          " is not a builtin or petriflow type name, so its values' type is not checked")
    assert notes["u"] == ("action 'loop.a' not checked: shop.py:11 registers an action whose name is not a literal"
                          " (it starts 'loop.')")
    assert notes["v"].startswith("action 'tool.x' not checked: no module read declares it, but shop.py:4 imports"
                                 " '.units', which is not found; shop.py:5 imports 'numpy', which is not read")
    # a name of the module's own namespace that nothing declares (the __main__ block does not run on import)
    with pytest.raises(NetFormatError, match=r"unknown action 'shop.main_only'"):
        bind(_net("  - {id: t, action: shop.main_only, in: [a], out: [b]}\n"), unimported=[str(module)])


@pytest.mark.parametrize("source, reason", [
    ("def broken(:\n", "shop.py:2 cannot be parsed (invalid syntax)"),
    (None, "action module '{missing}' was not found"),
])
def test_a_module_not_read_leaves_its_names_unchecked(tmp_path, source, reason):
    entry = str(_module(tmp_path, source)) if source is not None else str(tmp_path / "missing.py")
    bound = bind(_net("  - {id: t, action: shop.charge, params: {minutes: 2}, in: [a], out: [b]}\n"),
                 unimported=[entry])
    (item,) = bound.unchecked
    assert item.describe() == f"action 'shop.charge' not checked: {reason.format(missing=entry)}"
    with pytest.raises(NetFormatError, match=r"unknown action 'core.wiat' \(did you mean 'core.wait'"):
        bind(_net("  - {id: t, action: core.wiat, in: [a], out: [b]}\n"), unimported=[entry])


def test_guards_and_states_are_read(tmp_path):
    module = _module(tmp_path, """
from petriflow import guard
from petriflow.runtime.registry import default_registry
default_registry.register_state("shop.robot", object)
@guard("shop.idle", reads=("busy",))
def idle(state, params): return True
@guard("shop.free", reads=("busy_{robot}",))
def free(state, params): return True
""")
    agent = "  - id: r1\n    state: shop.robot\n"
    bound = bind(_net("  - {id: t, action: core.set, params: {value: 1}, guard: shop.idle, in: [a], out: [b]}\n",
                      subnets=agent), unimported=[str(module)])
    assert bound.unchecked == ()
    with pytest.raises(NetFormatError, match=r"guard shop.free reads \('busy_\{robot\}',\), which needs the"
                                             " parameter 'robot'"):
        bind(_net("  - {id: t, guard: shop.free, in: [a], out: [b]}\n", subnets=agent), unimported=[str(module)])
    with pytest.raises(NetFormatError, match=r"guard shop.idle reads its agent's state: put the transition in"):
        bind(_net("  - {id: t, guard: shop.idle, in: [a], out: [b]}\n"), unimported=[str(module)])
    with pytest.raises(NetFormatError, match=r"unknown guard 'shop.idel' \(did you mean 'shop.idle'"):
        bind(_net("  - {id: t, guard: shop.idel, in: [a], out: [b]}\n", subnets=agent), unimported=[str(module)])


def test_core_and_installed_namespaces_are_closed():
    closed = closed_namespaces()
    assert "core" in closed and "bidding" in closed and "planning" in closed
