/* petriflow view: helpers every page shares (no network, no globals but PF; no data in Node). */
"use strict";
globalThis.PF = (function () {
  const data = typeof document === "undefined" ? null : JSON.parse(document.getElementById("pf-data").textContent);

  /** The bytes packed by petriflow.view.page.pack_bytes (gzip + base64), inflated by the browser. */
  async function inflateBytes(b64) {
    const binary = atob(b64);
    const bytes = new Uint8Array(binary.length);
    for (let i = 0; i < binary.length; i++) bytes[i] = binary.charCodeAt(i);
    const stream = new Blob([bytes]).stream().pipeThrough(new DecompressionStream("gzip"));
    return new Uint8Array(await new Response(stream).arrayBuffer());
  }

  /** The text packed by petriflow.view.page.pack, inflated. */
  async function inflate(b64) { return new TextDecoder().decode(await inflateBytes(b64)); }

  const PALETTE = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#17becf",
                   "#bcbd22", "#7f7f7f", "#393b79", "#ad494a", "#637939", "#8c6d31", "#843c39", "#7b4173"];
  const colours = new Map();
  /** A stable colour per name (agents keep theirs across panels). */
  function colour(name) {
    if (!colours.has(name)) colours.set(name, PALETTE[colours.size % PALETTE.length]);
    return colours.get(name);
  }

  /** Index of the last element of sorted `arr` that is <= x (-1 if none). */
  function lastAtMost(arr, x) {
    let lo = 0, hi = arr.length - 1, found = -1;
    while (lo <= hi) {
      const mid = (lo + hi) >> 1;
      if (arr[mid] <= x) { found = mid; lo = mid + 1; } else hi = mid - 1;
    }
    return found;
  }

  function fmt(x, digits) {
    if (x === null || x === undefined) return "–";
    if (typeof x !== "number") return String(x);
    if (Number.isInteger(x)) return String(x);
    return x.toFixed(digits === undefined ? 3 : digits);
  }

  /** A canvas sized to its CSS box in device pixels; returns its 2D context. */
  const sizes = new WeakMap();   // canvas -> its CSS size, read once (reading forces a layout)
  const resized = { n: 0 };
  if (typeof window !== "undefined") window.addEventListener("resize", () => { resized.n++; });
  function fit(canvas) {
    const ratio = window.devicePixelRatio || 1;
    let size = sizes.get(canvas);
    if (!size || size.n !== resized.n) {
      size = { w: Math.max(50, canvas.clientWidth), h: Math.max(50, canvas.clientHeight), n: resized.n };
      sizes.set(canvas, size);
    }
    const w = size.w, h = size.h;
    if (canvas.width !== Math.round(w * ratio) || canvas.height !== Math.round(h * ratio)) {
      canvas.width = Math.round(w * ratio);
      canvas.height = Math.round(h * ratio);
    }
    const ctx = canvas.getContext("2d");
    ctx.setTransform(ratio, 0, 0, ratio, 0, 0);
    return { ctx, w, h };
  }

  function showError(message) {
    const div = document.createElement("div");
    div.id = "error";
    div.textContent = message;
    document.body.insertBefore(div, document.body.firstChild);
  }

  function forget(canvas) { sizes.delete(canvas); }

  /** The line of a `custom` event `property_violated` (recorded by `run --monitor`). */
  function violation(ev) {
    const d = ev.data || {};
    return `VIOLATED property ${d.property} at event ${d.event}${ev.transition ? " (" + ev.transition + ")" : ""}`;
  }

  return { data, inflate, inflateBytes, colour, lastAtMost, fmt, fit, forget, showError, violation };
})();
