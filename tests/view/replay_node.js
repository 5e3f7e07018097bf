/* The pure parts of a run's page (assets/common.js, trace.js, replay.js), run by Node over the
   data of a page petriflow wrote: `node replay_node.js ASSETS PAGE.html` prints one JSON
   document: per event its record as the page rebuilds it, the marking after it, the transitions
   running, the firings failed in the last 5 s and the messages ended in the last 5 s (as the net
   and the world panels ask), whether the page marks the event (red) and, for a property
   violation found by `run --monitor`, the line the events panel shows; the messages and the bodies' poses. tests/view/test_replay_js.py
   compares them with petriflow's own replay. */
"use strict";
const fs = require("fs");
const path = require("path");
const vm = require("vm");

const [assets, page] = process.argv.slice(2);
for (const name of ["common.js", "trace.js", "replay.js"]) {   // as the page inlines them, in order
  vm.runInThisContext(fs.readFileSync(path.join(assets, name), "utf8"), { filename: name });
}
const html = fs.readFileSync(page, "utf8");
const data = JSON.parse(html.match(/<script type="application\/json" id="pf-data">([\s\S]*?)<\/script>/)[1]);

async function main() {
  const trace = PF.readTrace(await PF.inflateBytes(data.columns));
  const replay = PF.replay(trace, JSON.parse(await PF.inflate(data.model)));
  const events = [];
  for (let i = 0; i < trace.count; i++) {
    events.push({
      record: trace.record(i),
      marking: replay.marking(i),
      running: replay.runningAt(i).map(f => f.t),
      failed: Array.from(replay.failedAt(i, 5), ([t, f]) => [t, f.outcome, f.reason]),
      ended: replay.endedWithin(i, 5).map(m => [m.s, m.e]),
      bad: replay.bad[i] === 1,
      violation: trace.event(i).kind === "custom" && trace.event(i).data.name === "property_violated"
        ? PF.violation(trace.event(i)) : null,
    });
  }
  const bodies = {};
  for (const [name, b] of replay.bodies) {
    bodies[name] = [b.idx, b.t, b.x, b.y, b.yaw].map(values => Array.from(values));
  }
  const messages = replay.messages.map(m => [m.s, m.e, m.fate, m.from, m.to, m.place, m.channel]);
  process.stdout.write(JSON.stringify({ events, messages, bodies }));
}

main().catch(err => { console.error(err); process.exit(1); });
