"""Run services over the bridge: a remote action's context asks the run, the run answers.

An action running on a remote agent reaches the run's services
(:class:`~petriflow.runtime.services.RunServices`) as a local one does (``ctx.read``,
``ctx.latest``, ``ctx.running``), but the services stay where the run is: the agent's
context holds proxies (:func:`calling_services`) that send a
:class:`~petriflow.bridge.protocol.Call` ``{goal id, call number, service, method,
args}`` and wait for its :class:`~petriflow.bridge.protocol.Reply` ``{value | error}``.
The run answers a goal's calls when the kernel polls that goal's firing: on the
kernel's thread, in firing order, from the run's own services (:func:`answer`), so the
value read is the run's at that instant and no agent keeps a copy that could diverge.

What is served (:data:`SERVED`), and what is not:

=============  ==========  =========================================  =================
service        method      context method                             served
=============  ==========  =========================================  =================
``tokens``     ``read``    ``ctx.read(port)``, ``ctx.latest(port)``   yes: the places
                                                                       the action's ports
                                                                       name
``liveness``   ``alive``   ``ctx.running(agent)``                     yes
``liveness``   ``running`` ``ctx.resource(...)`` of type              yes
                           ``core.liveness``: ``.running()``
``settings``               ``ctx.settings``                           on the agent, from
                                                                       its own world file
``agents``                 ``ctx.state``                              on the agent, when
                                                                       its subnet keeps a
                                                                       state
                                                                       (:mod:`~.held`)
``channels``               ``ctx.link``, ``ctx.medium``               no
``resources``              ``ctx.resource``                           ``core.liveness``
                                                                       by calls; those
                                                                       registered
                                                                       ``per_world`` on
                                                                       the agent, from
                                                                       its own world;
                                                                       others refused
                                                                       at bind time
=============  ==========  =========================================  =================

An action that uses a service not served fails its goal with a one-line reason
(:class:`Unserved`), at once, never waiting.

Examples:
    >>> from petriflow.bridge.protocol import Call
    >>> class Board:
    ...     def read(self, place): return [{"seen": place}]
    >>> from petriflow.runtime.services import RunServices
    >>> answer(Call("r/3/1", "red", 1, "tokens", "read", ["S"]), RunServices(tokens=Board()), {"S"})
    Reply(id='r/3/1', agent='red', call=1, value=[{'seen': 'S'}], error='')
    >>> answer(Call("r/3/1", "red", 2, "tokens", "read", ["P9"]), RunServices(tokens=Board()), {"S"}).error
    "tokens.read: place 'P9' is named by none of the action's ports"
    >>> check_call(Call("r/3/1", "red", 1, "agents", "state", [None]))
    'agents.state is not served to remote agents (served: tokens.read, liveness.alive, liveness.running)'
"""

from __future__ import annotations

from typing import Any, Callable, Mapping

from petriflow.bridge import protocol
from petriflow.bridge.codec import Codec
from petriflow.errors import PetriflowError
from petriflow.runtime.resources import LIVENESS
from petriflow.runtime.services import RunServices

__all__ = ["SERVED", "check_call", "answer", "calling_services", "Unserved", "CallRefused"]

#: ``{(service, method): the types of its arguments}``: what remote actions may call.
SERVED: dict[tuple[str, str], tuple[tuple[type, ...], ...]] = {
    ("tokens", "read"): ((str,),),
    ("liveness", "alive"): ((str, type(None)),),
    ("liveness", "running"): (),
}


class CallRefused(PetriflowError):
    """The run refused a remote action's call (its reply's ``error``)."""


def _served() -> str:
    return ", ".join(f"{service}.{method}" for service, method in SERVED)


def check_call(call: protocol.Call) -> str:
    """Why ``call`` is not one the run serves (``""``: it is).

    Examples:
        >>> check_call(protocol.Call("g", "red", 1, "tokens", "read", [3]))
        'tokens.read: argument 1 is a int, not str'
    """
    kinds = SERVED.get((call.service, call.method))
    if kinds is None:
        return f"{call.service[:40]}.{call.method[:40]} is not served to remote agents (served: {_served()})"
    if len(call.args) != len(kinds):
        return f"{call.service}.{call.method} takes {len(kinds)} argument(s), got {len(call.args)}"
    for number, (value, allowed) in enumerate(zip(call.args, kinds), 1):
        if not isinstance(value, allowed):
            return (f"{call.service}.{call.method}: argument {number} is a {type(value).__name__}, not"
                    f" {' or '.join(k.__name__ for k in allowed if k is not type(None))}")
    return ""


def answer(call: protocol.Call, services: RunServices, ports: set[str], codec: Codec | None = None) \
        -> protocol.Reply:
    """The reply to ``call`` (checked with :func:`check_call`) from the run's ``services``;
    ``ports``: the places the goal's action may read (those its ports name); ``codec``:
    how token data is sent (:mod:`~.codec`; default: messages tagged, no payload types)."""
    def refuse(error: str) -> protocol.Reply:
        return protocol.Reply(call.id, call.agent, call.call, None, error)

    if call.service == "tokens":
        place = call.args[0]
        if place not in ports:
            return refuse(f"tokens.read: place {place[:80]!r} is named by none of the action's ports")
        if services.tokens is None:
            return refuse("tokens.read: the run has no tokens to read")
        value: Any = services.tokens.read(place)
    elif call.method == "running":  # the run's core.liveness resource: the agents running now
        resources = services.resources
        live = None if resources is None else resources.get(LIVENESS)
        value = [] if live is None else list(live.running())
    else:
        value = True if services.liveness is None else bool(services.liveness.alive(call.args[0]))
    try:
        data = (codec or Codec()).encode(value)
        reply = protocol.Reply(call.id, call.agent, call.call, data)
        protocol.encode(reply)
    except ValueError as exc:
        return refuse(f"{call.service}.{call.method}: {exc}")
    return reply


class Unserved:
    """A run service a remote agent's context cannot reach: every use raises at once."""

    def __init__(self, service: str, uses: str) -> None:
        self.service = service
        self.uses = uses

    def __getattr__(self, name: str) -> Callable[..., Any]:
        if name.startswith("__"):
            raise AttributeError(name)

        def refuse(*args: Any, **kwargs: Any) -> Any:
            raise CallRefused(f"{self.uses} reaches the run's {self.service}, which is not served to remote"
                              f" agents (served: {_served()}; leave this subnet local)")
        return refuse


class _Tokens:
    def __init__(self, call: Callable[[str, str, list], Any], codec: Codec) -> None:
        self._call = call
        self._codec = codec

    def read(self, place: str) -> list[Any]:
        value = self._call("tokens", "read", [place])
        if not isinstance(value, list):
            raise CallRefused(f"tokens.read: the run replied with a {type(value).__name__}, not a list")
        return self._codec.decode(value)


class _Liveness:
    """``ctx.running`` and the ``core.liveness`` resource on an agent: the run's answers."""

    def __init__(self, call: Callable[[str, str, list], Any]) -> None:
        self._call = call

    def alive(self, agent: str | None) -> bool:
        value = self._call("liveness", "alive", [agent])
        if not isinstance(value, bool):
            raise CallRefused(f"liveness.alive: the run replied with a {type(value).__name__}, not a bool")
        return value

    def running(self) -> list[str]:
        value = self._call("liveness", "running", [])
        if not isinstance(value, list) or not all(isinstance(a, str) for a in value):
            raise CallRefused("liveness.running: the run replied with no list of agent names")
        return value


class _Resources:
    """``ctx.resource`` on an agent: the run's ``core.liveness`` (served by calls), the
    resources made per world from the agent's own world (``own``: the agent's
    :class:`~petriflow.runtime.resources.Resources` for the run, ``own_kinds`` the
    per-world types); any other resource is refused when the net is bound."""

    def __init__(self, live: _Liveness, own: Any = None, own_kinds: Callable[[str], bool] | None = None) -> None:
        self._live = live
        self._own = own
        self._own_kinds = own_kinds

    def get(self, kind: str) -> Any:
        if kind == LIVENESS:
            return self._live
        if self._own is not None and self._own_kinds is not None and self._own_kinds(kind):
            return self._own.get(kind)
        raise CallRefused(f"resource {kind!r} is not served to remote agents (served: {LIVENESS}, and the"
                          " resources registered per_world, made on the agent)")


def calling_services(settings: Mapping[str, Mapping[str, Any]],
                     call: Callable[[str, str, list], Any], agents: Any = None, own: Any = None,
                     own_kinds: Callable[[str], bool] | None = None, codec: Codec | None = None) -> RunServices:
    """A remote goal's services: ``settings`` (the agent's own), proxies that ``call``
    the run for what :data:`SERVED` lists, :class:`Unserved` for the rest; ``agents``
    (the agent's own, when it holds its subnet's state: :mod:`petriflow.bridge.held`)
    serves ``ctx.state`` on the agent; ``own`` (the agent's resources made from its own
    world) serves ``ctx.resource`` for the types ``own_kinds`` says are per world;
    ``codec`` decodes the token data the run replies (:mod:`~.codec`).

    Examples:
        >>> services = calling_services({}, lambda service, method, args: [f"{service}.{method}{args}"])
        >>> services.tokens.read("S")
        ["tokens.read['S']"]
        >>> services.agents.state("red")
        Traceback (most recent call last):
        ...
        petriflow.bridge.calls.CallRefused: ctx.state reaches the run's agent states, which is not served to remote agents (served: tokens.read, liveness.alive, liveness.running; leave this subnet local)
    """
    live = _Liveness(call)
    return RunServices(agents=agents if agents is not None else Unserved("agent states", "ctx.state"),
                       tokens=_Tokens(call, codec or Codec()),
                       channels=Unserved("channel places", "ctx.link/ctx.medium"),
                       resources=_Resources(live, own, own_kinds), liveness=live, settings=settings)
