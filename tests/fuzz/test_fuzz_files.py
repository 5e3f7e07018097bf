"""Fuzzing the other files petriflow reads: worlds, run configurations, journals and
traces. Each mutated file is used, or refused with a one-line error; never another
exception, never a hang."""

from __future__ import annotations

import json
import shutil
import sqlite3

import pytest
import yaml
from hypothesis import given
from hypothesis import strategies as st

from petriflow.errors import PetriflowError
from petriflow.io.yaml import parse_yaml
from petriflow.runtime.session import run_files
from petriflow.world import World
from petriflow.worldfile import check_world
from tests.conftest import NETS
from tests.fuzz.contract import HOSTILE_VALUES, assert_contract, mutate_yaml

#: A small net with two agents, a channel, a timeout and a cancellation: most of what
#: a run configuration can name.
RADIO = """petriflow: 1
net: radio
subnets:
  - {id: r1, places: [{id: a, tokens: 2}, done], transitions: [
      {id: go, action: core.fail, params: {seconds: 0.5, probability: 0.3}, timeout: 2, in: [a], out: [done, box],
       outcomes: {failed: [a], timeout: [a]}}]}
  - {id: r2, places: [{id: box, channel: radio}, got], transitions: [{id: take, in: [box], out: [got]}]}
places: [{id: alarm, tokens: 1}]
transitions:
  - {id: stop, action: core.wait, params: {seconds: 2.5}, in: [alarm], cancels: [go]}
"""

CONFIGS = [
    "seed: 3\nuntil: 6\nstall: 30\n"
    "faults: [{kill: r2, at: 1.5}, {drop_link: [r1, r2], at: 0.2, until: 0.9}]\n"
    "channels: {radio: {model: range, latency: 0.1, loss: 0.2}}\n",
    "seed: 1\nuntil: 4\ndt: 0.05\nchannels: {radio: {model: ideal, latency: 0.3}}\n",
    (NETS / "passage" / "run.yaml").read_text(),
]
WORLDS = [(NETS / "passage" / "world.yaml").read_text(), (NETS / "smart" / "world.yaml").read_text(),
          "dt: 0.01\nplane: true\nboxes: [{id: b, size: [0.2, 0.2, 0.2], position: [0, 0, 0.1], mass: 1}]\n"]


@pytest.fixture(scope="module")
def radio(tmp_path_factory):
    """The radio net, a trace of one run of it and its journal."""
    folder = tmp_path_factory.mktemp("radio")
    net = folder / "radio.yaml"
    net.write_text(RADIO)
    (folder / "run.yaml").write_text(CONFIGS[0])
    run_files(net, trace=folder / "trace.jsonl", db=folder / "run.sqlite")
    return folder


@st.composite
def mutated(draw: st.DrawFn, bases: list[str], keys: list[str]) -> bytes:
    return mutate_yaml(draw, draw(st.sampled_from(bases)), keys)


@given(mutated(WORLDS, ["mass: -1", "size: [1]", "yaw: .nan", "colour: [2, 0, 0]", "z: 1e9"]))
def test_worlds_load_or_refuse(text):
    try:
        world = check_world(parse_yaml(text.decode("utf-8", "replace")), "fuzz-world.yaml")
    except (PetriflowError, yaml.YAMLError):  # the command line makes YAML errors one line (below)
        return
    try:
        built = World(world, base=str(NETS / "passage"))
    except PetriflowError:  # a URDF that is not there
        return
    try:
        for _ in range(3):
            built.step()
    finally:
        built.close()


@given(mutated(WORLDS[::2], ["size: [1]", "position: [a, b]"]), st.sampled_from(["0.5", "3"]))
def test_worlds_through_the_command_line(tmp_path_factory, radio, text, until):
    folder = tmp_path_factory.mktemp("world")
    world = folder / "world.yaml"
    world.write_bytes(text)
    code = assert_contract("run", radio / "radio.yaml", "--world", world, "--until", until,
                           "--db", folder / "j.sqlite")
    if code == 2:  # refused before it started: no journal left behind
        assert not (folder / "j.sqlite").exists()


@given(mutated(CONFIGS[:2], ["model: carrier", "at: -1", "kill: nobody", "seconds: .inf"]))
def test_run_configurations_keep_the_contract(tmp_path_factory, radio, text):
    folder = tmp_path_factory.mktemp("config")
    config = folder / "run.yaml"
    config.write_bytes(text)
    shutil.copy(radio / "radio.yaml", folder / "radio.yaml")
    code = assert_contract("run", folder / "radio.yaml", "--config", config, "--max-firings", "200",
                           "--db", folder / "j.sqlite")
    if code == 2:
        assert not (folder / "j.sqlite").exists()


#: JSON values put in a journal's run inputs or a trace's fields.
JSON_VALUES = [None, True, -1, 0, 2**70, 1e308, "", "x", [], {}, [1, [2]], {"a": None}, "9" * 400,
               {"seq": 0}, "petriflow: 1\nplaces: [", float("nan")]


@st.composite
def damaged_journal(draw: st.DrawFn, folder, original) -> None:
    """Copy ``original`` to ``folder/run.sqlite`` and damage it: its run inputs, its
    events or its bytes."""
    db = folder / "run.sqlite"
    shutil.copy(original, db)
    kind = draw(st.sampled_from(["inputs", "inputs", "event", "rows", "bytes", "finished"]))
    if kind == "bytes":
        data = bytearray(db.read_bytes())
        for _ in range(draw(st.integers(1, 8))):
            at = draw(st.integers(0, len(data) - 1))
            data[at] = draw(st.integers(0, 255))
        db.write_bytes(bytes(data))
        return
    with sqlite3.connect(db) as con:
        if kind == "inputs":
            inputs = json.loads(con.execute("SELECT value FROM run WHERE key = 'inputs'").fetchone()[0])
            key = draw(st.sampled_from(sorted(inputs) + ["extra"]))
            value = draw(st.sampled_from(JSON_VALUES))
            if key in ("until", "max_firings") and isinstance(value, (int, float)) and value > 100:
                value = 100  # a long run is what such inputs ask for, not a hang
            if draw(st.booleans()) and key in inputs:
                del inputs[key]
            else:
                inputs[key] = value
            text = json.dumps(inputs) if draw(st.integers(0, 5)) else json.dumps(inputs)[:-3]
            con.execute("UPDATE run SET value = ? WHERE key = 'inputs'", (text,))
        elif kind == "event":
            seqs = [s for (s,) in con.execute("SELECT seq FROM event")]
            seq = draw(st.sampled_from(seqs))
            line = json.loads(con.execute("SELECT line FROM event WHERE seq = ?", (seq,)).fetchone()[0])
            line[draw(st.sampled_from(sorted(line)))] = draw(st.sampled_from(JSON_VALUES))
            con.execute("UPDATE event SET line = ? WHERE seq = ?", (json.dumps(line), seq))
        elif kind == "rows":
            action = draw(st.sampled_from(["DELETE FROM event WHERE seq % 3 = 1", "DELETE FROM run",
                                           "DROP TABLE event", "UPDATE event SET seq = seq + 1000 WHERE seq > 4",
                                           "INSERT INTO run VALUES ('other', 'x')"]))
            con.execute(action)
        con.execute("DELETE FROM run WHERE key = 'finished'")  # make it resumable
        if kind == "finished":
            con.execute("INSERT INTO run VALUES ('finished', ?)", (draw(st.sampled_from(["0", "yes", "1"])),))


@given(st.data())
def test_damaged_journals_resume_or_refuse(tmp_path_factory, radio, data):
    folder = tmp_path_factory.mktemp("journal")
    data.draw(damaged_journal(folder, radio / "run.sqlite"))
    assert_contract("run", "--resume", "--db", folder / "run.sqlite", "--trace", folder / "t.jsonl")


@st.composite
def damaged_trace(draw: st.DrawFn, lines: list[str]) -> bytes:
    lines = list(lines)
    for _ in range(draw(st.integers(1, 3))):
        at = draw(st.integers(0, len(lines) - 1))
        kind = draw(st.sampled_from(["field", "field", "data", "delete", "swap", "truncate", "garbage"]))
        if kind in ("field", "data"):
            try:
                event = json.loads(lines[at])
            except ValueError:
                continue
            if not isinstance(event, dict):
                continue
            target = event.get("data") if kind == "data" and isinstance(event.get("data"), dict) else event
            if target:
                target[draw(st.sampled_from(sorted(target)))] = draw(st.sampled_from(JSON_VALUES))
            lines[at] = json.dumps(event)
        elif kind == "delete":
            del lines[at]
        elif kind == "swap":
            other = draw(st.integers(0, len(lines) - 1))
            lines[at], lines[other] = lines[other], lines[at]
        elif kind == "truncate":
            lines[at] = lines[at][:draw(st.integers(0, len(lines[at])))]
        else:
            lines[at] = draw(st.sampled_from(HOSTILE_VALUES + ["\x00\xff", "[" * 200]))
        if not lines:
            break
    return ("\n".join(lines) + "\n").encode("utf-8", "surrogatepass")


@given(st.data())
def test_damaged_traces_replay_or_refuse(tmp_path_factory, radio, data):
    folder = tmp_path_factory.mktemp("trace")
    trace = folder / "t.jsonl"
    trace.write_bytes(data.draw(damaged_trace((radio / "trace.jsonl").read_text().splitlines())))
    assert_contract("replay", trace)
    assert_contract("replay", trace, "--at", data.draw(st.sampled_from(["0", "3", "1000000000", "-1"])))
