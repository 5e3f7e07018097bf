/* petriflow view: a sweep's page. The table as petriflow sweep prints it, and each
   metric against the first parameter with error bars, drawn with dygraphs. */
"use strict";
(function () {
  const D = PF.data;
  const plots = [];

  function cell(tr, text, cls) {
    const td = document.createElement("td");
    td.textContent = text === null || text === undefined ? "–" : String(text);
    if (cls) td.className = cls;
    tr.appendChild(td);
    return td;
  }

  function header(table, names) {
    const thead = document.createElement("thead");
    const tr = document.createElement("tr");
    for (const [name, cls] of names) {
      const th = document.createElement("th");
      th.textContent = name;
      if (cls) th.className = cls;
      tr.appendChild(th);
    }
    thead.appendChild(tr);
    table.appendChild(thead);
  }

  function reportTable() {
    const table = document.getElementById("report");
    const withPaper = D.metrics.filter(m => D.rows.some(r => m in r.paper));
    const withStatus = withPaper.filter(m => D.rows.some(r => m in r.paper && (r.paper_status || {})[m]));
    const cols = D.parameters.map(p => [p, "text"]).concat([["trials"], ["failed"]]);
    for (const m of D.metrics) {
      cols.push([m]);
      if (withPaper.includes(m)) { cols.push([m + " (paper)"]); cols.push(["deviation"]); }
      if (withStatus.includes(m)) cols.push(["status", "text"]);
    }
    header(table, cols);
    const body = document.createElement("tbody");
    for (const row of D.rows) {
      const tr = document.createElement("tr");
      if (row.failed) tr.className = "failed";
      for (const p of D.parameters) cell(tr, row.params[p], "text");
      cell(tr, row.trials); cell(tr, row.failed);
      for (const m of D.metrics) {
        cell(tr, row.cells[m]).dataset.metric = m;
        if (withPaper.includes(m)) {
          cell(tr, m in row.paper ? row.paper[m] : "–", "paper");
          cell(tr, row.deviations[m], "dev");
        }
        if (withStatus.includes(m)) {
          const st = m in row.paper ? (row.paper_status || {})[m] : null;
          const td = cell(tr, st ? (st.status.replace("-", " ") + (st.unexplained ? " (no mechanism stated)" : st.declared ? " (declared " + st.declared + ")" : "")) : "", "text status" + (st ? " st-" + st.status : ""));
          if (st && st.because) td.title = st.because;
        }
      }
      body.appendChild(tr);
    }
    table.appendChild(body);
    const notes = document.getElementById("status-notes");
    for (const row of D.status_notes || []) {
      const li = document.createElement("li"); li.textContent = row; notes.appendChild(li);
    }
  }

  function plotMetric(name) {
    const x = D.parameters[0] || null;
    const xs = [];
    for (const r of D.rows) { const v = x ? r.params[x] : 0; if (!xs.includes(v)) xs.push(v); }
    const categorical = !xs.every(v => typeof v === "number");
    const pos = v => (categorical ? xs.indexOf(v) : v);
    const groups = new Map();
    for (const r of D.rows) {
      const label = D.parameters.slice(1).map(p => `${p}=${r.params[p]}`).join(", ") || "measured";
      if (!groups.has(label)) groups.set(label, []);
      groups.get(label).push(r);
    }
    const labels = [x || ""], series = [], strokes = {};
    for (const [label, rows] of groups) {
      if (rows.some(r => r.metrics[name].mean !== null && !r.metrics[name].counts)) series.push([label, rows, "mean"]);
      if (rows.some(r => typeof r.paper[name] === "number")) series.push([label + " (paper)", rows, "paper"]);
    }
    if (!series.length) return false;
    const xsSorted = Array.from(new Set(xs.map(pos))).sort((a, b) => a - b);
    const data = xsSorted.map(px => {
      const line = [px];
      for (const [, rows, what] of series) {
        const r = rows.find(q => pos(x ? q.params[x] : 0) === px);
        if (!r) { line.push([null, null]); continue; }
        if (what === "mean") {
          const s = r.metrics[name];
          line.push(s.mean === null ? [null, null] : [s.mean, s.sd || 0]);
        } else {
          line.push(typeof r.paper[name] === "number" ? [r.paper[name], 0] : [null, null]);
        }
      }
      return line;
    });
    for (const [label, , what] of series) {
      labels.push(label);
      if (what === "paper") strokes[label] = { strokePattern: Dygraph.DASHED_LINE, pointSize: 4 };
    }
    const box = document.createElement("div");
    box.className = "plot-box";
    box.dataset.metric = name;
    const h3 = document.createElement("h3"); h3.textContent = name; box.appendChild(h3);
    const div = document.createElement("div"); div.className = "plot"; box.appendChild(div);
    const legend = document.createElement("div"); legend.className = "legend"; box.appendChild(legend);
    document.getElementById("plots").appendChild(box);
    const graph = new Dygraph(div, data, {
      labels, errorBars: true, sigma: 1, drawPoints: true, pointSize: 3, connectSeparatedPoints: true,
      xlabel: x || "", legend: "always", labelsDiv: legend, series: strokes, xRangePad: 12, yRangePad: 12,
      axes: categorical ? { x: { ticker: () => xs.map((v, k) => ({ v: k, label: String(v) })),
                                 valueFormatter: k => String(xs[k]) } } : {},
    });
    plots.push(graph);
    return true;
  }

  function trialsTable() {
    const table = document.getElementById("trials");
    const cols = [["row"], ["seed"]].concat(D.parameters.map(p => [p, "text"]), [["status", "text"]],
                                            D.metrics.map(m => [m]), [["wall s"], ["error", "text"]]);
    header(table, cols);
    const body = document.createElement("tbody");
    const select = document.getElementById("t-status");
    for (const s of Object.keys(D.statuses)) {
      const o = document.createElement("option"); o.value = s; o.textContent = `${s} (${D.statuses[s]})`; select.appendChild(o);
    }
    for (const t of D.trials) {
      const tr = document.createElement("tr");
      tr.dataset.status = t.status;
      if (t.status !== "ok") tr.className = "failed";
      cell(tr, t.row + 1); cell(tr, t.seed);
      for (const p of D.parameters) cell(tr, t.params[p], "text");
      cell(tr, t.status, "text");
      for (const m of D.metrics) cell(tr, PF.fmt(t.metrics[m], 4));
      cell(tr, t.wall === null ? null : t.wall.toFixed(2)); cell(tr, t.error || "", "text");
      body.appendChild(tr);
    }
    table.appendChild(body);
    const filter = () => {
      let n = 0;
      for (const tr of body.children) {
        const show = !select.value || tr.dataset.status === select.value;
        tr.style.display = show ? "" : "none";
        n += show;
      }
      document.getElementById("t-count").textContent = `${n} of ${D.trials.length} trials`;
    };
    select.addEventListener("change", filter);
    filter();
  }

  try {
    const failed = D.trials.filter(t => t.status !== "ok").length;
    document.getElementById("summary").textContent =
      `${D.db} · ${D.trials.length} trials in ${D.rows.length} rows (${failed} failed)` +
      (D.description ? ` · ${D.description}` : "") + (D.note ? ` · note: ${D.note}` : "") +
      (D.status_counts && Object.values(D.status_counts).some(n => n) ? " · published values: " +
        Object.entries(D.status_counts).filter(([, n]) => n).map(([k, n]) => `${n} ${k.replace("-", " ")}`).join(", ") : "");
    reportTable();
    let drawn = 0;
    for (const m of D.metrics) drawn += plotMetric(m) ? 1 : 0;
    if (!drawn) document.getElementById("plots").textContent = "No numeric metric to draw.";
    trialsTable();
    window.pfView = { ready: true, plots: plots.length };
  } catch (err) {
    PF.showError("The page could not be drawn: " + err);
    console.error(err);
  }
})();
