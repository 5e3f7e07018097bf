"""What an action is: one lifecycle, a status enum, declared parameters.

An action is what a transition does when it fires at run time. Its lifecycle follows
py_trees and Petri Net Plans (each hook's docstring on :class:`Action` says when it is
called and what raising or returning means):

* ``setup(world)`` once per run, for every bound transition, before the first firing;
* ``start(ctx)`` when the transition fires (its input tokens are already consumed);
* ``poll(ctx) -> Status`` until it returns ``OK`` or ``FAILED`` (non-blocking; the
  action reads the world and commands it, never sleeps);
* ``cancel(ctx) -> bool`` when a cancellation region, a timeout or a fault stops it;
  ``False`` while clean-up still needs more ticks, ``True`` once it is done;
* ``teardown()`` once at the end of the run.

An exception from any hook is never lost: it ends the firing with the ``failed``
outcome and the exception as its reason, which the net routes like any failure.

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
import math
import random
from dataclasses import dataclass, field
from typing import Any, Callable, ClassVar, Generator, Mapping, TypeVar

from petriflow.errors import NetFormatError, PetriflowError, did_you_mean
from petriflow.outcome import Outcome
from petriflow.runtime.services import AgentStates, ChannelLookup, RunServices
from petriflow.runtime.stopwatch import UNTIMED, Timing

__all__ = [
    "Status",
    "Outcome",
    "Param",
    "Port",
    "Action",
    "InstantAction",
    "ActionContext",
    "ActionFailure",
    "StateChange",
    "generator_action",
    "REQUIRED",
    "type_names",
]

_S = TypeVar("_S")


class Status(enum.Enum):
    """What :meth:`Action.poll` returns."""

    RUNNING = "running"
    """Not done yet: poll again later."""
    OK = "ok"
    """Done: the transition's plain output arcs produce."""
    FAILED = "failed"
    """Failed: the ``failed`` arcs produce (``ctx.reason`` says why)."""


REQUIRED = object()
"""Default of a :class:`Param` that a net must give."""


def type_names(kinds: Any) -> str:
    """A type or a tuple of types in words, as errors name them.

    Examples:
        >>> type_names((int, type(None)))
        'int or NoneType'
    """
    kinds = kinds if isinstance(kinds, tuple) else (kinds,)
    return " or ".join(getattr(k, "__name__", repr(k)) for k in kinds)


@dataclass(frozen=True)
class Param:
    """A declared action parameter, checked when a net is bound (loaded to run).

    Attributes:
        type: a type or tuple of types the value must have (``float`` accepts ints).
        default: value used when the net gives none; :data:`REQUIRED` if it must.
        doc: one line for ``petriflow actions``.
        choices: allowed values, if limited.
        low: the smallest value a number may take (``None``: no bound).
        high: the largest value a number may take (``None``: no bound).
        places: where the value names places of the net, checked when the net is bound
            (a misspelt place fails at load with its line and a close match):
            ``""`` the value itself, ``"*"`` every item of a list or value of a
            mapping, ``"key"`` the mapping's ``key``, ``"*.key"`` the ``key`` of every
            item (``None``: it names no place). A ``None`` found there names nothing.

    Examples:
        >>> Param(float, 0.5, low=0, high=1).check("probability", 2, where="t")
        Traceback (most recent call last):
        ...
        petriflow.errors.NetFormatError: 't': parameter 'probability' must be from 0 to 1, got 2.0
    """

    type: Any = object
    default: Any = REQUIRED
    doc: str = ""
    choices: tuple = ()
    low: float | None = None
    high: float | None = None
    places: str | None = None

    def place_names(self, value: Any) -> list[str]:
        """The place names ``value`` holds where :attr:`places` says (see the class).

        Examples:
            >>> Param(dict, places="*.box").place_names({"r2": {"box": "b2"}, "r3": {"box": "b3"}})
            ['b2', 'b3']
            >>> Param(list, places="*").place_names(["a", None, "c"])
            ['a', 'c']
        """
        if self.places is None or value is None:
            return []
        found = [value]
        for step in [s for s in self.places.split(".") if s]:
            nxt: list[Any] = []
            for item in found:
                if step == "*":
                    nxt.extend(item.values() if isinstance(item, dict) else item if isinstance(item, list) else [])
                elif isinstance(item, dict) and step in item:
                    nxt.append(item[step])
            found = nxt
        return [f for f in found if f is not None]

    def check(self, name: str, value: Any, where: str, what: str = "parameter") -> Any:
        """``value`` checked (an int for a ``float`` becomes a float).

        Raises:
            NetFormatError: ``where``: ``{what} {name!r} must be ...``.
        """
        types = self.type if isinstance(self.type, tuple) else (self.type,)
        if float in types and isinstance(value, int) and not isinstance(value, bool):
            try:
                value = float(value)
            except OverflowError:
                raise NetFormatError(f"{what} {name!r} is too large a number, got {value!r}",
                                     element=where) from None
        if isinstance(value, float) and not math.isfinite(value):
            raise NetFormatError(f"{what} {name!r} must be a finite number, got {value!r}", element=where)
        if self.type is not object and not isinstance(value, types):
            raise NetFormatError(f"{what} {name!r} must be {type_names(types)}, got {value!r}", element=where)
        if self.choices and value not in self.choices:
            raise NetFormatError(
                f"{what} {name!r} must be one of {list(self.choices)}, got {value!r}", element=where
            )
        if (self.low is not None or self.high is not None) and isinstance(value, (int, float)) \
                and not isinstance(value, bool):
            if (self.low is not None and value < self.low) or (self.high is not None and value > self.high):
                span = (f"from {self.low:g} to {self.high:g}" if self.low is not None and self.high is not None
                        else f">= {self.low:g}" if self.low is not None else f"<= {self.high:g}")
                raise NetFormatError(f"{what} {name!r} must be {span}, got {value!r}", element=where)
        return value


class Port(Param):
    """A parameter naming a place whose tokens the action reads while it runs.

    This is how an action shares state with others, as BehaviorTree.CPP's ports do:
    the state is token data in a place of the net (written by the transitions that
    produce into it), and the action declares that it reads it. Binding checks that
    the place exists, so a typo fails before anything moves; :meth:`ActionContext.read`
    and :meth:`ActionContext.latest` return what the place holds at that moment
    without consuming it. A port left at ``None`` reads nothing.

    Args:
        doc: one line for ``petriflow actions``.
        required: the net must name a place (default: a port may stay unconnected).

    Examples:
        >>> Port("the latest scene").check("scene", "S", where="walk")
        'S'
    """

    def __init__(self, doc: str = "", *, required: bool = False) -> None:
        super().__init__((str, type(None)), REQUIRED if required else None, doc)


class ActionFailure(PetriflowError):
    """Raise it inside an action to end the firing with the ``failed`` outcome.

    The message is the failure's reason (in the trace and in ``ctx.reason``). The
    runtime raises it too, naming the net, transition and action, when a failure has
    no ``failed`` arcs to take it and the run must stop.

    Examples:
        >>> str(ActionFailure("gripper jammed"))
        'gripper jammed'
        >>> str(ActionFailure("gripper jammed", net="cell", transition="grab", action="arm.pick"))
        "net 'cell': transition 'grab': action 'arm.pick' failed: gripper jammed"
    """

    def __init__(self, reason: str = "", *, net: str | None = None, transition: str | None = None,
                 action: str | None = None) -> None:
        self.reason = reason
        self.net = net
        self.transition = transition
        self.action = action
        if transition is None:
            super().__init__(reason)
        else:
            super().__init__(f"net {net!r}: transition {transition!r}: action {action or '-'!r} failed: {reason}")


def first_data(inputs: dict[str, list[Any]]) -> Any:
    """The data of the first consumed token that carries any (``None`` if none does)."""
    for tokens in inputs.values():
        for data in tokens:
            if data is not None:
                return data
    return None


class StateChange:
    """What a generator action yields to sleep until its agent's state changes.

    ``yield StateChange("outbox", "step")`` resumes the generator when one of those keys
    of its agent's state is touched (:meth:`~petriflow.runtime.agents.AgentState.touch`);
    ``StateChange()`` (or ``"*"``) when anything of the state changes, or any firing of
    the agent starts or ends; ``within=seconds`` also resumes it after that much
    simulated time, whichever comes first. The generator then looks at the state again
    (a change of a key is no promise about the value). Nothing polls it meanwhile (see
    :attr:`Action.wake_on`).

    Examples:
        >>> StateChange("outbox", within=2.0)
        StateChange('outbox', within=2.0)
    """

    __slots__ = ("keys", "within")

    def __init__(self, *keys: str, within: float | None = None) -> None:
        if not all(isinstance(k, str) and k for k in keys):
            raise PetriflowError(f"StateChange takes state keys (text), got {keys!r}")
        if within is not None and (isinstance(within, bool) or not isinstance(within, (int, float))
                                   or not within >= 0):
            raise PetriflowError(f"StateChange: within is a number of seconds >= 0, got {within!r}")
        self.keys: tuple[str, ...] = keys or (ANY_KEY,)
        self.within = within

    def __repr__(self) -> str:
        keys = ", ".join(repr(k) for k in self.keys)
        return f"StateChange({keys}{'' if self.within is None else f', within={self.within!r}'})"


#: The state key that stands for any change of an agent's state.
ANY_KEY = "*"


@dataclass(eq=False, slots=True)
class ActionContext:
    """What an action sees during one firing.

    Attributes:
        transition: id of the fired transition.
        agent: the agent running it (its subnet's agent), or ``None``.
        params: the checked parameters.
        inputs: ``{place id: [token data, ...]}`` consumed by the firing.
        world: the world the run steps (``None`` in a world-less run); it provides the
            capabilities the action declares (:attr:`Action.uses`).
        seed: seed of this firing's :attr:`rng` (the run seed and the firing number).
        started: simulated time the action started.
        now: current simulated time (updated by the scheduler before each call).
        result: data given to the output tokens (one value for all outputs, or a
            ``{place: data}`` dict when ``per_place`` is set).
        per_place: whether ``result`` maps output places to their token data.
        outputs: ``{place: data}`` for output places whose tokens get other data than
            ``result`` (see :meth:`put`).
        reason: why the action failed, when it did.
        emitted: the custom events recorded so far (:meth:`emit`).
        services: the run's services (:class:`~petriflow.runtime.services.RunServices`);
            ``None`` outside a run.
        action: the bound action's class (what it declares: resources, settings).
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
    outputs: dict[str, Any] | None = None
    reason: str = ""
    emitted: list[tuple[str, dict[str, Any]]] | None = None
    services: RunServices | None = field(default=None, repr=False)
    action: type[Action] | None = field(default=None, repr=False)
    _rng: random.Random | None = field(default=None, repr=False)

    def _need(self, service: _S | None, what: str) -> _S:
        """``service`` of the run, or the error that there is none."""
        if service is None:
            raise PetriflowError(f"{self.transition!r}: no run to {what}")
        return service

    @property
    def rng(self) -> random.Random:
        """This firing's random generator (deterministic for the run seed and firing)."""
        if self._rng is None:
            self._rng = random.Random(self.seed)
        return self._rng

    def _agents(self) -> AgentStates:
        return self._need(None if self.services is None else self.services.agents, "keep an agent state in")

    @property
    def state(self) -> Any:
        """The state of this firing's agent (``None`` until one of its actions sets it).

        Setting it makes the object the agent's state for the rest of the run (see
        :mod:`petriflow.runtime.agents`); it must be of the type the agent's subnet
        declares, if it declares one.
        """
        return self._agents().state(self.agent)

    @state.setter
    def state(self, value: Any) -> None:
        self._agents().set_state(self.agent, value)

    def resource(self, name: str) -> Any:
        """The run's resource the action declares as ``name`` (its ``resources``).

        Raises:
            PetriflowError: the action declares no resource of that name, or no run.
        """
        declared = {} if self.action is None else self.action.resources
        kind = declared.get(name)
        if kind is None:
            raise PetriflowError(f"{self.transition!r}: the action declares no resource {name!r}"
                                 f"{did_you_mean(name, declared)}")
        resources = None if self.services is None else self.services.resources
        return self._need(resources, f"take resource {name!r} from").get(kind)

    @property
    def settings(self) -> Mapping[str, Any]:
        """The world file's settings the action declares (:attr:`Action.settings`),
        checked when the world was loaded, defaults filled in: ``{name: value}``.

        Raises:
            PetriflowError: the action declares no settings, or no run.
        """
        section = None if self.action is None else self.action.settings
        if section is None:
            raise PetriflowError(f"{self.transition!r}: the action declares no world settings (settings =)")
        if self.services is None:
            raise PetriflowError(f"{self.transition!r}: no run to read settings {section.name!r} from")
        values = self.services.settings.get(section.name)
        if values is None:
            raise PetriflowError(f"{self.transition!r}: the run did not read the world's settings"
                                 f" {section.name!r} (bind the net with its actions first)")
        return values

    @property
    def elapsed(self) -> float:
        """Simulated seconds since the action started."""
        return self.now - self.started

    def token(self, place: str | None = None) -> Any:
        """The data of the (first) input token, from ``place`` or from any input place."""
        if place is not None:
            return self.inputs[place][0]
        return first_data(self.inputs)

    def read(self, port: str) -> list[Any]:
        """The data of the tokens now in the place the :class:`Port` ``port`` names
        (oldest first; empty when the port names no place or the place is empty).

        Raises:
            PetriflowError: no run to read from.
        """
        place = self.params.get(port)
        if place is None:
            return []
        tokens = None if self.services is None else self.services.tokens
        return self._need(tokens, f"read port {port!r} from").read(place)

    def latest(self, port: str, default: Any = None) -> Any:
        """The data of the newest token in the port's place, or ``default``."""
        tokens = self.read(port)
        return tokens[-1] if tokens else default

    def _channels(self, place: str) -> ChannelLookup:
        channels = None if self.services is None else self.services.channels
        return self._need(channels, f"look up channel place {place!r} in")

    def link(self, place: str) -> tuple[Any, str | None]:
        """The channel model that carries the channel place ``place`` and the agent that
        receives from it, to judge a link before sending (a radio's RSSI, a bus).

        Raises:
            PetriflowError: no run, or ``place`` is not a channel place.
        """
        return self._channels(place).model_for(place)

    def medium(self, place: str) -> Any:
        """What the medium carrying the channel place ``place`` lets this firing's agent
        ask about it: the view it declares (:meth:`petriflow.runtime.media.Medium.view`:
        is it quiet, how often this agent reads its buffer...).

        Raises:
            PetriflowError: no run, ``place`` is not a channel place, or its model offers
                no view.
        """
        return self._channels(place).view(place, self.agent)

    @property
    def stopwatch(self) -> Timing:
        """What the action reports its work's wall-clock time to
        (``with ctx.stopwatch.measure("vision"): ...``; :mod:`petriflow.runtime.stopwatch`):
        the run's stopwatch, or one that measures nothing."""
        return UNTIMED if self.services is None else self.services.stopwatch

    def running(self, agent: str | None) -> bool:
        """Whether ``agent`` runs now: not killed, not waiting to join (what a radio
        learns from an agent's beacon). ``True`` outside a run."""
        liveness = None if self.services is None else self.services.liveness
        return True if liveness is None else liveness.alive(agent)

    def put(self, place: str, data: Any) -> None:
        """Give the tokens this firing produces in ``place`` the data ``data`` instead
        of :attr:`result` (e.g. a state token taken and given back updated)."""
        if self.outputs is None:
            self.outputs = {}
        self.outputs[place] = data

    def emit(self, kind: str, **data: Any) -> None:
        """Record a custom event (it goes into the run's trace when the firing ends)."""
        if self.emitted is None:
            self.emitted = []
        self.emitted.append((kind, data))


class Action:
    """Base class of class-style actions: override the lifecycle hooks you need.

    The scheduler makes one instance per bound transition per run, so an instance may
    keep what it learns across that transition's firings (a robot handle, a counter);
    what it shares with other transitions goes into tokens.

    Attributes:
        params: class attribute ``{name: Param}`` declaring the parameters (and
            :class:`Port`\\ s); on an instance, the checked values.
        needs_world: whether the action must be polled at every world step (True) or
            only at the times it asks for through :attr:`wake_at` and :attr:`wake_on`
            (False).
        wake_at: for ``needs_world = False``: the simulated time of the next poll
            (``None``: the next tick, or, with :attr:`wake_on`, no time).
    """

    params: ClassVar[dict[str, Param]] = {}
    needs_world: ClassVar[bool] = True
    #: The world capabilities the action uses (protocols of :mod:`petriflow.capabilities`:
    #: ``(Poses, RayTests)``), checked when the net is bound: the run must have a world
    #: that provides each one (``file:line`` and what it lacks). What an action declares
    #: here it calls on ``ctx.world`` without probing it.
    uses: ClassVar[tuple[type, ...]] = ()
    #: The world file's settings the action reads: a
    #: :class:`~petriflow.runtime.settings.Section` (its name under the world's ``meta``
    #: and the settings it holds), checked when the world is loaded, read with
    #: ``ctx.settings``; ``None``: none.
    settings: ClassVar[Any] = None
    #: For an action that does not step with the world: the keys of its agent's state
    #: whose change wakes it (``("*",)``: any change), set before :meth:`poll` (or
    #: :meth:`start`) returns; ``None``: it does not wait on its state. It is then polled
    #: when one of those keys changes (or at :attr:`wake_at`, whichever comes first),
    #: and never in between (see :mod:`petriflow.runtime.agents`, "Waiting on state").
    wake_on: tuple[str, ...] | None = None
    #: What a transition bound to this action must have, checked when the net is bound
    #: (exit 2, ``file:line``) instead of failing when it fires: ``"agent"`` (the
    #: transition is in an agent subnet), ``"robot"`` (a ``robot`` parameter, or an agent
    #: subnet whose agent is the robot), ``"world"`` (the run has a world; declaring
    #: capabilities in :attr:`uses` implies it). Override
    #: :meth:`requirements` when they depend on the parameters.
    requires: ClassVar[frozenset[str]] = frozenset()
    #: The type of agent state the action reads and writes through ``ctx.state`` (a class
    #: or a tuple of classes), or ``None``. Binding checks that the transition's subnet
    #: declares a state of that type (``state:`` in the net).
    agent_state: ClassVar[Any] = None
    #: The run resources the action uses: ``{local name: registered resource type}``
    #: (``{"office": "bidding.office"}``), checked when the net is bound, made once per
    #: run, read with ``ctx.resource(local name)`` (see :mod:`petriflow.runtime.resources`).
    resources: ClassVar[dict[str, str]] = {}

    @classmethod
    def requirements(cls, params: dict[str, Any]) -> frozenset[str]:
        """What a transition with these (checked) ``params`` needs (see :attr:`requires`)."""
        return cls.requires

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
            try:
                if name not in declared:
                    raise NetFormatError(
                        f"action has no parameter {name!r}{did_you_mean(name, declared)}"
                        f" (it takes: {', '.join(declared) or 'none'})",
                        element=where,
                    )
                checked[name] = declared[name].check(name, value, where)
            except NetFormatError as exc:
                exc.param = name  # so binding can name the parameter's line
                raise
        for name, param in declared.items():
            if name not in checked:
                if param.default is REQUIRED:
                    raise NetFormatError(f"missing required parameter {name!r}", element=where)
                checked[name] = param.default
        return checked

    @classmethod
    def ports(cls) -> list[str]:
        """Names of the declared :class:`Port` parameters."""
        return [name for name, param in cls.params.items() if isinstance(param, Port)]

    def setup(self, world: Any) -> None:
        """Prepare, once per run, before the first firing of any transition.

        Called for every bound transition when the run starts, with the run's world
        (``None`` in a world-less run): open devices, look up bodies, check that the
        world has what the action needs. Nothing has fired yet and simulated time is 0.

        Raising (e.g. :class:`ActionFailure` "needs a world") does not stop the run:
        each later firing of this transition ends at once with the ``failed``
        outcome and this reason, and the net routes it.
        """

    def start(self, ctx: ActionContext) -> None:
        """Begin one firing; called when the transition fires.

        The input tokens are already consumed (``ctx.inputs``) and the cancellation
        region already applied. Set ``ctx.result`` here for an action that is done at
        once; :meth:`poll` is called right after, in the same instant.

        Raising ends the firing with the ``failed`` outcome and the exception as its
        reason (``ctx.reason``); :meth:`poll` is then not called.
        """

    def poll(self, ctx: ActionContext) -> Status:
        """Advance the action and say whether it is done.

        Called right after :meth:`start` (in the same instant; for an action with
        ``needs_world`` unset whose :meth:`start` set :attr:`wake_at` ahead, first at
        that time, or whose start set :attr:`wake_on`, first when that comes), then at
        every world step while ``needs_world`` is set, else when :attr:`wake_at` comes
        or a key of :attr:`wake_on` changes (or the next tick if neither is set).
        ``ctx.now`` is the current simulated time. Never block or sleep: command the
        world and return.

        Returns:
            ``Status.RUNNING`` to be polled again, ``Status.OK`` when done (set
            ``ctx.result`` for the output tokens' data), ``Status.FAILED`` to fail
            (set ``ctx.reason``). Anything else, or raising, fails the firing with
            the reason.
        """
        return Status.OK

    def delay(self) -> float | None:
        """For an action that does nothing but wait: the simulated seconds it waits
        before it ends ``ok`` with its input token's data (:meth:`ActionContext.token`),
        just as its :meth:`start` and :meth:`poll` would end it.

        A transition without a timeout whose action gives a delay (above a microsecond)
        is ended at that time without :meth:`start` or :meth:`poll` being called and
        without an :class:`ActionContext` being made (one is made if it is cancelled,
        for :meth:`cancel`): the commonest firing of a timed net then costs one
        scheduled event. ``None`` (the default): the runtime calls the hooks.
        """
        return None

    def cancel(self, ctx: ActionContext) -> bool:
        """Stop: a cancellation region, the transition's timeout or a fault (an agent
        killed) ends the firing early.

        Called instead of :meth:`poll` until it returns ``True``, once per tick: return
        ``False`` while clean-up (e.g. bringing a robot to rest) needs more ticks. The
        firing then ends with the ``cancelled`` (or ``timeout``) outcome.

        Raising ends the clean-up at once with the ``failed`` outcome and the
        exception as its reason.
        """
        return True

    def teardown(self) -> None:
        """Release what :meth:`setup` took; once, when the run ends (however it ends).

        Raising does not change how the run ended: the error is recorded in the run's
        ``stop`` event (``teardown_errors``) and the other actions are still torn down.
        """


class InstantAction(Action):
    """An action that does all its work at once: :meth:`run` returns the data of the
    output tokens when the firing starts, and the firing ends ``ok`` in the same instant
    (an exception from :meth:`run` is its ``failed`` outcome, with the message as reason).

    Examples:
        >>> class Double(InstantAction):
        ...     params = {"x": Param(int, 1)}
        ...     def run(self, ctx):
        ...         return 2 * self.params["x"]
    """

    needs_world = False

    def start(self, ctx: ActionContext) -> None:
        ctx.result = self.run(ctx)

    def poll(self, ctx: ActionContext) -> Status:
        return Status.OK

    def run(self, ctx: ActionContext) -> Any:  # pragma: no cover - overridden
        raise NotImplementedError


def generator_action(
    function: Callable[..., Generator[Any, Any, Any] | Any],
    params: dict[str, Param] | None = None,
    needs_world: bool = False,
) -> type[Action]:
    """Wrap a function ``f(ctx)`` into an :class:`Action` class.

    A plain function finishes at once with its return value as result. A generator
    function runs across ticks: ``yield`` waits one world step, ``yield seconds`` waits
    that much simulated time, ``yield StateChange(keys)`` sleeps until its agent's
    state changes (:class:`StateChange`), ``return value`` finishes; raising
    :class:`ActionFailure` (or any exception) fails the action.

    Examples:
        >>> def wait(ctx):
        ...     yield ctx.params["seconds"]
        ...     return "rested"
        >>> Wait = generator_action(wait, {"seconds": Param(float, 1.0)})
        >>> Wait.check_params({}, where="t")
        {'seconds': 1.0}
    """

    name = getattr(function, "__name__", "action")
    return type(name, (_FunctionAction,), {
        "__doc__": function.__doc__, "__qualname__": name, "params": dict(params or {}),
        "__module__": getattr(function, "__module__", __name__),
        "needs_world": needs_world, "function": staticmethod(function),
        "is_generator": inspect.isgeneratorfunction(function)})


class _FunctionAction(Action):
    """An action made of a function or generator function (see :func:`generator_action`)."""

    function: Callable[..., Any]
    is_generator = False

    def start(self, ctx: ActionContext) -> None:
        self._done = False
        self.wake_at = self.wake_on = None
        if not self.is_generator:
            ctx.result = self.function(ctx)
            self._done = True
            return
        self._steps = self.function(ctx)
        self._advance(ctx, None)

    def _advance(self, ctx: ActionContext, sent: Any) -> None:
        try:
            wait = self._steps.send(sent)
        except StopIteration as stop:
            ctx.result = stop.value
            self._done = True
            return
        self.wake_on = None
        if wait is None:
            self.wake_at = None
        elif isinstance(wait, StateChange):
            self.wake_on = wait.keys
            self.wake_at = None if wait.within is None else ctx.now + float(wait.within)
        else:
            if isinstance(wait, bool) or not isinstance(wait, (int, float)) or wait < 0:
                raise ActionFailure(f"yielded {wait!r}; yield nothing, a number of seconds or a StateChange")
            self.wake_at = ctx.now + float(wait)

    def poll(self, ctx: ActionContext) -> Status:
        # asleep on its state, it is polled only when woken (a change, or its time)
        if not self._done and (self.wake_on is not None or self.wake_at is None
                               or ctx.now >= self.wake_at - 1e-12):
            self._advance(ctx, None)
        return Status.OK if self._done else Status.RUNNING

    def cancel(self, ctx: ActionContext) -> bool:
        if self.is_generator and not self._done:
            self._steps.close()
        return True
