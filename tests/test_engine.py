"""Unit tests of petriflow.engine: enabledness, firing, sequences and the token game."""

from __future__ import annotations

import pytest

from petriflow.classic import dining_philosophers, independent_cycles, producer_consumer
from petriflow.engine import (
    CompiledNet,
    Deadlock,
    Simulation,
    enabled,
    fire,
    fire_sequence,
    is_enabled,
)
from petriflow.errors import NotEnabledError, UnknownElementError
from petriflow.marking import Marking
from petriflow.net import Net


def chain(tokens: int = 1) -> Net:
    """a --t--> b --u--> c, with ``tokens`` tokens in a."""
    net = Net("chain")
    net.add_place("a", tokens=tokens)
    net.add_place("b")
    net.add_place("c")
    net.add_transition("t")
    net.add_transition("u")
    net.add_arc("a", "t")
    net.add_arc("t", "b")
    net.add_arc("b", "u")
    net.add_arc("u", "c")
    return net


def weighted() -> Net:
    """t takes 2 from a and 1 from b, and puts 3 into c."""
    net = Net("weighted")
    net.add_place("a", tokens=2)
    net.add_place("b", tokens=1)
    net.add_place("c")
    net.add_transition("t")
    net.add_arc("a", "t", weight=2)
    net.add_arc("b", "t")
    net.add_arc("t", "c", weight=3)
    return net


def self_loop(take: int = 1, give: int = 1, tokens: int = 1) -> Net:
    """t reads p through a self-loop: takes ``take`` tokens from p and gives ``give`` back."""
    net = Net("loop")
    net.add_place("p", tokens=tokens)
    net.add_place("out")
    net.add_transition("t")
    net.add_arc("p", "t", weight=take)
    net.add_arc("t", "p", weight=give)
    net.add_arc("t", "out")
    return net


def source() -> Net:
    """A transition without input places that feeds p, and a sink that drains p."""
    net = Net("source")
    net.add_place("p")
    net.add_transition("gen")
    net.add_transition("sink")
    net.add_arc("gen", "p")
    net.add_arc("p", "sink")
    return net


# enabled / is_enabled ----------------------------------------------------------------


def test_enabled_lists_transitions_with_enough_tokens():
    """Only transitions whose every input place holds the arc weight are enabled."""
    assert enabled(chain(), Marking(a=1)) == ["t"]


def test_enabled_keeps_net_order():
    """Enabled transitions come in the order they were added to the net."""
    net = chain()
    assert enabled(net, Marking(a=1, b=1)) == ["t", "u"]


def test_enabled_is_empty_in_dead_marking():
    """A marking with no tokens where they are needed enables nothing."""
    assert enabled(chain(), Marking(c=1)) == []


def test_is_enabled_accepts_plain_dict():
    """is_enabled reads any mapping, not only Marking values."""
    assert is_enabled(chain(), {"a": 1}, "t")
    assert not is_enabled(chain(), {"a": 0}, "t")


def test_is_enabled_unknown_transition_raises():
    """is_enabled on an unknown transition raises UnknownElementError."""
    with pytest.raises(UnknownElementError):
        is_enabled(chain(), Marking(a=1), "nope")


# fire ---------------------------------------------------------------------------------


def test_fire_consumes_input_tokens():
    """Firing removes the arc weight from each input place."""
    assert fire(chain(tokens=2), Marking(a=2), "t")["a"] == 1


def test_fire_produces_output_tokens():
    """Firing adds the arc weight to each output place."""
    assert fire(chain(), Marking(a=1), "t") == Marking(b=1)


def test_fire_returns_marking_value():
    """fire returns a Marking, also when given a plain dict."""
    assert isinstance(fire(chain(), {"a": 1}, "t"), Marking)


def test_fire_leaves_argument_unchanged():
    """fire builds a new marking and leaves a dict argument as it was."""
    start = {"a": 1}
    fire(chain(), start, "t")
    assert start == {"a": 1}


def test_fire_drops_emptied_places():
    """A place emptied by firing is not stored in the result."""
    assert "a" not in fire(chain(), Marking(a=1), "t")


def test_fire_not_enabled_raises():
    """Firing a transition that is not enabled raises NotEnabledError."""
    with pytest.raises(NotEnabledError):
        fire(chain(), Marking(), "t")


def test_not_enabled_error_names_short_places():
    """NotEnabledError lists each short place with what it has and what it needs."""
    with pytest.raises(NotEnabledError) as info:
        fire(weighted(), Marking(a=1, b=1), "t")
    assert info.value.missing == {"a": (1, 2)}
    assert "a has 1, needs 2" in str(info.value)


def test_not_enabled_error_omits_satisfied_places():
    """Places that hold enough tokens are not named in NotEnabledError."""
    with pytest.raises(NotEnabledError) as info:
        fire(weighted(), Marking(a=1, b=1), "t")
    assert "b has" not in str(info.value)


def test_not_enabled_error_names_transition():
    """NotEnabledError carries and prints the transition id."""
    with pytest.raises(NotEnabledError) as info:
        fire(chain(), Marking(), "u")
    assert info.value.transition == "u"
    assert "'u'" in str(info.value)


def test_fire_unknown_transition_hints_close_name():
    """An unknown transition id raises UnknownElementError with a did-you-mean hint."""
    with pytest.raises(UnknownElementError) as info:
        fire(dining_philosophers(3), dining_philosophers(3).initial_marking, "take0")
    assert "did you mean" in str(info.value)
    assert "'take_0'" in str(info.value)


def test_unknown_element_error_is_key_error():
    """UnknownElementError is also a KeyError, for callers that catch lookups."""
    with pytest.raises(KeyError):
        fire(chain(), Marking(a=1), "zzz")


def test_fire_weight_above_one_needs_full_weight():
    """An arc of weight 2 needs two tokens: one is not enough."""
    assert not is_enabled(weighted(), Marking(a=1, b=1), "t")
    assert is_enabled(weighted(), Marking(a=2, b=1), "t")


def test_fire_weight_above_one_moves_weights():
    """Firing with weights > 1 subtracts and adds the full weights."""
    assert fire(weighted(), Marking(a=3, b=1), "t") == Marking(a=1, c=3)


def test_self_loop_needs_token_in_loop_place():
    """A self-loop transition is disabled when its loop place is empty."""
    assert enabled(self_loop(tokens=0), Marking()) == []


def test_self_loop_keeps_loop_place_count():
    """Firing a balanced self-loop leaves the loop place's count unchanged."""
    assert fire(self_loop(), Marking(p=1), "t") == Marking(p=1, out=1)


def test_unbalanced_self_loop_moves_net_difference():
    """A self-loop taking 2 and giving 1 lowers the place by 1."""
    assert fire(self_loop(take=2, give=1), Marking(p=3), "t") == Marking(p=2, out=1)


def test_unbalanced_self_loop_checks_input_weight():
    """Enabledness of a self-loop checks the input weight, not the net change."""
    assert not is_enabled(self_loop(take=2, give=1), Marking(p=1), "t")


def test_transition_without_inputs_always_enabled():
    """A transition with an empty preset is enabled even in the empty marking."""
    assert enabled(source(), Marking()) == ["gen"]


def test_transition_without_inputs_produces_tokens():
    """Firing a transition with an empty preset only adds tokens."""
    assert fire(source(), Marking(p=2), "gen") == Marking(p=3)


# fire_sequence ------------------------------------------------------------------------


def test_fire_sequence_fires_in_order():
    """fire_sequence fires each transition in turn."""
    assert fire_sequence(chain(), Marking(a=1), ["t", "u"]) == Marking(c=1)


def test_fire_sequence_empty_returns_start():
    """An empty sequence returns the start marking."""
    assert fire_sequence(chain(), {"a": 1}, []) == Marking(a=1)


def test_fire_sequence_raises_at_first_disabled():
    """fire_sequence raises NotEnabledError naming the first transition that cannot fire."""
    with pytest.raises(NotEnabledError) as info:
        fire_sequence(chain(), Marking(a=1), ["t", "t", "u"])
    assert info.value.transition == "t"


def test_fire_sequence_rejects_unknown_place_in_marking():
    """fire_sequence checks that the start marking names only places of the net."""
    with pytest.raises(UnknownElementError):
        fire_sequence(chain(), {"zz": 1}, ["t"])


# CompiledNet --------------------------------------------------------------------------


def test_compiled_vector_round_trips_marking():
    """CompiledNet.vector and CompiledNet.marking are inverse."""
    compiled = CompiledNet(weighted())
    assert compiled.marking(compiled.vector(Marking(a=2, c=5))) == Marking(a=2, c=5)


def test_compiled_incidence_is_post_minus_pre():
    """The incidence matrix row of a transition is its net token change."""
    compiled = CompiledNet(self_loop(take=2, give=1))
    row = compiled.incidence[compiled.transition_index["t"]]
    assert list(row) == [-1, 1]


def test_compiled_enabled_matches_enabled():
    """CompiledNet.enabled agrees with engine.enabled."""
    net = producer_consumer(3, batch=2)
    compiled = CompiledNet(net)
    names = [compiled.transitions[t] for t in compiled.enabled(compiled.vector(net.initial_marking))]
    assert names == enabled(net, net.initial_marking)


# Simulation ---------------------------------------------------------------------------


def test_simulation_starts_in_initial_marking():
    """A new Simulation's marking is the net's initial marking."""
    net = dining_philosophers(3)
    assert Simulation(net).marking == net.initial_marking


def test_simulation_accepts_start_marking():
    """A start marking given to Simulation replaces the initial marking."""
    assert Simulation(chain(), {"b": 1}).peek() == ["u"]


def test_simulation_rejects_unknown_place_in_start_marking():
    """A start marking naming an unknown place raises UnknownElementError."""
    with pytest.raises(UnknownElementError):
        Simulation(chain(), {"q": 1})


def test_simulation_peek_lists_enabled_in_net_order():
    """peek returns the enabled transitions in net order."""
    assert Simulation(chain(), {"a": 1, "b": 1}).peek() == ["t", "u"]


def test_simulation_same_seed_same_sequence():
    """Two simulations with the same seed fire the same sequence."""
    net = dining_philosophers(5)
    first = Simulation(net, seed=42).run(200)
    second = Simulation(net, seed=42).run(200)
    assert first == second


def test_simulation_same_seed_same_marking():
    """Two simulations with the same seed end in the same marking."""
    net = producer_consumer(4)
    a, b = Simulation(net, seed=7), Simulation(net, seed=7)
    a.run(123)
    b.run(123)
    assert a.marking == b.marking


def test_simulation_run_counts_firings():
    """run(n) on a live net fires exactly n times and counts them."""
    sim = Simulation(dining_philosophers(4), seed=1)
    assert len(sim.run(50)) == 50
    assert sim.fired == 50


def test_simulation_run_matches_fire_sequence():
    """The marking reached by run equals fire_sequence over the returned ids."""
    net = producer_consumer(5, batch=2)
    sim = Simulation(net, seed=3)
    fired = sim.run(300)
    assert sim.marking == fire_sequence(net, net.initial_marking, fired)


def test_simulation_enabled_set_tracks_definition():
    """After every step, peek equals engine.enabled on the current marking."""
    net = producer_consumer(3, batch=2)
    net.add_transition("loop")
    net.add_arc("buffer", "loop", weight=2)
    net.add_arc("loop", "buffer")
    net.add_arc("loop", "free")
    sim = Simulation(net, seed=5)
    for _ in range(300):
        assert sim.peek() == enabled(net, sim.marking)
        if sim.is_dead:
            break
        sim.step()


def test_simulation_run_stops_when_predicate_holds():
    """run(predicate) stops at the first marking where the predicate holds."""
    sim = Simulation(producer_consumer(5), seed=2)
    sim.run(lambda m: m["buffer"] >= 2)
    assert sim.marking["buffer"] == 2


def test_simulation_run_predicate_true_at_start_fires_nothing():
    """run(predicate) fires nothing when the predicate already holds."""
    sim = Simulation(chain(), seed=0)
    assert sim.run(lambda m: m["a"] == 1) == []


def test_simulation_run_predicate_stops_at_deadlock():
    """run(predicate) returns when no transition is enabled, even if it never held."""
    sim = Simulation(chain(), seed=0)
    assert sim.run(lambda m: False) == ["t", "u"]
    assert sim.is_dead


def test_simulation_run_int_stops_at_deadlock():
    """run(n) returns early when the net dies before n firings."""
    sim = Simulation(chain(), seed=0)
    assert sim.run(10) == ["t", "u"]


def test_simulation_step_returns_fired_id():
    """step fires the only enabled transition and returns its id."""
    sim = Simulation(chain())
    assert sim.step() == "t"
    assert sim.marking == Marking(b=1)


def test_simulation_step_on_dead_marking_raises_deadlock():
    """step raises Deadlock when no transition is enabled."""
    sim = Simulation(chain(), {"c": 1})
    with pytest.raises(Deadlock):
        sim.step()


def test_simulation_is_dead_in_dead_marking():
    """is_dead is True exactly when nothing is enabled."""
    assert Simulation(chain(), {"c": 1}).is_dead
    assert not Simulation(chain()).is_dead


def test_simulation_on_fire_handler_called_with_id_and_marking():
    """on_fire handlers get the fired id and the marking after the firing."""
    calls = []
    sim = Simulation(chain())
    sim.on_fire(lambda name, marking: calls.append((name, marking)))
    sim.run(5)
    assert calls == [("t", Marking(b=1)), ("u", Marking(c=1))]


def test_simulation_on_fire_handler_called_by_named_fire():
    """Simulation.fire also calls the on_fire handlers."""
    calls = []
    sim = Simulation(chain())
    sim.on_fire(lambda name, marking: calls.append(name))
    sim.fire("t")
    assert calls == ["t"]


def test_simulation_fire_named_transition():
    """Simulation.fire fires the named transition."""
    sim = Simulation(chain(), {"a": 1, "b": 1})
    sim.fire("u")
    assert sim.marking == Marking(a=1, c=1)


def test_simulation_fire_not_enabled_names_short_places():
    """Simulation.fire of a disabled transition raises NotEnabledError naming the place."""
    sim = Simulation(chain())
    with pytest.raises(NotEnabledError) as info:
        sim.fire("u")
    assert info.value.missing == {"b": (0, 1)}


def test_simulation_fire_not_enabled_leaves_marking():
    """A refused Simulation.fire changes neither the marking nor the count."""
    sim = Simulation(chain())
    with pytest.raises(NotEnabledError):
        sim.fire("u")
    assert sim.marking == Marking(a=1)
    assert sim.fired == 0


def test_simulation_fire_unknown_transition_hints():
    """Simulation.fire of an unknown id raises UnknownElementError with a hint."""
    sim = Simulation(dining_philosophers(3))
    with pytest.raises(UnknownElementError, match="did you mean"):
        sim.fire("release0")


def test_simulation_weights_above_one():
    """The token game honours arc weights > 1."""
    sim = Simulation(weighted())
    assert sim.run(5) == ["t"]
    assert sim.marking == Marking(c=3)


def test_simulation_self_loop_stays_enabled():
    """A balanced self-loop stays enabled after firing."""
    sim = Simulation(self_loop(), seed=0)
    assert sim.run(3) == ["t", "t", "t"]
    assert sim.marking == Marking(p=1, out=3)


def test_simulation_unbalanced_self_loop_disables_itself():
    """A self-loop taking 2 and giving 1 fires until fewer than 2 tokens remain."""
    sim = Simulation(self_loop(take=2, give=1, tokens=3))
    assert sim.run(10) == ["t", "t"]
    assert sim.marking == Marking(p=1, out=2)


def test_simulation_source_transition_never_deadlocks():
    """A transition with an empty preset keeps the token game going."""
    sim = Simulation(source(), seed=9)
    assert len(sim.run(100)) == 100
    assert not sim.is_dead


def test_simulation_source_transition_enabled_in_empty_marking():
    """A transition with an empty preset is enabled from the start."""
    assert Simulation(source()).peek() == ["gen"]


def test_simulation_independent_cycles_stay_one_safe():
    """Every place of independent cycles holds at most one token along a run."""
    net = independent_cycles(4)
    sim = Simulation(net, seed=11)
    peaks = []
    sim.on_fire(lambda name, marking: peaks.append(max(marking.values())))
    sim.run(500)
    assert len(peaks) == 500 and max(peaks) == 1


def test_outcome_routes_become_variant_rows():
    """A transition with failure arcs compiles to one row per outcome."""
    from petriflow.engine import CompiledNet, fire
    from petriflow.net import Net

    net = Net()
    for p in ("a", "ok", "retry"):
        net.add_place(p)
    net.add_transition("t")
    net.add_arc("a", "t")
    net.add_arc("t", "ok")
    net.add_arc("t", "retry", outcome="failed")
    compiled = CompiledNet(net)
    assert compiled.transitions == ["t", "t@failed"]
    assert compiled.origin == [("t", None), ("t", "failed")]
    assert fire(net, {"a": 1}, "t", "failed") == {"retry": 1}


def test_cancellation_region_empties_places_when_firing():
    """Firing a transition with a cancellation region resets those places."""
    from petriflow.engine import Simulation, fire
    from petriflow.net import Net

    net = Net()
    net.add_place("alarm", tokens=1)
    net.add_place("junk", tokens=4)
    net.add_place("safe")
    net.add_transition("stop", cancels=["junk"])
    net.add_arc("alarm", "stop")
    net.add_arc("stop", "safe")
    assert fire(net, net.initial_marking, "stop") == {"safe": 1}
    sim = Simulation(net, seed=0)
    sim.run(until=1)
    assert sim.marking == {"safe": 1}
