"""Plugin channel models bound to the world, actions judging a link before sending, and
the core metrics of a finished run."""

from __future__ import annotations

from dataclasses import dataclass

import pytest

from petriflow.io.yaml import loads_net
from petriflow.runtime.action import Action, Status
from petriflow.runtime.channels import ChannelModel
from petriflow.runtime.config import RunConfig
from petriflow.runtime.metrics import RunRecord, fired, messages, messages_per_channel, reported, result, time_of
from petriflow.runtime.registry import Registry, default_registry
from petriflow.runtime.scheduler import Scheduler
from petriflow.testing import StubWorld

NET = """
petriflow: 1
subnets:
  - id: a
    places: [{id: a_ready, tokens: 1}, a_done]
    transitions: [{id: send, action: test.judge, in: [a_ready], out: [a_done, inbox]}]
  - id: b
    places: [{id: inbox, channel: radio}, b_done]
    transitions: [{id: receive, action: core.wait, params: {seconds: 0.5}, in: [inbox], out: [b_done]}]
"""


@dataclass
class Walled(ChannelModel):
    """Loses everything when its world says there is a wall."""

    latency: float = 0.1

    def bind(self, world):
        self.world = world

    def deliver(self, message, rng):
        return None if getattr(self.world, "wall", False) else self.latency


class Judge(Action):
    """Records what ctx.link and ctx.running say about the channel place, then ends ok."""

    seen: list = []

    def start(self, ctx):
        model, receiver = ctx.link("inbox")
        Judge.seen.append((type(model).__name__, receiver, ctx.running(receiver)))
        ctx.emit("judged", receiver=receiver)
        ctx.result = {"size": 8, "verdict": "sent"}

    def poll(self, ctx):
        return Status.OK


@pytest.fixture
def registry():
    registry = Registry(load_plugins=False)  # the core actions are in every registry
    registry.register("test.judge", Judge)
    registry.register_channel("test.walled", Walled)  # a run resolves its channel models in its registry
    return registry


@pytest.fixture(autouse=True)
def walled_model():
    default_registry.register_channel("test.walled", Walled, replace=True)
    yield


def run(registry, world, config):
    Judge.seen = []
    scheduler = Scheduler(loads_net(NET), world=world, config=config, registry=registry)
    events = []
    scheduler.on_event(events.append)
    with scheduler:
        outcome = scheduler.run(until=5)
    return outcome, events


def test_a_registered_channel_model_is_bound_to_the_world(registry):
    config = RunConfig.from_dict({"channels": {"radio": {"model": "test.walled", "latency": 0.25}}})
    outcome, events = run(registry, StubWorld(), config)
    assert Judge.seen == [("Walled", "b", True)]
    assert [(e.data["fate"], e.time) for e in events if e.kind == "message"] == [("sent", 0.0), ("delivered", 0.25)]
    assert outcome.marking["b_done"] == 1
    world = StubWorld()
    world.wall = True
    outcome, events = run(registry, world, config)
    assert [e.data["fate"] for e in events if e.kind == "message"] == ["lost"]


def test_an_action_sees_whether_the_receiver_runs(registry):
    config = RunConfig.from_dict({"faults": [{"join": "b", "at": 3}]})
    run(registry, StubWorld(), config)
    assert Judge.seen == [("IdealChannel", "b", False)]


def test_unknown_channel_models_list_the_registered_ones():
    from petriflow.errors import NetFormatError

    with pytest.raises(NetFormatError, match="test.walled"):
        RunConfig.from_dict({"channels": {"radio": {"model": "walld"}}})


def test_core_metrics_of_a_run(registry):
    config = RunConfig.from_dict({"channels": {"radio": {"model": "ideal", "latency": 1.0}}})
    outcome, events = run(registry, StubWorld(), config)
    record = RunRecord(outcome, events)
    assert messages(record) == {"sent": 1, "delivered": 1, "lost": 0, "bytes": 8}
    assert messages_per_channel(record) == {"radio.sent": 1, "radio.delivered": 1, "radio.lost": 0, "radio.bytes": 8}
    assert fired(record, "receive") == 1 and fired(record, "receive", outcome="failed") == 0
    assert time_of(record, "receive") == pytest.approx(1.5)
    assert result(record, "send", "verdict") == "sent"
    assert reported(record, "judged", "receiver") == "b" and reported(record, "judged", reduce="count") == 1
    assert reported(record, "nothing") is None
