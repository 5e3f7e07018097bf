"""A test kit: fire one transition of a real net with its real action, in pytest.

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
from typing import Any, Mapping, Sequence

from petriflow.errors import PetriflowError
from petriflow.marking import Marking
from petriflow.net import Net
from petriflow.runtime.action import Action, ActionContext, Outcome, Param, Status
from petriflow.runtime.registry import Registry
from petriflow.runtime.scheduler import Scheduler
from petriflow.runtime.trace import Event

__all__ = ["fire_one", "FiredTransition", "ScriptedAction", "check_action", "StubWorld"]


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
    """

    outcome: str | None
    result: Any
    marking: Marking
    tokens: dict[str, list[Any]]
    events: list[Event] = field(default_factory=list)
    time: float = 0.0
    reason: str | None = None


def fire_one(
    net: Net,
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
        net: the net (its actions are bound and checked as in a real run).
        transition: the transition to fire.
        marking: token counts to start from (default: the net's initial marking);
            tokens without data (``None``).
        tokens: token data per place to start from, instead of ``marking``.
        world: a world (or :class:`StubWorld`) for actions that need one.
        registry: where actions are looked up (default: the run registry).
        seed: the run seed (the firing's random generator derives from it).
        timeout: simulated seconds to wait for the action.
        config: a run configuration (:class:`~petriflow.runtime.config.RunConfig`):
            its channel models carry the channel places (a radio the action judges).

    Raises:
        NotEnabledError: the transition is not enabled in the given marking.
    """
    scheduler = Scheduler(net, world=world, seed=seed, registry=registry, config=config)
    if tokens is not None:
        scheduler.set_tokens({p: list(v) for p, v in tokens.items()})
    elif marking is not None:
        net.check_marking(marking)
        scheduler.set_tokens({p: [None] * n for p, n in marking.items()})
    events: list[Event] = []
    scheduler.on_event(events.append)
    with scheduler:
        run = scheduler.fire_one(transition, timeout=timeout)
    ends = [e for e in events if e.kind == "end" and e.transition == transition]
    outcome = ends[-1].data["outcome"] if ends else None
    result = ends[-1].data.get("result") if ends else None
    reason = ends[-1].data.get("reason") if ends else None
    if run.reason == "failed":
        outcome, reason = Outcome.FAILED.value, run.error
    starts = [e for e in events if e.kind == "start"]
    took = (ends[-1].time if ends else run.time) - (starts[0].time if starts else 0.0)
    return FiredTransition(outcome, result, run.marking, run.tokens, events, round(took, 9), reason)


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


class StubWorld:
    """A world with no physics: a clock, fixed agent positions, and a step counter."""

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
    from types import SimpleNamespace

    ctx = ActionContext(transition="check", agent=None, params=checked, inputs={}, world=world, seed=0,
                        started=0.0, _run=SimpleNamespace(tokens=SimpleNamespace(read=lambda place: [])))
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
