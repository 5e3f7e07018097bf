"""A test kit: fire one transition of a real net with its real action, in pytest.

:func:`fire_one` loads a net the way ``petriflow run`` does: a net file (or a net read
from one) finds its run configuration (the one it names, else ``run.yaml`` beside it),
imports the action modules that configuration lists, and loads the world it names;
channels and faults come from it too. A firing that is still running when ``timeout``
(simulated seconds) runs out is an error naming the transition, its action and the
timeout, never a silent empty result.

The pytest fixture ``petriflow_net`` (this module is a pytest plugin, registered when
petriflow is installed) makes a user's test three lines::

    def test_dock(petriflow_net):
        fired = petriflow_net("nets/mine/net.yaml").fire("dock")
        assert fired.outcome == "ok"

Examples:
    >>> from petriflow.io.yaml import loads_net
    >>> net = loads_net('''
    ... petriflow: 1
    ... places: [{id: a, tokens: 1}, b]
    ... transitions: [{id: rest, action: core.wait, params: {seconds: 0.5}, in: [a], out: [b]}]
    ... ''')
    >>> fired = fire_one(net, "rest", tokens={"a": ["payload"]})
    >>> fired.outcome, fired.marking, fired.tokens, fired.time
    ('ok', Marking({'b': 1}), {'b': ['payload']}, 0.5)
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping, Sequence

from petriflow.errors import PetriflowError
from petriflow.marking import Marking
from petriflow.net import Net
from petriflow.runtime.action import Action, ActionContext, Outcome, Param, Status
from petriflow.runtime.services import RunServices
from petriflow.runtime.registry import Registry
from petriflow.runtime.trace import Event


def _fixture(function: Any) -> Any:
    """``pytest.fixture(function)`` when pytest is installed (this module is its plugin),
    else the function itself."""
    try:
        import pytest
    except ImportError:  # pragma: no cover - petriflow without pytest
        return function
    return pytest.fixture(function)

__all__ = ["fire_one", "FiredTransition", "FiringTimeout", "LoadedNet", "load", "ScriptedAction", "check_action",
           "StubWorld", "petriflow_net"]


class FiringTimeout(PetriflowError):
    """The fired transition's action was still running when the test's timeout ran out."""


@dataclass
class FiredTransition:
    """What firing one transition did.

    Attributes:
        outcome: ``ok``, ``failed``, ``timeout`` or ``cancelled``; ``None`` if the
            action was still running when ``timeout`` ran out.
        result: the action's result data.
        marking: token counts afterwards.
        tokens: token data afterwards, ``{place: [data, ...]}`` (marked places only).
        events: the events recorded (start, end, messages...).
        time: simulated seconds the firing took.
        reason: why the firing did not end ``ok``: the message of the action's
            :class:`~petriflow.runtime.action.ActionFailure` (``"charger fault"``), of an
            error it raised, or of its timeout; ``None`` for an ``ok`` firing.
    """

    outcome: str | None
    result: Any
    marking: Marking
    tokens: dict[str, list[Any]]
    events: list[Event] = field(default_factory=list)
    time: float = 0.0
    reason: str | None = None


def fire_one(
    net: Net | str | Path,
    transition: str,
    marking: Mapping[str, int] | None = None,
    *,
    tokens: Mapping[str, Sequence[Any]] | None = None,
    world: Any = None,
    registry: Registry | None = None,
    seed: int = 0,
    timeout: float = 60.0,
    config: Any = None,
) -> FiredTransition:
    """Fire ``transition`` of ``net`` once, with its bound action, and wait for it.

    Args:
        net: the net (its actions are bound and checked as in a real run), or its file.
        transition: the transition to fire.
        marking: token counts to start from (default: the net's initial marking);
            tokens without data (``None``).
        tokens: token data per place to start from, instead of ``marking``.
        world: a world (or :class:`StubWorld`) for actions that need one (default:
            the one the run configuration names, loaded for this firing).
        registry: where actions are looked up (default: the run registry).
        seed: the run seed (the firing's random generator derives from it).
        timeout: simulated seconds to wait for the action.
        config: a run configuration (:class:`~petriflow.runtime.config.RunConfig`,
            its mapping, or a file; default: the one the net's file names, as ``run``).

    Raises:
        NotEnabledError: the transition is not enabled in the given marking.
        FiringTimeout: the action was still running after ``timeout`` seconds.
    """
    with load(net, config=config, world=world, registry=registry) as loaded:
        return loaded.fire(transition, marking, tokens=tokens, seed=seed, timeout=timeout)


def _fire(net: Net, binding: Any, config: Any, world: Any, transition: str, marking: Mapping[str, int] | None,
          tokens: Mapping[str, Sequence[Any]] | None, seed: int, timeout: float) -> FiredTransition:
    from petriflow.runtime.assembly import CheckedRun, open_run

    with open_run(CheckedRun(net, binding, config), seed=seed, world=world) as scheduler:
        if tokens is not None:
            scheduler.set_tokens({p: list(v) for p, v in tokens.items()})
        elif marking is not None:
            net.check_marking(marking)
            scheduler.set_tokens({p: [None] * n for p, n in marking.items()})
        events: list[Event] = []
        scheduler.on_event(events.append)
        run = scheduler.fire_one(transition, timeout=timeout)
    ends = [e for e in events if e.kind == "end" and e.transition == transition]
    if not ends and run.reason != "failed":
        action = net.transitions[transition].action
        raise FiringTimeout(f"transition {transition!r} (action {action}) was still running after {timeout:g} s"
                            " of simulated time: give fire_one a longer timeout=, or check why it does not end")
    outcome = ends[-1].data["outcome"] if ends else None
    result = ends[-1].data.get("result") if ends else None
    reason = ends[-1].data.get("reason") if ends else None
    if run.reason == "failed":
        outcome, reason = Outcome.FAILED.value, run.error
    starts = [e for e in events if e.kind == "start"]
    took = (ends[-1].time if ends else run.time) - (starts[0].time if starts else 0.0)
    return FiredTransition(outcome, result, run.marking, run.tokens, events, round(took, 9), reason)


class LoadedNet:
    """A net loaded as ``petriflow run`` loads it, to fire its transitions one at a time
    (what :func:`load` and the ``petriflow_net`` fixture give).

    Attributes:
        net: the net.
        config: its run configuration.
        world: the world the configuration names (or the one given), or ``None``.
    """

    def __init__(self, net: Net, binding: Any, config: Any, world: Any, owned: bool) -> None:
        self.net, self.binding, self.config, self.world = net, binding, config, world
        self._owned = owned

    def fire(self, transition: str, marking: Mapping[str, int] | None = None, *,
             tokens: Mapping[str, Sequence[Any]] | None = None, seed: int = 0,
             timeout: float = 60.0) -> FiredTransition:
        """Fire ``transition`` once (see :func:`fire_one`)."""
        return _fire(self.net, self.binding, self.config, self.world, transition, marking, tokens, seed, timeout)

    def close(self) -> None:
        """Close the world if it was loaded here."""
        if self._owned and self.world is not None:
            self.world.close()
            self.world = None

    def __enter__(self) -> "LoadedNet":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()


def load(net: Net | str | Path, *, config: Any = None, world: Any = None,
         registry: Registry | None = None) -> LoadedNet:
    """Load a net (a file, or a net read from one) with its run configuration, action
    modules and world, as ``petriflow run`` does; a :class:`LoadedNet` to fire from.

    Raises:
        NetFormatError: a file is missing or malformed, or an action does not bind.
    """
    from petriflow.runtime.config import RunConfig, load_config
    from petriflow.runtime.validation import UNKNOWN, validate

    if isinstance(net, (str, Path)) or (config is None and getattr(net, "path", None)):
        from petriflow.runtime.session import prepare

        source = net if isinstance(net, (str, Path)) else Path(net.path)
        given = RunConfig.from_dict(config) if isinstance(config, dict) else config
        prepared = prepare(source, config=given, registry=registry)
        if not isinstance(net, (str, Path)):  # keep the caller's net object (it may be edited in the test)
            prepared.net = net
        net, config, binding = prepared.net, prepared.config, prepared.binding
        world_file = prepared.world
    else:
        config = RunConfig.from_dict(config) if isinstance(config, dict) else (
            load_config(config) if isinstance(config, (str, Path)) else config) or RunConfig()
        net = config.bound(net)
        config.import_actions()
        binding, world_file = None, None
    owned = world is None and world_file is not None
    binding = validate(net, config, binding=None if binding is None or binding.net is not net else binding,
                       registry=registry, world=True if owned else UNKNOWN if world is None else world)
    if owned:
        from petriflow.world import load_world

        world = load_world(world_file)
    return LoadedNet(net, binding, config, world, owned)


@_fixture
def petriflow_net(request: Any) -> Any:
    """The pytest fixture: ``petriflow_net(path, **load options)`` loads a net as
    ``petriflow run`` does (:func:`load`; a relative path is taken from the test's
    folder, then the current one), closed at the end of the test."""
    loaded: list[LoadedNet] = []

    def make(path: str | Path, **options: Any) -> LoadedNet:
        where = Path(path)
        if not where.is_absolute() and not where.exists():
            beside = Path(str(request.fspath)).parent / where
            where = beside if beside.exists() else where
        loaded.append(load(where, **options))
        return loaded[-1]

    yield make
    for item in loaded:
        item.close()


class ScriptedAction(Action):
    """A test double whose :meth:`poll` returns a scripted list of statuses.

    Use :meth:`script` to make a class with its own script and counters::

        Walk = ScriptedAction.script([Status.RUNNING, Status.RUNNING, Status.OK], result="there")
        registry.register("test.walk", Walk)
        ...
        assert Walk.calls["poll"] == 3
    """

    statuses: Sequence[Status] = (Status.OK,)
    outcome_result: Any = None
    calls: dict[str, int] = {}
    needs_world = False
    params = {"tag": Param(object, None, "free label, ignored")}

    @classmethod
    def script(cls, statuses: Sequence[Status], result: Any = None,
               needs_world: bool = False) -> type["ScriptedAction"]:
        """A subclass that polls ``statuses`` in order (the last one repeats)."""
        return type("Scripted", (cls,), {
            "statuses": tuple(statuses), "outcome_result": result, "needs_world": needs_world,
            "calls": {"setup": 0, "start": 0, "poll": 0, "cancel": 0, "teardown": 0},
        })

    def _count(self, name: str) -> None:
        type(self).calls[name] = type(self).calls.get(name, 0) + 1

    def setup(self, world: Any) -> None:
        self._count("setup")

    def start(self, ctx: ActionContext) -> None:
        self._count("start")
        self._position = 0

    def poll(self, ctx: ActionContext) -> Status:
        self._count("poll")
        status = self.statuses[min(self._position, len(self.statuses) - 1)]
        self._position += 1
        if status is Status.OK:
            ctx.result = self.outcome_result
        return status

    def cancel(self, ctx: ActionContext) -> bool:
        self._count("cancel")
        return True

    def teardown(self) -> None:
        self._count("teardown")


class _NoTokens:
    """The tokens of a context made outside a run: every place is empty."""

    def read(self, place: str) -> list[Any]:
        return []


class StubWorld:
    """A world with no physics: a clock, fixed agent positions, and a step counter (the
    :class:`~petriflow.capabilities.Distances` an action or a radio channel asks of it)."""

    def __init__(self, dt: float = 0.01, positions: Mapping[str, tuple[float, float]] | None = None) -> None:
        self.dt = dt
        self.steps = 0
        self.positions = dict(positions or {})

    def step(self) -> None:
        self.steps += 1

    def position(self, agent: str) -> tuple[float, float] | None:
        return self.positions.get(agent)

    def distance(self, a: str, b: str) -> float | None:
        pa, pb = self.positions.get(a), self.positions.get(b)
        if pa is None or pb is None:
            return None
        return ((pa[0] - pb[0]) ** 2 + (pa[1] - pb[1]) ** 2) ** 0.5


def check_action(cls: type[Action], params: Mapping[str, Any] | None = None, world: Any = None,
                 max_polls: int = 100_000) -> list[str]:
    """Conformance check of an Action class; returns the problems found (empty: fine).

    Checks that parameters are declared as :class:`Param`, that the defaults (plus
    ``params``) pass the class's own check, and that one lifecycle run (setup, start,
    poll until done, cancel, teardown) returns :class:`Status` values and ends. A hook
    that raises :class:`ActionFailure` (or another petriflow error) ends the firing
    ``failed`` as it should; any other exception is reported, since an action's
    failures should say what failed.
    """
    problems: list[str] = []
    if not (isinstance(cls, type) and issubclass(cls, Action)):
        return [f"{cls!r} is not an Action subclass"]
    for name, param in cls.params.items():
        if not isinstance(param, Param):
            problems.append(f"parameter {name!r} is not declared with Param")
    if problems:
        return problems
    try:
        checked = cls.check_params(dict(params or {}), where=cls.__name__)
    except Exception as exc:
        return [f"parameters do not check: {exc}"]
    action = cls(checked)
    ctx = ActionContext(transition="check", agent=None, params=checked, inputs={}, world=world, seed=0,
                        started=0.0, services=RunServices(tokens=_NoTokens()), action=cls)
    hook = "setup"
    try:
        action.setup(world)
        hook = "start"
        action.start(ctx)
        hook = "poll"
        for poll in range(max_polls):
            ctx.now = poll * getattr(world, "dt", 0.01)
            if action.wake_at is not None:
                ctx.now = max(ctx.now, action.wake_at)
            status = action.poll(ctx)
            if not isinstance(status, Status):
                problems.append(f"poll() returned {status!r}, not a Status")
                break
            if status is not Status.RUNNING:
                break
            if world is not None:
                world.step()
        else:
            problems.append(f"still running after {max_polls} polls")
    except PetriflowError:
        pass  # a deliberate failure: the firing ends failed
    except Exception as exc:
        problems.append(f"{hook}() raised {type(exc).__name__}: {exc} (raise ActionFailure to fail)")
    try:
        hook = "cancel"
        if action.cancel(ctx) not in (True, False):
            problems.append("cancel() must return True or False")
        hook = "teardown"
        action.teardown()
    except PetriflowError:
        pass
    except Exception as exc:
        problems.append(f"{hook}() raised {type(exc).__name__}: {exc}")
    return problems
