// Real Klipper files through the measured-data path (issues 20 and 25): for each file,
// parseRecording → identifyModes (default options) → recommendShaper with criterion 'klipper'
// (the reproduction of calibrate_shaper.py), and 'optimal' for mainline Klipper and for
// RepRapFirmware's custom shaper. Prints Klipper's pick and ours with Klipper's own figures
// (vibrations %, smoothing, score), the change of the score, and the identified modes.
//
// The files are not in the repository (their licences are unknown): the list of sources is
// benches/real_klipper_sources.md; fetch them into a directory and give its path.
//
//   node benches/real_klipper.mjs [--module pkg/input_shaping.js | pkg/page/recording.js]
//     [--json out.json] FILE|DIR…
//
// With --json, writes every result (for benches/reference/real_klipper_compare.py, which
// checks the Klipper picks against benches/reference/klipper_reference.py).
import { readFileSync, readdirSync, statSync, writeFileSync } from 'node:fs';
import { fileURLToPath } from 'node:url';
import path from 'node:path';

const root = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..');
const argv = process.argv.slice(2);
let modulePath = path.join(root, 'pkg/input_shaping.js');
let jsonOut = null;
const inputs = [];
// NO_MODES=1: the optimised shapers without the identified modes (Klipper's damping set only).
const withModes = !process.env.NO_MODES;
for (let i = 0; i < argv.length; i++) {
  if (argv[i] === '--module') modulePath = path.resolve(argv[++i]);
  else if (argv[i] === '--json') jsonOut = argv[++i];
  else inputs.push(argv[i]);
}
const files = inputs.flatMap((p) => (statSync(p).isDirectory()
  ? readdirSync(p).filter((n) => n.endsWith('.csv')).sort().map((n) => path.join(p, n))
  : [p]));

const mod = await import(modulePath);
await mod.default({ module_or_path: readFileSync(modulePath.replace(/\.js$/, '_bg.wasm')) });

const pct = (x) => (100 * x).toFixed(2);
const change = (ours, theirs) => (100 * (ours / theirs - 1));
const median = (xs) => {
  const s = [...xs].sort((a, b) => a - b);
  return s.length ? (s[(s.length - 1) >> 1] + s[s.length >> 1]) / 2 : NaN;
};

/** Klipper's figures of a ranked row. */
function row(r) {
  return {
    label: r.label, family: r.family, kind: r.kind ?? null,
    vibr: r.remainingVibration, smoothing: r.smoothing, score: r.klipperScore,
    maxAccel: r.maxAccel, impulses: r.shaper?.impulses?.length ?? null,
  };
}

const results = [];
for (const file of files) {
  const name = path.basename(file);
  const out = { file: name };
  results.push(out);
  try {
    const text = readFileSync(file, 'utf8');
    // The whole API has parseRecording; the page's recording module the chunked reader.
    const spectrum = mod.parseRecording
      ? mod.parseRecording(text, { fileName: name })
      : (() => {
        const p = new mod.RecordingParser({ fileName: name });
        p.push(text);
        return p.finish();
      })();
    out.format = spectrum.format;
    let klipperInput = spectrum;
    const t0 = performance.now();
    const id = mod.identifyModes(spectrum, {});
    out.identifyMs = performance.now() - t0;
    out.modes = id.modes.map((m) => ({
      f: m.frequencyHz, zeta: m.damping, sf: m.frequencyUncertaintyHz,
      sz: m.dampingUncertainty, prominenceDb: m.prominenceDb,
    }));
    if (spectrum.format === 'klipper' || spectrum.format === 'csv') {
      // A raw recording: Klipper's own PSD of it is what calibrate_shaper.py fits.
      klipperInput = id.spectrum;
    }
    const k = mod.recommendShaper(klipperInput, id.modes, { criterion: 'klipper' });
    const fam = k.klipper.families[k.klipper.best];
    out.klipperPick = {
      name: fam.name, freq: fam.pick.freq, printedFreq: fam.printed.freq,
      vibr: fam.pick.vibrs, smoothing: fam.pick.smoothing, score: fam.pick.score,
      families: k.klipper.families.map((f) => ({
        name: f.name, freq: f.pick.freq, vibr: f.pick.vibrs, smoothing: f.pick.smoothing,
        maxAccel: f.pick.maxAccel, score: f.pick.score,
      })),
    };
    for (const firmware of ['klipper', 'reprapfirmware']) {
      const t1 = performance.now();
      const o = mod.recommendShaper(klipperInput, withModes ? id.modes : [],
        { criterion: 'optimal', firmware });
      const ms = performance.now() - t1;
      const best = row(o.ranked[0]);
      const pick = o.ranked.map(row).find((r) => r.kind === 'klipper') ?? null;
      out[`optimal_${firmware}`] = { ms, best, pick, note: o.note ?? null };
    }
  } catch (e) {
    out.error = `${e.kind ?? e.name}: ${e.message}`;
  }
}

if (jsonOut) writeFileSync(jsonOut, JSON.stringify(results, null, 1));
const fmtRow = (r) => `${r.label} vibr ${pct(r.vibr)} % sm ${r.smoothing.toFixed(4)} `
  + `score ${r.score.toPrecision(4)}`;
const changes = { klipper: [], reprapfirmware: [] };
for (const r of results) {
  console.log(`\n${r.file} (${r.format ?? '?'})`);
  if (r.error) {
    console.log(`  ERROR ${r.error}`);
    continue;
  }
  const k = r.klipperPick;
  console.log(`  modes: ${r.modes.map((m) => `${m.f.toFixed(2)} Hz ζ ${m.zeta.toFixed(3)}`
    + ` (±${m.sf.toFixed(2)}, ±${m.sz.toFixed(3)}, ${m.prominenceDb.toFixed(1)} dB)`).join('; ')}`);
  console.log(`  klipper pick: ${k.name} @ ${k.printedFreq} Hz vibr ${pct(k.vibr)} % `
    + `sm ${k.smoothing.toFixed(4)} score ${k.score.toPrecision(4)}`);
  for (const fw of ['klipper', 'reprapfirmware']) {
    const o = r[`optimal_${fw}`];
    const c = change(o.best.score, k.score);
    changes[fw].push(c);
    const limit = Math.max(k.vibr, 0.05);
    const flags = [
      o.best.score > k.score * (1 + 1e-9) ? 'WORSE-SCORE' : '',
      o.best.vibr > limit + 1e-12 ? 'TOO-MUCH-R' : '',
    ].filter(Boolean).join(' ');
    console.log(`  ${fw.padEnd(14)} ${fmtRow(o.best)} (${c.toFixed(1)} %) ${o.ms.toFixed(0)} ms`
      + `${flags ? ` ${flags}` : ''}`);
  }
}
console.log('\nsummary');
for (const fw of ['klipper', 'reprapfirmware']) {
  const cs = changes[fw];
  console.log(`  ${fw}: ${cs.length} files, median change ${median(cs).toFixed(1)} %, `
    + `worst ${Math.max(...cs).toFixed(1)} %, best ${Math.min(...cs).toFixed(1)} %`);
}
const errors = results.filter((r) => r.error).length;
if (errors) console.log(`  ${errors} files failed`);
