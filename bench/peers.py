"""Peer libraries fed the same nets as petriflow, for benchmarks and tests only.

PM4Py is AGPL-licensed: it is used here, beside the project, never by the
``petriflow`` package itself.
"""

from __future__ import annotations

import platform
from typing import Any

from petriflow.net import Net

__all__ = ["to_pm4py", "versions"]


def to_pm4py(net: Net) -> tuple[Any, Any, dict[str, Any]]:
    """``(PetriNet, initial Marking, {place id: PM4Py place})`` of a petriflow net.

    Transitions keep their ids as names and their labels as PM4Py labels; output arcs
    reserved for an action outcome are left out (plain P/T semantics).
    """
    from pm4py.objects.petri_net.obj import Marking, PetriNet
    from pm4py.objects.petri_net.utils import petri_utils

    pnet = PetriNet(net.id)
    nodes: dict[str, Any] = {}
    for place in net.places:
        nodes[place] = PetriNet.Place(place)
        pnet.places.add(nodes[place])
    for transition in net.transitions.values():
        nodes[transition.id] = PetriNet.Transition(transition.id, transition.label or transition.id)
        pnet.transitions.add(nodes[transition.id])
    for arc in net.arcs:
        if arc.outcome is None:
            petri_utils.add_arc_from_to(nodes[arc.source], nodes[arc.target], pnet, weight=arc.weight)
    initial = Marking({nodes[p]: k for p, k in net.initial_marking.items()})
    return pnet, initial, {p: nodes[p] for p in net.places}


def versions(*distributions: str) -> dict[str, str]:
    """Python's version and each installed distribution's ("not installed" if absent)."""
    from importlib.metadata import PackageNotFoundError, version

    found = {"python": platform.python_version()}
    for name in distributions:
        try:
            found[name] = version(name)
        except PackageNotFoundError:
            found[name] = "not installed"
    return found
