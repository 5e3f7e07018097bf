"""The viewer's pages as data: what they carry, the pose sampling they draw the world
from, and the command line (the browser tests are in test_browser.py)."""

from __future__ import annotations

import base64
import gzip
import json
import subprocess
import sys
from pathlib import Path

import pytest

import petriflow
from petriflow.cli import main
from petriflow.runtime.replay import markings
from petriflow.runtime.trace import read_trace
from petriflow.examples import folder as nets_folder
from petriflow.view.columns import decoded
from petriflow.view.run_page import model, restored, unpacked


def _unpack(text: str) -> str:
    return gzip.decompress(base64.b64decode(text)).decode("utf-8")


def _records(data: dict) -> list[dict]:
    """Every event's record as the page's columns hold it."""
    return decoded(gzip.decompress(base64.b64decode(data["columns"])))[0]


def _page_model(data: dict) -> dict:
    """The replay model a page holds, with what it reads from the events' columns put back."""
    records, templates = decoded(gzip.decompress(base64.b64decode(data["columns"])))
    return restored(json.loads(_unpack(data["model"])), records, templates)


def _marking_after_each(m: dict) -> list[dict[str, int]]:
    counts: dict[str, int] = {}
    out = []
    for i in range(len(m["kind"])):
        for k in range(m["d_start"][i], m["d_start"][i + 1]):
            place = m["places"][m["d_place"][k]]
            counts[place] = counts.get(place, 0) + m["d_n"][k]
        out.append({p: n for p, n in counts.items() if n > 0})
    return out


@pytest.mark.parametrize("which", ["smart_trace", "bidding_trace"])
def test_the_replayed_marking_is_the_replay_commands_at_every_event(which, request):
    events = read_trace(request.getfixturevalue(which))
    replayed = _marking_after_each(unpacked(model(events)))
    expected = [marking.to_dict() for _, marking in markings(events)]
    assert replayed == expected


def test_messages_are_paired_with_their_delivery(bidding_trace):
    events = read_trace(bidding_trace)
    m = unpacked(model(events))
    sent = [e for e in events if e.kind == "message" and e.data["fate"] == "sent"]
    delivered = [i for i, e in enumerate(events) if e.kind == "message" and e.data["fate"] == "delivered"]
    assert sent and len(m["m_send"]) == len(sent)
    assert sorted(e for e in m["m_end"] if e >= 0) == delivered
    for send, end, place in zip(m["m_send"], m["m_end"], m["m_place"]):
        if end >= 0:  # the same channel place, and not before it was sent
            assert events[end].data["place"] == events[send].data["place"] == m["places"][place]
            assert events[end].time >= events[send].time


def test_firings_end_with_their_outcome(bidding_trace):
    events = read_trace(bidding_trace)
    m = unpacked(model(events))
    starts = [i for i, e in enumerate(events) if e.kind == "start"]
    assert m["f_start"] == starts
    for start, end, outcome in zip(m["f_start"], m["f_end"], m["f_outcome"]):
        if end >= 0:
            assert events[end].kind == "end" and events[end].data["firing"] == events[start].data["firing"]
            assert m["outcomes"][outcome] == events[end].data["outcome"]


WORLD = {"dt": 0.01, "gravity": 0.0, "plane": True,
         "boxes": [{"id": "wall", "size": [2.0, 0.1, 0.5], "position": [0.0, 1.0, 0.25]},
                   {"id": "crate", "size": [0.2, 0.2, 0.2], "position": [0.0, 0.0, 0.1], "mass": 1.0}]}
NET = """\
petriflow: 1
places: [{id: i, tokens: 1}, a, b, o]
transitions:
  - {id: one, action: core.wait, params: {seconds: 1}, in: [i], out: [a]}
  - {id: two, action: core.wait, params: {seconds: 1}, in: [a], out: [b]}
  - {id: three, action: core.wait, params: {seconds: 1}, in: [b], out: [o]}
"""


def _world_run(poses: float | None):
    from petriflow.io.yaml import loads_net
    from petriflow.runtime.poses import PoseSampler
    from petriflow.runtime.scheduler import EmptySchedule, Scheduler
    from petriflow.world import World

    world = World(WORLD)
    seen = []
    try:
        run = Scheduler(loads_net(NET), world=world, seed=1)
        run.on_event(seen.append)
        if poses is not None:
            run.on_instant(PoseSampler(poses))
        moves = iter([(0.5, 0.0), (0.5, 0.0), (0.7, 0.3)])  # the crate pushed between instants
        while True:
            try:
                run.step()
            except EmptySchedule:
                break
            x, y = next(moves, (0.7, 0.3))
            world.p.resetBasePositionAndOrientation(world.bodies["crate"], [x, y, 0.1], [0, 0, 0, 1],
                                                    physicsClientId=world.client)
    finally:
        world.close()
    return seen


def test_pose_sampling_records_the_bodies_that_moved_and_the_walls_once():
    events = _world_run(poses=0.5)
    poses = [e for e in events if e.kind == "pose"]
    assert [e.time for e in poses] == [0.0, 1.0, 3.0]  # at the instants; at t=2 it had not moved: nothing
    assert poses[0].data["poses"] == {"crate": [0.0, 0.0, 0.0]}
    assert [o["id"] for o in poses[0].data["outlines"]] == ["wall"]
    assert poses[0].data["outlines"][0]["points"] == [[-1.0, 0.95], [1.0, 0.95], [1.0, 1.05], [-1.0, 1.05]]
    assert poses[1].data == {"poses": {"crate": [0.5, 0.0, 0.0]}}
    assert poses[2].data == {"poses": {"crate": [0.7, 0.3, 0.0]}}
    assert [e.seq for e in events] == list(range(len(events)))  # numbered like every event


def test_without_pose_sampling_a_run_records_no_pose():
    plain = _world_run(poses=None)
    sampled = _world_run(poses=0.5)
    assert not [e for e in plain if e.kind == "pose"]
    strip = [(e.kind, e.transition, e.time) for e in sampled if e.kind != "pose"]
    assert strip == [(e.kind, e.transition, e.time) for e in plain]


def test_pose_sampling_interval_is_checked(tmp_path):
    from petriflow.runtime.poses import PoseSampler

    with pytest.raises(ValueError):
        PoseSampler(0)
    (tmp_path / "net.yaml").write_text(NET)
    assert main(["run", str(tmp_path / "net.yaml"), "--poses", "-1", "--quiet"]) == 2


def test_a_page_carries_every_event_and_fetches_nothing(bidding_trace, tmp_path, page_data):
    page = petriflow.view(bidding_trace, net=Path(nets_folder()) / "bidding/bidding-autonomous-2.yaml",
                          out=tmp_path / "run.html")
    text = page.read_text(encoding="utf-8")
    assert "<script src" not in text and "<link" not in text and "@import" not in text
    data = page_data(page)
    lines = bidding_trace.read_text(encoding="utf-8").splitlines()
    assert _records(data) == [json.loads(line) for line in lines]  # nothing lost
    assert _unpack(data["svg"]).startswith("<svg") and data["events"] == len(lines)
    replayed = _page_model(data)
    assert replayed == json.loads(json.dumps(model(read_trace(bidding_trace), data["net_places"])))
    assert replayed["poses"] and replayed["outlines"]  # the world can be drawn


def test_view_command_line(bidding_trace, tmp_path, capsys):
    out = tmp_path / "page.html"
    assert main(["view", str(bidding_trace), "-o", str(out)]) == 0
    assert out.is_file() and "wrote" in capsys.readouterr().out
    default = bidding_trace.with_suffix(".html")
    assert main(["view", str(bidding_trace)]) == 0 and default.is_file()
    default.unlink()


@pytest.mark.parametrize("args, message", [
    (["view", "missing.jsonl"], "missing.jsonl: no such file"),
    (["view", "{trace}", "-o", "{tmp}/page.png"], "name it .html"),
    (["view", "{trace}", "--net", "{nets}/smart/smart.yaml"], "was not recorded on"),
    (["view", "{bad}"], ":2:"),
    (["view", "{trace}", "--sweep", "x.yaml"], "--sweep is for a sweep"),
])
def test_view_bad_input_is_one_line_and_exit_2(args, message, bidding_trace, tmp_path, capsys):
    bad = tmp_path / "bad.jsonl"
    lines = bidding_trace.read_text().splitlines()
    bad.write_text(lines[0] + "\n{not json\n")
    values = {"trace": bidding_trace, "tmp": tmp_path, "nets": nets_folder(), "bad": bad}
    assert main([a.format(**values) for a in args]) == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1


def test_run_view_writes_the_page_and_no_trace_is_left(tmp_path, page_data):
    (tmp_path / "net.yaml").write_text(NET)
    out = tmp_path / "pages" / "run.html"
    done = subprocess.run([sys.executable, "-m", "petriflow.cli", "run", str(tmp_path / "net.yaml"), "--view", str(out),
                           "--quiet"], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert f"wrote {out}" in done.stdout
    assert sorted(p.name for p in out.parent.iterdir()) == ["run.html"]  # the made-up trace is gone
    data = page_data(out)
    assert data["events"] == 8 and data["net_file"] == "net.yaml" and data["svg"]


SWEEP = """\
petriflow-sweep: 1
description: a wait against its length
net: net.yaml
trials: 2
matrix:
  seconds: [1, 2, 4]
set:
  net.transitions.one.params.seconds: "${seconds}"
metrics:
  time_s: core.end_time
paper:
  source: Table 0
  rows:
    - {params: {seconds: 2}, values: {time_s: 4.5}}
"""


@pytest.fixture(scope="module")
def sweep_db(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("sweep")
    (folder / "net.yaml").write_text(NET)
    (folder / "sweep.yaml").write_text(SWEEP)
    from petriflow.sweep import load_sweep, run_sweep

    run_sweep(load_sweep(folder / "sweep.yaml"), workers=1, db=folder / "results.db")
    return folder / "results.db"


def test_sweep_page_has_the_table_beside_the_paper(sweep_db, tmp_path, page_data):
    page = petriflow.view(sweep_db, out=tmp_path / "sweep.html")
    data = page_data(page)
    assert data["parameters"] == ["seconds"] and data["metrics"] == ["time_s"]
    assert [r["params"]["seconds"] for r in data["rows"]] == [1, 2, 4]
    assert [r["metrics"]["time_s"]["mean"] for r in data["rows"]] == [3.0, 4.0, 6.0]
    assert data["rows"][1]["paper"] == {"time_s": 4.5} and data["rows"][1]["deviations"]["time_s"] == "-0.5 (-11.1%)"
    assert len(data["trials"]) == 6 and data["note"] is None
    assert "Dygraph" in page.read_text(encoding="utf-8")  # the plotting library is inside the page


def test_sweep_page_without_its_file_says_so(sweep_db, tmp_path, page_data):
    import sqlite3

    moved = tmp_path / "elsewhere.db"
    moved.write_bytes(sweep_db.read_bytes())
    with sqlite3.connect(moved) as db:  # as if the sweep file were gone
        db.execute("UPDATE sweep SET value = ? WHERE key = 'file'", (str(tmp_path / "gone.yaml"),))
    data = page_data(petriflow.view(moved, out=tmp_path / "s.html"))
    assert data["rows"][0]["metrics"]["time_s"]["mean"] == 3.0
    assert "not found" in data["note"]


def test_not_a_results_database(tmp_path, capsys):
    bad = tmp_path / "x.db"
    bad.write_bytes(b"not sqlite at all" * 10)
    assert main(["view", str(bad)]) == 2
    assert "results database" in capsys.readouterr().err


def test_view_is_part_of_the_api():
    assert "view" in petriflow.__all__ and callable(petriflow.view)


def test_every_event_line_is_json_in_the_page_model(smart_trace):
    events = read_trace(smart_trace)
    m = unpacked(model(events))
    assert m["seq"] == [e.seq for e in events]
    assert [m["kinds"][k] for k in m["kind"]] == [e.kind for e in events]
    assert [None if a < 0 else m["agents"][a] for a in m["agent"]] == [e.agent for e in events]
    assert {"robot3l", "robot4l"} <= set(m["poses"])  # SMART's robots posed



def test_a_page_over_its_size_keeps_every_event_and_says_what_it_left_out(smart_trace, tmp_path, page_data):
    whole = page_data(petriflow.view(smart_trace, out=tmp_path / "whole.html"))
    small = page_data(petriflow.view(smart_trace, out=tmp_path / "small.html", max_mb=0.2))
    assert whole["shortened"] is None
    assert small["shortened"]["events"] > 0 and len(small["columns"]) < len(whole["columns"])
    events = read_trace(smart_trace)
    records = _records(small)
    assert len(records) == len(events)  # every event is still there
    for number, (record, event) in enumerate(zip(records, events), start=1):
        assert (record["seq"], record["kind"], record["time"], record["agent"]) == (event.seq, event.kind, event.time,
                                                                                  event.agent)
        for key, value in record["data"].items():
            if value != event.data[key]:
                assert value.startswith("<left out of the page") and f"line {number} of the trace" in value
    assert _page_model(small) == _page_model(whole) == json.loads(json.dumps(model(events)))  # replay whole


@pytest.mark.parametrize("net, until, draw", [
    ("passage/passage.yaml", 10.0, True), ("comm/comm-decentralised-2.yaml", 30.0, True),
    ("bus/bus-algorithm2-3.yaml", 2.0, True),
    ("slam/slam-decentralised.yaml", 30.0, False),  # Graphviz takes ~15 s of CPU to lay its net out
])
def test_every_shipped_scenario_has_a_page(net, until, draw, tmp_path, page_data):
    from petriflow.runtime.session import run_files

    trace = tmp_path / "run.jsonl"
    run_files(nets_folder() / net, trace=trace, until=until, poses=1.0)
    events = read_trace(trace)
    data = page_data(petriflow.view(trace, net=nets_folder() / net if draw else None, out=tmp_path / "run.html"))
    replayed = unpacked(_page_model(data))
    assert _records(data) == [json.loads(line) for line in trace.read_text(encoding="utf-8").splitlines()]
    assert _marking_after_each(replayed) == [m.to_dict() for _, m in markings(events)]
    assert replayed["poses"] and bool(data["svg"]) == draw  # the world (and the net) can be drawn


def test_without_graphviz_the_page_lists_the_places(bidding_trace, tmp_path, page_data, monkeypatch):
    import petriflow.export

    monkeypatch.setattr(petriflow.export, "DOT_EXECUTABLE", "no-such-dot-program")
    data = page_data(petriflow.view(bidding_trace, net=nets_folder() / "bidding/bidding-autonomous-2.yaml",
                                    out=tmp_path / "run.html"))
    assert data["svg"] is None and "Graphviz" in data["svg_missing"]
    assert data["net_places"]  # the page lists them with their tokens instead
