"""Fixtures of seed 001's tests: the shipped world and run configuration, and a way to
fire one transition with its real action and the agents' states given."""

from __future__ import annotations

import pytest

from petriflow import examples
from petriflow.runtime.config import load_config
from petriflow.runtime.scheduler import Scheduler
from petriflow.world import load_world


@pytest.fixture
def world():
    """The shipped Fig. 6 world (closed after the test)."""
    loaded = load_world(examples.path("slam", "world.yaml"))
    yield loaded
    loaded.close()


@pytest.fixture(scope="session")
def config():
    """The shipped run configuration (the ESP8266 radio, the base's link)."""
    return load_config(examples.path("slam", "run.yaml"))


class Fired:
    """What :func:`fire` did: the run's result, its events, the scheduler (states, resources)."""

    def __init__(self, result, events, scheduler):
        self.result, self.events, self.scheduler = result, events, scheduler

    def outcome(self, transition):
        ends = [e.data["outcome"] for e in self.events if e.kind == "end" and e.transition == transition]
        return ends[-1] if ends else None

    def custom(self, name):
        return [e.data["data"] for e in self.events if e.kind == "custom" and e.data.get("name") == name]

    def state(self, agent):
        return self.scheduler.firer.agents.state(agent)

    @property
    def tokens(self):
        return self.result.tokens


@pytest.fixture
def fire():
    """``fire(net, transition, tokens, states=..., world=..., config=..., beacons=...)``: fire
    one transition with its real action. ``states`` are the agents' states (``{agent:
    state}``, as the run keeps them: ``petriflow.testing.fire_one`` takes token data only),
    ``beacons`` radios already on (``{name: Beacon}``)."""

    def run(net, transition, tokens, *, states=None, world=None, config=None, beacons=None, timeout=120.0,
            seed=0):
        scheduler = Scheduler(net, world=world, config=config, seed=seed)
        scheduler.set_tokens({p: list(v) for p, v in tokens.items()})
        agents = scheduler.firer.agents
        for agent, state in (states or {}).items():
            agents.set_state(agent, state, scheduler.index.state_type.get(agent))
        if beacons:
            air = scheduler.resources.get("slam.air")
            for name, beacon in beacons.items():
                air.publish(name, beacon)
        events = []
        scheduler.on_event(events.append)
        with scheduler:
            result = scheduler.fire_one(transition, timeout=timeout)
        return Fired(result, events, scheduler)

    return run
