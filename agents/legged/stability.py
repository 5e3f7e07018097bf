"""Static stability: the support polygon and how far inside it the centre of gravity is.

A walking robot stands still-stable while the vertical projection of its centre of
gravity lies inside the *support polygon*, the convex hull of its ground contacts
(seed 003, §3.5: "it is necessary for the center of gravity to be inside the area
formed by black circles"). The *stability margin* is the distance from that point to
the polygon's boundary, positive inside, negative outside.

Examples:
    >>> square = [(0, 0), (1, 0), (1, 1), (0, 1)]
    >>> stability_margin((0.5, 0.25), square)
    0.25
    >>> stability_margin((1.5, 0.5), square)
    -0.5
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence

__all__ = ["closest_point_inside", "convex_hull", "inner_polygon", "stability_margin"]

Point = tuple[float, float]


def _cross(o: Point, a: Point, b: Point) -> float:
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])


def convex_hull(points: Iterable[Sequence[float]]) -> list[Point]:
    """The convex hull of 2-D points, counter-clockwise, without collinear points.

    Examples:
        >>> convex_hull([(0, 0), (2, 0), (1.5, 1.5), (1, 0.2), (0, 2)])
        [(0.0, 0.0), (2.0, 0.0), (1.5, 1.5), (0.0, 2.0)]
    """
    unique = sorted({(float(p[0]), float(p[1])) for p in points})
    if len(unique) <= 2:
        return unique
    lower: list[Point] = []
    for p in unique:
        while len(lower) >= 2 and _cross(lower[-2], lower[-1], p) <= 1e-15:
            lower.pop()
        lower.append(p)
    upper: list[Point] = []
    for p in reversed(unique):
        while len(upper) >= 2 and _cross(upper[-2], upper[-1], p) <= 1e-15:
            upper.pop()
        upper.append(p)
    return lower[:-1] + upper[:-1]


def _segment_distance(p: Point, a: Point, b: Point) -> float:
    ax, ay = b[0] - a[0], b[1] - a[1]
    length2 = ax * ax + ay * ay
    t = 0.0 if length2 == 0 else max(0.0, min(1.0, ((p[0] - a[0]) * ax + (p[1] - a[1]) * ay) / length2))
    return math.hypot(p[0] - a[0] - t * ax, p[1] - a[1] - t * ay)


def stability_margin(point: Sequence[float], contacts: Iterable[Sequence[float]]) -> float:
    """Signed distance from ``point`` (x, y) to the boundary of the support polygon of
    ``contacts``: positive inside, negative outside; with fewer than three
    non-collinear contacts the polygon has no inside and the margin is ``-distance``
    (``0`` on the contacts' segment).

    Examples:
        >>> round(stability_margin((0.0, 0.0), [(-1, -1), (1, -1), (0, 1)]), 4)
        0.4472
        >>> stability_margin((0.0, 0.5), [(-1, 0), (1, 0)])
        -0.5
    """
    p = (float(point[0]), float(point[1]))
    hull = convex_hull(contacts)
    if not hull:
        raise ValueError("no contacts")
    if len(hull) == 1:
        return -math.hypot(p[0] - hull[0][0], p[1] - hull[0][1])
    if len(hull) == 2:
        return -_segment_distance(p, hull[0], hull[1])
    inside = all(_cross(hull[i], hull[(i + 1) % len(hull)], p) >= 0 for i in range(len(hull)))
    distance = min(_segment_distance(p, hull[i], hull[(i + 1) % len(hull)]) for i in range(len(hull)))
    return round(distance if inside else -distance, 12)


def inner_polygon(contacts: Iterable[Sequence[float]], margin: float) -> list[Point]:
    """The points of the support polygon at least ``margin`` inside its boundary (the
    polygon with every edge moved inwards by ``margin``), counter-clockwise; empty if
    none.

    Examples:
        >>> inner_polygon([(0, 0), (2, 0), (2, 2), (0, 2)], 0.5)
        [(0.5, 0.5), (1.5, 0.5), (1.5, 1.5), (0.5, 1.5)]
    """
    polygon = convex_hull(contacts)
    if len(polygon) < 3:
        return []
    # clip a large square by each inward-shifted edge's half-plane (Sutherland-Hodgman)
    big = 1e3
    region: list[Point] = [(-big, -big), (big, -big), (big, big), (-big, big)]
    for i in range(len(polygon)):
        a, b = polygon[i], polygon[(i + 1) % len(polygon)]
        ex, ey = b[0] - a[0], b[1] - a[1]
        length = math.hypot(ex, ey)
        nx, ny = -ey / length, ex / length           # inward normal of a counter-clockwise edge
        offset = nx * a[0] + ny * a[1] + margin      # keep n . p >= offset

        def side(p: Point, nx: float = nx, ny: float = ny, offset: float = offset) -> float:
            return nx * p[0] + ny * p[1] - offset

        clipped: list[Point] = []
        for j in range(len(region)):
            p, q = region[j], region[(j + 1) % len(region)]
            sp, sq = side(p), side(q)
            if sp >= 0:
                clipped.append(p)
            if (sp >= 0) != (sq >= 0):
                t = sp / (sp - sq)
                clipped.append((p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])))
        region = clipped
        if not region:
            return []
    return [(round(x, 9) + 0.0, round(y, 9) + 0.0) for x, y in convex_hull(region)]


def closest_point_inside(point: Sequence[float], polygon: Sequence[Point]) -> Point:
    """The point of a convex polygon nearest ``point`` (``point`` itself if inside).

    Examples:
        >>> closest_point_inside((3.0, 1.0), [(0, 0), (2, 0), (2, 2), (0, 2)])
        (2.0, 1.0)
    """
    p = (float(point[0]), float(point[1]))
    hull = convex_hull(polygon)
    if len(hull) >= 3 and all(_cross(hull[i], hull[(i + 1) % len(hull)], p) >= 0 for i in range(len(hull))):
        return p
    best, best_distance = hull[0], math.inf
    for i in range(len(hull)):
        a, b = hull[i], hull[(i + 1) % len(hull)]
        ax, ay = b[0] - a[0], b[1] - a[1]
        length2 = ax * ax + ay * ay
        t = 0.0 if length2 == 0 else max(0.0, min(1.0, ((p[0] - a[0]) * ax + (p[1] - a[1]) * ay) / length2))
        candidate = (a[0] + t * ax, a[1] + t * ay)
        distance = math.hypot(p[0] - candidate[0], p[1] - candidate[1])
        if distance < best_distance:
            best, best_distance = candidate, distance
    return best
