/* petriflow view: the trace a run's page holds (petriflow.view.columns), decoded. No DOM. */
"use strict";
/** The events of petriflow.view.columns.encode's block: `count`, `times`, `templates`, `order`
    (their numbers), `record(i)` (event i as its JSON line has it), `event(i)` (kept), `seqOf(i)`. */
PF.readTrace = function (bytes) {
  const E = { templates: [], columns: [], uses: [], timeAt: [], order: null, seq: null, cursors: [] };
  let STEP = 256;                   // where each column is read is kept every so many events (more
                                    // with very many columns: at most about 2 million positions kept)
  const parsed = new Map();         // events' records rebuilt, the last few thousand asked for

  /** The columns decoded, the templates parsed; returns each event's time. */
  function readColumns() {
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

  function event(i) {
    let e = parsed.get(i);
    if (!e) {
      e = record(i);
      if (parsed.size > 5000) parsed.clear();
      parsed.set(i, e);
    }
    return e;
  }

  const times = readColumns();
  return { count: E.order.length, times, templates: E.templates, order: E.order, record, event, seqOf };
};
