"""The bridge over MQTT (``paho-mqtt``; a broker such as Debian's ``mosquitto``).

One paho client per transport, its network loop in a thread; it reconnects by itself
(every 0.1 to 1 s) when the broker comes back and subscribes again on each
connection. Messages go at QoS 1 (the broker acknowledges them); what is sent while
disconnected is dropped, and the bridge's own re-sending (goals again with the same
id, agents de-duplicating) makes up for it.
"""

from __future__ import annotations

import logging
import socket
import threading
import uuid
from typing import Any

from petriflow.bridge.transport import Endpoint, Handler, require

__all__ = ["MqttTransport", "connect", "DEFAULT_PORT"]

DEFAULT_PORT = 1883
#: QoS 1 messages a client keeps in flight (unacknowledged by the broker) at once.
MAX_INFLIGHT = 1000
#: The MQTT quality of service of every message.
QOS = 1
log = logging.getLogger("petriflow.bridge")


def _mqtt() -> Any:
    return require("paho.mqtt.client", "paho-mqtt", "mqtt")


class MqttTransport:
    """A paho-mqtt client (:class:`~petriflow.bridge.transport.Transport`)."""

    def __init__(self, endpoint: Endpoint, name: str = "") -> None:
        mqtt = _mqtt()
        self._subscriptions: list[tuple[str, Handler]] = []
        self._lock = threading.Lock()
        self.connected = threading.Event()
        client_id = f"petriflow-{name or 'client'}-{uuid.uuid4().hex[:8]}"
        self.client = mqtt.Client(mqtt.CallbackAPIVersion.VERSION2, client_id=client_id, clean_session=True)
        if endpoint.user is not None:
            self.client.username_pw_set(endpoint.user, endpoint.password)
        self.client.reconnect_delay_set(min_delay=0.1, max_delay=1)
        # QoS 1 messages in flight before paho queues the rest (its default of 20 halves a burst's rate)
        self.client.max_inflight_messages_set(MAX_INFLIGHT)
        self.client.on_connect = self._on_connect
        self.client.on_disconnect = self._on_disconnect
        self.client.on_message = self._on_message
        host, port = endpoint.host_port(DEFAULT_PORT)
        self.client.connect_async(host, port, keepalive=5)
        self.client.loop_start()

    def _on_connect(self, client: Any, userdata: Any, flags: Any, reason: Any, properties: Any = None) -> None:
        if getattr(reason, "is_failure", False):
            return
        sock = client.socket()
        if sock is not None:  # small messages at once, not after Nagle's wait for an acknowledgement
            sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        with self._lock:
            for pattern, _ in self._subscriptions:
                client.subscribe(_mqtt_pattern(pattern), qos=QOS)
        self.connected.set()

    def _on_disconnect(self, *args: Any) -> None:
        self.connected.clear()

    def _on_message(self, client: Any, userdata: Any, message: Any) -> None:
        with self._lock:
            handlers = [handler for pattern, handler in self._subscriptions if _matches(pattern, message.topic)]
        for handler in handlers:
            try:
                handler(message.topic, message.payload)
            except Exception:  # a handler's error must never end the network loop
                log.exception("bridge: handling a message on %s failed", message.topic)

    def subscribe(self, pattern: str, handler: Handler) -> None:
        with self._lock:
            self._subscriptions.append((pattern, handler))
        if self.connected.is_set():
            self.client.subscribe(_mqtt_pattern(pattern), qos=QOS)

    def publish(self, topic: str, payload: bytes) -> None:
        self.client.publish(topic, payload, qos=QOS)

    def close(self) -> None:
        self.client.disconnect()
        self.client.loop_stop()


def _mqtt_pattern(pattern: str) -> str:
    """A pattern's ``*`` levels as MQTT's ``+``."""
    return "/".join("+" if level == "*" else level for level in pattern.split("/"))


def _matches(pattern: str, topic: str) -> bool:
    """Whether ``topic`` matches ``pattern`` (``*``: any one level).

    Examples:
        >>> _matches("a/*/c", "a/b/c"), _matches("a/*", "a/b/c")
        (True, False)
    """
    want, have = pattern.split("/"), topic.split("/")
    return len(want) == len(have) and all(w in ("*", h) for w, h in zip(want, have))


def connect(endpoint: Endpoint, name: str = "") -> MqttTransport:
    """A client of the broker at ``endpoint``."""
    return MqttTransport(endpoint, name)
