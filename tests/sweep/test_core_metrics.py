"""Built-in sweep metrics: core.completed and core.cpu_s_per_sim_s, on a tiny net."""

from __future__ import annotations

import math

import pytest

from petriflow.runtime.metrics import RunRecord, cpu_s_per_sim_s
from petriflow.runtime.registry import default_registry
from petriflow.sweep import load_sweep, run_sweep
from petriflow.sweep.trial import run_trial

from .conftest import write


def sweep_file(folder, tmp_path):
    """The one-wait net (1 s, then its final marking) under two time limits: 100 s (it
    finishes) and 0.5 s (``until`` stops it mid-wait)."""
    return write(tmp_path, "limits.yaml", f"""\
        petriflow-sweep: 1
        net: {folder}/net.yaml
        rows: [{{until: 100}}, {{until: 0.5}}]
        set: {{run.until: "${{until}}"}}
        metrics:
          completed: core.completed
          cpu: core.cpu_s_per_sim_s
          outcome: core.outcome
          end: core.end_time
        """)


def test_completed_is_1_at_the_final_marking_and_0_when_until_stops_the_run(folder, tmp_path):
    sweep = load_sweep(sweep_file(folder, tmp_path))
    finished, stopped = (run_trial(sweep.payload(trial)) for trial in sweep.trials())
    assert finished["status"] == stopped["status"] == "ok"
    assert finished["outcome"] == "final" and finished["metrics"]["completed"] == 1
    assert stopped["outcome"] == "until" and stopped["metrics"]["completed"] == 0
    assert finished["metrics"]["end"] == 1.0 and stopped["metrics"]["end"] == 0.5


def test_cpu_seconds_per_simulated_second_is_a_positive_finite_float(folder, tmp_path):
    sweep = load_sweep(sweep_file(folder, tmp_path))
    for trial in sweep.trials():
        cpu = run_trial(sweep.payload(trial))["metrics"]["cpu"]
        assert isinstance(cpu, float) and math.isfinite(cpu) and cpu > 0


def test_cpu_metric_is_marked_wall_clock_and_completed_is_not(folder, tmp_path):
    assert default_registry.metric_spec("core.cpu_s_per_sim_s").wall_clock
    assert not default_registry.metric_spec("core.completed").wall_clock
    result = run_sweep(load_sweep(sweep_file(folder, tmp_path)), workers=1)
    assert result.wall_clock() == ["cpu"]
    assert [row["metrics"]["completed"]["mean"] for row in result.rows] == [1.0, 0.0]


@pytest.mark.parametrize("cpu, time", [(None, 1.0), (0.1, 0.0)])
def test_cpu_metric_is_none_when_unmeasured_or_no_time_passed(cpu, time):
    class Result:
        pass

    result = Result()
    result.time = time
    assert cpu_s_per_sim_s(RunRecord(result, cpu=cpu)) is None
