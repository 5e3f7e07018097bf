"""Properties watched during a run: the first violation with its event, LTL on the finite trace."""

from __future__ import annotations

import json

from petriflow.cli import main
from petriflow.io.yaml import loads_net
from petriflow.properties.language import Finally, Globally, Next
from petriflow.properties.monitor import PropertyMonitor, holds_on_trace
from petriflow.properties.yaml_props import parse_formula
from petriflow.runtime.observers import run_observed
from petriflow.runtime.scheduler import Scheduler

RACE = """
petriflow: 1
net: race
places: [{id: red, tokens: 1}, {id: blue, tokens: 1}, red_in, blue_in]
transitions:
  - {id: red_enter, action: core.wait, params: {seconds: 2}, in: [red], out: [red_in]}
  - {id: blue_enter, action: core.wait, params: {seconds: 3}, in: [blue], out: [blue_in]}
properties:
  - {id: exclusive, never: "red_in + blue_in >= 2"}
  - {id: blue_answers, responds: {to: "red_in >= 1", with: "blue_in >= 1"}}
  - {id: red_answers, responds: {to: "blue_in >= 1", with: "red_in == 0"}}
  - {id: both_in, bound: [red_in, blue_in]}
  - {id: can_end, ctl: "AG EF blue_in == 1"}
"""


def test_the_first_violation_is_reported_with_its_event_and_marked_in_the_events():
    """Both robots end inside at t = 3 s: the end of blue_enter violates mutual exclusion."""
    net = loads_net(RACE)
    scheduler = Scheduler(net)
    monitor = PropertyMonitor(net, net.properties)
    monitor.attach(scheduler)
    result = run_observed(scheduler, keep_events=True)
    got = {r["id"]: r for r in monitor.results()}
    assert got["exclusive"]["verdict"] is False
    assert (got["exclusive"]["violation"]["time"], got["exclusive"]["violation"]["transition"]) == (3.0, "blue_enter")
    marks = [e for e in result.events if e.kind == "custom" and e.data.get("name") == "property_violated"]
    assert [m.data["property"] for m in marks] == ["exclusive"]
    assert got["blue_answers"]["verdict"] is True       # red in at 2 s, blue in at 3 s
    assert got["red_answers"]["verdict"] is False       # red never leaves before the run ends
    assert got["both_in"]["verdict"] == 2
    assert got["can_end"]["verdict"] is None and "branching" in got["can_end"]["reason"]


def test_ltl_on_finite_traces():
    """X needs a next marking; G and F range over the rest of the run."""
    p = parse_formula("a >= 1")
    trace = [{p: False}, {p: True}]
    assert holds_on_trace(Next(p), trace) is True
    assert holds_on_trace(Next(p), trace, at=1) is False
    assert holds_on_trace(Finally(p), trace) is True
    assert holds_on_trace(Globally(p), trace) is False
    assert holds_on_trace(Globally(p), trace, at=1) is True


def test_run_monitor_on_the_command_line(tmp_path, capsys):
    """`run --monitor`: a line per property, the violation in the trace, exit 1."""
    net = tmp_path / "race.yaml"
    net.write_text(RACE)
    trace = tmp_path / "race.jsonl"
    assert main(["run", str(net), "--monitor", "--trace", str(trace), "--json"]) == 1
    summary = json.loads(capsys.readouterr().out)
    assert {p["id"]: p["verdict"] for p in summary["properties"]}["exclusive"] is False
    events = [json.loads(line) for line in trace.read_text().splitlines()]
    assert any(e["kind"] == "custom" and e["data"].get("property") == "exclusive" for e in events)
