/* petriflow view: a run's page. Replays the trace held (in columns, compressed) in the page:
   the token game by the rule of petriflow.runtime.replay.markings, the firings, the
   messages and the world's poses, at the event the slider chooses. */
"use strict";
(function () {
  const D = PF.data;
  const CHECKPOINT = 256;           // a marking is kept every so many events
  const TRAIL = 30;                 // seconds of trail behind each robot
  const LINK_WINDOW = 5;            // seconds a delivered message's link stays drawn
  const MAX_ARROWS = 600;          // messages drawn at most in the sequence chart
  const RECENT = 5;                 // seconds a failed/cancelled firing stays marked in the net

  let N = 0;                        // events
  let M = null;                     // the model petriflow.view.run_page.model computed
  const parsed = new Map();         // events' records rebuilt, the last few thousand shown
  let times = null, kindOf = null, agentOf = null, transOf = null, bad = null;
  let dStart = null, dPlace = null, dN = null;
  let placeNames = [];
  const placeIndex = new Map();
  let checkpoints = [];             // Int32Array of counts before event c*CHECKPOINT
  let firings = [];                 // {t, agent, s, e, ts, te, outcome, reason}
  let firingStarts = null;          // Int32Array of start indices (sorted)
  const lastEnded = new Map();      // transition -> its firings that ended not ok
  let messages = [];                // {s, e, ts, te, from, to, fate, why, place, channel}
  let messageTimes = null;
  let arrivals = [], arrivalTimes = null;   // messages that ended, by the time they ended
  let messageCounts = "";
  const bodies = new Map();         // name -> {idx, t, x, y, yaw}
  let outlines = [];
  let lifelines = [], lifelineIndex = new Map();
  let current = 0;
  let playing = false;

  // The events' columns (petriflow.view.columns): templates and the numbers they miss -----
  let STEP = 256;                   // where each column is read is kept every so many events (more
                                    // with very many columns: at most about 2 million positions kept)
  const E = { templates: [], columns: [], uses: [], timeAt: [], order: null, seq: null, cursors: [] };

  /** The columns of the block petriflow.view.columns.encode wrote, decoded; the templates parsed. */
  function readColumns(bytes) {
    const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
    const size = view.getUint32(0, true);
    const header = JSON.parse(new TextDecoder().decode(bytes.subarray(4, 4 + size)));
    let at = 4 + size;
    for (const about of header.columns) {
      const n = about.count, values = new Float64Array(n);
      if (about.type === "f") {
        for (let k = 0; k < n; k++) values[k] = view.getFloat64(at + 8 * k, true);
      } else {
        let p = at;
        for (let k = 0; k < n; k++) {
          let u = 0, scale = 1, b;
          do { b = bytes[p++]; u += (b & 127) * scale; scale *= 128; } while (b >= 128);
          values[k] = u % 2 ? -(u + 1) / 2 : u / 2;
        }
        if (about.delta === 1) for (let k = 1; k < n; k++) values[k] += values[k - 1];
      }
      at += about.bytes;
      E.columns.push({ values, strings: about.strings || null, delta: about.delta, scale: about.type === "d" ? about.scale : 0 });
    }
    E.templates = header.templates;
    E.order = E.columns[header.template].values;
    E.seq = header.seq === null ? null : E.columns[header.seq].values;
    const mark = text => text.slice(1).split(".").map(Number);
    for (const t of E.templates) {
      const counts = new Map();
      const walk = v => {
        if (typeof v === "string") {
          if (v.charCodeAt(0) === 1) { const [c, j] = mark(v); counts.set(c, Math.max(counts.get(c) || 0, j + 1)); }
        } else if (Array.isArray(v)) v.forEach(walk);
        else if (v && typeof v === "object") Object.values(v).forEach(walk);
      };
      walk(t[3]); walk(t[4]);
      E.uses.push(Int32Array.from([].concat(...counts.entries())));
      E.timeAt.push(typeof t[4] === "string" && t[4].charCodeAt(0) === 1 ? mark(t[4]) : null);
    }
    const N = header.events;
    STEP = Math.max(256, Math.ceil(N * E.columns.length / 2e6));
    if (E.columns.some(c => c.delta === 2)) {   // each value less the one before at its template's place
      const last = E.templates.map(() => new Map()), cursor = new Int32Array(E.columns.length);
      for (let i = 0; i < N; i++) {
        const t = E.order[i], uses = E.uses[t];
        for (let k = 0; k < uses.length; k += 2) {
          const c = uses[k], n = uses[k + 1], column = E.columns[c];
          if (column.delta === 2) {
            let before = last[t].get(c);
            if (!before) last[t].set(c, (before = new Float64Array(n)));
            for (let j = 0; j < n; j++) before[j] = (column.values[cursor[c] + j] += before[j]);
          }
          cursor[c] += n;
        }
      }
    }
    for (const column of E.columns) {
      if (column.scale) { const d = 10 ** column.scale; for (let k = 0; k < column.values.length; k++) column.values[k] /= d; }
    }
    // each event's time; where each column is read, every STEP events
    const cursor = new Int32Array(E.columns.length);
    const out = new Float64Array(N);
    for (let i = 0; i < N; i++) {
      if (i % STEP === 0) E.cursors.push(Int32Array.from(cursor));
      const t = E.order[i], at = E.timeAt[t], uses = E.uses[t];
      out[i] = at ? E.columns[at[0]].values[cursor[at[0]] + at[1]] : E.templates[t][4];
      for (let k = 0; k < uses.length; k += 2) cursor[uses[k]] += uses[k + 1];
    }
    return out;
  }

  /** Event i's record, rebuilt from its template and columns (as its JSON line has it). */
  function record(i) {
    const c0 = Math.floor(i / STEP), cursor = Int32Array.from(E.cursors[c0]);
    for (let k = c0 * STEP; k < i; k++) {
      const uses = E.uses[E.order[k]];
      for (let q = 0; q < uses.length; q += 2) cursor[uses[q]] += uses[q + 1];
    }
    const fill = v => {
      if (typeof v === "string") {
        if (v.charCodeAt(0) !== 1) return v;
        const dot = v.indexOf("."), c = +v.slice(1, dot), column = E.columns[c];
        const x = column.values[cursor[c] + +v.slice(dot + 1)];
        return column.strings ? column.strings[x] : x;
      }
      if (Array.isArray(v)) return v.map(fill);
      if (v && typeof v === "object") {
        const o = {};
        for (const key of Object.keys(v)) Object.defineProperty(o, key, { value: fill(v[key]), enumerable: true, writable: true });
        return o;
      }
      return v;
    };
    const [kind, transition, agent, data, time] = E.templates[E.order[i]];
    return { agent, data: fill(data), kind, seq: seqOf(i), time: fill(time), transition };
  }

  function seqOf(i) { return E.seq ? E.seq[i] : i; }

  /** Event i as recorded (rebuilt once, while it stays among the last few thousand shown). */
  function ev(i) {
    let e = parsed.get(i);
    if (!e) {
      e = record(i);
      if (parsed.size > 5000) parsed.clear();
      parsed.set(i, e);
    }
    return e;
  }

  // The token game: event i changes place dPlace[k] by dN[k], dStart[i] <= k < dStart[i+1]
  function markingAt(i) {
    const c = Math.floor(i / CHECKPOINT);
    const counts = Int32Array.from(checkpoints[c]);
    for (let k = dStart[c * CHECKPOINT]; k < dStart[i + 1]; k++) counts[dPlace[k]] += dN[k];
    return counts;
  }

  function markingObject(counts) {
    const out = {};
    counts.forEach((n, k) => { if (n > 0) out[placeNames[k]] = n; });
    return out;
  }

  // Reading the model once ---------------------------------------------------------------
  function index() {
    // what the page reads from the columns rather than the model (see petriflow.view.run_page.stored)
    N = E.order.length;
    const numbers = key => new Map(M[key].map((name, k) => [name, k]));
    const kinds = numbers("kinds"), agents = numbers("agents"), transitions = numbers("transitions");
    const tKind = E.templates.map(t => kinds.get(t[0]));
    const tTransition = E.templates.map(t => (t[1] === null ? -1 : transitions.get(t[1])));
    const tAgent = E.templates.map(t => (t[2] === null ? -1 : agents.get(t[2])));
    kindOf = new Int8Array(N); agentOf = new Int32Array(N); transOf = new Int32Array(N); bad = new Uint8Array(N);
    const other = new Map();
    let at = 0;
    for (const [gap, change] of M.d_other) other.set((at += gap), change);
    const change = i => other.get(i) || M.t_change[E.order[i]];
    dStart = new Int32Array(N + 1);
    for (let i = 0; i < N; i++) {
      const t = E.order[i];
      kindOf[i] = tKind[t]; agentOf[i] = tAgent[t]; transOf[i] = tTransition[t];
      dStart[i + 1] = dStart[i] + change(i).length / 2;
    }
    dPlace = new Int32Array(dStart[N]); dN = new Int32Array(dStart[N]);
    for (let i = 0; i < N; i++) {
      const c = change(i);
      for (let k = 0; k < c.length; k += 2) { dPlace[dStart[i] + k / 2] = c[k]; dN[dStart[i] + k / 2] = c[k + 1]; }
    }
    at = 0;
    for (const gap of M.bad) bad[(at += gap)] = 1;
    const start = kinds.get("start");
    M.f_start = [];
    for (let i = 0; i < N; i++) if (kindOf[i] === start) M.f_start.push(i);
    M.f_end = M.f_end.map((offset, k) => (offset < 0 ? -1 : offset + M.f_start[k]));
    M.f_transition = M.f_start.map(i => transOf[i]);
    M.f_agent = M.f_start.map(i => agentOf[i]);
    at = 0;
    M.m_send = M.m_send.map(gap => (at += gap));
    M.m_end = M.m_end.map((offset, k) => (offset < 0 ? -1 : offset + M.m_send[k]));
    M.m_from = M.m_send.map(i => agentOf[i]);
    placeNames = M.places;
    placeNames.forEach((p, k) => placeIndex.set(p, k));
    const counts = new Int32Array(placeNames.length);
    for (let i = 0; i < N; i++) {
      if (i % CHECKPOINT === 0) checkpoints.push(Int32Array.from(counts));
      for (let k = dStart[i]; k < dStart[i + 1]; k++) counts[dPlace[k]] += dN[k];
    }
    const name = (table, k) => (k < 0 ? null : table[k]);
    for (let f = 0; f < M.f_start.length; f++) {
      const s = M.f_start[f], e = M.f_end[f];
      const firing = { t: name(M.transitions, M.f_transition[f]), agent: name(M.agents, M.f_agent[f]), s, e,
                       ts: times[s], te: e < 0 ? Infinity : times[e], outcome: name(M.outcomes, M.f_outcome[f]),
                       reason: M.f_reason[f] };
      firings.push(firing);
      if (e >= 0 && firing.outcome !== "ok") {
        if (!lastEnded.has(firing.t)) lastEnded.set(firing.t, []);
        lastEnded.get(firing.t).push(firing);
      }
    }
    firingStarts = Int32Array.from(M.f_start);
    for (let m = 0; m < M.m_send.length; m++) {
      const s = M.m_send[m], e = M.m_end[m];
      messages.push({ s, e, ts: times[s], te: e >= 0 ? times[e] : M.m_arrival[m], from: name(M.agents, M.m_from[m]),
                      to: name(M.agents, M.m_to[m]), fate: M.fates[M.m_fate[m]], why: M.m_why[m],
                      place: name(M.places, M.m_place[m]), channel: name(M.channels, M.m_channel[m]) });
    }
    messages.sort((a, b) => a.ts - b.ts || a.s - b.s);
    messageTimes = Float64Array.from(messages, m => m.ts);
    arrivals = messages.filter(m => m.e >= 0).sort((a, b) => a.te - b.te);
    arrivalTimes = Float64Array.from(arrivals, m => m.te);
    const fateCounts = {};
    for (const m of messages) fateCounts[m.fate] = (fateCounts[m.fate] || 0) + 1;
    messageCounts = `${messages.length} messages: ` + Object.entries(fateCounts).map(([k, v]) => `${v} ${k}`).join(", ");
    // the bodies' poses and the world's outlines, from the pose events (as run_page.model reads them)
    const tracks = new Map(), pose = kinds.get("pose");
    for (let i = 0; i < N; i++) {
      if (kindOf[i] !== pose) continue;
      const d = record(i).data;
      if (Array.isArray(d.outlines)) outlines = d.outlines;
      for (const [body, p] of Object.entries(d.poses || {})) {
        if (!Array.isArray(p) || p.length < 2) continue;
        if (!tracks.has(body)) tracks.set(body, [[], [], [], [], []]);
        const track = tracks.get(body);
        [i, times[i], p[0], p[1], p.length > 2 ? p[2] : 0].forEach((v, k) => track[k].push(v));
      }
    }
    for (const [body, track] of tracks) {
      bodies.set(body, { idx: Int32Array.from(track[0]), t: Float64Array.from(track[1]), x: Float64Array.from(track[2]),
                         y: Float64Array.from(track[3]), yaw: Float64Array.from(track[4]) });
    }
    const names = new Set(D.run_agents);
    for (const m of messages) { if (m.from) names.add(m.from); if (m.to) names.add(m.to); }
    lifelines = Array.from(names);
    if (messages.some(m => !m.from || !m.to)) lifelines.push("(net)");
    lifelines.forEach((n, k) => lifelineIndex.set(n, k));
  }

  function runningAt(i) {
    const out = [];
    const last = PF.lastAtMost(firingStarts, i);
    for (let k = 0; k <= last; k++) {
      const f = firings[k];
      if (f.e < 0 || f.e > i) out.push(f);
    }
    return out;
  }

  // The net ------------------------------------------------------------------------------
  const net = { places: new Map(), transitions: new Map(), shown: null, status: new Map() };

  let netSvg = null;               // the net's picture (SVG text), inflated

  function setupNet() {
    const box = document.getElementById("net");
    if (!netSvg) {
      box.id = "marking-list";
      box.innerHTML = "";
      const note = document.createElement("div");
      note.className = "note";
      note.textContent = "The net is not drawn: " + D.svg_missing + ". The places and their tokens:";
      box.appendChild(note);
      const table = document.createElement("table");
      table.innerHTML = "<thead><tr><th class='text'>place</th><th>tokens</th></tr></thead>";
      const body = document.createElement("tbody");
      for (const p of placeNames) {
        const tr = document.createElement("tr");
        tr.dataset.place = p;
        tr.innerHTML = "<td class='text'></td><td class='n'>0</td>";
        tr.firstChild.textContent = p;
        body.appendChild(tr);
        net.places.set(p, { row: tr, cell: tr.lastChild });
      }
      table.appendChild(body);
      box.appendChild(table);
      return;
    }
    box.innerHTML = netSvg;            // Graphviz's own SVG, as export writes it (no script in it)
    const svg = box.querySelector("svg");
    svg.removeAttribute("width"); svg.removeAttribute("height");
    const NS = "http://www.w3.org/2000/svg";
    const netPlaces = new Set(D.net_places);
    /** A shape's box from its own coordinates (no layout: getBBox on a large SVG is slow). */
    const box2 = shape => {
      const text = shape.getAttribute("points") || shape.getAttribute("d") || "";
      const v = (text.match(/-?[0-9.]+(?:e-?[0-9]+)?/g) || []).map(Number);
      let x0 = Infinity, y0 = Infinity, x1 = -Infinity, y1 = -Infinity;
      for (let k = 0; k + 1 < v.length; k += 2) {
        x0 = Math.min(x0, v[k]); x1 = Math.max(x1, v[k]); y0 = Math.min(y0, v[k + 1]); y1 = Math.max(y1, v[k + 1]);
      }
      return isFinite(x0) ? { x: x0, y: y0, width: x1 - x0, height: y1 - y0 } : { x: 0, y: 0, width: 0, height: 0 };
    };
    for (const g of svg.querySelectorAll("g.node")) {
      const title = g.querySelector("title");
      if (!title) continue;
      const id = title.textContent;
      if (netPlaces.has(id)) {
        const shape = g.querySelector("ellipse");
        if (!shape) continue;
        const text = document.createElementNS(NS, "text");
        text.setAttribute("class", "pf-tokens");
        text.setAttribute("x", shape.getAttribute("cx"));
        text.setAttribute("y", String(parseFloat(shape.getAttribute("cy")) + 4.5));
        text.setAttribute("text-anchor", "middle");
        g.appendChild(text);
        g.dataset.place = id;
        net.places.set(id, { g, text });
      } else if (D.transition_info[id]) {
        const shape = g.querySelector("polygon, path");
        let x = 0, y = 0;
        if (shape) {
          const b = box2(shape);
          x = b.x + b.width / 2; y = b.y + b.height + 10;
        }
        const text = document.createElementNS(NS, "text");
        text.setAttribute("class", "pf-status");
        text.setAttribute("x", String(x)); text.setAttribute("y", String(y));
        text.setAttribute("text-anchor", "middle");
        g.appendChild(text);
        g.dataset.transition = id;
        net.transitions.set(id, { g, text });
      }
    }
    panZoom(box, svg);
  }

  /** Wheel zooms around the pointer, dragging pans (the SVG's viewBox). */
  function panZoom(box, svg) {
    const vb = svg.viewBox.baseVal;
    if (!vb || !vb.width) return;
    const set = (x, y, w, h) => svg.setAttribute("viewBox", `${x} ${y} ${w} ${h}`);
    // start readable: fill the box in one direction (at most life size), from the top left
    const r0 = box.getBoundingClientRect();
    const cover = Math.min(1.0, Math.max(r0.width / vb.width, r0.height / vb.height));
    const home = [vb.x, vb.y, r0.width / cover, r0.height / cover];
    const whole = [vb.x, vb.y, vb.width, vb.height];
    set(...home);
    box.addEventListener("wheel", e => {
      e.preventDefault();
      const r = box.getBoundingClientRect();
      const scale = Math.min(r.width / vb.width, r.height / vb.height);
      const fx = vb.x + (e.clientX - r.left - (r.width - vb.width * scale) / 2) / scale;
      const fy = vb.y + (e.clientY - r.top - (r.height - vb.height * scale) / 2) / scale;
      const k = e.deltaY > 0 ? 1.15 : 1 / 1.15;
      set(fx - (fx - vb.x) * k, fy - (fy - vb.y) * k, vb.width * k, vb.height * k);
    }, { passive: false });
    let drag = null;
    box.addEventListener("mousedown", e => { drag = [e.clientX, e.clientY, vb.x, vb.y]; });
    window.addEventListener("mouseup", () => { drag = null; });
    window.addEventListener("mousemove", e => {
      if (!drag) return;
      const r = box.getBoundingClientRect();
      const scale = Math.min(r.width / vb.width, r.height / vb.height);
      set(drag[2] - (e.clientX - drag[0]) / scale, drag[3] - (e.clientY - drag[1]) / scale, vb.width, vb.height);
    });
    let zoomedOut = false;
    box.addEventListener("dblclick", () => { zoomedOut = !zoomedOut; set(...(zoomedOut ? whole : home)); });
  }

  function drawNet(i) {
    const counts = markingAt(i);
    const shown = net.shown;
    for (const [p, node] of net.places) {
      const n = counts[placeIndex.get(p)];
      if (shown && shown[placeIndex.get(p)] === n) continue;
      if (node.text) {
        node.text.textContent = n > 0 ? (n <= 3 ? "●".repeat(n) : String(n)) : "";
        node.g.dataset.tokens = String(n);
        node.g.classList.toggle("pf-marked", n > 0);
      } else {
        node.cell.textContent = String(n);
        node.row.dataset.tokens = String(n);
        node.row.style.fontWeight = n > 0 ? "bold" : "";
      }
    }
    net.shown = counts;
    if (!net.transitions.size) return;
    const now = times[i];
    const status = new Map();
    for (const f of runningAt(i)) {
      const label = (D.transition_info[f.t] && D.transition_info[f.t].action) || f.t;
      status.set(f.t, ["pf-running", `${label} · ${(now - f.ts).toFixed(1)} s`]);
    }
    for (const [t, ends] of lastEnded) {
      if (status.has(t)) continue;
      for (let k = ends.length - 1; k >= 0; k--) {
        const f = ends[k];
        if (f.e > i) continue;
        if (now - f.te <= RECENT) {
          const cls = f.outcome === "cancelled" ? "pf-cancelled" : "pf-failed";
          status.set(t, [cls, f.outcome + (f.reason ? ": " + f.reason : "")]);
        }
        break;
      }
    }
    for (const [t, old] of net.status) {
      if (!status.has(t)) {
        const node = net.transitions.get(t);
        if (node) { node.g.classList.remove(old[0]); node.text.textContent = ""; }
      }
    }
    for (const [t, st] of status) {
      const node = net.transitions.get(t);
      if (!node) continue;
      const old = net.status.get(t);
      if (old && old[0] !== st[0]) node.g.classList.remove(old[0]);
      node.g.classList.add(st[0]);
      const text = st[1].length > 48 ? st[1].slice(0, 47) + "…" : st[1];
      if (node.text.textContent !== text) node.text.textContent = text;
    }
    net.status = status;
  }

  // The world from above -------------------------------------------------------------------
  const world = { bounds: null, layer: null };

  function worldBounds() {
    let x0 = Infinity, y0 = Infinity, x1 = -Infinity, y1 = -Infinity;
    const add = (x, y) => { x0 = Math.min(x0, x); y0 = Math.min(y0, y); x1 = Math.max(x1, x); y1 = Math.max(y1, y); };
    for (const o of outlines) for (const [x, y] of o.points) add(x, y);
    for (const b of bodies.values()) for (let k = 0; k < b.x.length; k++) add(b.x[k], b.y[k]);
    if (!isFinite(x0)) return null;
    const pad = Math.max(x1 - x0, y1 - y0) * 0.04 + 0.1;
    return [x0 - pad, y0 - pad, x1 + pad, y1 + pad];
  }

  function poseAt(b, i) {
    const k = PF.lastAtMost(b.idx, i);
    return k < 0 ? null : k;
  }

  function drawWorld(i) {
    const canvas = document.getElementById("world");
    const { ctx, w, h } = PF.fit(canvas);
    ctx.clearRect(0, 0, w, h);
    if (!world.bounds) {
      ctx.fillStyle = "#5d6775"; ctx.font = "13px system-ui";
      ctx.fillText("No poses in this trace: record them with petriflow run --poses S (or --view).", 12, 24);
      return;
    }
    const [x0, y0, x1, y1] = world.bounds;
    const s = Math.min(w / (x1 - x0), h / (y1 - y0));
    const ox = (w - (x1 - x0) * s) / 2, oy = (h - (y1 - y0) * s) / 2;
    const X = x => ox + (x - x0) * s, Y = y => h - oy - (y - y0) * s;
    if (!world.layer || world.layer.w !== w || world.layer.h !== h) {   // the walls, drawn once per size
      const ratio = window.devicePixelRatio || 1;
      const off = document.createElement("canvas");
      off.width = canvas.width; off.height = canvas.height;
      const c2 = off.getContext("2d");
      c2.setTransform(ratio, 0, 0, ratio, 0, 0);
      for (const o of outlines) {
        const c = o.colour || [0.5, 0.5, 0.5];
        c2.fillStyle = `rgba(${Math.round(c[0] * 255)},${Math.round(c[1] * 255)},${Math.round(c[2] * 255)},0.55)`;
        c2.beginPath();
        o.points.forEach(([x, y], k) => k ? c2.lineTo(X(x), Y(y)) : c2.moveTo(X(x), Y(y)));
        c2.closePath(); c2.fill();
      }
      world.layer = { canvas: off, w, h };
    }
    ctx.save(); ctx.setTransform(1, 0, 0, 1, 0, 0); ctx.drawImage(world.layer.canvas, 0, 0); ctx.restore();
    const now = times[i];
    const where = new Map();
    for (const [name, b] of bodies) {
      const k = poseAt(b, i);
      if (k === null) continue;
      where.set(name, [b.x[k], b.y[k], b.yaw[k]]);
      ctx.strokeStyle = PF.colour(name); ctx.globalAlpha = 0.55; ctx.lineWidth = 1.5;
      ctx.beginPath();
      let j = k;
      while (j > 0 && b.t[j - 1] >= now - TRAIL) j--;
      for (let q = j; q <= k; q++) q === j ? ctx.moveTo(X(b.x[q]), Y(b.y[q])) : ctx.lineTo(X(b.x[q]), Y(b.y[q]));
      ctx.stroke(); ctx.globalAlpha = 1;
    }
    // links that carried a message in the last seconds (each pair once), and messages lost there
    const first = PF.lastAtMost(arrivalTimes, now - LINK_WINDOW) + 1;
    const links = [new Map(), new Map()];   // delivered, lost: "from|to" -> most recent end
    for (let k = Math.max(0, first); k < arrivals.length && arrivals[k].te <= now; k++) {
      const m = arrivals[k];
      if (m.e > i || !where.has(m.from) || !where.has(m.to)) continue;
      links[m.fate === "lost" ? 1 : 0].set(m.from + "|" + m.to, m);
    }
    ctx.lineWidth = 1.5;
    links.forEach((pairs, lost) => {
      if (!pairs.size) return;
      ctx.strokeStyle = lost ? "#b3261e" : "#0b6b50";
      ctx.setLineDash(lost ? [4, 3] : []);
      ctx.beginPath();
      for (const m of pairs.values()) {
        const a = where.get(m.from), b = where.get(m.to);
        ctx.moveTo(X(a[0]), Y(a[1])); ctx.lineTo(X(b[0]), Y(b[1]));
      }
      ctx.stroke();
    });
    ctx.setLineDash([]);
    const r = Math.max(5, Math.min(12, 0.18 * s));
    ctx.font = "11px system-ui";
    for (const [name, [x, y, yaw]] of where) {
      const px = X(x), py = Y(y);
      ctx.save(); ctx.translate(px, py); ctx.rotate(-yaw);
      ctx.fillStyle = PF.colour(name); ctx.strokeStyle = "#111"; ctx.lineWidth = 1;
      ctx.beginPath(); ctx.moveTo(r, 0); ctx.lineTo(-r * 0.7, r * 0.6); ctx.lineTo(-r * 0.7, -r * 0.6); ctx.closePath();
      ctx.fill(); ctx.stroke(); ctx.restore();
      ctx.fillStyle = "#111"; ctx.fillText(name, px + r + 2, py - 2);
    }
    ctx.fillStyle = "#5d6775";
    ctx.fillText(`${(x1 - x0).toFixed(1)} m × ${(y1 - y0).toFixed(1)} m`, 8, h - 8);
  }

  // Messages as a sequence chart -------------------------------------------------------------
  const seq = { hits: [] };

  function drawSequence(i) {
    const canvas = document.getElementById("seq");
    const { ctx, w, h } = PF.fit(canvas);
    ctx.clearRect(0, 0, w, h);
    seq.hits = [];
    if (!messages.length) {
      ctx.fillStyle = "#5d6775"; ctx.font = "13px system-ui";
      ctx.fillText("No message in this trace.", 12, 24);
      return;
    }
    const now = times[i];
    const windowS = parseFloat(document.getElementById("seq-window").value);
    const t0 = windowS > 0 ? now - windowS : times[0];
    const t1 = windowS > 0 ? now + windowS : times[times.length - 1] || 1;
    const top = 34, bottom = h - 8;
    const Y = t => top + (t - t0) / Math.max(1e-9, t1 - t0) * (bottom - top);
    const step = w / lifelines.length;
    const X = name => (lifelineIndex.get(name === null || name === undefined ? "(net)" : name) + 0.5) * step;
    const room = Math.max(3, Math.floor(step / 6.5));
    ctx.font = "11px system-ui"; ctx.textAlign = "center";
    for (const name of lifelines) {
      const x = X(name === "(net)" ? null : name);
      ctx.fillStyle = PF.colour(name); ctx.fillText(name.length > room ? name.slice(0, room - 1) + "…" : name, x, 14);
      ctx.strokeStyle = "#d5dae1"; ctx.beginPath(); ctx.moveTo(x, 20); ctx.lineTo(x, bottom); ctx.stroke();
    }
    ctx.textAlign = "left";
    const start = Math.max(0, PF.lastAtMost(messageTimes, t0 - 600) + 1);
    let drawn = 0;
    // arrows batched by look: one path per colour and dash, drawn at the end
    const styles = new Map();
    const style = (colour, dashed, alpha) => {
      const key = colour + dashed + alpha;
      if (!styles.has(key)) styles.set(key, { colour, dashed, alpha, lines: [], heads: [], crosses: [] });
      return styles.get(key);
    };
    const labels = [];
    for (let k = start; k < messages.length && messages[k].ts <= t1 && drawn < MAX_ARROWS; k++) {
      const m = messages[k];
      const te = m.te === null ? t1 : m.te;
      if (te < t0) continue;
      drawn++;
      const xa = X(m.from), xb = X(m.to), ya = Y(m.ts), yb = Y(Math.max(te, m.ts));
      const lost = m.fate === "lost", done = m.e >= 0 && m.e <= i;
      const xe = lost ? (xa + xb) / 2 : xb;
      const future = m.s > i;   // not sent yet: faint, solid (dashes cost much to draw)
      const st = style(lost ? "#b3261e" : (done ? "#0b6b50" : "#1f6feb"), !(done || lost || future), future ? 0.25 : 1);
      st.lines.push(xa, ya, xe, yb);
      if (lost) {
        st.crosses.push(xe, yb);
        if (m.why) labels.push([m.why, xe + 6, yb + 4, st.alpha]);
      } else st.heads.push(xa, ya, xe, yb);
      seq.hits.push([xa, ya, xe, yb, m]);
    }
    ctx.lineWidth = 1;
    for (const st of styles.values()) {
      ctx.globalAlpha = st.alpha; ctx.strokeStyle = st.colour; ctx.fillStyle = st.colour;
      ctx.setLineDash(st.dashed ? [4, 3] : []);
      ctx.beginPath();
      for (let q = 0; q < st.lines.length; q += 4) { ctx.moveTo(st.lines[q], st.lines[q + 1]); ctx.lineTo(st.lines[q + 2], st.lines[q + 3]); }
      for (let q = 0; q < st.crosses.length; q += 2) {
        const x = st.crosses[q], y = st.crosses[q + 1];
        ctx.moveTo(x - 4, y - 4); ctx.lineTo(x + 4, y + 4); ctx.moveTo(x + 4, y - 4); ctx.lineTo(x - 4, y + 4);
      }
      ctx.stroke();
      ctx.setLineDash([]);
      ctx.beginPath();
      for (let q = 0; q < st.heads.length; q += 4) {
        const [xa, ya, xe, yb] = [st.heads[q], st.heads[q + 1], st.heads[q + 2], st.heads[q + 3]];
        const ang = Math.atan2(yb - ya, xe - xa);
        ctx.moveTo(xe, yb); ctx.lineTo(xe - 7 * Math.cos(ang - 0.4), yb - 7 * Math.sin(ang - 0.4));
        ctx.lineTo(xe - 7 * Math.cos(ang + 0.4), yb - 7 * Math.sin(ang + 0.4)); ctx.closePath();
      }
      ctx.fill();
    }
    ctx.fillStyle = "#b3261e";
    for (const [text, x, y, alpha] of labels.slice(0, 200)) { ctx.globalAlpha = alpha; ctx.fillText(text, x, y); }
    ctx.globalAlpha = 1;
    const yn = Y(now);
    ctx.strokeStyle = "#d62728"; ctx.lineWidth = 1;
    ctx.beginPath(); ctx.moveTo(0, yn); ctx.lineTo(w, yn); ctx.stroke();
    ctx.fillStyle = "#d62728"; ctx.fillText(`t = ${now.toFixed(2)} s`, 4, yn - 3);
    document.getElementById("seq-note").textContent = messageCounts +
      (drawn >= MAX_ARROWS ? ` (the first ${MAX_ARROWS} of this window drawn; narrow it)` : "");
  }

  function clickSequence(ev) {
    const r = ev.target.getBoundingClientRect();
    const x = ev.clientX - r.left, y = ev.clientY - r.top;
    let best = null, bestD = 8;
    for (const [xa, ya, xb, yb, m] of seq.hits) {
      const dx = xb - xa, dy = yb - ya, len2 = dx * dx + dy * dy || 1;
      const u = Math.max(0, Math.min(1, ((x - xa) * dx + (y - ya) * dy) / len2));
      const d = Math.hypot(xa + u * dx - x, ya + u * dy - y);
      if (d < bestD) { bestD = d; best = m; }
    }
    if (best) setIndex(best.e >= 0 ? best.e : best.s, true);
  }

  // Firings per agent (Gantt) -------------------------------------------------------------
  const gantt = { image: null, rows: [], left: 110, top: 18, rowH: 0, t0: 0, t1: 1, w: 0 };
  const OUTCOME_COLOUR = { ok: "#4c8bf5", failed: "#d62728", timeout: "#ff7f0e", cancelled: "#9e9e9e" };

  function prepareGantt() {
    const canvas = document.getElementById("gantt");
    const rows = new Set();
    for (const f of firings) rows.add(f.agent || "(no agent)");
    const order = ["(no agent)"].concat(D.run_agents);   // the run's own order of agents
    gantt.rows = Array.from(rows).sort((a, b) => ((order.indexOf(a) + 1) || 1e9) - ((order.indexOf(b) + 1) || 1e9));
    canvas.style.height = Math.max(160, Math.min(900, 24 + gantt.rows.length * 18)) + "px";
    PF.forget(canvas);
    const { w, h } = PF.fit(canvas);
    const off = document.createElement("canvas");
    const ratio = window.devicePixelRatio || 1;
    off.width = Math.round(w * ratio); off.height = Math.round(h * ratio);
    const ctx = off.getContext("2d");
    ctx.setTransform(ratio, 0, 0, ratio, 0, 0);
    gantt.t0 = times[0]; gantt.t1 = Math.max(times[times.length - 1], gantt.t0 + 1e-6);
    gantt.w = w;
    const left = gantt.left, top = gantt.top;
    gantt.rowH = (h - top - 4) / Math.max(1, gantt.rows.length);
    const X = t => left + (t - gantt.t0) / (gantt.t1 - gantt.t0) * (w - left - 8);
    ctx.fillStyle = "#fff"; ctx.fillRect(0, 0, w, h);
    ctx.font = "11px system-ui";
    gantt.rows.forEach((name, k) => {
      const y = top + k * gantt.rowH;
      if (k % 2) { ctx.fillStyle = "#f6f7f9"; ctx.fillRect(0, y, w, gantt.rowH); }
      ctx.fillStyle = PF.colour(name);
      ctx.fillText(name.length > 16 ? name.slice(0, 15) + "…" : name, 4, y + gantt.rowH / 2 + 4);
    });
    for (const f of firings) {
      const k = gantt.rows.indexOf(f.agent || "(no agent)");
      const y = top + k * gantt.rowH + 2;
      const xa = X(f.ts), xb = X(f.te === Infinity ? gantt.t1 : f.te);
      ctx.fillStyle = OUTCOME_COLOUR[f.outcome] || "#4c8bf5";
      ctx.globalAlpha = f.outcome === null ? 0.5 : 0.85;
      ctx.fillRect(xa, y, Math.max(1, xb - xa), Math.max(2, gantt.rowH - 4));
    }
    ctx.globalAlpha = 1;
    ctx.fillStyle = "#5d6775";
    for (let q = 0; q <= 5; q++) {
      const t = gantt.t0 + (gantt.t1 - gantt.t0) * q / 5;
      ctx.fillText(`${t.toFixed(t < 10 ? 1 : 0)} s`, Math.min(w - 40, X(t)), 12);
    }
    gantt.image = off;
  }

  function drawGantt(i) {
    const canvas = document.getElementById("gantt");
    const { ctx, w, h } = PF.fit(canvas);
    if (!gantt.image || Math.abs(gantt.w - w) > 1) prepareGantt();
    ctx.setTransform(1, 0, 0, 1, 0, 0);
    ctx.drawImage(gantt.image, 0, 0);
    const ratio = window.devicePixelRatio || 1;
    ctx.setTransform(ratio, 0, 0, ratio, 0, 0);
    const x = gantt.left + (times[i] - gantt.t0) / (gantt.t1 - gantt.t0) * (w - gantt.left - 8);
    ctx.strokeStyle = "#d62728"; ctx.lineWidth = 1.5;
    ctx.beginPath(); ctx.moveTo(x, gantt.top - 4); ctx.lineTo(x, h); ctx.stroke();
  }

  function clickGantt(ev) {
    const r = ev.target.getBoundingClientRect();
    const x = ev.clientX - r.left, y = ev.clientY - r.top;
    const t = gantt.t0 + (x - gantt.left) / (gantt.w - gantt.left - 8) * (gantt.t1 - gantt.t0);
    const row = gantt.rows[Math.floor((y - gantt.top) / gantt.rowH)];
    let best = null;
    for (const f of firings) {
      if ((f.agent || "(no agent)") !== row) continue;
      if (f.ts <= t && t <= (f.te === Infinity ? gantt.t1 : f.te)) { best = f; break; }
    }
    if (best) setIndex(best.s, true);
    else setIndex(Math.max(0, PF.lastAtMost(times, t)), true);
  }

  // The event list --------------------------------------------------------------------------
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
      default: return `${ev.kind} ${ev.transition || ""}${who} ${JSON.stringify(d).slice(0, 120)}`;
    }
  }

  function setupFilters() {
    const agents = M.agents, kinds = M.kinds, transitions = M.transitions;
    const agentSel = document.getElementById("f-agent");
    for (const a of agents) { const o = document.createElement("option"); o.value = a; o.textContent = a; agentSel.appendChild(o); }
    const kindSel = document.getElementById("f-kind");
    for (const k of kinds) { const o = document.createElement("option"); o.value = k; o.textContent = k; kindSel.appendChild(o); }
    const dl = document.getElementById("transition-list");
    for (const t of transitions) { const o = document.createElement("option"); o.value = t; dl.appendChild(o); }
    for (const id of ["f-agent", "f-kind"]) document.getElementById(id).addEventListener("change", applyFilters);
    document.getElementById("f-transition").addEventListener("input", applyFilters);
    const box = document.getElementById("events");
    box.addEventListener("scroll", () => { list.top = box.scrollTop; renderList(); });
    box.addEventListener("wheel", () => { list.follow = false; }, { passive: true });
    box.addEventListener("click", e => {
      const row = e.target.closest(".row");
      if (row) { list.follow = true; setIndex(parseInt(row.dataset.index, 10), false); }
    });
  }

  function applyFilters() {
    const agent = document.getElementById("f-agent").value;
    const kind = document.getElementById("f-kind").value;
    const t = document.getElementById("f-transition").value.trim();
    const a = agent ? M.agents.indexOf(agent) : -2, kd = kind ? M.kinds.indexOf(kind) : -2;
    const ts = t ? new Set(M.transitions.map((name, k) => name.includes(t) ? k : -9).filter(k => k >= 0)) : null;
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
    scrollListTo(current);
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
      const idx = list.rows[k], e = ev(idx);
      node.style.display = "";
      node.style.top = k * list.rowH + "px";
      node.dataset.index = String(idx);
      node.dataset.agent = e.agent || "";
      node.className = "row k-" + e.kind + (idx === current ? " current" : "") + (bad[idx] ? " failed" : "");
      node.textContent = `${String(e.seq).padStart(7)}  t=${e.time.toFixed(3).padStart(10)}  ${describe(e)}`;
    }
    for (; n < list.nodes.length; n++) list.nodes[n].style.display = "none";
  }

  function showDetail(i) {
    document.getElementById("event-detail").textContent = JSON.stringify(ev(i), null, 1);
  }

  // Time ----------------------------------------------------------------------------------
  function setIndex(i, follow) {
    i = Math.max(0, Math.min(N - 1, i | 0));
    current = i;
    const slider = document.getElementById("slider");
    if (parseInt(slider.value, 10) !== i) slider.value = String(i);
    const running = runningAt(i).length;
    const tr = transOf[i] >= 0 ? " " + M.transitions[transOf[i]] : "";
    document.getElementById("now").textContent =
      `event ${i} (seq ${seqOf(i)}) of ${N - 1} · t = ${times[i].toFixed(3)} s · ${M.kinds[kindOf[i]]}${tr} · ${running} running`;
    const P = window.pfView.parts;
    let t = performance.now();
    const lap = name => { const n = performance.now(); P[name] = (P[name] || 0) + n - t; t = n; };
    drawNet(i); lap("net");
    drawWorld(i); lap("world");
    drawSequence(i); lap("sequence");
    drawGantt(i); lap("gantt");
    if (follow !== false) list.follow = true;
    const wall = performance.now();
    if (!playing || wall - list.drawnAt > 250) {  // while playing, the list catches up four times a second
      list.drawnAt = wall;
      if (list.follow) scrollListTo(i);
      renderList();
      showDetail(i);
    }
    lap("list");
  }

  function play() {
    playing = !playing;
    document.getElementById("b-play").textContent = playing ? "pause" : "play";
    if (!playing) { setIndex(current, false); return; }   // the list and the record shown catch up
    let simT = times[current], last = performance.now();
    const frame = now => {
      if (!playing) return;
      const speed = parseFloat(document.getElementById("speed").value);
      let next;
      if (speed < 0) next = current + 1;
      else {
        simT += (now - last) / 1000 * speed;
        next = Math.max(current, PF.lastAtMost(times, simT));
      }
      last = now;
      if (next >= N - 1) { setIndex(N - 1); play(); return; }
      if (next !== current) setIndex(next);
      requestAnimationFrame(frame);
    };
    requestAnimationFrame(frame);
  }

  function setupControls() {
    const slider = document.getElementById("slider");
    slider.max = String(N - 1);
    slider.addEventListener("input", () => setIndex(parseInt(slider.value, 10)));
    document.getElementById("b-first").addEventListener("click", () => setIndex(0));
    document.getElementById("b-prev").addEventListener("click", () => setIndex(current - 1));
    document.getElementById("b-next").addEventListener("click", () => setIndex(current + 1));
    document.getElementById("b-last").addEventListener("click", () => setIndex(N - 1));
    document.getElementById("b-play").addEventListener("click", play);
    document.getElementById("seq-window").addEventListener("change", () => drawSequence(current));
    document.getElementById("seq").addEventListener("click", clickSequence);
    document.getElementById("gantt").addEventListener("click", clickGantt);
    document.getElementById("link-window").textContent = String(LINK_WINDOW);
    document.addEventListener("keydown", e => {
      if (e.target.tagName === "INPUT" || e.target.tagName === "SELECT") return;  // the slider moves itself
      if (e.key === "ArrowRight") { setIndex(current + 1); e.preventDefault(); }
      else if (e.key === "ArrowLeft") { setIndex(current - 1); e.preventDefault(); }
      else if (e.key === " ") { play(); e.preventDefault(); }
    });
    window.addEventListener("resize", () => { gantt.image = null; setIndex(current, false); });
  }

  function summary() {
    const span = times[times.length - 1] - times[0];
    const stop = M.kinds[kindOf[N - 1]] === "stop" ? ev(N - 1).data.reason : "no stop event";
    const failed = firings.filter(f => f.outcome && f.outcome !== "ok").length;
    document.getElementById("summary").textContent =
      `${[D.trace, D.net_file].filter(Boolean).join(" on ") || D.name} · ${N} events over ${span.toFixed(2)} s simulated · ` +
      `${firings.length} firings (${failed} not ok) · ${messages.length} messages · ${bodies.size} bodies posed · ` +
      `ended: ${stop} · trace ${(D.trace_bytes / 1e6).toFixed(2)} MB, page ${(D.page_bytes / 1e6).toFixed(2)} MB` +
      (D.shortened ? ` · to stay under ${D.shortened.max_mb} MB, ${D.shortened.events} events carry their bulky data` +
       ` (over ${D.shortened.limit} characters, not needed to replay) as a note naming the trace line` : "");
  }

  async function main() {
    const started = performance.now();
    const T = window.pfView.timing = {};
    let mark = started;
    const lap = name => { const t = performance.now(); T[name] = t - mark; mark = t; };
    const [bytes, model, svg] = await Promise.all([PF.inflateBytes(D.columns), PF.inflate(D.model),
                                                   D.svg ? PF.inflate(D.svg) : Promise.resolve(null)]);
    netSvg = svg;
    lap("inflate");
    times = readColumns(bytes);
    M = JSON.parse(model);
    lap("parse");
    index();
    lap("index");
    world.bounds = worldBounds();
    setupNet();
    lap("net");
    setupControls();
    setupFilters();
    summary();
    applyFilters();
    lap("list");
    setIndex(0);
    lap("first");
    document.getElementById("loading").remove();
    window.pfView.ready = true;
    window.pfView.loadMs = performance.now() - started;
    window.pfView.readyAt = performance.now();   // since the page started loading
  }

  window.pfView = {
    ready: false,
    parts: {},
    setIndex: i => setIndex(i),
    get index() { return current; },
    get count() { return N; },
    get bodies() { return bodies.size; },
    markingAt: i => markingObject(markingAt(i)),
    /** Event i's record as the page rebuilds it from its columns (what the event list shows). */
    record: i => record(i),
    /** The marking the page shows now, read back from the net (or the place list). */
    shownMarking() {
      const out = {};
      for (const [p, node] of net.places) {
        const n = parseInt((node.g || node.row).dataset.tokens || "0", 10);
        if (n > 0) out[p] = n;
      }
      return out;
    },
    running: () => runningAt(current).map(f => f.t),
    listed: () => Array.from(document.querySelectorAll("#events .row")).filter(n => n.style.display !== "none")
      .map(n => ({ index: parseInt(n.dataset.index, 10), agent: n.dataset.agent })),
    filtered: () => Array.from(list.rows),
    /** Milliseconds per slider move (the update and the layout it forces), over `steps` moves. */
    bench(steps) {
      const ms = [];
      for (let k = 0; k < steps; k++) {
        const t = performance.now();
        setIndex(Math.floor((k + 1) * (N - 1) / steps));
        document.body.offsetHeight;
        ms.push(performance.now() - t);
      }
      ms.sort((a, b) => a - b);
      return { mean: ms.reduce((a, b) => a + b, 0) / ms.length, p95: ms[Math.floor(ms.length * 0.95)], max: ms[ms.length - 1] };
    },
  };

  main().catch(err => { PF.showError("The page could not read its trace: " + err); console.error(err); });
})();
