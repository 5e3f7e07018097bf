"""petriflow's YAML format: reading, line-numbered errors, round trips."""

import textwrap

import pytest

from petriflow.errors import NetFormatError
from petriflow.io.yaml import dumps_net, load_yaml, loads_net


def load(text):
    return loads_net(textwrap.dedent(text), path="net.yaml")


def error_of(text):
    with pytest.raises(NetFormatError) as info:
        load(text)
    return info.value


def test_reads_places_transitions_arcs_and_markings(sequence_net):
    """Every part of the file lands in the model."""
    net = sequence_net
    assert list(net.places) == ["i", "p", "o"]
    assert net.preset("b") == {"p": 1} and net.postset("b") == {"o": 2}
    assert net.initial_marking == {"i": 1}
    assert net.final_marking == {"o": 2}


def test_action_params_guard_and_priority_are_bound():
    """Transition bindings are read as plain data."""
    net = load("""
        petriflow: 1
        places: [p]
        transitions:
          - {id: t, action: robot.move, params: {goal: [1, 2]}, guard: path_free, priority: 3, in: [p]}
    """)
    t = net.transition("t")
    assert (t.action, t.params, t.guard, t.priority) == ("robot.move", {"goal": [1, 2]}, "path_free", 3)
    assert type(t.params) is dict and type(t.params["goal"]) is list


def test_nodes_declared_in_a_subnet_belong_to_it():
    """Places and transitions listed under a subnet are members of it."""
    net = load("""
        petriflow: 1
        subnets:
          - id: cam
            label: Camera
            agent: camera_1
            places: [shot]
            transitions: [{id: capture, in: [i], out: [shot]}]
        places: [{id: i, tokens: 1}]
    """)
    assert net.subnets["cam"].agent == "camera_1"
    assert net.nodes_of("cam") == (["shot"], ["capture"])


def test_arcs_section_accepts_mappings_and_pairs():
    """Arcs can be listed separately, as mappings or [from, to, weight] lists."""
    net = load("""
        petriflow: 1
        places: [p, q]
        transitions: [t]
        arcs:
          - {from: p, to: t, weight: 2}
          - [t, q, 3]
    """)
    assert net.preset("t") == {"p": 2} and net.postset("t") == {"q": 3}


def test_xor_split_shorthand_expands():
    """split: xor expands into one transition per branch."""
    net = load("""
        petriflow: 1
        places: [{id: i, tokens: 1}, a, b]
        transitions: [{id: choose, split: xor, in: [i], out: [a, b]}]
    """)
    assert list(net.transitions) == ["choose_op_1", "choose_op_2"]


@pytest.mark.parametrize(
    "text, line, fragment",
    [
        ("petriflow: 1\nplaces: [p]\ntransitions:\n  - {id: t, in: [q]}\n", 4, "unknown place 'q'"),
        ("petriflow: 1\nplaces: [p]\ntransitions:\n  - {id: t, acton: x}\n", 4, "unknown key 'acton'"),
        ("petriflow: 1\nplaces: [p, p]\n", 2, "duplicate id"),
        ("petriflow: 1\nplaces: [p]\ntransitions: [{id: t}]\narcs:\n  - {from: p, to: t, weight: -1}\n",
         5, "weight must be a whole number"),
        ("petriflow: 1\nplaces: [p]\ntransitions: [{id: t}]\narcs:\n  - {from: p, to: x}\n",
         5, "unknown node 'x'"),
        ("petriflow: 1\nplaces:\n  - {id: p, tokens: 1.5}\n", 3, "tokens must be a whole number"),
        ("petriflow: 1\nplaces: [p\n", 3, "malformed YAML"),
        ("places: [p]\n", 1, "missing 'petriflow: 1'"),
        ("petriflow: 2\n", 1, "unsupported format version"),
        ("petriflow: 1\nplaces: [p]\nplaces: [q]\n", 3, "duplicate key 'places'"),
    ],
)
def test_errors_name_file_and_line(text, line, fragment):
    """Each malformed file gives one error naming the file, line and problem."""
    message = str(error_of(text))
    assert message.startswith(f"net.yaml:{line}: "), message
    assert fragment in message
    assert "\n" not in message


def test_unknown_key_suggests_close_match():
    """A typo in a key is answered with the key meant."""
    assert "did you mean 'action'" in str(error_of("petriflow: 1\ntransitions: [{id: t, acton: x}]\n"))


def test_python_tags_are_not_executed():
    """The loader is safe: Python object tags are a format error, not code."""
    message = str(error_of("petriflow: 1\nnet: !!python/object/apply:os.system ['echo hi']\n"))
    assert "malformed YAML" in message


def test_missing_file_is_a_format_error(tmp_path):
    """A file that is not there is named in the error."""
    with pytest.raises(NetFormatError, match="absent.yaml"):
        load_yaml(tmp_path / "absent.yaml")


def test_round_trip_keeps_everything():
    """YAML -> model -> YAML -> model gives the same net."""
    net = load("""
        petriflow: 1
        net: demo
        label: A demo
        subnets:
          - {id: r, label: Robot, agent: r1, places: [a], transitions: [{id: walk, action: gait.walk, in: [a], out: [o]}]}
        places: [{id: i, tokens: 2, meta: {position: [10, 20]}}, {id: o, label: end}]
        transitions:
          - {id: s, split: xor, action: plan, params: {k: 1}, in: {i: 2}, out: [a, o]}
          - {id: q, guard: ready, priority: -1, silent: true, in: [o], out: [o]}
        final: {o: 1}
    """)
    again = loads_net(dumps_net(net))
    assert again.structure() == net.structure()
    assert again.places["i"].meta == {"position": [10, 20]}
    assert "split: xor" in dumps_net(net)


def test_example_nets_round_trip(tmp_path):
    """Every YAML net shipped in nets/ survives a write and a read."""
    from tests.conftest import net_files

    for path in (p for p in net_files() if p.suffix == ".yaml"):
        net = load_yaml(path)
        assert loads_net(dumps_net(net)).structure() == net.structure(), path


@pytest.mark.parametrize("encoding", ["utf-8-sig", "utf-16", "utf-16-le", "utf-32"])
def test_yaml_nets_in_any_encoding_yaml_allows(tmp_path, encoding):
    """YAML allows UTF-8 with a mark, UTF-16 and UTF-32: the same net every time."""
    from petriflow.io import load_net

    text = "petriflow: 1\nplaces: [{id: p, tokens: 1}, q]\ntransitions: [{id: t, in: [p], out: [q]}]\n"
    path = tmp_path / "net.yaml"
    path.write_bytes(text.encode(encoding))
    assert load_net(path).structure() == loads_net(text).structure()
