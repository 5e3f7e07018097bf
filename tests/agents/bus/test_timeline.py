"""The simulated clock."""

from __future__ import annotations

import math

import pytest
from petriflow.agents.bus.timeline import MEDIUM, MODULE, Timeline


def test_callbacks_run_by_time_then_rank_then_order():
    """Equal times: the medium's events first, then in scheduling order."""
    timeline = Timeline()
    seen = []
    timeline.at(1.0, seen.append, "module-1", rank=MODULE)
    timeline.at(1.0, seen.append, "medium", rank=MEDIUM)
    timeline.at(1.0, seen.append, "module-2", rank=MODULE)
    timeline.at(0.5, seen.append, "early")
    timeline.run()
    assert seen == ["early", "medium", "module-1", "module-2"]
    assert timeline.now == 1.0 and timeline.peek() == math.inf


def test_cancelled_timers_do_not_run_and_run_until_stops_the_clock():
    """A cancelled timer is skipped; run(until) leaves later ones and sets the clock."""
    timeline = Timeline()
    seen = []
    timeline.at(1.0, seen.append, 1).cancel()
    timeline.at(3.0, seen.append, 3)
    timeline.run(until=2.0)
    assert seen == [] and timeline.now == 2.0 and timeline.peek() == 3.0


def test_the_past_cannot_be_scheduled():
    """Scheduling before now is an error."""
    timeline = Timeline(start=5.0)
    with pytest.raises(ValueError):
        timeline.at(4.0, print)


def test_run_stops_on_predicate():
    """run(stop=...) returns after the step that makes it true."""
    timeline = Timeline()
    seen = []
    for t in range(5):
        timeline.at(float(t), seen.append, t)
    timeline.run(stop=lambda: len(seen) == 2)
    assert seen == [0, 1] and timeline.now == 1.0
