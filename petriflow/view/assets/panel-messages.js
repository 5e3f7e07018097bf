/* A run's page: the messages as a sequence chart around the chosen event. */
"use strict";
/** #seq: `draw(i)`; a click on an arrow goes to its event. */
PF.messagePanel = function (view) {
  const MAX_ARROWS = 600;          // messages drawn at most in the sequence chart
  const messages = view.replay.messages, messageTimes = view.replay.messageTimes, times = view.trace.times;
  const seq = { hits: [] };
  const names = new Set(view.data.run_agents);   // the lifelines: the run's agents, then the others
  for (const m of messages) { if (m.from) names.add(m.from); if (m.to) names.add(m.to); }
  const lifelines = Array.from(names), lifelineIndex = new Map();
  if (messages.some(m => !m.from || !m.to)) lifelines.push("(net)");
  lifelines.forEach((n, k) => lifelineIndex.set(n, k));
  const fateCounts = {};
  for (const m of messages) fateCounts[m.fate] = (fateCounts[m.fate] || 0) + 1;
  const messageCounts = `${messages.length} messages: ` + Object.entries(fateCounts).map(([k, v]) => `${v} ${k}`).join(", ");

  function draw(i) {
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

  function click(ev) {
    const r = ev.target.getBoundingClientRect();
    const x = ev.clientX - r.left, y = ev.clientY - r.top;
    let best = null, bestD = 8;
    for (const [xa, ya, xb, yb, m] of seq.hits) {
      const dx = xb - xa, dy = yb - ya, len2 = dx * dx + dy * dy || 1;
      const u = Math.max(0, Math.min(1, ((x - xa) * dx + (y - ya) * dy) / len2));
      const d = Math.hypot(xa + u * dx - x, ya + u * dy - y);
      if (d < bestD) { bestD = d; best = m; }
    }
    if (best) view.go(best.e >= 0 ? best.e : best.s, true);
  }
  document.getElementById("seq-window").addEventListener("change", () => draw(view.index));
  document.getElementById("seq").addEventListener("click", click);
  return { draw };
};
