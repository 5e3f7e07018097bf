"""What a live page is sent stays bounded however long the run (events windowed)."""

from __future__ import annotations

from petriflow.live.state import LiveState, Sample
from petriflow.runtime.trace import Event


def test_the_window_and_batches_stay_bounded_over_a_long_run():
    """A million firings' worth of samples: the state keeps the window, a batch at most the window."""
    state = LiveState(window=50)
    state.apply(Event(0, 0.0, "run", None, None, {"marking": {"p": 1}}))
    for k in range(20_000):
        firing = {"t": "t", "agent": "a", "firing": k, "since": float(k)}
        state.take(Sample(float(k), {"p": k % 3}, (firing,)))
        if k % 1000 == 0:
            batch = state.batch()
            assert batch is not None and len(batch["events"]) <= 50
    assert len(state.recent) == 50
    assert len(state.snapshot()["events"]) == 50
    assert state.snapshot()["marking"] == {"p": 19_999 % 3} if 19_999 % 3 else {}


def test_the_stop_event_sets_the_final_marking():
    """Whatever the last sample said, the page ends on the run's final marking."""
    state = LiveState()
    state.apply(Event(0, 0.0, "run", None, None, {"marking": {"i": 2}}))
    state.take(Sample(1.0, {"i": 1}, ()))
    state.apply(Event(9, 3.0, "stop", None, None, {"marking": {"o": 2}, "reason": "final"}))
    assert state.snapshot()["marking"] == {"o": 2}
    assert state.batch()["marking"] == {"i": 0, "o": 2}
