// How each family parameter is edited on the page. Parameters are named as in a design spec
// (README, "Shaper families"); a parameter not listed here gets a plain number field.
// kind: 'number' | 'integer' | 'numbers' (comma-separated list) | 'percent' (fraction shown in %)
// | 'select' (with `options`) | 'boolean' | 'pairs' (impulses, one "time, amplitude" per line)
// | 'points' (one "x, y" per line, sent as [[x, y], …]). `optional`: a blank field leaves the parameter out of the spec
// (the core's default applies). FAMILY_PARAMS overrides PARAMS for one family.
export const PARAMS = {
  derivatives: { label: 'Zero derivatives n', kind: 'integer', min: 0, max: 30, default: 3 },
  vtol: { label: 'Hump height V (%)', kind: 'percent', default: 0.05 },
  humps: { label: 'Humps n', kind: 'integer', min: 1, max: 10, default: 2 },
  distance: { label: 'Move distance', kind: 'number', default: 1 },
  maxAcceleration: { label: 'Max acceleration (distance/s²)', kind: 'number', default: 10 },
  coastTime: { label: 'Coast time (s)', kind: 'number', default: 0.5 },
  normalize: { label: 'Normalise amplitudes to sum 1', kind: 'boolean', default: false },
  periodS: { label: 'Controller period T (s)', kind: 'number', default: 0.012 },
  delaySamples: { label: 'Ramp delay m (periods; blank = free, 0 = full compensation)', kind: 'integer', optional: true, default: 17 },
  weight: { label: 'Control-error weight Q', kind: 'number', default: 0.1 },
  plantGain: { label: 'Plant gain K (s²; blank = 1/ω²)', kind: 'number', optional: true },
  objective: { label: 'Objective', kind: 'select', options: ['controlError', 'minimumNorm'], default: 'controlError' },
  amplitudeMin: { label: 'Amplitude min (blank = none)', kind: 'number', optional: true },
  amplitudeMax: { label: 'Amplitude max (blank = none)', kind: 'number', optional: true },
  incrementMin: { label: 'Increment min (blank = none)', kind: 'number', optional: true },
  incrementMax: { label: 'Increment max (blank = none)', kind: 'number', optional: true },
  maxDuration: { label: 'Max duration (s; blank = none)', kind: 'number', optional: true },
};

export const FAMILY_PARAMS = {
  custom: {
    impulses: {
      label: 'Impulses: one "time (s), amplitude" per line',
      kind: 'pairs',
      default: [{ time: 0, amplitude: 0.5 }, { time: 0.25, amplitude: 0.5 }],
    },
  },
  si: {
    vtol: { label: 'Tolerable vibration Vtol (%)', kind: 'percent', default: 0.05 },
    insensitivity: {
      label: 'Insensitivity I (band f(1 ± I/2) around each mode; blank to use the band below)',
      kind: 'number', optional: true, default: 0.4,
    },
    bandHz: { label: 'Band [low, high] Hz (one mode; blank = none)', kind: 'numbers', optional: true },
    dampingRange: { label: 'Damping range [ζ low, ζ high] (blank = the modes\' ζ)', kind: 'numbers', optional: true },
    sampleFrequenciesHz: {
      label: 'Sample only these frequencies, Hz (blank = guarantee the whole band)', kind: 'numbers', optional: true,
    },
    vtolProfile: {
      label: 'Vtol profile: one "frequency Hz, Vtol (fraction)" per line (blank = constant Vtol)',
      kind: 'points', optional: true,
    },
    amplitudeMin: { label: 'Amplitude min (blank = 0)', kind: 'number', optional: true },
    amplitudeMax: { label: 'Amplitude max (blank = 1)', kind: 'number', optional: true },
    maxImpulses: { label: 'Max impulses (blank = any)', kind: 'integer', optional: true },
  },
  direct: {
    derivatives: { label: 'Zero derivatives at every mode (0 = ZV, 1 = ZVD …)', kind: 'integer', min: 0, max: 4, default: 1 },
    amplitudeMin: { label: 'Amplitude min (blank = 0)', kind: 'number', optional: true },
    amplitudeMax: { label: 'Amplitude max (blank = 1)', kind: 'number', optional: true },
  },
  sampled: {
    impulses: { label: 'Impulses n', kind: 'integer', min: 2, max: 256, default: 36 },
    derivatives: { label: 'Zero derivatives', kind: 'integer', min: 0, max: 3, default: 1 },
  },
};

/** The editing description of parameter `name` of `family` (a plain number for unknown ones). */
export function paramInfo(name, family) {
  return FAMILY_PARAMS[family]?.[name] ?? PARAMS[name] ?? { label: name, kind: 'number', default: 0 };
}

/** Reads an input's text as the parameter's value: NaN / [] when not a number (the core then
 * says why), `undefined` for a blank optional parameter. */
export function parseParam(info, text) {
  const t = String(text).trim();
  if (info.optional && t === '') return undefined;
  if (info.kind === 'numbers') {
    return t === '' ? [] : t.split(/[,\s;]+/).filter(Boolean).map(Number);
  }
  if (info.kind === 'select') return t;
  if (info.kind === 'boolean') return t === 'true';
  if (info.kind === 'points') {
    return t.split(/\n+/).map((l) => l.trim()).filter(Boolean)
      .map((line) => line.split(/[,;\s]+/).filter(Boolean).map(Number));
  }
  if (info.kind === 'pairs') {
    return t.split(/\n+/).map((l) => l.trim()).filter(Boolean).map((line) => {
      const [time, amplitude] = line.split(/[,;\s]+/).map((x) => (x === undefined || x === '' ? NaN : Number(x)));
      return { time, amplitude };
    });
  }
  if (t === '') return NaN;
  const v = Number(t);
  return info.kind === 'percent' ? v / 100 : v;
}

/** Formats a parameter value for its input. */
export function formatParam(info, value) {
  if (value === undefined || value === null) return '';
  if (info.kind === 'numbers') return Array.isArray(value) ? value.join(', ') : String(value);
  if (info.kind === 'pairs') return Array.isArray(value) ? value.map((p) => `${p?.time}, ${p?.amplitude}`).join('\n') : '';
  if (info.kind === 'points') return Array.isArray(value) ? value.map((p) => (Array.isArray(p) ? p.join(', ') : String(p))).join('\n') : '';
  if (info.kind === 'boolean') return String(Boolean(value));
  if (info.kind === 'percent') return Number.isFinite(value) ? String(+(value * 100).toPrecision(10)) : '';
  return String(value);
}

/** The fields of each command kind of the simulation: [name, label]. */
export const COMMAND_PARAMS = {
  step: [['distance', 'Distance']],
  trapezoid: [['distance', 'Distance'], ['maxVelocity', 'Max velocity (distance/s)'], ['maxAcceleration', 'Max acceleration (distance/s²)']],
  sCurve: [['distance', 'Distance'], ['maxVelocity', 'Max velocity (distance/s)'], ['maxAcceleration', 'Max acceleration (distance/s²)'],
    ['maxJerk', 'Max jerk (distance/s³)']],
};

/** A command of `kind` keeping what it shares with `previous` (limits default to a 1-unit move). */
export function commandFor(kind, previous = {}) {
  const distance = Number.isFinite(previous.distance) ? previous.distance : 1;
  const next = { kind, distance };
  if (kind === 'trapezoid' || kind === 'sCurve') {
    next.maxVelocity = Number.isFinite(previous.maxVelocity) ? previous.maxVelocity : Math.abs(distance) || 1;
    next.maxAcceleration = Number.isFinite(previous.maxAcceleration) ? previous.maxAcceleration : 10 * next.maxVelocity;
  }
  if (kind === 'sCurve') {
    next.maxJerk = Number.isFinite(previous.maxJerk) ? previous.maxJerk : 20 * next.maxAcceleration;
  }
  return next;
}
