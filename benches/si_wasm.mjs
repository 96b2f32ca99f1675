// Issue 24 item 1 in wasm: `si` over three modes (1.2 / 3.4 / 7.9 Hz, ζ 0.02, Vtol 5 %) at
// I 0.3 and 0.7, timed in node with the whole-API module, two builds side by side in one run
// (alternating, so both see the same load): e.g. main's pkg (the old path) and this branch's.
//
//   bash scripts/build.sh --library          # this branch's pkg/input_shaping.js
//   node benches/si_wasm.mjs OLD/input_shaping.js pkg/input_shaping.js
//
// ALL=1 adds the other rows (see below). Prints per build and case the median and
// minimum of RUNS (default 5) runs after one warm-up (wall clock), and the design's duration
// and impulse count (which must agree), or its error's kind and message.
import { readFileSync } from 'node:fs';
import path from 'node:path';

const RUNS = Number(process.env.RUNS ?? 5);
const modules = process.argv.slice(2);
if (modules.length === 0) modules.push('pkg/input_shaping.js');
const loaded = [];
for (const m of modules) {
  const p = path.resolve(m);
  const mod = await import(p);
  await mod.default({ module_or_path: readFileSync(p.replace(/\.js$/, '_bg.wasm')) });
  loaded.push({ name: m, mod });
}
const modes = [1.2, 3.4, 7.9].map((f) => ({ frequencyHz: f, damping: 0.02 }));
const cases = [0.3, 0.7].map((i) => ({ name: `si three modes I ${i}`, spec: { family: 'si', modes, vtol: 0.05, insensitivity: i } }));
// ALL=1: the other rows too (Peláez & Singhose's one-mode SI, `direct` ZVD over three
// and six modes).
if (process.env.ALL === '1') {
  const six = [1.2, 3.4, 7.9, 13, 21, 34].map((f) => ({ frequencyHz: f, damping: 0.02 }));
  cases.unshift({ name: 'si one mode (Peláez & Singhose) I 0.7', spec: { family: 'si', modes: [{ frequencyHz: 0.5, damping: 0.002 }], vtol: 0.05, insensitivity: 0.7 } });
  cases.push({ name: 'direct ZVD three modes', spec: { family: 'direct', modes, derivatives: 1 } });
  cases.push({ name: 'direct ZVD six modes', spec: { family: 'direct', modes: six, derivatives: 1 } });
}
for (const c of cases) {
  const times = loaded.map(() => []);
  const attempt = (mod) => { try { return mod.design(c.spec); } catch (e) { return { error: e }; } };
  const results = loaded.map(({ mod }) => attempt(mod)); // warm-up
  for (let r = 0; r < RUNS; r++) {
    loaded.forEach(({ mod }, k) => {
      const t0 = performance.now();
      attempt(mod);
      times[k].push(performance.now() - t0);
    });
  }
  loaded.forEach(({ name }, k) => {
    const s = [...times[k]].sort((a, b) => a - b);
    const res = results[k];
    const what = res.error ? `${res.error.kind}: ${String(res.error.message).slice(0, 80)}` : `${res.duration.toFixed(6)} s, ${res.impulses.length} impulses`;
    console.log(`${c.name} | ${name} | median ${s[s.length >> 1].toFixed(1)} ms, min ${s[0].toFixed(1)} ms | ${what}`);
  });
}
