"""Support polygon and stability margin."""

from __future__ import annotations

import pytest
from petriflow.agents.legged.stability import (
    closest_point_inside,
    convex_hull,
    inner_polygon,
    stability_margin,
)

SQUARE = [(0, 0), (1, 0), (1, 1), (0, 1)]


def test_convex_hull_is_counter_clockwise_without_inner_points():
    """Inner and collinear points drop out; the hull turns left."""
    hull = convex_hull([(0, 0), (1, 0), (0.5, 0.5), (1, 1), (0, 1), (0.5, 0)])
    assert hull == [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]


@pytest.mark.parametrize("point, margin", [((0.5, 0.5), 0.5), ((0.9, 0.5), 0.1), ((1.2, 0.5), -0.2),
                                           ((1.3, 1.4), -0.5)])
def test_margin_is_the_signed_distance_to_the_edge(point, margin):
    """Positive inside, negative outside, distance to the nearest edge or corner."""
    assert stability_margin(point, SQUARE) == pytest.approx(margin)


def test_two_contacts_have_no_inside():
    """Standing on two feet: the margin is never positive."""
    assert stability_margin((0.5, 0.0), [(0, 0), (1, 0)]) == 0.0
    assert stability_margin((0.5, 0.1), [(0, 0), (1, 0)]) == pytest.approx(-0.1)


def test_inner_polygon_and_closest_point():
    """Every point of the inner polygon keeps the margin; the closest point inside is
    on the boundary."""
    inner = inner_polygon([(0, 0), (2, 0), (0, 2)], 0.2)
    assert inner and all(stability_margin(p, [(0, 0), (2, 0), (0, 2)]) >= 0.2 - 1e-9 for p in inner)
    assert inner_polygon([(0, 0), (1, 0), (0, 1)], 1.0) == []
    assert closest_point_inside((0.5, -1.0), SQUARE) == (0.5, 0.0)
    assert closest_point_inside((0.5, 0.5), SQUARE) == (0.5, 0.5)
