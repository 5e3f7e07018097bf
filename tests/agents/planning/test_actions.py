"""The planning actions and guards as a net uses them: conformance, token data in and
out, failures with a reason, and guards routing a tracking decision."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest

from petriflow.agents.planning.actions import PlanPath, TrackPath, plan_world_path, scene_frame
from petriflow.agents.planning.errors import PlanningError
from petriflow.agents.planning.maps import OBSTACLE, ROBOT_LABELS, GridFrame, configuration_space, draw_disc
from petriflow.errors import PetriflowError
from petriflow.io.yaml import loads_net
from petriflow.runtime.registry import Registry, default_registry
from petriflow.runtime.binding import bind
from petriflow.testing import StubWorld, check_action, fire_one

MPP = 0.01  # a 64 x 48 pixel map of 0.64 m x 0.48 m


def label_map() -> np.ndarray:
    """Red at the left, blue in the middle, a wall from the top between them and the goal."""
    label = np.zeros((48, 64), np.uint8)
    label[:30, 40:43] = OBSTACLE
    label = draw_disc(label, (24, 8), 4, ROBOT_LABELS["red"])
    return draw_disc(label, (24, 25), 4, ROBOT_LABELS["blue"])


def scene() -> dict:
    return {"label_map": label_map(), "metres_per_pixel": MPP, "origin": [0.0, 0.0],
            "poses": {"red": [0.08, -0.24, 0.0]}, "goal": {"red": [0.55, -0.1]}}


PLAN_NET = """
petriflow: 1
net: plan
places: [{id: seen, tokens: 1}, planned, unplanned]
transitions:
  - id: plan
    action: planning.astar
    params: {robot: red, radius: 0.04, cell: 2}
    in: [seen]
    out: [planned]
    outcomes: {failed: [unplanned]}
"""

TRACK_NET = """
petriflow: 1
net: track
places: [{id: walked, tokens: 1}, checked, lost, going, rejoining, replanning]
transitions:
  - id: check
    action: planning.track
    params: {robot: red, step: 0.02, radius: 0.05}
    in: [walked]
    out: [checked]
    outcomes: {failed: [lost]}
  - {id: keep_going, guard: planning.on_track, in: [checked], out: [going]}
  - {id: rejoin, guard: planning.reinsert, in: [checked], out: [rejoining]}
  - {id: replan, guard: planning.replan, in: [checked], out: [replanning]}
"""


@pytest.mark.parametrize("cls, params", [(PlanPath, {"robot": "red", "goal": [1.0, 0.0]}), (PlanPath, {}),
                                         (TrackPath, {}), (TrackPath, {"step": 0.1, "radius": 0.3})])
def test_actions_pass_the_conformance_check(cls, params):
    """Both actions pass check_action (without inputs they fail cleanly, not by raising)."""
    assert check_action(cls, params) == []


def test_plugin_registers_actions_and_guards():
    """The default registry finds the planning actions and guards through the entry point."""
    assert default_registry.resolve("planning.astar") is PlanPath
    assert default_registry.resolve("planning.track") is TrackPath
    for guard in ("planning.on_track", "planning.reinsert", "planning.replan"):
        assert callable(default_registry.guard(guard))


def test_plan_world_path_avoids_obstacles_grown_by_the_radius():
    """The world path keeps the robot's disc off obstacles and the other robot."""
    result = plan_world_path(label_map(), GridFrame(MPP, cell=2), "red", (0.55, -0.1), radius=0.04)
    assert result["found"] and result["path"][0] == result["start"] and result["path"][-1] == [0.55, -0.1]
    cspace = configuration_space(label_map() == OBSTACLE, 0.04 / MPP) | configuration_space(
        label_map() == ROBOT_LABELS["blue"], 0.04 / MPP)
    pixels = np.rint(GridFrame(MPP).world_to_pixel(result["path"])).astype(int)
    assert not cspace[pixels[:, 0], pixels[:, 1]].any()
    assert result["length_m"] > 0.47  # around the wall, not through it


def test_plan_world_path_snaps_a_goal_on_another_robot():
    """A goal on a robot (the helper walks to the fallen one) moves to the nearest free cell."""
    frame = GridFrame(MPP, cell=2)
    blue = (0.25, -0.24)
    result = plan_world_path(label_map(), frame, "red", blue, radius=0.04, snap=0.1)
    end = np.array(result["path"][-1])
    assert 0.04 + 0.04 - 0.02 <= np.hypot(*(end - blue)) <= 0.1
    with pytest.raises(PlanningError, match="blocked"):
        plan_world_path(label_map(), frame, "red", blue, radius=0.04, snap=0.01)


def pushed_into_a_margin() -> tuple[np.ndarray, tuple[float, float], tuple[float, float]]:
    """A wall along the top and three obstacle pixels below it; the start is inside the
    wall's grown margin, and the free cell nearest to it is a pocket the search cannot
    leave (a robot pushed against a wall, next to a stray obstacle)."""
    label = np.zeros((48, 64), np.uint8)
    label[:8, :] = OBSTACLE
    for row, col in ((12, 14), (12, 26), (17, 20)):
        label[row, col] = OBSTACLE
    frame = GridFrame(MPP)
    start = tuple(frame.pixel_to_world((10, 20)).tolist())
    goal = tuple(frame.pixel_to_world((40, 50)).tolist())
    return label, start, goal


def test_plan_world_path_leads_a_start_in_a_margin_out_toward_the_goal():
    """A start inside an obstacle's grown margin moves to the nearest free cell from which
    the goal is reached (not to a nearer pocket), and the path begins where the robot
    stands, its first leg crossing no obstacle."""
    from petriflow.agents.planning.astar import astar
    from petriflow.agents.planning.maps import nearest_free, planning_grid, segment_free

    label, start, goal = pushed_into_a_margin()
    frame = GridFrame(MPP)
    grid = planning_grid(label, "red", 0.04 / MPP, 1)
    pocket = nearest_free(grid, (10, 20), 15)
    assert pocket is not None and not astar(grid, pocket, (40, 50)).found   # the nearest one is a trap
    result = plan_world_path(label, frame, "red", goal, start, radius=0.04, snap=0.15)
    assert result["found"] and result["path"][0] == list(start) and result["path"][-1] == list(goal)
    out = tuple(int(v) for v in frame.world_to_cell(result["path"][1]))
    assert out != pocket and not grid[out]
    assert segment_free(label == OBSTACLE, frame, start, result["path"][1])
    cells = frame.world_to_cell(result["path"][1:])
    assert not grid[cells[:, 0], cells[:, 1]].any()


def test_plan_world_path_finds_no_way_out_beyond_the_snap_distance():
    """With no free cell toward the goal within the snap distance, there is no path (a
    measured failure, not an error)."""
    label, start, goal = pushed_into_a_margin()
    result = plan_world_path(label, GridFrame(MPP), "red", goal, start, radius=0.04, snap=0.03)
    assert not result["found"] and result["path"] == [] and result["start"] == list(start)


def test_plan_world_path_reports_no_path():
    """A goal walled off gives found=False and an empty path."""
    label = label_map()
    label[:, 40:43] = OBSTACLE
    result = plan_world_path(label, GridFrame(MPP, cell=2), "red", (0.55, -0.1), radius=0.04)
    assert not result["found"] and result["path"] == []


def test_plan_world_path_needs_the_robot_on_the_map():
    """Without a start, the robot must be on the label map."""
    with pytest.raises(PlanningError, match="'green' is not on the label map"):
        plan_world_path(label_map(), GridFrame(MPP, cell=2), "green", (0.5, -0.1))


def test_fire_plan_transition_with_a_scene_token():
    """planning.astar in a net: the scene token in, the path token out."""
    fired = fire_one(loads_net(PLAN_NET), "plan", tokens={"seen": [scene()]})
    assert fired.outcome == "ok" and fired.time == 0.0
    result = fired.tokens["planned"][0]
    assert result["robot"] == "red" and result["variant"] == "optimal"
    assert result["start"] == [0.08, -0.24] and result["goal"] == [0.55, -0.1]
    assert result["path"][0] == result["start"] and result["path"][-1] == result["goal"]
    assert result["expanded"] > 0 and "ms" not in result


def test_plan_transition_is_deterministic():
    """The same token gives the same result data (no wall-clock time in it by default)."""
    net = loads_net(PLAN_NET)
    assert fire_one(net, "plan", tokens={"seen": [scene()]}).tokens == \
        fire_one(net, "plan", tokens={"seen": [scene()]}).tokens


def test_plan_transition_paper_variant_and_timing():
    """params select the variant; report_ms adds the search time."""
    params = "cell: 2, variant: paper, report_ms: true, goal: [0.55, -0.3]}"
    net = loads_net(PLAN_NET.replace("cell: 2}", params))
    result = fire_one(net, "plan", tokens={"seen": [scene()]}).tokens["planned"][0]
    assert result["variant"] == "paper" and result["goal"] == [0.55, -0.3] and result["ms"] >= 0


def test_plan_transition_reads_a_scene_object():
    """A scene may be an object with attributes (as the vision agent's Scene is)."""

    @dataclass
    class Scene:
        label_map: np.ndarray
        metres_per_pixel: float
        origin: tuple
        poses: dict

    token = Scene(label_map(), MPP, (0.0, 0.0), {"red": [0.08, -0.24, 1.0]})
    net = loads_net(PLAN_NET.replace("cell: 2}", "cell: 2, goal: [0.55, -0.1]}"))
    fired = fire_one(net, "plan", tokens={"seen": [token]})
    assert fired.outcome == "ok" and fired.tokens["planned"][0]["path"][-1] == [0.55, -0.1]


def test_plan_transition_fails_with_a_reason():
    """No path, no scene or no goal: the failed outcome, with the reason."""
    walled = scene()
    walled["label_map"][:, 40:43] = OBSTACLE
    net = loads_net(PLAN_NET)
    fired = fire_one(net, "plan", tokens={"seen": [walled]})
    assert fired.outcome == "failed" and "no path for robot 'red'" in fired.reason
    fired = fire_one(net, "plan", tokens={"seen": [{"goal": [0.1, 0.1]}]})
    assert fired.outcome == "failed" and "no scene" in fired.reason
    fired = fire_one(net, "plan", tokens={"seen": [{**scene(), "goal": None}]})
    assert fired.outcome == "failed" and "no goal for robot 'red'" in fired.reason


def test_unknown_variant_is_refused_when_the_net_loads():
    """A misspelt variant fails at binding time, naming the transition."""
    net = loads_net(PLAN_NET.replace("cell: 2}", "cell: 2, variant: fastest}"))
    with pytest.raises(PetriflowError, match="'plan'.*variant"):
        bind(net, Registry())


@pytest.mark.parametrize("pose, decision, route", [
    ([0.3, 0.005], "on_track", "keep_going"),
    ([0.3, 0.03], "reinsert", "rejoin"),
    ([0.3, 0.2], "replan", "replan"),
])
def test_track_decision_routes_through_guards(pose, decision, route):
    """planning.track decides; exactly the matching guarded transition can take the token."""
    net = loads_net(TRACK_NET)
    token = {"path": [[x / 100, 0.0] for x in range(101)], "pose": pose}
    fired = fire_one(net, "check", tokens={"walked": [token]})
    assert fired.outcome == "ok"
    checked = fired.tokens["checked"][0]
    assert checked["decision"] == decision
    if decision == "reinsert":
        assert checked["point"] == [0.32, 0.0]  # farthest path point within 2 steps (0.04 m)
    for transition in ("keep_going", "rejoin", "replan"):
        if transition == route:
            assert fire_one(net, transition, tokens={"checked": [checked]}).outcome == "ok"
        else:
            with pytest.raises(PetriflowError):
                fire_one(net, transition, tokens={"checked": [checked]})


def test_track_reads_the_pose_from_the_world():
    """Without a pose in the tokens, planning.track asks the world where the robot is."""
    net = loads_net(TRACK_NET)
    world = StubWorld(positions={"red": (0.5, 0.2)})
    fired = fire_one(net, "check", tokens={"walked": [{"path": [[0, 0], [1, 0]]}]}, world=world)
    assert fired.tokens["checked"][0]["decision"] == "replan"
    fired = fire_one(net, "check", tokens={"walked": [{"path": [[0, 0], [1, 0]]}]})
    assert fired.outcome == "failed" and "no pose for robot 'red'" in fired.reason


def test_scene_frame_defaults_to_the_image_centre():
    """Without an origin, the image centre is the world origin; a GridFrame is taken as is."""
    frame = scene_frame({"metres_per_pixel": 0.01}, (5, 7), 1)
    assert frame.pixel_to_world((2, 3)).tolist() == pytest.approx([0.0, 0.0])
    given = GridFrame(0.02, (1.0, 1.0))
    assert scene_frame({"frame": given}, (5, 7), 3) == given.with_cell(3)
    with pytest.raises(PlanningError, match="no metres_per_pixel"):
        scene_frame({}, (5, 7), 1)
