"""Auto-addressing of the chain."""

from __future__ import annotations

import random

import pytest
from petriflow.agents.bus.addressing import MAX_MODULES, AddressingError, AddressingModule, auto_address


def chain(names):
    """``behind`` and ``front_free`` for modules in physical order, head first."""
    behind = {a: b for a, b in zip(names, [*names[1:], None])}
    return behind, {name: i == 0 for i, name in enumerate(names)}


def test_head_takes_zero_and_the_chain_numbers_itself():
    """Addresses follow the physical order from the module whose front is free."""
    names = [f"serial-{n}" for n in random.Random(2).sample(range(1000), 6)]
    behind, front = chain(names)
    shuffled = dict(random.Random(3).sample(sorted(behind.items()), len(behind)))
    assert auto_address(shuffled, front) == {name: i for i, name in enumerate(names)}


def test_new_head_inherits_address_zero():
    """The head leaves: the next module's front frees and it becomes 0."""
    behind, front = chain(["a", "b", "c"])
    del behind["a"], front["a"]
    front["b"] = True
    assert auto_address(behind, front) == {"b": 0, "c": 1}


def test_no_head_two_heads_or_unreached_modules_are_errors():
    """A ring, two free fronts, a module nobody notifies."""
    with pytest.raises(AddressingError, match="nobody takes address 0"):
        auto_address({"a": "b", "b": "a"}, {})
    with pytest.raises(AddressingError, match="several"):
        auto_address({"a": None, "b": None}, {"a": True, "b": True})
    with pytest.raises(AddressingError, match="never reached"):
        auto_address({"a": None, "b": None}, {"a": True})


def test_chain_longer_than_supported_is_an_error():
    """254 modules fit; the 255th would need address 254."""
    names = list(range(MAX_MODULES))
    assert max(auto_address(*chain(names)).values()) == MAX_MODULES - 1
    with pytest.raises(AddressingError, match="beyond"):
        auto_address(*chain(list(range(MAX_MODULES + 1))))


def test_module_ignores_a_second_notice_and_a_head_ignores_notices():
    """Once addressed, a module keeps its address; the head never takes one from behind."""
    module = AddressingModule("m", front_free=False)
    head = AddressingModule("h", front_free=True)
    [notice] = head.start()
    module.receive(notice)
    assert module.receive(notice) == [] and module.address == 1
    assert head.receive(notice) == [] and head.address == 0
