"""A run's stopwatch: the clock reports the world's steps, actions report their work; nothing is patched."""

from __future__ import annotations

from petriflow.io.yaml import loads_net
from petriflow.runtime.action import Action, Status
from petriflow.runtime.assembly import open_run
from petriflow.runtime.clock import SimulatedClock
from petriflow.runtime.registry import Registry
from petriflow.runtime.scheduler import Scheduler
from petriflow.runtime.stopwatch import UNTIMED, Stopwatch, timed
from petriflow.runtime.validation import validate
from petriflow.runtime.config import RunConfig
from petriflow.testing import StubWorld

NET = """\
petriflow: 1
places: [{id: i, tokens: 1}, o]
transitions:
  - {id: work, action: demo.work, in: [i], out: [o]}
"""


class Work(Action):
    """Three polls of 'control' (each with a nested measure, counted once) and a 'vision' block."""

    needs_world = True

    def start(self, ctx):
        self.left = 3
        with ctx.stopwatch.measure("vision", keep=True):
            self.seen = ctx.stopwatch is not UNTIMED

    @timed("control")
    def poll(self, ctx):
        with ctx.stopwatch.measure("control"):
            self.left -= 1
        ctx.result = self.seen
        return Status.RUNNING if self.left else Status.OK


def _registry():
    registry = Registry()
    registry.register("demo.work", Work)
    return registry


def test_a_timed_run_counts_world_steps_and_what_actions_measure():
    watch = Stopwatch(["render"])
    world = StubWorld(dt=0.1)
    net = loads_net(NET)
    binding = validate(net, RunConfig(), registry=_registry(), world=world)
    with open_run(net, binding, RunConfig(), world=world, stopwatch=watch) as scheduler:
        result = scheduler.run()
    assert result.tokens == {"o": [True]}
    assert watch.calls["physics"] == world.steps > 0
    assert watch.calls["control"] == 3 and watch.calls["vision"] == 1 and len(watch.samples["vision"]) == 1
    assert watch.calls["render"] == 0 and watch.seconds["render"] == 0.0  # declared, nothing reported


def test_an_untimed_run_measures_nothing_and_runs_the_same():
    world = StubWorld(dt=0.1)
    result = Scheduler(loads_net(NET), registry=_registry(), world=world, clock=SimulatedClock()).run()
    assert result.tokens == {"o": [False]}  # ctx.stopwatch was UNTIMED
    timed_world = StubWorld(dt=0.1)
    watch = Stopwatch()
    again = Scheduler(loads_net(NET), registry=_registry(), world=timed_world, clock=SimulatedClock(watch),
                      stopwatch=watch).run()
    assert (again.time, again.firings) == (result.time, result.firings) and timed_world.steps == world.steps
