/* A run's page: the firings per agent (Gantt), coloured by outcome. */
"use strict";
/** #gantt: `draw(i)`, `resized()`; a click goes to the firing there, else to that time. */
PF.ganttPanel = function (view) {
  const firings = view.replay.firings, times = view.trace.times;
  const gantt = { image: null, rows: [], left: 110, top: 18, rowH: 0, t0: 0, t1: 1, w: 0 };
  const OUTCOME_COLOUR = { ok: "#4c8bf5", failed: "#d62728", timeout: "#ff7f0e", cancelled: "#9e9e9e" };

  function prepare() {
    const canvas = document.getElementById("gantt");
    const rows = new Set();
    for (const f of firings) rows.add(f.agent || "(no agent)");
    const order = ["(no agent)"].concat(view.data.run_agents);   // the run's own order of agents
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

  function draw(i) {
    const canvas = document.getElementById("gantt");
    const { ctx, w, h } = PF.fit(canvas);
    if (!gantt.image || Math.abs(gantt.w - w) > 1) prepare();
    ctx.setTransform(1, 0, 0, 1, 0, 0);
    ctx.drawImage(gantt.image, 0, 0);
    const ratio = window.devicePixelRatio || 1;
    ctx.setTransform(ratio, 0, 0, ratio, 0, 0);
    const x = gantt.left + (times[i] - gantt.t0) / (gantt.t1 - gantt.t0) * (w - gantt.left - 8);
    ctx.strokeStyle = "#d62728"; ctx.lineWidth = 1.5;
    ctx.beginPath(); ctx.moveTo(x, gantt.top - 4); ctx.lineTo(x, h); ctx.stroke();
  }

  function click(ev) {
    const r = ev.target.getBoundingClientRect();
    const x = ev.clientX - r.left, y = ev.clientY - r.top;
    const t = gantt.t0 + (x - gantt.left) / (gantt.w - gantt.left - 8) * (gantt.t1 - gantt.t0);
    const row = gantt.rows[Math.floor((y - gantt.top) / gantt.rowH)];
    let best = null;
    for (const f of firings) {
      if ((f.agent || "(no agent)") !== row) continue;
      if (f.ts <= t && t <= (f.te === Infinity ? gantt.t1 : f.te)) { best = f; break; }
    }
    if (best) view.go(best.s, true);
    else view.go(Math.max(0, PF.lastAtMost(times, t)), true);
  }

  document.getElementById("gantt").addEventListener("click", click);
  return { draw, resized: () => { gantt.image = null; } };
};
