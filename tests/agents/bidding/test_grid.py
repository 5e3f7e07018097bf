"""The global occupancy grid, its frame, and the map accuracy of eq. 10."""

from __future__ import annotations

import doctest
import importlib

import numpy as np
import pytest

from petriflow.agents.bidding.errors import BiddingError
from petriflow.agents.bidding.grid import Accuracy, GlobalMap, Grid, accuracy, dilate, draw_map


def test_cell_of_is_vectorised_and_drops_points_outside():
    frame = Grid(origin=(-1.0, 2.0), resolution=0.5, shape=(4, 6))
    points = np.array([[-1.0, 2.0], [1.99, 3.99], [-1.01, 2.5], [2.0, 2.5], [0.0, 4.0], [np.nan, 3.0],
                       [0.2, 2.7]])
    rows, cols = frame.cell_of(points)
    assert rows.tolist() == [0, 3, 1] and cols.tolist() == [0, 5, 2]
    assert rows.dtype.kind == "i"
    empty = frame.cell_of(np.zeros((0, 2)))
    assert empty[0].size == 0 and empty[1].size == 0
    with pytest.raises(BiddingError):
        frame.cell_of([1.0, 2.0, 3.0])


def test_centre_is_the_inverse_of_cell_of():
    frame = Grid((-16.0, -11.0), 0.1, (220, 320))
    assert frame.centre(0, 0) == pytest.approx((-15.95, -10.95))
    rows, cols = np.arange(220), np.arange(220) % 320
    xs, ys = frame.centre(rows, cols)
    back = frame.cell_of(np.column_stack((xs, ys)))
    assert back[0].tolist() == rows.tolist() and back[1].tolist() == cols.tolist()


def test_grid_frames_are_checked_and_span_rectangles():
    assert Grid.spanning(-16, -11, 16, 11, 0.1).shape == (220, 320)
    assert Grid.spanning(0, 0, 1.05, 1, 0.5).shape == (2, 3)
    assert Grid((0, 0), 1.0, (2, 3)).extent == (0.0, 3.0, 0.0, 2.0)
    for bad in (dict(origin=(0, 0), resolution=0.0, shape=(2, 2)),
                dict(origin=(0, 0), resolution=1.0, shape=(0, 2)),
                dict(origin=(0, 0), resolution=1.0, shape=(2, 2), occupied=np.zeros((3, 3), bool))):
        with pytest.raises(BiddingError):
            Grid(**bad)


def test_add_counts_new_cells_and_remembers_the_first_robot():
    team = GlobalMap(Grid((0.0, 0.0), 1.0, (4, 4)))
    assert team.add(0, [(0.5, 0.5), (0.6, 0.7), (1.5, 0.5)]) == 2          # two points in one cell
    assert team.add(2, [(1.5, 0.5), (3.5, 3.5), (9.0, 9.0)]) == 1          # one new, one known, one outside
    assert team.add(1, np.zeros((0, 2))) == 0
    assert team.count() == 3 and team.count(0) == 2 and team.count(2) == 1 and team.count(1) == 0
    assert team.owner[0, :2].tolist() == [0, 0] and team.owner[3, 3] == 2 and team.owner[2, 2] == -1
    assert team.occupied.sum() == 3
    with pytest.raises(ValueError):
        team.occupied[0, 0] = False                                        # a read-only view
    for bad in (-1, 1.0, True, "1"):
        with pytest.raises(BiddingError):
            team.add(bad, [(0.5, 0.5)])


def test_add_is_fast_for_a_run_of_scans():
    team = GlobalMap(Grid((-16.0, -11.0), 0.1, (220, 320)))
    rng = np.random.default_rng(0)
    scans = rng.uniform((-16, -11), (16, 11), size=(2000, 360, 2))
    new = sum(team.add(k % 5, points) for k, points in enumerate(scans))
    assert new == team.count() and 0 < new <= 220 * 320


def test_accuracy_of_ten_real_cells_and_one_fictitious_is_90_percent():
    truth = np.zeros((6, 14), bool)
    truth[1, 1:11] = True
    seen = truth.copy()
    seen[4, 13] = True                       # a teammate three rows away from any wall
    result = accuracy(seen, truth)
    assert result == Accuracy(sigma=10, xi=1, percent=90.0, coverage=1.0)


def test_the_tolerance_decides_what_is_real():
    truth = np.zeros((9, 9), bool)
    truth[4, 4] = True
    one_off, two_off = np.zeros_like(truth), np.zeros_like(truth)
    one_off[5, 5] = True                     # diagonal neighbour: Chebyshev distance 1
    two_off[6, 4] = True
    assert (accuracy(one_off, truth, 1).sigma, accuracy(one_off, truth, 1).xi) == (1, 0)
    assert (accuracy(one_off, truth, 0).sigma, accuracy(one_off, truth, 0).xi) == (0, 1)
    assert (accuracy(two_off, truth, 1).sigma, accuracy(two_off, truth, 1).xi) == (0, 1)
    assert (accuracy(two_off, truth, 2).sigma, accuracy(two_off, truth, 2).xi) == (1, 0)
    assert accuracy(one_off, truth, 1).coverage == 1.0 and accuracy(one_off, truth, 0).coverage == 0.0
    with pytest.raises(BiddingError):
        accuracy(one_off, truth, -1)


def test_accuracy_edge_cases_and_coverage():
    truth = np.zeros((7, 20), bool)
    truth[3, :] = True
    nothing = np.zeros_like(truth)
    assert accuracy(nothing, truth) == Accuracy(0, 0, 100.0, 0.0)             # sigma = xi = 0: 100 %
    ghosts = nothing.copy()
    ghosts[0, :3] = True
    assert accuracy(ghosts, truth) == Accuracy(0, 3, 0.0, 0.0)                # sigma = 0, xi > 0: 0 %
    ghosts[3, 0] = True
    assert accuracy(ghosts, truth).percent == 0.0                             # 1 - 3/1 < 0: clipped
    assert accuracy(ghosts, nothing).coverage == 1.0                          # nothing to cover
    half = nothing.copy()
    half[3, :10] = True
    assert accuracy(half, truth).coverage == pytest.approx(11 / 20)           # one more within tolerance
    assert accuracy(half, truth, 0).coverage == pytest.approx(10 / 20)
    with pytest.raises(BiddingError):
        accuracy(half, truth[:, :5])


def test_dilate_is_a_chebyshev_max_filter():
    rng = np.random.default_rng(1)
    mask = rng.random((23, 17)) < 0.05
    for radius in (0, 1, 2, 30):
        expected = np.zeros_like(mask)
        for r, c in zip(*np.nonzero(mask)):
            expected[max(0, r - radius):r + radius + 1, max(0, c - radius):c + radius + 1] = True
        assert np.array_equal(dilate(mask, radius), expected)
    assert dilate(mask, 1) is not mask and not np.shares_memory(dilate(mask, 0), mask)


def test_draw_map_writes_a_png(tmp_path):
    from petriflow.agents.bidding.office import generated_office

    office = generated_office(2, 2)
    truth = office.truth(0.2)
    team = GlobalMap(truth)
    team.add(0, [(-7.9, 0.0), (-7.9, 1.0)])
    team.add(1, [(7.9, 0.0)])
    for kwargs in ({"office": office, "title": "two robots"}, {}):
        path = tmp_path / f"map{len(kwargs)}.png"
        draw_map(team, path, **kwargs)
        assert path.read_bytes()[:4] == b"\x89PNG"


@pytest.mark.parametrize("name", ["grid", "laser", "office"])
def test_docstring_examples_run(name):
    module = importlib.import_module(f"petriflow.agents.bidding.{name}")
    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    assert result.attempted > 0 and result.failed == 0
