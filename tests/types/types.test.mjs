// The TypeScript declarations of pkg/input_shaping.d.ts are the truth (issue 21 item 2;
// docs/js-api.md, *TypeScript*). Three checks, after `npm run build`:
//  1. example.ts, a program using every export, compiles with `tsc --strict --noEmit`;
//  2. mistakes.ts compiles (each mistake is marked `// @ts-expect-error TSnnnn`, so tsc fails
//     if one of them compiles), and with the markers removed every marked line, and no other,
//     fails with the code its marker names: each mistake fails on its own, for its reason;
//  3. every export is called with representative arguments through the generated glue, and
//     its results are written into a .ts file as object literals typed with the declared
//     result type (`const r: Shaper = { … }`), compiled the same way: a field the declaration
//     lacks is an excess property, a declared field the result lacks a missing property, a
//     wrong type a wrong type. The errors are thrown objects too (`InputShapingError`). Every
//     call that returned is written there too, with its arguments, so the declared parameter
//     types take what the functions take.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { existsSync, mkdirSync, readFileSync, writeFileSync } from 'node:fs';
import { fileURLToPath } from 'node:url';

const root = fileURLToPath(new URL('../../', import.meta.url));
const here = `${root}tests/types/`;
const out = `${root}target/types/`;
const tsc = `${root}node_modules/typescript/bin/tsc`;

/** Compiles `files` with tests/types/tsconfig.json's options; → { ok, errors: [{ file, line, code, text }] }. */
function compile(files) {
  const config = `${out}tsconfig.${files.length}.${files[0].replace(/\W/g, '_')}.json`;
  mkdirSync(out, { recursive: true });
  writeFileSync(config, JSON.stringify({ extends: `${here}tsconfig.json`, files }));
  try {
    execFileSync(process.execPath, [tsc, '-p', config, '--pretty', 'false'], { encoding: 'utf8' });
    return { ok: true, errors: [] };
  } catch (e) {
    const text = `${e.stdout ?? ''}${e.stderr ?? ''}`;
    const errors = [...text.matchAll(/^(.*?)\((\d+),\d+\): error (TS\d+): (.*)$/gm)].map((m) => ({
      file: m[1],
      line: Number(m[2]),
      code: m[3],
      text: m[4],
    }));
    return { ok: false, errors, text };
  }
}

function requireBuild() {
  assert.ok(existsSync(`${root}pkg/input_shaping.d.ts`), 'pkg/input_shaping.d.ts is missing: npm run build first');
}

test('the declarations of every module have no `any` outside comments', () => {
  requireBuild();
  const modules = ['pkg/input_shaping', 'pkg/page/playground', 'pkg/page/designer', 'pkg/page/recording'];
  for (const file of modules.flatMap((m) => [`${m}.d.ts`, `${m}_bg.wasm.d.ts`])) {
    const code = readFileSync(`${root}${file}`, 'utf8').replace(/\/\*[\s\S]*?\*\//g, '').replace(/\/\/.*$/gm, '');
    const anys = code.split('\n').filter((l) => /\bany\b/.test(l));
    assert.deepEqual(anys, [], `${file}: lines with any:\n${anys.join('\n')}`);
  }
});

test('example.ts compiles with tsc --strict --noEmit', () => {
  requireBuild();
  const r = compile([`${here}example.ts`]);
  assert.ok(r.ok, r.text);
});

test('every mistake in mistakes.ts fails to compile, each for its own reason', () => {
  requireBuild();
  const source = readFileSync(`${here}mistakes.ts`, 'utf8');
  const r = compile([`${here}mistakes.ts`]);
  assert.ok(r.ok, `a marked mistake compiles, or another line fails:\n${r.text}`);
  // The markers removed: each marked line must fail with its code, no other line may fail.
  const lines = source.split('\n');
  const expected = new Map();
  const stripped = lines.map((line, i) => {
    const m = line.match(/^\s*\/\/ @ts-expect-error (TS\d+)\s*$/);
    if (!m) return line;
    expected.set(i + 2, m[1]); // the statement is on the next line (1-based: i + 2)
    return '//';
  });
  assert.ok(expected.size >= 25, `only ${expected.size} mistakes`);
  const file = `${out}mistakes_unmarked.ts`;
  writeFileSync(file, stripped.join('\n').replaceAll('../../pkg/', `${root}pkg/`));
  const bare = compile([file]);
  const byLine = new Map();
  for (const e of bare.errors) byLine.set(e.line, [...(byLine.get(e.line) ?? []), e]);
  const problems = [];
  for (const [line, code] of expected) {
    const got = byLine.get(line) ?? [];
    if (got.length === 0) problems.push(`line ${line} (${lines[line - 1].trim()}) compiles`);
    else if (!got.some((e) => e.code === code)) {
      problems.push(`line ${line}: expected ${code}, got ${got.map((e) => `${e.code} ${e.text}`).join('; ')}`);
    }
  }
  for (const [line, errs] of byLine) {
    if (!expected.has(line)) problems.push(`unmarked line ${line} fails: ${errs.map((e) => e.text).join('; ')}`);
  }
  assert.deepEqual(problems, [], problems.join('\n'));
});

/** `value` as a TypeScript expression: typed arrays as `new Float64Array([…])`, long arrays
 * cut to their first elements (their type is what is checked). */
function literal(value, depth = 0) {
  if (value === undefined) return 'undefined';
  if (value === null) return 'null';
  if (typeof value === 'number') return Number.isNaN(value) ? 'NaN' : Number.isFinite(value) ? String(value) : value > 0 ? 'Infinity' : '-Infinity';
  if (typeof value === 'string' || typeof value === 'boolean') return JSON.stringify(value);
  if (value instanceof Float64Array || value instanceof Float32Array) {
    return `new ${value.constructor.name}([${Array.from(value.slice(0, 2)).map((v) => literal(v)).join(', ')}])`;
  }
  const pad = '  '.repeat(depth + 1);
  if (Array.isArray(value)) {
    if (value.length === 0) return '[]';
    // A fixed-length pair ([low, high]) is kept whole: it may be declared a tuple.
    const kept = value.length === 2 ? value : value.slice(0, 2);
    return `[${kept.map((v) => literal(v, depth + 1)).join(', ')}]`;
  }
  if (typeof value === 'object') {
    const fields = Object.entries(value).map(([k, v]) => `${pad}${JSON.stringify(k)}: ${literal(v, depth + 1)},`);
    return `{\n${fields.join('\n')}\n${'  '.repeat(depth)}}`;
  }
  throw new Error(`cannot write ${typeof value}`);
}

/** A thrown error as a literal of `InputShapingError` (its name, message and own fields). */
function errorLiteral(e) {
  assert.ok(e instanceof Error, `not an Error: ${e}`);
  return literal({ name: e.name, message: e.message, ...Object.fromEntries(Object.entries(e)) });
}

/** Every export called with representative arguments: the results ([declared type, value])
 * and the calls that returned ([export, arguments]). */
function calls(exports) {
  const made = [];
  const api = new Proxy(exports, {
    get(target, name) {
      const f = target[name];
      if (typeof f !== 'function' || name === 'RecordingParser') return f;
      return (...args) => {
        const value = f(...args);
        made.push([name, args]);
        return value;
      };
    },
  });
  const data = (f) => readFileSync(`${root}tests/data/klipper/${f}`, 'utf8');
  const mode = { frequencyHz: 2, damping: 0.05 };
  const results = [];
  const add = (type, value) => results.push([type, value]);
  const fails = (f) => {
    try {
      f();
    } catch (e) {
      return e;
    }
    assert.fail(`did not throw: ${f}`);
  };

  const zvd = api.design({ family: 'zvd', modes: [mode] });
  add('Shaper', zvd);
  // Every family from its editor defaults: the spec is a DesignSpec, the design a Shaper.
  for (const f of api.families()) {
    add('FamilyInfo', f);
    const spec = { family: f.name, modes: [mode] };
    for (const p of f.params) if (p.default !== undefined) spec[p.name] = p.default;
    add('DesignSpec', spec);
    add('Shaper', api.design(spec));
  }
  add('number', api.residualVibration(zvd, mode));
  add('SensitivityCurve', api.sensitivity(zvd, { fromHz: 0, toHz: 4, points: 5 }));
  add('Insensitivity', api.insensitivity(zvd, mode, 0.05));
  add('SensitivityMap', api.sensitivityMap(zvd, { fromHz: 0, toHz: 4, frequencyPoints: 3, dampingFrom: 0, dampingTo: 0.2, dampingPoints: 2 }));
  add('DampingSensitivityCurve', api.dampingSensitivity(zvd, { frequencyHz: 2, fromDamping: 0, toDamping: 0.3, points: 3 }));
  add('DampingInsensitivity', api.dampingInsensitivity(zvd, mode, 0.05));
  add('RobustnessRow[]', api.robustnessTable(mode, 0.05));
  add('RobustnessRow[]', api.robustnessTable(mode, 0.05, [{ family: 'ei', vtol: 0.1 }, { family: 'sampled', periodS: 0.05, impulses: 20 }]));
  for (const format of ['csv', 'json', 'c', 'cFixed', 'rrf']) add('string', api.exportShaper(zvd, { format }));
  add('KlipperFigures', api.klipperFigures(zvd));
  add('KlipperFigures', api.klipperFigures(zvd, null));
  add('KlipperFigures', api.klipperFigures({ impulses: [{ time: 0, amplitude: 1 }] }, { scv: 5 }));
  add('number', api.rampDelay(zvd, mode));
  add('SampledReport', api.sampledReport({ family: 'sampled', periodS: 0.05, impulses: 20, delaySamples: 5, modes: [mode] }));
  add('QuantizeReport', api.quantize(zvd, mode, { amplitudeSteps: 255, tickS: 0.001 }));
  for (const firmware of ['ideal', 'klipper', 'kalico', 'rrf', 'marlin', 'marlinFtMotion', 'prusa', 'generic']) {
    add('Realization', api.realizeShaper({ family: 'mzv', modes: [{ frequencyHz: 40, damping: 0.1 }] }, { firmware, periodS: firmware === 'generic' ? 0.001 : null }));
  }
  add('Realization', api.realizeShaper({ family: 'zvd', modes: [{ frequencyHz: 40, damping: 0.05 }, { frequencyHz: 90, damping: 0.02 }] }, { firmware: 'kalico', vtol: 0.1, curve: { fromHz: 0, toHz: 200, points: 5 } }));
  const modal = { kind: 'modal', modes: [{ frequencyHz: 1.2, damping: 0.012 }, { frequencyHz: 3.4, damping: 0.013, participation: 0.3 }] };
  add('SimulationResult', api.simulate({ plant: modal, command: { kind: 'trapezoid', distance: 1, maxVelocity: 1, maxAcceleration: 4 }, shaper: { family: 'zvd' }, sampleRateHz: 100 }));
  add('SimulationResult', api.simulate({ plant: { kind: 'pendulum', length: 1 }, command: { kind: 'sCurve', distance: 1, maxVelocity: 1, maxAcceleration: 2, maxJerk: 10 }, samplePeriod: 0.05 }));
  add('SimulationResult', api.simulate({ plant: { kind: 'twoMass', baseMass: 1, tipMass: 0.2, stiffness: 100 }, command: { kind: 'profile', shape: 'triangle', frequencyHz: 2, distance: 1, duration: 2 }, impulses: [{ time: 0, amplitude: 1 }], duration: 3 }));
  add('SimulationResult', api.simulate({ plant: { kind: 'vecianaTestBed' }, command: { kind: 'sampled', samplePeriod: 0.1, values: [0, 0.5, 1, 1], interpolation: 'hold' }, shaper: { family: 'zv', modes: [{ frequencyHz: 1.2 }] }, duration: 2, samplePeriod: 0.05 }));
  add('SpectrumResult', api.spectrum({ command: { kind: 'ramp', slope: 1 }, shaper: { family: 'zv', modes: [mode] }, toHz: 10, points: 4, signal: 'position' }));
  add('SpectrumResult', api.spectrum({ command: { kind: 'step' }, plant: modal, points: 3 }));
  add('ProfileSpectrum', api.profileSpectrum({ kind: 'profile', shape: 'robustTrapezium', frequencyHz: 2, deltaHz: 0.2, distance: 1, duration: 2 }, { toHz: 5, points: 3 }));
  add('CornerResult', api.simulateCorner({ path: { kind: 'square', sideMm: 5 }, velocity: 50, accel: 2000, x: { modes: [{ frequencyHz: 40 }], shaper: { family: 'zv' } }, y: { modes: [{ frequencyHz: 50, damping: 0.1 }] }, samplePeriodS: 0.01, magnify: 10 }));
  add('CornerResult', api.simulateCorner({ path: { kind: 'ringingTower', sideMm: 20, thicknessMm: 2 }, velocity: 50, accel: 2000, squareCornerVelocity: 0, x: { modes: [{ frequencyHz: 40 }] }, y: { modes: [{ frequencyHz: 50 }] }, samplePeriodS: 0.01, settleS: 0 }));
  add('PlaygroundResult', api.renderPlayground({
    modes: [mode, { frequencyHz: 5, damping: 0.02 }],
    shapers: [{ family: 'zv' }, { family: 'ei', vtol: 0.05 }],
    designed: [null, null],
    view: { vtol: 0.05, points: 5, samples: 50, plant: { kind: 'pendulum' }, command: { kind: 'trapezoid', distance: 1, maxVelocity: 1, maxAcceleration: 4 } },
  }, {}));
  add('PlaygroundResult', api.renderPlayground({ modes: [mode], shaper: { family: 'umzv' } }));

  // Measured data: a Klipper raw recording, a resonances file, a calibration file.
  const raw = api.parseRecording(data('raw_data_x_single47z08.csv'), { fileName: 'raw_data_x_single47z08.csv' });
  add('ParsedRecording', raw);
  add('Recording', raw);
  const resonances = api.parseRecording(data('resonances_x_m1.csv'), { fileName: 'resonances_x_m1.csv', channel: 'x' });
  add('SpectrumFile', resonances);
  const calibration = api.parseRecording(data('calibration_data_x_m1.csv'), { fileName: 'calibration_data_x_m1.csv' });
  add('SpectrumFile', calibration);
  add('ParsedRecording', api.parseRecording('time,a,b\n0,1,2\n0.01,2,3\n0.02,3,1\n0.03,1,1\n'));
  const parser = new api.RecordingParser({ timeScale: 1 });
  parser.push('#time,accel_x\n0,1\n0.001,2\n');
  parser.push('0.002,1\n0.003,0\n');
  add('number', parser.lines);
  add('number', parser.rows);
  add('ParsedRecording', parser.finish());
  const signal = raw.channels[0].values;
  const fs = raw.sampleRateHz;
  add('Psd', api.welch(signal, { sampleRateHz: fs, segmentLength: 1024, window: 'kaiser', kaiserBeta: 6, detrend: 'linear', scaling: 'spectrum' }));
  add('Psd', api.welch(Array.from(signal.slice(0, 4096)), { preset: 'klipper', sampleRateHz: fs }));
  add('AmplitudeSpectrum', api.fftSpectrum(signal.slice(0, 1000), { sampleRateHz: fs, window: 'hann' }));
  const id = api.identifyModes(raw, { channel: 'accel_x', maxModes: 2 });
  add('Identification', id);
  add('Identification', api.identifyModes(signal, { sampleRateHz: fs, freeDecay: true }));
  add('Identification', api.identifyModes(resonances, { maxModes: 2 }));
  add('Psd', id.spectrum);
  add('IdentifiedMode[]', id.modes);
  add('Recommendation', api.recommendShaper(id.spectrum, id.modes));
  add('Recommendation', api.recommendShaper(calibration, null, { criterion: 'klipper' }));
  add('Recommendation', api.recommendShaper(resonances, [], { criterion: 'optimal', firmware: 'klipper' }));
  add('FirmwareConfig', api.firmwareConfig({ firmware: 'klipperCommand', axes: [{ axis: 'x', family: 'mzv', frequencyHz: 40, damping: 0.1 }] }));
  add('FirmwareConfig', api.firmwareConfig({ firmware: 'rrf', axes: [{ axis: 'x', family: 'custom', impulses: zvd.impulses }] }));

  // Errors: thrown as InputShapingError, recording errors with their line and column.
  add('InputShapingError', fails(() => api.design({ family: 'zv', modes: [{ frequencyHz: 2, damping: 1.5 }] })));
  add('InputShapingError', fails(() => api.design(null)));
  add('InputShapingError', fails(() => api.parseRecording('#time,accel_x\n0,1\n0.001,x\n', { fileName: 'bad.csv' })));
  add('InputShapingError', fails(() => api.drawSpectrum(null, { frequencyHz: [1], psd: [1] })));
  add('InputShapingError', fails(() => api.sensitivityMap(zvd, { fromHz: 0, toHz: 1, frequencyPoints: 2000, dampingFrom: 0, dampingTo: 0.5, dampingPoints: 2000 })));
  return { results, made };
}

test('every export returns what its declaration says, and takes what it was given', async () => {
  requireBuild();
  const api = await import(`${root}pkg/input_shaping.js`);
  api.initSync({ module: readFileSync(`${root}pkg/input_shaping_bg.wasm`) });
  const { results, made } = calls(api);
  const types = [...new Set(results.map(([t]) => t.replace('[]', '')))].filter((t) => !['number', 'string'].includes(t));
  const lines = [
    '// Generated by tests/types/types.test.mjs: what every export returned, typed as declared,',
    '// then every call that returned, with its arguments (a result passed on is named).',
    `import type { ${types.join(', ')} } from '${root}pkg/input_shaping.js';`,
    `import * as api from '${root}pkg/input_shaping.js';`,
  ];
  const named = new Map();
  results.forEach(([type, value], i) => {
    const expr = type === 'InputShapingError' ? errorLiteral(value) : literal(value);
    lines.push(`export const r${i}: ${type} = ${expr};`);
    if (value !== null && typeof value === 'object' && !named.has(value)) named.set(value, `r${i}`);
  });
  for (const [name, args] of made) {
    const list = args.map((a) => named.get(a) ?? literal(a, 1));
    lines.push(`api.${name}(${list.join(', ')});`);
  }
  const file = `${out}results.ts`;
  writeFileSync(file, lines.join('\n') + '\n');
  const r = compile([file]);
  assert.ok(r.ok, `results or arguments differ from their declared types (${file}):\n${r.text}`);
  console.log(`# ${results.length} results of ${new Set(results.map(([t]) => t)).size} declared types, ${made.length} calls checked`);
});
