"""The reproduction: every published value of every shipped sweep file has a status and
is in the report; `petriflow reproduce` runs the tables and writes the report and pages."""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

import pytest

from petriflow.io.files import read_yaml_file
from petriflow.sweep.reproduce import markdown, published_values, reproduce, scenarios
from petriflow.sweep.spec import Sweep

ROOT = Path(__file__).resolve().parents[2]
NETS = ROOT / "nets"


def sweep_files() -> list[Path]:
    """Every shipped sweep file with published values."""
    found = []
    for path in sorted(NETS.glob("*/experiments/*.yaml")):
        data = read_yaml_file(path)
        if isinstance(data, dict) and "petriflow-sweep" in data and data.get("paper"):
            found.append(path)
    return found


def test_every_shipped_published_value_has_a_status():
    files = sweep_files()
    assert len(files) >= 16
    for path in files:
        sweep = Sweep.from_dict(read_yaml_file(path, lines=True), path)
        for row in sweep.rows:
            for name in row.paper:
                assert name in row.paper_status, f"{path.relative_to(ROOT)}: row {row.params}: {name} has no status"


def test_the_report_lists_every_published_value_of_every_sweep_file(tmp_path):
    outcome = reproduce(NETS, tmp_path, measure=False)
    text = markdown(outcome, NETS)
    tables = {t.path for s in outcome.scenarios for t in s.tables}
    assert tables == set(sweep_files())
    lines = text.splitlines()
    for scenario in outcome.scenarios:
        assert f"## {scenario.title}" in lines
        for table in scenario.tables:
            where = lines.index(next(line for line in lines if line.startswith(f"`{table.path.relative_to(ROOT)}`")))
            body = []
            for line in lines[where + 4:]:
                if not line.startswith("| "):
                    break
                body.append(line)
            listed = [[cell.strip() for cell in line.strip("|").split(" | ")] for line in body]
            expected = published_values(table)
            assert len(listed) == len(expected), table.path
            for (params, name, value, status), cells in zip(expected, listed):
                assert cells[1] == name and cells[2] == str(value).replace("|", "\\|")
                assert cells[3] == "not run"
                assert cells[4] == status["status"].replace("-", " ")
    total = re.search(r"\| \*\*all\*\* \| (\d+) \| \*\*(\d+)\*\* \| \*\*(\d+)\*\* \| \*\*(\d+)\*\* \| \*\*(\d+)\*\* \|", text)
    assert total and int(total.group(1)) == len(tables)
    counted = sum(int(total.group(k)) for k in range(2, 6))
    assert counted == sum(len(published_values(t)) for s in outcome.scenarios for t in s.tables)
    assert total.group(5) == "0"  # no value without a status


def test_a_tiny_project_is_reproduced_with_report_and_pages(tmp_path):
    root = tmp_path / "nets"
    (root / "demo" / "experiments").mkdir(parents=True)
    (root / "demo" / "README.md").write_text("# A demo scenario\n")
    (root / "demo" / "net.yaml").write_text(
        "petriflow: 1\nplaces: [{id: i, tokens: 1}, o]\n"
        "transitions: [{id: rest, action: core.wait, params: {seconds: 1}, in: [i], out: [o]}]\nfinal: {o: 1}\n")
    (root / "demo" / "experiments" / "t1.yaml").write_text(
        "petriflow-sweep: 1\nnet: ../net.yaml\ntrials: 3\nmatrix: {w: [1, 2]}\n"
        "set: {net.transitions.rest.params.seconds: '${w}'}\nmetrics: {t: core.end_time}\n"
        "paper:\n  source: Table 1\n  rows:\n"
        "    - {params: {w: 1}, values: {t: {value: 1, status: built-in, because: the wait is the paper's}}}\n"
        "    - {params: {w: 2}, values: {t: {value: 3, status: missed, because: a second nobody explains}}}\n")
    (root / "demo" / "experiments" / "other.yaml").write_text(  # no paper values: not a table
        "petriflow-sweep: 1\nnet: ../net.yaml\n")
    from petriflow.cli import main

    report = tmp_path / "report.md"
    assert main(["reproduce", str(root), "--quick", "--out", str(tmp_path / "out"), "--report", str(report),
                 "--workers", "1"]) == 0
    text = report.read_text()
    assert "quick: one trial a row" in text
    assert "| w=1 | t | 1 | 1 | built in | +0 | the wait is the paper's |" in text.replace("(+0.0%) ", "")
    assert "| w=2 | t | 3 | 2 | missed | -1 (-33.3%) | a second nobody explains |" in text
    assert "| [A demo scenario](#a-demo-scenario) | 1 | 0 | 1 | 1 | 0 |" in text
    assert (tmp_path / "out" / "demo" / "t1.db").is_file() and (tmp_path / "out" / "demo" / "t1.html").is_file()
    assert "other" not in text
    # again: the same code and files resume (nothing to run), the report is the same but for the wall time
    assert main(["reproduce", str(root), "--quick", "--out", str(tmp_path / "out"), "--report", str(report),
                 "--workers", "1", "--no-pages"]) == 0
    assert "| w=2 | t | 3 | 2 | missed |" in report.read_text()


def test_bad_input_is_one_line_and_exit_2(tmp_path, capsys):
    from petriflow.cli import main

    assert main(["reproduce", str(tmp_path / "nowhere")]) == 2
    assert main(["reproduce", str(NETS), "--only", "comms", "--list", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert "no such folder of scenarios" in err and "no scenario 'comms'" in err and "did you mean 'comm'" in err
    assert "Traceback" not in err


@pytest.mark.slow
def test_the_script_quick_mode_runs_a_scenario_and_reports_its_measurements(tmp_path):
    out, report = tmp_path / "out", tmp_path / "reproduction.md"
    done = subprocess.run(["bash", str(ROOT / "scripts" / "reproduce.sh"), "--quick", "--only", "slam",
                           "--out", str(out), "--report", str(report)],
                          capture_output=True, text=True, timeout=1800)
    assert done.returncode == 0, done.stderr[-2000:]
    text = report.read_text()
    for table in next(s for s in scenarios(NETS) if s.name == "slam").tables:
        assert f"`{table.path.relative_to(ROOT)}`: {sum(1 for _ in Sweep.from_dict(read_yaml_file(table.path), table.path).rows)} trials" in text
    assert "| mode=decentralised | time_s | 1340 |" in text
    assert "not measured" not in text and "not run" not in text
    assert (out / "slam" / "table7.html").is_file()
