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

from typing import TYPE_CHECKING, Any, Callable, Iterable

from petriflow.errors import PetriflowError

if TYPE_CHECKING:
    from petriflow.runtime.enabling import EnabledSet
    from petriflow.runtime.index import RunIndex

__all__ = ["AgentState", "Agents", "ANY"]

#: The key a guard reads to be re-checked after anything its agent does.
ANY = "*"


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


class Agents:
    """A run's agent states and the guard answers they decide (see the module).

    Args:
        index: the run's net index (per transition: agent, guard reads).
        enabled: the run's enabled set (whose guard answers this invalidates).
    """

    def __init__(self, index: "RunIndex", enabled: "EnabledSet") -> None:
        self.index = index
        self.enabled = enabled
        self.states: dict[str, Any] = {}
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
        """Make ``state`` the state of ``agent``.

        Raises:
            PetriflowError: no agent (the transition is outside every agent's subnet),
                or the state is not of the type the agent's subnet declares.
        """
        if agent is None:
            raise PetriflowError("an agent state needs an agent: put the transition in an agent subnet")
        if expected is not None and state is not None and not isinstance(state, expected):
            raise PetriflowError(f"agent {agent!r}: its state must be a {_names(expected)}, not"
                                 f" {type(state).__name__}")
        old = self.states.get(agent)
        if isinstance(old, AgentState) and old is not state:
            old.attach(None)
        self.states[agent] = state
        if isinstance(state, AgentState):
            state.attach(lambda keys, agent=agent: self.touched(agent, keys))
        self.acted(agent)

    def touched(self, agent: str, keys: Iterable[str]) -> None:
        """Keys of the state of ``agent`` changed: forget the answers of the guards reading them."""
        readers = self._readers.get(agent)
        if readers:
            forget = self.enabled.forget
            for key in keys:
                for t in readers.get(key, ()):
                    forget(t)

    def acted(self, agent: str | None) -> None:
        """``agent`` did something (a firing of its started or ended): forget the
        answers of its guards that read anything."""
        if agent is not None:
            forget = self.enabled.forget
            for t in self._any.get(agent, ()):
                forget(t)


def _names(kinds: type | tuple) -> str:
    kinds = kinds if isinstance(kinds, tuple) else (kinds,)
    return " or ".join(k.__name__ for k in kinds)
