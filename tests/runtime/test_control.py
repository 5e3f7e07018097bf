"""Steering a run through its control queue (petriflow.runtime.control): interventions
apply only at checkpoints, are events in the trace, and a breakpoint stops the run
before any later firing."""

from __future__ import annotations

import threading

import pytest

from petriflow.io.yaml import loads_net
from petriflow.runtime.control import Control, ControlError, Intervention, parse_breakpoint
from petriflow.runtime.replay import markings
from petriflow.runtime.scheduler import Scheduler

NET = """
petriflow: 1
places: [{id: i, tokens: 3}, o, bad, extra]
transitions:
- {id: work, action: core.wait, params: {seconds: 2}, in: [i], out: [o], outcomes: {failed: [bad]}}
- {id: more, action: core.wait, params: {seconds: 1}, in: [extra], out: [o]}
"""


def steered(control: Control, steps) -> tuple[Scheduler, list, object]:
    """Run NET under ``control`` while another thread does ``steps(control)``; the
    scheduler, its events and the result."""
    scheduler = Scheduler(loads_net(NET), seed=1, control=control)
    events: list = []
    scheduler.on_event(events.append)
    errors: list = []

    def drive() -> None:
        try:
            steps(control)
        except BaseException as exc:  # noqa: BLE001 - reported below
            errors.append(exc)
            control.submit(Intervention.of("resume"))

    thread = threading.Thread(target=drive)
    thread.start()
    result = scheduler.run()
    thread.join(timeout=30)
    assert not errors, errors
    return scheduler, events, result


def ask(control: Control, command: str, **args) -> str:
    reply = control.submit(Intervention.of(command, args, by="test"))
    assert reply.done.wait(30), f"{command}: no reply"
    assert reply.ok, reply.message
    return reply.message


def controls(events: list) -> list:
    return [e for e in events if e.kind == "control"]


def test_breakpoint_syntax_errors_name_the_syntax():
    """A malformed breakpoint is refused with the language's syntax."""
    for bad in ("place o >=", "transition", "place o => 2", "when done", 3):
        with pytest.raises(ControlError, match="transition NAME"):
            parse_breakpoint(bad)


def test_malformed_interventions_are_refused_before_queueing():
    """Unknown commands, bad counts and outcomes fail when asked, not in the run."""
    for command, args in (("jump", {}), ("inject", {"place": "o", "count": 0}), ("step", {"count": "x"}),
                          ("force", {"firing": "work", "outcome": "maybe"}), ("speed", {"factor": -1}),
                          ("inject", {"count": 1}), ("hit", {})):
        with pytest.raises(ControlError):
            Intervention.of(command, args)


def test_paused_run_waits_and_steps_one_firing_at_a_time():
    """Started paused, the run fires nothing until a step, then exactly one firing per step."""
    seen = []

    def steps(control):
        import time

        time.sleep(0.3)
        seen.append(len(control._run.running()))  # nothing fired while paused
        ask(control, "step", count=1)
        time.sleep(0.3)
        seen.append(control._run.running())
        ask(control, "resume")

    _, events, result = steered(Control(paused=True, interactive=True), steps)
    assert seen == [0, ["work"]]
    assert result.marking.to_dict() == {"o": 3}
    assert [e.data["action"] for e in controls(events)] == ["step", "resume"]


def test_breakpoint_on_a_place_stops_before_any_later_firing():
    """`place o >= 1` pauses the run when o reaches 1; no firing starts until the resume."""
    def steps(control):
        import time

        while not control.paused:
            time.sleep(0.01)
        time.sleep(0.2)
        ask(control, "resume")

    _, events, _ = steered(Control(breakpoints=["place o >= 1"], interactive=True), steps)
    hit = next(e for e in events if e.kind == "control" and e.data["action"] == "hit")
    resume = next(e for e in events if e.kind == "control" and e.data["action"] == "resume")
    assert hit.data["spec"] == "place o >= 1" and hit.data["tokens"] == 1
    assert not [e for e in events if hit.seq < e.seq < resume.seq and e.kind == "start"]
    assert [e for e in events if e.seq > resume.seq and e.kind == "start"]


def test_breakpoint_without_anyone_to_resume_is_recorded_and_the_run_goes_on():
    """With no live page (not interactive) a hit is an event and the run does not wait."""
    _, events, result = steered(Control(breakpoints=["transition work"]), lambda control: None)
    hits = [e for e in controls(events) if e.data["action"] == "hit"]
    assert [h.transition for h in hits] == ["work"] * 3
    assert result.marking.to_dict() == {"o": 3}


def test_inject_remove_and_force_change_the_run_and_replay_to_its_marking():
    """Tokens injected and removed and a forced failure take effect, and the trace's
    replay ends at the run's own final marking."""
    def steps(control):
        import time

        while not control.paused:
            time.sleep(0.01)
        ask(control, "inject", place="extra", count=2)
        ask(control, "remove", place="i", count=1)
        ask(control, "force", firing="work", outcome="failed")
        refused = control.submit(Intervention.of("remove", {"place": "i", "count": 5}))
        assert refused.done.wait(30) and not refused.ok and "holds 1 token, not 5" in refused.message
        ask(control, "resume")

    control = Control(paused=True, interactive=True)
    control.submit(Intervention.of("step", {"count": 1}))
    _, events, result = steered(control, steps)
    assert result.marking.to_dict() == {"bad": 1, "o": 3}
    assert list(markings(events))[-1][1] == result.marking
    end = next(e for e in events if e.kind == "end")
    assert end.data == {"firing": 1, "outcome": "failed", "produced": {"bad": 1}, "reason": "forced failed by test"}


def test_unknown_names_are_refused_by_the_run():
    """A place or firing the run does not have is refused with a close match; nothing is recorded."""
    def steps(control):
        import time

        time.sleep(0.2)
        for command, args, text in (("inject", {"place": "extr"}, "did you mean 'extra'"),
                                    ("force", {"firing": "nope", "outcome": "ok"}, "no running firing 'nope'"),
                                    ("clear", {"spec": "lost"}, "no breakpoint 'lost'")):
            reply = control.submit(Intervention.of(command, args))
            assert reply.done.wait(30) and not reply.ok and text in reply.message, reply.message
        ask(control, "resume")

    _, events, _ = steered(Control(paused=True, interactive=True), steps)
    assert [e.data["action"] for e in controls(events)] == ["resume"]


def test_the_run_refuses_interventions_once_it_ended():
    """After the run, what is submitted is answered at once: the run has ended."""
    control = Control()
    Scheduler(loads_net(NET), seed=1, control=control).run()
    reply = control.submit(Intervention.of("pause"))
    assert reply.done.is_set() and not reply.ok and "ended" in reply.message


def test_unsteered_control_changes_no_event():
    """A run with a control queue nobody uses makes the same events as one without."""
    plain, with_control = [], []
    a = Scheduler(loads_net(NET), seed=3)
    a.on_event(plain.append)
    a.run()
    b = Scheduler(loads_net(NET), seed=3, control=Control(interactive=True))
    b.on_event(with_control.append)
    b.run()
    assert [e.to_json() for e in plain] == [e.to_json() for e in with_control]


def test_failed_breakpoint_triggers_at_each_failure_before_the_next_firing():
    """`failed` triggers after an action ends failed, at the next checkpoint, naming it."""
    net = loads_net("""
petriflow: 1
places: [{id: i, tokens: 2}, o, bad]
transitions:
- {id: work, action: core.fail, in: [i], out: [o], outcomes: {failed: [bad]}}
""")
    scheduler = Scheduler(net, seed=1, control=Control(breakpoints=["failed"]))
    events: list = []
    scheduler.on_event(events.append)
    scheduler.run()
    hits = [e for e in controls(events) if e.data["action"] == "hit"]
    assert [(h.data["spec"], h.data["failed"]) for h in hits] == [("failed", "work")] * 2
    ends = [e.seq for e in events if e.kind == "end"]
    starts = [e.seq for e in events if e.kind == "start"]
    assert ends[0] < hits[0].seq < starts[1]  # before the next firing


def test_a_paused_run_whose_time_goes_on_rests_between_looks_and_wakes_for_the_operator():
    """A paused run with an ``idle`` (remote agents) and an unpaced clock: the control waits out
    each step in wall-clock time between two calls (no spinning), and a resume ends the wait."""
    import time

    from petriflow.runtime.control import PAUSED_STEP

    control = Control(paused=True, interactive=True)
    scheduler = Scheduler(loads_net(NET), seed=1, control=control)
    assert not scheduler.paced
    calls: list[float] = []

    def idle() -> bool:
        calls.append(time.monotonic())
        if len(calls) == 6:
            control.submit(Intervention.of("resume", by="test"))
        return False

    control.idle = idle
    result = scheduler.run()
    assert result.marking.to_dict() == {"o": 3} and len(calls) == 6
    gaps = [b - a for a, b in zip(calls, calls[1:])]
    assert min(gaps) >= 0.8 * PAUSED_STEP  # it rested between looks
