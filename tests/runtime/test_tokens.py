"""Tokens keep their data in arrival order, black tokens (no data) included: random
sequences of firings starts, ends and deliveries against a plain list per place."""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st

from petriflow.engine import CompiledNet
from petriflow.net import Net
from petriflow.runtime.tokens import TokenStore


def small_net() -> Net:
    """Two places; ``move`` takes 2 from ``a`` into ``b``; ``take`` takes 1 from ``b`` and
    empties ``a`` (a cancellation region); ``put`` puts 1 into ``a``."""
    net = Net("tokens")
    net.add_place("a", tokens=1)
    net.add_place("b")
    net.add_transition("move")
    net.add_arc("a", "move", weight=2)
    net.add_arc("move", "b")
    net.add_transition("take", cancels=["a"])
    net.add_arc("b", "take")
    net.add_arc("take", "a")
    net.add_transition("put")
    net.add_arc("put", "a")
    return net


operations = st.lists(st.tuples(st.sampled_from(["move", "take", "put", "deliver"]),
                                st.one_of(st.none(), st.integers(0, 9))), max_size=40)


@settings(max_examples=200, deadline=None)
@given(operations)
def test_data_and_counts_follow_a_list_per_place(ops):
    compiled = CompiledNet(small_net())
    store = TokenStore(compiled, {"a": 1})
    expected = {"a": [None], "b": []}
    row = {name: compiled.transitions.index(name) for name in ("move", "take", "put")}
    skip = [False, False]
    for name, data in ops:
        if name == "deliver":  # a message arriving in a
            store.add(compiled.place_index["a"], data)
            expected["a"].append(data)
        elif name == "put":
            assert store.produce(row["put"], data, None, skip) == {"a": 1}
            expected["a"].append(data)
        elif name == "move" and len(expected["a"]) >= 2:
            taken, withdrawn = store.consume(row["move"])
            assert taken == {"a": expected["a"][:2]} and withdrawn == {}
            del expected["a"][:2]
            store.produce(row["move"], data, None, skip)
            expected["b"].append(data)
        elif name == "take" and expected["b"]:
            taken, withdrawn = store.consume(row["take"])
            assert taken == {"b": expected["b"][:1]}
            assert withdrawn == ({"a": len(expected["a"])} if expected["a"] else {})
            del expected["b"][:1]
            expected["a"].clear()
            store.produce(row["take"], data, {"a": data}, skip)
            expected["a"].append(data)
        assert store.tokens() == {p: v for p, v in expected.items() if v}
        assert store.read("a") == expected["a"] and store.read("b") == expected["b"]
        assert store.counts == [len(expected["a"]), len(expected["b"])]
