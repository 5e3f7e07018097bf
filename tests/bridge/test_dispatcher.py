"""The orchestrator's side: hostile messages are dropped and counted, lost goals sent again."""

import pytest

from petriflow.bridge import protocol
from petriflow.bridge.dispatcher import Dispatcher, Phase
from petriflow.bridge.spec import BridgeSpec
from petriflow.bridge.transport import from_agent


class Loopback:
    """A transport that keeps what is published (no network)."""

    def __init__(self):
        self.sent = []

    def subscribe(self, pattern, handler):
        pass

    def publish(self, topic, payload):
        self.sent.append((topic, protocol.decode(payload)))

    def close(self):
        pass


def dispatcher(now=None, **spec) -> Dispatcher:
    """A dispatcher over a transport that keeps what it sends (``now``: its clock)."""
    spec = BridgeSpec.from_dict({"transport": "mqtt", "agents": {"red": "red"}, "heartbeat": 1000,
                                 "heartbeat_timeout": 2000, **spec})
    return Dispatcher(spec, Loopback(), run="r", **({} if now is None else {"now": lambda: now[0]}))


@pytest.fixture
def timed():
    """``(dispatcher, now)``: a dispatcher whose clock is ``now[0]`` seconds, closed after the test."""
    now = [0.0]
    made = dispatcher(now)
    yield made, now
    made.close()


def test_hostile_messages_are_dropped_and_counted_by_reason():
    """Malformed, oversized, unknown agent, unknown goal, replayed result, another agent's goal."""
    bridge = dispatcher()
    try:
        bridge.send(protocol.Goal("r/1/1", "red", "core.noop", {}))
        result = protocol.encode(protocol.Result("r/1/1", "red", "ok", 5))
        bridge.receive(from_agent("red"), b"{not json")
        bridge.receive(from_agent("red"), b"x" * (11 << 20))
        bridge.receive(from_agent("mallory"), result)
        bridge.receive(from_agent("red"), protocol.encode(protocol.Result("r/99/1", "red", "ok")))
        bridge.receive(from_agent("red"), result)
        bridge.receive(from_agent("red"), result)  # replayed
        bridge.receive(from_agent("red"), protocol.encode(protocol.Accepted("r/1/1", "blue")))
        assert bridge.goal("r/1/1").phase == Phase.OK and bridge.goal("r/1/1").data == 5
        assert dict(bridge.dropped) == {"malformed": 1, "oversized": 1, "unknown_agent": 1, "unknown_goal": 1,
                                        "replayed": 1, "wrong_agent": 1}
    finally:
        bridge.close()


def test_a_goal_the_agent_does_not_hold_is_sent_again_with_the_same_id(timed):
    """After a heartbeat that does not list it (lost in a broker restart), the same goal goes again."""
    bridge, now = timed
    bridge.send(protocol.Goal("r/1/1", "red", "core.noop", {}))
    bridge.receive(from_agent("red"), protocol.encode(protocol.Heartbeat("red", ["r/1/1"])))
    spec_beat = bridge.spec.heartbeat
    now[0] += 3 * spec_beat
    bridge.send_again()
    assert len(bridge.transport.sent) == 1  # the agent holds it: not sent again
    bridge.receive(from_agent("red"), protocol.encode(protocol.Heartbeat("red", [])))
    now[0] += 3 * spec_beat
    bridge.send_again()
    again = [m for _, m in bridge.transport.sent if isinstance(m, protocol.Goal)]
    assert [g.id for g in again] == ["r/1/1", "r/1/1"] and bridge.goal("r/1/1").resent == 1


def test_an_agent_silent_past_the_timeout_is_lost_and_back_when_it_announces():
    now = [0.0]
    bridge = dispatcher(now, heartbeat=1, heartbeat_timeout=3)
    try:
        bridge.receive(from_agent("red"), protocol.encode(protocol.Announce("red", {})))
        assert bridge.watch() == ([], [])
        now[0] = 2.9
        assert bridge.watch() == ([], [])
        now[0] = 3.1
        assert bridge.watch() == (["red"], []) and bridge.is_lost("red")
        bridge.receive(from_agent("red"), protocol.encode(protocol.Heartbeat("red")))
        assert bridge.watch() == ([], [])  # a heartbeat is not enough: it must announce itself again
        bridge.receive(from_agent("red"), protocol.encode(protocol.Announce("red", {})))
        assert bridge.watch() == ([], ["red"]) and not bridge.is_lost("red")
    finally:
        bridge.close()


def test_goals_held_by_an_agent_that_restarted_fail_and_are_not_sent_again(timed):
    """A new instance announcing itself means the old process died: its goals fail, never run twice."""
    bridge, now = timed
    bridge.receive(from_agent("red"), protocol.encode(protocol.Announce("red", {}, "first")))
    bridge.send(protocol.Goal("r/1/1", "red", "core.noop", {}))
    bridge.receive(from_agent("red"), protocol.encode(protocol.Announce("red", {}, "first")))
    assert not bridge.goal("r/1/1").ended  # the same process again: nothing happened
    bridge.receive(from_agent("red"), protocol.encode(protocol.Announce("red", {}, "second")))
    state = bridge.goal("r/1/1")
    assert state.phase == Phase.FAILED and "restarted" in state.reason
    now[0] += 10 * bridge.spec.heartbeat
    bridge.send_again()
    assert sum(isinstance(m, protocol.Goal) for _, m in bridge.transport.sent) == 1