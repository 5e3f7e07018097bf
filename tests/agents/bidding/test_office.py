"""The office of seed 004's Fig. 6 and generated offices: layout, free space, worlds."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from petriflow.agents.bidding.errors import BiddingError
from petriflow.agents.bidding.office import Office, Room, draw, from_meta, generated_office, paper_office
from petriflow.worldfile import check_world

TABLE2_ZONES = [(10.5, 8.1), (2, 8.1), (-5, 8.1), (-12.5, 8.1), (13, -8.1), (0.5, -5.5), (-8.1, -5.5), (0, 2)]
TABLE2_STARTS = [(6, -9), (7, -9), (8, -9), (9, -9), (10, -9)]


@pytest.fixture(scope="module")
def office() -> Office:
    return paper_office()


def reachable(free: np.ndarray, row: int, col: int) -> np.ndarray:
    """The free cells 4-connected to (row, col): a flood fill by repeated one-cell growth."""
    reach = np.zeros_like(free)
    reach[row, col] = True
    while True:
        grown = reach.copy()
        grown[1:] |= reach[:-1]
        grown[:-1] |= reach[1:]
        grown[:, 1:] |= reach[:, :-1]
        grown[:, :-1] |= reach[:, 1:]
        grown &= free
        if np.array_equal(grown, reach):
            return reach
        reach = grown


def cell(frame, x: float, y: float) -> tuple[int, int]:
    rows, cols = frame.cell_of([(x, y)])
    return int(rows[0]), int(cols[0])


def test_the_paper_office_has_the_zones_and_starts_of_table_2(office):
    assert office.size == (32.0, 22.0) and office.bounds == (-16.0, -11.0, 16.0, 11.0)
    assert office.zones == tuple((float(x), float(y)) for x, y in TABLE2_ZONES)
    assert [s[:2] for s in office.starts] == [(float(x), float(y)) for x, y in TABLE2_STARTS]
    assert all(s[2] == pytest.approx(math.pi / 2) for s in office.starts)


def test_each_zone_is_in_its_own_room_and_the_eighth_in_the_corridor(office):
    rooms = [office.room_of(*zone) for zone in office.zones]
    assert None not in rooms and len(set(rooms)) == 8
    assert rooms[7] == "corridor"
    assert {r.name for r in office.rooms} == set(rooms)
    assert all(office.room_of(x, y) == rooms[4] for x, y, _ in office.starts)   # robots start in Z5's room
    # the north rooms' centres are near Z1-Z4
    for zone, name in zip(office.zones[:4], rooms[:4]):
        room = next(r for r in office.rooms if r.name == name)
        assert math.dist(room.centre, zone) < 1.0
    assert office.room_of(0.0, 11.5) is None


def test_walls_are_thin_and_inside_the_floor(office):
    assert all(min(w, d) == pytest.approx(0.1) for _, _, w, d in office.walls)
    xmin, ymin, xmax, ymax = office.bounds
    for cx, cy, w, d in office.walls + office.furniture:
        assert xmin - 0.051 <= cx - w / 2 and cx + w / 2 <= xmax + 0.051
        assert ymin - 0.051 <= cy - d / 2 and cy + d / 2 <= ymax + 0.051


def door_gaps(office: Office, room: Room) -> list[tuple[float, float]]:
    """The gaps (from, to) in the wall between a room and the corridor."""
    corridor = next(r for r in office.rooms if r.name == "corridor")
    y = corridor.ymin if room.ymax <= corridor.ymin else corridor.ymax
    pieces = sorted((cx - w / 2, cx + w / 2) for cx, cy, w, d in office.walls if abs(cy - y) < 1e-9 and w > d)
    gaps, end = [], room.xmin
    for a, b in pieces:
        if a > end and a > room.xmin and end < room.xmax:
            gaps.append((max(end, room.xmin), min(a, room.xmax)))
        end = max(end, b)
    return gaps


@pytest.mark.parametrize("build", [paper_office, lambda: generated_office(3, 2, seed=5)])
def test_every_room_has_one_door_into_the_corridor_away_from_its_corners(build):
    office = build()
    for room in office.rooms:
        if room.name == "corridor":
            continue
        gaps = door_gaps(office, room)
        assert len(gaps) == 1, (room, gaps)
        (a, b), = gaps
        assert b - a >= 1.4
        assert a - room.xmin >= 0.5 and room.xmax - b >= 0.5


def test_zones_and_starts_are_free_floor_clear_of_furniture(office):
    free, frame = office.free_grid()
    assert frame.shape == (220, 320) and free.dtype == bool
    for x, y in office.zones + tuple(s[:2] for s in office.starts):
        assert free[cell(frame, x, y)]
        assert office.clearance(x, y) >= 1.0
    # walls and furniture are not free; a door is
    assert not free[cell(frame, 0.0, 4.5)] and not free[cell(frame, 11.0, -5.0)]
    assert free[cell(frame, 9.0, 4.5)]
    assert 0.5 < free.mean() < 0.95


@pytest.mark.parametrize("build", [paper_office, lambda: generated_office(4, 6, seed=3),
                                   lambda: generated_office(2, 3, room=(5.0, 4.0), corridor=2.5, seed=9)])
def test_every_zone_is_reachable_from_every_start(build):
    office = build()
    free, frame = office.free_grid(0.1, 0.3)
    reach = reachable(free, *cell(frame, *office.starts[0][:2]))
    for x, y in office.zones + tuple(s[:2] for s in office.starts):
        assert reach[cell(frame, x, y)], (x, y)


def test_the_world_passes_check_world_and_builds_in_pybullet(office):
    from petriflow.world import World

    description = office.world(5)
    checked = check_world(description)
    assert checked["gravity"] == 0.0 and checked["dt"] == 0.1
    assert len(checked["boxes"]) == len(office.walls) + len(office.furniture)
    assert all(box["size"][2] == 0.5 for box in checked["boxes"])
    assert [r["id"] for r in checked["robots"]] == [f"robot{k}" for k in range(1, 6)]
    assert json.loads(json.dumps(description)) == description
    world = World(description)
    try:
        assert sorted(world.agents) == [f"robot{k}" for k in range(1, 6)]
        for k, (x, y, yaw) in enumerate(office.starts):
            px, py, pyaw = world.pose(f"robot{k + 1}")
            assert (px, py, pyaw) == pytest.approx((x, y, yaw), abs=1e-6)
        assert from_meta(world.meta["office"]) == office
    finally:
        world.close()


def test_world_takes_fewer_robots_but_not_more(office):
    assert office.world(0)["robots"] == []
    assert len(office.world(2, urdf="x.urdf")["robots"]) == 2
    with pytest.raises(BiddingError, match="5 robot starts"):
        office.world(6)
    with pytest.raises(BiddingError):
        office.world(-1)


@pytest.mark.parametrize("build", [paper_office, lambda: generated_office(3, 4, seed=1)])
def test_meta_round_trips_exactly(build):
    office = build()
    meta = office.meta()
    assert from_meta(meta) == office
    assert from_meta(json.loads(json.dumps(meta))) == office
    assert from_meta(meta).meta() == meta


def test_from_meta_rejects_what_is_not_an_office():
    meta = paper_office().meta()
    with pytest.raises(BiddingError):
        from_meta({k: v for k, v in meta.items() if k != "walls"})
    with pytest.raises(BiddingError):
        from_meta({**meta, "zones": [[1.0]]})
    with pytest.raises(BiddingError):
        from_meta({**meta, "size": [32.0, -1.0]})


def test_the_truth_is_the_outline_of_walls_and_furniture(office):
    truth = office.truth(0.1)
    occupied = truth.occupied
    assert occupied.shape == truth.shape == (220, 320)
    assert occupied[cell(truth, 0.0, 4.5)] and occupied[cell(truth, -15.98, 0.0)]
    assert occupied[cell(truth, 11.0, -4.52)]                 # the table's north edge
    assert not occupied[cell(truth, 11.0, -5.0)]              # inside the table: no laser reaches it
    assert not any(occupied[cell(truth, x, y)] for x, y in office.zones)
    assert not occupied[cell(truth, 9.0, 4.5)]                # a door
    coarse = office.truth(0.5)
    assert coarse.shape == (44, 64) and coarse.occupied.any()


def test_waypoints_lie_in_the_zone_region_clear_of_furniture(office):
    for j, zone in enumerate(office.zones):
        points = office.waypoints(j)
        region = office.region(j)
        assert points[0] == zone and 3 <= len(points) <= 5
        for x, y in points:
            assert region.contains(x, y) and office.clearance(x, y) >= 0.4
    with pytest.raises(BiddingError):
        office.waypoints(8)


def test_corridor_zones_split_the_corridor():
    office = generated_office(3, 2)
    corridor = [j for j, zone in enumerate(office.zones) if office.room_of(*zone) == "corridor"]
    assert len(corridor) == 3
    regions = sorted((office.region(j) for j in corridor), key=lambda r: r.xmin)
    assert regions[0].xmin == office.bounds[0] and regions[-1].xmax == office.bounds[2]
    assert all(a.xmax == pytest.approx(b.xmin) for a, b in zip(regions, regions[1:]))


def test_generated_office_sizes_zones_and_starts():
    office = generated_office(3, 5, room=(8.0, 7.0), corridor=4.0, seed=2)
    assert office.size == (24.0, 18.0) and office.origin == (-12.0, -9.0)
    assert len(office.rooms) == 7 and office.rooms[-1].name == "corridor"
    assert len(office.zones) == 9
    rooms = [office.room_of(*zone) for zone in office.zones]
    assert rooms[:6] == [f"room{k}" for k in range(1, 7)] and rooms[6:] == ["corridor"] * 3
    # rank order: north rooms east to west, south rooms east to west, corridor east to west
    assert [z[0] for z in office.zones] == [8.0, 0.0, -8.0] * 3
    assert [z[1] > 0 for z in office.zones[:6]] == [True] * 3 + [False] * 3
    assert [s[:2] for s in office.starts] == [(-2.0, 0.0), (-1.0, 0.0), (0.0, 0.0), (1.0, 0.0), (2.0, 0.0)]
    assert 3 <= len(office.furniture) <= 18
    for x, y in office.zones:
        assert office.clearance(x, y) >= 1.0
    assert generated_office(3, 5, seed=2) == office
    assert generated_office(3, 5, seed=3) != office
    assert len(check_world(office.world(5))["robots"]) == 5


@pytest.mark.parametrize("args, kwargs, message", [
    ((0, 2), {}, "rooms per side"),
    ((2, 0), {}, "robots"),
    ((2.5, 2), {}, "rooms per side"),
    ((1, 8), {}, "do not fit"),
    ((2, 2), {"room": (2.0, 7.0)}, "at least 3 m"),
    ((2, 2), {"room": (8.0,)}, "room"),
    ((2, 2), {"corridor": 1.0}, "at least 2 m"),
    ((2, 2), {"corridor": math.nan}, "corridor"),
    ((200, 2), {}, "larger than"),
])
def test_generated_office_rejects_impossible_arguments(args, kwargs, message):
    with pytest.raises(BiddingError, match=message):
        generated_office(*args, **kwargs)


def test_draw_writes_a_png(office, tmp_path):
    path = tmp_path / "office.png"
    draw(office, path, title="Fig. 6", robots=5)
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and path.stat().st_size > 10_000
    with pytest.raises(BiddingError):
        draw(office, tmp_path / "x.png", robots=6)


def _run_with(tmp_path, lines):
    """Exit code and error line of the one-robot net run over a world file of ``lines``."""
    pytest.importorskip("pybullet")
    from petriflow import examples
    from petriflow.cli import main

    world = tmp_path / "world.yaml"
    world.write_text("\n".join(lines) + "\n", encoding="utf-8")
    net = examples.path("bidding", "bidding-autonomous-1.yaml")
    return main(["run", str(net), "--world", str(world), "--until", "0"]), world


def _world_lines():
    from petriflow import examples

    return examples.path("bidding", "world.yaml").read_text(encoding="utf-8").splitlines()


@pytest.mark.parametrize("setting, typo, why", [
    ("size", "siz", "unknown setting 'siz' (did you mean 'size'?)"),
    ("xmin", "xmn", "unknown setting 'xmn' (did you mean 'xmin'?)"),
])
def test_a_misspelt_office_setting_stops_the_run_at_its_line(tmp_path, capsys, setting, typo, why):
    """meta.office is a declared settings section: a typo fails before the run, at the world file's line."""
    lines = _world_lines()
    office = lines.index("  office:")
    at = next(i for i, line in enumerate(lines) if i > office and line.strip().startswith(f"{setting}:"))
    lines[at] = lines[at].replace(f"{setting}:", f"{typo}:", 1)
    code, world = _run_with(tmp_path, lines)
    error = capsys.readouterr().err.strip()
    assert code == 2 and error.startswith(f"petriflow: {world}:{at + 1}: 'meta.office"), error
    assert why in error and "Traceback" not in error


def test_a_mistyped_office_setting_stops_the_run_at_its_line(tmp_path, capsys):
    """A zone that is not a list of numbers fails at its line, exit 2."""
    lines = _world_lines()
    lines.insert(lines.index("    zones:") + 1, "    - [north, 1.0]")
    code, world = _run_with(tmp_path, lines)
    error = capsys.readouterr().err.strip()
    assert code == 2 and error.startswith(f"petriflow: {world}:"), error
    assert "'meta.office'" in error and "north" in error, error
