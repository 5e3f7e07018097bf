"""Algorithm 1 (the RA's history update and its moves) and §3.2's reading rule."""

from __future__ import annotations

import random

from petriflow.agents.slam.history import (
    History,
    choose,
    left_of,
    opposite,
    pending_text,
    read_node,
    right_of,
    update,
)


def test_cardinal_identifiers_follow_fig1_and_table3():
    """0 west, 1 north, 2 east, 3 south; facing north the laterals are 0 and 2."""
    assert opposite(1) == 3 and opposite(0) == 2
    assert (left_of(1), right_of(1)) == (0, 2)
    assert (left_of(2), right_of(2)) == (1, 3)
    assert pending_text([0, 2]) == "0.2" and pending_text([]) == "-"


def test_the_fig3_walkthrough_gives_table3():
    """Start at (0, 0) facing north; a wall ahead at (0, 0.5) with both laterals open adds
    0 and 2; the random choice takes one of them out (Table 3 keeps '0')."""
    h = History(radius=0.3)
    start = update(h, (0.0, 0.0), heading=1, openings=[1], came_from=None)
    assert h.table() == [(0, 0.0, 0.0, 0, "1")]
    assert choose(h, start, random.Random(0)).direction == 1
    one = update(h, (0.0, 0.5), heading=1, openings=[0, 2], came_from=start)
    assert h.table()[1] == (1, 0.0, 0.5, 0, "0.2")
    picked = choose(h, one, random.Random(5))
    assert picked.direction == 2 and h.table() == [(0, 0.0, 0.0, 0, "-"), (1, 0.0, 0.5, 0, "0")]


def test_the_choice_among_pending_paths_is_random_and_seeded():
    """Both laterals get chosen over seeds, and the same seed chooses the same."""
    chosen = set()
    for seed in range(20):
        h = History()
        v = h.add((0, 0), None, [0, 2])
        chosen.add(choose(h, v, random.Random(seed)).direction)
    assert chosen == {0, 2}
    a, b = History(), History()
    for h in (a, b):
        h.add((0, 0), None, [0, 1, 2])
    assert choose(a, 0, random.Random(7)) == choose(b, 0, random.Random(7))


def test_an_existing_position_updates_pending_paths_and_adds_no_row():
    """Arriving at a known vertex by another corridor takes that corridor off its pending paths."""
    h = History(radius=1.0)
    a = h.add((0.0, 0.0), None, [1, 2])
    b = h.add((0.0, 5.0), a, [2])
    h.link(a, 1, b)
    c = h.add((-5.0, 5.0), b, [3])   # east of b (x grows west)
    h.link(b, 2, c)
    assert h.rows[a].pending == [2]
    again = update(h, (-5.1, 0.2), heading=3, openings=[0], came_from=c)   # c southwards: a new vertex
    assert again == 3 and len(h) == 4
    back = update(h, (0.3, -0.1), heading=0, openings=[1], came_from=again)   # west to a: exists
    assert back == a and len(h) == 4
    assert h.rows[a].pending == [] and h.rows[again].pending == []


def test_back_tracking_goes_to_the_nearest_vertex_with_pending_paths():
    """A dead end with nothing pending: the route over the known corridors to the nearest
    vertex that still has a pending path."""
    h = History()
    a = h.add((0, 0), None, [2])
    b = h.add((0, 4), a, [0])
    h.link(a, 1, b)
    c = h.add((0, 9), b, [])
    h.link(b, 1, c)
    choice = choose(h, c, random.Random(0))
    assert choice.direction is None and choice.route == [(3, b)] and choice.target == b
    h.take(b, 0)
    assert choose(h, c, random.Random(0)).route == [(3, b), (3, a)]


def test_the_exploration_ends_when_nothing_is_pending():
    h = History()
    a = h.add((0, 0), None, [])
    assert choose(h, a, random.Random(0)).direction is None
    assert choose(h, a, random.Random(0)).route == []
    assert not h.has_pending()


def test_the_reading_rule_follows_ignores_or_keeps_going():
    """A new node id: take the first pending path of the array; the same id: ignore; a
    new id with nothing pending: keep going away from it."""
    h = History()
    h.add((0, 0), None, [])
    h.add((0, 6), 0, [0])
    h.add((0.2, 10), 1, [])
    h.add((3, 9.7), 2, [3])
    assert read_node(h, "WA_R1_1", None).path == (1, 0)
    assert read_node(h, "WA_R1_1", "WA_R1_1").kind == "ignore"
    for v in list(h.rows):
        h.rows[v].pending = []
    assert read_node(h, "WA_R1_2", "WA_R1_1").kind == "away"


def test_a_goal_from_the_reading_rule_routes_there_then_takes_its_path():
    h = History()
    a = h.add((0, 0), None, [])
    b = h.add((0, 6), a, [0, 2])
    h.link(a, 1, b)
    goal = (b, 0)
    h.take(*goal)
    first = choose(h, a, random.Random(0), goal)
    assert first.route == [(1, b)]
    there = choose(h, b, random.Random(0), goal)
    assert there.direction == 0


def test_table8_the_arrays_the_second_ra_loads_carry_pending_paths_as_text():
    """Table 8's shape: vertices with their pending paths as identifiers separated by periods."""
    h = History()
    for v, (x, y, last, pending) in enumerate([(0, 0, 0, []), (0, 6, 0, [0]), (0.2, 10, 1, []), (3, 9.7, 2, [3]),
                                               (9, 10, 3, [0]), (9, 19.7, 4, [0]), (9, 21.7, 5, [0, 2])]):
        h.add((x, y), None if v == 0 else last, pending)
    assert [row[4] for row in h.table()] == ["-", "0", "-", "3", "0", "0", "0.2"]
    assert h.first_pending() == (1, 0)
