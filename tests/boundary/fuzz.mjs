// The boundary fuzz (issue 21 item 1), shared by Node (tests/boundary/node.test.mjs) and
// headless Chromium (tests/e2e/boundary.test.mjs): every export of a built module (pkg/), called
// through its generated JS glue with hostile values — wrong types, null / undefined, strings
// where numbers go, NaN, detached and huge typed arrays, huge sparse arrays, deep nesting,
// missing and extra arguments — in every argument position and inside the valid objects.
// Every call must return or throw the documented `Error` (`kind`, and `field` for an input
// error, naming the argument it came from); a trap (`WebAssembly.RuntimeError`) or any other
// thrown value is counted as a failure. Afterwards every export still answers its valid call
// with the same result as before. Plain ES module, no Node or DOM APIs at the top level.

/** The documented kinds (docs/js-api.md, *Errors*). */
export const KINDS = ['invalid', 'tooLarge', 'infeasible', 'parse', 'render', 'unavailable'];
/** The kinds of an input error, which always name the field. */
const FIELD_KINDS = ['invalid', 'tooLarge', 'parse'];

/** Mulberry32: a tiny deterministic PRNG. */
export function rng(seed) {
  let a = seed >>> 0;
  return () => {
    a = (a + 0x6d2b79f5) >>> 0;
    let t = a;
    t = Math.imul(t ^ (t >>> 15), t | 1);
    t ^= t + Math.imul(t ^ (t >>> 7), t | 61);
    return ((t ^ (t >>> 14)) >>> 0) / 4294967296;
  };
}

function detached(n) {
  const a = new Float64Array(n);
  structuredClone(a.buffer, { transfer: [a.buffer] });
  return a;
}

function nested(depth) {
  let v = 1;
  for (let i = 0; i < depth; i++) v = [v];
  return v;
}

let hugeFloat32;
/** A Float32Array one element longer than the longest signal accepted (2^26): 256 MB, made once. */
function huge32() {
  hugeFloat32 ??= new Float32Array((1 << 26) + 1);
  return hugeFloat32;
}

/**
 * The hostile values: [label, make]. `make` builds a fresh value (the huge typed array is
 * shared: it is never written to).
 */
export const HOSTILE = [
  ['123', () => 123], ['-1', () => -1], ['0', () => 0], ['-0', () => -0], ['0.5', () => 0.5],
  ['NaN', () => NaN], ['Infinity', () => Infinity], ['-Infinity', () => -Infinity],
  ['1e308', () => 1e308], ['2**53+2', () => 2 ** 53 + 2], ['5e-324', () => 5e-324],
  ['{}', () => ({})], ['[]', () => []], ['null', () => null], ['undefined', () => undefined],
  ['true', () => true], ['false', () => false],
  ["''", () => ''], ["'abc'", () => 'abc'], ["'123'", () => '123'], ["'0.05'", () => '0.05'],
  ["'NaN'", () => 'NaN'], ["'zv'", () => 'zv'], ["'csv'", () => 'csv'], ["'\\0'", () => '\u0000'],
  ["'🙂'", () => '🙂'], ['lone surrogate', () => '\ud800x'], ['10⁶-char string', () => '1,'.repeat(5e5)],
  ['CSV-looking string', () => '#time,accel_x\n0,1\n0.001,2\n'],
  ['[1,2,3]', () => [1, 2, 3]], ['[null]', () => [null]], ['[[]]', () => [[]]], ['[{}]', () => [{}]],
  ["['1','2']", () => ['1', '2']], ['[NaN, Infinity]', () => [NaN, Infinity]],
  ['sparse Array(2^32-1)', () => new Array(2 ** 32 - 1)], ['sparse Array(2^27)', () => new Array(2 ** 27)],
  ['Array(1e5) of 0', () => new Array(1e5).fill(0)],
  ['Float64Array(0)', () => new Float64Array(0)], ['Float64Array(3)', () => new Float64Array([1, 2, 3])],
  ['Float64Array NaN', () => new Float64Array([NaN, 1, 2, 3])], ['Float32Array(4)', () => new Float32Array(4)],
  ['Int32Array(4)', () => new Int32Array(4)], ['Uint8Array(4)', () => new Uint8Array(4)],
  ['BigInt64Array(2)', () => new BigInt64Array(2)], ['ArrayBuffer(16)', () => new ArrayBuffer(16)],
  ['DataView', () => new DataView(new ArrayBuffer(8))],
  ['detached Float64Array', () => detached(64)], ['detached Float32Array', () => { const a = new Float32Array(8); structuredClone(a.buffer, { transfer: [a.buffer] }); return a; }],
  ['huge Float32Array (2^26+1)', huge32],
  ['BigInt', () => 12345678901234567890n], ['Symbol', () => Symbol('x')], ['function', () => () => 1],
  ['Map', () => new Map([['family', 'zv']])], ['Set', () => new Set([1])], ['Date', () => new Date(0)],
  ['RegExp', () => /x/], ['Promise', () => Promise.resolve(1)], ['Error', () => new Error('x')],
  ['null-prototype object', () => Object.create(null)],
  ['object with numeric keys', () => ({ 0: 1, 1: 2, length: 2 })],
  ['deep array (10⁴)', () => nested(1e4)], ['deep array (10⁵)', () => nested(1e5)],
  ['throwing getters', () => ({ get family() { throw new TypeError('boom'); }, get frequencyHz() { throw 7; }, get impulses() { throw 7; }, get sampleRateHz() { throw 7; } })],
  ['Proxy with throwing traps', () => new Proxy({}, { get() { throw 7; }, has() { throw 7; }, ownKeys() { throw 7; }, getOwnPropertyDescriptor() { throw 7; } })],
  ['transparent Proxy of a Float64Array', () => new Proxy(new Float64Array([1, 2, 3, 4]), {})],
  ['transparent Proxy of an array', () => new Proxy([1, 2, 3, 4], {})],
  ['transparent Proxy of a spec', () => new Proxy({ family: 'zv', modes: [{ frequencyHz: 40 }] }, {})],
  ['{frequencyHz: NaN}', () => ({ frequencyHz: NaN, damping: Infinity })],
  ['{family: "nope"}', () => ({ family: 'nope', modes: [{ frequencyHz: 1 }] })],
  ['{family: 123}', () => ({ family: 123 })],
  ['{impulses: huge}', () => ({ impulses: new Array(1e5).fill({ time: 0, amplitude: 1 }) })],
  ['{channels: [{}]}', () => ({ channels: [{}], sampleRateHz: 1000 })],
  ['{frequencyHz, psd} mismatched', () => ({ frequencyHz: [1, 2, 3], psd: [1] })],
];

/** A decaying 40 Hz ring sampled at 1 kHz, with a little deterministic noise. */
function ring(n = 1024) {
  const r = rng(7);
  const x = new Float64Array(n);
  for (let k = 0; k < n; k++) {
    const t = k / 1000;
    x[k] = Math.exp(-0.05 * 2 * Math.PI * 40 * t) * Math.sin(2 * Math.PI * 40 * t) + 0.001 * (r() - 0.5);
  }
  return x;
}

function csv(n = 600) {
  const x = ring(n);
  let s = '#time,accel_x,accel_y,accel_z\n';
  for (let k = 0; k < n; k++) s += `${(k / 1000).toFixed(6)},${x[k].toFixed(6)},0,1\n`;
  return s;
}

/**
 * Every export with a valid argument list: `names` are the arguments' names (the `field` an
 * error about that argument starts with; `null`: a spec whose fields are named from its root).
 * `canvas` marks the drawing exports (their first argument is a canvas).
 */
function exportsTable(env) {
  const mode = () => ({ frequencyHz: 40, damping: 0.05 });
  const shaper = () => ({ impulses: [{ time: 0, amplitude: 0.5 }, { time: 0.0125, amplitude: 0.5 }], duration: 0.0125 });
  const spectrum = () => {
    const f = Float64Array.from({ length: 100 }, (_, i) => i * 2);
    const p = Float64Array.from(f, (v) => 1e-3 + 1 / (1 + ((v - 40) / 2) ** 2));
    return { frequencyHz: f, psd: p };
  };
  const text = csv();
  return [
    // A family the page's design worker's module designs too (it designs the solved ones only).
    { name: 'design', names: [null], args: () => [{ family: 'sampled', periodS: 0.012, impulses: 36, delaySamples: 17, modes: [{ frequencyHz: 4.7746, damping: 0.02 }] }] },
    { name: 'residualVibration', names: ['shaper', 'mode'], args: () => [shaper(), mode()] },
    { name: 'sensitivity', names: ['shaper', 'options'], args: () => [shaper(), { fromHz: 0, toHz: 100, points: 50, damping: 0.05 }] },
    { name: 'insensitivity', names: ['shaper', 'mode', 'vtol'], args: () => [shaper(), mode(), 0.05] },
    { name: 'sensitivityMap', names: ['shaper', 'options'], args: () => [shaper(), { fromHz: 0, toHz: 100, frequencyPoints: 20, dampingFrom: 0, dampingTo: 0.2, dampingPoints: 5 }] },
    { name: 'dampingSensitivity', names: ['shaper', 'options'], args: () => [shaper(), { frequencyHz: 40, fromDamping: 0, toDamping: 0.3, points: 20 }] },
    { name: 'dampingInsensitivity', names: ['shaper', 'mode', 'vtol'], args: () => [shaper(), mode(), 0.05] },
    { name: 'robustnessTable', names: ['mode', 'vtol', 'specs'], args: () => [mode(), 0.05, [{ family: 'zv' }, { family: 'ei', vtol: 0.05 }]] },
    { name: 'families', names: [], args: () => [] },
    { name: 'exportShaper', names: ['shaper', 'options'], args: () => [shaper(), { format: 'cFixed', amplitudeSteps: 255, tickS: 1e-5 }] },
    { name: 'klipperFigures', names: ['shaper', 'options'], args: () => [shaper(), { scv: 5 }] },
    { name: 'rampDelay', names: ['shaper', 'mode'], args: () => [shaper(), mode()] },
    { name: 'sampledReport', names: [null], args: () => [{ family: 'sampled', periodS: 0.012, impulses: 36, delaySamples: 17, modes: [{ frequencyHz: 4.7746, damping: 0.02 }] }] },
    { name: 'quantize', names: ['shaper', 'mode', 'options'], args: () => [shaper(), mode(), { amplitudeSteps: 255, tickS: 0.001 }] },
    { name: 'realizeShaper', names: [null, 'options'], args: () => [{ family: 'zv', modes: [{ frequencyHz: 60, damping: 0 }] }, { firmware: 'generic', periodS: 0.001, amplitudeSteps: 255, maxImpulses: 5, curve: { fromHz: 0, toHz: 150, points: 64 } }] },
    { name: 'simulate', names: [null], args: () => [{ plant: { kind: 'modal', modes: [{ frequencyHz: 4, damping: 0.05 }] }, command: { kind: 'trapezoid', distance: 1, maxVelocity: 1, maxAcceleration: 4 }, shaper: { family: 'zvd' }, sampleRateHz: 100 }] },
    { name: 'simulateCorner', names: [null], args: () => [{ path: { kind: 'square', sideMm: 10 }, velocity: 100, accel: 3000, squareCornerVelocity: 5, x: { modes: [{ frequencyHz: 40, damping: 0.05 }], shaper: { family: 'zv' } }, y: { modes: [{ frequencyHz: 50, damping: 0.05 }] }, samplePeriodS: 0.002, magnify: 10 }] },
    { name: 'profileSpectrum', names: ['command', 'options'], args: () => [{ kind: 'profile', shape: 'triangle', frequencyHz: 2, distance: 1, duration: 1.5 }, { toHz: 10, points: 64 }] },
    { name: 'spectrum', names: [null], args: () => [{ command: { kind: 'step' }, shaper: { family: 'zvd', modes: [{ frequencyHz: 1 }] }, toHz: 5, points: 64 }] },
    { name: 'renderPlayground', names: [null, 'canvases'], args: () => [{ modes: [{ frequencyHz: 40, damping: 0.05 }], shapers: [{ family: 'zv' }], view: { vtol: 0.05, points: 50, samples: 200, mapFrequencyPoints: 8, mapDampingPoints: 4, dampingPoints: 8, spectrumPoints: 32 } }, {}] },
    { name: 'parseRecording', names: ['text', 'options'], aliases: { text: ['recording'] }, args: () => [text, { fileName: 'x.csv' }] },
    { name: 'welch', names: ['signal', 'options'], aliases: { options: ['signal'] }, args: () => [ring(), { sampleRateHz: 1000, segmentLength: 256 }] },
    { name: 'fftSpectrum', names: ['signal', 'options'], aliases: { options: ['signal'] }, args: () => [ring(), { sampleRateHz: 1000 }] },
    { name: 'identifyModes', names: ['recording', 'options'], aliases: { recording: ['signal', 'spectrum'] }, args: () => [ring(), { sampleRateHz: 1000, segmentLength: 256 }] },
    { name: 'recommendShaper', names: ['spectrum', 'modes', 'options'], args: () => [spectrum(), [mode()], { families: [{ family: 'zv' }, { family: 'ei', vtol: 0.05 }] }] },
    { name: 'firmwareConfig', names: ['request'], args: () => [{ firmware: 'klipper', axes: [{ axis: 'x', family: 'mzv', frequencyHz: 53.8 }] }] },
    { name: 'renderCorner', names: [null, 'shapers', 'canvas', 'options'], canvas: true, args: () => [{ path: { kind: 'square', sideMm: 10 }, velocity: 100, accel: 3000, x: { modes: [{ frequencyHz: 40, damping: 0.05 }] }, y: { modes: [{ frequencyHz: 50, damping: 0.05 }] }, samplePeriodS: 0.002 }, [{ family: 'zv' }], env.canvas(), { pixelRatio: 1 }] },
    { name: 'drawSpectrum', names: ['canvas', 'spectrum', 'options'], canvas: true, args: () => [env.canvas(), spectrum(), { peaksHz: [40] }] },
    // Its data's fields are named by their keys (`frequencyHz`, `shapers[0].values`), as documented.
    { name: 'drawKlipperChart', names: ['canvas', 'data', 'options'], canvas: true, aliases: { data: ['frequencyHz', 'psdSum', 'psdX', 'psdY', 'psdZ', 'after', 'shapers'] }, args: () => { const s = spectrum(); return [env.canvas(), { frequencyHz: s.frequencyHz, psdSum: s.psd }, { maxHz: 150 }]; } },
    // The realisation chart (issue 23): the two curves per shaper are realizeShaper's.
    { name: 'drawRealisation', names: ['canvas', 'data', 'options'], canvas: true, aliases: { data: ['shapers', 'vtol', 'modesHz'] }, args: () => [env.canvas(), { shapers: [{ label: 'ZV', color: '#0072b2', ideal: { frequencyHz: [0, 30, 60, 90], vibration: [1, 0.5, 0, 0.5] }, realised: { frequencyHz: [0, 30, 60, 90], vibration: [1, 0.45, 0.06, 0.55] } }], vtol: 0.05, modesHz: [60] }, { pixelRatio: 1 }] },
    // The class: its constructor, and its methods on a live parser (a new one after `finish`).
    { name: 'new RecordingParser', names: ['options'], cls: 'new', args: () => [{ fileName: 'x.csv' }] },
    { name: 'RecordingParser.push', names: ['chunk'], aliases: { chunk: ['recording'] }, cls: 'push', args: () => [text.slice(0, text.indexOf('\n', 200) + 1)] },
    { name: 'RecordingParser.finish', names: [], cls: 'finish', args: () => [] },
  ];
}

/**
 * Calls entry `e` of `api` with `args`. `push` goes to a parser kept between calls (after a
 * bad chunk it keeps throwing, as documented; `fresh` starts a new one); `finish` to a new
 * parser that was given the whole valid recording.
 */
function invoke(api, e, args, state, fresh = false) {
  if (!e.cls) return api[e.name](...args);
  if (e.cls === 'new') {
    const p = new api.RecordingParser(...args);
    const lines = p.lines;
    p.free();
    return { lines };
  }
  if (e.cls === 'push') {
    if (fresh || state.parser === null || state.pushes++ > 20) {
      state.parser?.free();
      state.parser = new api.RecordingParser();
      state.pushes = 0;
    }
    void state.parser.lines;
    return state.parser.push(...args);
  }
  const p = new api.RecordingParser();
  try {
    p.push(state.text);
    return p.finish(...args);
  } finally { p.free(); }
}

/** What a call did: 'returned', 'documented' (the documented Error), 'trap' or 'other'. */
export function classify(thrown, error) {
  if (!thrown) return 'returned';
  if (typeof WebAssembly !== 'undefined' && error instanceof WebAssembly.RuntimeError) return 'trap';
  if (!(error instanceof Error) || !KINDS.includes(error.kind) || typeof error.message !== 'string' || error.message === '') return 'other';
  if (FIELD_KINDS.includes(error.kind) && (typeof error.field !== 'string' || error.field === '')) return 'other';
  return 'documented';
}

function describe(v) {
  if (typeof v === 'string') return v.length > 40 ? `string(${v.length})` : JSON.stringify(v);
  if (typeof v === 'bigint' || typeof v === 'symbol' || typeof v === 'function') return typeof v;
  if (ArrayBuffer.isView(v)) return `${v.constructor.name}(${v.length})`;
  if (Array.isArray(v)) return `Array(${v.length})`;
  try { const s = JSON.stringify(v); return s === undefined ? String(v) : s.length > 60 ? `${s.slice(0, 60)}…` : s; } catch { return Object.prototype.toString.call(v); }
}

/**
 * Whether an error's `field` names the argument `name` of export `e` that was replaced by a
 * hostile value: `name`, or a field inside it (`options.points`, `modes[0]`), or one of the
 * export's documented aliases (a recording's content errors name `recording`, or
 * `recording (line 10)`). An options object's own checks name the argument too
 * (`options.sampleRateHz`, issue 21). A drawing export without a canvas (Node) always names
 * `canvas` first.
 */
function namesArgument(field, e, name, canDraw) {
  if (e.canvas && !canDraw) return field === 'canvas';
  const under = (n) => field === n || field.startsWith(`${n}.`) || field.startsWith(`${n}[`) || field.startsWith(`${n} (`);
  return under(name) || (e.aliases?.[name] ?? []).some(under);
}

/** Sets a hostile value at a random depth inside `value` (an object or array); false if none. */
function plant(value, hostile, r, path) {
  if (value === null || typeof value !== 'object' || ArrayBuffer.isView(value)) return false;
  const keys = Object.keys(value);
  if (keys.length === 0) return false;
  const key = keys[Math.floor(r() * keys.length)];
  path.push(key);
  if (r() < 0.5 && plant(value[key], hostile, r, path)) return true;
  value[key] = hostile;
  return true;
}

/**
 * Runs `calls` random calls over every export `api` has (seeded). Returns the counts
 * `{ calls, returned, documented, traps, other, wrongField, failures: [...] }` (failures: the
 * first few of each bad outcome, with the call that gave it) and whether every export still
 * answers its valid call as before (`stillAnswering`, `unchanged`).
 */
export function fuzz(api, { calls = 2000, seed = 20261204, env = { canvas: () => null }, onCall = null } = {}) {
  const table = exportsTable(env).filter((e) => typeof api[e.cls ? 'RecordingParser' : e.name] === 'function');
  const values = HOSTILE.map(([label, make]) => [label, make]);
  const r = rng(seed);
  const pick = (list) => list[Math.floor(r() * list.length)];
  const state = { parser: null, pushes: 0, text: csv() };
  const counts = { exports: table.map((e) => e.name), calls: 0, returned: 0, documented: 0, traps: 0, other: 0, wrongField: 0, extraRejected: 0, failures: [], ms: {} };
  const canDraw = env.canvas() !== null;
  const note = (what, e, call, error) => {
    if (counts.failures.filter((f) => f.what === what).length < 8) {
      counts.failures.push({ what, export: e.name, call, error: error instanceof Error ? `${error.constructor.name}: ${error.message} (kind ${error.kind}, field ${error.field})` : describe(error) });
    }
  };
  // The valid calls first: what each answers, to compare with after the fuzz.
  const before = new Map();
  for (const e of table) {
    if (e.canvas && !canDraw) continue;
    before.set(e.name, snapshot(invoke(api, e, e.args(), state, true)));
  }
  for (let n = 0; n < calls; n++) {
    const e = pick(table);
    const args = e.args();
    const how = r();
    let call;
    let expectField = null; // the argument name the error's field must start with
    let valid = false; // the arguments are valid (extra ones only): the call must not throw
    if (how < 0.4 && args.length > 0) {
      const i = Math.floor(r() * args.length);
      const [label, make] = pick(values);
      args[i] = make();
      expectField = e.names[i];
      call = `arg ${i} = ${label}`;
    } else if (how < 0.75 && args.length > 0) {
      const i = Math.floor(r() * args.length);
      const [label, make] = pick(values);
      const path = [];
      if (!plant(args[i], make(), r, path)) { args[i] = make(); expectField = e.names[i]; }
      call = `arg ${i}${path.map((k) => `.${k}`).join('')} = ${label}`;
    } else if (how < 0.85) {
      const keep = Math.floor(r() * args.length);
      args.length = keep;
      call = `only ${keep} arguments`;
    } else if (how < 0.95) {
      const extra = 1 + Math.floor(r() * 3);
      const labels = [];
      for (let k = 0; k < extra; k++) { const [label, make] = pick(values); args.push(make()); labels.push(label); }
      valid = !e.canvas || canDraw;
      if (e.cls === 'push') state.parser = null;
      call = `extra arguments ${labels.join(', ')}`;
    } else {
      const labels = [];
      for (let i = 0; i < args.length; i++) { const [label, make] = pick(values); args[i] = make(); labels.push(label); }
      call = `every argument hostile: ${labels.join(', ')}`;
    }
    let thrown = false;
    let error;
    onCall?.(n, e.name, call);
    const t0 = performance.now();
    try { invoke(api, e, args, state); } catch (err) { thrown = true; error = err; }
    const dt = performance.now() - t0;
    if (dt > (counts.slowest?.ms ?? 0)) counts.slowest = { ms: Math.round(dt), export: e.name, call };
    counts.ms[e.name] = (counts.ms[e.name] ?? 0) + dt;
    counts.calls++;
    const outcome = classify(thrown, error);
    counts[outcome === 'trap' ? 'traps' : outcome]++;
    if (outcome === 'trap' || outcome === 'other') note(outcome, e, call, error);
    if (outcome === 'trap') state.parser = null;
    if (outcome === 'documented' && expectField !== undefined && expectField !== null && FIELD_KINDS.includes(error.kind)) {
      if (!namesArgument(error.field, e, expectField, canDraw)) {
        counts.wrongField++;
        note('wrongField', e, `${call}: field must start with ${expectField}`, error);
      }
    }
    if (valid && thrown) {
      counts.extraRejected++;
      note('extraRejected', e, call, error);
    }
  }
  // Afterwards: every export answers its valid call, with the same result.
  counts.stillAnswering = true;
  counts.unchanged = true;
  for (const e of table) {
    if (!before.has(e.name)) continue;
    let now;
    try { now = snapshot(invoke(api, e, e.args(), state, true)); } catch (err) {
      counts.stillAnswering = false;
      note('notAnswering', e, 'the valid call', err);
      continue;
    }
    if (now !== before.get(e.name)) { counts.unchanged = false; note('changed', e, 'the valid call', now.slice(0, 80)); }
  }
  return counts;
}

/** A comparable text of a result (typed arrays as arrays). */
function snapshot(v) {
  return JSON.stringify(v ?? null, (_, x) => (ArrayBuffer.isView(x) ? Array.from(x) : x));
}
