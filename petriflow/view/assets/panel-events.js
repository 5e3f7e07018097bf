/* A run's page: the events, filtered, and the chosen one's whole record. */
"use strict";
/** #events: `draw(i, follow)`, `listed()` (rows shown), `filtered()`; a click on a row goes there. */
PF.eventsPanel = function (view) {
  const trace = view.trace, replay = view.replay, N = trace.count;
  const agentOf = replay.agentOf, kindOf = replay.kindOf, transOf = replay.transOf;
  const list = { rows: new Int32Array(0), rowH: 18, nodes: [], follow: true, drawnAt: 0 };

  function describe(ev) {
    const d = ev.data, who = ev.agent ? ` [${ev.agent}]` : "";
    switch (ev.kind) {
      case "start": return `fire   ${ev.transition}${who} (firing ${d.firing})`;
      case "end": return `end    ${ev.transition}${who} ${d.outcome}${d.reason ? ": " + d.reason : ""}`;
      case "message": return `msg    ${d.place} via ${d.channel}${who}${d.receiver ? " → " + d.receiver : ""}: ${d.fate}${d.why ? " (" + d.why + ")" : ""}`;
      case "fault": return `fault  ${d.fault}${who} ${d.link || ""}`;
      case "cancel": return `cancel by ${ev.transition}: places ${Object.keys(d.withdrawn || {}).sort().join(", ")}`;
      case "run": return `run    ${d.net} seed ${d.seed}`;
      case "stop": return `stop   ${d.reason} after ${d.firings} firings`;
      case "pose": return `pose   ${Object.keys(d.poses || {}).length} bodies${d.outlines ? ", " + d.outlines.length + " outlines" : ""}`;
      case "feedback": return `fb     ${ev.transition}${who} from ${d.remote_agent} (firing ${d.firing}): ${JSON.stringify(d.data).slice(0, 100)}`;
      case "custom": if (d.name === "property_violated") return PF.violation(ev);
      default: return `${ev.kind} ${ev.transition || ""}${who} ${JSON.stringify(d).slice(0, 120)}`;
    }
  }

  function setup() {
    const agents = replay.agents, kinds = replay.kinds, transitions = replay.transitions;
    const agentSel = document.getElementById("f-agent");
    for (const a of agents) { const o = document.createElement("option"); o.value = a; o.textContent = a; agentSel.appendChild(o); }
    const kindSel = document.getElementById("f-kind");
    for (const k of kinds) { const o = document.createElement("option"); o.value = k; o.textContent = k; kindSel.appendChild(o); }
    const dl = document.getElementById("transition-list");
    for (const t of transitions) { const o = document.createElement("option"); o.value = t; dl.appendChild(o); }
    for (const id of ["f-agent", "f-kind"]) document.getElementById(id).addEventListener("change", filter);
    document.getElementById("f-transition").addEventListener("input", filter);
    const box = document.getElementById("events");
    box.addEventListener("scroll", () => { list.top = box.scrollTop; renderList(); });
    box.addEventListener("wheel", () => { list.follow = false; }, { passive: true });
    box.addEventListener("click", e => {
      const row = e.target.closest(".row");
      if (row) { list.follow = true; view.go(parseInt(row.dataset.index, 10), false); }
    });
  }

  function filter() {
    const agent = document.getElementById("f-agent").value;
    const kind = document.getElementById("f-kind").value;
    const t = document.getElementById("f-transition").value.trim();
    const a = agent ? replay.agents.indexOf(agent) : -2, kd = kind ? replay.kinds.indexOf(kind) : -2;
    const ts = t ? new Set(replay.transitions.map((name, k) => name.includes(t) ? k : -9).filter(k => k >= 0)) : null;
    const out = new Int32Array(N);
    let n = 0;
    for (let k = 0; k < N; k++) {
      if (a !== -2 && agentOf[k] !== a) continue;
      if (kd !== -2 && kindOf[k] !== kd) continue;
      if (ts && !ts.has(transOf[k])) continue;
      out[n++] = k;
    }
    list.rows = out.slice(0, n);
    document.getElementById("f-count").textContent = `${n} of ${N} events`;
    document.getElementById("events-spacer").style.height = out.length * list.rowH + "px";
    list.follow = true;
    scrollListTo(view.index);
    renderList();
  }

  function boxHeight() {
    if (!list.height || list.resized !== window.innerWidth + "x" + window.innerHeight) {
      list.height = document.getElementById("events").clientHeight;
      list.resized = window.innerWidth + "x" + window.innerHeight;
    }
    return list.height;
  }

  function scrollListTo(i) {
    const box = document.getElementById("events");
    const k = PF.lastAtMost(list.rows, i);
    if (k < 0) return;
    const y = k * list.rowH;
    const top = list.top === undefined ? box.scrollTop : list.top, height = boxHeight();
    if (y < top || y > top + height - list.rowH) { list.top = Math.max(0, y - height / 2); box.scrollTop = list.top; }
  }

  function renderList() {
    const box = document.getElementById("events");
    const top = list.top === undefined ? box.scrollTop : list.top;
    const first = Math.max(0, Math.floor(top / list.rowH) - 5);
    const last = Math.min(list.rows.length, first + Math.ceil(boxHeight() / list.rowH) + 10);
    let n = 0;
    for (let k = first; k < last; k++, n++) {
      let node = list.nodes[n];
      if (!node) { node = document.createElement("div"); box.appendChild(node); list.nodes.push(node); }
      const idx = list.rows[k], e = trace.event(idx);
      node.style.display = "";
      node.style.top = k * list.rowH + "px";
      node.dataset.index = String(idx);
      node.dataset.agent = e.agent || "";
      node.className = "row k-" + e.kind + (idx === view.index ? " current" : "") + (replay.bad[idx] ? " failed" : "");
      node.textContent = `${String(e.seq).padStart(7)}  t=${e.time.toFixed(3).padStart(10)}  ${describe(e)}`;
    }
    for (; n < list.nodes.length; n++) list.nodes[n].style.display = "none";
  }

  function draw(i, follow) {
    if (follow !== false) list.follow = true;
    const wall = performance.now();
    if (!view.playing || wall - list.drawnAt > 250) {  // while playing, the list catches up four times a second
      list.drawnAt = wall;
      if (list.follow) scrollListTo(i);
      renderList();
      document.getElementById("event-detail").textContent = JSON.stringify(trace.event(i), null, 1);
    }
  }

  setup();
  filter();
  return {
    draw,
    listed: () => Array.from(document.querySelectorAll("#events .row")).filter(n => n.style.display !== "none")
      .map(n => ({ index: parseInt(n.dataset.index, 10), agent: n.dataset.agent })),
    filtered: () => Array.from(list.rows),
  };
};
