"""The 802.15.4 MAC on its own (zigbee.CsmaCa): what a layer above it is told, and when."""

from __future__ import annotations

import random

import pytest

from petriflow.agents.bus import Frame, ZigbeeBus
from petriflow.agents.bus.zigbee import CsmaCa
from petriflow.runtime.kernel import Kernel
from petriflow.runtime.media import ProcessClock

UNIT = 320e-6
CCA = 128e-6
TURNAROUND = 192e-6
LIFS = 640e-6  # after a MAC frame over 18 bytes (with ZigBee's 16 network bytes, every frame)


class ZeroBackoff(random.Random):
    def randrange(self, *args, **kwargs):
        return 0


def radios(bus=None, nodes=(0, 1), rng=None):
    """Radios on a clock of their own; every callback is recorded as (time, what, ...)."""
    clock = ProcessClock(Kernel(1e-6))
    heard = []
    mac = CsmaCa(bus or ZigbeeBus(), clock, rng or ZeroBackoff(0),
                 on_start=lambda t: heard.append((clock.now, "start", t.frame.sender)),
                 on_collision=lambda t: heard.append((clock.now, "collision", t.frame.sender)),
                 on_sent=lambda node, t: heard.append((clock.now, "sent", node, t.garbled)),
                 on_failure=lambda node: heard.append((clock.now, "failure", node)),
                 on_free=lambda node: heard.append((clock.now, "free", node)))
    for node in nodes:
        mac.add_node(node)
    return mac, clock, heard


def test_a_lone_frame_is_sent_after_assessment_and_turnaround_then_the_radio_rests():
    """From send: backoff 0, the CCA, the turnaround, the frame; the radio is serving
    until the frame is off the air, free after the long interframe spacing."""
    mac, clock, heard = radios()
    frame = Frame(0, (1,), bytes(2))
    mac.send(0, frame)
    assert mac.serving(0) and not mac.busy()
    clock.run(until=0.1)
    on_air = CCA + TURNAROUND
    off_air = on_air + mac.airtime(frame)
    assert heard == [(pytest.approx(on_air), "start", 0), (pytest.approx(off_air), "sent", 0, False),
                     (pytest.approx(off_air + LIFS), "free", 0)]
    assert not mac.serving(0)


def test_a_frame_is_taken_when_it_is_ready_not_before():
    mac, clock, heard = radios()
    mac.send(0, Frame(0, (1,), bytes(2)), ready=0.01)
    clock.run(until=0.1)
    assert heard[0] == (pytest.approx(0.01 + CCA + TURNAROUND), "start", 0)


def test_two_radios_that_assess_together_collide_and_each_is_told_once():
    mac, clock, heard = radios()
    for node in (0, 1):
        mac.send(node, Frame(node, (1 - node,), bytes(2)))
    clock.run(until=0.1)
    kinds = [entry[1:] for entry in heard]
    assert kinds[:4] == [("start", 0), ("start", 1), ("collision", 0), ("collision", 1)]
    assert ("sent", 0, True) in kinds and ("sent", 1, True) in kinds


def test_a_radio_that_never_finds_the_air_clear_gives_up_and_is_free_at_once():
    """A long frame holds the air; the other radio's every assessment finds it busy:
    after max_backoffs + 1 assessments CSMA/CA gives up (no interframe spacing)."""
    bus = ZigbeeBus(max_backoffs=2)
    mac, clock, heard = radios(bus)
    mac.send(0, Frame(0, (1,), bytes(90)))      # about 3.6 ms on the air
    clock.run(until=CCA + TURNAROUND + 1e-5)
    mac.send(1, Frame(1, (0,), bytes(2)))
    clock.run(until=0.1)
    failure = next(entry for entry in heard if entry[1] == "failure")
    assert failure[2] == 1 and (failure[0], "free", 1) in heard
    assert failure[0] == pytest.approx(CCA + TURNAROUND + 1e-5 + 3 * CCA)


def test_a_frame_taken_during_the_spacing_starts_at_once_and_the_radio_is_free_once():
    """The layer above may hand the radio its next frame while it rests: CSMA/CA starts
    then, and the end of that rest tells nothing (the radio is busy again)."""
    mac, clock, heard = radios()
    frame = Frame(0, (1,), bytes(2))
    mac.send(0, frame)
    off_air = CCA + TURNAROUND + mac.airtime(frame)
    clock.run(until=off_air + LIFS / 2)
    mac.send(0, frame)
    clock.run(until=0.1)
    starts = [entry[0] for entry in heard if entry[1] == "start"]
    assert starts[1] == pytest.approx(off_air + LIFS / 2 + CCA + TURNAROUND, abs=2e-6)
    assert [entry[1] for entry in heard].count("free") == 1


def test_distance_and_link_follow_the_spacing_unless_positions_say_otherwise():
    clock = ProcessClock(Kernel(1e-6))
    noop = lambda *args: None  # noqa: E731
    mac = CsmaCa(ZigbeeBus(spacing=0.5), clock, random.Random(0), on_start=noop, on_sent=noop,
                 on_failure=noop, on_free=noop, positions={2: 10.0})
    assert mac.distance(0, 1) == 0.5 and mac.distance(1, 2) == 9.5
