// A long sequence inside an argument is refused before it is read (issue 21 item 1).
//
// The 10⁶-call boundary profile in Chromium (2026-12-04, commit 3912351) found a trap the Node
// runs never showed: `drawSpectrum(canvas, spectrum, { peaksHz: new Float32Array(2 ** 26 + 1) })`
// made the JS reader grow a `Vec<f64>` element by element to a gigabyte, the browser's wasm
// memory refused to grow, and the allocator's abort (`unreachable`) left the module trapping on
// every later call. Node grants the memory, so there the same call ended in the documented error
// after reading everything. Now a sequence read through the JS reader (`crate/js/jsde.rs`) is at
// most 2²⁶ elements (the longest array an export's own arguments take), checked on its length
// before its first element: here the module's memory must not grow by the size of the input.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync, existsSync } from 'node:fs';
import { fileURLToPath } from 'node:url';

const root = fileURLToPath(new URL('../../', import.meta.url));
const LIMIT = 2 ** 26;

async function load(path) {
  assert.ok(existsSync(`${root}${path}.js`), `${path}.js is missing: npm run build first`);
  const api = await import(`${root}${path}.js`);
  const wasm = api.initSync({ module: readFileSync(`${root}${path}_bg.wasm`) });
  return { api, memory: () => wasm.memory.buffer.byteLength };
}

/** A sampled command whose `values` is `values` (simulate's spec, docs/js-api.md). */
function spec(values) {
  return {
    plant: { kind: 'modal', modes: [{ frequencyHz: 2, damping: 0.05 }] },
    shaper: { family: 'zv' },
    command: { kind: 'sampled', samplePeriod: 0.01, values },
  };
}

function refused(api, values) {
  let error;
  try {
    api.simulate(spec(values));
  } catch (e) {
    error = e;
  }
  assert.ok(error instanceof Error, `expected the documented Error, got ${error}`);
  return error;
}

test('a typed array of 2^26 + 1 inside a spec is refused by its length, unread', async () => {
  const { api, memory } = await load('pkg/input_shaping');
  const before = memory();
  const e = refused(api, new Float32Array(LIMIT + 1));
  assert.equal(e.kind, 'parse');
  assert.equal(e.field, 'command.values');
  assert.match(e.message, /invalid length 67108865, expected at most 67108864 elements/);
  // Reading it would have taken 2^26 × 8 bytes (512 MiB) at least.
  assert.ok(memory() - before < 64 << 20, `memory grew by ${(memory() - before) >> 20} MiB`);
  // The module still answers.
  assert.ok(api.simulate(spec([0, 1, 1, 1])).shaped, 'simulate no longer answers');
});

test('an array longer than 2^26 (sparse) is refused by its length', async () => {
  const { api } = await load('pkg/input_shaping');
  const e = refused(api, new Array(LIMIT + 1));
  assert.equal(e.field, 'command.values');
  assert.match(e.message, /invalid length 67108865/);
});

// A generator that never ends is stopped at the limit, not at memory's end. It is read one
// element at a time through the iterator protocol, 2^26 of them (about 40 s), so this case runs
// in the long profile (`npm run test:boundary:long`) only.
const LONG = Number(process.env.BOUNDARY_CALLS ?? 0) >= 100000;
test('an endless iterable is refused at 2^26 elements', { skip: !LONG && 'long profile only' }, async () => {
  const { api, memory } = await load('pkg/input_shaping');
  const before = memory();
  const e = refused(api, {
    *[Symbol.iterator]() {
      for (;;) yield 0;
    },
  });
  assert.equal(e.field, 'command.values');
  assert.match(e.message, /invalid length 67108865/);
  assert.ok(memory() - before < 1200 << 20, `memory grew by ${(memory() - before) >> 20} MiB`);
  assert.ok(api.simulate(spec([0, 1, 1, 1])).shaped, 'simulate no longer answers');
});

test('at the limit a sequence is still read (the check is not off by one)', async () => {
  const { api } = await load('pkg/input_shaping');
  // 2^26 holes: read as far as the first element, which is not a number, so the error names
  // the element, not the length.
  const e = refused(api, new Array(LIMIT));
  assert.equal(e.field, 'command.values[0]');
  assert.doesNotMatch(e.message, /invalid length/);
});
