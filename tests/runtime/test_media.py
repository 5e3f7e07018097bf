"""Contended media run as processes on the run's kernel: fates are decided when they
happen, at their exact times, and actions ask a medium only through its view."""

from __future__ import annotations

import math

import pytest

from petriflow.io.yaml import loads_net
from petriflow.runtime.action import InstantAction, Param
from petriflow.runtime.config import RunConfig
from petriflow.runtime.kernel import Kernel
from petriflow.runtime.media import Medium, ProcessClock
from petriflow.runtime.registry import Registry
from petriflow.runtime.scheduler import Scheduler


class BufferedWire(Medium):
    """One frame at a time (1 ms each); the receiver's buffer holds one frame and a
    newer frame overwrites an unread one; the receiver reads its buffer every
    ``period`` seconds (its view sets the period). Reads are scheduled only while a
    frame waits."""

    period = 0.005

    def attach(self, port):
        self.port, self.busy_until, self.buffer, self.read_at = port, -math.inf, None, None
        self.log = []

    def send(self, message):
        clock = self.port.clock
        start = max(clock.now, self.busy_until)
        self.busy_until = start + 0.001
        clock.at(self.busy_until, self._arrive, message)

    def _arrive(self, message):
        now = self.port.clock.now
        self.log.append(("arrive", message.data, round(now, 6)))
        if self.buffer is not None:
            self.port.lose(self.buffer, "overwritten")
        self.buffer = message
        if self.read_at is None:
            self.read_at = math.ceil(now / self.period - 1e-9) * self.period
            self.port.clock.at(self.read_at, self._read, rank=1)

    def _read(self):
        self.read_at = None
        message, self.buffer = self.buffer, None
        self.port.deliver(message)

    def view(self, agent):
        return self


def registry_and_net():
    registry = Registry(False)
    registry.register_channel("test.wire", BufferedWire)

    class Say(InstantAction):
        params = {"word": Param(str)}

        def run(self, ctx):
            return self.params["word"]

    class Period(InstantAction):
        params = {"box": Param(str, places="")}

        def run(self, ctx):
            ctx.medium(self.params["box"]).period = 0.004  # through the declared view
            return None

    registry.register("test.say", Say)
    registry.register("test.period", Period)
    net = loads_net("""petriflow: 1
subnets:
  - id: a
    places: [{id: a0, tokens: 1}, a1, a2]
    transitions:
      - {id: a_first, action: test.say, params: {word: one}, in: [a0], out: [a1, box]}
      - {id: a_second, action: test.say, params: {word: two}, in: [a1], out: [a2, box]}
  - id: b
    places: [{id: box, channel: wire}, got, {id: b0, tokens: 1}, b1]
    transitions:
      - {id: b_setup, action: test.period, params: {box: box}, in: [b0], out: [b1]}
      - {id: b_take, in: [box], out: [got]}
""")
    return registry, net


def test_a_contended_medium_decides_a_loss_when_it_happens():
    """Two messages sent in the same instant: the first reaches the buffer at 1 ms, the
    second at 2 ms and overwrites it (lost then, not when sent); the reader finds the
    second at its read 4 ms later (the period its view set)."""
    registry, net = registry_and_net()
    run = Scheduler(net, registry=registry, config=RunConfig(dt=0.001, channels={"wire": {"model": "test.wire"}}))
    events = []
    run.on_event(events.append)
    result = run.run(until=1)
    messages = [(e.time, e.data["fate"], e.data.get("why")) for e in events if e.kind == "message"]
    assert messages == [(0.0, "sent", None), (0.0, "sent", None), (0.002, "lost", "overwritten"),
                        (0.004, "delivered", None)]
    assert result.tokens["got"] == ["two"]
    assert result.reason.value == "dead" and result.time == 0.004


def test_timed_events_run_in_time_order_before_the_instants_polls():
    kernel = Kernel(dt=0.01)
    clock = ProcessClock(kernel)
    seen = []
    for t in (0.0049, 0.0011, 0.0031):
        clock.at(t, lambda t=t: seen.append((t, clock.now)))
    later = clock.at(0.02, seen.append, "cancelled")
    later.cancel()
    assert kernel.pending == 3
    clock.run(until=0.05)
    assert seen == [(0.0011, 0.0011), (0.0031, 0.0031), (0.0049, 0.0049)]
    assert kernel.pending == 0
    with pytest.raises(ValueError, match="cannot schedule"):
        clock.at(0.001, seen.append, "past")
