"""End to end: the three SMART experiments run (camera at 320 x 240 to save time), print
their tables beside the paper's, and write traces and pictures. The helping run is the
smoke test of `petriflow run nets/smart/smart.yaml`: it reaches the final marking with
Robot4L standing."""

from __future__ import annotations

import contextlib
import io
import json

import pytest

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def ran(tmp_path_factory):
    from petriflow.agents.smart.experiments import main

    out = tmp_path_factory.mktemp("smart")
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        code = main(["all", "--camera", "320x240", "--out", str(out), "--json", str(out / "summary.json")])
    return code, printed.getvalue(), json.loads((out / "summary.json").read_text()), out


def test_all_experiments_finish_and_write_their_files(ran):
    import cv2

    code, text, summary, out = ran
    assert code == 0
    for name in ("reinsertion", "crossing", "helping"):
        assert summary[name]["reason"] == "final"
        assert (out / f"{name}.jsonl").stat().st_size > 0
        picture = cv2.imread(str(out / f"{name}.png"))
        assert picture is not None and picture.shape[0] > 300 and picture.shape[1] > 400
    assert text.count("| quantity | measured | paper (seed 003) |") == 3


def test_reinsertion_rejoins_the_path_after_the_push(ran):
    """The push takes the robot between dmin and r from its path: reinsertion at a point
    ahead, back on track, goal reached."""
    first = ran[2]["reinsertion"]["first_off_track"]
    result = ran[2]["reinsertion"]
    assert first["decision"] == "reinsert" and 0.08 <= first["dc"] <= 0.15
    assert result["ahead_m"] > 0 and result["candidates"] > 1
    assert result["rejoined"] is not None and result["arrived"] and result["replans"] == 0


def test_crossing_holds_blue_and_replans_yellow(ran):
    result = ran[2]["crossing"]
    assert result["detected_at"] is not None and result["centre_distance_at_detection"] < 0.42
    assert result["blue_held_s"] > 1.0 and len(result["yellow_plans"]) >= 2
    assert len(result["blue_plans"]) == 1
    assert result["arrived"] == {"y": True, "b": True}
    assert result["closest_centres"] > 0.22
    assert result["frames"] and {f["robot"] for f in result["frames"]} == {3}   # STOP frames to blue only


def test_helping_runs_the_corrected_net_to_its_end(ran):
    result = ran[2]["helping"]
    assert result["sequence"] == ["T0", "T1", "T3", "T4", "T5", "T7", "T8", "T6", "T9"]
    assert result["loop_hz"] == pytest.approx(6.0, abs=0.1)
    assert result["stand_up"]["tilt"] < 5.0
    assert [f["action"] for f in result["frames"] if f["action"] != "MOVE_TO"] == ["STOP", "HELP", "HOLD"]
