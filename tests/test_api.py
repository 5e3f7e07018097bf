"""The public API: the stable top-level names, and running a net from Python with them."""

import importlib
import subprocess
import sys

import pytest

import petriflow
from petriflow import (
    Action,
    ActionFailure,
    Net,
    Param,
    Status,
    StopReason,
    action,
    run,
)
from petriflow.outcome import Outcome
from petriflow.runtime.registry import Registry


def charging_net(action_name: str) -> Net:
    net = Net("charging")
    for place in ("empty", "full", "faulty"):
        net.add_place(place, tokens=1 if place == "empty" else 0)
    net.add_transition("charge", action=action_name, params={"minutes": 2})
    net.add_arc("empty", "charge")
    net.add_arc("charge", "full")
    net.add_arc("charge", "faulty", outcome="failed")
    return net


def test_a_generator_function_registered_with_action_runs_from_python():
    registry = Registry(load_plugins=False)

    @action("demo.charge", params={"minutes": Param(float, 5.0)}, registry=registry)
    def charge(ctx):
        yield ctx.params["minutes"] * 60
        return {"battery": 1.0}

    outcome = run(charging_net("demo.charge"), registry=registry, keep_events=True)
    assert outcome.result.reason == StopReason.DEAD and outcome.result.time == 120.0
    assert outcome.result.tokens == {"full": [{"battery": 1.0}]}
    assert [e.kind for e in outcome.events] == ["run", "start", "end", "stop"]


def test_an_action_class_raising_action_failure_is_routed():
    registry = Registry(load_plugins=False)

    @action("demo.charge", registry=registry)
    class Charge(Action):
        params = {"minutes": Param(float, 5.0)}
        needs_world = False

        def start(self, ctx):
            raise ActionFailure("charger fault")

        def poll(self, ctx):
            return Status.OK

    outcome = run(charging_net("demo.charge"), registry=registry, keep_events=True)
    end = outcome.events[2]
    assert (end.data["outcome"], end.data["reason"]) == (Outcome.FAILED, "charger fault")
    assert outcome.result.marking == {"faulty": 1}


def test_an_action_class_declares_its_own_params():
    registry = Registry(load_plugins=False)
    with pytest.raises(Exception, match="declares its own params"):
        action("demo.x", params={"a": Param(int, 1)}, registry=registry)(type("X", (Action,), {}))


def test_the_top_level_holds_at_most_35_names_and_each_one_resolves():
    """Every name of ``petriflow.__all__`` is an attribute, and ``dir`` lists it."""
    assert len(petriflow.__all__) <= 35 and len(set(petriflow.__all__)) == len(petriflow.__all__)
    for name in petriflow.__all__:
        assert getattr(petriflow, name) is not None, name
    assert set(petriflow.__all__) <= set(dir(petriflow))


def test_importing_petriflow_loads_no_runtime_and_no_numpy():
    """``import petriflow`` alone (a fresh process) imports neither the runtime, the
    engine, the readers nor numpy: a stable name loads its module when asked for."""
    code = ("import sys, petriflow; print(' '.join(sorted(m for m in sys.modules"
            " if m.startswith(('petriflow', 'numpy', 'yaml')))))")
    loaded = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split()
    assert loaded == ["petriflow", "petriflow.errors", "petriflow.view"]


@pytest.mark.parametrize("name", sorted(petriflow._MOVED))
def test_a_name_that_left_the_top_level_is_importable_from_its_module(name):
    """A former top-level name is found in the module the top level names, and asking
    the top level for it says where that is."""
    home = petriflow._MOVED[name]
    assert getattr(importlib.import_module(home), name) is not None
    with pytest.raises(AttributeError, match=f"import it from {home}$"):
        getattr(petriflow, name)


def test_a_submodule_is_still_importable_from_the_top_level():
    from petriflow import examples, limits

    assert callable(examples.path) and limits.__name__ == "petriflow.limits"
    assert callable(petriflow.view)  # the function, though petriflow.view is also a subpackage


def test_type_checkers_see_each_stable_name_from_the_module_it_is_loaded_from():
    """The ``if TYPE_CHECKING:`` imports of ``petriflow/__init__.py`` (what editors and
    type checkers read) name the same module for each stable name as the lazy loader."""
    import ast
    from pathlib import Path

    tree = ast.parse(Path(petriflow.__file__).read_text(encoding="utf-8"))
    block = next(node for node in tree.body if isinstance(node, ast.If) and ast.unparse(node.test) == "TYPE_CHECKING")
    seen = {alias.name: node.module for node in block.body for alias in node.names}
    assert seen == {name: module for name, module in petriflow._STABLE.items()}
