"""What an action's context reaches of its run: the run's services, typed.

An :class:`~petriflow.runtime.action.ActionContext` gives an action its firing (the
transition, the tokens it took, the time) and, through a :class:`RunServices`, the
parts of the run it may use while it runs:

========================  ==============================  =================================
service                   used by                         made by the run as
========================  ==============================  =================================
``agents``                ``ctx.state``                   :class:`~.agents.Agents`
``tokens``                ``ctx.read``, ``ctx.latest``    :class:`~.tokens.TokenStore`
``channels``              ``ctx.link``, ``ctx.medium``    :class:`~.channels.Channels`
``resources``             ``ctx.resource``                :class:`~.resources.Resources`
``liveness``              ``ctx.running``                 :class:`~.faults.Faults`
``settings``              ``ctx.settings``                the world file's checked settings
``stopwatch``             ``ctx.stopwatch``               where wall-clock time goes (:mod:`~.stopwatch`)
``remote``                remote actions (the bridge)     :class:`~petriflow.bridge.dispatcher.Dispatcher`
========================  ==============================  =================================

Each service is a small protocol here, so an action (and a test that makes a context
by hand) depends on what it asks, not on the class that answers; the scheduler makes
one :class:`RunServices` per run and every context of the run shares it. Outside a
run a context has none, and what needs one raises.

Examples:
    >>> class Board:
    ...     def read(self, place): return ["seen"] if place == "scene" else []
    >>> services = RunServices(tokens=Board())
    >>> services.tokens.read("scene"), services.settings
    (['seen'], {})
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Mapping, Protocol

from petriflow.runtime.stopwatch import UNTIMED, Timing

__all__ = ["RunServices", "AgentStates", "PortReader", "ChannelLookup", "ResourceSource", "AgentLiveness",
           "RemoteGoals"]


class AgentStates(Protocol):
    """The agents' states (:class:`~petriflow.runtime.agents.Agents`)."""

    def state(self, agent: str | None) -> Any:
        """The state of ``agent`` (``None`` when it has none yet)."""

    def set_state(self, agent: str | None, state: Any, expected: Any = None) -> None:
        """Make ``state`` the state of ``agent`` (checked against the type its subnet
        declares, or ``expected``)."""


class PortReader(Protocol):
    """The tokens of the run's places (:class:`~petriflow.runtime.tokens.TokenStore`)."""

    def read(self, place: str) -> list[Any]:
        """The data of the tokens now in ``place``, oldest first."""


class ChannelLookup(Protocol):
    """The run's channel places (:class:`~petriflow.runtime.channels.Channels`)."""

    def model_for(self, place: str) -> tuple[Any, str | None]:
        """The model carrying the channel place ``place`` and the agent receiving from it."""

    def view(self, place: str, agent: str | None) -> Any:
        """What the medium carrying ``place`` lets ``agent`` ask about it."""


class ResourceSource(Protocol):
    """The run's resources (:class:`~petriflow.runtime.resources.Resources`)."""

    def get(self, kind: str) -> Any:
        """The run's resource of type ``kind``."""


class AgentLiveness(Protocol):
    """Which agents run now (:class:`~petriflow.runtime.faults.Faults`)."""

    def alive(self, agent: str | None) -> bool:
        """Whether ``agent`` runs now (not killed, not waiting to join)."""


class RemoteGoals(Protocol):
    """Where goals for agents outside the run's process go (:mod:`petriflow.bridge`)."""

    run: str

    def send(self, goal: Any) -> Any:
        """Send a goal (again, with the same id, if it was sent before)."""

    def goal(self, goal_id: str) -> Any:
        """What is known of the goal ``goal_id`` (``None``: never sent)."""

    def cancel(self, goal_id: str) -> None:
        """Ask its agent to stop the goal ``goal_id``."""

    def is_lost(self, agent: str) -> bool:
        """Whether the remote ``agent`` stopped answering."""

    def take_calls(self, goal_id: str) -> list[Any]:
        """The calls of the goal's action on the run's services, not yet answered."""

    def reply(self, reply: Any) -> None:
        """Send the answer to a call."""

    def refuse_calls(self, goal_id: str, why: str) -> None:
        """Refuse the goal's calls not yet answered, with ``why``."""


@dataclass(frozen=True, eq=False)
class RunServices:
    """The services of one run that its actions' contexts reach (see the module).

    A service left at ``None`` is one the run (or the test that made the context)
    does not offer: the context method that needs it raises ``no run to ...``.

    Attributes:
        agents: the agents' states.
        tokens: the tokens of the places (what ports read).
        channels: the channel places and their models.
        resources: the run's declared resources.
        liveness: which agents run now.
        settings: ``{section: {name: value}}``, the world file's settings the bound
            actions declare, checked (:mod:`petriflow.settings`).
        stopwatch: what the actions report their work's wall-clock time to
            (:data:`~petriflow.runtime.stopwatch.UNTIMED`: a run nobody times).
        remote: where goals for remote agents go (a run with a ``bridge:``).
    """

    agents: AgentStates | None = None
    tokens: PortReader | None = None
    channels: ChannelLookup | None = None
    resources: ResourceSource | None = None
    liveness: AgentLiveness | None = None
    settings: Mapping[str, Mapping[str, Any]] = field(default_factory=dict)
    stopwatch: Timing = UNTIMED
    remote: RemoteGoals | None = None
