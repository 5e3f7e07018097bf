/* A run's page: the net's picture (else its places) with the marking. */
"use strict";
/** #net: `draw(i)`; `shown()` reads the marking shown back. */
PF.netPanel = function (view, svg) {
  const RECENT = 5;                 // seconds a failed/cancelled firing stays marked in the net
  const D = view.data, replay = view.replay;
  const net = { places: new Map(), transitions: new Map(), shown: null, status: new Map() };

  function setup() {
    const box = document.getElementById("net");
    if (!svg) {
      box.id = "marking-list";
      box.innerHTML = "";
      const note = document.createElement("div");
      note.className = "note";
      note.textContent = "The net is not drawn: " + D.svg_missing + ". The places and their tokens:";
      box.appendChild(note);
      const table = document.createElement("table");
      table.innerHTML = "<thead><tr><th class='text'>place</th><th>tokens</th></tr></thead>";
      const body = document.createElement("tbody");
      for (const p of replay.places) {
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
    show(svg, null);
  }

  /** Put a picture in the panel: the net (or its folded drawing) or, `agent` given, one
   *  agent's subnet opened from the folded drawing, with a way back. */
  function show(text, agent) {
    const box = document.getElementById("net");
    net.places.clear(); net.transitions.clear(); net.status = new Map(); net.shown = null; net.boxes = [];
    box.innerHTML = text;               // Graphviz's own SVG, as export writes it (no script in it)
    if (D.folded) {
      const bar = document.createElement("div");
      bar.className = "pf-fold-bar note";
      if (agent) {
        const back = document.createElement("button");
        back.textContent = "back to all agents";
        back.id = "net-back";
        back.addEventListener("click", () => { show(svg, null); redraw(); });
        bar.appendChild(back);
        bar.appendChild(document.createTextNode(" " + agent.slice("agent:".length) + "'s subnet"));
      } else {
        bar.textContent = "folded: one box per agent; click a box to open its subnet";
      }
      box.insertBefore(bar, box.firstChild);
    }
    const picture = box.querySelector("svg");
    picture.removeAttribute("width"); picture.removeAttribute("height");
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
    for (const g of picture.querySelectorAll("g.node")) {
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
      } else if (!agent && D.folded && D.folded[id]) {
        const shape = g.querySelector("polygon, path");
        const b = shape ? box2(shape) : { x: 0, y: 0, width: 0, height: 0 };
        const text = document.createElementNS(NS, "text");
        text.setAttribute("class", "pf-tokens");
        text.setAttribute("x", String(b.x + b.width / 2));
        text.setAttribute("y", String(b.y + b.height + 11));
        text.setAttribute("text-anchor", "middle");
        g.appendChild(text);
        g.dataset.agent = id;
        g.style.cursor = "pointer";
        net.boxes.push({ g, text, places: D.folded[id].places });
        let down = null;
        g.addEventListener("mousedown", e => { down = [e.clientX, e.clientY]; });
        g.addEventListener("click", e => {   // a click, not the end of a drag
          if (down && Math.hypot(e.clientX - down[0], e.clientY - down[1]) > 4) return;
          open(id);
        });
      }
    }
    net.boxes = net.boxes.map(b => ({ ...b, places: b.places.filter(p => !net.places.has(p)) }));
    panZoom(box, picture);
  }

  /** Open one agent's subnet (drawn in full) in place of the folded drawing: from the
   *  page's data, or asked of the page's server (`view.part`, a live page) when it is not there. */
  function open(id) {
    const part = D.folded && D.folded[id];
    if (!part) return;
    const text = part.svg ? PF.inflate(part.svg) : view.part ? view.part(id) : null;
    if (!text) return;
    Promise.resolve(text).then(svgText => { if (svgText) { show(svgText, id); redraw(); } });
  }

  function redraw() { if (net.last !== undefined) draw(net.last); }

  /** Wheel zooms around the pointer, dragging pans (the SVG's viewBox). The listeners are
   *  added once, on the first picture, and act on the picture shown now (`zoom`): one
   *  added per picture would keep every picture ever opened alive. */
  const zoom = { svg: null, vb: null, home: null, whole: null, drag: null, zoomedOut: false, box: null };
  function panZoom(box, svg) {
    const vb = svg.viewBox.baseVal;
    zoom.svg = null;
    if (!vb || !vb.width) return;
    // start readable: fill the box in one direction (at most life size), from the top left
    const r0 = box.getBoundingClientRect();
    const cover = Math.min(1.0, Math.max(r0.width / vb.width, r0.height / vb.height));
    Object.assign(zoom, { svg, vb, home: [vb.x, vb.y, r0.width / cover, r0.height / cover],
                          whole: [vb.x, vb.y, vb.width, vb.height], drag: null, zoomedOut: false });
    set(...zoom.home);
    if (zoom.box === box) return;
    zoom.box = box;
    box.addEventListener("wheel", e => {
      if (!zoom.svg) return;
      e.preventDefault();
      const vb = zoom.vb, r = box.getBoundingClientRect();
      const scale = Math.min(r.width / vb.width, r.height / vb.height);
      const fx = vb.x + (e.clientX - r.left - (r.width - vb.width * scale) / 2) / scale;
      const fy = vb.y + (e.clientY - r.top - (r.height - vb.height * scale) / 2) / scale;
      const k = e.deltaY > 0 ? 1.15 : 1 / 1.15;
      set(fx - (fx - vb.x) * k, fy - (fy - vb.y) * k, vb.width * k, vb.height * k);
    }, { passive: false });
    box.addEventListener("mousedown", e => { if (zoom.svg) zoom.drag = [e.clientX, e.clientY, zoom.vb.x, zoom.vb.y]; });
    window.addEventListener("mouseup", () => { zoom.drag = null; });
    window.addEventListener("mousemove", e => {
      const drag = zoom.drag, vb = zoom.vb;
      if (!drag || !zoom.svg) return;
      const r = box.getBoundingClientRect();
      const scale = Math.min(r.width / vb.width, r.height / vb.height);
      set(drag[2] - (e.clientX - drag[0]) / scale, drag[3] - (e.clientY - drag[1]) / scale, vb.width, vb.height);
    });
    box.addEventListener("dblclick", () => {
      if (!zoom.svg) return;
      zoom.zoomedOut = !zoom.zoomedOut;
      set(...(zoom.zoomedOut ? zoom.whole : zoom.home));
    });
  }
  function set(x, y, w, h) { zoom.svg.setAttribute("viewBox", `${x} ${y} ${w} ${h}`); }

  function draw(i) {
    net.last = i;
    const counts = replay.markingAt(i), placeIndex = replay.placeIndex;
    const shown = net.shown;
    for (const b of net.boxes || []) {
      let n = 0;
      for (const p of b.places) n += counts[placeIndex.get(p)] || 0;
      b.text.textContent = n > 0 ? (n <= 3 ? "●".repeat(n) : String(n) + " tokens") : "";
      b.g.dataset.tokens = String(n);
    }
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
    const now = view.trace.times[i];
    const status = new Map();
    for (const f of replay.runningAt(i)) {
      const label = (D.transition_info[f.t] && D.transition_info[f.t].action) || f.t;
      status.set(f.t, ["pf-running", `${label} · ${(now - f.ts).toFixed(1)} s`]);
    }
    for (const [t, f] of replay.failedAt(i, RECENT)) {
      if (status.has(t)) continue;
      status.set(t, [f.outcome === "cancelled" ? "pf-cancelled" : "pf-failed", f.outcome + (f.reason ? ": " + f.reason : "")]);
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

  /** The marking shown: `{place: tokens}` of the places drawn, and `{"agent:ID": tokens}`
   *  of a folded drawing's boxes (the tokens in the places folded into each). */
  function shown() {
    const out = {};
    for (const [p, node] of net.places) {
      const n = parseInt((node.g || node.row).dataset.tokens || "0", 10);
      if (n > 0) out[p] = n;
    }
    for (const b of net.boxes || []) {
      const n = parseInt(b.g.dataset.tokens || "0", 10);
      if (n > 0) out[b.g.dataset.agent] = n;
    }
    return out;
  }

  setup();
  return { draw, shown, open };
};
