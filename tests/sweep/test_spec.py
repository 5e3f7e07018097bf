"""Reading sweep files: grid expansion, rows, seeds, metrics, paper values, errors with lines."""

from __future__ import annotations

import pytest

from petriflow.errors import NetFormatError
from petriflow.io.files import read_yaml_file
from petriflow.sweep.load import load_sweep
from petriflow.sweep.ship import collect
from petriflow.sweep.spec import Sweep

from .conftest import write


def sweep_text(folder, body: str) -> str:
    import textwrap

    return f"petriflow-sweep: 1\nnet: {folder}/net.yaml\n{textwrap.dedent(body)}"


def test_matrix_expands_first_parameter_slowest_then_explicit_rows(folder, tmp_path):
    path = write(tmp_path, "s.yaml", sweep_text(folder, """\
        matrix: {a: [1, 2], b: [5, 6, 7]}
        rows: [{a: 9, b: 8, paper: {core.end_time: 4}}]
        set: {net.transitions.rest.params.seconds: "${a}", run.seed: "${b}"}
        trials: 2
        """))
    sweep = load_sweep(path)
    assert [tuple(r.params.values()) for r in sweep.rows] == [
        (1, 5), (1, 6), (1, 7), (2, 5), (2, 6), (2, 7), (9, 8)]
    assert sweep.rows[-1].paper == {"core.end_time": 4}
    assert [(t.row, t.seed) for t in sweep.trials()][:3] == [(0, 1), (0, 2), (1, 1)]
    assert len(sweep.trials()) == 14
    assert sweep.with_seeds(5).seeds == [1, 2, 3, 4, 5]


def test_paper_rows_match_by_parameters(folder, tmp_path):
    path = write(tmp_path, "s.yaml", sweep_text(folder, """\
        matrix: {a: [1, 2], b: [x, y]}
        set: {net.transitions.rest.params.seconds: "${a}", run.faults: [{join: "robot_${b}", at: 1}]}
        metrics: {t: core.end_time}
        paper:
          source: Table 1
          rows:
            - {params: {a: 2}, values: {t: 7.5}}
            - {params: {a: 2, b: y}, values: {t: 8}}
        """))
    sweep = Sweep.from_dict(read_yaml_file(path, lines=True), path)  # (the net has no such agents)
    assert [r.paper for r in sweep.rows] == [{}, {}, {"t": 7.5}, {"t": 8}]
    assert sweep.paper_source == "Table 1"


def test_explicit_seeds_and_no_parameters_make_one_row(folder, tmp_path):
    sweep = load_sweep(write(tmp_path, "s.yaml", sweep_text(folder, "seeds: [7, 3]\n")))
    assert [r.params for r in sweep.rows] == [{}]
    assert [t.seed for t in sweep.trials()] == [7, 3]


def test_the_digest_ignores_seeds_timeout_and_paper_but_not_what_decides_results(folder, tmp_path):
    base = "matrix: {a: [1]}\nset: {net.transitions.rest.params.seconds: \"${a}\"}\n"
    one = load_sweep(write(tmp_path, "a.yaml", sweep_text(folder, base + "trials: 2\ntimeout: 5\n")))
    two = load_sweep(write(tmp_path, "b.yaml", sweep_text(folder, base + "trials: 9\n")))
    three = load_sweep(write(tmp_path, "c.yaml", sweep_text(folder, base + "metrics: [core.firings]\n")))
    assert collect(one).digest() == collect(two).digest() != collect(three).digest()


@pytest.mark.parametrize("body, fragment, line", [
    ("matrix: {a: []}\n", "'a' needs a non-empty list", 3),
    ("matrix: {a: [1, 1]}\nset: {run.seed: '${a}'}\n", "lists a value twice", 3),
    ("set: {run.until: '${missing}'}\n", "has no value for ${missing}", None),
    ("matrix: {a: [1]}\n", "parameter 'a' is not used", 3),
    ("set: {planet.x: 1}\n", "must start with run., world. or net.", 3),
    ("set: {net.places.x: 1}\n", "net.transitions.ID.params.KEY", 3),
    ("metrics: [core.firngs]\n", "unknown metric 'core.firngs' (did you mean 'core.firings'", 3),
    ("metrics: [core.firings, core.firings]\n", "listed twice", 3),
    ("trials: 0\n", "trials must be an integer from 1", 3),
    ("trials: 2\nseeds: [1]\n", "not both", 4),
    ("timeout: .nan\n", "timeout must be a positive number", 3),
    ("timeout: -1\n", "timeout must be a positive number", 3),
    ("rows: [{a: 1}, {b: 2}]\nset: {run.seed: '${a}', run.until: '${b}'}\n", "every row must set the same", 3),
    ("rows: [{seed: 1}]\n", "not a parameter name", 3),
    ("matrix: {a: [1, 2]}\nrows: [{a: 1}]\nset: {run.seed: '${a}'}\n", "repeats the parameters of row 1", None),
    ("paper: {rows: [{params: {a: 5}, values: {core.end_time: 1}}]}\n", "no row has the parameters", 3),
    ("paper: {rows: [{values: {nope: 1}}]}\n", "'nope' is not one of the sweep's metrics", 3),
    ("colour: blue\n", "unknown key 'colour'", 3),
    ("matrix: {a: [.inf]}\nset: {run.seed: '${a}'}\n", "not plain data", 3),
])
def test_mistakes_are_one_error_naming_the_file_and_line(folder, tmp_path, body, fragment, line):
    path = write(tmp_path, "bad.yaml", sweep_text(folder, body))
    with pytest.raises(NetFormatError) as caught:
        load_sweep(path)
    assert fragment in caught.value.message
    assert caught.value.path == str(path)
    if line is not None:
        assert caught.value.line == line


@pytest.mark.parametrize("text, fragment", [
    ("net: x.yaml\n", "not a sweep file"),
    ("petriflow-sweep: 2\nnet: x.yaml\n", "version 2 is not supported"),
    ("petriflow-sweep: true\nnet: x.yaml\n", "version True is not supported"),
    ("petriflow-sweep: 1\nnet: nowhere.yaml\n", "net 'nowhere.yaml' not found"),
    ("petriflow-sweep: 1\nnet: {builder: 'not a module'}\n", "net must be a file name"),
    ("petriflow-sweep: 1\nnet: n.yaml\nrun: nowhere.yaml\n", "run configuration 'nowhere.yaml' not found"),
    ("- 1\n- 2\n", "a sweep file is a mapping"),
    ("petriflow-sweep: 1\nnet: [\n", "malformed YAML"),
])
def test_files_that_are_not_sweeps_are_refused(tmp_path, text, fragment):
    (tmp_path / "n.yaml").write_text("petriflow: 1\nplaces: [p]\n")
    path = write(tmp_path, "bad.yaml", text)
    with pytest.raises(NetFormatError, match="bad.yaml") as caught:
        load_sweep(path)
    assert fragment in str(caught.value)


@pytest.mark.parametrize("body, fragment", [
    ("matrix: {a: [1, x]}\nset: {run.seed: '${a}'}\n", "row 2 ({\"a\":\"x\"}): "),
    ("set: {net.transitions.nope.params.x: 1}\n", "no transition 'nope'"),
    ("set: {net.transitions.rest.params.secs: 1}\n", "action has no parameter 'secs'"),
    ("set: {world.robots.0.position: [1, 1]}\n", "the run has no world"),
    ("metrics: [core.firngs]\n", "unknown metric 'core.firngs' (did you mean 'core.firings'"),
])
def test_rows_are_built_before_anything_runs(folder, tmp_path, body, fragment):
    """Every row's trial is built (not run) when the file is read: a mistake in any
    row is one error naming the sweep file and the line of set: or metrics:."""
    path = write(tmp_path, "bad.yaml", sweep_text(folder, body))
    with pytest.raises(NetFormatError) as caught:
        load_sweep(path)
    assert fragment in str(caught.value)
    assert str(caught.value).startswith(f"{path}:{3 if body.startswith(('set', 'metrics')) else 4}: ")


def test_a_builder_refusing_a_row_is_one_error_naming_the_row(tmp_path):
    (tmp_path / "world.yaml").write_text("dt: 0.1\n")
    (tmp_path / "run.yaml").write_text("world: world.yaml\n")
    path = write(tmp_path, "bad.yaml", "petriflow-sweep: 1\nnet: {builder: 'petriflow.agents.bidding.nets:build'}\n"
                 "run: run.yaml\nmatrix: {robots: [2, 0]}\n")
    with pytest.raises(NetFormatError) as caught:
        load_sweep(path)
    assert str(caught.value).startswith(f"{path}:2: row 2 ") and "robots must be from 1 to 200, got 0" in str(caught.value)
