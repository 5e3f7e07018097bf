"""Channels between agents and injected faults."""

import pytest

from petriflow.errors import NetFormatError
from petriflow.io.yaml import loads_net
from petriflow.runtime.channels import BusChannel, Message, RangeChannel
from petriflow.runtime.config import RunConfig
from petriflow.runtime.scheduler import Scheduler
from petriflow.testing import StubWorld

TALK = """
petriflow: 1
subnets:
  - id: a
    places: [{id: a_ready, tokens: 1}, a_done]
    transitions: [{id: send, action: core.set, params: {value: {size: 4}}, in: [a_ready], out: [a_done, inbox]}]
  - id: b
    places: [{id: inbox, channel: radio}, b_done]
    transitions: [{id: receive, in: [inbox], out: [b_done]}]
"""


def run(config=None, world=None, until=10):
    scheduler = Scheduler(loads_net(TALK), config=config, world=world)
    events = []
    scheduler.on_event(events.append)
    return scheduler.run(until=until), events


def messages(events):
    return [(e.data["fate"], e.time) for e in events if e.kind == "message"]


def test_ideal_channel_delivers_after_its_latency():
    """A token put in a channel place arrives after the model's delay."""
    result, events = run(RunConfig(channels={"radio": {"model": "ideal", "latency": 0.25}}))
    assert messages(events) == [("sent", 0.0), ("delivered", 0.25)]
    assert result.marking == {"a_done": 1, "b_done": 1}


def test_out_of_range_message_is_lost():
    """The range model drops messages whose RSSI is under the threshold."""
    config = RunConfig(channels={"radio": {"model": "range", "tx_power_dbm": -40, "exponent": 2.0,
                                           "threshold_dbm": -63.4375}})
    near = StubWorld(positions={"a": (0, 0), "b": (1, 0)})
    far = StubWorld(positions={"a": (0, 0), "b": (30, 0)})
    assert run(config, near)[0].marking == {"a_done": 1, "b_done": 1}
    result, events = run(config, far)
    assert result.marking == {"a_done": 1}
    assert [e.data["why"] for e in events if e.kind == "message"] == ["channel model"]


def test_dropped_link_loses_messages_until_restored():
    """drop_link loses what the two agents send each other in that window."""
    config = RunConfig.from_dict({"faults": [{"drop_link": ["a", "b"], "at": 0, "until": 5}]})
    result, events = run(config)
    assert result.marking == {"a_done": 1}
    assert [e.data for e in events if e.kind == "message"][0]["why"] == "link down"


def test_killed_agent_stops_and_its_running_action_is_cancelled():
    """kill stops an agent's running action (outcome cancelled) and its transitions."""
    net = loads_net("""
petriflow: 1
subnets:
  - {id: r1, places: [{id: go, tokens: 2}, done], transitions: [{id: walk, action: core.wait, params: {seconds: 4}, in: [go], out: [done]}]}
  - {id: r2, places: [{id: go2, tokens: 1}, done2], transitions: [{id: walk2, action: core.wait, params: {seconds: 6}, in: [go2], out: [done2]}]}
""")
    config = RunConfig.from_dict({"faults": [{"kill": "r1", "at": 1}]})
    scheduler = Scheduler(net, config=config)
    events = []
    scheduler.on_event(events.append)
    result = scheduler.run()
    ends = [(e.transition, e.data["outcome"], e.time) for e in events if e.kind == "end"]
    assert ends == [("walk", "cancelled", 1.0), ("walk2", "ok", 6.0)]
    assert result.marking == {"go": 1, "done2": 1}


def test_late_joiner_starts_only_when_it_joins():
    """An agent that joins at t does nothing before t."""
    config = RunConfig.from_dict({"faults": [{"join": "a", "at": 3}]})
    result, events = run(config)
    first = [e for e in events if e.kind == "start"][0]
    assert first.time == 3.0 and result.marking == {"a_done": 1, "b_done": 1}


def test_faults_must_name_known_agents():
    """A fault naming an agent the net lacks is bad input."""
    config = RunConfig.from_dict({"faults": [{"kill": "robot9", "at": 1}]})
    with pytest.raises(NetFormatError, match="unknown agent 'robot9'"):
        Scheduler(loads_net(TALK), config=config)


def test_unknown_channel_model_is_rejected():
    """Channel models are looked up by name with a hint."""
    with pytest.raises(NetFormatError, match="unknown channel model 'rang'.*did you mean 'range'"):
        RunConfig.from_dict({"channels": {"radio": {"model": "rang"}}})


def test_bus_with_arbitration_queues_frames():
    """On an arbitrated bus a second frame waits for the first."""
    bus = BusChannel(baud=1000.0, overhead_bits=0)
    first = bus.deliver(Message("p", "a", "b", None, 0.0, size=10), None)
    second = bus.deliver(Message("p", "c", "b", None, 0.0, size=10), None)
    assert (first, second) == (0.08, 0.16)


def test_bus_without_arbitration_loses_colliding_frame():
    """Without arbitration a frame sent onto a busy bus is lost."""
    bus = BusChannel(baud=1000.0, overhead_bits=0, arbitration=False)
    assert bus.deliver(Message("p", "a", "b", None, 0.0, size=10), None) == 0.08
    assert bus.deliver(Message("p", "c", "b", None, 0.05, size=10), None) is None
    assert bus.deliver(Message("p", "c", "b", None, 0.09, size=10), None) == pytest.approx(0.08)


def test_range_model_rssi_falls_with_distance():
    """RSSI follows the log-distance law: -20 dB per decade at exponent 2."""
    radio = RangeChannel(tx_power_dbm=-40.0, exponent=2.0)
    assert radio.rssi(1.0) - radio.rssi(10.0) == pytest.approx(20.0)


def two_agents(channel: str, tokens: int, seconds: float) -> str:
    """Agent ``a`` sends ``tokens`` messages over ``channel``, one every ``seconds``, into
    a channel place in its own subnet; agent ``b`` takes them."""
    return f"""
petriflow: 1
subnets:
  - id: a
    places: [{{id: a_ready, tokens: {tokens}}}, {{id: outbox, channel: {channel}}}]
    transitions: [{{id: send, action: core.wait, params: {{seconds: {seconds}}}, in: [a_ready], out: [outbox]}}]
  - id: b
    places: [b_done]
    transitions: [{{id: receive, in: [outbox], out: [b_done]}}]
"""


def test_the_receiver_is_the_agent_that_takes_from_the_channel_place():
    """A channel place declared in the sender's subnet is still received by the agent
    whose transitions consume from it: killing that agent loses the message."""
    net = loads_net(two_agents("radio", tokens=1, seconds=2))
    config = RunConfig.from_dict({"faults": [{"kill": "b", "at": 1}]})
    scheduler = Scheduler(net, config=config)
    events = []
    scheduler.on_event(events.append)
    scheduler.run()
    message = [e.data for e in events if e.kind == "message"][0]
    assert (message["receiver"], message["fate"], message["why"]) == ("b", "lost", "receiver not running")


def test_messages_between_many_agents_are_delivered_in_order():
    """Pairs of agents exchanging through an ideal channel with latency: every message
    arrives after the latency, in the order sent."""
    lines = ["petriflow: 1", "subnets:"]
    for k in range(20):
        lines.append(f"  - {{id: s{k}, places: [{{id: s{k}r, tokens: 1}}], transitions: ["
                     f"{{id: s{k}send, action: core.wait, params: {{seconds: 0.{k + 1:02d}}}, in: [s{k}r], out: [m{k}]}}]}}")
        lines.append(f"  - {{id: d{k}, places: [{{id: m{k}, channel: radio}}, d{k}got], transitions: ["
                     f"{{id: d{k}take, in: [m{k}], out: [d{k}got]}}]}}")
    config = RunConfig.from_dict({"channels": {"radio": {"model": "ideal", "latency": 0.5}}})
    scheduler = Scheduler(loads_net("\n".join(lines) + "\n"), config=config)
    events = []
    scheduler.on_event(events.append)
    result = scheduler.run()
    delivered = [(e.data["place"], e.time) for e in events if e.kind == "message" and e.data["fate"] == "delivered"]
    assert delivered == [(f"m{k}", round(0.01 * (k + 1) + 0.5, 9)) for k in range(20)]
    assert result.marking == {f"d{k}got": 1 for k in range(20)}


def test_a_lost_message_can_leave_a_loss_notice():
    """on_loss: notify puts a notice token in the channel place at once (fate noticed,
    not delivered); the default drops the message."""
    far = StubWorld(positions={"a": (0, 0), "b": (30, 0)})
    radio = {"model": "range", "tx_power_dbm": -40, "exponent": 2.0, "threshold_dbm": -63.4375}
    result, events = run(RunConfig(channels={"radio": {**radio, "on_loss": "notify"}}), far)
    assert messages(events) == [("lost", 0.0), ("noticed", 0.0)]
    assert result.marking == {"a_done": 1, "b_done": 1}
    notice = [e for e in events if e.kind == "end" and e.transition == "receive"]
    assert notice, "the receiver consumed the notice"
    with pytest.raises(NetFormatError, match="on_loss is drop or notify"):
        Scheduler(loads_net(TALK), config=RunConfig(channels={"radio": {**radio, "on_loss": "maybe"}}))


def test_a_medium_that_loses_a_message_in_flight_counts_it_once_as_sent():
    """A medium (a process on the run's kernel) that loses a message after it was sent
    records it lost then (fate lost, in_flight), counted once as sent, and leaves a
    notice with on_loss: notify."""
    from petriflow.runtime.media import Medium
    from petriflow.runtime.metrics import RunRecord, messages as count
    from petriflow.runtime.registry import Registry

    class Fickle(Medium):
        def attach(self, port):
            self.port = port

        def send(self, message):
            self.port.clock.after(0.5, self.port.lose, message, "overwritten")

    registry = Registry(False)
    registry.register_channel("test.fickle", Fickle)
    scheduler = Scheduler(loads_net(TALK), registry=registry,
                          config=RunConfig(channels={"radio": {"model": "test.fickle", "on_loss": "notify"}}))
    events = []
    scheduler.on_event(events.append)
    result = scheduler.run(until=5)
    assert messages(events) == [("sent", 0.0), ("lost", 0.5), ("noticed", 0.5)]
    assert [e.data.get("in_flight") for e in events if e.kind == "message"] == [None, True, None]
    assert result.marking == {"a_done": 1, "b_done": 1}
    assert count(RunRecord(result, events)) == {"sent": 1, "delivered": 0, "lost": 1, "bytes": 4}


class _CountingWorld(StubWorld):
    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.asked = 0

    def distance(self, a, b):
        self.asked += 1
        return super().distance(a, b)



@pytest.mark.parametrize("channel, model, needs", [("lan", {"model": "ideal"}, False),
                                                    ("radio", {"model": "range", "latency": 0.0}, True)])
def test_message_events_and_distances_only_for_whom_needs_them(channel, model, needs):
    """A message event's data is built only when someone listens to message events, and
    the sender-receiver distance is asked of the world only for such a listener or a
    model that reads it (range: yes; ideal: no). Either way the same tokens arrive."""
    net = loads_net(two_agents(channel, tokens=3, seconds=1))
    config = RunConfig.from_dict({"channels": {channel: model}})
    quiet_world = _CountingWorld(positions={"a": (0, 0), "b": (3, 4)})
    quiet = Scheduler(net, world=quiet_world, config=config)
    firings = []
    quiet.on_event(firings.append, ["end"])
    quiet.run()
    assert quiet_world.asked == (3 if needs else 0)
    listened_world = _CountingWorld(positions={"a": (0, 0), "b": (3, 4)})
    listened = Scheduler(net, world=listened_world, config=config)
    events = []
    listened.on_event(events.append)
    listened.run()
    assert listened_world.asked == 3
    messages = [e.data for e in events if e.kind == "message"]
    assert [m["fate"] for m in messages] == ["sent", "delivered"] * 3
    assert all(m["distance"] == 5.0 for m in messages if m["fate"] == "sent")
    assert [e.seq for e in firings] == [e.seq for e in events if e.kind == "end"]  # the same numbering
    assert quiet.tokens.counts == listened.tokens.counts


def test_on_loss_written_in_the_configuration_overrides_the_models_default():
    """A model may default to notify (the comm radio does); ``on_loss: drop`` written in the
    configuration is what the run gets."""
    from dataclasses import dataclass

    from petriflow.runtime.channels import IdealChannel, build_channel
    from petriflow.runtime.registry import Registry

    @dataclass
    class Noticing(IdealChannel):
        on_loss = "notify"

    registry = Registry(load_plugins=False)
    registry.register_channel("test.noticing", Noticing)
    assert build_channel("c", {"model": "test.noticing"}, registry=registry).on_loss == "notify"
    assert build_channel("c", {"model": "test.noticing", "on_loss": "drop"}, registry=registry).on_loss == "drop"
