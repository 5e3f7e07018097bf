/* petriflow view: a run's page. The trace decoded (trace.js) and replayed (replay.js), the panels
   (panel-*.js) drawn at the chosen event; here the summary and the controls. */
"use strict";
(function () {
  const D = PF.data;
  /** All the panels share: go(i, follow) chooses event i (follow: the list scrolls to it). */
  const view = { data: D, trace: null, replay: null, index: 0, playing: false, go: (i, follow) => setIndex(i, follow) };
  const panels = {};
  let setIndex = null;

  /** The controls and the summary of the decoded `view.trace`, replayed in `view.replay`. */
  function start() {
    const trace = view.trace, replay = view.replay, N = trace.count, times = trace.times;
    const slider = document.getElementById("slider");

    setIndex = function (i, follow) {
      i = Math.max(0, Math.min(N - 1, i | 0));
      view.index = i;
      if (parseInt(slider.value, 10) !== i) slider.value = String(i);
      const running = replay.runningAt(i).length;
      const tr = replay.transOf[i] >= 0 ? " " + replay.transitions[replay.transOf[i]] : "";
      document.getElementById("now").textContent =
        `event ${i} (seq ${trace.seqOf(i)}) of ${N - 1} · t = ${times[i].toFixed(3)} s · ${replay.kinds[replay.kindOf[i]]}${tr} · ${running} running`;
      const P = window.pfView.parts;
      let t = performance.now();
      const lap = name => { const n = performance.now(); P[name] = (P[name] || 0) + n - t; t = n; };
      panels.net.draw(i); lap("net");
      panels.world.draw(i); lap("world");
      panels.messages.draw(i); lap("sequence");
      panels.gantt.draw(i); lap("gantt");
      panels.events.draw(i, follow); lap("list");
    };

    function play() {
      view.playing = !view.playing;
      document.getElementById("b-play").textContent = view.playing ? "pause" : "play";
      if (!view.playing) { setIndex(view.index, false); return; }   // the list and the record shown catch up
      let simT = times[view.index], last = performance.now();
      const frame = now => {
        if (!view.playing) return;
        const speed = parseFloat(document.getElementById("speed").value);
        let next;
        if (speed < 0) next = view.index + 1;
        else {
          simT += (now - last) / 1000 * speed;
          next = Math.max(view.index, PF.lastAtMost(times, simT));
        }
        last = now;
        if (next >= N - 1) { setIndex(N - 1); play(); return; }
        if (next !== view.index) setIndex(next);
        requestAnimationFrame(frame);
      };
      requestAnimationFrame(frame);
    }

    slider.max = String(N - 1);
    slider.addEventListener("input", () => setIndex(parseInt(slider.value, 10)));
    document.getElementById("b-first").addEventListener("click", () => setIndex(0));
    document.getElementById("b-prev").addEventListener("click", () => setIndex(view.index - 1));
    document.getElementById("b-next").addEventListener("click", () => setIndex(view.index + 1));
    document.getElementById("b-last").addEventListener("click", () => setIndex(N - 1));
    document.getElementById("b-play").addEventListener("click", play);
    document.addEventListener("keydown", e => {
      if (e.target.tagName === "INPUT" || e.target.tagName === "SELECT") return;  // the slider moves itself
      if (e.key === "ArrowRight") { setIndex(view.index + 1); e.preventDefault(); }
      else if (e.key === "ArrowLeft") { setIndex(view.index - 1); e.preventDefault(); }
      else if (e.key === " ") { play(); e.preventDefault(); }
    });
    window.addEventListener("resize", () => { panels.gantt.resized(); setIndex(view.index, false); });

    const span = times[N - 1] - times[0];
    const stop = replay.kinds[replay.kindOf[N - 1]] === "stop" ? trace.event(N - 1).data.reason : "no stop event";
    const failed = replay.firings.filter(f => f.outcome && f.outcome !== "ok").length;
    const custom = replay.kinds.indexOf("custom"), violations = [];
    for (let i = 0; custom >= 0 && i < N; i++) {
      if (replay.kindOf[i] === custom && replay.bad[i]) violations.push(PF.violation(trace.event(i)));
    }
    document.getElementById("summary").textContent = violations.map(v => v + " · ").join("") +
      `${[D.trace, D.net_file].filter(Boolean).join(" on ") || D.name} · ${N} events over ${span.toFixed(2)} s simulated · ` +
      `${replay.firings.length} firings (${failed} not ok) · ${replay.messages.length} messages · ${replay.bodies.size} bodies posed · ` +
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
    lap("inflate");
    view.trace = PF.readTrace(bytes);
    const tables = JSON.parse(model);
    lap("parse");
    view.replay = PF.replay(view.trace, tables);
    lap("index");
    panels.world = PF.worldPanel(view);
    panels.net = PF.netPanel(view, svg);
    lap("net");
    panels.messages = PF.messagePanel(view);
    panels.gantt = PF.ganttPanel(view);
    start();
    panels.events = PF.eventsPanel(view);
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
    get index() { return view.index; },
    get count() { return view.trace.count; },
    get bodies() { return view.replay.bodies.size; },
    markingAt: i => view.replay.marking(i),
    /** Event i's record as the page rebuilds it from its columns (what the event list shows). */
    record: i => view.trace.record(i),
    /** The marking the page shows now, read back from the net (or the place list). */
    shownMarking: () => panels.net.shown(),
    running: () => view.replay.runningAt(view.index).map(f => f.t),
    listed: () => panels.events.listed(),
    filtered: () => panels.events.filtered(),
    /** Milliseconds per slider move (the update and the layout it forces), over `steps` moves. */
    bench(steps) {
      const ms = [], N = view.trace.count;
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
