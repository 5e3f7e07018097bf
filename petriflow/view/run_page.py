"""A run's page: the trace replayed in the browser.

The page holds the whole trace (every event, in the columns of
:mod:`petriflow.view.columns`, compressed: nothing of the JSON Lines file is left out,
and each event's full record is rebuilt and shown when it is listed or picked), the
replay computed once (:func:`model`, held as :func:`stored` keeps it), the net
drawn by :func:`petriflow.export.to_dot` with no tokens (the page puts the marking in),
and what it needs to know about the net's transitions. The token game is replayed by
the page's script with the rule of :func:`petriflow.runtime.replay.markings`, so the
marking it shows after event N is the one ``petriflow replay --at N`` prints.
"""

from __future__ import annotations

import html
import json
import re
import tempfile
from pathlib import Path
from typing import Any

from petriflow.errors import PetriflowError
from petriflow.runtime.trace import read_trace
from petriflow.view.columns import encoded
from petriflow.view.page import pack, pack_bytes, render

__all__ = ["run_page", "net_picture", "net_pictures", "subnet_picture", "model", "unpacked", "stored", "restored"]


def net_picture(net: Any) -> tuple[str | None, str | None]:
    """``(svg, None)``: the net drawn with Graphviz without tokens, as inline SVG; or
    ``(None, why)`` when it cannot be drawn (Graphviz missing or failing)."""
    from petriflow.export import to_dot

    return _svg(to_dot(net, {p: 0 for p in net.places}, title=""))


def net_pictures(net: Any, *, subnets: bool = True) -> tuple[str | None, str | None, dict[str, Any] | None]:
    """The net panel's pictures: ``(svg, why, folded)`` as :func:`net_picture`, with
    ``folded`` ``None``; or, for a net ``export`` folds (:func:`petriflow.fold.should_fold`),
    the folded drawing as ``svg`` and ``folded`` = ``{"agent:SUBNET": {"places": [...],
    "svg": packed SVG of the subnet drawn in full}}``, which the panel opens when its box
    is clicked. ``subnets=False``: the subnets are not drawn (``"svg": None``); a page
    that can ask for them draws each when it is opened (:func:`subnet_picture`)."""
    from petriflow.fold import folded_dot, should_fold

    if not should_fold(net):
        svg, why = net_picture(net)
        return svg, why, None
    svg, why = _svg(folded_dot(net, {p: 0 for p in net.places}, title=""))
    if svg is None:
        return None, why, None
    folded: dict[str, Any] = {}
    for subnet in net.subnets:
        inner = subnet_picture(net, f"agent:{subnet}") if subnets else None
        places, _ = net.nodes_of(subnet)
        folded[f"agent:{subnet}"] = {"places": list(places), "svg": None if inner is None else pack(inner)}
    return svg, None, folded


def subnet_picture(net: Any, key: str) -> str | None:
    """The SVG of one agent's subnet drawn in full (``key``: ``agent:SUBNET``, as in
    :func:`net_pictures`' ``folded``); ``None`` for no such subnet or no Graphviz."""
    from petriflow.export import to_dot
    from petriflow.fold import agent_net

    subnet = key[len("agent:"):] if key.startswith("agent:") else None
    if subnet not in net.subnets:
        return None
    part = agent_net(net, subnet)
    inner, _ = _svg(to_dot(part, {p: 0 for p in part.places}, title=part.label or ""))
    return inner


def _svg(source: str) -> tuple[str | None, str | None]:
    """DOT text drawn as inline SVG (comments left out), or ``(None, why)``."""
    from petriflow.export import render as render_dot

    with tempfile.TemporaryDirectory(prefix="petriflow-view-") as folder:
        path = Path(folder) / "net.svg"
        try:
            render_dot(source, path, "svg")
        except PetriflowError as exc:
            return None, str(exc)
        text = path.read_text(encoding="utf-8")
    start = text.find("<svg")
    if start < 0:
        return None, "Graphviz wrote no SVG"
    text = re.sub(r"<!--.*?-->", "", text[start:], flags=re.S)
    return text, None


def _transitions(net: Any, events: list[Any]) -> dict[str, dict[str, Any]]:
    """What the page shows about each transition: label, action, agent."""
    out: dict[str, dict[str, Any]] = {}
    agents = {s.id: (s.agent or s.id) for s in net.subnets.values()} if net is not None else {}
    if net is not None:
        for t in net.transitions.values():
            out[t.id] = {"label": t.label or t.id, "action": t.action, "agent": agents.get(t.subnet) if t.subnet else None}
    for event in events:
        if event.transition and event.transition not in out:
            out[event.transition] = {"label": event.transition, "action": None, "agent": event.agent}
        if event.kind == "start" and event.agent and not out[event.transition].get("agent"):
            out[event.transition]["agent"] = event.agent
    return out


class _Names:
    """Names numbered in the order first seen (``-1`` for none)."""

    def __init__(self, first: list[str] | None = None) -> None:
        self.names: list[str] = []
        self.index: dict[str, int] = {}
        for name in first or []:
            self(name)

    def __call__(self, name: str | None) -> int:
        if name is None:
            return -1
        number = self.index.get(name)
        if number is None:
            number = self.index[name] = len(self.names)
            self.names.append(name)
        return number


def model(events: list[Any], places: list[str] | None = None) -> dict[str, Any]:
    """What the page replays, computed once: per event its kind, time, agent and
    transition (numbers into name tables) and its change to the marking; the firings
    (start and end event, outcome); the messages (send and delivery or loss, paired per
    channel place); the bodies' poses and the world's outlines.

    Indices are stored compactly (compressed pages stay small): ``d_count`` changes per
    event, ``f_start``/``m_send`` as gaps from the previous one, ``f_end``/``m_end`` as
    offsets from their start (``-1``: none), ``seq`` ``None`` when it is the index;
    :func:`unpacked` restores the plain lists.

    The marking changes follow :func:`petriflow.runtime.replay.markings` (the rule
    ``petriflow replay`` prints): after event ``i`` the marking is the sum of the
    changes of events ``0..i``.

    Examples:
        >>> from petriflow.runtime.trace import Event
        >>> m = model([Event(0, 0.0, "run", data={"marking": {"i": 1}}),
        ...            Event(1, 0.0, "start", "t", "a", {"firing": 1, "consumed": {"i": 1}}),
        ...            Event(2, 2.0, "end", "t", "a", {"firing": 1, "outcome": "ok", "produced": {"o": 1}})])
        >>> m["places"], m["d_count"], m["d_place"], m["d_n"]
        (['i', 'o'], [1, 1, 1], [0, 0, 1], [1, -1, 1])
        >>> unpacked(m)["f_start"], unpacked(m)["f_end"], m["outcomes"][m["f_outcome"][0]]
        ([1], [2], 'ok')
    """
    place, agent, transition = _Names(places), _Names(), _Names()
    kinds, outcomes, fates, channels = _Names(), _Names(["ok"]), _Names(), _Names()
    out: dict[str, Any] = {k: [] for k in (
        "kind", "time", "seq", "agent", "transition", "d_start", "d_place", "d_n", "bad",
        "f_start", "f_end", "f_transition", "f_agent", "f_outcome", "f_reason",
        "m_send", "m_end", "m_from", "m_to", "m_fate", "m_why", "m_place", "m_channel", "m_arrival")}
    counts: dict[int, int] = {}
    open_firings: dict[Any, int] = {}
    in_flight: dict[str, list[int]] = {}
    poses: dict[str, list[list[float]]] = {}
    outlines: list[Any] = []
    change = out["d_place"], out["d_n"]

    def add(p: str, n: int) -> None:
        number = place(p)
        counts[number] = counts.get(number, 0) + n
        change[0].append(number)
        change[1].append(n)

    for i, event in enumerate(events):
        data = event.data
        out["kind"].append(kinds(event.kind))
        out["time"].append(event.time)
        out["seq"].append(event.seq)
        out["agent"].append(agent(event.agent))
        out["transition"].append(transition(event.transition))
        out["d_start"].append(len(change[0]))
        out["bad"].append(1 if event.kind in ("fault", "cancel") or (
            event.kind == "end" and data.get("outcome") != "ok") or (
            event.kind == "message" and data.get("fate") == "lost") or (
            event.kind == "custom" and data.get("name") == "property_violated") else 0)
        kind = event.kind
        if kind == "run":
            wanted = {place(p): n for p, n in data.get("marking", {}).items()}
            for number in sorted(set(counts) | set(wanted)):
                n = wanted.get(number, 0) - counts.get(number, 0)
                if n:
                    add(place.names[number], n)
        elif kind == "start":
            for p, n in data.get("consumed", {}).items():
                add(p, -n)
            open_firings[data["firing"]] = len(out["f_start"])
            for key, value in (("f_start", i), ("f_end", -1), ("f_transition", transition(event.transition)),
                               ("f_agent", agent(event.agent)), ("f_outcome", -1), ("f_reason", None)):
                out[key].append(value)
        elif kind == "cancel":
            for p in data.get("withdrawn", {}):
                held = counts.get(place(p), 0)
                if held:
                    add(p, -held)
        elif kind == "end":
            for p, n in data.get("produced", {}).items():
                add(p, n)
            f = open_firings.pop(data.get("firing"), None)
            if f is not None:
                out["f_end"][f] = i
                out["f_outcome"][f] = outcomes(data.get("outcome"))
                out["f_reason"][f] = data.get("reason")
        elif kind == "message":
            fate = data.get("fate")
            if fate in ("delivered", "noticed"):
                add(data["place"], 1)
            queue = in_flight.setdefault(data.get("place"), [])
            if fate == "sent":
                queue.append(len(out["m_send"]))
                _message(out, i, -1, event.agent, data.get("receiver"), None, None, data, agent, fates, channels, place)
                continue
            if fate in ("delivered", "noticed") or (fate == "lost" and data.get("in_flight")):
                m = _take(out, queue, agent(event.agent), event.time)
                if m is not None:
                    out["m_end"][m] = i
                    out["m_fate"][m] = fates(fate)
                    out["m_why"][m] = data.get("why")
                    continue
            _message(out, i, i, event.agent, data.get("receiver"), fate, data.get("why"), data, agent, fates,
                     channels, place)
        elif kind == "control":  # someone steering the run put tokens in or took them out
            for p, n in (data.get("added") or {}).items():
                add(p, n)
            for p, n in (data.get("removed") or {}).items():
                add(p, -n)
        elif kind == "pose":
            if isinstance(data.get("outlines"), list):
                outlines = data["outlines"]
            for name, pose in data.get("poses", {}).items():
                if isinstance(pose, list) and len(pose) >= 2:
                    track = poses.setdefault(name, [[], [], [], [], []])
                    for k, value in enumerate((i, event.time, pose[0], pose[1], pose[2] if len(pose) > 2 else 0.0)):
                        track[k].append(value)
    out["d_start"].append(len(change[0]))
    out["m_fate"] = [fates("in flight") if f is None else f for f in out["m_fate"]]
    # smaller once compressed: counts instead of running offsets, gaps instead of indices
    out["d_count"] = [b - a for a, b in zip(out["d_start"], out["d_start"][1:])]
    out["seq"] = None if out["seq"] == list(range(len(events))) else out["seq"]
    for key, base in (("f_end", "f_start"), ("m_end", "m_send")):
        out[key] = [-1 if e < 0 else e - s for e, s in zip(out[key], out[base])]
    for key in ("f_start", "m_send"):
        out[key] = [b - a for a, b in zip([0] + out[key], out[key])]
    del out["d_start"]
    out.update(places=place.names, agents=agent.names, transitions=transition.names, kinds=kinds.names,
               outcomes=outcomes.names, fates=fates.names, channels=channels.names, poses=poses, outlines=outlines)
    return out


def unpacked(m: dict[str, Any]) -> dict[str, Any]:
    """The :func:`model` with plain lists: ``d_start`` offsets, absolute ``f_start``,
    ``f_end``, ``m_send``, ``m_end`` and ``seq`` (what the page's script computes)."""
    from itertools import accumulate

    out = dict(m)
    out["d_start"] = [0] + list(accumulate(m["d_count"]))
    for key, end in (("f_start", "f_end"), ("m_send", "m_end")):
        out[key] = list(accumulate(m[key]))
        out[end] = [-1 if e < 0 else e + s for e, s in zip(m[end], out[key])]
    out["seq"] = list(range(len(m["kind"]))) if m["seq"] is None else m["seq"]
    return out


def _message(out, send, end, sender, receiver, fate, why, data, agent, fates, channels, place) -> None:
    out["m_send"].append(send)
    out["m_end"].append(end)
    out["m_from"].append(agent(sender))
    out["m_to"].append(agent(receiver))
    out["m_fate"].append(None if fate is None else fates(fate))
    out["m_why"].append(why)
    out["m_place"].append(place(data["place"]) if isinstance(data.get("place"), str) else -1)
    out["m_channel"].append(channels(data.get("channel")) if isinstance(data.get("channel"), str) else -1)
    out["m_arrival"].append(data.get("arrival") if isinstance(data.get("arrival"), (int, float)) else None)


def _take(out: dict[str, Any], queue: list[int], sender: int, time: float) -> int | None:
    """The message in flight on a place that an event (its delivery or loss) ends: the
    first one from the same sender due at ``time``, else the first from that sender,
    else the first."""
    tests = (lambda m: out["m_from"][m] == sender and out["m_arrival"][m] is not None
             and abs(out["m_arrival"][m] - time) < 1e-6,
             lambda m: out["m_from"][m] == sender,
             lambda m: True)
    for test in tests:
        for k, m in enumerate(queue):
            if test(m):
                return queue.pop(k)
    return None


#: The page's scripts, inlined in this order: the shared helpers, the trace decoded, the pure
#: replay (these three run in Node too: tests/view/replay_node.js), one per panel, then the
#: summary and controls that tie them together.
SCRIPTS = ["common.js", "trace.js", "replay.js", "panel-net.js", "panel-world.js", "panel-messages.js",
           "panel-gantt.js", "panel-events.js", "run.js"]

#: What the page needs of each kind of event, never left out to keep it small.
_KEEP = {"run": {"marking", "agents", "net", "seed", "dt"}, "start": {"firing", "consumed"},
         "end": {"firing", "outcome", "produced", "reason"}, "cancel": {"withdrawn", "actions"},
         "message": {"place", "fate", "channel", "receiver", "why", "arrival", "in_flight", "size", "distance"},
         "pose": {"poses", "outlines"}, "custom": {"name", "firing", "property", "event"},
         "feedback": {"firing", "goal", "remote_agent"},
         "control": {"action", "added", "removed", "by", "wall", "spec", "place", "count", "firing", "number",
                     "outcome", "factor", "point", "tokens"}}

#: The largest a run's page should be, in MB (``petriflow view --max-mb``).
DEFAULT_MAX_MB = 20.0


def _shortened(events: list[Any], limit: int | None) -> tuple[list[Any], int]:
    """The events; with ``limit``, each event's data values longer than ``limit``
    characters that the page does not need (token data copied into ``inputs`` and
    ``result``, an action's own reports) replaced by a note saying how long they were
    and on which line of the trace they are. Returns the events and how many lost
    something."""
    if limit is None:
        return events, 0
    out, shortened = [], 0
    for number, event in enumerate(events, start=1):
        keep = _KEEP.get(event.kind)
        data = event.data
        if keep is not None:
            cut = {}
            for key, value in data.items():
                if key not in keep:
                    size = len(json.dumps(value, separators=(",", ":"), default=str))
                    if size > limit:
                        cut[key] = f"<left out of the page: {size} characters; line {number} of the trace>"
            if cut:
                shortened += 1
                event = type(event)(event.seq, event.time, event.kind, event.transition, event.agent, {**data, **cut})
        out.append(event)
    return out, shortened


def stored(m: dict[str, Any], templates: list[int]) -> dict[str, Any]:
    """The :func:`model` as the page holds it, beside the events' columns
    (:mod:`petriflow.view.columns`): without what the page reads from those (each
    event's kind, time, seq, agent and transition; which events start a firing, its
    transition and agent; a message's sender; the poses and outlines of the pose
    events), the events marked failed as gaps between them, and the changes to the
    marking per template (``templates[i]``: event ``i``'s), as the first event of that
    template made them, with the events that made other changes listed apart
    (``d_other``: gap from the previous such event, then its changes as place, n,
    place, n...). :func:`restored` undoes it."""
    out = {k: v for k, v in m.items() if k not in (
        "kind", "time", "seq", "agent", "transition", "bad", "d_count", "d_place", "d_n",
        "f_start", "f_transition", "f_agent", "m_from", "poses", "outlines")}
    bad = [i for i, b in enumerate(m["bad"]) if b]
    out["bad"] = [b - a for a, b in zip([0] + bad, bad)]
    by_template: dict[int, list[int]] = {}
    other: list[Any] = []
    at = last = 0
    for i, (count, template) in enumerate(zip(m["d_count"], templates)):
        change = [x for k in range(at, at + count) for x in (m["d_place"][k], m["d_n"][k])]
        at += count
        known = by_template.setdefault(template, change)
        if known != change:
            other.append([i - last, change])
            last = i
    out["t_change"] = [by_template.get(t, []) for t in range(max(templates, default=-1) + 1)]
    out["d_other"] = other
    return out


def restored(s: dict[str, Any], records: list[dict[str, Any]], templates: list[int]) -> dict[str, Any]:
    """The :func:`model` (its compact form) back from :func:`stored` and the events'
    records and template numbers (as the page's script restores it)."""
    from itertools import accumulate

    from petriflow.runtime.trace import Event

    m = {k: v for k, v in s.items() if k not in ("t_change", "d_other")}
    indices = [i for i, r in enumerate(records) if r["kind"] == "pose"]
    names = {key: {name: k for k, name in enumerate(s[key])} for key in ("agents", "transitions", "kinds")}
    agent = [-1 if r["agent"] is None else names["agents"][r["agent"]] for r in records]
    transition = [-1 if r["transition"] is None else names["transitions"][r["transition"]] for r in records]
    m.update(kind=[names["kinds"][r["kind"]] for r in records], time=[r["time"] for r in records],
             agent=agent, transition=transition)
    seq = [r["seq"] for r in records]
    m["seq"] = None if seq == list(range(len(records))) else seq
    bad = set(accumulate(s["bad"]))
    m["bad"] = [1 if i in bad else 0 for i in range(len(records))]
    other = dict(zip(accumulate(gap for gap, _ in s["d_other"]), (change for _, change in s["d_other"])))
    m["d_count"], m["d_place"], m["d_n"] = [], [], []
    for i, t in enumerate(templates):
        change = other.get(i, s["t_change"][t])
        m["d_count"].append(len(change) // 2)
        m["d_place"].extend(change[0::2])
        m["d_n"].extend(change[1::2])
    starts = [i for i, r in enumerate(records) if r["kind"] == "start"]
    m["f_start"] = [b - a for a, b in zip([0] + starts, starts)]
    m["f_transition"] = [transition[i] for i in starts]
    m["f_agent"] = [agent[i] for i in starts]
    m["m_from"] = [agent[i] for i in accumulate(s["m_send"])]
    poses = model([Event.from_dict(r) for r in records if r["kind"] == "pose"])
    m["outlines"] = poses["outlines"]
    m["poses"] = {body: [[indices[k] for k in track[0]], *track[1:]]
                  for body, track in poses["poses"].items()}
    return m


def run_page(trace: str | Path, *, net: str | Path | None = None, max_mb: float = DEFAULT_MAX_MB,
             trace_name: str | None = "") -> str:
    """The HTML of the page of ``trace`` (optionally drawing ``net``). The page names the
    trace by ``trace_name`` (default: its file name; ``None``: no trace file to name, as
    for a run's ``--view`` without ``--trace``).

    Raises:
        NetFormatError: the trace or the net is malformed (file, line, what).
        PetriflowError: the trace was not recorded on ``net``.
    """
    trace = Path(trace)
    events = read_trace(trace)
    if not events:
        raise PetriflowError(f"{trace}: the trace holds no event")
    loaded = None
    svg, why, folded = None, "no net given (--net NET draws it)", None
    if net is not None:
        from petriflow.io import load_net

        loaded = load_net(net)
        unknown = sorted({e.transition for e in events if e.transition and e.transition not in loaded.transitions})
        if unknown:
            raise PetriflowError(f"{trace} was not recorded on {net}: it fires {', '.join(unknown[:3])},"
                                 " which the net does not have")
        svg, why, folded = net_pictures(loaded)
    first = events[0].data if events[0].kind == "run" else {}
    replay = model(events, list(loaded.places) if loaded is not None else None)
    pictures = len(pack(svg or "")) + sum(len(f["svg"] or "") for f in (folded or {}).values())
    budget = max_mb * 1e6 - pictures - 200_000  # the page's own code and styles
    shortened, limit = 0, None
    for limit in (None, 1024, 256, 64):  # each event whole, else its bulky data left out, less and less
        kept, shortened = _shortened(events, limit)
        block, templates = encoded(kept)
        packed = pack_bytes(block)
        replayed = pack(json.dumps(stored(replay, templates), separators=(",", ":"), allow_nan=False))
        if len(packed) + len(replayed) <= budget:
            break
    name = str(first.get("net") or trace.stem)
    data = {
        "kind": "run",
        "name": name,
        "trace": trace.name if trace_name == "" else trace_name,
        "net_file": None if net is None else Path(net).name,
        "seed": first.get("seed"),
        "events": len(events),
        "trace_bytes": trace.stat().st_size,
        "columns": packed,
        "model": replayed,
        "shortened": {"events": shortened, "limit": limit, "max_mb": max_mb} if shortened else None,
        "svg": None if svg is None else pack(svg),
        "svg_missing": why if svg is None else None,
        "folded": folded,
        "net_places": list(loaded.places) if loaded is not None else [],
        "transition_info": _transitions(loaded, events),
        "run_agents": [str(a) for a in first.get("agents") or []],
    }
    title = f"{name}: run (seed {first.get('seed')})"
    data["page_bytes"] = 0
    page = render(title=title, body=_BODY.replace("{title}", html.escape(title)), data=data,
                  scripts=SCRIPTS, styles=["common.css", "run.css"])
    data["page_bytes"] = len(page.encode("utf-8"))
    return render(title=title, body=_BODY.replace("{title}", html.escape(title)), data=data,
                  scripts=SCRIPTS, styles=["common.css", "run.css"])


_BODY = """
<header>
  <h1>{title}</h1>
  <div id="summary"></div>
</header>
<div id="loading">loading the trace…</div>
<section id="controls" class="bar">
  <button id="b-first" title="first event">|◀</button>
  <button id="b-prev" title="previous event (←)">◀</button>
  <button id="b-play" title="play / pause (space)">play</button>
  <button id="b-next" title="next event (→)">▶</button>
  <button id="b-last" title="last event">▶|</button>
  <input id="slider" type="range" min="0" max="0" value="0" step="1" aria-label="event">
  <label>speed <select id="speed">
    <option value="0.5">0.5×</option><option value="1">1×</option><option value="5" selected>5×</option>
    <option value="20">20×</option><option value="100">100×</option><option value="-1">event by event</option>
  </select></label>
  <span id="now"></span>
</section>
<main>
  <section class="panel wide" id="p-net"><h2>Net <small>marking after the chosen event; running transitions lit with their action and time; failed or cancelled firings marked; wheel: zoom, drag: pan, double click: all</small></h2>
    <div id="net"></div></section>
  <section class="panel" id="p-world"><h2>World from above <small>poses, trails, links that carried a message in the last <span id="link-window">5</span> s</small></h2>
    <canvas id="world" width="640" height="420"></canvas><div id="world-note" class="note"></div></section>
  <section class="panel" id="p-seq"><h2>Messages <small>sent → delivered, lost ✕ with the reason; ±<select id="seq-window">
    <option value="10" selected>10</option><option value="30">30</option><option value="120">120</option><option value="0">all</option></select> s around now</small></h2>
    <canvas id="seq" width="640" height="380"></canvas><div id="seq-note" class="note"></div></section>
  <section class="panel wide" id="p-gantt"><h2>Firings per agent <small>ok, failed, timeout, cancelled; click to go there</small></h2>
    <canvas id="gantt" width="640" height="300"></canvas></section>
  <section class="panel wide" id="p-events"><h2>Events</h2>
    <div class="bar" id="filters">
      <label>agent <select id="f-agent"><option value="">all</option></select></label>
      <label>transition <input id="f-transition" list="transition-list" placeholder="any"></label>
      <datalist id="transition-list"></datalist>
      <label>kind <select id="f-kind"><option value="">all</option></select></label>
      <span id="f-count"></span>
    </div>
    <div id="events"><div id="events-spacer"></div></div>
    <pre id="event-detail"></pre>
  </section>
</main>
"""
