"""The petriflow command line: results, exit codes and one-line errors."""

import json
import subprocess
import sys

import pytest

from petriflow.cli import main
from petriflow.io.yaml import loads_net
from tests.conftest import NETS, SEQUENCE_YAML

INSPECTION = str(NETS / "examples" / "inspection.yaml")


@pytest.fixture
def sequence_file(tmp_path):
    path = tmp_path / "sequence.yaml"
    path.write_text(SEQUENCE_YAML)
    return str(path)


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


@pytest.mark.parametrize("command", ["info", "simulate", "fire", "export", "run", "check"])
def test_every_command_has_help(command, capsys):
    """--help works on every command and exits 0."""
    with pytest.raises(SystemExit) as info:
        main([command, "--help"])
    assert info.value.code == 0
    assert "usage: petriflow" in capsys.readouterr().out


def test_info_lists_subnets_and_actions(capsys):
    """info shows sizes, subnets and bound actions."""
    code, out, _ = run(capsys, "info", INSPECTION, "--json")
    data = json.loads(out)
    assert code == 0
    assert (data["places"], data["transitions"]) == (9, 8)
    assert set(data["subnets"]) == {"camera", "planner", "red", "blue"}
    assert data["actions"]["capture"] == "smart.capture"


def test_simulate_is_deterministic_for_a_seed(capsys):
    """The same seed gives the same firing sequence."""
    first = json.loads(run(capsys, "simulate", INSPECTION, "--steps", "50", "--seed", "7", "--json")[1])
    second = json.loads(run(capsys, "simulate", INSPECTION, "--steps", "50", "--seed", "7", "--json")[1])
    assert first == second
    assert first["deadlock"] and first["marking"] == {"o": 1}


def test_simulate_prints_fired_transitions_and_final_marking(capsys, sequence_file):
    """Human output lists each firing and the final marking."""
    code, out, _ = run(capsys, "simulate", sequence_file, "--steps", "5")
    assert code == 0
    assert out.splitlines()[:2] == ["     1  a", "     2  b"]
    assert "marking at the end: o=2" in out


def test_fire_prints_marking_after_each_transition(capsys, sequence_file):
    """fire shows the marking reached after each named transition."""
    code, out, _ = run(capsys, "fire", sequence_file, "a", "b", "--json")
    assert code == 0
    assert json.loads(out)["marking"] == {"o": 2}


def test_fire_from_given_marking(capsys, sequence_file):
    """--marking replaces the initial marking."""
    code, out, _ = run(capsys, "fire", sequence_file, "b", "--marking", '{"p": 1}', "--json")
    assert code == 0 and json.loads(out)["marking"] == {"o": 2}


def test_fire_not_enabled_exits_1_naming_step_and_place(capsys, sequence_file):
    """A transition that cannot fire is reported with its short place; exit 1."""
    code, _, err = run(capsys, "fire", sequence_file, "b")
    assert code == 1
    assert "step 1: transition 'b' is not enabled: p has 0, needs 1" in err


@pytest.mark.parametrize(
    "argv, fragment",
    [
        (["fire", "{net}", "x"], "unknown transition 'x'"),
        (["fire", "{net}", "a", "--marking", '{"i": 1.5}'], "--marking: place 'i': token count"),
        (["fire", "{net}", "a", "--marking", '{"zz": 1}'], "unknown place 'zz'"),
        (["simulate", "{net}", "--steps", "-1"], "--steps must be from 0 to"),
        (["info", "missing.yaml"], "missing.yaml: no such file"),
    ],
)
def test_bad_input_exits_2_with_one_line(argv, fragment, capsys, sequence_file):
    """Bad input: one line on stderr, exit 2, nothing on stdout."""
    code, out, err = run(capsys, *[a.replace("{net}", sequence_file) for a in argv])
    assert code == 2
    assert fragment in err and err.count("\n") == 1
    assert out == ""


def test_malformed_yaml_exits_2_naming_file_and_line(capsys, tmp_path):
    """A YAML net with a bad arc is named with file and line."""
    path = tmp_path / "bad.yaml"
    path.write_text("petriflow: 1\nplaces: [p]\ntransitions:\n  - {id: t, in: [p], out: [nowhere]}\n")
    code, _, err = run(capsys, "info", str(path))
    assert code == 2
    assert err.strip() == f"petriflow: {path}:4: 't': 'out' names unknown place 'nowhere'"


def test_check_reports_a_sound_workflow_net(capsys, sequence_file):
    """check on a sound WF-net exits 0 and says so in JSON."""
    code, out, _ = run(capsys, "check", sequence_file, "--json")
    assert code == 0 and json.loads(out)["sound"] is True


def test_console_script_runs_without_traceback(tmp_path):
    """The installed entry point prints one line and no traceback on bad input."""
    path = tmp_path / "broken.yaml"
    path.write_text("petriflow: 1\nplaces: [p\n")
    done = subprocess.run([sys.executable, "-m", "petriflow.cli", "info", str(path)],
                          capture_output=True, text=True)
    assert done.returncode == 2
    assert "Traceback" not in done.stderr and done.stderr.count("\n") == 1


@pytest.mark.parametrize(
    "content, fragment",
    [
        ('<?xml version="1.0"?>\n<pnml><net id="n" type="http://www.pnml.org/version-2009/grammar/ptnet">\n<page id="g">',
         "bad.pnml:3"),
        ('<pnml><net id="n" type="http://www.pnml.org/version-2009/grammar/symmetricnet"><page id="g"/></net></pnml>',
         "symmetricnet"),
    ],
    ids=["truncated-xml", "wrong-pnml-type"],
)
def test_bad_pnml_exits_2_with_one_line(content, fragment, capsys, tmp_path):
    """Truncated XML and a coloured-net type are one-line errors naming the file."""
    path = tmp_path / "bad.pnml"
    path.write_text(content)
    code, out, err = run(capsys, "info", str(path))
    assert code == 2 and out == "" and err.count("\n") == 1
    assert fragment in err and "bad.pnml" in err


def test_commands_work_on_pnml_written_by_pm4py(capsys, tmp_path):
    """info, simulate, fire and export accept a PNML file PM4Py wrote."""
    pm4py = pytest.importorskip("pm4py")
    from pm4py.objects.petri_net.obj import Marking as PM4PyMarking, PetriNet
    from pm4py.objects.petri_net.utils import petri_utils

    net = PetriNet("pm")
    source, sink = PetriNet.Place("source"), PetriNet.Place("sink")
    work = PetriNet.Transition("work", "Work")
    net.places.update({source, sink})
    net.transitions.add(work)
    petri_utils.add_arc_from_to(source, work, net)
    petri_utils.add_arc_from_to(work, sink, net, weight=2)
    path = tmp_path / "pm.pnml"
    pm4py.write_pnml(net, PM4PyMarking({source: 1}), PM4PyMarking({sink: 2}), str(path))
    assert run(capsys, "info", str(path))[0] == 0
    code, out, _ = run(capsys, "fire", str(path), "work", "--json")
    assert code == 0 and json.loads(out)["marking"] == {"sink": 2}
    assert run(capsys, "simulate", str(path), "--steps", "3")[0] == 0
    assert run(capsys, "export", str(path), "-f", "yaml", "-o", str(tmp_path / "pm.yaml"))[0] == 0


def test_check_accepts_a_net_ending_in_its_final_marking(capsys):
    """A non-WF net whose only dead marking is its declared final marking passes check."""
    code, out, _ = run(capsys, "check", str(NETS / "passage" / "passage.yaml"), "--json")
    result = json.loads(out)
    assert code == 0
    assert (result["deadlock_free"], result["stuck_markings"], result["final_marking_reached"]) == (
        False, 0, True)


def test_check_exit_1_with_a_witness_for_the_papers_smart_net(capsys):
    """The SMART net as published deadlocks; check exits 1 with the firing sequence."""
    code, out, _ = run(capsys, "check", str(NETS / "smart" / "smart-paper.yaml"), "--json")
    violations = json.loads(out)["violations"]
    assert code == 1
    assert {v["kind"] for v in violations} >= {"not_wf_net", "deadlock"}
    deadlock = next(v for v in violations if v["kind"] == "deadlock")
    assert deadlock["transitions"][-1] == "T9" and deadlock["marking"] == {"P2": 1, "P5": 1}


def test_export_draws_a_violation_witness(capsys, tmp_path):
    """export --violation highlights the witness path of the first violation."""
    out_file = tmp_path / "violation.dot"
    code, out, _ = run(capsys, "export", str(NETS / "smart" / "smart-paper.yaml"), "-f", "dot",
                       "-o", str(out_file), "--violation")
    assert code == 0 and "deadlock" in out
    from petriflow.export import HIGHLIGHT_COLOUR

    assert out_file.read_text().count(HIGHLIGHT_COLOUR) >= 8


def test_export_violation_maps_outcome_variants_to_their_transition(capsys, tmp_path):
    """A witness through ``t@failed`` highlights ``t``, even when ``t``'s id has an '@'."""
    net = tmp_path / "dock.yaml"
    net.write_text("""petriflow: 1
places: [{id: i, tokens: 1}, o, broken]
final: {o: 1}
transitions:
  - {id: "scan@dock", in: [i], out: [o], outcomes: {failed: [broken]}}
""")
    out_file = tmp_path / "dock.dot"
    code, out, _ = run(capsys, "export", str(net), "-f", "dot", "-o", str(out_file),
                       "--violation")
    assert code == 0 and "broken=1" in out          # the witness: scan@dock@failed
    from petriflow.export import HIGHLIGHT_COLOUR

    highlighted = [line for line in out_file.read_text().splitlines()
                   if HIGHLIGHT_COLOUR in line]
    assert any('"scan@dock"' in line for line in highlighted)


def test_export_violation_on_a_sound_net_draws_nothing_and_exits_0(capsys, tmp_path, sequence_file):
    """No violation is not a problem: exit 0, a line saying so, no file."""
    out_file = tmp_path / "v.svg"
    assert main(["export", str(sequence_file), "-o", str(out_file), "--violation"]) == 0
    assert "no violation" in capsys.readouterr().err and not out_file.exists()


def test_export_violation_says_what_the_red_path_is(capsys, tmp_path):
    out_file = tmp_path / "v.dot"
    assert main(["export", str(NETS / "smart" / "smart-paper.yaml"), "-o", str(out_file), "--violation"]) == 0
    assert "red: deadlock: 1 reachable marking enables no transition" in out_file.read_text()


def test_replay_checks_its_options_before_printing(capsys, tmp_path, sequence_file):
    """--draw without --net, or --at out of range: one line, exit 2, nothing printed first."""
    trace = tmp_path / "t.jsonl"
    assert main(["run", str(sequence_file), "--trace", str(trace)]) == 0
    capsys.readouterr()
    assert main(["replay", str(trace), "--draw", str(tmp_path / "m.svg")]) == 2
    captured = capsys.readouterr()
    assert captured.out == "" and "--draw needs --net" in captured.err
    assert main(["replay", str(trace), "--at", "99"]) == 2
    assert capsys.readouterr().out == ""
    assert main(["replay", str(trace), "--net", str(sequence_file), "--draw", str(tmp_path / "m.gif")]) == 2
    assert "cannot tell the format" in capsys.readouterr().err


def test_run_summary_says_how_it_ended_and_the_seed(capsys, sequence_file):
    """Stopped short of the net's final marking by a limit: exit 1, saying how it ended."""
    assert main(["run", str(sequence_file), "--max-firings", "1", "--seed", "4"]) == 1
    out = capsys.readouterr().out
    assert "firings at t = 0 s after 1 firing (seed 4;" in out and "no simulated time passed" in out
    assert "marking at the end: p=1" in out and "final marking" not in out


def test_export_to_dash_writes_standard_output_and_no_file(tmp_path, monkeypatch, capfdbinary, sequence_file):
    """``-o -`` writes the export's bytes to standard output (a picture too), never a file named '-'."""
    monkeypatch.chdir(tmp_path)
    assert main(["export", str(sequence_file), "-f", "yaml", "-o", "-"]) == 0
    out = capfdbinary.readouterr().out
    assert out.startswith(b"petriflow: 1") and loads_net(out.decode()).transitions
    assert main(["export", str(sequence_file), "-f", "png", "-o", "-"]) == 0
    assert capfdbinary.readouterr().out.startswith(b"\x89PNG")
    assert main(["export", str(sequence_file), "-o", "-"]) == 2
    assert "give -f" in capfdbinary.readouterr().err.decode()
    assert [p.name for p in tmp_path.iterdir()] == ["sequence.yaml"]


@pytest.mark.parametrize("argv", [["run", "{net}", "--until", "\u0663"], ["run", "{net}", "--until", "1_0"],
                                  ["run", "{net}", "--poses", "\u0661"], ["view", "{net}", "--max-mb", "\u0662"],
                                  ["run", "{net}", "--progress-every", "\uff15"]])
def test_decimal_options_take_ascii_numbers_only(capsys, sequence_file, argv):
    """Another script's digits are not read as a number (float() would read U+0663 as 3)."""
    with pytest.raises(SystemExit) as exit:
        main([a.format(net=sequence_file) for a in argv])
    assert exit.value.code == 2
    assert "not a number written in ASCII" in capsys.readouterr().err
