"""Hostile and malformed input: one line, exit 2, nothing created; no hang, no wrong
answer. Each test is one family of cases the reliability review found."""

from __future__ import annotations

import os
import stat

import pytest

from petriflow.cli import main
from petriflow.runtime.journal import Journal
from petriflow.runtime.session import resume, run_files
from tests.conftest import NETS

PASSAGE = NETS / "passage" / "passage.yaml"

TICKER = """petriflow: 1
places: [{id: p, tokens: 1}, count]
transitions:
  - {id: tick, action: core.wait, params: {seconds: 0.5}, in: [p], out: [p, count]}
"""


def one_line_error(capsys, argv, *fragments) -> str:
    """Run the CLI: exit 2, one line on stderr containing every fragment, no traceback."""
    code = main([str(a) for a in argv])
    err = capsys.readouterr().err
    assert code == 2, err
    assert err.startswith("petriflow: ") and err.count("\n") == 1, err
    for fragment in fragments:
        assert fragment in err, err
    return err


@pytest.fixture
def ticker(tmp_path):
    path = tmp_path / "ticker.yaml"
    path.write_text(TICKER)
    return path


# Outputs ------------------------------------------------------------------------------
def test_two_outputs_on_one_file_are_refused(tmp_path, ticker, capsys):
    same = tmp_path / "x"
    one_line_error(capsys, ["run", ticker, "--trace", same, "--db", same], "--db and --trace name the same file")
    assert not same.exists()


def test_an_output_over_an_input_is_refused(tmp_path, ticker, capsys):
    one_line_error(capsys, ["run", ticker, "--trace", ticker], "would overwrite one of the inputs")
    assert ticker.read_text() == TICKER


def test_two_writers_of_one_trace_each_finish_a_whole_file(tmp_path):
    """Unique temporary names: the second writer's rename wins, the first's is intact too."""
    from petriflow.runtime.trace import TraceWriter, read_trace

    first, second = TraceWriter(tmp_path / "t.jsonl"), TraceWriter(tmp_path / "t.jsonl")
    run_files(_ticker(tmp_path), until=0.5, trace=tmp_path / "other.jsonl")
    events = read_trace(tmp_path / "other.jsonl")
    for event in events:
        first(event)
        second(event)
    first.close()
    second.close()
    assert len(read_trace(tmp_path / "t.jsonl")) == len(events)
    assert sorted(p.name for p in tmp_path.iterdir() if ".partial" in p.name) == []


def _ticker(folder):
    path = folder / "ticker.yaml"
    path.write_text(TICKER)
    return path


def test_a_journal_has_one_writer_at_a_time(tmp_path, ticker, capsys):
    """A second resume of a journal in use is refused with one line."""
    db = tmp_path / "run.sqlite"
    run_files(ticker, until=0.5, db=db)
    with Journal(db):  # a run holding it
        one_line_error(capsys, ["run", "--resume", "--db", db], "in use by another run")


def test_a_run_that_cannot_start_leaves_no_journal(tmp_path, capsys):
    """Bad world, unknown fault agent, NaN limits: refused before the journal exists."""
    net = tmp_path / "net.yaml"
    net.write_text(TICKER.replace("petriflow: 1\n", "petriflow: 1\nrun: {world: world.yaml}\n"))
    (tmp_path / "world.yaml").write_text("dt: fast\n")
    db = tmp_path / "run.sqlite"
    one_line_error(capsys, ["run", net, "--db", db], "world.yaml:1: dt must be a number of seconds")
    assert not db.exists()
    one_line_error(capsys, ["run", _ticker(tmp_path), "--until", "nan", "--db", db], "--until must be a time from 0 to 1e+12 s")
    assert not db.exists()


def test_files_are_written_with_ordinary_modes(tmp_path, ticker):
    previous = os.umask(0o022)
    try:
        run_files(ticker, until=0.5, trace=tmp_path / "t.jsonl", xes=tmp_path / "t.xes")
        assert main(["export", str(ticker), "-o", str(tmp_path / "n.pnml")]) == 0
    finally:
        os.umask(previous)
    for name in ("t.jsonl", "t.xes", "n.pnml"):
        assert stat.S_IMODE((tmp_path / name).stat().st_mode) == 0o644, name


# Numbers -------------------------------------------------------------------------------
def test_huge_weights_are_refused_never_wrapped(tmp_path, capsys):
    """Beyond 2**60 the file is refused when read (the one number rule, limits.parse_integer)."""
    net = tmp_path / "w.yaml"
    net.write_text("petriflow: 1\nplaces: [{id: p, tokens: 1}, q]\n"
                   f"transitions: [{{id: t, in: [p], out: {{q: {2**62}, p: 1}}}}]\n")
    one_line_error(capsys, ["check", net, "--json"], "w.yaml:3: integer 4611686018427387904 is beyond 2**60")


def test_a_huge_final_marking_is_refused(tmp_path, capsys):
    """Found by the nightly fuzz profile: a final marking of 10**21 was a traceback."""
    net = tmp_path / "f.yaml"
    net.write_text("petriflow: 1\nplaces: [{id: i, tokens: 1}, o]\ntransitions: [{id: t, in: [i], out: [o]}]\n"
                   f"final: {{o: {10**21}}}\n")
    one_line_error(capsys, ["check", net], "f.yaml:4: integer 1000000000000000000000 is beyond 2**60")


@pytest.mark.parametrize("places, out, fragment", [
    (f"[{{id: p, tokens: {10**8}}}, q]", "[q]", ":2: 'p': starts with 100000000 tokens"),
    ("[{id: p, tokens: 1}, q]", f"{{q: {10**11}}}", ":3: 't': arc 't' -> 'q' has weight 100000000000"),
])
def test_counts_a_run_cannot_hold_are_refused_before_it_starts(tmp_path, capsys, places, out, fragment):
    net = tmp_path / "n.yaml"
    net.write_text(f"petriflow: 1\nplaces: {places}\ntransitions: [{{id: t, in: [p], out: {out}}}]\n")
    one_line_error(capsys, ["run", net, "--db", tmp_path / "j"], fragment)
    assert not (tmp_path / "j").exists()
    assert main(["simulate", str(net), "--steps", "1"]) == 0  # the token game only counts


@pytest.mark.parametrize("tokens, fragment", [
    (2**63, f"big.pnml:1: 'p': initial marking {2**63} is beyond 2**60"),
    (10**30, "initial marking '100000000000...' (31 digits) is beyond"),
])
def test_huge_pnml_markings_are_refused(tmp_path, capsys, tokens, fragment):
    net = tmp_path / "big.pnml"
    net.write_text('<pnml><net id="n" type="http://www.pnml.org/version-2009/grammar/ptnet"><page id="g">'
                   f'<place id="p"><initialMarking><text>{tokens}</text></initialMarking></place>'
                   '<transition id="t"/><arc id="a" source="p" target="t"/></page></net></pnml>')
    one_line_error(capsys, ["check", net], fragment)


@pytest.mark.parametrize("text, fragment", [
    ("petriflow: 1\nplaces: [{id: a, tokens: " + "9" * 5000 + "}]\n", "(5000 digits) is beyond 2**60"),
    ("petriflow: true\nplaces: [a]\n", "unsupported format version True"),
    ("petriflow: 1\nplaces: [{id: a, label: [1, 2]}]\n", "label must be text"),
    ("petriflow: 1\nplaces: [{id: a, meta: {1: x}}]\n", "'meta' keys must be text"),
    ("petriflow: 1\nplaces: [a, b]\ntransitions: [{id: t, in: [a], out: [b], operator: {group: g, split: weird}}]\n",
     "operator split must be one of and, xor"),
    ("petriflow: 1\nplaces: [{id: a, tokens: 1}, b]\n"
     "transitions: [{id: t, action: core.wait, params: {seconds: .nan}, in: [a], out: [b]}]\n",
     "must be a finite number"),
    ("petriflow: 1\nmeta: " + "[" * 500 + "]" * 500 + "\nplaces: [a]\n", "nested more than 64 levels deep"),
])
def test_malformed_net_values_are_one_line(tmp_path, capsys, text, fragment):
    net = tmp_path / "net.yaml"
    net.write_text(text)
    one_line_error(capsys, ["info", net], str(net), fragment)


def test_an_alias_bomb_is_refused_at_once(tmp_path, capsys):
    lines = ["petriflow: 1", "meta:", "  a: &a [x, x, x, x, x, x, x, x, x, x]"]
    for k, name in enumerate("bcdefgh"):
        previous = "abcdefgh"[k]
        lines.append(f"  {name}: &{name} [" + ", ".join([f"*{previous}"] * 10) + "]")
    lines.append("places: [a]")
    net = tmp_path / "bomb.yaml"
    net.write_text("\n".join(lines) + "\n")
    one_line_error(capsys, ["check", net], "an alias bomb?")


def test_invalid_utf8_is_one_line(tmp_path, capsys):
    net = tmp_path / "net.yaml"
    net.write_bytes(b"petriflow: 1\nplaces: [\xff\xfe]\n")
    one_line_error(capsys, ["info", net], "cannot read")


def test_a_large_chain_gets_a_note_not_gigabytes(tmp_path, capsys):
    """Invariants of a net whose Farkas matrix is too large are skipped with a note."""
    n = 3000    # places x (places + transitions) = 18 million > INVARIANT_CELLS
    net = tmp_path / "chain.yaml"
    net.write_text("petriflow: 1\nplaces: [{id: p0, tokens: 1}, " + ", ".join(f"p{i}" for i in range(1, n + 1))
                   + "]\ntransitions:\n" + "".join(f"  - {{id: t{i}, in: [p{i}], out: [p{i + 1}]}}\n"
                                                   for i in range(n)))
    assert main(["check", str(net)]) in (0, 1)
    assert "invariants not computed for a net this large" in capsys.readouterr().out


# Worlds and configurations ---------------------------------------------------------------
@pytest.mark.parametrize("world, fragment", [
    ("robots: [{id: r, urdf: x.urdf, position: [.nan, .inf]}]", "position must be a finite number"),
    ("dt: 1.0e-9", "dt must be a number of seconds from 0.0001 to 1"),
    ("boxes: [{id: b, size: [1], position: [0, 0, 0]}]", "size must be 3 numbers > 0"),
    ("robots: [{id: r, urdf: x.urdf, position: [a, b]}]", "position must be a number, got 'a'"),
    ("dt: fast", "dt must be a number of seconds"),
    ("boxes: 7", "'boxes' must be a list"),
    ("cameras: [{id: top, width: -5}]", "width must be a whole number of pixels"),
    ("dt: [", "malformed YAML"),
    ("gravity: " + "9" * 5000, "(5000 digits) is beyond 2**60"),
])
def test_malformed_worlds_are_one_line_before_anything_runs(tmp_path, capsys, world, fragment):
    (tmp_path / "world.yaml").write_text(world + "\n")
    net = tmp_path / "net.yaml"
    net.write_text(TICKER.replace("petriflow: 1\n", "petriflow: 1\nrun: {world: world.yaml, until: 1}\n"))
    one_line_error(capsys, ["run", net, "--db", tmp_path / "run.sqlite"], "world.yaml", fragment)
    assert not (tmp_path / "run.sqlite").exists()


@pytest.mark.parametrize("config, fragment", [
    ("until: .nan", "until must be a number of seconds from 0 to 1e12"),
    ("faults: [{kill: r, at: .inf}]", "'at' must be a time in seconds from 0 to 1e12"),
    ("dt: .nan", "dt must be a number of seconds"),
    ("world: ../../../../../../../../etc/passwd", "outside the configuration's folder"),
    ("stall: -1", "stall must be a number of seconds > 0"),
])
def test_malformed_run_configurations_are_one_line(tmp_path, capsys, ticker, config, fragment):
    (tmp_path / "run.yaml").write_text(config + "\n")
    one_line_error(capsys, ["run", ticker, "--config", tmp_path / "run.yaml", "--db", tmp_path / "j.sqlite"],
                   fragment)
    assert not (tmp_path / "j.sqlite").exists()


def test_a_world_outside_the_folder_is_allowed_from_petriflow_path(tmp_path, monkeypatch, ticker):
    shared = tmp_path / "shared"
    shared.mkdir()
    (shared / "world.yaml").write_text("plane: false\n")
    config = tmp_path / "conf"
    config.mkdir()
    (config / "run.yaml").write_text("world: ../shared/world.yaml\nuntil: 1\n")
    monkeypatch.setenv("PETRIFLOW_PATH", str(shared))
    assert run_files(ticker, config=config / "run.yaml").result.time == 1.0


# Journals and traces -------------------------------------------------------------------------
def test_damaged_journals_are_one_line(tmp_path, capsys):
    garbage = tmp_path / "garbage.sqlite"
    garbage.write_bytes(b"SQLite format 3\x00" + os.urandom(4000))
    one_line_error(capsys, ["run", "--resume", "--db", garbage], "journal")
    import sqlite3

    for name, inputs in (("nonjson", "{not json"), ("missing", '{"net_text": "x"}'), ("deep", "[" * 200 + "]" * 200)):
        db = tmp_path / f"{name}.sqlite"
        with sqlite3.connect(db) as connection:
            connection.executescript("CREATE TABLE run (key TEXT PRIMARY KEY, value TEXT NOT NULL);"
                                     "CREATE TABLE event (seq INTEGER PRIMARY KEY, line TEXT NOT NULL);")
            connection.execute("INSERT INTO run VALUES ('inputs', ?)", (inputs,))
        one_line_error(capsys, ["run", "--resume", "--db", db], "not a petriflow journal, or a damaged one")


@pytest.mark.parametrize("line, fragment", [
    ('{"seq": 0, "time": 0, "kind": "start", "data": {}}', "a start event's 'firing' is missing"),
    ('{"seq": 0, "time": "soon", "kind": "run"}', "'time' is missing or not a number"),
    ('{"seq": 0, "time": 0, "kind": "launch"}', "unknown kind 'launch'"),
    ('[1, 2]', "a trace line is a JSON object"),
    ("[" * 300 + "]" * 300, "nested more than 64 levels deep"),
    ('{"seq": 0, "time": 0, "kind": "end", "data": {"firing": 1, "outcome": "ok", "produced": {"p": -1}}}',
     "'produced' is missing or malformed"),
    ('{"seq": 0, "time": 0, "kind": "end", "data": {"firing": 1, "outcome": [], "produced": {}}}',
     "'outcome' is missing or malformed"),
])
def test_malformed_traces_are_one_line_in_replay(tmp_path, capsys, line, fragment):
    trace = tmp_path / "t.jsonl"
    trace.write_text(line + "\n")
    one_line_error(capsys, ["replay", trace], "t.jsonl:1: not a trace event", fragment)


# Runs that would not end -------------------------------------------------------------------
def test_a_run_stepping_without_progress_stops_as_stalled():
    """An action polled every tick that never ends: stopped after the configured stall."""
    from petriflow.io.yaml import loads_net
    from petriflow.runtime.config import RunConfig
    from petriflow.runtime.registry import Registry
    from petriflow.runtime.scheduler import Scheduler
    from petriflow.runtime.action import Status
    from petriflow.testing import ScriptedAction, StubWorld

    registry = Registry(load_plugins=False)
    registry.register("test.forever", ScriptedAction.script([Status.RUNNING], needs_world=True))
    net = loads_net("petriflow: 1\nplaces: [{id: a, tokens: 1}, b]\n"
                    "transitions: [{id: walk, action: test.forever, in: [a], out: [b]}]\n")
    result = Scheduler(net, world=StubWorld(dt=0.01), registry=registry,
                       config=RunConfig.from_dict({"stall": 5})).run()
    assert result.reason == "stalled" and result.time == pytest.approx(5.0)
    assert "no firing started or ended for 5 s of simulated time while walk ran" in result.error


def test_gui_without_a_display_is_one_line(capsys, monkeypatch):
    monkeypatch.delenv("DISPLAY", raising=False)
    one_line_error(capsys, ["run", PASSAGE, "--gui", "--until", "0.1"], "--gui needs a display")


def test_resume_does_not_depend_on_the_working_folder(tmp_path, monkeypatch):
    """A journal started in one folder resumes from another (its paths are absolute)."""
    db = tmp_path / "run.sqlite"
    monkeypatch.chdir(NETS.parent)
    run_files("nets/passage/passage.yaml", db=db, max_firings=2)
    import sqlite3

    with sqlite3.connect(db) as connection:  # pretend it was killed: not finished
        connection.execute("DELETE FROM run WHERE key = 'finished'")
    monkeypatch.chdir(tmp_path)
    assert resume(db).result.firings == 2


# Limits --------------------------------------------------------------------------------
@pytest.fixture
def own_limits(monkeypatch):
    """Changes to petriflow.limits made in the test are undone after it."""
    from petriflow import limits

    for name in limits.LIMITS:
        monkeypatch.setattr(limits, name, getattr(limits, name))
    return limits


def test_limits_are_raised_and_lowered_from_the_environment(tmp_path, capsys, monkeypatch, own_limits):
    net = tmp_path / "n.yaml"
    net.write_text("petriflow: 1\nplaces: [{id: p, tokens: 20000000}, q]\ntransitions: [{id: t, in: [p], out: [q]}]\n")
    one_line_error(capsys, ["run", net, "--max-firings", "1"], "a run holds at most 10,000,000 in one place")
    monkeypatch.setenv("PETRIFLOW_LIMITS", "RUN_TOKENS=3e7")
    assert main(["run", str(net), "--max-firings", "1"]) == 1  # it runs: one firing, short of its sink q
    capsys.readouterr()
    monkeypatch.setenv("PETRIFLOW_LIMITS", "RUN_TOKENS=3e7, YAML_DEPTH=2")
    one_line_error(capsys, ["info", net], "nested more than 2 levels deep")
    monkeypatch.setenv("PETRIFLOW_LIMITS", "RUN_TOKEN=1")
    one_line_error(capsys, ["info", net], "PETRIFLOW_LIMITS: unknown limit 'RUN_TOKEN' (did you mean 'RUN_TOKENS'?)")


def test_limits_are_raised_from_python(own_limits):
    from petriflow.errors import NetFormatError
    from petriflow.io.yaml import loads_net

    deep = "petriflow: 1\nmeta: {x: " + "[" * 80 + "]" * 80 + "}\nplaces: [a]\n"
    with pytest.raises(NetFormatError, match="nested more than 64 levels deep"):
        loads_net(deep)
    own_limits.YAML_DEPTH = 100
    assert list(loads_net(deep).places) == ["a"]


def test_a_parameter_named_by_a_number_is_one_line(tmp_path, capsys):
    """Found by the nightly fuzz profile: params {seconds: 1, -1} made the hint a traceback."""
    net = tmp_path / "k.yaml"
    net.write_text("petriflow: 1\nplaces: [{id: i, tokens: 1}, o]\n"
                   "transitions: [{id: t, action: core.wait, params: {seconds: 1, -1}, in: [i], out: [o]}]\n")
    one_line_error(capsys, ["info", net], "k.yaml:3: 't': 'params': key -1 must be text")


# The classes of the second hostile corpus ------------------------------------------------
HUGE = "9" * 5000


@pytest.mark.parametrize("argv", [
    ["fire", PASSAGE, "red_approach", "--marking", '{"red_home": %s}' % HUGE],
    ["export", PASSAGE, "-f", "dot", "-o", "x.dot", "--marking", '{"red_home": %s}' % HUGE],
    ["simulate", PASSAGE, "--marking", '{"red_home": %s}' % HUGE],
], ids=["fire", "export", "simulate"])
def test_integers_of_thousands_of_digits_are_one_line(tmp_path, capsys, monkeypatch, argv):
    monkeypatch.chdir(tmp_path)
    err = one_line_error(capsys, argv, "--marking: place 'red_home': token count '999999999999...'"
                         " (5000 digits) is beyond 2**60")
    assert len(err) < 300
    assert not (tmp_path / "x.dot").exists()


@pytest.mark.parametrize("option", ["--steps", "--seed"])
def test_an_unreadable_option_value_is_shown_by_its_start(capsys, option):
    with pytest.raises(SystemExit) as stopped:
        main(["simulate", str(PASSAGE), option, HUGE])
    err = capsys.readouterr().err
    assert stopped.value.code == 2 and err.count("\n") == 1 and len(err) < 200, err
    assert f"argument {option}: the value '999999999999...' (5000 digits) is beyond 2**60" in err


@pytest.mark.parametrize("until", ["1e308", "1e13", "-1", "inf"])
def test_absurd_time_limits_are_refused_before_the_run(tmp_path, capsys, ticker, until):
    db = tmp_path / "run.sqlite"
    one_line_error(capsys, ["run", ticker, "--until", until, "--db", db], "--until must be a time from 0 to 1e+12 s")
    assert not db.exists()


def test_absurd_times_in_a_run_configuration_and_from_python(tmp_path, capsys, ticker):
    from petriflow import run
    from petriflow.errors import PetriflowError

    (tmp_path / "run.yaml").write_text("until: 1e300\n")
    one_line_error(capsys, ["run", ticker], "run.yaml:1: until must be a number of seconds from 0 to 1e12")
    (tmp_path / "run.yaml").write_text(f"until: {'9' * 400}\n")
    one_line_error(capsys, ["run", ticker],
                   "run.yaml:1: integer '999999999999...' (400 digits) is beyond 2**60")
    (tmp_path / "run.yaml").unlink()
    with pytest.raises(PetriflowError, match="until must be a time"):
        run(ticker, until=1e308)


def test_simulate_is_bounded_by_a_documented_limit(capsys, own_limits):
    one_line_error(capsys, ["simulate", PASSAGE, "--steps", "1000001"], "--steps must be from 0 to 1,000,000",
                   "SIMULATE_STEPS")
    own_limits.SIMULATE_STEPS = 5
    one_line_error(capsys, ["simulate", PASSAGE, "--steps", "6"], "--steps must be from 0 to 5")
    assert main(["simulate", str(PASSAGE), "--steps", "5"]) == 0


@pytest.mark.parametrize("argv, option", [
    (["run", "{ticker}", "--trace", "{blocker}/t.jsonl"], "--trace"),
    (["run", "{ticker}", "--db", "{blocker}/t.sqlite"], "--db"),
    (["export", "{ticker}", "-o", "{blocker}/x.svg"], "--output"),
    (["replay", "{trace}", "--net", "{ticker}", "--draw", "{blocker}/x.svg"], "--draw"),
], ids=["trace", "db", "export", "replay"])
def test_an_output_that_cannot_be_written_is_one_line_before_any_work(tmp_path, capsys, ticker, argv, option):
    """An output inside something that is not a writable folder (here a file, which no
    user, root included, can write into)."""
    blocker = tmp_path / "blocker"
    blocker.write_text("a file, not a folder")
    trace = tmp_path / "t.jsonl"
    run_files(ticker, until=1, trace=trace)
    capsys.readouterr()
    filled = [a.format(ticker=ticker, blocker=blocker, trace=trace) for a in argv]
    one_line_error(capsys, filled, option, "cannot write into")
    assert capsys.readouterr().out == ""
    assert blocker.read_text() == "a file, not a folder"


def test_ids_yaml_reads_as_numbers_follow_one_rule(tmp_path, capsys):
    """A whole number is its decimal text everywhere (places, arcs, final marking,
    exports); a value YAML turns into something else is refused with its line."""
    from petriflow.io import load_net
    from petriflow.io.pnml import loads_pnml, dumps_pnml
    from petriflow.io.yaml import dumps_net, loads_net

    path = tmp_path / "n.yaml"
    path.write_text("petriflow: 1\nplaces: [{id: 0, tokens: 1}, 1]\ntransitions: [{id: 2, in: [0], out: {1: 1}}]\n"
                    "final: {1: 1}\n")
    net = load_net(path)
    assert list(net.places) == ["0", "1"] and list(net.transitions) == ["2"]
    assert net.final_marking.to_dict() == {"1": 1}
    assert loads_net(dumps_net(net)).structure() == net.structure()
    assert loads_pnml(dumps_pnml(net)).structure() == net.structure()
    assert main(["check", str(path)]) == 0
    capsys.readouterr()
    for text, fragment in [("places: [{id: p, tokens: 1}, yes]", "n.yaml:2: a place id must be text"),
                           ("places: [{id: p, tokens: 1}, null]", "YAML reads this one as null"),
                           ("places: [{id: p, tokens: 1}, q]\nfinal: {1.5: 1}", "final marking must be text"),
                           ("places: [{id: p, tokens: 1}, q]\ntransitions: [{id: t, in: [p], out: [on]}]",
                            "a place in 'out' must be text")]:
        path.write_text(f"petriflow: 1\n{text}\n")
        one_line_error(capsys, ["info", path], fragment, "put it in quotes")


@pytest.mark.parametrize("transition, fragment", [
    ("{id: t, action: core.fail, params: {probability: 2}, in: [i], out: [o]}",
     "parameter 'probability' must be from 0 to 1, got 2.0"),
    ("{id: t, action: core.wait, params: {seconds: -3}, in: [i], out: [o]}", "parameter 'seconds' must be >= 0"),
    ("{id: t, action: drive.goto, params: {x: 1, y: 0}, in: [i], out: [o]}",
     "action drive.goto moves a robot: give params.robot or put the transition in an agent subnet"),
])
def test_parameter_ranges_and_requirements_fail_when_the_net_binds(tmp_path, capsys, transition, fragment):
    path = tmp_path / "n.yaml"
    path.write_text(f"petriflow: 1\nplaces: [{{id: i, tokens: 1}}, o]\ntransitions:\n  - {transition}\n")
    for command in ("info", "check", "run"):
        one_line_error(capsys, [command, path], "n.yaml:4: 't': " + fragment)


def test_an_action_that_needs_a_world_is_refused_before_a_worldless_run(tmp_path, capsys):
    path = tmp_path / "n.yaml"
    path.write_text("petriflow: 1\nplaces: [{id: i, tokens: 1}, o]\ntransitions:\n"
                    "  - {id: look, action: vision.capture, in: [i], out: [o]}\n")
    db = tmp_path / "run.sqlite"
    one_line_error(capsys, ["run", path, "--db", db], "n.yaml:4: 'look': action vision.capture needs a world")
    assert not db.exists()
    assert main(["info", str(path)]) == 0  # looking needs no world
