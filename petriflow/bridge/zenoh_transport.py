"""The bridge over Zenoh (``eclipse-zenoh``): a client session, and a router in Python.

Zenoh is one of ROS 2's transports; its Python session can itself be the router
(:func:`serve_router`), so nothing else is installed. A client session reconnects by
itself when the router comes back, and keeps its subscriptions.
"""

from __future__ import annotations

import json
import logging
from typing import Any

from petriflow.bridge.transport import Endpoint, Handler, require
from petriflow.errors import PetriflowError

__all__ = ["ZenohTransport", "connect", "serve_router", "DEFAULT_PORT"]

DEFAULT_PORT = 7447
#: How long opening a client session waits for the router (milliseconds).
CONNECT_TIMEOUT_MS = 10_000
log = logging.getLogger("petriflow.bridge")


def _zenoh() -> Any:
    return require("zenoh", "eclipse-zenoh", "zenoh")


def _config(mode: str, endpoint: Endpoint, *, listen: bool = False) -> Any:
    zenoh = _zenoh()
    config = zenoh.Config()
    host, port = endpoint.host_port(DEFAULT_PORT)
    address = json.dumps([f"tcp/{host}:{port}"])
    config.insert_json5("mode", json.dumps(mode))
    config.insert_json5("scouting/multicast/enabled", "false")
    config.insert_json5("listen/endpoints" if listen else "connect/endpoints", address)
    if not listen:
        # the router must answer within the timeout at the start (a wrong password or address is
        # an error, not a wait for ever); once connected, a restarted router is found again quickly
        config.insert_json5("connect/timeout_ms", str(CONNECT_TIMEOUT_MS))
        config.insert_json5("connect/exit_on_failure", "true")
        config.insert_json5("connect/retry", json.dumps({"period_init_ms": 100, "period_max_ms": 500,
                                                          "period_increase_factor": 1.5}))
    if endpoint.user is not None:
        config.insert_json5("transport/auth/usrpwd/user", json.dumps(endpoint.user))
        config.insert_json5("transport/auth/usrpwd/password", json.dumps(endpoint.password or ""))
    return config


class ZenohTransport:
    """A Zenoh client session (:class:`~petriflow.bridge.transport.Transport`)."""

    def __init__(self, endpoint: Endpoint) -> None:
        zenoh = _zenoh()
        try:
            self.session = zenoh.open(_config("client", endpoint))
        except zenoh.ZError as exc:
            raise PetriflowError(f"cannot connect to the Zenoh router at {endpoint.connect}"
                                 f"{' as ' + endpoint.user if endpoint.user else ''}: {str(exc).split(' at /')[0]}")\
                from None
        self._subscribers: list[Any] = []
        self._publishers: dict[str, Any] = {}

    def subscribe(self, pattern: str, handler: Handler) -> None:
        def receive(sample: Any) -> None:
            try:
                handler(str(sample.key_expr), sample.payload.to_bytes())
            except Exception:  # a handler's error must never reach Zenoh's threads
                log.exception("bridge: handling a message on %s failed", sample.key_expr)

        self._subscribers.append(self.session.declare_subscriber(pattern, receive))

    def publish(self, topic: str, payload: bytes) -> None:
        publisher = self._publishers.get(topic)
        if publisher is None:
            publisher = self._publishers[topic] = self.session.declare_publisher(topic)
        publisher.put(payload)

    def close(self) -> None:
        for publisher in self._publishers.values():
            publisher.undeclare()
        for subscriber in self._subscribers:
            subscriber.undeclare()
        self._publishers.clear()
        self._subscribers.clear()
        self.session.close()


def connect(endpoint: Endpoint, name: str = "") -> ZenohTransport:
    """A client session to the router at ``endpoint``."""
    return ZenohTransport(endpoint)


def serve_router(listen: Endpoint, *, users: dict[str, str] | None = None) -> Any:
    """A Zenoh router listening on ``listen`` (a session in router mode; close it to
    stop). ``users``: ``{user: password}`` a client must authenticate as."""
    zenoh = _zenoh()
    config = _config("router", Endpoint(listen.connect), listen=True)
    if users:
        import os
        import tempfile

        handle, path = tempfile.mkstemp(prefix="petriflow-zenoh-users-", text=True)
        with os.fdopen(handle, "w") as out:
            out.writelines(f"{user}:{password}\n" for user, password in users.items())
        config.insert_json5("transport/auth/usrpwd/dictionary_file", json.dumps(path))
    return zenoh.open(config)
