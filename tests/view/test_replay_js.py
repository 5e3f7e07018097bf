"""The page's own replay without a browser: Node runs the pure parts of a run's page
(``assets/trace.js``, ``replay.js``, see :data:`petriflow.view.run_page.SCRIPTS`) over the
data of a page petriflow wrote (``replay_node.js``), and what they compute is compared
with petriflow's: the marking after every event with ``petriflow replay``'s
(:func:`petriflow.runtime.replay.markings`), each event's record with its line of the
trace, the firings running, the messages and the poses with the trace's."""

from __future__ import annotations

import json
import re
import shutil
import subprocess
from importlib import resources
from pathlib import Path

import pytest

import petriflow
from petriflow.examples import folder as nets_folder
from petriflow.runtime.replay import markings
from petriflow.runtime.trace import Event, read_trace
from petriflow.view.run_page import SCRIPTS, model, unpacked

NODE = shutil.which("node")
SCRIPT = Path(__file__).with_name("replay_node.js")


def _node_major() -> int:
    text = subprocess.run([NODE, "--version"], capture_output=True, text=True, check=True).stdout
    return int(re.match(r"v(\d+)", text).group(1))


pytestmark = pytest.mark.skipif(NODE is None or _node_major() < 18, reason="no Node.js 18 or later"
                                " (the page's replay is run in Node: apt-get install nodejs)")


def replayed(page: Path) -> dict:
    """What the page's scripts compute over its data, run in Node (see replay_node.js)."""
    assets = resources.files("petriflow.view").joinpath("assets")
    done = subprocess.run([NODE, str(SCRIPT), str(assets), str(page)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


def page_of(trace: Path, folder: Path, net: str | None = None) -> Path:
    return petriflow.view(trace, net=None if net is None else nets_folder() / net, out=folder / "page.html")


def lines(trace: Path) -> list[dict]:
    """The trace's events as its lines hold them."""
    return [json.loads(line) for line in trace.read_text(encoding="utf-8").splitlines()]


def written(folder: Path, events: list[Event]) -> Path:
    trace = folder / "trace.jsonl"
    trace.write_text("".join(e.to_json() + "\n" for e in events), encoding="utf-8")
    return trace


def running_after_each(events: list[Event]) -> list[list[str]]:
    """The transitions whose firings have started and not ended, after each event, in the
    order they started."""
    running: dict[int, str] = {}
    out = []
    for event in events:
        if event.kind == "start":
            running[event.data["firing"]] = event.transition
        elif event.kind == "end":
            running.pop(event.data["firing"], None)
        out.append(list(running.values()))
    return out


def test_the_page_needs_only_its_inlined_scripts_in_node():
    """The pure parts are the first scripts the page inlines, before any panel."""
    assert SCRIPTS[:3] == ["common.js", "trace.js", "replay.js"]
    assert all(resources.files("petriflow.view").joinpath("assets", name).is_file() for name in SCRIPTS)


@pytest.mark.parametrize("which, net", [("smart_trace", "smart/smart.yaml"),
                                        ("bidding_trace", "bidding/bidding-autonomous-2.yaml")])
def test_the_pages_replay_is_petriflow_replays_at_every_event(which, net, request, tmp_path):
    """The marking after each event is ``petriflow replay --at N``'s, the records are the
    trace's lines, the firings running are those started and not ended."""
    trace = request.getfixturevalue(which)
    events = read_trace(trace)
    out = replayed(page_of(trace, tmp_path, net))["events"]
    assert len(out) == len(events)
    assert [e["marking"] for e in out] == [m.to_dict() for _, m in markings(events)]
    assert [e["record"] for e in out] == lines(trace)
    assert [e["running"] for e in out] == running_after_each(events)
    assert any(e["running"] for e in out)


def test_the_pages_messages_and_poses_are_the_traces(bidding_trace, tmp_path):
    """Each message from its sending to its delivery (same place, same sender), each body's
    poses at their events, as petriflow.view.run_page.model pairs and reads them."""
    events = read_trace(bidding_trace)
    out = replayed(page_of(bidding_trace, tmp_path))
    m = unpacked(model(events))
    name = lambda table, k: None if k < 0 else m[table][k]  # noqa: E731
    columns = zip(m["m_send"], m["m_end"], m["m_fate"], m["m_from"], m["m_to"], m["m_place"], m["m_channel"])
    expected = sorted(([s, e, m["fates"][f], name("agents", a), name("agents", b), name("places", p),
                        name("channels", c)] for s, e, f, a, b, p, c in columns),
                      key=lambda row: (events[row[0]].time, row[0]))
    assert out["messages"] == expected and len(expected) > 10
    assert out["bodies"] == m["poses"] and len(out["bodies"]) >= 2


def test_failed_firings_and_ended_messages_are_seen_for_a_while(tmp_path):
    """A firing that failed is reported from its end on, for 5 s (5 s after still); a message
    that ended, from its delivery (not before, at the same time) on, for 5 s."""
    box = {"place": "box", "channel": "lan"}
    events = [Event(0, 0.0, "run", data={"marking": {"i": 1}}),
              Event(1, 1.0, "start", "t", "a", {"firing": 1, "consumed": {"i": 1}}),
              Event(2, 2.0, "end", "t", "a", {"firing": 1, "outcome": "failed", "reason": "blocked",
                                              "produced": {}}),
              Event(3, 3.0, "message", None, "a", {**box, "fate": "sent", "receiver": "b"}),
              Event(4, 3.0, "message", None, "a", {**box, "fate": "delivered"}),
              Event(5, 7.0, "message", None, "b", {**box, "fate": "lost", "why": "range"}),
              Event(6, 10.0, "stop", data={"reason": "final", "firings": 1, "marking": {}})]
    out = replayed(page_of(written(tmp_path, events), tmp_path))["events"]
    assert [e["failed"] for e in out] == [[], [], [["t", "failed", "blocked"]], [["t", "failed", "blocked"]],
                                          [["t", "failed", "blocked"]], [["t", "failed", "blocked"]], []]
    assert [e["ended"] for e in out] == [[], [], [], [], [[3, 4]], [[3, 4], [5, 5]], [[5, 5]]]
    assert [e["running"] for e in out] == [[], ["t"], [], [], [], [], []]
    assert [e["marking"] for e in out] == [m.to_dict() for _, m in markings(events)] == [
        {"i": 1}, {}, {}, {}, {"box": 1}, {"box": 1}, {"box": 1}]


def test_node_rebuilds_awkward_records_exactly(awkward_events, tmp_path):
    """Numbers no short decimal holds, integers past 2**50, placeholder-like strings: each
    record comes back as its trace line has it."""
    trace = written(tmp_path, awkward_events)
    out = replayed(page_of(trace, tmp_path))["events"]
    assert [e["record"] for e in out] == lines(trace)


def test_a_monitored_violation_is_marked_on_the_page(tmp_path):
    """`run --monitor` records a violation as a `custom` event: the page marks it red and
    its events panel names the property and the event that broke it."""
    from petriflow.cli import main
    from tests.properties.test_monitor import RACE

    net = tmp_path / "race.yaml"
    net.write_text(RACE)
    trace = tmp_path / "race.jsonl"
    assert main(["run", str(net), "--monitor", "--trace", str(trace), "--quiet"]) == 1
    events = replayed(page_of(trace, tmp_path))["events"]
    marked = [e for e in events if e["violation"]]
    assert len(marked) == 1 and marked[0]["bad"]
    violated_at = [e["record"]["seq"] for e in events
                   if e["record"]["kind"] == "end" and e["record"]["transition"] == "blue_enter"]
    assert marked[0]["violation"] == f"VIOLATED property exclusive at event {violated_at[0]} (blue_enter)"
    assert not any(e["bad"] for e in events if not e["violation"])

