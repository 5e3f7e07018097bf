"""``petriflow ctl URL COMMAND ...``: steer a live run from the command line (or a script).

The client connects to the run's WebSocket (the page's URL, with its token), sends one
command, waits for the run to apply or refuse it, prints the answer and exits: 0 when
applied, 1 when the run refused it (too few tokens, no such firing, the run ended), 2
when the command or the URL is malformed or the run cannot be reached.

Examples:
    >>> command_of(["inject", "dock", "2"])
    ('inject', {'place': 'dock', 'count': 2})
    >>> command_of(["break", "place", "done", ">=", "3"])
    ('break', {'spec': 'place done >= 3'})
    >>> command_of(["force", "7", "cancel"])
    ('force', {'firing': '7', 'outcome': 'cancel'})
"""

from __future__ import annotations

import getpass
import json
from typing import Any
from urllib.parse import parse_qs, urlsplit

from petriflow.errors import PetriflowError

__all__ = ["command_of", "websocket_url", "send", "USAGE"]

USAGE = ("pause | resume | step [N] | break SPEC | clear [SPEC] | inject PLACE [N] | remove PLACE [N] |"
         " force FIRING ok|failed|cancel | speed X | status")


def _count(words: list[str], at: int) -> int:
    if len(words) <= at:
        return 1
    if not words[at].isdigit():
        raise PetriflowError(f"ctl {words[0]}: a count is a whole number, got {words[at]!r}")
    return int(words[at])


def command_of(words: list[str]) -> tuple[str, dict[str, Any]]:
    """``(command, args)`` from ``ctl``'s words.

    Raises:
        PetriflowError: not a command (the error gives the usage).
    """
    if not words:
        raise PetriflowError(f"ctl: give a command ({USAGE})")
    name, rest = words[0], words[1:]
    shapes = {"pause": (0, 0), "resume": (0, 0), "status": (0, 0), "step": (0, 1), "break": (1, 99),
              "clear": (0, 99), "inject": (1, 2), "remove": (1, 2), "force": (2, 2), "speed": (1, 1)}
    if name not in shapes:
        raise PetriflowError(f"ctl: unknown command {name!r} ({USAGE})")
    low, high = shapes[name]
    if not low <= len(rest) <= high:
        raise PetriflowError(f"ctl {name}: wrong number of arguments ({USAGE})")
    if name == "step":
        return name, {"count": _count(words, 1)}
    if name in ("break", "clear"):
        return name, ({"spec": " ".join(rest)} if rest else {})
    if name in ("inject", "remove"):
        return name, {"place": rest[0], "count": _count(words, 2)}
    if name == "force":
        return name, {"firing": rest[0], "outcome": rest[1]}
    if name == "speed":
        return name, {"factor": rest[0]}
    return name, {}


def websocket_url(url: str) -> str:
    """The run's WebSocket address from its page's URL (as ``--live`` printed it).

    Raises:
        PetriflowError: not a live page's URL (no token, another scheme).

    Examples:
        >>> websocket_url("http://127.0.0.1:8765/?token=abc")
        'ws://127.0.0.1:8765/ws?token=abc'
    """
    try:
        parts = urlsplit(url)
        token = (parse_qs(parts.query).get("token") or [""])[0]
    except ValueError:
        token, parts = "", None
    if parts is None or parts.scheme not in ("http", "https") or not parts.netloc or not token:
        raise PetriflowError(f"ctl: {url!r} is not a live run's URL (http://HOST:PORT/?token=..., as"
                             " petriflow run --live prints it)")
    scheme = "wss" if parts.scheme == "https" else "ws"
    return f"{scheme}://{parts.netloc}/ws?token={token}"


def send(url: str, command: str, args: dict[str, Any], *, by: str | None = None, timeout: float = 40.0) -> dict[str, Any]:
    """Send one command to the live run at ``url``; returns the run's reply.

    Raises:
        PetriflowError: the run cannot be reached, or refused the connection.
    """
    from websockets.exceptions import InvalidStatus, WebSocketException
    from websockets.sync.client import connect

    target = websocket_url(url)
    who = by or _user()
    try:
        with connect(target, open_timeout=10, close_timeout=2, max_size=2 ** 24) as socket:
            socket.send(json.dumps({"id": 1, "command": command, "args": args, "by": who}))
            while True:
                message = json.loads(socket.recv(timeout=timeout))
                if message.get("type") == "reply" and message.get("id") == 1:
                    return message
    except InvalidStatus as exc:
        status = exc.response.status_code
        raise PetriflowError(f"ctl: the run refused the connection ({status}"
                             f"{': wrong or missing token' if status == 403 else ''})") from None
    except TimeoutError:
        raise PetriflowError(f"ctl: no answer from the run within {timeout:g} s") from None
    except (OSError, WebSocketException) as exc:
        raise PetriflowError(f"ctl: cannot reach the run at {urlsplit(url).netloc}: {exc}") from None


def _user() -> str:
    try:
        return getpass.getuser()
    except Exception:  # noqa: BLE001 - no user name: say so
        return "unknown"
