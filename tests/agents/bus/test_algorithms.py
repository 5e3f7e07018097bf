"""The paper's algorithms 1 and 2 as rules."""

from __future__ import annotations

import random

import pytest
from petriflow.agents.bus.algorithms import ALGORITHMS, BusAwareScheme, NativeScheme
from petriflow.agents.bus.packet import Packet


def test_native_delay_is_drawn_once_in_zero_to_one_second():
    """As printed: one U[0, 1000] ms delay before the loop; every iteration waits it."""
    delays = set()
    for seed in range(200):
        scheme = NativeScheme(0, 3, random.Random(seed))
        assert 0.0 <= scheme.delay <= 1.0
        assert {scheme.iteration() for _ in range(5)} == {scheme.step_time + scheme.delay}
        delays.add(round(scheme.delay, 1))
    assert len(delays) == 11  # covers the whole range


def test_native_redraw_changes_the_delay():
    """redraw=True draws a new delay every iteration."""
    scheme = NativeScheme(0, 3, random.Random(1), redraw=True)
    assert len({scheme.iteration() for _ in range(10)}) == 10


def test_native_sends_whatever_the_bus_does():
    """Algorithm 1 ignores the bus."""
    scheme = NativeScheme(1, 3, random.Random(0))
    assert scheme.wants_to_send(bus_free=True) and scheme.wants_to_send(bus_free=False)


def test_native_sends_to_both_neighbours_that_exist():
    """myaddress + 1 and myaddress − 1, within the chain."""
    rng = random.Random(0)
    assert [NativeScheme(a, 3, rng).receivers() for a in range(3)] == [(1,), (2, 0), (1,)]


def test_bus_aware_sends_only_on_a_free_bus():
    """The bus-available handler checks the bus."""
    scheme = BusAwareScheme(0, 3, random.Random(0))
    assert scheme.bus_available(bus_free=True) and not scheme.bus_available(bus_free=False)
    assert scheme.iteration() == scheme.step_time


def test_bus_aware_overflow_sends_when_indicator_below_half():
    """Indicator ~ U[0, 1]; send if < 0.5: exactly the draws of the module's generator."""
    scheme = BusAwareScheme(0, 3, random.Random(42))
    mirror = random.Random(42)
    decisions = [scheme.overflow() for _ in range(1000)]
    assert decisions == [mirror.random() < 0.5 for _ in range(1000)]
    assert 450 < sum(decisions) < 550


def test_bus_aware_idle_delay_is_uniform_in_the_window():
    """The bus-available interrupt comes U[0, idle_window] after a quiet bus."""
    scheme = BusAwareScheme(0, 3, random.Random(3), idle_window=0.2)
    draws = [scheme.idle_delay() for _ in range(500)]
    assert 0.0 <= min(draws) and max(draws) <= 0.2 and max(draws) > 0.19


def test_bus_aware_message_goes_to_the_next_address_and_is_kept_from_a_neighbour():
    """String[0] = my address + 1; a module keeps messages for it from a neighbour only."""
    scheme = BusAwareScheme(1, 3, random.Random(0))
    assert scheme.receivers() == (2,)
    assert scheme.accepts(Packet((1,), 0, 0.0))
    assert not scheme.accepts(Packet((1,), 3, 0.0))
    assert not scheme.accepts(Packet((2,), 0, 0.0))


def test_native_accepts_either_receiver_slot():
    """Algorithm 1's message carries two addresses; either receiver keeps it."""
    assert NativeScheme(0, 3, random.Random(0)).accepts(Packet((2, 0), 1, 0.0))
    assert not NativeScheme(0, 3, random.Random(0)).accepts(Packet((1,), 2, 0.0))


@pytest.mark.parametrize("number", [1, 2])
def test_same_seed_same_decisions(number):
    """A scheme's draws depend only on its generator's seed."""

    def draws(seed):
        scheme = ALGORITHMS[number](0, 3, random.Random(seed))
        if number == 1:
            return [scheme.delay]
        return [scheme.overflow() for _ in range(20)] + [scheme.idle_delay() for _ in range(5)]

    assert draws(5) == draws(5) and draws(5) != draws(6)
