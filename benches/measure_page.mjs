// Issue 20 item 7 (a spectrum file to Klipper's recommendation in the page's worker ≤ 100 ms),
// measured on the path the page runs when a spectrum file is dropped (web/measure_worker.js:
// `identifyModes` on the first file, then `recommendShaper(…, { criterion: 'klipper' })`),
// with the measured-data worker's module (pkg/page/recording.js) inside a module Worker of
// headless Chromium. Each step is timed on its own and the two together. Not part of npm test.
//
//   npm run build && npm run bench:measure
//   FILES=resonances_y_three.csv,… RUNS=9 MODULES=pkg/page/recording.js,OLD/recording.js \
//   node benches/measure_page.mjs
//   DIR=/tmp/rand_1 RUNS=3 node benches/measure_page.mjs   # every spectrum file of a directory
//
// DIR (default tests/data/klipper) is where the files are read; given without FILES, every
// resonances_*.csv and calibration_data_*.csv in it (e.g. a batch of
// benches/reference/sweep_random.py) is timed, and the slowest total is printed at the end.
// MODULES (paths under the repository root, served as the page is) lists builds of the module
// to compare (e.g. another commit's pkg/page copied under the repository); their runs
// alternate, file by file, so a machine whose load moves treats them alike. Per file and
// module: the median and range of RUNS timed calls after 2 warm-ups, wall time in the worker
// (performance.now()), each call its own message as the page sends them.
import { readdirSync, readFileSync } from 'node:fs';
import path from 'node:path';
import { header, root, uptime, withWorkers, workerSource } from './worker_bench.mjs';

const list = (v, d) => (v ? v.split(',').filter(Boolean) : d);
const DIR = path.resolve(root, process.env.DIR ?? 'tests/data/klipper');
const FILES = list(process.env.FILES, process.env.DIR
  ? readdirSync(DIR).filter((f) => /^(resonances|calibration_data)_.*\.csv$/.test(f)).sort()
  : ['resonances_x_m1.csv', 'resonances_y_three.csv', 'resonances_y_two38x14.csv', 'resonances_x_cliff133.csv',
    'calibration_data_y_three.csv']);
const MODULES = list(process.env.MODULES, ['pkg/page/recording.js']);
const RUNS = Number(process.env.RUNS ?? 7);

/** A Klipper spectrum file as the page's parser reads it (done in the worker: not timed). */
const text = (name) => readFileSync(path.join(DIR, name), 'utf8');

// The worker: the module initialised once, the file parsed once, then each request timed.
const WORKER = workerSource(`
  const { name, text, runs, warm } = data;
  const parser = new mod.RecordingParser({ fileName: name });
  parser.push(text);
  const rec = parser.finish();
  parser.free();
  const warmups = warm ? 2 : 0;
  const times = { identify: [], klipper: [], total: [] };
  let id;
  let rank;
  for (let i = 0; i < runs + warmups; i++) {
    const t0 = performance.now();
    id = mod.identifyModes(rec, {});
    const t1 = performance.now();
    rank = mod.recommendShaper(rec, [], { criterion: 'klipper' });
    const t2 = performance.now();
    if (i >= warmups) {
      times.identify.push(t1 - t0);
      times.klipper.push(t2 - t1);
      times.total.push(t2 - t0);
    }
  }
  const modes = id.modes.map((m) => m.frequencyHz.toFixed(2) + ' Hz ζ ' + m.damping.toFixed(4)).join(', ');
  postMessage({ times, modes, pick: rank.klipper?.best ?? rank.recommended });
`);

const load0 = header();
const median = (v) => [...v].sort((a, b) => a - b)[Math.floor(v.length / 2)];
const range = (v) => `${Math.min(...v).toFixed(0)}–${Math.max(...v).toFixed(0)}`;
const slowest = MODULES.map(() => ({ file: '', total: 0 }));
await withWorkers(WORKER, MODULES, async (page) => {
  for (const file of FILES) {
    const results = MODULES.map(() => ({ identify: [], klipper: [], total: [], modes: '', pick: '' }));
    for (let i = 0; i < RUNS; i++) {
      for (let m = 0; m < MODULES.length; m++) {
        const out = await page.evaluate(([m, name, text, first]) => new Promise((done) => {
          const w = window.__workers[m];
          w.onmessage = ({ data }) => done(data);
          w.postMessage({ name, text, runs: 1, warm: first });
        }), [m, file, text(file), i === 0]);
        for (const k of ['identify', 'klipper', 'total']) results[m][k].push(...out.times[k]);
        results[m].modes = out.modes;
        results[m].pick = typeof out.pick === 'object' ? JSON.stringify(out.pick) : String(out.pick);
      }
    }
    MODULES.forEach((m, i) => {
      const r = results[i];
      if (median(r.total) > slowest[i].total) slowest[i] = { file, total: median(r.total) };
      console.log(`${file} [${m}]: identify ${median(r.identify).toFixed(0)} ms (${range(r.identify)}), `
        + `klipper ${median(r.klipper).toFixed(0)} ms (${range(r.klipper)}), total ${median(r.total).toFixed(0)} ms `
        + `(${range(r.total)}), ${r.total.length} runs; modes ${r.modes}`);
    });
  }
});
MODULES.forEach((m, i) => console.log(`slowest [${m}]: ${slowest[i].file}, total ${slowest[i].total.toFixed(0)} ms (median)`));
console.log(`machine: ${load0.replace(/.*load/, 'load')} at the start, ${uptime().replace(/.*load/, 'load')} at the end`);
