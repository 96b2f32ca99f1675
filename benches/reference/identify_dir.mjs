// Identify every recording a generator's manifest lists and tally them against the truth
// (issue 20's targets): a mode standing ≥ 6 dB counts as met when its frequency is within 1 %
// and its damping within 15 %; an identified mode more than 5 % from every true one is
// spurious. For benches/reference/sweep_chirps.py (and any manifest of the same shape:
// [{ file, modes: [[f, ζ, peakDb?, prominenceDb?]] }]).
//
//   node benches/reference/identify_dir.mjs DIR [--module pkg/input_shaping.js]
import { readFileSync } from 'node:fs';
import { fileURLToPath } from 'node:url';
import path from 'node:path';

const root = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../..');
const argv = process.argv.slice(2);
let modulePath = path.join(root, 'pkg/input_shaping.js');
const dirs = [];
for (let i = 0; i < argv.length; i++) {
  if (argv[i] === '--module') modulePath = path.resolve(argv[++i]);
  else dirs.push(argv[i]);
}
const mod = await import(modulePath);
await mod.default({ module_or_path: readFileSync(modulePath.replace(/\.js$/, '_bg.wasm')) });

let met = 0; let counted = 0; let spurious = 0; let weak = 0; let weakMet = 0;
for (const dir of dirs) {
  const manifest = JSON.parse(readFileSync(path.join(dir, 'manifest.json'), 'utf8'));
  for (const c of manifest) {
    const file = c.file ?? `raw_data_x_${c.name}.csv`;
    const text = readFileSync(path.join(dir, file), 'utf8');
    let id;
    try {
      const rec = mod.parseRecording(text, { fileName: file });
      id = mod.identifyModes(rec, { channel: 'accel_x' });
    } catch (e) {
      console.log(`${c.name}: error ${e.kind} ${e.field} ${e.message}`);
      continue;
    }
    const found = id.modes.map((m) => ({ f: m.frequencyHz, z: m.damping, used: false }));
    const cells = [];
    for (const [f, z, , prom] of c.modes) {
      let best = null;
      for (const m of found) if (!best || Math.abs(m.f - f) < Math.abs(best.f - f)) best = m;
      const ok = best && Math.abs(best.f / f - 1) <= 0.01 && Math.abs(best.z / z - 1) <= 0.15;
      if (best && Math.abs(best.f / f - 1) <= 0.05) best.used = true;
      const strong = prom === undefined || prom >= 6;
      if (strong) { counted++; if (ok) met++; } else { weak++; if (ok) weakMet++; }
      cells.push(`${f.toFixed(1)}/${z.toFixed(3)}${strong ? '' : ' (weak)'} → ${best
        ? `${best.f.toFixed(2)}/${best.z.toFixed(4)} ${ok ? 'ok' : 'MISS'}` : 'none MISS'}`);
    }
    const extra = found.filter((m) => !m.used);
    spurious += extra.length;
    const sweep = id.sweep ? `sweep ${id.sweep.bandHz.map((x) => x.toFixed(1)).join('–')} @ ${id.sweep.rateHzPerS.toFixed(2)}`
      : 'no sweep';
    console.log(`${c.name} [${c.drive ?? ''} ${c.plant ?? ''} ${c.fs ?? ''} ${c.duration?.toFixed(1) ?? ''} s, ${c.start?.toFixed(1)}–${c.end?.toFixed(1)} Hz; ${sweep}${id.cutOff ? `; cut off ${id.cutOff.frequencyHz.toFixed(1)}` : ''}]: ${cells.join('; ')}${extra.length ? `; SPURIOUS ${extra.map((m) => `${m.f.toFixed(2)}/${m.z.toFixed(4)}`).join(', ')}` : ''}`);
  }
}
console.log(`\nmodes ≥ 6 dB within 1 % / 15 %: ${met} of ${counted}; weaker: ${weakMet} of ${weak}; spurious: ${spurious}`);
