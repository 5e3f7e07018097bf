"""The contract every reader and command keeps, whatever it is given."""

from __future__ import annotations

import contextlib
import io
import warnings

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
