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

def test_goals_the_run_is_done_with_are_forgotten_and_their_replays_still_dropped():
    """10,000 goals through the dispatcher, each answered and done with as a run does: it holds no
    more than one goal and at most KEPT_ENDED ended ids per agent; a result replayed for a goal
    long forgotten is dropped and counted, never recorded."""
    from petriflow.bridge.dispatcher import KEPT_ENDED

    bridge = dispatcher()
    try:
        held = 0
        for number in range(1, 10_001):
            goal_id = protocol.goal_id("r", number)
            bridge.send(protocol.Goal(goal_id, "red", "core.noop", {}))
            bridge.receive(from_agent("red"), protocol.encode(protocol.Accepted(goal_id, "red")))
            bridge.receive(from_agent("red"), protocol.encode(protocol.Result(goal_id, "red", "ok", number)))
            assert bridge.goal(goal_id).data == number
            held = max(held, len(bridge.goals))
            bridge.done(goal_id)
            bridge.transport.sent.clear()
        assert held == 1 and not bridge.goals
        assert len(bridge.ended["red"]) == KEPT_ENDED
        assert not bridge.dropped
        recent, old = protocol.goal_id("r", 10_000), protocol.goal_id("r", 1)
        for goal_id in (recent, old):
            bridge.receive(from_agent("red"), protocol.encode(protocol.Result(goal_id, "red", "ok", "again")))
        assert bridge.goal(recent) is None and bridge.goal(old) is None  # never recorded
        assert dict(bridge.dropped) == {"replayed": 1, "unknown_goal": 1}  # the old one: beyond the record
    finally:
        bridge.close()


def test_an_answer_expected_twice_after_a_resend_is_dropped_silently_once_done(timed):
    """A goal sent again may be answered twice: the second answer, after the run is done with
    the goal, is dropped without being counted as a replay."""
    bridge, now = timed
    bridge.send(protocol.Goal("r/1/1", "red", "core.noop", {}))
    now[0] += 3 * bridge.spec.heartbeat
    bridge.receive(from_agent("red"), protocol.encode(protocol.Heartbeat("red", [])))
    bridge.send_again()
    assert bridge.goal("r/1/1").resent == 1
    result = protocol.encode(protocol.Result("r/1/1", "red", "ok", 1))
    bridge.receive(from_agent("red"), result)
    bridge.done("r/1/1")
    bridge.receive(from_agent("red"), result)
    assert bridge.goal("r/1/1") is None and not bridge.dropped


def test_a_cancel_not_acknowledged_in_time_gives_the_goal_up_and_holds_its_agent_lost(timed):
    """The cancel's deadline passes: the goal is abandoned, its agent lost (why: the cancel) while its
    heartbeats list the goal; the late acknowledgement is dropped and counted; then the agent is back."""
    bridge, now = timed
    spec = bridge.spec
    bridge.receive(from_agent("red"), protocol.encode(protocol.Announce("red", {})))
    bridge.send(protocol.Goal("r/1/1", "red", "core.noop", {}, "go"))
    bridge.receive(from_agent("red"), protocol.encode(protocol.Heartbeat("red", ["r/1/1"])))
    bridge.cancel("r/1/1")
    assert bridge.goal("r/1/1").cancel_asked == 0.0 and spec.cancel_timeout == spec.heartbeat_timeout
    now[0] = spec.cancel_timeout * 0.9
    bridge.receive(from_agent("red"), protocol.encode(protocol.Heartbeat("red", ["r/1/1"])))
    assert bridge.watch() == ([], []) and not bridge.goal("r/1/1").ended
    now[0] = spec.cancel_timeout * 1.1
    bridge.receive(from_agent("red"), protocol.encode(protocol.Heartbeat("red", ["r/1/1"])))
    assert bridge.watch() == (["red"], [])
    state = bridge.goal("r/1/1")
    assert state.phase == Phase.ABANDONED and "not acknowledged" in state.reason
    assert "did not acknowledge the cancel of 'go'" in bridge.why_lost("red")
    bridge.done("r/1/1")
    bridge.receive(from_agent("red"), protocol.encode(protocol.Announce("red", {})))
    assert bridge.watch() == ([], [])  # alive, but still doing the goal given up
    bridge.receive(from_agent("red"), protocol.encode(protocol.Cancelled("r/1/1", "red")))  # late
    assert dict(bridge.dropped) == {"replayed": 1}
    bridge.receive(from_agent("red"), protocol.encode(protocol.Heartbeat("red", [])))
    assert bridge.watch() == ([], ["red"]) and not bridge.is_lost("red")


def test_feedback_is_kept_for_the_run_in_order_and_a_flood_is_bounded(timed):
    """Feedback waits for the run's thread (take_feedback), oldest first; beyond KEPT_FEEDBACK the
    oldest are left out and counted; feedback that came with the goal's end is still taken."""
    from petriflow.bridge.dispatcher import KEPT_FEEDBACK

    bridge, _ = timed
    goal = protocol.Goal("r/1/1", "red", "core.noop", {}, "go")
    bridge.send(goal)
    for k in range(KEPT_FEEDBACK + 3):
        bridge.receive(from_agent("red"), protocol.encode(protocol.Feedback("r/1/1", "red", {"k": k})))
    [(taken, items, skipped)] = bridge.take_feedback()
    assert taken == goal and skipped == 3 and items[0] == {"k": 3} and len(items) == KEPT_FEEDBACK
    assert bridge.take_feedback() == []
    bridge.receive(from_agent("red"), protocol.encode(protocol.Feedback("r/1/1", "red", "last")))
    bridge.receive(from_agent("red"), protocol.encode(protocol.Result("r/1/1", "red", "ok")))
    bridge.done("r/1/1")
    assert bridge.take_feedback() == [(goal, ["last"], 0)]
