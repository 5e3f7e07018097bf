"""The contract every reader and command keeps, whatever it is given."""

from __future__ import annotations

import contextlib
import io
import re
import warnings

from hypothesis import strategies as st

from petriflow.cli import main

#: Values a fuzzer puts where a file had a value: the hostile and the merely odd.
HOSTILE_VALUES = [
    "-1", "0", "1", "2.5", ".nan", ".inf", "-.inf", "1e309", "9" * 5000, "true", "null", "[]", "{}",
    "'x'", "''", "[1, [2, [3]]]", "{a: {b: {c: 1}}}", "&a [1, 2]", "*a", "!!python/object/apply:os.system ['true']",
    "!!binary AAAA", '"\\x00"', "1000000000000000000000", "-0.0", "[" * 80 + "]" * 80, "~", "yes",
    "2026-11-23", "0x1F", "[.nan, .inf]", "{id: x}", "- a\n- b",
]


def run_cli(*argv: object) -> tuple[int, str, str]:
    """Run the command line in this process; return ``(exit code, stdout, stderr)``.

    Raises whatever the command raises: the contract is that it raises nothing.
    """
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        code = main([str(a) for a in argv])
    return code, out.getvalue(), err.getvalue()


def assert_contract(*argv: object) -> int:
    """The command exits 0, 1 or 2, and bad input is one line naming what is wrong."""
    code, _, err = run_cli(*argv)
    assert code in (0, 1, 2), (code, err)
    if code == 2:
        lines = err.strip().splitlines()
        assert lines and lines[-1].startswith("petriflow: ") and "Traceback" not in err, err
    return code


def mutate_yaml(draw: st.DrawFn, text: str, keys: list[str] = ()) -> bytes:
    """``text`` (YAML) with one to three lines changed: a value made hostile, a line
    deleted, duplicated, swapped or cut off, one of ``keys`` slipped into a flow
    mapping; then, half the time, a few random bytes inserted."""
    lines = text.splitlines()
    for _ in range(draw(st.integers(1, 3))):
        if not lines:
            break
        at = draw(st.integers(0, len(lines) - 1))
        kind = draw(st.sampled_from(["value", "value", "delete", "duplicate", "swap", "key", "truncate"]))
        if kind == "value":
            values = list(re.finditer(r"(?<=: )[^,{}\[\]\n]+|(?<=[\[,] )[^,{}\[\]\n]+", lines[at]))
            if values:
                hit = draw(st.sampled_from(values))
                lines[at] = lines[at][:hit.start()] + draw(st.sampled_from(HOSTILE_VALUES)) + lines[at][hit.end():]
        elif kind == "delete":
            del lines[at]
        elif kind == "duplicate":
            lines.insert(at, lines[at])
        elif kind == "swap":
            other = draw(st.integers(0, len(lines) - 1))
            lines[at], lines[other] = lines[other], lines[at]
        elif kind == "key" and keys:
            lines[at] = re.sub(r"\{(\w+):", lambda m: "{" + draw(st.sampled_from(keys)) + ", " + m.group(1) + ":",
                               lines[at], count=1)
        else:
            lines = lines[:at]
    data = ("\n".join(lines) + "\n").encode()
    if draw(st.booleans()):
        cut = draw(st.integers(0, len(data)))
        data = data[:cut] + draw(st.binary(max_size=4)) + data[cut:]
    return data
