"""Every reader, one number rule (issue 40, item 3).

Every whole number petriflow reads, from PNML, from YAML, from a ``--marking`` or from an
integer option, goes through :func:`petriflow.limits.parse_integer`: an optional sign and
the ASCII digits 0-9, at most 2**60. Another script's digits (U+0663 is not 3) and
numbers beyond 2**60 (5,000 digits included) are refused with one line naming the file
and the line, exit 2, no traceback; ASCII numbers within the range still load.
"""

from __future__ import annotations

import contextlib
import io
import sys
import unicodedata
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from petriflow.cli import main
from petriflow.errors import NetFormatError, NumberError
from petriflow.io import load_net
from petriflow.io.pnml_read import WOPED_OPERATOR_TYPES
from petriflow.limits import MAX_INTEGER, integer_argument, parse_integer
from petriflow.marking import parse_marking

#: Every character Unicode calls a decimal digit (category Nd, a decimal value) that is
#: not one of ASCII's 0-9: 650 of them (Python 3.11's Unicode 14), in some 65 scripts.
FOREIGN_DIGITS = [c for c in map(chr, range(128, sys.maxunicode + 1))
                  if unicodedata.category(c) == "Nd" and unicodedata.decimal(c, None) is not None]

ascii_digits = st.sampled_from("0123456789")
#: Text that ``int()`` and ``\d`` take for a number: ASCII digits with at least one other
#: script's digit among them.
foreign_numbers = st.tuples(st.lists(ascii_digits, max_size=3), st.sampled_from(FOREIGN_DIGITS),
                            st.lists(ascii_digits | st.sampled_from(FOREIGN_DIGITS), max_size=3)).map(
    lambda parts: "".join(parts[0]) + parts[1] + "".join(parts[2]))
#: ASCII whole numbers past the maximum: just past it, far past it, 5,000 digits.
huge_numbers = (st.integers(MAX_INTEGER + 1, 10**40).map(str)
                | st.sampled_from([str(MAX_INTEGER + 1), "9" * 5000, "1" + "0" * 4400, str(10**19)]))
hostile_numbers = foreign_numbers | huge_numbers

PTNET = "http://www.pnml.org/version-2009/grammar/ptnet"


def pnml(marking: str = "1", weight: str = "1", priority: str = "0", final: str = "1") -> str:
    """An ISO P/T net with a PM4Py-style final marking; the numbers on lines 5, 10, 13, 18."""
    return f"""<?xml version="1.0" encoding="UTF-8"?>
<pnml xmlns="http://www.pnml.org/version-2009/grammar/pnml">
<net id="n" type="{PTNET}">
<page id="g"><place id="p"><initialMarking>
<text>{marking}</text>
</initialMarking></place>
<place id="q"/>
<transition id="t">
<toolspecific tool="petriflow" version="1">
<priority>{priority}</priority>
</toolspecific></transition>
<arc id="a" source="p" target="t"><inscription>
<text>{weight}</text>
</inscription></arc>
<arc id="b" source="t" target="q"/>
</page>
<finalmarkings><marking><place idref="q">
<text>{final}</text>
</place></marking></finalmarkings>
</net>
</pnml>
"""


def woped(code: str = "104") -> str:
    """A WoPeD net (ptNetb, no page, the operator split into parts, as WoPeD writes it):
    the XOR-split ``t1`` from ``p1`` to ``p2`` or ``p3``; its first part's operator type is
    on line 10."""
    part = ('<toolspecific version="1.0" tool="WoPeD">\n<operator type="{}" id="t1"/>\n<time>0</time>\n'
            "</toolspecific>")
    return f"""<?xml version="1.0" encoding="UTF-8"?>
<pnml>
<net id="noID" type="http://www.informatik.hu-berlin.de/top/pntd/ptNetb">
<place id="p1"><initialMarking><text>1</text></initialMarking></place>
<place id="p2"/>
<place id="p3"/>
<transition id="t1_op_1">
<name><text>t1</text></name>
{part.format(code)}
</transition>
<transition id="t1_op_2">
<name><text>t1</text></name>
{part.format("104")}
</transition>
<arc id="a1" source="p1" target="t1_op_1"><inscription><text>1</text></inscription></arc>
<arc id="a2" source="t1_op_1" target="p2"><inscription><text>1</text></inscription></arc>
<arc id="a3" source="p1" target="t1_op_2"><inscription><text>1</text></inscription></arc>
<arc id="a4" source="t1_op_2" target="p3"><inscription><text>1</text></inscription></arc>
</net>
</pnml>
"""


def pipe(count: str = "1") -> str:
    """PIPE's dialect: ``Default,N`` token counts in ``<value>`` (line 5), positions as
    decimals."""
    return f"""<?xml version="1.0" encoding="ISO-8859-1"?>
<pnml>
<net id="Net-One" type="P/T net">
<place id="P0"><graphics><position x="120.0" y="90.0"/></graphics>
<initialMarking><value>Default,{count}</value></initialMarking></place>
<place id="P1"/>
<transition id="T0"/>
<arc id="P0 to T0" source="P0" target="T0"><inscription><value>Default,1</value></inscription></arc>
<arc id="T0 to P1" source="T0" target="P1"><inscription><value>Default,1</value></inscription></arc>
</net>
</pnml>
"""


def positioned(x: str = "10") -> str:
    """An ISO net whose place has ``<position x=...>`` on line 4."""
    return f"""<pnml>
<net id="n" type="{PTNET}">
<page id="g"><place id="p">
<graphics><position x="{x}" y="20"/></graphics>
<initialMarking><text>1</text></initialMarking></place>
<place id="q"/><transition id="t"/>
<arc id="a" source="p" target="t"/><arc id="b" source="t" target="q"/>
</page></net></pnml>
"""


def yaml_net(tokens: str = "1", weight: str = "1", priority: str = "0", final: str = "1") -> str:
    """A YAML net: tokens on line 2, priority and weight on line 4, the final marking on 5."""
    return (f"petriflow: 1\nplaces: [{{id: p, tokens: {tokens}}}, q]\ntransitions:\n"
            f"  - {{id: t, priority: {priority}, in: {{p: {weight}}}, out: [q]}}\nfinal: {{q: {final}}}\n")


#: Each reader: (file name, the file with the number in it, the line it is on).
FILE_READERS = {
    "pnml-initial-marking": ("n.pnml", lambda v: pnml(marking=v), 5),
    "pnml-arc-inscription": ("n.pnml", lambda v: pnml(weight=v), 13),
    "pnml-priority": ("n.pnml", lambda v: pnml(priority=v), 10),
    "pnml-final-marking": ("n.pnml", lambda v: pnml(final=v), 18),
    "pnml-woped-operator-type": ("w.pnml", woped, 10),
    "pnml-pipe-class-count": ("pipe.xml", pipe, 5),
    "pnml-position": ("pos.pnml", positioned, 4),
    "yaml-tokens": ("n.yaml", lambda v: yaml_net(tokens=v), 2),
    "yaml-weight": ("n.yaml", lambda v: yaml_net(weight=v), 4),
    "yaml-priority": ("n.yaml", lambda v: yaml_net(priority=v), 4),
    "yaml-final-marking": ("n.yaml", lambda v: yaml_net(final=v), 5),
}


def cli(argv: list[str]) -> tuple[int, str]:
    """Run the command line in this process: its exit code and standard error."""
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        try:
            code = main([str(a) for a in argv])
        except SystemExit as stop:  # argparse's own errors
            code = stop.code
    return code, err.getvalue()


def assert_refused(code: int, err: str, value: str, *where: str) -> None:
    """Exit 2, one line, no traceback, naming ``where`` and saying which rule."""
    assert code == 2, err
    assert err.startswith("petriflow") and err.count("\n") == 1 and "Traceback" not in err, err
    assert len(err) < 400, err
    for fragment in where:
        assert fragment in err, err
    if value.isascii():
        assert "2**60" in err, err
    else:
        assert "ASCII digits 0-9" in err, err


@pytest.fixture(scope="module")
def folder(tmp_path_factory) -> Path:
    return tmp_path_factory.mktemp("numbers")


@pytest.fixture(scope="module")
def small_net(folder) -> Path:
    path = folder / "small.yaml"
    path.write_text(yaml_net())
    return path


# Refused: another script's digits, and numbers past 2**60 -------------------------------
@pytest.mark.parametrize("reader", FILE_READERS)
@given(value=hostile_numbers)
def test_every_file_reader_refuses_foreign_digits_and_huge_numbers(folder, reader, value):
    name, make, line = FILE_READERS[reader]
    path = folder / name
    path.write_text(make(value), encoding="utf-8")
    code, err = cli(["info", path])
    assert_refused(code, err, value, f"{path}:{line}: ")


@given(value=hostile_numbers)
def test_a_marking_on_the_command_line_refuses_foreign_digits_and_huge_numbers(small_net, value):
    for marking in (f'{{"p": {value}}}', f'{{"p": "{value}"}}'):  # a JSON number, and as text
        code, err = cli(["simulate", small_net, "--steps", "1", "--marking", marking])
        assert code == 2 and err.count("\n") == 1 and "Traceback" not in err, err
        assert err.startswith("petriflow: --marking: "), err
        if value.isascii() or marking.startswith('{"p": "'):  # else not JSON at all: it says so
            assert_refused(code, err, value, "--marking: place 'p': token count")


@pytest.mark.parametrize("argv", [
    ["simulate", "{net}", "--steps"], ["simulate", "{net}", "--seed"], ["check", "{net}", "--max-states"],
    ["check", "{net}", "--invariant-budget"], ["run", "{net}", "--max-firings"],
    ["sweep", "{net}", "--workers"], ["sweep", "{net}", "--trials"], ["replay", "{net}", "--at"],
], ids=lambda argv: argv[-1])
@given(value=hostile_numbers)
def test_every_integer_option_refuses_foreign_digits_and_huge_numbers(small_net, argv, value):
    code, err = cli([a.format(net=small_net) for a in argv] + [value])
    assert_refused(code, err, value, f"argument {argv[-1]}: the value")


def test_every_foreign_digit_is_refused_by_the_rule_and_by_both_formats(folder):
    """All of them, not a sample: none reads as a number anywhere."""
    assert len(FOREIGN_DIGITS) >= 650
    for digit in FOREIGN_DIGITS:
        with pytest.raises(NumberError, match="ASCII digits 0-9"):
            parse_integer(digit)
        with pytest.raises(NumberError, match="ASCII digits 0-9"):
            parse_integer("1" + digit)
    yaml_path, pnml_path = folder / "each.yaml", folder / "each.pnml"
    for digit in FOREIGN_DIGITS:
        yaml_path.write_text(yaml_net(tokens=digit), encoding="utf-8")
        pnml_path.write_text(pnml(marking=digit), encoding="utf-8")
        for path, line in ((yaml_path, 2), (pnml_path, 5)):
            expected = f"^{path}:{line}: .*ASCII digits 0-9.*U[+]{ord(digit):04X}"
            with pytest.raises(NetFormatError, match=expected):
                load_net(path)


@pytest.mark.parametrize("text, meant", [("0x10", 16), ("0b11", 3), ("017", 15), ("00", 0),
                                         ("1_000", 1000), ("1:30", 90), ("+0x1", 1)])
def test_yaml_11_integer_forms_are_refused_not_guessed(folder, text, meant):
    """PyYAML reads these as integers (YAML 1.1); petriflow refuses them with their line,
    saying what YAML 1.1 would have read, in every YAML file (an id included)."""
    path = folder / "forms.yaml"
    for net, line in ((yaml_net(tokens=text), 2), (yaml_net(weight=text), 4),
                      (f"petriflow: 1\nplaces:\n  - {text}\n", 3)):
        path.write_text(net)
        code, err = cli(["info", path])
        assert code == 2 and err.count("\n") == 1, err
        expected = f"{path}:{line}: integer {text!r} (YAML 1.1 reads it as {meant}) is not plain decimal"
        assert expected in err, err


def test_a_number_in_quotes_is_text_and_refused(folder):
    path = folder / "quoted.yaml"
    path.write_text(yaml_net(tokens='"3"'))
    code, err = cli(["info", path])
    assert code == 2 and f"{path}:2: 'p': tokens must be a whole number, got the text '3'" in err, err


# Still read: ASCII whole numbers up to 2**60 ---------------------------------------------
counts = st.integers(0, MAX_INTEGER)
padded = st.tuples(st.sampled_from(["", " ", "\n  "]), st.sampled_from(["", "+", "0", "00"])).map("".join)


@given(tokens=counts, weight=st.integers(1, MAX_INTEGER), priority=st.integers(-MAX_INTEGER, MAX_INTEGER),
       final=counts, space=padded)
def test_pnml_reads_ascii_numbers_up_to_the_maximum(folder, tokens, weight, priority, final, space):
    """XSD integers: a sign, leading zeros and the whitespace around them are allowed."""
    path = folder / "fine.pnml"
    path.write_text(pnml(marking=f"{space}{tokens}", weight=str(weight), priority=str(priority),
                         final=f"{space}{final}"))
    net = load_net(path)
    assert net.initial_marking["p"] == tokens and net.transitions["t"].priority == priority
    assert net.preset("t") == {"p": weight} and net.final_marking["q"] == final


@given(tokens=counts, weight=st.integers(1, MAX_INTEGER), priority=st.integers(-MAX_INTEGER, MAX_INTEGER),
       final=counts)
def test_yaml_reads_ascii_numbers_up_to_the_maximum(folder, tokens, weight, priority, final):
    path = folder / "fine.yaml"
    path.write_text(yaml_net(tokens=str(tokens), weight=str(weight), priority=str(priority),
                             final=str(final)))
    net = load_net(path)
    assert net.initial_marking["p"] == tokens and net.transitions["t"].priority == priority
    assert net.preset("t") == {"p": weight} and net.final_marking["q"] == final


@given(code=st.sampled_from(sorted(WOPED_OPERATOR_TYPES)) | st.integers(0, MAX_INTEGER),
       x=st.integers(-MAX_INTEGER, MAX_INTEGER))
def test_woped_types_and_positions_read_up_to_the_maximum(folder, code, x):
    path = folder / "fine_w.pnml"
    path.write_text(woped(str(code)))
    with pytest.warns() if code not in WOPED_OPERATOR_TYPES else contextlib.nullcontext():
        net = load_net(path)
    operator = net.transitions["t1_op_1"].operator
    assert (operator is not None) == (code in WOPED_OPERATOR_TYPES)
    path = folder / "fine_pos.pnml"
    path.write_text(positioned(str(x)))
    assert load_net(path).places["p"].meta["position"] == [x, 20]


@given(count=counts, steps=st.integers(0, 50), option=st.integers(-MAX_INTEGER, MAX_INTEGER))
def test_markings_and_options_read_up_to_the_maximum(small_net, count, steps, option):
    assert parse_marking(f'{{"p": {count}}}', ["p", "q"]).to_dict() == ({"p": count} if count else {})
    assert integer_argument(str(option)) == option and integer_argument(f" +{abs(option)}") == abs(option)
    code, err = cli(["simulate", small_net, "--steps", str(steps), "--seed", str(option),
                     "--marking", f'{{"p": {count}}}'])
    assert code == 0, err


def test_the_maximum_is_the_analysis_range():
    """The analysis counts exactly up to 2**60; the readers let nothing larger through."""
    from petriflow.analysis.check_result import MAX_EXACT

    assert MAX_INTEGER == MAX_EXACT == 2**60
    assert parse_integer(str(MAX_INTEGER)) == MAX_INTEGER
    assert parse_integer(f"-{MAX_INTEGER}") == -MAX_INTEGER
    for beyond in (str(MAX_INTEGER + 1), f"-{MAX_INTEGER + 1}", MAX_INTEGER + 1):
        with pytest.raises(NumberError, match="2[*][*]60"):
            parse_integer(beyond)


def test_the_analysis_still_refuses_counts_past_the_maximum_built_in_python():
    """Files cannot carry such counts any more; a net built in code is refused by check."""
    from petriflow.analysis.report import check_net
    from petriflow.errors import PetriflowError
    from petriflow.net import Net

    net = Net("big")
    net.add_place("p", tokens=1)
    net.add_place("q")
    net.add_transition("t")
    net.add_arc("p", "t", 1)
    net.add_arc("t", "q", 2**62)
    with pytest.raises(PetriflowError, match=r"weight 4611686018427387904 is beyond .*2\*\*60"):
        check_net(net)
