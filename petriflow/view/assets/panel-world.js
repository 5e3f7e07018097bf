/* A run's page: the world from above (poses, trails, walls, links). */
"use strict";
/** #world: `draw(i)`. */
PF.worldPanel = function (view) {
  const TRAIL = 30;                 // seconds of trail behind each robot
  const LINK_WINDOW = 5;            // seconds a delivered message's link stays drawn
  const replay = view.replay, bodies = replay.bodies, outlines = replay.outlines;

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

  function draw(i) {
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
    const now = view.trace.times[i];
    const where = new Map();
    for (const [name, b] of bodies) {
      const k = replay.poseAt(b, i);
      if (k < 0) continue;
      where.set(name, [b.x[k], b.y[k], b.yaw[k]]);
      ctx.strokeStyle = PF.colour(name); ctx.globalAlpha = 0.55; ctx.lineWidth = 1.5;
      ctx.beginPath();
      let j = k;
      while (j > 0 && b.t[j - 1] >= now - TRAIL) j--;
      for (let q = j; q <= k; q++) q === j ? ctx.moveTo(X(b.x[q]), Y(b.y[q])) : ctx.lineTo(X(b.x[q]), Y(b.y[q]));
      ctx.stroke(); ctx.globalAlpha = 1;
    }
    // links that carried a message in the last seconds (each pair once), and messages lost there
    const links = [new Map(), new Map()];   // delivered, lost: "from|to" -> most recent end
    for (const m of replay.endedWithin(i, LINK_WINDOW)) {
      if (!where.has(m.from) || !where.has(m.to)) continue;
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

  world.bounds = worldBounds();
  document.getElementById("link-window").textContent = String(LINK_WINDOW);
  return { draw };
};
