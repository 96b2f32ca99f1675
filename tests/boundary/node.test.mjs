// The boundary fuzz in Node (issue 21 item 1; tests/boundary/fuzz.mjs): every export of each
// module `scripts/build.sh` builds into pkg/, through its generated glue, with hostile
// arguments. 0 traps, 0 errors other than the documented `Error` with `kind` and `field` (naming
// the argument), and every export answers its valid call as before afterwards.
// BOUNDARY_CALLS sets the calls per module (default 3000, a few seconds: the quick run of
// `npm test`); `npm run test:boundary:long` makes 10⁶ over the whole API. BOUNDARY_SEED
// replays another sequence.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync, existsSync } from 'node:fs';
import { fileURLToPath } from 'node:url';
import { fuzz } from './fuzz.mjs';

const CALLS = Number(process.env.BOUNDARY_CALLS ?? 3000);
const SEED = Number(process.env.BOUNDARY_SEED ?? 20261204);
const root = fileURLToPath(new URL('../../', import.meta.url));

// The whole API, then the page's three modules (the same Rust, glue generated per module). The
// printed-corner module (pkg/page/corner) has one export, a drawing one: it is fuzzed in
// Chromium (tests/e2e/boundary.test.mjs), where it has a canvas.
const MODULES = [
  ['pkg/input_shaping', CALLS],
  ['pkg/page/playground', Math.ceil(CALLS / 4)],
  ['pkg/page/designer', Math.ceil(CALLS / 10)],
  ['pkg/page/recording', Math.ceil(CALLS / 4)],
];

for (const [path, calls] of MODULES) {
  test(`${path}: ${calls} hostile calls, no trap, only documented errors`, async () => {
    assert.ok(existsSync(`${root}${path}.js`), `${path}.js is missing: npm run build first`);
    const api = await import(`${root}${path}.js`);
    api.initSync({ module: readFileSync(`${root}${path}_bg.wasm`) });
    const started = Date.now();
    const r = fuzz(api, { calls, seed: SEED });
    const seconds = (Date.now() - started) / 1000;
    const summary = `${r.calls} calls over ${r.exports.length} exports in ${seconds.toFixed(1)} s: ${r.returned} returned, ${r.documented} documented errors, ${r.traps} traps, ${r.other} other, ${r.wrongField} naming another field`;
    console.log(`# ${path}: ${summary}`);
    const failures = r.failures.map((f) => `${f.what}: ${f.export}(${f.call}) → ${f.error}`).join('\n');
    assert.ok(r.exports.length > 0, 'no export found');
    assert.equal(r.traps, 0, `traps:\n${failures}`);
    assert.equal(r.other, 0, `errors other than the documented Error:\n${failures}`);
    assert.equal(r.wrongField, 0, `errors whose field does not name the argument:\n${failures}`);
    assert.equal(r.extraRejected, 0, `extra arguments rejected:\n${failures}`);
    assert.ok(r.stillAnswering, `an export no longer answers its valid call:\n${failures}`);
    assert.ok(r.unchanged, `an export's valid call changed its answer:\n${failures}`);
    assert.ok(r.documented > r.calls / 4 && r.returned > 0, summary);
  });
}

// A freed RecordingParser (issue 21 item 1): every method, getter and a second free() answer the
// documented Error (`kind: "invalid"`, `field: "this"`), not wasm-bindgen's "null pointer passed
// to rust" (scripts/guard-freed.mjs rewrites the glue); a live parser and the module answer as
// before. In both modules that have the class.
for (const path of ['pkg/input_shaping', 'pkg/page/recording']) {
  test(`${path}: a freed RecordingParser answers the documented Error`, async () => {
    const api = await import(`${root}${path}.js`);
    api.initSync({ module: readFileSync(`${root}${path}_bg.wasm`) });
    const text = '#time,accel_x,accel_y,accel_z\n0,1,2,3\n0.001,2,3,4\n0.002,3,4,5\n';
    const p = new api.RecordingParser();
    p.push(text.slice(0, 20));
    p.free();
    const uses = {
      push: () => p.push(text),
      finish: () => p.finish(),
      lines: () => p.lines,
      rows: () => p.rows,
      'free again': () => p.free(),
    };
    for (const [what, use] of Object.entries(uses)) {
      assert.throws(use, (e) => e instanceof Error && e.kind === 'invalid' && e.field === 'this'
        && /^this: this RecordingParser was freed/.test(e.message), what);
    }
    const live = new api.RecordingParser();
    live.push(text);
    assert.equal(live.finish().rows, 3);
    live.free();
  });
}
