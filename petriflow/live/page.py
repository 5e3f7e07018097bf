"""The live page: the net with its marking as the run goes, the firings running, the
latest events, and the controls (pause, resume, step, breakpoints, tokens, forced
outcomes, speed).

The page is made from the net alone (no trace: the run's state comes over the
WebSocket, :mod:`petriflow.live.server`), and only when a page is first asked for
(:class:`LivePage`): a run served live that nobody watches draws nothing, and the
drawing is done in the server's thread, not before the run. It reuses the run page's
net panel (``panel-net.js``, the same picture as ``petriflow view``); a net too big to
draw readably (the threshold ``export`` folds at, :func:`petriflow.fold.should_fold`)
is drawn folded, one box per agent, and a click on a box opens that agent's subnet,
which is drawn then (:meth:`LivePage.part`, served at ``/part?key=agent:SUBNET``) and
kept: the 20-robot mission's 22 subnets cost a second of Graphviz that a page opening
one of them does not need.
"""

from __future__ import annotations

import html
import threading
from typing import Any

from petriflow.view.page import render

__all__ = ["live_page", "LivePage"]

SCRIPTS = ["common.js", "panel-net.js", "live.js"]


def live_page(net: Any, *, subnets: bool = True) -> str:
    """The HTML of the live page of a run of ``net``; ``subnets=False``: a folded net's
    subnets are left out, for the page to ask for when one is opened."""
    from petriflow.view.page import pack
    from petriflow.view.run_page import net_pictures

    svg, why, folded = net_pictures(net, subnets=subnets)
    agents = {s.id: (s.agent or s.id) for s in net.subnets.values()}
    data = {
        "kind": "live",
        "name": net.id,
        "svg": None if svg is None else pack(svg),
        "svg_missing": why if svg is None else None,
        "folded": folded,
        "net_places": list(net.places),
        "transition_info": {t.id: {"label": t.label or t.id, "action": t.action,
                                   "agent": agents.get(t.subnet) if t.subnet else None}
                            for t in net.transitions.values()},
    }
    title = f"{net.id}: live run"
    about = net.label if net.label and net.label != net.id else ""  # the net's own description
    body = _BODY.replace("{title}", html.escape(title)).replace("{about}", html.escape(about))
    return render(title=f"{title}: {about}" if about else title, body=body, data=data, scripts=SCRIPTS,
                  styles=["common.css", "run.css"], connect=True)


class LivePage:
    """A run's live page and the pictures of its subnets, each made when first asked
    for, then kept (thread-safe: the server asks from its own threads).

    Args:
        net: the net run.
    """

    def __init__(self, net: Any) -> None:
        self.net = net
        self._lock = threading.Lock()
        self._page: bytes | None = None
        self._parts: dict[str, bytes | None] = {}

    def page(self) -> bytes:
        """The page's HTML (UTF-8)."""
        with self._lock:
            if self._page is None:
                self._page = live_page(self.net, subnets=False).encode("utf-8")
            return self._page

    def part(self, key: str) -> bytes | None:
        """The SVG of the subnet ``key`` (``agent:SUBNET``) drawn in full; ``None`` for
        no such subnet (or no Graphviz)."""
        from petriflow.view.run_page import subnet_picture

        with self._lock:
            if key not in self._parts:
                svg = subnet_picture(self.net, key)
                if svg is None:
                    return None
                self._parts[key] = svg.encode("utf-8")
            return self._parts[key]


_BODY = """
<header>
  <h1>{title}</h1>
  <div id="about" class="note">{about}</div>
  <div id="summary"><span id="status">connecting…</span></div>
</header>
<section id="controls" class="bar">
  <button id="c-pause" title="stop at the next firing">pause</button>
  <button id="c-resume" title="go on">resume</button>
  <button id="c-step" title="let this many firings happen, then pause">step</button>
  <input id="c-step-n" type="number" min="1" value="1" size="3" aria-label="firings per step">
  <label>speed <input id="c-speed" type="number" min="0" step="0.5" value="1" size="4"
    title="times real time; 0: as fast as it goes"></label><button id="c-speed-set">set</button>
  <span id="c-reply" role="status"></span>
</section>
<section class="bar" id="c-more">
  <label>breakpoint <input id="c-break" size="24" placeholder="transition T | place P >= N | lost | failed"
    list="c-break-hints"></label><button id="c-break-add">add</button>
  <datalist id="c-break-hints"><option value="failed"><option value="lost"></datalist>
  <span id="c-breaks"></span>
  <label>place <input id="c-place" size="14" list="c-places"></label>
  <datalist id="c-places"></datalist>
  <input id="c-count" type="number" min="1" value="1" size="3" aria-label="tokens">
  <button id="c-inject">inject</button><button id="c-remove">remove</button>
  <label>firing <select id="c-firing"></select></label>
  <select id="c-outcome"><option value="failed">failed</option><option value="ok">ok</option>
    <option value="cancel">cancel</option></select>
  <button id="c-force">force</button>
</section>
<main>
  <section class="panel wide" id="p-net"><h2>Net <small>the marking now; running transitions lit with their action and
    time; failed or cancelled firings marked; wheel: zoom, drag: pan, double click: all</small></h2>
    <div id="net"></div></section>
  <section class="panel" id="p-running"><h2>Running</h2><ol id="running"></ol></section>
  <section class="panel" id="p-events"><h2>Latest events <small>newest first; the trace has them all</small></h2>
    <div id="events-live"></div></section>
</main>
"""
