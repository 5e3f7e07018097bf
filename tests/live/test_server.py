"""The live server's security and bounds (docs/security.md): the token, the origin,
malformed requests, many connections, huge frames, and stopping with the run."""

from __future__ import annotations

import contextlib
import http.client
import json
import socket

import pytest

from petriflow.live.server import MAX_CLIENTS, MAX_FRAME, LiveServer, parse_address
from petriflow.runtime.control import Control

pytest.importorskip("websockets")
from websockets.exceptions import ConnectionClosed, InvalidStatus  # noqa: E402
from websockets.sync.client import connect  # noqa: E402


@pytest.fixture
def server():
    live = LiveServer(Control(interactive=True), "<!DOCTYPE html><title>page</title>", "127.0.0.1", 0,
                      token="secret-token")
    live.start()
    try:
        yield live
    finally:
        live.stop()


def get(server: LiveServer, path: str, method: str = "GET", headers: dict | None = None) -> tuple[int, bytes]:
    connection = http.client.HTTPConnection("127.0.0.1", server.port, timeout=10)
    try:
        connection.request(method, path, headers=headers or {})
        response = connection.getresponse()
        return response.status, response.read()
    finally:
        connection.close()


def ws(server: LiveServer, token: str = "secret-token", **options):
    return connect(f"ws://127.0.0.1:{server.port}/ws?token={token}", open_timeout=10, **options)


def test_requests_without_the_right_token_are_forbidden(server):
    """No token or a wrong one: 403, for the page and the WebSocket alike."""
    assert get(server, "/")[0] == 403
    assert get(server, "/?token=secret-tokeN")[0] == 403
    assert get(server, "/ws?token=nope")[0] == 403
    with pytest.raises(InvalidStatus) as refused:
        ws(server, token="wrong")
    assert refused.value.response.status_code == 403


def test_the_page_is_served_with_the_token_and_nothing_else(server):
    """With the token: the page (no file of the machine is reachable); other paths 404."""
    status, body = get(server, "/?token=secret-token")
    assert status == 200 and body.startswith(b"<!DOCTYPE html>")
    assert get(server, "/../../etc/passwd?token=secret-token")[0] == 404
    assert get(server, "/run.jsonl?token=secret-token")[0] == 404


def test_another_origin_is_forbidden(server):
    """A page of another site that somehow has the token still cannot connect."""
    assert get(server, "/ws?token=secret-token", headers={"Origin": "http://evil.example"})[0] == 403


def test_malformed_requests_get_400(server):
    """/ws without a WebSocket upgrade, and malformed commands, are 400."""
    assert get(server, "/ws?token=secret-token")[0] == 400
    with ws(server) as client:
        snapshot = json.loads(client.recv(timeout=10))
        assert snapshot["type"] == "snapshot"
        for bad in ("not json", "[1, 2]", json.dumps({"id": 7, "command": "jump"}),
                    json.dumps({"id": 8, "command": "inject", "args": {"place": "p", "count": -1}}),
                    json.dumps({"id": 9, "command": "pause", "args": "x"})):
            client.send(bad)
            reply = json.loads(client.recv(timeout=10))
            assert reply["type"] == "reply" and reply["ok"] is False and reply["status"] == 400, reply


def test_a_huge_frame_closes_the_connection(server):
    """A frame over MAX_FRAME bytes is refused (1009) and the server goes on."""
    with ws(server) as client:
        client.recv(timeout=10)
        client.send("x" * (MAX_FRAME + 1))
        with pytest.raises(ConnectionClosed) as closed:
            client.recv(timeout=10)
        assert closed.value.rcvd.code == 1009
    with ws(server) as client:
        assert json.loads(client.recv(timeout=10))["type"] == "snapshot"


def test_connections_are_bounded(server):
    """Beyond MAX_CLIENTS connections at once, the next is refused (503)."""
    with contextlib.ExitStack() as stack:
        for _ in range(MAX_CLIENTS):
            stack.enter_context(ws(server)).recv(timeout=10)
        with pytest.raises(InvalidStatus) as refused:
            ws(server)
        assert refused.value.response.status_code == 503


def test_the_server_stops_with_the_run():
    """After stop() nothing listens on the port and open connections are closed."""
    live = LiveServer(Control(), "page", "127.0.0.1", 0)
    live.start()
    with ws(live, token=live.token) as client:
        client.recv(timeout=10)
        live.stop()
        with pytest.raises(ConnectionClosed):
            client.recv(timeout=10)
    with pytest.raises(OSError):
        socket.create_connection(("127.0.0.1", live.port), timeout=2).close()


def test_addresses():
    """--live takes [HOST:]PORT, loopback by default; anything else is a clear error."""
    from petriflow.errors import PetriflowError

    assert parse_address("0") == ("127.0.0.1", 0)
    assert parse_address("[::1]:9000") == ("::1", 9000)
    for bad in ("", "host:", "x:70000", "abc"):
        with pytest.raises(PetriflowError, match="HOST:]PORT"):
            parse_address(bad)


def test_a_folded_nets_page_and_subnets_are_drawn_when_asked_for():
    """A net drawn folded: the page holds no subnet's picture; each is served, with the
    token, when the page opens it (an SVG of that subnet); an unknown one is 404."""
    pytest.importorskip("shutil").which("dot") or pytest.skip("Graphviz is not installed")
    import re
    import tempfile
    from pathlib import Path

    from petriflow.io import load_net
    from petriflow.live.page import LivePage
    from tests.live.test_live_memory import team

    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "team.yaml"
        path.write_text(team())
        net = load_net(path)
    page = LivePage(net)
    live = LiveServer(Control(interactive=True), page, "127.0.0.1", 0, token="secret-token")
    live.start()
    try:
        status, body = get(live, "/?token=secret-token")
        data = json.loads(re.search(rb'id="pf-data">(.*?)</script>', body, re.S).group(1))
        assert sorted(data["folded"]) == ["agent:a", "agent:b"]
        assert all(part["svg"] is None for part in data["folded"].values())  # drawn when opened
        status, svg = get(live, "/part?key=agent:a&token=secret-token")
        assert status == 200 and svg.lstrip().startswith(b"<svg") and b">at0<" in svg and b">bt0<" not in svg
        assert get(live, "/part?key=agent:a")[0] == 403
        assert get(live, "/part?key=agent:nobody&token=secret-token")[0] == 404
        assert get(live, "/part?key=../../etc/passwd&token=secret-token")[0] == 404
    finally:
        live.stop()


def test_the_page_names_the_net_and_says_what_it_is():
    """The page's title and header give the net's id and its own description (its label)."""
    from petriflow.io.yaml import loads_net
    from petriflow.live.page import live_page

    net = loads_net("petriflow: 1\nnet: relay\nlabel: two robots <hand over> a box\nplaces: [{id: i, tokens: 1}, o]\n"
                    "transitions: [{id: t, in: [i], out: [o]}]\n")
    page = live_page(net)
    assert "<title>relay: live run: two robots &lt;hand over&gt; a box</title>" in page
    assert '<div id="about" class="note">two robots &lt;hand over&gt; a box</div>' in page
