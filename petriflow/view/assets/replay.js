/* petriflow view: the run at any event by the rule of petriflow.runtime.replay.markings (the
   marking after event i is `petriflow replay --at i`'s). No DOM: Node runs it too. */
"use strict";
/** `trace` (PF.readTrace) replayed with `model` (petriflow.view.run_page.stored; the rest read as
    run_page.restored does): name tables, per event kindOf/agentOf/transOf (-1: none) and bad,
    `firings` {t, agent, s, e, ts, te, outcome, reason} (e -1 while running), `messages` {s, e, ts,
    te, from, to, fate, why, place, channel} by time sent, `bodies` (name -> {idx, t, x, y, yaw}). */
PF.replay = function (trace, model) {
  const CHECKPOINT = 256;           // a marking is kept every so many events
  const M = model, N = trace.count, times = trace.times;
  const numbers = key => new Map(M[key].map((name, k) => [name, k]));
  const kinds = numbers("kinds"), agents = numbers("agents"), transitions = numbers("transitions");
  const placeIndex = new Map(M.places.map((p, k) => [p, k]));
  const kindOf = new Int8Array(N), agentOf = new Int32Array(N), transOf = new Int32Array(N), bad = new Uint8Array(N);
  const dStart = new Int32Array(N + 1);   // event i changes place dPlace[k] by dN[k], dStart[i] <= k < dStart[i+1]
  let dPlace, dN;
  const checkpoints = [];           // the counts before event c*CHECKPOINT
  const firings = [], lastEnded = new Map();   // transition -> its firings that ended not ok
  const messages = [], bodies = new Map();
  let outlines = [];

  // what the page reads from the trace rather than the model (see petriflow.view.run_page.stored)
  const tKind = trace.templates.map(t => kinds.get(t[0]));
  const tTransition = trace.templates.map(t => (t[1] === null ? -1 : transitions.get(t[1])));
  const tAgent = trace.templates.map(t => (t[2] === null ? -1 : agents.get(t[2])));
  const other = new Map();
  let at = 0;
  for (const [gap, change] of M.d_other) other.set((at += gap), change);
  const change = i => other.get(i) || M.t_change[trace.order[i]];
  for (let i = 0; i < N; i++) {
    const t = trace.order[i];
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
  const start = kinds.get("start"), fStart = [];
  for (let i = 0; i < N; i++) if (kindOf[i] === start) fStart.push(i);
  at = 0;
  const mSend = M.m_send.map(gap => (at += gap));
  const counts = new Int32Array(M.places.length);
  for (let i = 0; i < N; i++) {
    if (i % CHECKPOINT === 0) checkpoints.push(Int32Array.from(counts));
    for (let k = dStart[i]; k < dStart[i + 1]; k++) counts[dPlace[k]] += dN[k];
  }
  const name = (table, k) => (k < 0 ? null : table[k]);
  fStart.forEach((s, f) => {
    const e = M.f_end[f] < 0 ? -1 : M.f_end[f] + s;
    const firing = { t: name(M.transitions, transOf[s]), agent: name(M.agents, agentOf[s]), s, e,
                     ts: times[s], te: e < 0 ? Infinity : times[e], outcome: name(M.outcomes, M.f_outcome[f]),
                     reason: M.f_reason[f] };
    firings.push(firing);
    if (e >= 0 && firing.outcome !== "ok") {
      if (!lastEnded.has(firing.t)) lastEnded.set(firing.t, []);
      lastEnded.get(firing.t).push(firing);
    }
  });
  const firingStarts = Int32Array.from(fStart);
  mSend.forEach((s, m) => {
    const e = M.m_end[m] < 0 ? -1 : M.m_end[m] + s;
    messages.push({ s, e, ts: times[s], te: e >= 0 ? times[e] : M.m_arrival[m], from: name(M.agents, agentOf[s]),
                    to: name(M.agents, M.m_to[m]), fate: M.fates[M.m_fate[m]], why: M.m_why[m],
                    place: name(M.places, M.m_place[m]), channel: name(M.channels, M.m_channel[m]) });
  });
  messages.sort((a, b) => a.ts - b.ts || a.s - b.s);
  const messageTimes = Float64Array.from(messages, m => m.ts);
  const arrivals = messages.filter(m => m.e >= 0).sort((a, b) => a.te - b.te);   // by the time they ended
  const arrivalTimes = Float64Array.from(arrivals, m => m.te);
  // the bodies' poses and the world's outlines, from the pose events (as run_page.model reads them)
  const tracks = new Map(), pose = kinds.get("pose");
  for (let i = 0; i < N; i++) {
    if (kindOf[i] !== pose) continue;
    const d = trace.record(i).data;
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

  /** The tokens of each place (as numbered in `places`) after event i. */
  function markingAt(i) {
    const c = Math.floor(i / CHECKPOINT);
    const out = Int32Array.from(checkpoints[c]);
    for (let k = dStart[c * CHECKPOINT]; k < dStart[i + 1]; k++) out[dPlace[k]] += dN[k];
    return out;
  }

  /** The marking after event i as {place: tokens > 0}. */
  function marking(i) {
    const out = {};
    markingAt(i).forEach((n, k) => { if (n > 0) out[M.places[k]] = n; });
    return out;
  }

  /** The firings started by event i and not ended by it, in the order they started. */
  function runningAt(i) {
    const out = [];
    const last = PF.lastAtMost(firingStarts, i);
    for (let k = 0; k <= last; k++) {
      const f = firings[k];
      if (f.e < 0 || f.e > i) out.push(f);
    }
    return out;
  }

  /** transition -> its last firing that ended not ok by event i, at most `seconds` before it. */
  function failedAt(i, seconds) {
    const out = new Map();
    for (const [t, ends] of lastEnded) {
      for (let k = ends.length - 1; k >= 0; k--) {
        const f = ends[k];
        if (f.e > i) continue;
        if (times[i] - f.te <= seconds) out.set(t, f);
        break;
      }
    }
    return out;
  }

  /** The messages that ended by event i, less than `seconds` before it, in the order they ended. */
  function endedWithin(i, seconds) {
    const out = [], now = times[i];
    for (let k = PF.lastAtMost(arrivalTimes, now - seconds) + 1; k < arrivals.length && arrivals[k].te <= now; k++) {
      if (arrivals[k].e <= i) out.push(arrivals[k]);
    }
    return out;
  }

  /** Body `b`'s last pose by event i (-1: none). */
  function poseAt(b, i) { return PF.lastAtMost(b.idx, i); }

  return { places: M.places, agents: M.agents, transitions: M.transitions, kinds: M.kinds, placeIndex,
           kindOf, agentOf, transOf, bad, firings, messages, messageTimes, bodies, outlines,
           markingAt, marking, runningAt, failedAt, endedWithin, poseAt };
};
