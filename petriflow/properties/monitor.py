"""Properties watched while a net runs: safety on every marking, LTL on the finite trace.

:class:`PropertyMonitor` is a run observer (:meth:`Scheduler.on_event
<petriflow.runtime.scheduler.Scheduler.on_event>`). The run's markings are the marking
at the start and the one after each event that moves tokens (a firing's start consumes
its inputs, its end produces the outputs, a cancellation withdraws; tokens of a running
action are in neither place). On that sequence of markings:

* **safety** (``never``, ``always``, ``AG p``): ``p`` is checked on every marking; the
  first marking violating it is reported with the event that made it (sequence number,
  time, kind, transition), and the monitor records a ``custom`` event
  ``property_violated`` (naming the property and that event) after the instant, so the
  trace marks the spot;
* **bounds**: the most tokens the places held together (and, with ``at_most``, a
  violation when it is exceeded, as for safety);
* **reachability** (``reachable``, ``EF p``): ``true`` once a marking satisfies ``p``,
  else ``null`` (a finite run that has not seen it says nothing about the net);
* **LTL** (``eventually``, ``responds``, ``ltl``): evaluated at the end on the finite
  trace with the usual finite-trace semantics (LTLf): ``X p`` needs a next marking (false
  at the last one), ``G p`` means at every remaining marking of the run, ``F p`` at some,
  ``p U q`` as usual within the run. So ``responds`` fails when a request is still
  unanswered when the run ends. A run's verdict is about that run, not the net;
* CTL formulas with nested path quantifiers (``AG EF p``) speak of branches a run does
  not take: not monitored (``null``, with the reason).

``enabled(t)`` is read structurally (``t``'s input places hold enough tokens), without
guards. Only the places the properties read are looked at: the monitor subscribes to
the starts of the transitions that take from them, the ends of those that put into
them (but for a channel place, whose tokens come as messages) and the messages that
arrive in them (``delivered``, ``noticed``) (``Scheduler.on_event(..., transitions=, places=)``),
so the run builds no event for the other firings and computes no message distance for
it; an event that moves none of those places is skipped (so the LTL trace's positions
are the markings after events that change those places). Results: :meth:`PropertyMonitor.results`, one entry per property like ``check``'s
(``verdict``, ``method``, and ``violation``: ``{"seq", "time", "kind", "transition"}``).

Examples:
    >>> from petriflow.io.yaml import loads_net
    >>> from petriflow.runtime.scheduler import Scheduler
    >>> from petriflow.runtime.observers import run_observed
    >>> net = loads_net('''
    ... {petriflow: 1, places: [{id: home, tokens: 1}, way, gate],
    ...  transitions: [{id: leave, in: [home], out: [way]}, {id: stop, in: [way], out: [gate]}],
    ...  properties: [{id: never_gate, never: "gate >= 1"}, {id: ends, eventually: "gate == 1"}]}
    ... ''')
    >>> scheduler = Scheduler(net)
    >>> monitor = PropertyMonitor(net, net.properties)
    >>> monitor.attach(scheduler)
    >>> _ = run_observed(scheduler)
    >>> [(r["id"], r["verdict"]) for r in monitor.results()]
    [('never_gate', False), ('ends', True)]
    >>> monitor.results()[0]["violation"]["transition"]
    'stop'
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from petriflow.net import Net
from petriflow.properties.language import (
    AllPaths, And, Compare, Constant, Deadlock, ExistsPath, Finally, Fireable, Formula, Globally, Next,
    Not, Or, Property, Until, atoms
)

__all__ = ["PropertyMonitor", "compile_predicate", "holds_on_trace"]

#: The event kinds after which the marking may have changed.
MOVING_KINDS = ("run", "start", "end", "cancel", "message", "fault")
#: Those the monitor hears whatever they are about (the others: only those about the
#: transitions and places its properties read).
WHOLE_KINDS = ("run", "cancel", "fault")
#: The fates of the messages that put a token into their place (a message sent or
#: lost moves none).
ARRIVING = ("delivered", "noticed")  # petriflow.runtime.channel_models.Fate values

def holds_on_trace(formula: Formula, trace: Sequence[Mapping[Formula, bool]], at: int = 0) -> bool:
    """LTLf: whether the path formula holds at position ``at`` of a finite trace, each
    position giving the value of the formula's atoms (:func:`~petriflow.properties.language.atoms`)."""
    return _ltlf(formula, trace)[at]


def _ltlf(formula: Formula, trace: Sequence[Mapping[Formula, bool]]) -> list[bool]:
    n = len(trace)
    if formula in trace[0]:
        return [step[formula] for step in trace]
    if isinstance(formula, Not):
        return [not v for v in _ltlf(formula.operand, trace)]
    if isinstance(formula, (And, Or)):
        parts = [_ltlf(f, trace) for f in formula.operands]
        combine = all if isinstance(formula, And) else any
        return [combine(p[i] for p in parts) for i in range(n)]
    if isinstance(formula, Next):
        inner = _ltlf(formula.operand, trace)
        return inner[1:] + [False]
    if isinstance(formula, (Finally, Globally, Until)):
        if isinstance(formula, Until):
            left, right = _ltlf(formula.left, trace), _ltlf(formula.right, trace)
        elif isinstance(formula, Finally):
            left, right = [True] * n, _ltlf(formula.operand, trace)
        else:      # G p = ¬F¬p
            left, right = [True] * n, [not v for v in _ltlf(formula.operand, trace)]
        out, later = [False] * n, False
        for i in range(n - 1, -1, -1):
            later = right[i] or (left[i] and later)
            out[i] = later
        return [not v for v in out] if isinstance(formula, Globally) else out
    if isinstance(formula, Constant):
        return [formula.value] * n
    raise ValueError(f"not an LTL path formula: {formula}")


def compile_predicate(net: Net, formula: Formula, index: Mapping[str, int]):
    """A state predicate as a function of the run's token counts (a list indexed by
    ``index[place]``): Python source built from the formula's integers and indices
    only (no name or text of the file reaches it), compiled once, so that checking a
    marking costs a few comparisons.

    Examples:
        >>> from petriflow.properties.yaml_props import parse_formula
        >>> from petriflow.net import Net
        >>> check = compile_predicate(Net(), parse_formula("a + 2*b <= 3"), {"a": 0, "b": 1})
        >>> check([1, 1]), check([2, 1])
        (True, False)
    """
    def linear(expression) -> str:
        terms = [f"{int(k)}*m[{int(index[p])}]" for p, k in expression.terms]
        return " + ".join(terms + [str(int(expression.offset))])

    def enabled(transition: str) -> str:
        need = [f"m[{int(index[p])}] >= {int(w)}" for p, w in net.preset(transition).items()]
        return "(" + (" and ".join(need) or "True") + ")"

    def source(node: Formula) -> str:
        if isinstance(node, Constant):
            return "True" if node.value else "False"
        if isinstance(node, Compare):
            return f"(({linear(node.left)}) {node.op} ({linear(node.right)}))"
        if isinstance(node, Fireable):
            return "(" + (" or ".join(enabled(t) for t in node.transitions) or "False") + ")"
        if isinstance(node, Deadlock):
            return "(not (" + (" or ".join(enabled(t) for t in net.transitions) or "False") + "))"
        if isinstance(node, Not):
            return f"(not {source(node.operand)})"
        if isinstance(node, (And, Or)):   # an empty conjunction is true, an empty disjunction false
            joiner, empty = (" and ", "True") if isinstance(node, And) else (" or ", "False")
            return "(" + (joiner.join(source(f) for f in node.operands) or empty) + ")"
        raise ValueError(f"not a state predicate: {node}")

    return eval(compile(f"lambda m: {source(formula)}", "<property>", "eval"), {"__builtins__": {}})  # noqa: S307


class PropertyMonitor:
    """Watches a run for the net's properties (see the module documentation).

    Args:
        net: the net that runs.
        properties: what to watch (usually ``net.properties``).
    """

    def __init__(self, net: Net, properties: Sequence[Property]) -> None:
        self.net = net
        self.properties = list(properties)
        self.scheduler: Any = None
        self._kind: dict[str, str] = {}
        self._predicate: dict[str, Formula] = {}
        self._violation: dict[str, dict[str, Any]] = {}
        self._seen: dict[str, dict[str, Any]] = {}
        self._most: dict[str, tuple[int, dict[str, Any] | None]] = {}
        self._atoms: list[Formula] = []
        self._trace: list[dict[Formula, bool]] = []
        self.markings = 0
        self._every_step = _has_next(self.properties)
        self._pending: list[tuple[str | None, dict[str, Any]]] = []
        for prop in self.properties:
            formula = prop.formula
            if formula is None:
                self._kind[prop.id] = "bound"
            elif isinstance(formula, AllPaths) and isinstance(formula.operand, Globally) \
                    and not _temporal(formula.operand.operand):
                self._kind[prop.id], self._predicate[prop.id] = "safety", formula.operand.operand
            elif isinstance(formula, ExistsPath) and isinstance(formula.operand, Finally) \
                    and not _temporal(formula.operand.operand):
                self._kind[prop.id], self._predicate[prop.id] = "reachability", formula.operand.operand
            elif isinstance(formula, AllPaths) and not _quantified(formula.operand):
                self._kind[prop.id] = "ltl"
                self._atoms.extend(a for a in atoms(formula.operand) if a not in self._atoms)
            else:
                self._kind[prop.id] = "branching"
        self._read = self._places_read()
        self._tokens: Any = None

    def _places_read(self) -> tuple[str, ...]:
        """The places the monitored properties read (``enabled``/``deadlock``: presets)."""
        read: dict[str, None] = {}
        for prop in self.properties:
            kind = self._kind[prop.id]
            if kind == "bound":
                read.update(dict.fromkeys(prop.bound))
            elif kind != "branching":
                for node in prop.formula.walk():
                    if isinstance(node, Compare):
                        read.update(dict.fromkeys(p for p, _ in node.left.terms + node.right.terms))
                    elif isinstance(node, (Fireable, Deadlock)):
                        names = node.transitions if isinstance(node, Fireable) else tuple(self.net.transitions)
                        for t in names:
                            read.update(dict.fromkeys(self.net.preset(t)))
        return tuple(read)

    def attach(self, scheduler: Any) -> None:
        """Subscribe to ``scheduler``'s events (before the run starts)."""
        self.scheduler = scheduler
        self._tokens = scheduler.tokens
        index = self._tokens.index
        self._check = {pid: compile_predicate(self.net, f, index) for pid, f in self._predicate.items()}
        self._atom_checks = [(a, compile_predicate(self.net, a, index)) for a in self._atoms]
        self._bound_columns = {p.id: [index[q] for q in dict.fromkeys(p.bound)] for p in self.properties
                               if p.formula is None}
        self._relevant = read = frozenset(self._read)
        net = self.net
        taking = [t for t in net.transitions if not read.isdisjoint(net.preset(t))]
        # a channel place's tokens arrive by message, not at the end of the firing that sends
        giving = list(dict.fromkeys(t for p in read if net.places[p].channel is None for t in net.place_preset(p)))
        # only what the properties read: the firings that take from or put into their
        # places, the messages into them (no event is built for the others)
        scheduler.on_event(self, WHOLE_KINDS)
        scheduler.on_event(self, ("start",), transitions=taking)
        scheduler.on_event(self, ("end",), transitions=giving)
        scheduler.on_event(self, ("message",), places=read, fields={"fate": ARRIVING})
        scheduler.on_instant(self._flush)

    def _marking(self) -> dict[str, int]:
        """The counts of the places read, now (for a report)."""
        counts, index = self._tokens.counts, self._tokens.index
        return {p: counts[index[p]] for p in self._read}

    def __call__(self, event: Any) -> None:
        """One event: check the marking it leaves, when it moved tokens the properties read."""
        if event.kind == "start" or event.kind == "end":
            moved = event.data.get("consumed" if event.kind == "start" else "produced") or ()
            if self.markings and self._relevant.isdisjoint(moved):
                return
        counts = self._tokens.counts
        self.markings += 1
        for prop in self.properties:
            kind = self._kind[prop.id]
            if kind == "safety" and prop.id not in self._violation:
                if not self._check[prop.id](counts):
                    self._violate(prop, event)
            elif kind == "reachability" and prop.id not in self._seen:
                if self._check[prop.id](counts):
                    self._seen[prop.id] = _where(event)
            elif kind == "bound":
                total = sum(counts[i] for i in self._bound_columns[prop.id])
                if prop.id not in self._most or total > self._most[prop.id][0]:
                    self._most[prop.id] = (total, _where(event))
                if prop.at_most is not None and total > prop.at_most and prop.id not in self._violation:
                    self._violate(prop, event)
        if self._atoms:
            step = {a: check(counts) for a, check in self._atom_checks}
            if not self._trace or step != self._trace[-1] or self._every_step:
                self._trace.append(step)

    def _violate(self, prop: Property, event: Any) -> None:
        where = _where(event)
        marking = self._marking()
        self._violation[prop.id] = where
        # recorded once the event being handled is done (an event handler must not emit)
        self._pending.append((where["transition"], {"name": "property_violated", "property": prop.id,
                                                    "event": where["seq"],
                                                    "marking": {p: c for p, c in marking.items() if c}}))

    def _flush(self, scheduler: Any = None) -> None:
        """After an instant: record the violations found as ``custom`` events."""
        pending, self._pending = self._pending, []
        for transition, data in pending:
            self.scheduler.emit("custom", transition, None, **data)

    def results(self) -> list[dict[str, Any]]:
        """One entry per property: ``{"id", "kind", "verdict", "method", "violation"?}``."""
        self._pending = []  # a violation in the last instant: the run is over, its events closed
        out = []
        for prop in self.properties:
            kind = self._kind[prop.id]
            entry: dict[str, Any] = {"id": prop.id, "kind": kind, "verdict": None}
            if kind == "safety":
                entry.update(verdict=prop.id not in self._violation, method="every marking of the run")
            elif kind == "reachability":
                entry.update(verdict=True if prop.id in self._seen else None, method="markings of the run")
                if prop.id in self._seen:
                    entry["seen"] = self._seen[prop.id]
            elif kind == "bound":
                most, where = self._most.get(prop.id, (0, None))
                entry.update(bound_reached=most, method="markings of the run", at=where)
                entry["verdict"] = most if prop.at_most is None else prop.id not in self._violation
            elif kind == "ltl":
                entry["method"] = "LTL on the finite trace (LTLf)"
                entry["verdict"] = bool(self._trace) and holds_on_trace(prop.formula.operand, self._trace)
            else:
                entry["reason"] = "a branching-time (CTL) property: a single run cannot decide it"
            if prop.id in self._violation:
                entry["violation"] = self._violation[prop.id]
            out.append(entry)
        return out


def _where(event: Any) -> dict[str, Any]:
    return {"seq": event.seq, "time": event.time, "kind": event.kind, "transition": event.transition}


def _temporal(formula: Formula) -> bool:
    return any(isinstance(n, (Next, Finally, Globally, Until, AllPaths, ExistsPath)) for n in formula.walk())


def _quantified(formula: Formula) -> bool:
    return any(isinstance(n, (AllPaths, ExistsPath)) for n in formula.walk())


def _has_next(properties: Sequence[Property]) -> bool:
    """Whether some LTL formula uses X: then every marking is a step (no stutter folding)."""
    return any(p.formula is not None and any(isinstance(n, Next) for n in p.formula.walk()) for p in properties)
