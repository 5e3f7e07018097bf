"""A run builds and keeps only the event kinds its observers and metrics read."""

from __future__ import annotations

import pytest

from petriflow.errors import PetriflowError
from petriflow.io.yaml import loads_net
from petriflow.runtime.registry import Registry, default_registry
from petriflow.runtime.scheduler import Scheduler
from petriflow.runtime.session import run_files

NET = """
petriflow: 1
net: kinds
places: [{id: a, tokens: 2}, b]
transitions:
  - {id: go, action: core.wait, params: {seconds: 1}, in: [a], out: [b]}
"""


def test_an_observer_of_some_kinds_sees_those_events_numbered_as_the_whole_run():
    everything, ends = [], []
    scheduler = Scheduler(loads_net(NET), seed=0)
    scheduler.on_event(everything.append)
    scheduler.on_event(ends.append, kinds=["end", "stop"])
    scheduler.run()
    assert [(e.seq, e.kind) for e in ends] == [(e.seq, e.kind) for e in everything if e.kind in ("end", "stop")]
    assert [e.kind for e in ends] == ["end", "end", "stop"]


def test_an_unknown_kind_is_refused():
    with pytest.raises(ValueError, match="no event kind 'ends'"):
        Scheduler(loads_net(NET), seed=0).on_event(print, kinds=["ends"])
    with pytest.raises(PetriflowError, match="names no event kind"):
        Registry().register_metric("x.y", lambda record: 0, events=["ends"])


def test_a_metric_of_some_kinds_gets_a_run_that_kept_only_those(tmp_path):
    seen = {}

    def kinds_seen(record):
        seen["kinds"] = sorted({e.kind for e in record.events})
        return len(record.events)

    default_registry.register_metric("test.kinds_seen", kinds_seen, events=("end",), replace=True)
    path = tmp_path / "net.yaml"
    path.write_text(NET)
    outcome = run_files(path, metrics=["test.kinds_seen"])
    assert seen["kinds"] == ["end"] and outcome.metrics["test.kinds_seen"] == 2
    default_registry.register_metric("test.kinds_seen", kinds_seen, events=True, replace=True)
    run_files(path, metrics=["test.kinds_seen"])
    assert seen["kinds"] == ["end", "run", "start", "stop"]


TWO = """
petriflow: 1
net: narrowed
places: [{id: a, tokens: 2}, b, {id: c, tokens: 1}, d]
transitions:
  - {id: go, action: core.wait, params: {seconds: 1}, in: [a], out: [b]}
  - {id: other, action: core.wait, params: {seconds: 2}, in: [c], out: [d]}
"""


def test_an_observer_narrowed_to_transitions_and_fields_sees_only_those_numbered_as_the_whole_run():
    everything, about_go, ok_ends = [], [], []
    scheduler = Scheduler(loads_net(TWO), seed=0)
    scheduler.on_event(everything.append)
    scheduler.on_event(about_go.append, kinds=["start", "end"], transitions=["go"])
    scheduler.on_event(ok_ends.append, fields={"outcome": ["ok"], "reason": ["no such reason"]})
    scheduler.run()
    assert [(e.seq, e.kind, e.transition) for e in about_go] == \
        [(e.seq, e.kind, e.transition) for e in everything if e.kind in ("start", "end") and e.transition == "go"]
    assert [e.kind for e in about_go] == ["start", "end", "start", "end"]
    # every end has outcome ok; the stop event has a reason that is not the one asked for
    assert [e.kind for e in ok_ends] == [e.kind for e in everything if e.kind != "stop"]
    assert any(e.kind == "stop" and "reason" in e.data for e in everything)


def test_a_narrowed_observer_of_an_unknown_kind_is_refused():
    with pytest.raises(ValueError, match="no event kind 'ends'"):
        Scheduler(loads_net(TWO), seed=0).on_event(print, kinds=["ends"], transitions=["go"])
