"""The live page's server: the run page fed as the run goes, and its controls.

``petriflow run NET --live [HOST:]PORT`` starts a :class:`LiveServer` beside the run.
It serves, on one port, the page (``GET /?token=…``; drawn when first asked for, and a
folded net's subnets at ``/part?key=agent:SUBNET&token=…`` when the page opens one:
:class:`~petriflow.live.page.LivePage`) and a WebSocket (``/ws?token=…``)
that sends the page a snapshot when it connects, then what changed, at most
:data:`RATE` times a second, and takes the page's (and ``petriflow ctl``'s) controls,
which go to the run's :class:`~petriflow.runtime.control.Control` and nowhere else.

The server is `websockets <https://websockets.readthedocs.io>`_' asyncio server, run
in a thread of its own: a maintained implementation of RFC 6455 with its frame size,
its receive queue and the opening handshake's time bounded, and plain HTTP responses
for the page. (Server-sent events would need a second channel for the controls; a
WebSocket carries both.)

Security (docs/security.md): it listens on loopback unless told otherwise; every
request must carry the run's secret token (a request without it, or with another, gets
403; a page from another origin gets 403); the only things served are the page (made
before the run, from the net) and the run's state; a command names a place, a
transition or a firing of the run and is checked before it is queued (malformed: 400);
at most :data:`MAX_CLIENTS` connections, frames of at most :data:`MAX_FRAME` bytes; the
server stops with the run.
"""

from __future__ import annotations

import asyncio
import hmac
import http
import json
import secrets
import threading
from collections import deque
from typing import Any
from urllib.parse import parse_qs, urlsplit

from petriflow.errors import PetriflowError
from petriflow.runtime.control import Control, ControlError, Intervention
from petriflow.runtime.trace import Event
from petriflow.live.state import WINDOW, LiveState, Sample

__all__ = ["LiveServer", "parse_address", "RATE", "MAX_CLIENTS", "MAX_FRAME"]

#: Updates a second sent to a page at most.
RATE = 20
#: Connections (pages and ``ctl`` clients) at once at most.
MAX_CLIENTS = 8
#: The largest frame a client may send, in bytes (a command is a few hundred).
MAX_FRAME = 16 * 1024
#: Seconds a command waits for the run to apply it (a run busy in a long step).
REPLY_WAIT = 30.0


def parse_address(text: str) -> tuple[str, int]:
    """``[HOST:]PORT`` as ``(host, port)``; the host defaults to loopback.

    Raises:
        PetriflowError: not an address.

    Examples:
        >>> parse_address("8765"), parse_address("0.0.0.0:0")
        (('127.0.0.1', 8765), ('0.0.0.0', 0))
    """
    host, _, port = str(text).rpartition(":")
    host = host.strip("[]") or "127.0.0.1"
    if not port.isdigit() or not 0 <= int(port) <= 65535:
        raise PetriflowError(f"--live takes [HOST:]PORT (port 0: a free one), got {text!r}")
    return host, int(port)


class LiveServer:
    """Serves one run's live page and controls (see the module).

    Args:
        control: the run's control queue.
        page: the page's HTML, or what makes it when first asked for (a
            :class:`~petriflow.live.page.LivePage`: ``page()`` and ``part(key)``).
        host, port: where to listen (port 0: a free one).
        token: the secret every request must carry (default: a new random one).
        window: events a page keeps.
    """

    def __init__(self, control: Control, page: Any, host: str = "127.0.0.1", port: int = 0, *,
                 token: str | None = None, window: int = WINDOW) -> None:
        self.control = control
        self.page = page
        self.host, self.port = host, port
        self.token = token or secrets.token_urlsafe(24)
        self.state = LiveState(window)
        self.clients: set[Any] = set()
        self.refused = 0  # connections refused (no token, too many, malformed)
        self._busy = 0  # commands waiting for the run's answer
        self._inbox: deque[Any] = deque()  # events from the run's thread (deque appends are atomic)
        self._thread: threading.Thread | None = None
        self._loop: asyncio.AbstractEventLoop | None = None
        self._ready = threading.Event()
        self._done: asyncio.Event | None = None
        self._error: BaseException | None = None
        self._fresh: asyncio.Event | None = None  # set (in the server's thread) when the inbox has something
        control.listeners.append(self._put)

    # The run's thread -------------------------------------------------------------
    def __call__(self, event: Event) -> None:
        """An observer of the run's events (``scheduler.on_event``)."""
        self._put(event)

    def _put(self, item: Any) -> None:
        """Leave ``item`` for the server's thread and wake it (it sleeps while the run
        sends nothing: a paused run, or one between samples, costs no wakeup)."""
        self._inbox.append(item)
        loop, fresh = self._loop, self._fresh
        if loop is not None and fresh is not None and not fresh.is_set():
            try:
                loop.call_soon_threadsafe(fresh.set)
            except RuntimeError:  # the server has stopped; stop() drains what is left
                pass

    def watch(self, scheduler: Any) -> None:
        """Follow ``scheduler``: its rare events (``run``, ``control``, ``stop``), and
        samples of its state after an instant at most :data:`RATE` times a second of
        wall time, and whenever its control queue waits (a paused run)."""
        import time as wallclock

        tokens, ids, agents = scheduler.tokens, scheduler.index.ids, scheduler.index.agent
        places, counts = tokens.places, tokens.counts
        seen = [-1] * len(places)
        period = 1.0 / RATE
        last = [0.0]

        def sample(*_: Any, force: bool = False) -> None:
            now = wallclock.perf_counter()
            if not force and now - last[0] < period:
                return
            last[0] = now
            changed = {}
            for i, n in enumerate(counts):
                if n != seen[i]:
                    seen[i] = n
                    changed[places[i]] = n
            running = tuple({"t": ids[f.index], "agent": agents[f.index], "firing": f.number,
                             "since": f.ctx.started if f.ctx is not None else f.started}
                            for f in scheduler.runner.in_firing_order())
            self._put(Sample(round(scheduler.now, 9), changed, running))

        scheduler.on_event(self, kinds=["run", "control", "stop"])
        scheduler.on_instant(sample)
        self.control.waiting.append(lambda: sample(force=True))

    @property
    def url(self) -> str:
        """The page's address, with the token."""
        host = f"[{self.host}]" if ":" in self.host else self.host
        return f"http://{host}:{self.port}/?token={self.token}"

    def start(self) -> str:
        """Listen (in a thread of its own); returns the page's URL.

        Raises:
            PetriflowError: the address cannot be listened on.
        """
        self._thread = threading.Thread(target=self._main, name="petriflow-live", daemon=True)
        self._thread.start()
        self._ready.wait()
        if self._error is not None:
            raise PetriflowError(f"--live {self.host}:{self.port}: cannot listen: "
                                 f"{getattr(self._error, 'strerror', None) or self._error}")
        return self.url

    def stop(self) -> None:
        """The run ended: send the pages what is left, close every connection, stop."""
        self.control.close()
        if self._loop is not None and self._done is not None and self._thread is not None:
            self._loop.call_soon_threadsafe(self._done.set)
            self._thread.join(timeout=10)

    def __enter__(self) -> "LiveServer":
        self.start()
        return self

    def __exit__(self, *exc: Any) -> None:
        self.stop()

    # The server's thread ------------------------------------------------------------
    def _main(self) -> None:
        try:
            asyncio.run(self._serve())
        except BaseException as exc:  # noqa: BLE001 - reported by start()
            self._error = exc
            self._ready.set()

    async def _serve(self) -> None:
        from websockets.asyncio.server import serve

        self._loop = asyncio.get_running_loop()
        self._done = asyncio.Event()
        self._fresh = asyncio.Event()
        async with serve(self._connection, self.host, self.port, process_request=self._request,
                         max_size=MAX_FRAME, max_queue=4, open_timeout=5, ping_interval=20,
                         ping_timeout=20, close_timeout=2, server_header=None,
                         logger=_QuietLogger()) as server:
            self.port = server.sockets[0].getsockname()[1]
            self._ready.set()
            publisher = asyncio.create_task(self._publish())
            await self._done.wait()
            for _ in range(100):  # the replies of commands the run took just before it ended
                if not self._busy:
                    break
                await asyncio.sleep(0.02)
            publisher.cancel()
            self._drain()
            self._send(self.state.batch())
            for client in list(self.clients):
                await client.close(1001, "the run ended")

    async def _request(self, connection: Any, request: Any) -> Any:
        """Every HTTP request: the token, the origin, the path; the page, or on to the
        WebSocket handshake."""
        from websockets.datastructures import Headers
        from websockets.http11 import Response

        def answer(status: http.HTTPStatus, body: bytes, kind: str = "text/plain; charset=utf-8") -> Response:
            if status != http.HTTPStatus.OK:
                self.refused += 1
            headers = Headers([("Content-Type", kind), ("Content-Length", str(len(body))),
                               ("Cache-Control", "no-store"), ("X-Content-Type-Options", "nosniff"),
                               ("Referrer-Policy", "no-referrer"), ("Connection", "close")])
            return Response(status.value, status.phrase, headers, body)

        try:
            parts = urlsplit(request.path)
            query = parse_qs(parts.query, max_num_fields=4)
        except ValueError:
            return answer(http.HTTPStatus.BAD_REQUEST, b"malformed request\n")
        given = (query.get("token") or [""])[0]
        if not hmac.compare_digest(given.encode("utf-8", "replace"), self.token.encode("utf-8")):
            return answer(http.HTTPStatus.FORBIDDEN, b"forbidden: this run's token is needed\n")
        origin = request.headers.get("Origin")
        if origin is not None and urlsplit(origin).netloc != request.headers.get("Host"):
            return answer(http.HTTPStatus.FORBIDDEN, b"forbidden: another origin\n")
        if parts.path == "/":
            page = self.page.encode("utf-8") if isinstance(self.page, str) else \
                await asyncio.to_thread(self.page.page)  # drawn in a thread: the updates go on
            return answer(http.HTTPStatus.OK, page, "text/html; charset=utf-8")
        if parts.path == "/part":
            key = (query.get("key") or [""])[0]
            svg = None if isinstance(self.page, str) else await asyncio.to_thread(self.page.part, key)
            if svg is None:
                return answer(http.HTTPStatus.NOT_FOUND, b"no such part of the net\n")
            return answer(http.HTTPStatus.OK, svg, "image/svg+xml")
        if parts.path != "/ws":
            return answer(http.HTTPStatus.NOT_FOUND, b"not found\n")
        if "websocket" not in request.headers.get("Upgrade", "").lower():
            return answer(http.HTTPStatus.BAD_REQUEST, b"/ws is a WebSocket\n")
        if len(self.clients) >= MAX_CLIENTS:
            return answer(http.HTTPStatus.SERVICE_UNAVAILABLE, b"too many connections\n")
        return None

    async def _connection(self, client: Any) -> None:
        try:
            self._drain()
            self._send(self.state.batch())  # the pages already open get what is new first
            snapshot = self.state.snapshot()
            snapshot["control"] = self.control.state()
            self.clients.add(client)
            await client.send(json.dumps(snapshot, separators=(",", ":")))
            async for message in client:
                await client.send(json.dumps(await self._command(message), separators=(",", ":")))
        except Exception:  # noqa: BLE001 - a connection that breaks ends; the run goes on
            pass
        finally:
            self.clients.discard(client)

    async def _command(self, message: Any) -> dict[str, Any]:
        """One command from a client: ``{"id": N, "command": NAME, "args": {...}, "by": WHO}``."""
        ident = None
        try:
            if not isinstance(message, str):
                raise ControlError("a command is a JSON text frame")
            request = json.loads(message)
            if not isinstance(request, dict):
                raise ControlError("a command is a JSON object")
            ident = request.get("id") if isinstance(request.get("id"), (int, str)) else None
            if request.get("command") == "status":
                return {"type": "reply", "id": ident, "ok": True, "status": 200, "message": "status",
                        "control": self.control.state(), "time": self.state.time,
                        "marking": {p: n for p, n in self.state.counts.items() if n},
                        "running": list(self.state.running.values()), "stop": self.state.stop}
            args = request.get("args") or {}
            if not isinstance(args, dict):
                raise ControlError("a command's args are a JSON object")
            intervention = Intervention.of(str(request.get("command")), args, by=request.get("by") or "unknown")
        except (ValueError, ControlError) as exc:
            return {"type": "reply", "id": ident, "ok": False, "status": 400, "message": str(exc)}
        reply = self.control.submit(intervention)
        self._busy += 1
        try:
            await asyncio.to_thread(reply.done.wait, REPLY_WAIT)
        finally:
            self._busy -= 1
        if not reply.done.is_set():
            return {"type": "reply", "id": ident, "ok": False, "status": 504,
                    "message": f"the run did not reach a checkpoint within {REPLY_WAIT:g} s; still queued"}
        return {"type": "reply", "id": ident, "ok": reply.ok, "status": 200 if reply.ok else 409,
                "message": reply.message, "control": self.control.state()}

    def _drain(self) -> None:
        """Take in what the run's thread left in the inbox."""
        inbox, state = self._inbox, self.state
        while inbox:
            item = inbox.popleft()
            if isinstance(item, Event):
                state.apply(item)
            elif isinstance(item, Sample):
                state.take(item)
            else:
                state.control = item

    async def _publish(self) -> None:
        """What changed, to every page, when the run has left something, at most
        :data:`RATE` times a second."""
        while True:
            await self._fresh.wait()
            await asyncio.sleep(1.0 / RATE)  # what else comes meanwhile goes in the same batch
            self._fresh.clear()
            self._drain()
            if self.clients:
                self._send(self.state.batch())
            else:
                self.state.batch()  # nobody to send it to: the next page gets a snapshot

    def _send(self, batch: dict[str, Any] | None) -> None:
        from websockets.asyncio.server import broadcast

        if batch is None or not self.clients:
            return
        batch["control"] = self.control.state()
        broadcast(self.clients, json.dumps(batch, separators=(",", ":")))


class _QuietLogger:
    """websockets' log, kept out of the run's output (a refused or broken connection
    is the client's business; the counts are on the server)."""

    def __getattr__(self, name: str) -> Any:
        return lambda *args, **kwargs: None

    def isEnabledFor(self, level: int) -> bool:  # noqa: N802 - logging's name
        return False
