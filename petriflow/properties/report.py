"""What ``petriflow check --properties`` prints, and its exit code.

Text: one line per property, ``id: verdict`` and how it was decided, then its evidence
(the firing sequence; for a lasso, the cycle repeated forever). The exit code: ``1``
when some property is false (a yes/no property; a bound's integer is an answer, not a
failure), else ``2`` when some property is undecided, else ``0``.

Examples:
    >>> results = [{"id": "mutex", "verdict": False, "method": "reachability graph",
    ...             "witness": ["red_enter", "blue_enter"], "formula": "AG(!(x >= 2))"}]
    >>> print(format_properties(results))
    mutex: false  (reachability graph)
      AG(!(x >= 2))
      counterexample: red_enter blue_enter
    >>> properties_exit_code(results)
    1
"""

from __future__ import annotations

from typing import Any

__all__ = ["format_properties", "properties_exit_code"]


def _verdict(value: Any) -> str:
    if value is None:
        return "undecided"
    if isinstance(value, bool):
        return "true" if value else "false"
    return str(value)


def format_properties(results: list[dict[str, Any]]) -> str:
    """The text report of :func:`~petriflow.properties.check.check_properties`'s results."""
    lines = []
    for r in results:
        how = f"  ({r['method']})" if r.get("method") else f"  ({r.get('reason')})" if r.get("reason") else ""
        lines.append(f"{r['id']}: {_verdict(r['verdict'])}{how}")
        if r.get("formula"):
            lines.append(f"  {r['formula']}")
        if r.get("witness") is not None and (r["witness"] or "cycle" in r):
            label = "witness" if r["verdict"] is True or not isinstance(r["verdict"], bool) else "counterexample"
            lines.append(f"  {label}: {' '.join(r['witness']) or '(the initial marking)'}")
        if "cycle" in r:
            lines.append(f"  then forever: {' '.join(r['cycle']) or '(stays in this deadlock)'}")
    return "\n".join(lines)


def properties_exit_code(results: list[dict[str, Any]]) -> int:
    """1: a property is false; 2: none false, some undecided; 0: all hold (or bounded)."""
    if any(r["verdict"] is False for r in results):
        return 1
    return 2 if any(r["verdict"] is None for r in results) else 0
