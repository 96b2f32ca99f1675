// Klipper's recommendation in wasm (issue 20 item 7): a spectrum file of the test set to
// recommendShaper(spectrum, [], { criterion: 'klipper' }) in the measured-data worker's module,
// timed in node. The file is read here with a few lines of JS (the product reads it with
// parseRecording); the figure is the fit.
//
//   bash scripts/build.sh   # or any --target web build of the js-recording feature
//   node benches/klipper_wasm.mjs [path/to/recording.js] [files…]
//   CRITERION=optimal FIRMWARE=reprapfirmware node benches/klipper_wasm.mjs …
//                           # issue 25: the optimised shapers (Klipper's pick, best mainline,
//                           # best custom: the page's continuation), per axis
//
// Prints, per file, the median and minimum of 20 runs (RUNS=n: n) after 3 warm-ups (wall clock
// and the process's CPU time, which a busy machine inflates less), and the pick.
import { readFileSync } from 'node:fs';
import { fileURLToPath } from 'node:url';
import path from 'node:path';

const root = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..');
const args = process.argv.slice(2);
const modulePath = path.resolve(args[0] ?? path.join(root, 'pkg/page/recording.js'));
const files = args.length > 1 ? args.slice(1) : [
  'resonances_x_m1.csv', 'resonances_x_z018f61.csv', 'resonances_y_z020f61.csv',
  'calibration_data_x_m1.csv',
];
const criterion = process.env.CRITERION ?? 'klipper';
const firmware = process.env.FIRMWARE ?? 'klipper';
const RUNS = Number(process.env.RUNS ?? 20);
const mod = await import(modulePath);
const wasm = readFileSync(modulePath.replace(/\.js$/, '_bg.wasm'));
await mod.default({ module_or_path: wasm });

/** A Klipper `freq,psd_x,psd_y,psd_z,psd_xyz[,shapers:…]` file as a spectrum object. */
function read(name) {
  const lines = readFileSync(path.join(root, 'tests/data/klipper', name), 'utf8')
    .split('\n').filter((l) => l && !l.startsWith('#'));
  const header = lines.shift();
  const rows = lines.map((l) => l.split(',').map((x) => (x === '' ? 0 : Number(x))));
  const col = (i) => Float64Array.from(rows, (r) => r[i]);
  return {
    frequencyHz: col(0), psdX: col(1), psdY: col(2), psdZ: col(3), psdSum: col(4), psd: col(4),
    normalization: header.includes(',shapers:') ? 'klipper' : 'none',
  };
}

for (const name of files) {
  const spectrum = read(name);
  const options = criterion === 'optimal' ? { criterion, firmware } : { criterion };
  const run = () => mod.recommendShaper(spectrum, [], options);
  for (let i = 0; i < 3; i++) run();
  const times = [];
  const cpu = [];
  let r;
  for (let i = 0; i < RUNS; i++) {
    const t0 = performance.now();
    const c0 = process.cpuUsage();
    r = run();
    const c = process.cpuUsage(c0);
    times.push(performance.now() - t0);
    cpu.push((c.user + c.system) / 1000);
  }
  times.sort((a, b) => a - b);
  cpu.sort((a, b) => a - b);
  const pick = criterion === 'optimal'
    ? `${r.ranked[0].label}, score ${r.ranked[0].klipperScore.toPrecision(4)}`
    : (({ name, printed }) => `${name} @ ${printed.freq} Hz`)(r.klipper.families[r.klipper.best]);
  const mid = Math.floor(RUNS / 2);
  console.log(`${name}: median ${times[mid].toFixed(1)} ms, min ${times[0].toFixed(1)} ms `
    + `(CPU time: median ${cpu[mid].toFixed(1)} ms, min ${cpu[0].toFixed(1)} ms) `
    + `(${spectrum.frequencyHz.length} bins) → ${pick}`);
}
