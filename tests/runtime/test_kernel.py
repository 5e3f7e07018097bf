"""The event core: a tick clock, polls before applies, order within a tick."""

from petriflow.runtime.kernel import APPLY, POLL, Kernel, Scheduled


class Note(Scheduled):
    def __init__(self, log, name, phase=APPLY, alive=True):
        self.log, self.name, self.phase, self.alive = log, name, phase, alive

    def live(self, tick):
        return self.alive

    def apply(self, tick):
        self.log.append((tick, self.name))


def drain(kernel):
    kernel.run_due()


def test_polls_come_first_in_key_order_then_applies_in_schedule_order():
    """At one tick: polls sorted by their key (the firing number), then applies as scheduled."""
    kernel, log = Kernel(0.1), []
    kernel.schedule(2, Note(log, "apply-1"))
    kernel.schedule(2, Note(log, "poll-9", POLL), key=9)
    kernel.schedule(2, Note(log, "apply-2"))
    kernel.schedule(2, Note(log, "poll-3", POLL), key=3)
    assert kernel.peek() == 2
    kernel.tick = 2
    drain(kernel)
    assert [name for _, name in log] == ["poll-3", "poll-9", "apply-1", "apply-2"]
    assert kernel.peek() is None and kernel.pending == 0


def test_peek_skips_events_that_no_longer_matter():
    """A poll that is no longer live (its firing ended) does not make a tick."""
    kernel, log = Kernel(1.0), []
    kernel.schedule(1, Note(log, "stale", POLL, alive=False), key=1)
    kernel.schedule(4, Note(log, "later"))
    assert kernel.peek() == 4


def test_an_event_in_the_past_happens_now():
    """Scheduling before the current tick means the current tick."""
    kernel, log = Kernel(0.5), []
    kernel.tick = 6
    kernel.schedule(2, Note(log, "late"))
    assert kernel.peek() == 6
    drain(kernel)
    assert log == [(6, "late")]


def test_applies_scheduled_while_draining_the_tick_are_taken_too():
    """A zero-delay delivery made while the tick's events apply is applied in that tick."""
    kernel, log = Kernel(1.0), []

    class Chain(Note):
        def apply(self, tick):
            super().apply(tick)
            kernel.schedule(tick, Note(log, "follow-up"))

    kernel.schedule(0, Chain(log, "first"))
    drain(kernel)
    assert [name for _, name in log] == ["first", "follow-up"]


def test_ticks_at_rounds_up_to_the_first_tick_not_before():
    kernel = Kernel(0.1)
    assert [kernel.ticks_at(s) for s in (0.0, 0.3, 0.31, -1.0)] == [0, 3, 4, 0]
