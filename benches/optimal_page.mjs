// Issue 25's speed goal (≤ 500 ms per axis in the page's worker), measured where the page runs
// it: recommendShaper(spectrum, [], { criterion: 'optimal', firmware }) of the measured-data
// worker's module (pkg/page/recording.js, what web/measure_worker.js imports) inside a module
// Worker of headless Chromium, side by side with Klipper's own fit as calibrate_shaper.py does
// it in numpy (benches/klipper_numpy_time.py: benches/reference/klipper_reference.py, the
// independent numpy reading of Klipper's algorithm) on the same files, in the same run.
// Not part of npm test.
//
//   npm run build && npm run bench:optimal
//   FILES=resonances_y_three.csv,… RUNS=9 FIRMWARES=reprapfirmware,klipper NUMPY_RUNS=3 \
//   MODULES=pkg/page/recording.js,pkg/variants/o3/recording.js node benches/optimal_page.mjs
//
// MODULES (paths under the repository root, served as the page is) lists builds of the module
// to compare; their runs alternate, file by file, so a machine whose load moves treats them
// alike. Per file and module: the median and range of RUNS timed calls (after 2 warm-ups per
// file) of
// one axis's optimal recommendation, wall time in the worker (performance.now()), each call
// its own message as the page sends them. NUMPY_RUNS=0
// skips the numpy side (its fit takes seconds per file).
import { readFileSync } from 'node:fs';
import { execFileSync } from 'node:child_process';
import path from 'node:path';
import { header, root, uptime, withWorkers, workerSource } from './worker_bench.mjs';

const list = (v, d) => (v ? v.split(',').filter(Boolean) : d);
const FILES = list(process.env.FILES, [
  'resonances_x_m1.csv', 'resonances_y_m1.csv', 'resonances_y_three.csv', 'resonances_y_z020f61.csv',
]);
const MODULES = list(process.env.MODULES, ['pkg/page/recording.js']);
const FIRMWARES = list(process.env.FIRMWARES, ['reprapfirmware']);
const RUNS = Number(process.env.RUNS ?? 7);
const NUMPY_RUNS = Number(process.env.NUMPY_RUNS ?? 3);

/** A Klipper `freq,psd_x,psd_y,psd_z,psd_xyz` file as a spectrum object (as benches/klipper_wasm.mjs). */
function read(name) {
  const lines = readFileSync(path.join(root, 'tests/data/klipper', name), 'utf8')
    .split('\n').filter((l) => l && !l.startsWith('#'));
  const header = lines.shift();
  const rows = lines.map((l) => l.split(',').map((x) => (x === '' ? 0 : Number(x))));
  const col = (i) => Array.from(rows, (r) => r[i]);
  return {
    frequencyHz: col(0), psdX: col(1), psdY: col(2), psdZ: col(3), psdSum: col(4), psd: col(4),
    normalization: header.includes(',shapers:') ? 'klipper' : 'none',
  };
}

// The worker: the module initialised once, then each request timed call by call.
const WORKER = workerSource(`
  const { spectrum, options, runs, warm } = data;
  const warmups = warm ? 2 : 0;
  const f64 = (a) => Float64Array.from(a);
  const s = { ...spectrum };
  for (const k of ['frequencyHz', 'psdX', 'psdY', 'psdZ', 'psdSum', 'psd']) s[k] = f64(s[k]);
  const times = [];
  let r;
  for (let i = 0; i < runs + warmups; i++) {
    const t0 = performance.now();
    r = mod.recommendShaper(s, [], options);
    if (i >= warmups) times.push(performance.now() - t0);
  }
  const best = r.ranked[0];
  postMessage({ times, label: best.label, score: best.klipperScore, vibrations: best.remainingVibration });
`);

const load0 = header();
const results = new Map(); // `${file} ${firmware} ${module}` → times
await withWorkers(WORKER, MODULES, async (page) => {
  for (const file of FILES) {
    const spectrum = read(file);
    for (const firmware of FIRMWARES) {
      // Alternate the modules: one call of each in turn, RUNS times over.
      for (let i = 0; i < RUNS; i++) {
        for (let m = 0; m < MODULES.length; m++) {
          const out = await page.evaluate(([m, spectrum, options, first]) => new Promise((done) => {
            const w = window.__workers[m];
            w.onmessage = ({ data }) => done(data);
            w.postMessage({ spectrum, options, runs: 1, warm: first });
          }), [m, spectrum, { criterion: 'optimal', firmware }, i === 0]);
          const key = `${file}\t${firmware}\t${MODULES[m]}`;
          if (!results.has(key)) results.set(key, { times: [], out });
          results.get(key).times.push(...out.times);
        }
      }
      for (const m of MODULES) {
        const { times, out } = results.get(`${file}\t${firmware}\t${m}`);
        times.sort((a, b) => a - b);
        const med = times[Math.floor(times.length / 2)];
        console.log(`${file} ${firmware} [${m}]: median ${med.toFixed(0)} ms (${times[0].toFixed(0)}–${times[times.length - 1].toFixed(0)}, ${times.length} runs) → ${out.label}, score ${out.score.toPrecision(6)}, R ${(100 * out.vibrations).toFixed(2)} %`);
      }
    }
    if (NUMPY_RUNS > 0) {
      const py = execFileSync('python3', [path.join(root, 'benches/klipper_numpy_time.py'), file], {
        cwd: root, encoding: 'utf8', env: { ...process.env, RUNS: String(NUMPY_RUNS) },
      }).trim();
      console.log(`${py.replace(/^[^:]*: /, `${file} numpy (klipper_reference.py, Klipper's fit): `)}`);
    }
  }
});
console.log(`machine: ${load0.replace(/.*load/, 'load')} at the start, ${uptime().replace(/.*load/, 'load')} at the end`);
