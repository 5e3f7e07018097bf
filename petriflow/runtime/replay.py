"""Replaying a recorded run: markings rebuilt from a trace, printed or drawn.

A trace holds enough to rebuild the token game without running anything: the
``run`` event has the initial marking, ``start`` events the tokens consumed,
``cancel`` events the tokens withdrawn, ``end`` events the tokens produced, and
``message`` events the tokens delivered through channels, and ``control`` events the
tokens someone put in or took out while steering the run.
"""

from __future__ import annotations

from pathlib import Path
from typing import Iterable, Iterator

from petriflow.errors import PetriflowError
from petriflow.marking import Marking
from petriflow.runtime.trace import Event, read_trace

__all__ = ["markings", "replay", "describe", "running_at"]


def markings(events: Iterable[Event]) -> Iterator[tuple[Event, Marking]]:
    """Yield each event with the marking right after it."""
    counts: dict[str, int] = {}
    for event in events:
        data = event.data
        if event.kind == "run":
            counts = dict(data.get("marking", {}))
        elif event.kind == "start":
            for place, n in data.get("consumed", {}).items():
                counts[place] = counts.get(place, 0) - n
        elif event.kind == "cancel":
            for place in data.get("withdrawn", {}):
                counts[place] = 0
        elif event.kind == "end":
            for place, n in data.get("produced", {}).items():
                counts[place] = counts.get(place, 0) + n
        elif event.kind == "message" and data.get("fate") in ("delivered", "noticed"):
            counts[data["place"]] = counts.get(data["place"], 0) + 1
        elif event.kind == "control":  # someone put tokens in or took them out
            for place, n in (data.get("added") or {}).items():
                counts[place] = counts.get(place, 0) + n
            for place, n in (data.get("removed") or {}).items():
                counts[place] = counts.get(place, 0) - n
        yield event, Marking({p: c for p, c in counts.items() if c > 0})


def describe(event: Event, labels: dict[str, str] | None = None) -> str:
    """One readable line for an event; a transition with a label (``labels``: the run
    event's, ``{id: label}``) is named by it, its id beside it.

    Examples:
        >>> describe(Event(1, 0.0, "start", "n18", None, {"firing": 1}), {"n18": "register"})
        'fire   register (n18) (firing 1)'
    """
    who = f" [{event.agent}]" if event.agent else ""
    data = event.data
    name = event.transition
    if labels and name in labels:
        name = f"{labels[name]} ({name})"
    if event.kind == "start":
        return f"fire   {name}{who} (firing {data['firing']})"
    if event.kind == "end":
        extra = f": {data['reason']}" if data.get("reason") else ""
        return f"end    {name}{who} {data['outcome']}{extra}"
    if event.kind == "message":
        return f"msg    {data.get('place')} via {data.get('channel')}{who}: {data.get('fate')}"
    if event.kind == "fault":
        return f"fault  {data.get('fault')}{who} {data.get('link', '')}".rstrip()
    if event.kind == "cancel":
        return f"cancel by {event.transition}: places {sorted(data.get('withdrawn', {}))}," \
               f" actions {data.get('actions', [])}"
    if event.kind == "run":
        return f"run    {data.get('net')} seed {data.get('seed')}"
    if event.kind == "stop":
        return f"stop   {data.get('reason')} after {data.get('firings')} firings"
    if event.kind == "control":
        what = " ".join(str(data[k]) for k in ("spec", "place", "count", "firing", "outcome", "factor") if k in data)
        by = f" by {data['by']}" if data.get("by") else ""
        return f"ctl    {data.get('action')} {what}{by}".rstrip()
    return f"{event.kind:6} {event.transition or ''}{who} {data}"


def running_at(events: Iterable[Event]) -> dict[str, dict[str, int]]:
    """``{transition: {place: tokens}}`` of the firings started and not yet ended after
    ``events``: their actions are running and hold the tokens they consumed.

    Examples:
        >>> start = Event(1, 0.0, "start", "walk", None, {"firing": 1, "consumed": {"home": 1}})
        >>> running_at([start])
        {'walk': {'home': 1}}
    """
    open_firings: dict[int, tuple[str, dict[str, int]]] = {}
    for event in events:
        if event.kind == "start":
            open_firings[event.data["firing"]] = (event.transition, dict(event.data.get("consumed", {})))
        elif event.kind == "end":
            open_firings.pop(event.data.get("firing"), None)
    return {transition: held for transition, held in open_firings.values()}


def replay(trace: str | Path, *, net_path: str | Path | None = None, draw: str | Path | None = None,
           at: int | None = None) -> int:
    """Print the token game of ``trace`` (up to event ``at``); optionally draw the marking,
    with the transitions still running at that event and the tokens they hold.

    Every option is checked before anything is printed.

    Returns:
        The command's exit code (0).
    """
    net = None
    if draw is not None:
        if net_path is None:
            raise PetriflowError("--draw needs --net (the net the trace was recorded on)")
        from petriflow.export import format_of
        from petriflow.io import load_net

        format_of(draw)  # the picture's format from its ending, before any work
        from petriflow.runtime.outputs import check_outputs

        check_outputs({"--draw": draw}, [trace, net_path])
        net = load_net(net_path)
    elif net_path is not None:
        raise PetriflowError("--net is only used with --draw")
    events = read_trace(trace)
    if at is not None:
        if not 0 <= at < len(events):
            raise PetriflowError(f"--at must be an event number from 0 to {len(events) - 1}")
        events = events[: at + 1]
    if net is not None:
        unknown = sorted({e.transition for e in events if e.transition and e.transition not in net.transitions})
        if unknown:
            raise PetriflowError(f"{trace} was not recorded on {net_path}: it fires {', '.join(unknown[:3])},"
                                 " which the net does not have")
    last = Marking()
    labels = events[0].data.get("labels") if events and events[0].kind == "run" else None
    labels = labels if isinstance(labels, dict) else None
    for event, marking in markings(events):
        shown = ", ".join(f"{p}={c}" for p, c in marking.items()) or "(empty)"
        print(f"{event.seq:6d}  t={event.time:10.3f}  {describe(event, labels):48}  {shown}")
        last = marking
    if draw is not None and net is not None:
        from petriflow.export import export_net

        running = running_at(events)
        seq = events[-1].seq if events else 0
        caption = f"the marking after event {seq} (t = {events[-1].time:g} s)" if events else None
        if running:
            caption += "; blue: actions running, holding the tokens they took"
        export_net(net, draw, marking=net.check_marking(last), running=running, caption=caption)
        print(f"drew the marking after event {seq} to {draw}")
    return 0
