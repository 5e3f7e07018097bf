"""The remote-action protocol: versioned messages between a run and its agents.

A run (the *orchestrator*) and the processes that execute its actions (*agents*: a
``petriflow agent``, or a robot speaking the protocol in any language) exchange small
JSON objects over a publish/subscribe transport (:mod:`petriflow.bridge.transport`).
Every message has ``v`` (the protocol version, :data:`VERSION`), ``type`` (a
:class:`Kind`) and the fields its dataclass declares; docs/bridge.md is the
language-neutral description.

==============  ==============  ===================================================
message         sent by         says
==============  ==============  ===================================================
``announce``    agent           its name, the actions it serves with their parameters
``heartbeat``   both            alive; an agent's lists the goals it is running
``goal``        orchestrator    run this action (an idempotent ``id``: run/firing/attempt)
``accepted``    agent           the goal runs (also the answer to a goal sent again)
``rejected``    agent           the goal cannot run (unknown action, bad parameters)
``feedback``    agent           progress of a running goal (optional)
``result``      agent           ``ok`` with the output token data, or ``failed``
``cancel``      orchestrator    stop this goal
``cancelled``   agent           the goal was stopped (the cancel's acknowledgement)
``call``        agent           a running goal's action asks the run's services (a port, liveness)
``reply``       orchestrator    the call's value, or why it was refused
==============  ==============  ===================================================

Everything that comes from the network is data: :func:`decode` parses JSON (never
code), refuses a message over :data:`MAX_MESSAGE` bytes before parsing it, and checks
the version, the type and each field's type; what it refuses is a :class:`Refused`
with the :class:`Drop` reason the receiver counts.

Examples:
    >>> goal = Goal(id="r1/3/1", agent="red", action="core.wait", params={"seconds": 1.0},
    ...             transition="t", inputs={"i": [None]}, seed="1:3")
    >>> data = encode(goal)
    >>> decode(data) == goal
    True
    >>> decode(b'{"v": 1, "type": "result", "id": "x"}')
    Traceback (most recent call last):
    ...
    petriflow.bridge.protocol.Refused: malformed: result: missing field 'agent'
"""

from __future__ import annotations

import dataclasses
import json
import math
from dataclasses import dataclass, field
from typing import Any, ClassVar

from petriflow.errors import PetriflowError
from petriflow.outcome import Name

__all__ = ["VERSION", "MAX_MESSAGE", "Kind", "Drop", "Refused", "Announce", "Heartbeat", "Goal", "Accepted",
           "Rejected", "Feedback", "Result", "Cancel", "Cancelled", "Call", "Reply", "BridgeMessage", "About", "encode", "decode", "goal_id",
           "to_data"]

#: The protocol version this code speaks (a message of another version is dropped).
VERSION = 1
#: The largest message accepted, in bytes (a larger one is dropped unread).
MAX_MESSAGE = 1 << 20
#: The deepest nesting of lists and mappings accepted in a message.
MAX_DEPTH = 32
#: Fields added to version 1 compatibly (agent-held state): left out of a message
#: when empty, so a message that does not use them is the bytes it always was.
EXTENSIONS = frozenset({"state", "guards", "seq", "events", "outputs", "per_place"})


class Kind(Name):
    """The types of message."""

    ANNOUNCE = "announce"
    HEARTBEAT = "heartbeat"
    GOAL = "goal"
    ACCEPTED = "accepted"
    REJECTED = "rejected"
    FEEDBACK = "feedback"
    RESULT = "result"
    CANCEL = "cancel"
    CANCELLED = "cancelled"
    CALL = "call"
    REPLY = "reply"


class Drop(Name):
    """Why a received message was dropped (each reason is counted)."""

    OVERSIZED = "oversized"
    """Longer than :data:`MAX_MESSAGE`."""
    MALFORMED = "malformed"
    """Not JSON, not an object, an unknown type, a missing or ill-typed field."""
    VERSION = "version"
    """Another protocol version."""
    UNKNOWN_AGENT = "unknown_agent"
    """From an agent name the run's configuration does not list."""
    UNKNOWN_GOAL = "unknown_goal"
    """About a goal this run never sent."""
    REPLAYED = "replayed"
    """About a goal already ended (a result or acknowledgement received twice)."""
    WRONG_AGENT = "wrong_agent"
    """About a goal sent to another agent."""
    UNKNOWN_CALL = "unknown_call"
    """A call of a service or method the run does not serve, or with ill-typed arguments."""


class Refused(PetriflowError):
    """A message :func:`decode` refuses; :attr:`drop` says why."""

    def __init__(self, drop: Drop, detail: str) -> None:
        super().__init__(f"{drop.value}: {detail}")
        self.drop = drop


@dataclass(frozen=True)
class BridgeMessage:
    """Fields every message of the bridge protocol has (subclasses add theirs): what
    travels between a run and its agents, not the runtime's
    :class:`~petriflow.runtime.channel_models.Message` between agents of a run."""

    kind: ClassVar[Kind]


@dataclass(frozen=True)
class Announce(BridgeMessage):
    """An agent says who it is and what it serves.

    Attributes:
        agent: its name.
        actions: ``{action: {parameter: {"type": TYPE, "default": VALUE}}}`` (a
            parameter without ``default`` is required; ``type`` one of ``float``,
            ``int``, ``str``, ``bool``, ``list``, ``dict``, ``any``).
        instance: a name for the agent's process, new at every start (a restarted
            agent is told from one that only lost some messages).
    """

    kind: ClassVar[Kind] = Kind.ANNOUNCE
    agent: str
    actions: dict[str, dict[str, Any]]
    instance: str = ""


@dataclass(frozen=True)
class Heartbeat(BridgeMessage):
    """Alive. From an agent, ``running`` lists the goal ids it is executing; the
    orchestrator's has ``agent`` ``""``."""

    kind: ClassVar[Kind] = Kind.HEARTBEAT
    agent: str
    running: list[str] = field(default_factory=list)
    instance: str = ""


@dataclass(frozen=True)
class Goal(BridgeMessage):
    """Run ``action`` with ``params`` on ``inputs`` (``{place: [token data]}``).

    ``id`` is idempotent: the same goal sent again (after a reconnect) carries the same
    id, and an agent that has it already answers as for the first one, never running
    the action twice. ``seed`` seeds the firing's random generator as a local run would.
    ``state`` (not empty: the goal's subnet keeps an agent state, held by the agent) is
    ``{"type": NAME, "guards": {transition: [guard, params]}}``: the state type the
    subnet declares (``""``: none) and the subnet's guards over that state, which the
    agent evaluates and sends back with its results (:mod:`petriflow.bridge.held`).
    """

    kind: ClassVar[Kind] = Kind.GOAL
    id: str
    agent: str
    action: str
    params: dict[str, Any]
    transition: str = ""
    inputs: dict[str, list[Any]] = field(default_factory=dict)
    seed: str = ""
    state: dict[str, Any] = field(default_factory=dict)


@dataclass(frozen=True)
class About(BridgeMessage):
    """A message about the goal ``id`` of ``agent`` (the answers, and a cancel)."""

    id: str
    agent: str


@dataclass(frozen=True)
class Rejected(About):
    """The goal ``id`` cannot run, and why."""

    kind: ClassVar[Kind] = Kind.REJECTED
    reason: str = ""


@dataclass(frozen=True)
class Feedback(About):
    """Progress of the goal ``id``; ``guards`` (with their snapshot number ``seq``): the
    values of its subnet's state guards after the agent's state changed mid-action."""

    kind: ClassVar[Kind] = Kind.FEEDBACK
    data: Any = None
    guards: dict[str, bool] = field(default_factory=dict)
    seq: int = 0


@dataclass(frozen=True)
class Result(About):
    """The goal ``id`` ended: ``outcome`` ``ok`` (``data``: the output tokens' data) or
    ``failed`` (``reason``). For a goal whose subnet's state the agent holds,
    ``guards`` are the values of the subnet's state guards when it ended, ``seq`` their
    snapshot's number (a newer snapshot replaces an older one); ``events`` are the
    custom events its action emitted, ``[[name, data], ...]``."""

    kind: ClassVar[Kind] = Kind.RESULT
    outcome: str
    data: Any = None
    reason: str = ""
    guards: dict[str, bool] = field(default_factory=dict)
    seq: int = 0
    events: list[Any] = field(default_factory=list)
    outputs: dict[str, Any] = field(default_factory=dict)
    per_place: bool = False


def _bare(name: str, kind: Kind, doc: str) -> type[About]:
    """A message about a goal with no field of its own."""
    cls = type(name, (About,), {"__doc__": doc, "__module__": __name__, "__annotations__": {"kind": "ClassVar[Kind]"},
                                "kind": kind})
    return dataclass(frozen=True)(cls)


@dataclass(frozen=True)
class Call(About):
    """The running goal ``id``'s action asks the run's ``service`` (``method`` with
    ``args``, JSON data); ``call`` numbers the goal's calls from 1, so a call sent
    again (no reply came) is answered once (see :mod:`petriflow.bridge.calls`)."""

    kind: ClassVar[Kind] = Kind.CALL
    call: int
    service: str
    method: str
    args: list[Any] = field(default_factory=list)


@dataclass(frozen=True)
class Reply(About):
    """The answer to the goal ``id``'s call ``call``: its ``value`` (JSON data), or
    ``error`` (not empty: the call was refused, e.g. the goal was cancelled)."""

    kind: ClassVar[Kind] = Kind.REPLY
    call: int
    value: Any = None
    error: str = ""


Accepted = _bare("Accepted", Kind.ACCEPTED, "The goal ``id`` runs.")
Cancel = _bare("Cancel", Kind.CANCEL, "Stop the goal ``id``.")
Cancelled = _bare("Cancelled", Kind.CANCELLED, "The goal ``id`` stopped (acknowledges :class:`Cancel`).")

_TYPES: dict[str, type[BridgeMessage]] = {cls.kind.value: cls for cls in
                                    (Announce, Heartbeat, Goal, Accepted, Rejected, Feedback, Result, Cancel,
                                     Cancelled, Call, Reply)}
_OUTCOMES = ("ok", "failed")


def goal_id(run: str, firing: int, attempt: int = 1) -> str:
    """The idempotent id of a goal: ``run/firing/attempt``.

    Examples:
        >>> goal_id("4f2a", 12)
        '4f2a/12/1'
    """
    return f"{run}/{firing}/{attempt}"


def to_data(value: Any, depth: int = 0) -> Any:
    """``value`` as JSON data: tuples and sets become lists, numpy values plain
    numbers and lists, any other object its ``to_token()`` or its type's name.

    Examples:
        >>> to_data({"p": (1, 2), "s": {3}})
        {'p': [1, 2], 's': [3]}
    """
    if depth > MAX_DEPTH:
        raise ValueError(f"data nested deeper than {MAX_DEPTH}")
    if value is None or isinstance(value, (bool, int, str)):
        return value
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {str(k): to_data(v, depth + 1) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [to_data(v, depth + 1) for v in value]
    if isinstance(value, (set, frozenset)):
        return sorted((to_data(v, depth + 1) for v in value), key=repr)
    if hasattr(value, "tolist"):  # numpy arrays and scalars
        return to_data(value.tolist(), depth + 1)
    if hasattr(value, "to_token"):
        return to_data(value.to_token(), depth + 1)
    return f"<{type(value).__name__}>"


def encode(message: BridgeMessage) -> bytes:
    """``message`` as the bytes sent (compact JSON, ``v`` and ``type`` first).

    Raises:
        ValueError: the encoded message is longer than :data:`MAX_MESSAGE`.
    """
    body = {"v": VERSION, "type": message.kind.value}
    for item in dataclasses.fields(message):
        value = getattr(message, item.name)
        if item.name in EXTENSIONS and not value:
            continue  # left out when empty: a peer that predates it reads the message unchanged
        body[item.name] = to_data(value)
    data = json.dumps(body, separators=(",", ":"), allow_nan=False).encode()
    if len(data) > MAX_MESSAGE:
        raise ValueError(f"a {message.kind.value} message of {len(data):,} bytes is over the limit of"
                         f" {MAX_MESSAGE:,}")
    return data


def _depth(value: Any, depth: int = 0) -> int:
    if depth > MAX_DEPTH:
        return depth
    if isinstance(value, dict):
        return max((_depth(v, depth + 1) for v in value.values()), default=depth)
    if isinstance(value, list):
        return max((_depth(v, depth + 1) for v in value), default=depth)
    return depth


_FIELD_TYPES = {"str": str, "dict[str, Any]": dict, "dict[str, bool]": dict, "bool": bool, "dict[str, dict[str, Any]]": dict,
                "dict[str, list[Any]]": dict, "list[str]": list,
                "int": int, "list[Any]": list}


def decode(data: bytes | bytearray | memoryview | str) -> BridgeMessage:
    """The message in ``data``, checked (see the module).

    Raises:
        Refused: oversized, not JSON, another version, an unknown type, a missing,
            unknown or ill-typed field.
    """
    if len(data) > MAX_MESSAGE:
        raise Refused(Drop.OVERSIZED, f"{len(data):,} bytes (the limit is {MAX_MESSAGE:,})")
    try:
        body = json.loads(bytes(data) if not isinstance(data, str) else data)
    except (ValueError, UnicodeDecodeError) as exc:
        raise Refused(Drop.MALFORMED, f"not JSON ({exc})") from None
    if not isinstance(body, dict):
        raise Refused(Drop.MALFORMED, "not a JSON object")
    if body.get("v") != VERSION:
        raise Refused(Drop.VERSION, f"version {body.get('v')!r} (this is version {VERSION})")
    kind = body.get("type")
    cls = _TYPES.get(kind) if isinstance(kind, str) else None
    if cls is None:
        raise Refused(Drop.MALFORMED, f"unknown type {kind!r}")
    if _depth(body) > MAX_DEPTH:
        raise Refused(Drop.MALFORMED, f"{kind}: nested deeper than {MAX_DEPTH}")
    values: dict[str, Any] = {}
    for item in dataclasses.fields(cls):
        if item.name not in body:
            if item.default is dataclasses.MISSING and item.default_factory is dataclasses.MISSING:
                raise Refused(Drop.MALFORMED, f"{kind}: missing field {item.name!r}")
            continue
        value = body[item.name]
        wanted = _FIELD_TYPES.get(str(item.type))
        if wanted is not None and not isinstance(value, wanted):
            raise Refused(Drop.MALFORMED, f"{kind}: field {item.name!r} is not a {wanted.__name__}")
        values[item.name] = value
    unknown = set(body) - {"v", "type"} - {item.name for item in dataclasses.fields(cls)}
    if unknown:
        raise Refused(Drop.MALFORMED, f"{kind}: unknown field {sorted(unknown)[0]!r}")
    if cls is Result and values["outcome"] not in _OUTCOMES:
        raise Refused(Drop.MALFORMED, f"result: outcome {values['outcome']!r} is neither ok nor failed")
    if cls is Heartbeat and not all(isinstance(g, str) for g in values.get("running", [])):
        raise Refused(Drop.MALFORMED, "heartbeat: running lists goal ids (strings)")
    if cls is Goal and not all(isinstance(v, list) for v in values.get("inputs", {}).values()):
        raise Refused(Drop.MALFORMED, "goal: inputs maps places to lists of token data")
    if cls in (Call, Reply) and (isinstance(values["call"], bool) or values["call"] < 1):
        raise Refused(Drop.MALFORMED, f"{kind}: call numbers a goal's calls from 1")
    if cls in (Result, Feedback) and not all(isinstance(v, bool) for v in values.get("guards", {}).values()):
        raise Refused(Drop.MALFORMED, f"{kind}: guards maps transitions to true or false")
    if cls in (Result, Feedback) and (isinstance(values.get("seq", 0), bool) or values.get("seq", 0) < 0):
        raise Refused(Drop.MALFORMED, f"{kind}: seq numbers the guards' snapshots from 1")
    if cls is Result and not all(isinstance(e, list) and len(e) == 2 and isinstance(e[0], str)
                                 and isinstance(e[1], dict) for e in values.get("events", [])):
        raise Refused(Drop.MALFORMED, "result: events lists [name, data] pairs")
    if cls is Announce and not all(isinstance(v, dict) for v in values["actions"].values()):
        raise Refused(Drop.MALFORMED, "announce: actions maps each action to its parameters")
    return cls(**values)
