"""Agents as run parts: one state object per agent, and guards that cost by what changed.

An agent is a subnet of the net (its ``agent:``, else its id). It may keep one state
object for the whole run (what it knows, what it has to send, its robot): an action
of the agent sets it (``ctx.state = RobotState(...)``) and every later action and
guard of the agent gets it (``ctx.state``). The run keeps it (:class:`Agents`), not a
token, so no action scans its inputs for it, and it never goes through a trace (a
state's :meth:`AgentState.to_token` says what a trace shows of it).

The subnet may declare its state's type (``state: bidding.robot``, a name registered
with :meth:`~petriflow.runtime.registry.Registry.register_state`); actions that read
an agent state say which type they expect (:attr:`Action.state
<petriflow.runtime.action.Action.state>`), and binding checks the two agree.

**Guards that declare what they read.** A guard registered with ``reads=(...)`` is
``f(state, params) -> bool`` and declares the keys of the agent state it reads
(``"outbox/{peer}"`` is formatted with the transition's parameters; ``"*"`` means
anything). Its answer is kept until one of those keys changes, so after a firing only
the guards whose inputs changed run again. A state says what changed with
:meth:`AgentState.touch`; anything one of the agent's own transitions does (a firing
starting or ending) counts as a change of ``"*"``.

**Waiting on state.** An action that has nothing to do until its agent's state changes
(a message arrives, a step is decided) sleeps on keys of that state instead of
polling it every tick: it sets :attr:`~petriflow.runtime.action.Action.wake_on` (a
generator action yields a :class:`~petriflow.runtime.action.StateChange`) and the run
registers its firing here (:class:`Sleepers`). A :meth:`AgentState.touch` of one of
those keys wakes it; a wait on ``"*"`` wakes on any touch, and on anything its agent's
transitions do (as a guard reading ``"*"`` is checked again). A wait on
:data:`RUNNING` wakes when which agents of the run are running changes (a teammate
killed, or joining late). The woken firing is
polled at the tick a firing polled at every tick would first see the change: in the
same instant when its poll there is still to come (the change happened in a timed
event, or in the poll of an earlier firing), else at the next tick. So a sleeping
action gives the same events, at the same times, as its polled twin, and costs
nothing while it sleeps; a run in which nothing but sleepers is left ends ``dead``
(a polled twin would step on until its time or stall limit).

Examples:
    >>> class Counter(AgentState):
    ...     def __init__(self): super().__init__(); self.n = 0
    ...     def bump(self): self.n += 1; self.touch("n")
    >>> seen = []
    >>> state = Counter(); state.attach(lambda keys: seen.append(keys))
    >>> state.bump(); seen
    [('n',)]
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Callable, Iterable, MutableMapping, Protocol

from petriflow.errors import PetriflowError
from petriflow.runtime.action import ANY_KEY, type_names

if TYPE_CHECKING:
    from petriflow.runtime.enabling import EnabledSet
    from petriflow.runtime.index import RunIndex

__all__ = ["AgentState", "Agents", "ANY", "RUNNING", "Sleepers", "Sleeper"]

#: The key a guard reads (or a sleeping action waits on) to be re-checked after
#: anything its agent does.
ANY = ANY_KEY
#: The key a guard reads (or a sleeping action waits on) to be re-checked when which
#: agents of the run are running changes (a fault kills one, one joins late), whatever
#: the agent: no state touches it, the run does (:meth:`Agents.running_changed`).
RUNNING = "running"


class AgentState:
    """Base class of an agent's state: it tells the run which of its keys changed.

    Subclasses call :meth:`touch` with the keys a change affects (``"outbox/robot2"``)
    so the guards that read them are checked again; a plain object works as a state
    too, its guards are then checked whenever their agent acts.
    """

    def __init__(self) -> None:
        self._notify: Callable[[tuple[str, ...]], None] | None = None

    def attach(self, notify: Callable[[tuple[str, ...]], None] | None) -> None:
        """Called by the run when the state becomes an agent's (``None``: detached)."""
        self._notify = notify

    def touch(self, *keys: str) -> None:
        """Say that these keys changed (the guards reading them are checked again)."""
        notify = getattr(self, "_notify", None)
        if notify is not None:
            notify(keys)

    def to_token(self) -> dict[str, Any]:
        """What a trace records of the state (default: its class name)."""
        return {"state": type(self).__name__}


class Sleeper(Protocol):
    """A firing asleep on its agent's state (the run's
    :class:`~petriflow.runtime.lifecycle.Firing`): it says whether a registration is
    still its current sleep, and wakes."""

    def asleep_on(self, nap: int) -> bool:
        """Whether the sleep ``nap`` is still the firing's current one."""

    def rouse(self) -> None:
        """Its state changed: have it polled when a polled firing would see the change."""


class Sleepers:
    """The firings asleep until keys of their agent's state change (see the module).

    Registrations are kept by agent and key; one whose firing has been polled since
    (woken by its time, cancelled) is dropped the next time its key changes or its
    list is pruned, so a sleep costs nothing but its entry.

    Examples:
        >>> class Nap:
        ...     def __init__(self): self.naps = 1; self.woken = 0
        ...     def asleep_on(self, nap): return nap == self.naps
        ...     def rouse(self): self.woken += 1; self.naps += 1
        >>> sleepers, nap = Sleepers(), Nap()
        >>> sleepers.add("r1", ("outbox",), nap, 1)
        >>> sleepers.touched("r1", ("step",)); nap.woken
        0
        >>> sleepers.touched("r1", ("outbox",)); sleepers.touched("r1", ("outbox",)); nap.woken
        1
    """

    def __init__(self) -> None:
        self._keyed: dict[str, dict[str, list[tuple[Sleeper, int]]]] = {}
        #: ``{agent: [(firing, nap), ...]}`` of the firings asleep on any change (``"*"``).
        self.any: dict[str, list[tuple[Sleeper, int]]] = {}

    def add(self, agent: str, keys: Iterable[str], firing: Sleeper, nap: int) -> None:
        """``firing`` sleeps (its sleep ``nap``) until one of ``keys`` of ``agent``'s state changes."""
        for key in keys:
            entries = (self.any.setdefault(agent, []) if key == ANY
                       else self._keyed.setdefault(agent, {}).setdefault(key, []))
            entries.append((firing, nap))
            if len(entries) >= 16 and not len(entries) & (len(entries) - 1):  # at 16, 32, 64...: prune
                entries[:] = [(f, n) for f, n in entries if f.asleep_on(n)]

    def touched(self, agent: str, keys: Iterable[str]) -> None:
        """Keys of ``agent``'s state changed: wake the firings asleep on them (and on ``"*"``)."""
        keyed = self._keyed.get(agent)
        woken: list[tuple[Sleeper, int]] = []
        if keyed:
            for key in keys:
                woken.extend(keyed.pop(key, ()))
        woken.extend(self.any.pop(agent, ()))
        self._wake(woken)

    def acted(self, agent: str) -> None:
        """A firing of ``agent`` started or ended: wake the firings asleep on ``"*"``."""
        self._wake(self.any.pop(agent, ()))

    def woken_by(self, agent: str, key: str) -> None:
        """Wake the firings of ``agent`` asleep on ``key`` (not those on ``"*"``: nothing
        of the state itself changed)."""
        keyed = self._keyed.get(agent)
        if keyed:
            self._wake(keyed.pop(key, ()))

    @staticmethod
    def _wake(entries: Iterable[tuple[Sleeper, int]]) -> None:
        for firing, nap in entries:
            if firing.asleep_on(nap):  # once, even when it slept on several of the keys
                firing.rouse()


class Agents:
    """A run's agent states, the guard answers they decide and the firings asleep on
    them (see the module).

    Args:
        index: the run's net index (per transition: agent, guard reads).
        enabled: the run's enabled set (whose guard answers this invalidates).
        states: where the states are kept, ``{agent: state}`` (shared with the enabled
            set, whose state guards read it).

    Attributes:
        sleepers: the firings asleep until their agent's state changes.
    """

    def __init__(self, index: "RunIndex", enabled: "EnabledSet",
                 states: MutableMapping[str, Any] | None = None) -> None:
        self.index = index
        self.enabled = enabled
        self.states: MutableMapping[str, Any] = {} if states is None else states
        self.sleepers = Sleepers()
        self._any: dict[str, list[int]] = {}  # agent -> transitions whose guard reads "*"
        self._readers: dict[str, dict[str, list[int]]] = {}  # agent -> key -> transitions
        for t, reads in enumerate(index.reads):
            agent = index.agent[t]
            if reads is None or agent is None:
                continue
            for key in reads:
                if key == ANY:
                    self._any.setdefault(agent, []).append(t)
                else:
                    self._readers.setdefault(agent, {}).setdefault(key, []).append(t)

    def any_readers(self, agent: str | None) -> bool:
        """Whether ``agent`` has guards that read anything of its state (``"*"``)."""
        return agent is not None and bool(self._any.get(agent))

    def state(self, agent: str | None) -> Any:
        """The state of ``agent`` (``None`` when it has none yet)."""
        return None if agent is None else self.states.get(agent)

    def set_state(self, agent: str | None, state: Any, expected: type | tuple | None = None) -> None:
        """Make ``state`` the state of ``agent`` (of the type ``expected``, by default
        the one the agent's subnet declares).

        Raises:
            PetriflowError: no agent (the transition is outside every agent's subnet),
                or the state is not of the type the agent's subnet declares.
        """
        if agent is None:
            raise PetriflowError("an agent state needs an agent: put the transition in an agent subnet")
        if expected is None:
            expected = self.index.state_type.get(agent)
        if expected is not None and state is not None and not isinstance(state, expected):
            raise PetriflowError(f"agent {agent!r}: its state must be a {type_names(expected)}, not"
                                 f" {type(state).__name__}")
        old = self.states.get(agent)
        if isinstance(old, AgentState) and old is not state:
            old.attach(None)
        self.states[agent] = state
        if isinstance(state, AgentState):
            state.attach(lambda keys, agent=agent: self.touched(agent, keys))
        self.acted(agent)

    def touched(self, agent: str, keys: Iterable[str]) -> None:
        """Keys of the state of ``agent`` changed: forget the answers of the guards
        reading them, wake the firings asleep on them."""
        keys = keys if isinstance(keys, tuple) else tuple(keys)
        readers = self._readers.get(agent)
        if readers:
            forget = self.enabled.forget
            for key in keys:
                for t in readers.get(key, ()):
                    forget(t)
        self.sleepers.touched(agent, keys)

    def running_changed(self) -> None:
        """Which agents of the run are running changed (a fault killed one, or one
        joined late): for every agent, forget the answers of the guards reading
        :data:`RUNNING` and wake its firings asleep on it, so an action can sleep until a
        teammate stops (``StateChange(RUNNING)``) instead of asking at every tick."""
        forget = self.enabled.forget
        for agent in self.index.agents:
            readers = self._readers.get(agent)
            if readers:
                for t in readers.get(RUNNING, ()):
                    forget(t)
            self.sleepers.woken_by(agent, RUNNING)

    def acted(self, agent: str | None) -> None:
        """``agent`` did something (a firing of its started or ended, a new state):
        forget the answers of its guards that read anything, wake its firings asleep
        on any change."""
        if agent is not None:
            forget = self.enabled.forget
            for t in self._any.get(agent, ()):
                forget(t)
            if self.sleepers.any:
                self.sleepers.acted(agent)

