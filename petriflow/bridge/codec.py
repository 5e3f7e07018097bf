"""Token data across the bridge: JSON, with the core's message type and registered
payload types tagged, and rebuilt on the other side.

What a goal carries (its input tokens' data) and what its result carries back (the
output tokens' data, per place or not) is JSON (:func:`petriflow.bridge.protocol.to_data`).
Some token data holds objects: a channel place's token data is often a
:class:`~petriflow.runtime.channel_models.Message` (petriflow's one message type),
whose ``data`` is a scenario's payload dataclass. :class:`Codec` sends those as tagged
objects and rebuilds them, so an action on an agent reads the very objects a local
action reads, and a token the agent puts is the object a local run would put:

* a :class:`~petriflow.runtime.channel_models.Message`: ``{"$type": "message",
  "place", "sender", "receiver", "data", "time", "size", "distance"}`` (its ``data``
  encoded the same way);
* a dataclass registered as a data type
  (:meth:`Registry.register_data_type <petriflow.runtime.registry.Registry.register_data_type>`):
  ``{"$type": NAME, field: value, ...}``, rebuilt with ``cls(**fields)`` (its
  ``__post_init__`` checks the values, as when it was first made);
* anything else as :func:`~petriflow.bridge.protocol.to_data` sends it: tuples as
  lists, numpy values as numbers and lists, an object with ``to_token()`` its token,
  any other object only its type's name (``"<Thing>"``), which the other side cannot
  rebuild.

A tagged object whose ``$type`` the receiving side does not know (a payload type its
registry lacks) stays the JSON object it is; one that does not rebuild (a missing
field, a value its ``__post_init__`` refuses) raises :class:`CodecError`, and the goal
fails with the reason. A local run does not use the codec: its tokens and traces are
unchanged.

Examples:
    >>> from dataclasses import dataclass
    >>> from petriflow.runtime.channel_models import Message
    >>> @dataclass(frozen=True)
    ... class Hello:
    ...     text: str
    ...     size: int = 5
    >>> codec = Codec({"demo.hello": Hello})
    >>> sent = codec.encode({"message": Message("box", "a", "b", Hello("hi"), 1.5)})
    >>> sent["message"]["$type"], sent["message"]["data"]
    ('message', {'$type': 'demo.hello', 'text': 'hi', 'size': 5})
    >>> codec.decode(sent)["message"] == Message("box", "a", "b", Hello("hi"), 1.5)
    True
    >>> Codec().decode(sent)["message"].data          # a payload type this side lacks: its JSON
    {'$type': 'demo.hello', 'text': 'hi', 'size': 5}
"""

from __future__ import annotations

import dataclasses
from typing import Any, Mapping

from petriflow.bridge import protocol
from petriflow.errors import PetriflowError
from petriflow.runtime.channel_models import Message

__all__ = ["Codec", "CodecError", "TAG", "MESSAGE"]

#: The key naming a tagged object's type.
TAG = "$type"
#: The tag of :class:`~petriflow.runtime.channel_models.Message`.
MESSAGE = "message"
_MESSAGE_FIELDS = ("place", "sender", "receiver", "data", "time", "size", "distance")


class CodecError(PetriflowError):
    """A tagged object that does not rebuild (its type's fields or checks refuse it)."""


class Codec:
    """Encodes token data for the bridge and decodes it (see the module).

    Args:
        types: ``{name: dataclass}``, the registered data types (a registry's
            :meth:`~petriflow.runtime.registry.Registry.data_types`).
    """

    def __init__(self, types: Mapping[str, type] | None = None) -> None:
        self.types = dict(types or {})
        if MESSAGE in self.types:
            raise PetriflowError(f"data type name {MESSAGE!r} is the core message's")
        self.names = {cls: name for name, cls in self.types.items()}

    def encode(self, value: Any, depth: int = 0) -> Any:
        """``value`` as JSON data, messages and registered types tagged.

        Raises:
            ValueError: data nested deeper than the protocol allows.
        """
        if depth > protocol.MAX_DEPTH:
            raise ValueError(f"data nested deeper than {protocol.MAX_DEPTH}")
        if isinstance(value, Message):
            fields = {name: getattr(value, name) for name in _MESSAGE_FIELDS}
            return {TAG: MESSAGE, **{k: self.encode(v, depth + 1) for k, v in fields.items()}}
        name = self.names.get(type(value))
        if name is not None:
            return {TAG: name, **{f.name: self.encode(getattr(value, f.name), depth + 1)
                                  for f in dataclasses.fields(value) if f.init}}
        if isinstance(value, dict):
            return {str(k): self.encode(v, depth + 1) for k, v in value.items()}
        if isinstance(value, (list, tuple)):
            return [self.encode(v, depth + 1) for v in value]
        return protocol.to_data(value, depth)

    def decode(self, value: Any) -> Any:
        """JSON data with its tagged objects rebuilt (unknown tags stay JSON).

        Raises:
            CodecError: a tagged object of a known type that does not rebuild.
        """
        if isinstance(value, list):
            return [self.decode(v) for v in value]
        if not isinstance(value, dict):
            return value
        fields = {k: self.decode(v) for k, v in value.items() if k != TAG}
        tag = value.get(TAG)
        if tag == MESSAGE:
            return self._build(tag, Message, fields)
        cls = self.types.get(tag) if isinstance(tag, str) else None
        if cls is None:  # untagged, or a tag this side does not know: the JSON object itself
            return fields if TAG not in value else {TAG: tag, **fields}
        return self._build(tag, cls, fields)

    @staticmethod
    def _build(tag: str, cls: type, fields: dict[str, Any]) -> Any:
        try:
            return cls(**fields)
        except Exception as exc:
            raise CodecError(f"token data: a {tag!r} object does not rebuild: {type(exc).__name__}: {exc}")\
                from None
