"""The pipeline on rendered frames: robots, obstacles, label map, scene token."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from petriflow.runtime.trace import summarize
from petriflow.vision.markers import DEFAULT_GEOMETRY, ROBOT_COLOURS
from petriflow.vision.pipeline import STAGES, VisionConfig, process

MARKER_Z = DEFAULT_GEOMETRY.marker_z


def test_finds_all_robots_and_obstacles(shots640, shots320):
    for shot in (*shots640, *shots320):
        scene = process(shot.frame, shot.camera)
        assert scene.missing == ()
        assert set(scene.robots) == set(ROBOT_COLOURS)
        assert len(scene.obstacle_boxes) == shot.obstacles


def test_label_map_values(shots640):
    """0 floor, 1 obstacles, 2..5 robots as squares of side L at their poses."""
    shot = shots640[0]
    scene = process(shot.frame, shot.camera)
    labels = scene.labels
    assert labels.dtype == np.uint8 and labels.shape == (480, 640)
    assert set(np.unique(labels).tolist()) == {0, 1, 2, 3, 4, 5}
    assert ((labels == 1) == (scene.obstacles > 0)).mean() > 0.99
    side_px = DEFAULT_GEOMETRY.side / scene.metres_per_pixel
    for i, colour in enumerate(ROBOT_COLOURS):
        x, y, _ = shot.truth[colour]
        col, row = shot.camera.project(x, y, MARKER_Z)
        assert labels[int(round(row - 1)), int(round(col))] == 2 + i
        assert (labels == 2 + i).sum() == pytest.approx(side_px ** 2, rel=0.1)
    assert (labels[0, :] == 0).all()                         # the floor at the image's edge


def test_segmented_keeps_what_was_seen(shots640):
    scene = process(shots640[1].frame, shots640[1].camera)
    assert set(np.unique(scene.segmented).tolist()) == {0, 1, 2, 3, 4, 5}


def test_grid_frame_for_the_planner(shots640):
    """metres_per_pixel and origin map a robot's pixel to its world position."""
    shot = shots640[0]
    scene = process(shot.frame, shot.camera)
    for colour, pose in scene.robots.items():
        x = scene.origin[0] + pose.pixel[0] * scene.metres_per_pixel
        y = scene.origin[1] - pose.pixel[1] * scene.metres_per_pixel
        assert math.hypot(x - pose.position[0], y - pose.position[1]) < 1e-6
    assert scene.label_map is scene.labels
    assert set(scene.poses) == set(ROBOT_COLOURS)


def test_timings_cover_every_stage(shots320):
    scene = process(shots320[0].frame, shots320[0].camera)
    assert list(scene.timings) == [*STAGES, "total"]
    assert all(value >= 0 for value in scene.timings.values())


def test_token_is_json_and_has_no_images_or_timings(shots320):
    shot = shots320[0]
    scene = process(shot.frame, shot.camera)
    token = scene.to_token()
    text = json.dumps(token)
    assert "timings" not in text and len(text) < 2000
    assert set(token["robots"]) == set(ROBOT_COLOURS)
    assert set(token["robots"]["red"]) == {"x", "y", "heading", "u", "v", "heading_px"}
    assert summarize(scene) == token                     # what a trace records
    assert process(shot.frame, shot.camera).to_token() == token   # deterministic


def test_explicit_hsv_path_gives_the_same_scene(shots320):
    shot = shots320[1]
    fast = process(shot.frame, shot.camera)
    explicit = process(shot.frame, shot.camera, VisionConfig(use_table=False))
    assert fast.to_token() == explicit.to_token()
    assert (fast.labels == explicit.labels).all()


def test_without_mode_filter_robots_are_still_found(shots320):
    shot = shots320[2]
    scene = process(shot.frame, shot.camera, VisionConfig(mode_filter=False))
    assert scene.missing == ()


def test_loose_pixels_do_not_become_obstacles(shots640):
    """Salt noise of black pixels on the floor: the mode filter removes it, so the
    obstacle count stays right; without the filter it would not."""
    shot = shots640[2]
    frame = shot.frame.copy()
    rng = np.random.default_rng(7)
    rows, cols = rng.integers(0, 480, 400), rng.integers(0, 640, 400)
    frame[rows, cols] = (4, 4, 4)
    scene = process(frame, shot.camera, VisionConfig(min_obstacle_area=0))
    assert len(scene.obstacle_boxes) == shot.obstacles
    raw = process(frame, shot.camera, VisionConfig(mode_filter=False, min_obstacle_area=0))
    assert len(raw.obstacle_boxes) > shot.obstacles


def test_a_robot_without_discs_is_missing(shots320):
    """Paint a robot's discs over with its colour: it is reported missing."""
    shot = shots320[0]
    frame = shot.frame.copy()
    x, y, _ = shot.truth["blue"]
    col, row = (int(v) for v in shot.camera.project(x, y, MARKER_Z))
    patch = frame[row - 8:row + 8, col - 8:col + 8]
    blue = np.array([23, 47, 215], np.uint8)
    patch[(patch.astype(int).sum(axis=2) < 30) | (patch.min(axis=2) > 120)] = blue
    scene = process(frame, shot.camera)
    assert "blue" in scene.missing and "blue" not in scene.robots
    assert len(scene.robots) == 3


def test_bad_inputs_are_rejected(shots320):
    with pytest.raises(ValueError, match="H x W x 3 uint8"):
        process(np.zeros((10, 10), np.uint8))
    with pytest.raises(ValueError, match="camera renders"):
        process(np.zeros((48, 64, 3), np.uint8), shots320[0].camera)


def test_empty_floor_gives_an_empty_scene():
    scene = process(np.full((48, 64, 3), 239, np.uint8))
    assert scene.robots == {} and scene.missing == ROBOT_COLOURS
    assert scene.obstacle_boxes == [] and not scene.labels.any()
