// Page benchmark (not a test): time full updates of the playground in headless Chromium —
// recompute everything and redraw every chart (impulses, V(f), V(ζ), the map, the simulated
// response, the command, its spectrum, robustness), as one input event does — with 3 modes and
// 4 compared shapers, and report p50 / p95 / max in ms, plus the shipped size (gzip -9 of every
// file the browser fetched: on the first load; then for opening a recording, which fetches
// the measured-data worker and its module; then for choosing a solved family, which starts the
// design worker and fetches its module with the optimisation solver; and for a link to a state
// with a solved family: what it is drawn with, the same first load, and the design worker's
// files, fetched as it starts, which add the solved shaper when they have designed it).
// Two kinds of edit: a mode's frequency (every shaper redesigned and every chart recomputed;
// the robustness background is cached per damping ratio and Vtol, so a frequency edit only
// rescales it) and the mismatch r (the designs stay; the simulation and its charts change).
// Each update runs in an animation frame of its own, as the page schedules them (one update
// per frame, however many input events came). Back-to-back updates with no frame between them
// pile up the canvases' recorded drawing until the browser rasterises several frames of it
// inside one update: that gave the 200–500 ms maxima reported before this pacing.
// Run: npm run bench:page   (after npm run build); RUNS=n sets the updates per case (200),
// SHAPERS=1 or SHAPERS=4 runs only the cases with that many shapers, EXPANDED=1 presses every
// impulse table's "Show all" first (by default a table longer than 20 rows shows 20).
import { chromium } from 'playwright-core';
import { readFileSync } from 'node:fs';
import { gzipSync } from 'node:zlib';
import { startServer } from '../scripts/serve.mjs';

const RUNS = Number(process.env.RUNS ?? 200);
const state = {
  modes: [
    { frequencyHz: 1.2, damping: 0.012 },
    { frequencyHz: 3.4, damping: 0.013 },
    { frequencyHz: 7.9, damping: 0.02 },
  ],
  shapers: [{ family: 'zv' }, { family: 'zvd' }, { family: 'zvdd' }, { family: 'zvdn', derivatives: 3 }],
  view: {
    vtol: 0.05, scv: 5, mismatch: 1.1, mapShaper: 1, plant: { kind: 'modal' },
    command: { kind: 'trapezoid', distance: 1, maxVelocity: 0.75, maxAcceleration: 8 },
  },
};

const { server, url } = await startServer({ port: 0 });
const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM ?? '/usr/bin/chromium',
  args: ['--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run', '--disable-background-networking', '--disable-component-update', '--disable-sync'],
});
try {
  const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
  const fetched = []; // every request, in order (a file fetched again counts again)
  page.on('request', (r) => fetched.push(new URL(r.url()).pathname));
  await page.goto(`${url}#state=${encodeURIComponent(JSON.stringify(state))}`);
  await page.waitForSelector('body[data-ready="true"]');
  await page.waitForLoadState('networkidle');
  const firstLoad = [...new Set(fetched)];
  const loaded = fetched.length;
  const charts = await page.$$eval('.charts canvas', (c) => c.length);
  const cases = [[4, 'mode'], [4, 'mismatch'], [1, 'mode'], [1, 'mismatch']]
    .filter(([n]) => !process.env.SHAPERS || Number(process.env.SHAPERS) === n);
  for (const [shapers, edit] of cases) {
    if (shapers === 1) {
      await page.evaluate(() => { const pg = window.__playground; pg.state.shapers.splice(1); pg.state.shapers[0] = { family: 'zvd' }; pg.state.view.mapShaper = 0; pg.update(); });
    }
    if (process.env.EXPANDED) {
      await page.evaluate(() => document.querySelectorAll('.impulses tfoot:not([hidden]) button[aria-expanded="false"]').forEach((b) => b.click()));
    }
    const times = await page.evaluate(async ([runs, what]) => {
      const out = [];
      const pg = window.__playground;
      const frame = () => new Promise((done) => requestAnimationFrame(done));
      for (let i = 0; i < 10; i++) { await frame(); pg.update(); } // warm up
      for (let i = 0; i < runs; i++) {
        await frame();
        if (what === 'mode') pg.state.modes[0].frequencyHz = 1.2 + (i % 10) * 0.01;
        else pg.state.view.mismatch = 0.8 + (i % 40) * 0.01;
        out.push(pg.update());
      }
      return out;
    }, [RUNS, edit]);
    const errors = await page.$$eval('.error', (e) => e.map((x) => x.textContent).filter(Boolean));
    if (errors.length) throw new Error(`page errors during the benchmark: ${errors.join('; ')}`);
    times.sort((a, b) => a - b);
    const q = (p) => times[Math.min(times.length - 1, Math.floor(p * times.length))];
    console.log(`full update after a ${edit} edit, 3 modes, ${shapers === 4 ? '4 shapers (ZV, ZVD, ZVDD, ZV-D³: 8 … 125 impulses)' : '1 shaper (ZVD, 27 impulses)'}, ${charts} charts (${RUNS} runs): p50 ${q(0.5).toFixed(2)} ms, p95 ${q(0.95).toFixed(2)} ms, max ${times[times.length - 1].toFixed(2)} ms (budget: p95 16 ms)`);
  }
  // Open a recording (2 s of a 40 Hz decay at 3200 Hz): the page starts the measured-data
  // worker, which fetches its script and module.
  const rows = ['time,accel_x'];
  for (let k = 0; k < 6400; k++) rows.push(`${(k / 3200).toFixed(6)},${(1000 * Math.exp(-7.5 * (k % 3200) / 3200) * Math.sin(2 * Math.PI * 40 * k / 3200)).toFixed(4)}`);
  await page.setInputFiles('#measure-file', { name: 'decay.csv', mimeType: 'text/csv', buffer: Buffer.from(rows.join('\n')) });
  await page.waitForFunction(() => document.getElementById('measure-file-name').textContent !== ''
    || document.getElementById('measure-error').textContent !== '');
  await page.waitForLoadState('networkidle');
  const measured = [...new Set(fetched.slice(loaded))];
  // Choose a solved family (SI over I = 0.3 at Vtol 5 %): the page starts the design worker.
  const beforeSolver = fetched.length;
  await page.evaluate(() => { const pg = window.__playground; pg.state.shapers[0] = { family: 'si', vtol: 0.05, insensitivity: 0.3 }; pg.update(); });
  await page.waitForFunction(() => !document.body.dataset.fetching);
  await page.waitForLoadState('networkidle');
  const solver = [...new Set(fetched.slice(beforeSolver))];
  // A link to that state, opened afresh.
  const linked = await browser.newPage({ viewport: { width: 1280, height: 800 } });
  const linkFetched = [];
  linked.on('request', (r) => linkFetched.push(new URL(r.url()).pathname));
  await linked.goto(`${url}#state=${encodeURIComponent(JSON.stringify(await page.evaluate(() => window.__playground.state)))}`);
  await linked.waitForSelector('body[data-ready="true"]');
  await linked.waitForLoadState('networkidle');
  report('shipped on the first load', firstLoad, '(budget: 300 KB)');
  report('fetched when a recording is opened', measured, '(the measured-data worker)');
  report('fetched when a solved family (SI) is chosen', solver, '(the design worker and its module with the solver)');
  const designer = (f) => f.startsWith('/pkg/page/design');
  const link = [...new Set(linkFetched)];
  report('shipped on the first load of a link with a solved family', link.filter((f) => !designer(f)), '(the page is drawn, the solved shaper left out until designed)');
  report('  then fetched for its solved shaper', link.filter(designer), '(the design worker and its module)');
} finally {
  await browser.close();
  server.close();
}

/** Prints the gzip -9 size of the files at `paths` (URL paths under the repository root). */
function report(what, paths, note) {
  const root = new URL('..', import.meta.url);
  const files = paths.filter((f) => f !== '/' && !f.startsWith('/favicon')).concat(paths.includes('/') ? ['/index.html'] : []);
  const sizes = files.map((f) => [f, gzipSync(readFileSync(new URL(`.${f}`, root)), { level: 9 }).length]);
  const total = sizes.reduce((sum, [, n]) => sum + n, 0);
  console.log(`${what}: ${(total / 1024).toFixed(1)} KiB gzip (${(total / 1000).toFixed(1)} KB) ${note}`);
  for (const [f, n] of sizes.sort((a, b) => b[1] - a[1])) console.log(`  ${(n / 1024).toFixed(1).padStart(7)} KiB  ${f}`);
}
