"""A run configuration's ``bridge:`` section: which subnets run on remote agents.

::

    bridge:
      transport: zenoh              # or mqtt
      connect: tcp/127.0.0.1:7447   # the router or broker (loopback by default)
      agents: {red: red, blue: blue}   # subnet (its agent) -> the remote agent's name
      heartbeat: 0.5                # seconds between heartbeats, both ways
      heartbeat_timeout: 3          # an agent silent this long is lost
      cancel_timeout: 3             # a cancel not acknowledged this long gives the goal up (default: heartbeat_timeout)
      wait: 10                      # seconds to wait for the agents to announce themselves
      rejoin: 30                    # seconds a run with nothing else to do waits for a lost agent
      user: robot                   # authenticate as (optional)
      password_env: PETRIFLOW_BRIDGE_PASSWORD   # the password, from this environment variable

Subnets not listed run in the run's own process, as without a bridge.

Examples:
    >>> spec = BridgeSpec.from_dict({"transport": "mqtt", "connect": "127.0.0.1:1883", "agents": {"red": "r1"}})
    >>> spec.agents, spec.heartbeat_timeout, spec.cancel_timeout
    ({'red': 'r1'}, 3.0, 3.0)
    >>> BridgeSpec.from_dict({"transport": "tcp", "agents": {}})
    Traceback (most recent call last):
    ...
    petriflow.errors.NetFormatError: bridge: unknown transport 'tcp' (one of: zenoh, mqtt)
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from typing import Any, Callable

from petriflow.bridge.transport import AGENT_NAME, TRANSPORTS, Endpoint
from petriflow.errors import NetFormatError, did_you_mean

__all__ = ["BridgeSpec", "DEFAULT_CONNECT"]

_KEYS = ("transport", "connect", "agents", "heartbeat", "heartbeat_timeout", "cancel_timeout", "wait", "rejoin",
         "user", "password_env")
#: Where each transport connects by default: loopback.
DEFAULT_CONNECT = {"zenoh": "tcp/127.0.0.1:7447", "mqtt": "tcp/127.0.0.1:1883"}


@dataclass(frozen=True)
class BridgeSpec:
    """The ``bridge:`` section (see the module).

    Attributes:
        transport: ``zenoh`` or ``mqtt``.
        connect: the router's or broker's endpoint.
        agents: ``{subnet: remote agent name}``.
        heartbeat: seconds between heartbeats.
        heartbeat_timeout: seconds of silence after which an agent is lost.
        cancel_timeout: seconds a cancel may go unacknowledged: then the run gives the
            goal up (its firing ends ``failed``: what the action did is unknown) and
            holds the agent lost while its heartbeats still list the goal.
        wait: seconds to wait for the agents to announce themselves before binding.
        rejoin: seconds a run waits for a lost agent to come back (when nothing else is
            to happen; afterwards it may end ``dead``).
        user: the user to authenticate as (``None``: none).
        password_env: the environment variable holding its password.
    """

    transport: str
    connect: str
    agents: dict[str, str] = field(default_factory=dict)
    heartbeat: float = 0.5
    heartbeat_timeout: float = 3.0
    wait: float = 10.0
    rejoin: float = 30.0
    user: str | None = None
    password_env: str | None = None
    cancel_timeout: float = 3.0

    @classmethod
    def from_dict(cls, data: Any, fail: Callable[..., Any] | None = None) -> "BridgeSpec":
        """The section from parsed YAML; ``fail(message, key=...)`` reports an error
        (default: raise :class:`NetFormatError` naming no file)."""

        def refuse(message: str, key: str | None = None) -> Any:
            if fail is not None:
                fail(f"bridge: {message}", key="bridge")
            raise NetFormatError(f"bridge: {message}")

        if not isinstance(data, dict):
            refuse("bridge is a mapping such as {transport: zenoh, agents: {red: red}}")
        for key in data:
            if key not in _KEYS:
                refuse(f"unknown key {key!r}{did_you_mean(str(key), _KEYS)}")
        transport = data.get("transport")
        if transport not in TRANSPORTS:
            refuse(f"unknown transport {transport!r} (one of: {', '.join(TRANSPORTS)})")
        connect = data.get("connect", DEFAULT_CONNECT[transport])
        if not isinstance(connect, str) or not connect.strip():
            refuse(f"connect takes an endpoint such as {DEFAULT_CONNECT[transport]}, got {connect!r}")
        agents = data.get("agents")
        if not isinstance(agents, dict) or not agents:
            refuse("agents maps subnets to the remote agents that run them, e.g. {red: red}")
        for subnet, name in agents.items():
            if not isinstance(name, str) or not AGENT_NAME.match(name):
                refuse(f"agents: {subnet!r}: an agent name is letters, digits, '_', '.', '-' (at most 64),"
                       f" got {name!r}")
        times = {}
        given = data.get("heartbeat_timeout", 3.0)
        for key, default in (("heartbeat", 0.5), ("heartbeat_timeout", 3.0), ("wait", 10.0), ("rejoin", 30.0),
                             ("cancel_timeout", given)):
            value = data.get(key, default)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) \
                    or not 0 < value <= 3600:
                refuse(f"{key} must be a number of seconds > 0 and at most 3600, got {value!r}")
            times[key] = float(value)
        if times["heartbeat_timeout"] <= times["heartbeat"]:
            refuse(f"heartbeat_timeout ({times['heartbeat_timeout']:g} s) must be longer than heartbeat"
                   f" ({times['heartbeat']:g} s)")
        user, password_env = data.get("user"), data.get("password_env")
        for key, value in (("user", user), ("password_env", password_env)):
            if value is not None and not isinstance(value, str):
                refuse(f"{key} must be a string, got {value!r}")
        return cls(transport, connect.strip(), {str(k): v for k, v in agents.items()}, times["heartbeat"],
                   times["heartbeat_timeout"], times["wait"], times["rejoin"], user, password_env,
                   times["cancel_timeout"])

    def endpoint(self) -> Endpoint:
        """Where to connect, with the credentials (the password read from
        :attr:`password_env` now)."""
        password = os.environ.get(self.password_env) if self.password_env else None
        return Endpoint(self.connect, self.user, password)

    def to_dict(self) -> dict[str, Any]:
        """Plain data (what the journal keeps; the password is never in it)."""
        data: dict[str, Any] = {"transport": self.transport, "connect": self.connect, "agents": dict(self.agents),
                                "heartbeat": self.heartbeat, "heartbeat_timeout": self.heartbeat_timeout,
                                "cancel_timeout": self.cancel_timeout, "wait": self.wait, "rejoin": self.rejoin}
        if self.user is not None:
            data["user"] = self.user
        if self.password_env is not None:
            data["password_env"] = self.password_env
        return data
