"""From the grey label map to a robot's planning grid (seed 003 §4): binary map,
C-space dilation, cell decomposition, and pixel ↔ cell ↔ world conversions."""

from __future__ import annotations

import numpy as np
import pytest

from petriflow.agents.planning.errors import PlanningError
from petriflow.agents.planning.maps import (
    OBSTACLE,
    ROBOT_LABELS,
    GridFrame,
    binary_map,
    cell_grid,
    configuration_space,
    disc_kernel,
    draw_disc,
    free_cells_near,
    free_region,
    nearest_free,
    planning_grid,
    robot_centre,
    robot_label,
    segment_free,
)
from scipy.ndimage import distance_transform_edt


def test_binary_map_frees_the_robot_and_blocks_the_others():
    """Obstacles and the other robots are occupied; the planning robot's own pixels are free."""
    label = np.array([[0, 1, 2, 3, 4, 5]], np.uint8)
    assert binary_map(label, "red").tolist() == [[False, True, False, True, True, True]]
    assert binary_map(label, "green").tolist() == [[False, True, True, True, True, False]]
    assert binary_map(label, None).tolist() == [[False, True, True, True, True, True]]


def test_robot_labels_by_colour_or_number():
    """Robots are named by colour (any case) or label 2..5; others are a PlanningError."""
    assert [robot_label(c) for c in ("red", "Blue", "yellow", "green")] == [2, 3, 4, 5]
    assert robot_label(np.uint8(5)) == 5
    for bad in ("purple", 1, 6, True, None):
        with pytest.raises(PlanningError):
            robot_label(bad)


@pytest.mark.parametrize("radius", [0.0, 0.7, 1.0, 2.5, 4.0, 6.3])
@pytest.mark.parametrize("border", [False, True])
def test_configuration_space_is_the_set_within_radius_of_an_obstacle(radius, border):
    """A pixel is occupied in C-space iff its centre is within the radius of an
    obstacle pixel's centre (or of outside the map, with border)."""
    rng = np.random.default_rng(int(radius * 10) + border)
    occupied = rng.random((30, 40)) < 0.02
    pad = int(np.ceil(radius)) + 2
    padded = np.pad(occupied, pad, constant_values=border)
    within = distance_transform_edt(~padded) <= radius + 1e-9
    expected = within[pad:-pad, pad:-pad]
    assert np.array_equal(configuration_space(occupied, radius, border=border), expected)


def test_disc_kernel_is_round_and_symmetric():
    """The structuring element is the disc of pixel centres within the radius."""
    kernel = disc_kernel(3.0)
    assert kernel.shape == (7, 7) and kernel[3, 0] == 1 and kernel[0, 0] == 0
    assert np.array_equal(kernel, kernel.T) and np.array_equal(kernel, kernel[::-1])
    with pytest.raises(PlanningError):
        disc_kernel(-1)


@pytest.mark.parametrize("cell", [1, 2, 3, 5])
def test_cell_is_occupied_if_any_of_its_pixels_is(cell):
    """Cell decomposition matches the definition, including partial edge cells."""
    rng = np.random.default_rng(cell)
    occupied = rng.random((23, 31)) < 0.03
    cells = cell_grid(occupied, cell)
    assert cells.shape == (-(-23 // cell), -(-31 // cell))
    for i in range(cells.shape[0]):
        for j in range(cells.shape[1]):
            assert cells[i, j] == occupied[i * cell:(i + 1) * cell, j * cell:(j + 1) * cell].any()


def test_planning_grid_of_a_640x480_map_is_320x240():
    """The paper's resolution: 640 × 480 pixels in cells of 2 × 2 → 320 × 240."""
    label = np.zeros((480, 640), np.uint8)
    label[100:140, 200:260] = OBSTACLE
    label[300:320, 300:320] = ROBOT_LABELS["blue"]
    grid = planning_grid(label, "red", radius_px=10, cell=2)
    assert grid.shape == (240, 320)
    assert grid[60, 115] and grid[155, 155] and not grid[120, 160]
    assert grid[0, :].all() and grid[:, 0].all()  # the border is out of reach for a disc of 10 px


def test_robot_centre_is_its_pixels_centroid():
    """A robot's position on the map is the centroid of its pixels; absent: None."""
    label = draw_disc(np.zeros((50, 50), np.uint8), (20, 30), 5, ROBOT_LABELS["yellow"])
    assert robot_centre(label, "yellow") == pytest.approx((20.0, 30.0))
    assert robot_centre(label, "red") is None


def test_nearest_free_cell():
    """The nearest free cell within the distance, or None; a free cell is itself."""
    grid = np.ones((9, 9), bool)
    grid[2, 7] = grid[8, 8] = False
    assert nearest_free(grid, (2, 7), 0) == (2, 7)
    assert nearest_free(grid, (4, 6), 3) == (2, 7)
    assert nearest_free(grid, (4, 6), 2) is None
    assert nearest_free(grid, (10, 10), 3) == (8, 8)  # from off the map too


def test_nearest_free_cell_within_a_region():
    """With a region, the nearest free cell inside it: a nearer free cell outside is passed over."""
    grid = np.ones((9, 9), bool)
    grid[2, 7] = grid[8, 8] = False
    region = np.zeros((9, 9), bool)
    region[8, 8] = True
    assert nearest_free(grid, (4, 6), 5, region=region) == (8, 8)
    assert nearest_free(grid, (4, 6), 3, region=region) is None
    assert free_cells_near(grid, (4, 6), 5).tolist() == [[2, 7], [8, 8]]


def test_free_region_follows_the_planners_moves():
    """A free region is what the search can reach: without corner cutting a diagonal gap
    between two occupied cells does not join two regions; with it, it does. On random
    grids the region is exactly the cells A* finds a path to."""
    from petriflow.agents.planning.astar import astar

    grid = np.ones((4, 4), bool)
    grid[0, 0] = grid[1, 1] = grid[2, 1] = grid[3, 3] = False
    assert free_region(grid, (1, 1)).sum() == 2           # (2, 1) straight; (0, 0) only diagonal
    assert free_region(grid, (1, 1), cut_corners=True)[0, 0]
    assert not free_region(grid, (1, 1), cut_corners=True)[3, 3]
    assert not free_region(grid, (0, 1)).any()            # an occupied cell has no region
    rng = np.random.default_rng(3)
    for _ in range(20):
        grid = rng.random((9, 11)) < 0.45
        grid[4, 5] = False
        for cut in (False, True):
            region = free_region(grid, (4, 5), cut_corners=cut)
            for row, col in zip(*np.nonzero(~grid)):
                assert region[row, col] == astar(grid, (4, 5), (row, col), cut_corners=cut).found


def test_frame_round_trips_pixels_cells_and_world():
    """World → pixel → world is the identity; a cell's centre lies in the cell."""
    frame = GridFrame(0.005, origin=(-1.6, 1.2), cell=2)
    rng = np.random.default_rng(0)
    points = rng.uniform((-1.6, -1.2), (1.6, 1.2), size=(50, 2))
    assert np.allclose(frame.pixel_to_world(frame.world_to_pixel(points)), points)
    cells = frame.world_to_cell(points)
    assert np.array_equal(frame.world_to_cell(frame.cell_to_world(cells)), cells)
    assert np.abs(frame.cell_to_world(cells) - points).max() <= frame.metres_per_cell / 2 * np.sqrt(2) + 1e-12


def test_frame_axes():
    """Columns run toward +x; rows toward −y (or +y with flip_y=False)."""
    down = GridFrame(0.1, origin=(1.0, 2.0))
    assert down.pixel_to_world((3, 4)).tolist() == pytest.approx([1.4, 1.7])
    up = GridFrame(0.1, origin=(1.0, 2.0), flip_y=False)
    assert up.pixel_to_world((3, 4)).tolist() == pytest.approx([1.4, 2.3])
    assert GridFrame(0.1, cell=4).cell_to_pixel((1, 2)).tolist() == [5.5, 9.5]
    with pytest.raises(PlanningError):
        GridFrame(0.0)
    with pytest.raises(PlanningError):
        GridFrame(0.1, cell=0)


def test_segment_free_sees_walls_and_the_map_edge():
    """A straight move is free only if every cell it crosses is free and on the map."""
    grid = np.zeros((10, 10), bool)
    grid[:, 5] = True
    frame = GridFrame(0.1, origin=(0.0, 0.0), flip_y=False)
    assert segment_free(grid, frame, (0.0, 0.0), (0.4, 0.9))
    assert not segment_free(grid, frame, (0.0, 0.0), (0.9, 0.0))
    assert not segment_free(grid, frame, (0.0, 0.0), (-0.5, 0.0))
