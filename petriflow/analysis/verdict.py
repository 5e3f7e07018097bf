"""The verdict of ``petriflow check``: its exit code, as the rest of the command line.

* ``0`` (:data:`EXIT_OK`) — the net is a sound WF-net, or (not a WF-net) bounded and
  deadlock-free, where a dead marking equal to the net's declared final marking counts
  as proper termination (``deadlock_free`` keeps the MCC's strict meaning;
  ``stuck_markings`` counts the dead markings other than the final one);
* ``1`` (:data:`EXIT_PROBLEM`) — a property fails (the ``violations`` say which, with
  witnesses), also when found before the state limit or by another method;
* ``2`` (:data:`EXIT_UNDECIDED`) — no verdict: the state space exceeds
  ``--max-states`` (``"complete": false`` in the JSON, a one-line message on standard
  error) and nothing found before the limit fails (a deadlock, or for a WF-net improper
  completion or a dead end, found before it gives ``1``), or the net file is bad input.

A state space stopped at the limit when the verdict was reached anyway (``0`` or ``1``)
is no error: ``check`` prints nothing on standard error.
"""

from __future__ import annotations

from typing import Any

__all__ = ["EXIT_OK", "EXIT_PROBLEM", "EXIT_UNDECIDED", "exit_code"]

EXIT_OK, EXIT_PROBLEM, EXIT_UNDECIDED = 0, 1, 2


def exit_code(result: dict[str, Any]) -> int:
    """0: sound WF-net, or bounded and deadlock-free; 1: a property fails; 2: no verdict.

    A result stopped at the state limit (``complete`` false) is 1 when what was found
    before the limit already fails (a deadlock, improper completion, a dead end in a
    WF-net), else 2.

    Examples:
        >>> exit_code({"complete": False})
        2
        >>> exit_code({"complete": True, "workflow_net": False, "bounded": True,
        ...            "deadlock_free": False})
        1
    """
    if not result.get("complete", True):
        # Stopped at the limit: a definite failure found on the way still fails; a
        # verdict another method reached (the Rank Theorem, stubborn sets) still holds.
        decided = result.get("methods") or {}
        if result.get("workflow_net"):
            if result.get("sound") is False:
                return EXIT_PROBLEM
            return EXIT_OK if result.get("sound") and decided.get("sound") else EXIT_UNDECIDED
        found = any(v.get("kind") == "deadlock" for v in result.get("violations", ()))
        if found or result.get("bounded") is False:
            return EXIT_PROBLEM
        return EXIT_OK if result.get("bounded") and result.get("stuck_markings") == 0 \
            and decided.get("stuck_markings") else EXIT_UNDECIDED
    if result.get("workflow_net"):
        return EXIT_OK if result.get("sound") else EXIT_PROBLEM
    stuck = result.get("stuck_markings")
    terminates = result.get("deadlock_free") if stuck is None else stuck == 0
    return EXIT_OK if result.get("bounded") and terminates else EXIT_PROBLEM
