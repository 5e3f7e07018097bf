"""What an action is: one lifecycle, a status enum, declared parameters.

An action is what a transition does when it fires at run time. Its lifecycle follows
py_trees and Petri Net Plans:

* ``setup(world)`` once per run, before the first start (open a camera, load a URDF);
* ``start(ctx)`` when the transition fires (its input tokens are already consumed);
* ``poll(ctx) -> Status`` every scheduler tick until it returns ``OK`` or ``FAILED``
  (non-blocking; the action reads the world and commands it, never sleeps);
* ``cancel(ctx) -> bool`` when a cancellation region or a fault stops it; return
  ``False`` while clean-up still needs more ticks, ``True`` once it is done;
* ``teardown()`` once at the end of the run.

Most actions are easier to write as a generator function; :func:`generator_action`
wraps one. It ``yield``\\ s to wait one world step, ``yield seconds`` to wait simulated
time, ``return value`` to finish with a result, and raises :class:`ActionFailure` to
fail.

Examples:
    >>> class Count(Action):
    ...     params = {"to": Param(int, 3)}
    ...     def start(self, ctx):
    ...         self.left = self.params["to"]
    ...     def poll(self, ctx):
    ...         self.left -= 1
    ...         return Status.OK if self.left == 0 else Status.RUNNING
    >>> Count.check_params({"to": 2}, where="t1")
    {'to': 2}
"""

from __future__ import annotations

import enum
import inspect
import random
from dataclasses import dataclass, field
from typing import Any, Callable, ClassVar, Generator

from petriflow.errors import NetFormatError, PetriflowError, did_you_mean

__all__ = [
    "Status",
    "Outcome",
    "Param",
    "Action",
    "ActionContext",
    "ActionFailure",
    "ActionFailed",
    "generator_action",
    "REQUIRED",
]


class Status(enum.Enum):
    """What :meth:`Action.poll` returns."""

    RUNNING = "running"
    OK = "ok"
    FAILED = "failed"


class Outcome(str, enum.Enum):
    """How a started action ended; selects the output arcs that produce tokens."""

    OK = "ok"
    FAILED = "failed"
    TIMEOUT = "timeout"
    CANCELLED = "cancelled"


REQUIRED = object()
"""Default of a :class:`Param` that a net must give."""


@dataclass(frozen=True)
class Param:
    """A declared action parameter, checked when a net is loaded.

    Attributes:
        type: a type or tuple of types the value must have (``float`` accepts ints).
        default: value used when the net gives none; :data:`REQUIRED` if it must.
        doc: one line for ``petriflow actions``.
        choices: allowed values, if limited.
    """

    type: Any = object
    default: Any = REQUIRED
    doc: str = ""
    choices: tuple = ()

    def check(self, name: str, value: Any, where: str) -> Any:
        types = self.type if isinstance(self.type, tuple) else (self.type,)
        if float in types and isinstance(value, int) and not isinstance(value, bool):
            value = float(value)
        if self.type is not object and not isinstance(value, types):
            wanted = " or ".join(t.__name__ for t in types)
            raise NetFormatError(f"parameter {name!r} must be {wanted}, got {value!r}", element=where)
        if self.choices and value not in self.choices:
            raise NetFormatError(
                f"parameter {name!r} must be one of {list(self.choices)}, got {value!r}", element=where
            )
        return value


class ActionFailure(PetriflowError):
    """Raised inside an action to end it with the ``failed`` outcome."""


class ActionFailed(PetriflowError):
    """An action failed and the net has no ``failed`` arcs to route the failure."""

    def __init__(self, net: str, transition: str, action: str, reason: str) -> None:
        self.transition = transition
        self.action = action
        self.reason = reason
        super().__init__(f"net {net!r}: transition {transition!r}: action {action!r} failed: {reason}")


@dataclass
class ActionContext:
    """What an action sees while it runs.

    Attributes:
        transition: id of the fired transition.
        agent: the agent running it (its subnet's agent), or ``None``.
        params: the checked parameters.
        inputs: ``{place id: [token data, ...]}`` consumed by the firing.
        world: the world the run steps (``None`` in a world-less run).
        rng: a random generator seeded from the run seed and the firing number
            (made on first use from ``seed``).
        started: simulated time the action started.
        now: current simulated time (updated by the scheduler before each poll).
        result: data given to the output tokens (one value for all outputs, or a
            ``{place: data}`` dict when ``per_place`` is set).
        per_place: whether ``result`` maps output places to their token data.
        reason: why the action failed, when it did.
        blackboard: run-wide shared dict (e.g. the last camera frame).
    """

    transition: str
    agent: str | None
    params: dict[str, Any]
    inputs: dict[str, list[Any]]
    world: Any
    seed: Any
    started: float
    now: float = 0.0
    result: Any = None
    per_place: bool = False
    reason: str = ""
    blackboard: dict[str, Any] = field(default_factory=dict)
    emitted: list[tuple[str, dict[str, Any]]] = field(default_factory=list)
    _rng: random.Random | None = field(default=None, repr=False, compare=False)

    @property
    def rng(self) -> random.Random:
        """This firing's random generator (deterministic for the run seed and firing)."""
        if self._rng is None:
            self._rng = random.Random(self.seed)
        return self._rng

    @property
    def elapsed(self) -> float:
        """Simulated seconds since the action started."""
        return self.now - self.started

    def token(self, place: str | None = None) -> Any:
        """The data of the (first) input token, from ``place`` or from any input place."""
        if place is not None:
            return self.inputs[place][0]
        for tokens in self.inputs.values():
            for data in tokens:
                if data is not None:
                    return data
        return None

    def emit(self, kind: str, **data: Any) -> None:
        """Record a custom event (it goes into the run's trace)."""
        self.emitted.append((kind, data))


class Action:
    """Base class of class-style actions. Subclasses override the lifecycle methods.

    Attributes:
        params: class attribute ``{name: Param}`` declaring the parameters; on an
            instance, the checked values.
        needs_world: whether the action must be polled every world step (True) or
            only at the times it asks for through :attr:`wake_at` (False).
    """

    params: ClassVar[dict[str, Param]] = {}
    needs_world: ClassVar[bool] = True

    def __init__(self, params: dict[str, Any] | None = None) -> None:
        self.params = dict(params or {})  # type: ignore[misc]
        self.wake_at: float | None = None

    @classmethod
    def check_params(cls, given: dict[str, Any], where: str) -> dict[str, Any]:
        """Check ``given`` against the declared parameters and fill in defaults.

        Raises:
            NetFormatError: an unknown, missing or ill-typed parameter, naming ``where``.
        """
        declared = cls.params
        checked: dict[str, Any] = {}
        for name, value in given.items():
            if name not in declared:
                raise NetFormatError(
                    f"action has no parameter {name!r}{did_you_mean(name, declared)}"
                    f" (it takes: {', '.join(declared) or 'none'})",
                    element=where,
                )
            checked[name] = declared[name].check(name, value, where)
        for name, param in declared.items():
            if name not in checked:
                if param.default is REQUIRED:
                    raise NetFormatError(f"missing required parameter {name!r}", element=where)
                checked[name] = param.default
        return checked

    def setup(self, world: Any) -> None:
        """Prepare once per run (the world exists, nothing has fired yet)."""

    def start(self, ctx: ActionContext) -> None:
        """Begin; the transition's input tokens are already consumed."""

    def poll(self, ctx: ActionContext) -> Status:
        """Advance one tick and say whether the action is done."""
        return Status.OK

    def cancel(self, ctx: ActionContext) -> bool:
        """Stop; return False while clean-up needs more ticks."""
        return True

    def teardown(self) -> None:
        """Release what :meth:`setup` took."""


def generator_action(
    function: Callable[..., Generator[Any, Any, Any] | Any],
    params: dict[str, Param] | None = None,
    needs_world: bool = False,
) -> type[Action]:
    """Wrap a function ``f(ctx)`` into an :class:`Action` class.

    A plain function finishes at once with its return value as result. A generator
    function runs across ticks: ``yield`` waits one world step, ``yield seconds`` waits
    that much simulated time, ``return value`` finishes; raising
    :class:`ActionFailure` (or any exception) fails the action.

    Examples:
        >>> def wait(ctx):
        ...     yield ctx.params["seconds"]
        ...     return "rested"
        >>> Wait = generator_action(wait, {"seconds": Param(float, 1.0)})
        >>> Wait.check_params({}, where="t")
        {'seconds': 1.0}
    """

    is_generator = inspect.isgeneratorfunction(function)

    class FunctionAction(Action):
        __doc__ = function.__doc__

        def start(self, ctx: ActionContext) -> None:
            self._done = False
            self.wake_at = None
            if not is_generator:
                ctx.result = function(ctx)
                self._done = True
                return
            self._steps = function(ctx)
            self._advance(ctx, None)

        def _advance(self, ctx: ActionContext, sent: Any) -> None:
            try:
                wait = self._steps.send(sent)
            except StopIteration as stop:
                ctx.result = stop.value
                self._done = True
                return
            if wait is None:
                self.wake_at = None
            else:
                if isinstance(wait, bool) or not isinstance(wait, (int, float)) or wait < 0:
                    raise ActionFailure(f"yielded {wait!r}; yield nothing or a number of seconds")
                self.wake_at = ctx.now + float(wait)

        def poll(self, ctx: ActionContext) -> Status:
            if not self._done and (self.wake_at is None or ctx.now >= self.wake_at - 1e-12):
                self._advance(ctx, None)
            return Status.OK if self._done else Status.RUNNING

        def cancel(self, ctx: ActionContext) -> bool:
            if is_generator and not self._done:
                self._steps.close()
            return True

    FunctionAction.params = dict(params or {})
    FunctionAction.needs_world = needs_world
    FunctionAction.__name__ = FunctionAction.__qualname__ = getattr(function, "__name__", "action")
    return FunctionAction
