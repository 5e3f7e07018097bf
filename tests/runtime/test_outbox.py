"""An agent's outbox: per-receiver order, and only the changed receiver's key touched."""

from petriflow.runtime.agents import AgentState
from petriflow.runtime.outbox import KEY, Outbox


def _watched() -> tuple[AgentState, list]:
    state, touched = AgentState(), []
    state.attach(touched.append)
    return state, touched


def test_each_receiver_gets_its_messages_oldest_first():
    box = Outbox()
    for item in ("a1", "b1", "a2"):
        box.put(item[0], item)
    assert [box.take("a"), box.take("a"), box.take("a")] == ["a1", "a2", None]
    assert box.take("b") == "b1" and box.waiting("b") == 0


def test_only_the_receiver_whose_queue_changed_is_touched():
    state, touched = _watched()
    box = Outbox(state)
    box.put("robot2", 1)
    box.take("robot3")  # nothing waits for robot3: nothing changed
    box.take("robot2")
    assert touched == [(KEY.format(peer="robot2"),), ("outbox/robot2",)]

