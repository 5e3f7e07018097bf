"""Random nets for the analysis tests, and a plain reference exploration to compare with.

Nets from :func:`bounded_nets` are bounded by construction: every transition consumes
as many tokens as it produces (arc weights included), so the token total never changes
and a token budget bounds every place.
"""

from __future__ import annotations

from hypothesis import strategies as st

from petriflow.engine import enabled, fire
from petriflow.marking import Marking
from petriflow.net import Net

#: Place names are letters only, so PM4Py's state names (marking reprs with the
#: punctuation removed, e.g. "pa1pb2") cannot collide.
PLACE_NAMES = [f"p{chr(ord('a') + k)}" for k in range(8)]


@st.composite
def bounded_nets(draw: st.DrawFn, max_places: int = 6, max_transitions: int = 6,
                 max_tokens: int = 4) -> Net:
    """A conservative P/T net: 1-6 places, 1-6 transitions, weights 1-2, a token budget.

    Each transition takes 1-3 arcs in (weights 1-2) and spreads exactly as many tokens
    over random output places, so self-loops and parallel transitions occur.
    """
    n_places = draw(st.integers(1, max_places))
    places = PLACE_NAMES[:n_places]
    net = Net("random")
    for place in places:
        net.add_place(place)
    for k in range(draw(st.integers(1, max_transitions))):
        name = f"t{chr(ord('a') + k)}"
        net.add_transition(name)
        inputs = draw(st.dictionaries(st.sampled_from(places), st.integers(1, 2),
                                      min_size=1, max_size=min(3, n_places)))
        outputs: dict[str, int] = {}
        for _ in range(sum(inputs.values())):
            place = draw(st.sampled_from(places))
            outputs[place] = outputs.get(place, 0) + 1
        for place, weight in inputs.items():
            net.add_arc(place, name, weight)
        for place, weight in outputs.items():
            net.add_arc(name, place, weight)
    tokens = draw(st.lists(st.sampled_from(places), max_size=max_tokens))
    net.set_initial_marking(Marking({p: tokens.count(p) for p in set(tokens)}))
    return net


def reference_exploration(net: Net, start=None) -> tuple[set[Marking], int]:
    """Reachable markings and (marking, transition) edge count, by the textbook BFS on
    :func:`petriflow.engine.fire` (slow, obviously right)."""
    start = net.initial_marking if start is None else Marking(start)
    seen = {start}
    queue = [start]
    edges = 0
    for marking in queue:
        for transition in enabled(net, marking):
            successor = fire(net, marking, transition)
            edges += 1
            if successor not in seen:
                seen.add(successor)
                queue.append(successor)
    return seen, edges


def to_pm4py(net: Net):
    """``(pm4py PetriNet, initial Marking, place objects)``: the benchmarks' converter."""
    from tests.conftest import bench_module

    return bench_module("peers").to_pm4py(net)
