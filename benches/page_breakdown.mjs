// Where a page update's time goes, chart by chart (not a test): the page's full update timed
// with all eight charts, then with each chart left out in turn (its canvas hidden from the page:
// the chart is not drawn and its analysis not computed), then with none. p50 of 25 updates each,
// each in an animation frame of its own. M=3 (the benchmark's 3 modes) or 6 (issue 24's six, the
// default); N shapers of ZV, ZVD, ZVDD, ZV-D³ (default 3); EDIT=mismatch (default) or mode;
// ROOT=dir serves another checkout (built).
// Run: node benches/page_breakdown.mjs
import { chromium } from 'playwright-core';
import { startServer } from '../scripts/serve.mjs';
const root = process.env.ROOT ?? '/work/wt/frame';
const { server, url } = await startServer({ port: 0, root });
const browser = await chromium.launch({ executablePath: '/usr/bin/chromium', args: ['--no-sandbox', '--disable-gpu'] });
const modes = process.env.M === '3' ? [{ frequencyHz: 1.2, damping: 0.012 }, { frequencyHz: 3.4, damping: 0.013 }, { frequencyHz: 7.9, damping: 0.02 }]
  : [1.2, 3.4, 7.9, 13, 21, 34].map((f) => ({ frequencyHz: f, damping: 0.02 }));
const n = Number(process.env.N ?? 3);
const shapers = [{ family: 'zv' }, { family: 'zvd' }, { family: 'zvdd' }, { family: 'zvdn', derivatives: 3 }].slice(0, n);
const state = { modes, shapers, view: { vtol: 0.05, scv: 5, mismatch: 1.1, mapShaper: 1, plant: { kind: 'modal' }, command: { kind: 'trapezoid', distance: 1, maxVelocity: 0.75, maxAcceleration: 8 } } };
const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
await page.goto(`${url}#state=${encodeURIComponent(JSON.stringify(state))}`);
await page.waitForSelector('body[data-ready="true"]');
const ids = ['impulses-chart', 'sensitivity-chart', 'damping-chart', 'map-chart', 'response-chart', 'command-chart', 'spectrum-chart', 'robustness-chart'];
for (const hide of [[], ...ids.map((i) => [i]), ids]) {
  const r = await page.evaluate(async ([hide, edit]) => {
    const orig = Document.prototype.getElementById;
    document.getElementById = function (id) { return hide.includes(id) ? document.createElement('div') : orig.call(this, id); };
    const pg = window.__playground;
    const frame = () => new Promise((d) => requestAnimationFrame(d));
    const out = [];
    for (let i = 0; i < 30; i++) {
      await frame();
      if (edit === 'mode') pg.state.modes[0].frequencyHz = 1.2 + (i % 10) * 0.01; else pg.state.view.mismatch = 0.8 + (i % 40) * 0.01;
      const t = pg.update(); if (i >= 5) out.push(t);
    }
    delete document.getElementById;
    out.sort((a, b) => a - b);
    return out[Math.floor(out.length / 2)];
  }, [hide, process.env.EDIT ?? 'mismatch']);
  console.log(`without ${hide.length > 1 ? 'all charts' : hide[0] ?? 'nothing'}: p50 ${r.toFixed(1)} ms`);
}
await browser.close(); server.close();
