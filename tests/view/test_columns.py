"""The events' columns a run's page holds (petriflow.view.columns): every record comes
back with the values of its JSON line, however awkward they are."""

from __future__ import annotations

import json

from petriflow.runtime.trace import Event
from petriflow.view.columns import decode, decoded, encode, encoded


def test_every_awkward_record_comes_back_equal(awkward_events):
    events = awkward_events
    records = decode(encode(events))
    assert records == [json.loads(e.to_json()) for e in events]
    assert json.loads(json.dumps(records[5]))["data"]["z"] == 0.0  # -0.0 equal to it


def test_integers_past_a_browsers_numbers_are_kept_whole():
    events = [Event(0, 0.0, "custom", data={"n": 2 ** 70 + 1, "m": -(2 ** 64)})]
    assert decode(encode(events))[0]["data"] == {"n": 2 ** 70 + 1, "m": -(2 ** 64)}


def test_seq_other_than_the_position_is_kept():
    events = [Event(10 + 3 * k, float(k), "custom", data={"n": k}) for k in range(5)]
    assert [r["seq"] for r in decode(encode(events))] == [10, 13, 16, 19, 22]


def test_repeated_events_share_a_template_and_cost_little():
    events = [Event(0, 0.0, "run", data={"marking": {"i": 1}})]
    for k in range(1, 5001):
        events.append(Event(k, round(0.1 * (k // 4), 1), "start", "t", "a",
                            {"firing": k, "consumed": {"i": 1}}))
    block, templates = encoded(events)
    assert set(templates[1:]) == {1}
    lines = "\n".join(e.to_json() for e in events).encode()
    assert len(block) < len(lines) / 20
    records, again = decoded(block)
    assert again == templates and records == [json.loads(e.to_json()) for e in events]
