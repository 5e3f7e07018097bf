"""The text ``petriflow check`` prints: :func:`format_report` of a check result.

The text gives each property with its verdict and the method that decided it
(docs/analysis.md, "The text report"); for a sound WF-net it says why
``deadlock_free``, ``live`` and ``reversible`` are false for the net as given (its runs
end in the dead final marking) and that the short-circuited net has them. A state space
stopped at the limit when the verdict was reached anyway ends with a note naming the
properties left undecided.

:func:`~petriflow.analysis.check.check_net`, :func:`~petriflow.analysis.verdict.exit_code`
with its ``EXIT_*`` codes and :func:`~petriflow.analysis.check_result.plain` are
importable from here too, as the command uses them together.

Examples:
    >>> from petriflow.classic import dining_philosophers
    >>> result = check_net(dining_philosophers(5))
    >>> exit_code(result), format_report(result).splitlines()[0]
    (0, 'philosophers-5: 15 places, 10 transitions -- OK')
"""

from __future__ import annotations

import re
from typing import Any

from petriflow.analysis.check import check_net
from petriflow.analysis.check_result import plain, quantity
from petriflow.analysis.verdict import EXIT_OK, EXIT_PROBLEM, EXIT_UNDECIDED, exit_code
from petriflow.marking import format_marking

__all__ = [
    "EXIT_OK",
    "EXIT_PROBLEM",
    "EXIT_UNDECIDED",
    "check_net",
    "exit_code",
    "format_report",
    "plain",
]


#: How the text names each method of ``methods``.
_METHOD_NAMES = {"explicit": "state space", "symmetry": "state space up to symmetry",
                 "stubborn": "stubborn sets", "stubborn+symmetry": "stubborn sets up to symmetry",
                 "structural": "Rank Theorem", "Karp-Miller": "Karp-Miller search"}

#: The properties each report line gives, and the name the text prints.
_PROPERTIES = (("sound", "sound"), ("bounded", "bounded"), ("deadlock_free", "deadlock-free"),
               ("live", "live"), ("reversible", "reversible"), ("dead_transitions", "dead transitions"))

_AGREES = " (structural agrees)"


def _yes(value: Any) -> str:
    return {True: "yes", False: "no", None: "undecided"}[value]


def _decided_by(result: dict[str, Any], key: str) -> str:
    """The method that decided ``key``, as the text names it.

    Examples:
        >>> _decided_by({"workflow_net": True, "complete": True,
        ...              "methods": {"sound": "explicit (structural agrees)"}}, "sound")
        'state space; the Rank Theorem agrees'
        >>> _decided_by({"workflow_net": False, "complete": True, "methods": {}}, "sound")
        'WF-net structure'
    """
    if key == "sound" and not result["workflow_net"]:
        return "WF-net structure"
    how = (result.get("methods") or {}).get(key)
    algorithm = result.get("algorithm") or ""
    if result.get("bounded") is False and (
            key == "dead_transitions" or (key == "bounded" and "Karp-Miller coverability search (depth"
                                          " first): unbounded" in algorithm)):
        how = "Karp-Miller"           # the search that found the pump
    if how is None:                   # check_net(method=None): no ``methods``
        if key == "bounded" and result.get("structurally_bounded"):
            how = "P-semiflows"
        elif key == "bounded" and (result.get("coverability") or {}).get("complete"):
            how = "Karp-Miller"
        else:
            how = "explicit"
    agrees = how.endswith(_AGREES)
    how = how[:-len(_AGREES)] if agrees else how
    name = _METHOD_NAMES.get(how, how)
    if how in ("explicit", "symmetry") and not result["complete"]:
        name += ", found before the limit"
    return name + ("; the Rank Theorem agrees" if agrees else "")


def _limit(result: dict[str, Any]) -> str:
    """Why the state space is not complete, in a few words."""
    if result.get("method") == "stubborn":
        return "--method stubborn builds no full state space"
    found = re.search(r"max_states=(\d+)", result.get("error") or "")
    return f"state space over --max-states{'=' + found.group(1) if found else ''}"


def _why_undecided(result: dict[str, Any], key: str) -> str:
    """Why ``key`` is undecided, in a few words."""
    if result.get("bounded") is False and key in ("deadlock_free", "live", "reversible"):
        return "unbounded: no finite state space"
    if key == "dead_transitions" and result.get("bounded") is False:
        return "Karp-Miller search over its budget"
    why = []
    if not result["complete"]:
        why.append(_limit(result))
    elif key == "live" and result.get("symmetry"):
        why.append("the symmetry reduction does not preserve it")
    if key == "bounded" and result.get("coverability") and not result["coverability"]["complete"]:
        why.append("Karp-Miller search over its budget")
    if key == "deadlock_free" and "stubborn" in (result.get("states_visited") or {}):
        why.append("stubborn sets stopped before finding one: see the note below")
    if key == "sound" and (result.get("reduced") or {}).get("sound", True) is None:
        why.append("not decided on the stubborn-set graph: see the note below")
    return "; ".join(why) or "not decided"


def _run_end(result: dict[str, Any]) -> str | None:
    """Where a run ends, when that is the only dead marking reached (else None).

    For a sound WF-net explored from ``[i]``, a dead marking reached is the final marking
    (soundness: from every reachable marking the final one is reachable); for another
    net, when ``stuck_markings`` is 0, it is the declared final marking.
    """
    final = result.get("final_marking")
    if result.get("deadlock_free") is not False or final is None:
        return None
    if result["workflow_net"]:
        start = {result["source_place"]: 1}
        if result.get("sound") is True and result["initial_marking"] == start:
            return f"the final marking {format_marking(final)}"
        return None
    if result.get("stuck_markings") == 0:
        return f"the declared final marking {format_marking(final)}"
    return None


def _witnessed(result: dict[str, Any], kinds: set[str]) -> bool:
    return any(v["kind"] in kinds and v.get("transitions") for v in result["violations"])


def _property_lines(result: dict[str, Any]) -> list[str]:
    """One line per property: its verdict and the method that decided it, or why not."""
    lines = []
    ends = _run_end(result)

    def line(key: str, name: str, text: str, inside: str = "") -> None:
        value = result.get(key)
        if value is None:
            lines.append(f"  {name}: undecided ({_why_undecided(result, key)}){text}")
        else:
            lines.append(f"  {name}: {_yes(value)} ({_decided_by(result, key)}{inside}){text}")

    sound = result.get("sound")
    line("sound", "sound", "", "; witnesses below" if result["workflow_net"] and sound is False and _witnessed(
        result, {"improper_completion", "no_option_to_complete", "dead_transition", "unbounded"}) else "")
    bounded, safe = result.get("bounded"), result.get("safe")
    found = result.get("partial") or {}
    if safe is False and found.get("k_bound_at_least"):
        top = max(found["k_bound_at_least"].items(), key=lambda item: item[1])
        extra = f", not safe ({top[0]} reaches {top[1]} tokens)"
    elif bounded and safe is False and result.get("max_tokens_place") is not None:
        extra = f", {result['max_tokens_place']}-bounded"
    elif bounded and safe:
        extra = ", safe"
    else:
        extra = ""
    if bounded is False:
        more = "" if result.get("unbounded_places_complete", True) else (
            " (at least; the others are undecided: coverability over its budget)")
        extra = f" -- UNBOUNDED: places {', '.join(result['unbounded_places'])}{more}"
    line("bounded", "bounded", extra, "; witness below" if bounded is False and _witnessed(
        result, {"unbounded"}) else "")
    if result.get("deadlock_free") is None and result.get("stuck_markings") == 0:
        by = _METHOD_NAMES.get((result.get("methods") or {}).get("stuck_markings") or "explicit")
        lines.append(f"  deadlock-free: undecided; no dead marking other than the declared final marking"
                     f" {format_marking(result.get('final_marking') or {})} ({by})")
    else:
        witnessed = result.get("deadlock_free") is False and _witnessed(result, {"deadlock"})
        line("deadlock_free", "deadlock-free", f" -- only at {ends}, where a run ends" if ends else "",
             "; witness below" if witnessed and not ends else "")
    line("live", "live", f" -- no transition fires again once {ends} is reached"
         if ends and result.get("live") is False else "")
    line("reversible", "reversible", f" -- the initial marking {format_marking(result['initial_marking'])}"
         " is not reached again"
         f" from {ends}" if ends and result.get("reversible") is False else "")
    if ends and result["workflow_net"] and result.get("final_marking") == {result["sink_place"]: 1} \
            and result.get("live") is False:
        lines.append(f"    (short-circuited, {result['sink_place']} connected back to {result['source_place']}"
                     " as WF-net tools analyse it: deadlock-free, live and reversible, as soundness"
                     " implies)")
    dead = result.get("dead_transitions")
    fired = found.get("not_dead_transitions") or result.get("not_dead_transitions")
    if dead is None and fired is not None:
        line("dead_transitions", "dead transitions",
             f"; {len(fired)} of {result['transitions']} fire (not dead)")
    elif dead is None:
        line("dead_transitions", "dead transitions", "")
    else:
        lines.append(f"  dead transitions: {', '.join(dead) if dead else 'none'}"
                     f" ({_decided_by(result, 'dead_transitions')})")
    return lines


def _answer(result: dict[str, Any], code: int) -> str:
    """What the exit code rests on, in a few words."""
    workflow = result["workflow_net"]
    if code == EXIT_OK:
        if workflow:
            return "sound"
        return "bounded, deadlock-free" if result.get("final_marking") is None else (
            "bounded, no dead marking other than the declared final one")
    if code == EXIT_PROBLEM:
        if workflow:
            return "not sound"
        return "unbounded" if result.get("bounded") is False else "a deadlock"
    if workflow:
        return "sound"
    missing = ["bounded"] if result.get("bounded") is None else []
    return ", ".join(missing + ["deadlock-free"]) if not any(
        v["kind"] == "deadlock" for v in result["violations"]) else ", ".join(missing)


def format_report(result: dict[str, Any]) -> str:
    """A short readable report of a :func:`check_net` result.

    After the header (the exit code's word: ``OK``, ``PROBLEM``, ``UNDECIDED``), one line
    per property: its verdict and the method that decided it, or ``undecided`` and why;
    then the state space, the semiflows, the method's notes and the violations with
    their witnesses. When the state space is not complete the last line says what that
    leaves undecided: a ``note`` when the exit code's verdict was reached anyway,
    ``no verdict`` when it was not (exit 2).

    Examples:
        >>> from petriflow.classic import dining_philosophers
        >>> print(format_report(check_net(dining_philosophers(3))).splitlines()[0])
        philosophers-3: 9 places, 6 transitions -- OK
    """
    code = exit_code(result)
    verdict = {EXIT_OK: "OK", EXIT_PROBLEM: "PROBLEM", EXIT_UNDECIDED: "UNDECIDED"}[code]
    lines = [(f"{result['net']}: {result['places']} places, {result['transitions']} transitions"
              f" -- {verdict}")]
    lines.append(f"  initial marking: {format_marking(result['initial_marking'])}")
    if result["workflow_net"]:
        lines.append(f"  WF-net (i = {result['source_place']}, o = {result['sink_place']})"
                     f"{', free-choice' if result['free_choice'] else ''}")
    else:
        problem = next((v["message"] for v in result["violations"] if v["kind"] == "not_wf_net"), "")
        lines.append(f"  {problem or 'not a WF-net'}")
    lines.extend(_property_lines(result))
    if not result["complete"]:
        error = result.get("error") or ""
        if result.get("method") == "stubborn":
            error = "not built (--method stubborn)"
        lines.append(f"  state space: {error[len('state space '):] if error.startswith('state space ') else error}")
        found = result.get("partial")
        if found:
            facts = [f"{quantity(found['states_explored'], 'state')} ({found['states_expanded']} expanded),"
                     f" {quantity(found['edges_explored'], 'edge')}"]
            if found["deadlock_markings_found"]:
                facts.append(f"{quantity(found['deadlock_markings_found'], 'deadlock')} found")
            lines.append("  found before the limit: " + "; ".join(facts))
    elif result["states"] is not None:
        lines.append(f"  state space: {quantity(result['states'], 'state')},"
                     f" {quantity(result['edges'], 'edge')};"
                     f" at most {quantity(result['max_tokens_place'], 'token')} in a place,"
                     f" {result['max_tokens_marking']} in a marking")
    invariants = result.get("invariants") or {}
    p_flows, t_flows = invariants.get("p_semiflows"), invariants.get("t_semiflows")
    why = invariants.get("not_computed") or {}

    def counted(flows, key):
        if flows is not None:
            return str(len(flows))
        return f"not computed ({why[key]})" if key in why else "not computed"

    too_large = invariants.get("note") if "net too large" in why.values() else None
    lines.append(
        f"  P-semiflows: {counted(p_flows, 'p_semiflows')}"
        f"{' (cover every place)' if invariants.get('covered_by_p_semiflows') else ''};"
        f" T-semiflows: {counted(t_flows, 't_semiflows')}" + (f" ({too_large})" if too_large else ""))
    if result.get("methods") is not None:
        visited = ", ".join(f"{how} {count:,}" for how, count in
                            (result.get("states_visited") or {}).items() if count is not None)
        lines.append(f"  method: {result.get('method', 'auto')}"
                     + (f" (markings stored: {visited})" if visited else ""))
        lines.extend(f"    {note}" for note in result.get("method_notes") or ())
    for violation in result["violations"]:
        if violation["kind"] == "not_wf_net" and not result["workflow_net"]:
            continue
        lines.append(f"  - {violation['message']}")
        if violation["transitions"]:
            lines.append(f"      witness: {' '.join(violation['transitions'])}")
    if not result["complete"]:
        open_ = [name for key, name in _PROPERTIES if result.get(key) is None
                 and (key != "sound" or result["workflow_net"])]
        if code == EXIT_UNDECIDED:
            missing = _answer(result, code)
            key = "sound" if result["workflow_net"] else "bounded" if missing == "bounded" else "deadlock_free"
            lines.append(f"  no verdict: {missing} undecided ({_why_undecided(result, key)})")
        elif open_:
            lines.append(f"  note: {', '.join(open_)} undecided ({_limit(result)}); the verdict"
                         f" ({_answer(result, code)}) does not depend on them")
        else:
            lines.append(f"  note: {_limit(result)}; every property above was decided without it")
    return "\n".join(lines)
