/* petriflow run --live: the run's page fed as it goes (a snapshot on connecting, then what changed),
   and its controls. Everything goes over one WebSocket to the server the page came from, with the
   run's token (from the page's own address); the page keeps a bounded window of events. */
"use strict";
(function () {
  const D = PF.data;
  const token = new URLSearchParams(location.search).get("token") || "";
  const places = D.net_places.slice();
  const placeIndex = new Map(places.map((p, i) => [p, i]));
  const live = {
    counts: new Array(places.length).fill(0), running: [], failures: [], time: 0, seq: -1,
    events: [], window: 400, control: { paused: false, steps: 0, breakpoints: [] }, stop: null,
    connected: false, snapshotAt: null, updates: 0, received: 0, violations: [],
  };
  let socket = null, nextId = 1, panel = null;
  const waiting = new Map();

  /** The run page's net panel, fed the live state: event "0" is always now. */
  const view = {
    data: D,
    trace: { times: [0] },
    replay: {
      places, placeIndex,
      markingAt: () => live.counts.slice(),
      runningAt: () => live.running.map(f => ({ t: f.t, ts: f.since })),
      failedAt: (i, recent) => new Map(live.failures.filter(f => live.time - f.time <= recent).map(f => [f.t, f])),
    },
    /** A folded net's subnet, drawn by the server when it is first opened. */
    part: key => fetch(`/part?key=${encodeURIComponent(key)}&token=${encodeURIComponent(token)}`)
      .then(r => (r.ok ? r.text() : null)),
  };

  function setMarking(marking, whole) {
    if (whole) live.counts = new Array(places.length).fill(0);
    else live.counts = live.counts.slice();
    for (const [p, n] of Object.entries(marking)) {
      let i = placeIndex.get(p);
      if (i === undefined) { i = places.length; places.push(p); placeIndex.set(p, i); live.counts.push(0); }
      live.counts[i] = n;
    }
  }

  function addEvents(events) {
    live.received += events.length;
    for (const e of events) {
      live.events.push(e);
      if (e.kind === "custom" && e.data && e.data.name === "property_violated") live.violations.push(e);
    }
    if (live.events.length > live.window) live.events.splice(0, live.events.length - live.window);
  }

  function describe(e) {
    const d = e.data || {};
    const who = e.agent ? ` [${e.agent}]` : "";
    switch (e.kind) {
      case "start": return `fire   ${e.transition}${who} (firing ${d.firing})`;
      case "end": return `end    ${e.transition}${who} ${d.outcome}${d.reason ? ": " + d.reason : ""}`;
      case "message": return `msg    ${d.place} ${d.fate}${who}`;
      case "control": {
        const what = ["spec", "place", "count", "firing", "outcome", "factor"].filter(k => k in d).map(k => d[k]).join(" ");
        return `ctl    ${d.action} ${what}${d.by ? " by " + d.by : ""}`;
      }
      case "stop": return `stop   ${d.reason} after ${d.firings} firings`;
      case "run": return `run    ${d.net} seed ${d.seed}`;
      case "feedback": return `fb     ${e.transition}${who} from ${d.remote_agent} (firing ${d.firing}): ${JSON.stringify(d.data).slice(0, 100)}`;
      case "custom": if (d.name === "property_violated") return PF.violation(e);
      default: return `${e.kind} ${e.transition || ""}${who}`;
    }
  }

  function show() {
    view.trace.times[0] = live.time;
    if (panel) panel.draw(0);
    const c = live.control || {};
    const state = live.stop ? `ended: ${live.stop.reason}` : !live.connected ? "disconnected"
      : c.paused ? (c.steps ? `stepping (${c.steps} left)` : "paused") : "running";
    document.getElementById("status").textContent =
      `t = ${live.time.toFixed(3)} s · event ${live.seq} · ${live.running.length} running · ${state}` +
      live.violations.map(e => ` · ${PF.violation(e)}`).join("");
    document.body.dataset.state = state.split(":")[0].split(" ")[0];
    document.getElementById("c-breaks").textContent = (c.breakpoints || []).length
      ? "breakpoints: " + c.breakpoints.join("; ") : "";
    const running = document.getElementById("running");
    running.textContent = "";
    const select = document.getElementById("c-firing");
    const chosen = select.value;
    select.textContent = "";
    for (const f of live.running) {
      const li = document.createElement("li");
      li.textContent = `${f.t}${f.agent ? " [" + f.agent + "]" : ""} · firing ${f.firing} · ${(live.time - f.since).toFixed(1)} s`;
      running.appendChild(li);
      const option = document.createElement("option");
      option.value = String(f.firing);
      option.textContent = `${f.t} (firing ${f.firing})`;
      select.appendChild(option);
    }
    if ([...select.options].some(o => o.value === chosen)) select.value = chosen;
    const list = document.getElementById("events-live");
    const shown = live.events.slice(-60).reverse();
    list.textContent = "";
    for (const e of shown) {
      const div = document.createElement("div");
      const violated = e.kind === "custom" && e.data && e.data.name === "property_violated";
      div.className = "row k-" + e.kind + ((e.data && e.data.outcome && e.data.outcome !== "ok") || violated ? " failed" : "");
      div.textContent = `${String(e.seq).padStart(6)}  t=${e.time.toFixed(3).padStart(9)}  ${describe(e)}`;
      list.appendChild(div);
    }
  }

  function received(message) {
    const m = JSON.parse(message.data);
    if (m.type === "snapshot") {
      live.window = m.window || live.window;
      live.run = m.run;
      setMarking(m.marking, true);
      live.events = [];
      addEvents(m.events);
      live.snapshotAt = performance.now();
    } else if (m.type === "events") {
      setMarking(m.marking, false);
      addEvents(m.events);
      live.updates += 1;
    } else if (m.type === "reply") {
      const done = waiting.get(m.id);
      waiting.delete(m.id);
      document.getElementById("c-reply").textContent = (m.ok ? "" : "refused: ") + m.message;
      if (m.control) live.control = m.control;
      if (done) done(m);
      show();
      return;
    }
    for (const key of ["time", "seq", "running", "failures", "stop", "control"]) if (m[key] !== undefined) live[key] = m[key];
    show();
    if (m.type === "snapshot") { window.pfLive.ready = true; window.pfLive.readyMs = performance.now(); }
  }

  /** Send a command; resolves with the server's reply. */
  function send(command, args) {
    return new Promise(resolve => {
      if (!socket || socket.readyState !== WebSocket.OPEN) { resolve({ ok: false, message: "not connected" }); return; }
      const id = nextId++;
      waiting.set(id, resolve);
      socket.send(JSON.stringify({ id, command, args: args || {}, by: "page" }));
    });
  }

  function controls() {
    const n = id => Math.max(1, parseInt(document.getElementById(id).value, 10) || 1);
    const on = (id, f) => document.getElementById(id).addEventListener("click", f);
    on("c-pause", () => send("pause"));
    on("c-resume", () => send("resume"));
    on("c-step", () => send("step", { count: n("c-step-n") }));
    on("c-speed-set", () => send("speed", { factor: parseFloat(document.getElementById("c-speed").value) }));
    on("c-break-add", () => send("break", { spec: document.getElementById("c-break").value }));
    on("c-inject", () => send("inject", { place: document.getElementById("c-place").value, count: n("c-count") }));
    on("c-remove", () => send("remove", { place: document.getElementById("c-place").value, count: n("c-count") }));
    on("c-force", () => send("force", { firing: document.getElementById("c-firing").value,
                                        outcome: document.getElementById("c-outcome").value }));
    const hints = document.getElementById("c-places");
    for (const p of D.net_places) { const o = document.createElement("option"); o.value = p; hints.appendChild(o); }
    const breaks = document.getElementById("c-break-hints");
    for (const t of Object.keys(D.transition_info)) {
      const o = document.createElement("option"); o.value = "transition " + t; breaks.appendChild(o);
    }
  }

  async function main() {
    const svg = D.svg ? await PF.inflate(D.svg) : null;
    panel = PF.netPanel(view, svg);
    controls();
    const scheme = location.protocol === "https:" ? "wss:" : "ws:";
    socket = new WebSocket(`${scheme}//${location.host}/ws?token=${encodeURIComponent(token)}`);
    socket.addEventListener("open", () => { live.connected = true; });
    socket.addEventListener("message", received);
    socket.addEventListener("close", () => { live.connected = false; show(); });
  }

  window.pfLive = {
    ready: false,
    send,
    get state() { return live.stop ? "ended" : live.control && live.control.paused ? "paused" : "running"; },
    get time() { return live.time; },
    get stop() { return live.stop; },
    get violations() { return live.violations.map(e => ({ property: e.data.property, event: e.data.event })); },
    get control() { return live.control; },
    get events() { return live.events.length; },
    get received() { return live.received; },
    get window() { return live.window; },
    get updates() { return live.updates; },
    marking() { const out = {}; places.forEach((p, i) => { if (live.counts[i] > 0) out[p] = live.counts[i]; }); return out; },
    shownMarking: () => panel.shown(),
    running: () => live.running.map(f => f.t),
  };

  main().catch(err => { PF.showError("The live page could not start: " + err); console.error(err); });
})();
