// How each family parameter is edited on the page comes from the library's family table
// (`families()`: each row's `params`, crate/design/family.rs): `{ name, label, kind, min?, max?,
// default?, optional, options? }`. kind: 'number' | 'integer' | 'numbers' (comma-separated
// list) | 'percent' (fraction shown in %) | 'select' (with `options`) | 'boolean' | 'pairs'
// (impulses, one "time, amplitude" per line) | 'points' (one "x, y" per line, sent as
// [[x, y], …]). `optional`: a blank field leaves the parameter out of the spec (the core's
// default applies). `min`/`max` are in the spec's units (a fraction for 'percent').

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

/** A command of `kind` keeping what it shares with `previous` (limits default to a 1-unit move;
 * a profile is Veciana & Cardona's triangle for the first of `modes`, lasting 2.6 of its periods
 * (its final pulse's zeros then fall off the triangle's);
 * a list a made-up joystick trace, 0.05 s apart). */
export function commandFor(kind, previous = {}, modes = []) {
  const distance = Number.isFinite(previous.distance) ? previous.distance : 1;
  const next = { kind, distance };
  if (kind === 'profile') {
    const f = modes[0]?.frequencyHz > 0 ? modes[0].frequencyHz : 1;
    return { ...next, shape: 'triangle', frequencyHz: f, duration: Number((2.6 / f).toPrecision(3)) };
  }
  if (kind === 'sampled') {
    return { kind, samplePeriod: 0.05, values: [0, 0.1, 0.3, 0.6, 0.8, 0.9, 1, 1, 1, 0.9, 0.7, 0.6, 0.6].map((v) => v * distance), interpolation: 'linear' };
  }
  if (kind === 'trapezoid' || kind === 'sCurve') {
    next.maxVelocity = Number.isFinite(previous.maxVelocity) ? previous.maxVelocity : Math.abs(distance) || 1;
    next.maxAcceleration = Number.isFinite(previous.maxAcceleration) ? previous.maxAcceleration : 10 * next.maxVelocity;
  }
  if (kind === 'sCurve') {
    next.maxJerk = Number.isFinite(previous.maxJerk) ? previous.maxJerk : 20 * next.maxAcceleration;
  }
  return next;
}
