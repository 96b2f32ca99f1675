// Where an update's time goes, function by function (not a test): a Chromium CPU profile
// (100 µs sampling) of RUNS (100) full updates after an edit, self time summed per function and
// the top 40 printed. Wasm functions are named only in a module built without wasm-opt's name
// stripping: ROOT=dir serves such a checkout (index.html, web/, pkg/ with
// pkg/page/playground_bg.wasm straight from wasm-bindgen). M=3|6 modes, N shapers of ZV, ZVD,
// ZVDD, ZV-D³ (4), EDIT=mode|mismatch.
// Run: ROOT=/path/to/named/build node benches/page_profile.mjs
import { chromium } from 'playwright-core';
import { resolve } from 'node:path';
import { startServer } from '../scripts/serve.mjs';

const { server, url } = await startServer({ port: 0, ...(process.env.ROOT ? { root: resolve(process.env.ROOT) } : {}) });
const browser = await chromium.launch({ executablePath: process.env.CHROMIUM ?? '/usr/bin/chromium', args: ['--no-sandbox', '--disable-gpu'] });
const modes = process.env.M === '6' ? [1.2, 3.4, 7.9, 13, 21, 34].map((f) => ({ frequencyHz: f, damping: 0.02 }))
  : [{ frequencyHz: 1.2, damping: 0.012 }, { frequencyHz: 3.4, damping: 0.013 }, { frequencyHz: 7.9, damping: 0.02 }];
const shapers = [{ family: 'zv' }, { family: 'zvd' }, { family: 'zvdd' }, { family: 'zvdn', derivatives: 3 }].slice(0, Number(process.env.N ?? 4));
const state = { modes, shapers, view: { vtol: 0.05, scv: 5, mismatch: 1.1, mapShaper: 1, plant: { kind: 'modal' }, command: { kind: 'trapezoid', distance: 1, maxVelocity: 0.75, maxAcceleration: 8 } } };
try {
  const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
  await page.goto(`${url}#state=${encodeURIComponent(JSON.stringify(state))}`);
  await page.waitForSelector('body[data-ready="true"]');
  const cdp = await page.context().newCDPSession(page);
  await cdp.send('Profiler.enable');
  await cdp.send('Profiler.setSamplingInterval', { interval: 100 });
  await cdp.send('Profiler.start');
  const total = await page.evaluate(async ([runs, edit]) => {
    const pg = window.__playground;
    const frame = () => new Promise((d) => requestAnimationFrame(d));
    let sum = 0;
    for (let i = 0; i < runs; i++) {
      await frame();
      if (edit === 'mode') pg.state.modes[0].frequencyHz = 1.2 + (i % 10) * 0.01; else pg.state.view.mismatch = 0.8 + (i % 40) * 0.01;
      sum += pg.update();
    }
    return sum;
  }, [Number(process.env.RUNS ?? 100), process.env.EDIT ?? 'mode']);
  const { profile } = await cdp.send('Profiler.stop');
  const self = new Map();
  const dt = new Map();
  profile.samples.forEach((id, i) => dt.set(id, (dt.get(id) ?? 0) + (profile.timeDeltas[i] ?? 0)));
  for (const n of profile.nodes) {
    const name = n.callFrame.functionName || `(${n.callFrame.url.split('/').pop() || 'program'})`;
    self.set(name, (self.get(name) ?? 0) + (dt.get(n.id) ?? 0) / 1000);
  }
  const runs = Number(process.env.RUNS ?? 100);
  console.log(`${runs} updates, ${(total / runs).toFixed(2)} ms each on average (update()); self time per update:`);
  [...self.entries()].filter(([k]) => !/^\((idle|program|garbage collector)\)$/.test(k) || true).sort((a, b) => b[1] - a[1]).slice(0, 40)
    .forEach(([k, v]) => console.log(`${(v / runs).toFixed(3).padStart(8)} ms  ${k}`));
} finally {
  await browser.close();
  server.close();
}
