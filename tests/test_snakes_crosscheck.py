"""petriflow's firing rule checked against SNAKES on random small P/T nets.

SNAKES is the oracle: every net is converted with :func:`petriflow.interop.snakes.to_snakes`
and both libraries must agree on the enabled transitions and on every successor marking.

SNAKES 0.9.33's ``Transition.modes()`` returns ``[]`` for a transition without input
arcs (its cross product of zero input bindings is empty), while P/T semantics, petriflow
and SNAKES' own ``Transition.enabled(Substitution())`` treat such a transition as always
enabled. :func:`snakes_enabled` therefore asks ``enabled(Substitution())`` for those
transitions and ``modes()`` for all others.
"""

from __future__ import annotations

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from petriflow.engine import Simulation, enabled, fire
from petriflow.errors import MarkingError, NetFormatError
from petriflow.interop.snakes import from_snakes, marking_from_snakes, snakes_marking, to_snakes
from petriflow.marking import Marking
from petriflow.net import Net

snakes_nets = pytest.importorskip("snakes.nets")

# SNAKES 0.9.33 imports modules Python is deprecating (imp, cgi, pkgutil's emulation).
pytestmark = [
    pytest.mark.filterwarnings("ignore:the imp module is deprecated:DeprecationWarning"),
    pytest.mark.filterwarnings("ignore:'cgi' is deprecated:DeprecationWarning"),
    pytest.mark.filterwarnings("ignore:This emulation is deprecated:DeprecationWarning"),
]

SETTINGS = settings(
    max_examples=200,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow],
)

#: Node ids to pick from: SNAKES names are any string, so spaces, punctuation and
#: non-ASCII letters are in. (No control characters: SNAKES writes names into PNML
#: unescaped, and XML cannot hold them.)
ID_POOL = ("p", "q", "t", "u", "p 1", "t-2", "é", "λ", "_", "0", "a.b", "Ω7")

# Strategies are built once, and each draws few choices (sampled_from rather than
# one_of/tuples): Hypothesis' cost per choice, not the libraries, bounds this file's time.
IDS = st.permutations(ID_POOL)
NET_IDS = st.sampled_from(ID_POOL)
PLACE_COUNT = st.integers(2, 6)
TRANSITION_COUNT = st.integers(1, 6)
TOKENS = st.integers(0, 3)
LABELS = st.sampled_from([None, "", "a", "b x", "é"])
#: (input weight, output weight) of one place for one transition; both set: a self-loop.
WEIGHT_PAIRS = st.sampled_from(
    [(i, o) for i in (None, 1, 2, 3) for o in (None, 1, 2, 3) if (i, o) != (None, None)]
)
ARCS = st.dictionaries(st.integers(0, 5), WEIGHT_PAIRS, max_size=6)


@st.composite
def pt_nets(draw: st.DrawFn) -> Net:
    """A random P/T net: 2-6 places, 1-6 transitions, weights 1-3, 0-3 tokens a place.

    Each transition draws a few places and, for each, an input weight, an output weight
    or both, so self-loops (arcs both ways) and transitions without inputs occur often.
    """
    n_places, n_transitions = draw(PLACE_COUNT), draw(TRANSITION_COUNT)
    ids = draw(IDS)
    places, transitions = ids[:n_places], ids[n_places:n_places + n_transitions]
    net = Net(draw(NET_IDS), draw(LABELS))
    for place in places:
        net.add_place(place, tokens=draw(TOKENS), label=draw(LABELS))
    for transition in transitions:
        net.add_transition(transition, label=draw(LABELS))
        arcs = {places[k % n_places]: weights for k, weights in draw(ARCS).items()}
        for place, (weight_in, weight_out) in arcs.items():
            if weight_in is not None:
                net.add_arc(place, transition, weight_in)
            if weight_out is not None:
                net.add_arc(transition, place, weight_out)
    return net


def snakes_enabled(snet: "snakes_nets.PetriNet") -> list[str]:
    """Names of the SNAKES transitions enabled in the SNAKES net's current marking."""
    names = []
    for transition in snet.transition():
        if transition.input():
            modes = transition.modes()
            assert modes in ([], [snakes_nets.Substitution()])  # a P/T net has one mode at most
            if modes:
                names.append(transition.name)
        elif transition.enabled(snakes_nets.Substitution()):
            names.append(transition.name)
    return names


def snakes_fire(snet: "snakes_nets.PetriNet", name: str) -> None:
    """Fire the SNAKES transition ``name`` in its only P/T mode."""
    transition = snet.transition(name)
    modes = transition.modes() if transition.input() else [snakes_nets.Substitution()]
    transition.fire(modes[0])


def snakes_state(snet: "snakes_nets.PetriNet") -> Marking:
    """The SNAKES net's current marking as a petriflow Marking."""
    return marking_from_snakes(snet.get_marking())


@SETTINGS
@given(pt_nets())
def test_enabled_sets_agree_in_initial_marking(net):
    """petriflow and SNAKES enable the same transitions in the initial marking."""
    assert enabled(net, net.initial_marking) == snakes_enabled(to_snakes(net))


@SETTINGS
@given(pt_nets())
def test_successor_markings_agree(net):
    """Each enabled transition leads to the same marking in petriflow and SNAKES."""
    snet = to_snakes(net)
    start = snakes_marking(net.initial_marking)
    for name in enabled(net, net.initial_marking):
        snet.set_marking(start)
        snakes_fire(snet, name)
        assert snakes_state(snet) == fire(net, net.initial_marking, name), name


@SETTINGS
@given(pt_nets(), st.lists(st.integers(0, 1000), max_size=10))
def test_random_firing_sequences_agree(net, choices):
    """Along a random firing sequence both libraries agree on every enabled set and marking.

    The sequence is played three ways side by side: petriflow's reference ``fire``, the
    incremental :class:`Simulation`, and SNAKES.
    """
    snet = to_snakes(net)
    sim = Simulation(net)
    marking = net.initial_marking
    for choice in choices:
        expected = enabled(net, marking)
        assert snakes_enabled(snet) == expected
        assert sim.peek() == expected
        if not expected:
            break
        name = expected[choice % len(expected)]
        marking = fire(net, marking, name)
        snakes_fire(snet, name)
        sim.fire(name)
        assert snakes_state(snet) == marking
        assert sim.marking == marking


@SETTINGS
@given(pt_nets())
def test_round_trip_keeps_structure(net):
    """from_snakes(to_snakes(net)) has the structure, labels and node order of net."""
    back = from_snakes(to_snakes(net))
    assert back.structure() == net.structure()
    assert list(back.places) == list(net.places)
    assert list(back.transitions) == list(net.transitions)


@settings(max_examples=50, deadline=None)
@given(pt_nets())
def test_snakes_marking_round_trips(net):
    """marking_from_snakes inverts snakes_marking."""
    assert marking_from_snakes(snakes_marking(net.initial_marking)) == net.initial_marking


@settings(max_examples=50, deadline=None)
@given(pt_nets())
def test_pnml_round_trip_keeps_semantics_only(net):
    """Through SNAKES' PNML, ids, arcs, weights and the marking survive; labels do not.

    SNAKES' PNML has no field for labels (nor for any other petriflow attribute), so
    the ``petriflow`` attribute that carries them is dropped by ``dumps``/``loads``.
    """
    import snakes.pnml

    back = from_snakes(snakes.pnml.loads(snakes.pnml.dumps(to_snakes(net))))
    places, transitions, arcs, subnets, initial, final, run = net.structure()
    got = back.structure()
    assert [p[0] for p in got[0]] == [p[0] for p in places]
    assert [t[0] for t in got[1]] == [t[0] for t in transitions]
    assert got[2:] == (arcs, subnets, initial, final, run)
    assert all(p[1] is None for p in got[0])


# Conversion details ----------------------------------------------------------------------


def test_round_trip_keeps_petriflow_attributes():
    """Labels, bindings, subnets, meta, arc ids and the final marking survive a round trip."""
    net = Net("cell", "work cell")
    net.meta["author"] = "lab"
    net.add_subnet("arm", "Arm", agent="ur5")
    net.add_place("ready", tokens=2, label="Ready", subnet="arm", meta={"x": 10})
    net.add_place("done")
    net.add_transition("pick", label="Pick", action="robot.pick", params={"speed": 0.2},
                       guard="has_part", subnet="arm", priority=2)
    net.add_transition("tau", silent=True)
    net.add_arc("ready", "pick", weight=2, id="a1")
    net.add_arc("pick", "done", id="a2")
    net.add_arc("done", "tau")
    net.add_arc("tau", "ready")
    net.set_final_marking({"done": 1})
    back = from_snakes(to_snakes(net))
    assert back.structure() == net.structure()
    assert (back.label, back.meta, back.places["ready"].meta) == ("work cell", {"author": "lab"}, {"x": 10})
    assert back.arc("ready", "pick").id == "a1"


def test_outcome_arcs_are_kept_out_of_snakes_firing():
    """Output arcs reserved for an action outcome are not SNAKES arcs but round-trip."""
    import inspect

    if "outcome" not in inspect.signature(Net.add_arc).parameters:
        pytest.skip("this petriflow has no outcome arcs")
    net = Net("retry")
    net.add_place("p", tokens=1)
    net.add_place("ok")
    net.add_place("failed")
    net.add_transition("t", action="robot.move")
    net.add_arc("p", "t")
    net.add_arc("t", "ok")
    net.add_arc("t", "failed", outcome="failed")
    snet = to_snakes(net)
    assert [place.name for place, _ in snet.transition("t").output()] == ["ok"]
    assert from_snakes(snet).structure() == net.structure()


def test_from_snakes_reads_current_marking():
    """The SNAKES net's current marking becomes the initial marking."""
    net = Net("n")
    net.add_place("a", tokens=1)
    net.add_place("b")
    net.add_transition("t")
    net.add_arc("a", "t")
    net.add_arc("t", "b", weight=3)
    snet = to_snakes(net)
    snakes_fire(snet, "t")
    assert from_snakes(snet).initial_marking == Marking(b=3)


def test_weight_above_one_is_a_multiarc_of_dots():
    """A weight-3 arc becomes MultiArc of three Value(dot), weight 1 a single Value(dot)."""
    net = Net("n")
    net.add_place("a")
    net.add_transition("t")
    net.add_arc("a", "t", weight=3)
    net.add_arc("t", "a")
    transition = to_snakes(net).transition("t")
    dot = snakes_nets.Value(snakes_nets.dot)
    assert transition.input()[0][1] == snakes_nets.MultiArc([dot, dot, dot])
    assert transition.output()[0][1] == dot


def coloured_net(construct: str) -> "snakes_nets.PetriNet":
    """A one-transition SNAKES net with one coloured construct."""
    sn = snakes_nets
    snet = sn.PetriNet("coloured")
    tokens = [1, 2] if construct == "int tokens" else [sn.dot]
    check = sn.tInteger if construct == "typed place" else None
    snet.add_place(sn.Place("p", tokens if check is None else [], check))
    guard = sn.Expression("x > 0") if construct == "guard" else None
    snet.add_transition(sn.Transition("t", guard))
    labels = {
        "variable": sn.Variable("x"),
        "value": sn.Value(1),
        "tuple": sn.Tuple([sn.Value(sn.dot), sn.Value(sn.dot)]),
        "test arc": sn.Test(sn.Value(sn.dot)),
        "mixed multiarc": sn.MultiArc([sn.Value(sn.dot), sn.Variable("y")]),
    }
    snet.add_input("p", "t", labels.get(construct, sn.Value(sn.dot)))
    return snet


@pytest.mark.parametrize(
    ("construct", "element", "words"),
    [
        ("variable", "t", "variable 'x'"),
        ("mixed multiarc", "t", "variable 'y'"),
        ("value", "t", "Value(1)"),
        ("tuple", "t", "Tuple"),
        ("test arc", "t", "Test"),
        ("guard", "t", "guard 'x > 0'"),
        ("int tokens", "p", "holds the token"),
        ("typed place", "p", "typed"),
    ],
)
def test_from_snakes_rejects_coloured_construct(construct, element, words):
    """from_snakes raises NetFormatError naming the element for each coloured construct."""
    with pytest.raises(NetFormatError) as info:
        from_snakes(coloured_net(construct))
    assert info.value.element == element
    assert words in str(info.value)


def test_from_snakes_rejects_expression_on_output_arc():
    """An expression on an output arc is not a P/T arc."""
    sn = snakes_nets
    snet = sn.PetriNet("n")
    snet.add_place(sn.Place("p"))
    snet.add_transition(sn.Transition("t"))
    snet.add_output("p", "t", sn.Expression("1 + 1"))
    with pytest.raises(NetFormatError, match="output arc t -> p"):
        from_snakes(snet)


def test_marking_from_snakes_rejects_coloured_tokens():
    """marking_from_snakes raises MarkingError for a token other than dot."""
    with pytest.raises(MarkingError, match="place 'p'"):
        marking_from_snakes({"p": snakes_nets.MultiSet([7])})
