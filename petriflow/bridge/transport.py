"""The one interface the bridge speaks through, and the topics it uses.

A :class:`Transport` publishes bytes on a topic and calls a handler for the bytes
published on the topics a pattern matches; it reconnects by itself when its router
or broker goes away and comes back. Two implementations: Zenoh
(:mod:`petriflow.bridge.zenoh_transport`) and MQTT
(:mod:`petriflow.bridge.mqtt_transport`), chosen by name (:func:`open_transport`).

Topics (the same strings over both; a pattern's ``*`` is one level, MQTT's ``+``):

* ``petriflow/v1/to/AGENT``: goals and cancels for ``AGENT``, and the orchestrator's
  heartbeat to it;
* ``petriflow/v1/from/AGENT``: everything ``AGENT`` sends.

Examples:
    >>> to_agent("red"), from_agent("*")
    ('petriflow/v1/to/red', 'petriflow/v1/from/*')
    >>> agent_of("petriflow/v1/from/blue")
    'blue'
"""

from __future__ import annotations

import importlib
import re
import socket
import time
from dataclasses import dataclass
from typing import Any, Callable, Protocol

from petriflow.errors import PetriflowError

__all__ = ["Transport", "Endpoint", "Handler", "open_transport", "to_agent", "from_agent", "agent_of",
           "TRANSPORTS", "DependencyNotInstalled", "AGENT_NAME", "require", "wait_for_port"]

PREFIX = "petriflow/v1"
#: What an agent name may be (it is one level of a topic).
AGENT_NAME = re.compile(r"^[A-Za-z0-9_][A-Za-z0-9_.-]{0,63}$")
#: ``{name: module}`` of the transports.
TRANSPORTS = {"zenoh": "petriflow.bridge.zenoh_transport", "mqtt": "petriflow.bridge.mqtt_transport"}
#: Called with (topic, payload) for each message received.
Handler = Callable[[str, bytes], None]


class DependencyNotInstalled(PetriflowError):
    """The transport's Python package is missing."""


def require(module: str, package: str, transport: str) -> Any:
    """Import ``module`` (a transport's library), or say which package to install.

    Raises:
        DependencyNotInstalled: it is missing (``pip install petriflow[bridge]``).
    """
    try:
        return importlib.import_module(module)
    except ImportError:
        raise DependencyNotInstalled(f"the {transport} transport needs {package}: pip install petriflow[bridge]")\
            from None


def wait_for_port(port: int, seconds: float = 10.0, host: str = "127.0.0.1") -> None:
    """Wait until something listens on ``host:port`` (a router or broker just started).

    Raises:
        PetriflowError: nothing listens there after ``seconds``.
    """
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        with socket.socket() as sock:
            if sock.connect_ex((host, port)) == 0:
                return
        time.sleep(0.02)
    raise PetriflowError(f"nothing listens on {host}:{port} after {seconds:g} s")


def to_agent(agent: str) -> str:
    """The topic of what is sent to ``agent``."""
    return f"{PREFIX}/to/{agent}"


def from_agent(agent: str) -> str:
    """The topic of what ``agent`` sends (``*``: every agent's)."""
    return f"{PREFIX}/from/{agent}"


def agent_of(topic: str) -> str:
    """The agent a ``to``/``from`` topic names."""
    return topic.rsplit("/", 1)[-1]


@dataclass(frozen=True)
class Endpoint:
    """Where to connect and as whom.

    Attributes:
        connect: the router's or broker's address: ``tcp/HOST:PORT`` (Zenoh's form;
            MQTT takes it too, or ``HOST:PORT``, ``mqtt://HOST:PORT``).
        user: the user name to authenticate with (``None``: none).
        password: its password.
    """

    connect: str
    user: str | None = None
    password: str | None = None

    def host_port(self, default_port: int) -> tuple[str, int]:
        """``(host, port)`` of :attr:`connect`.

        Examples:
            >>> Endpoint("tcp/127.0.0.1:7447").host_port(1883)
            ('127.0.0.1', 7447)
            >>> Endpoint("mqtt://localhost").host_port(1883)
            ('localhost', 1883)
        """
        address = re.sub(r"^(tcp/|mqtt://|tcp://)", "", self.connect)
        host, _, port = address.rpartition(":") if ":" in address else (address, "", "")
        host = host.strip("[]") or "127.0.0.1"
        try:
            return host, int(port) if port else default_port
        except ValueError:
            raise PetriflowError(f"bad endpoint {self.connect!r}: the port must be a number") from None


class Transport(Protocol):
    """A publish/subscribe connection (see the module)."""

    def subscribe(self, pattern: str, handler: Handler) -> None:
        """Call ``handler(topic, payload)`` for each message on a topic ``pattern`` matches
        (kept across reconnects)."""

    def publish(self, topic: str, payload: bytes) -> None:
        """Send ``payload`` on ``topic`` (dropped silently while disconnected)."""

    def close(self) -> None:
        """Disconnect for good."""


def open_transport(kind: str, endpoint: Endpoint, name: str = "") -> Transport:
    """Connect with the transport ``kind`` (``zenoh`` or ``mqtt``).

    Raises:
        PetriflowError: an unknown transport; DependencyNotInstalled: its package is
            missing (``pip install petriflow[bridge]``).
    """
    module = TRANSPORTS.get(kind)
    if module is None:
        raise PetriflowError(f"unknown transport {kind!r} (one of: {', '.join(TRANSPORTS)})")
    return importlib.import_module(module).connect(endpoint, name)
