"""Segmentation: HSV thresholds on rendered frames, the mode filter, contours, label maps."""

from __future__ import annotations

import numpy as np
import pytest

from petriflow.vision.markers import ROBOT_COLOURS
from petriflow.vision.segment import (
    DEFAULT_THRESHOLDS,
    FLOOR,
    OBSTACLE,
    colour_mask,
    colour_table,
    find_blobs,
    grey_map,
    label_pixels,
    mode_filter,
    obstacle_mask,
    robot_label,
    to_hsv,
)


def brute_mode(labels: np.ndarray) -> np.ndarray:
    """3 x 3 mode by counting every label at every pixel (border replicated; ties:
    the centre's label, else the lowest)."""
    padded = np.pad(labels, 1, mode="edge")
    height, width = labels.shape
    windows = np.stack([padded[r:r + height, c:c + width] for r in range(3) for c in range(3)])
    n = int(labels.max()) + 1
    counts = np.stack([(windows == k).sum(axis=0) for k in range(n)]) * 2
    counts += np.stack([labels == k for k in range(n)])
    return counts.argmax(axis=0).astype(np.uint8)


# -- thresholds, measured on rendered frames -------------------------------------------

def test_robot_colours_fall_inside_their_ranges_only(shots640):
    """Every robot colour seen on a rendered frame is claimed by its own range and by
    no other one (the ranges are disjoint on what TinyRenderer draws)."""
    for shot in shots640:
        hsv = to_hsv(shot.frame)
        masks = {name: colour_mask(hsv, ranges) > 0 for name, ranges in DEFAULT_THRESHOLDS.items()}
        claimed = sum(masks[name].astype(int) for name in (*ROBOT_COLOURS, "black"))
        assert claimed.max() == 1
        for colour in ROBOT_COLOURS:
            assert masks[colour].sum() > 300, colour


def test_floor_is_white_and_unclaimed(shots640):
    """The floor renders as one white (S 0, V 239): label 0, inside the white range."""
    frame = shots640[0].frame
    corner = frame[:5, :5].reshape(-1, 3)
    assert (corner == corner[0]).all()
    hsv = to_hsv(frame[:5, :5])
    assert (colour_mask(hsv, DEFAULT_THRESHOLDS["white"]) == 255).all()
    assert (label_pixels(hsv) == FLOOR).all()


def test_labels_have_the_four_robots_and_black(shots640):
    """Labels 0..5 all occur on a rendered scene: floor, black, the four robots."""
    labels = label_pixels(to_hsv(shots640[0].frame))
    assert set(np.unique(labels).tolist()) == {0, 1, 2, 3, 4, 5}
    assert [robot_label(c) for c in ROBOT_COLOURS] == [2, 3, 4, 5]


def test_colour_table_equals_the_explicit_hsv_path(shots640, shots320):
    """The precomputed RGB -> label table gives the explicit HSV path's labels exactly,
    on rendered frames and on random colours."""
    table = colour_table()
    for shot in (*shots640[:2], *shots320[:2]):
        assert (table(shot.frame) == label_pixels(to_hsv(shot.frame))).all()
    rng = np.random.default_rng(0)
    colours = rng.integers(0, 256, size=(200, 300, 3), dtype=np.uint8)
    assert (table(colours) == label_pixels(to_hsv(colours))).all()


def test_colour_table_follows_a_custom_table():
    """A different thresholds table builds a different table (cached per table)."""
    custom = dict(DEFAULT_THRESHOLDS)
    custom["red"] = (((170, 120, 70), (179, 255, 255)),)   # drop the H 0..10 half of red
    frame = np.array([[[215, 23, 23]]], np.uint8)              # H 0
    assert colour_table()(frame)[0, 0] == 2
    assert colour_table(custom)(frame)[0, 0] == 0
    assert colour_table(custom) is colour_table(dict(custom))


# -- mode filter ---------------------------------------------------------------------

def test_mode_filter_removes_isolated_pixels():
    """Loose pixels of any label vanish, on the floor and inside a blob."""
    labels = np.zeros((40, 50), np.uint8)
    labels[10:30, 10:30] = 3
    rng = np.random.default_rng(1)
    rows, cols = rng.integers(0, 40, 30), rng.integers(0, 50, 30)
    noisy = labels.copy()
    for r, c in zip(rows, cols):
        if 1 <= r < 39 and 1 <= c < 49 and not (8 <= r < 32 and 8 <= c < 32):
            noisy[r, c] = rng.integers(1, 6)
    noisy[20, 20] = 1                      # a loose black pixel inside the blob
    noisy[15, 25] = 0                      # a loose floor pixel inside the blob
    filtered = mode_filter(noisy)
    assert (filtered[labels == 0] == 0).all()
    assert filtered[20, 20] == 3 and filtered[15, 25] == 3


def test_mode_filter_keeps_blobs():
    """A blob keeps everything but the tips of its corners; a disc of radius 3 survives
    with its centre where it was."""
    labels = np.zeros((30, 30), np.uint8)
    labels[5:15, 5:15] = 2
    yy, xx = np.mgrid[:30, :30]
    labels[(yy - 22) ** 2 + (xx - 22) ** 2 <= 9] = 1
    filtered = mode_filter(labels)
    assert (filtered[6:14, 6:14] == 2).all()
    assert (filtered == 2).sum() == 100 - 4                # the four corner tips
    rows, cols = np.nonzero(filtered == 1)
    assert len(rows) >= 0.7 * (labels == 1).sum()
    assert (rows.mean(), cols.mean()) == (22.0, 22.0)
    assert set(np.unique(filtered).tolist()) == {0, 1, 2}


@pytest.mark.parametrize("seed", range(4))
def test_mode_filter_is_the_exact_mode(seed):
    """On random label images (many mixed windows and ties) the fast filter equals a
    brute-force count of every label."""
    rng = np.random.default_rng(seed)
    labels = rng.integers(0, 6, size=(37, 53)).astype(np.uint8)
    labels[rng.random(labels.shape) < 0.4] = 0
    assert (mode_filter(labels) == brute_mode(labels)).all()


def test_mode_filter_on_a_rendered_frame_equals_brute_force(shots320):
    labels = label_pixels(to_hsv(shots320[0].frame))
    assert (mode_filter(labels) == brute_mode(labels)).all()


def test_mode_filter_rejects_non_label_images():
    with pytest.raises(ValueError):
        mode_filter(np.zeros((4, 4), np.int32))


# -- contours, obstacles, label map -----------------------------------------------------

def test_each_robot_blob_has_its_two_discs_as_holes(shots640):
    labels = mode_filter(label_pixels(to_hsv(shots640[0].frame)))
    for colour in ROBOT_COLOURS:
        blobs = find_blobs(labels, robot_label(colour), min_area=150)
        assert len(blobs) == 1, colour
        assert len(blobs[0].holes) == 2, colour


def test_obstacle_mask_excludes_the_black_discs(shots640):
    """Black discs are inside robots, so they are not obstacles; the obstacles are."""
    for shot in shots640[:2]:
        labels = mode_filter(label_pixels(to_hsv(shot.frame)))
        robots = [b for c in ROBOT_COLOURS for b in find_blobs(labels, robot_label(c), 150)]
        mask = obstacle_mask(labels, robots)
        for colour, (x, y, _) in shot.truth.items():
            col, row = shot.camera.project(x, y, 0.104)
            assert mask[int(row) - 12:int(row) + 12, int(col) - 12:int(col) + 12].max() == 0, colour
        assert ((mask > 0) == (labels == OBSTACLE)).sum() > 0.99 * labels.size


def test_grey_map_values():
    obstacles = np.zeros((10, 10), np.uint8)
    obstacles[0, :] = 255
    grey = grey_map((10, 10), obstacles, {5: [[4, 4], [7, 4], [7, 7], [4, 7]]})
    assert grey.dtype == np.uint8
    assert set(np.unique(grey).tolist()) == {0, 1, 5}
    assert (grey[0] == 1).all() and (grey[4:8, 4:8] == 5).all() and grey[5, 2] == 0
