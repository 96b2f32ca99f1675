// How each family parameter is edited on the page. Parameters are named as in a design spec
// (README, "Shaper families"); a parameter not listed here gets a plain number field.
// kind: 'number' | 'integer' | 'numbers' (comma-separated list) | 'percent' (fraction shown in %)
// | 'select'.
export const PARAMS = {
  derivatives: { label: 'Zero derivatives n', kind: 'integer', min: 0, max: 30, default: 3 },
};

/** The editing description of parameter `name` (a sensible default for unknown ones). */
export function paramInfo(name) {
  return PARAMS[name] ?? { label: name, kind: 'number', default: 0 };
}

/** Reads an input's text as the parameter's value (NaN / [] when not a number: the core says why). */
export function parseParam(info, text) {
  const t = String(text).trim();
  if (info.kind === 'numbers') {
    return t === '' ? [] : t.split(/[,\s;]+/).filter(Boolean).map(Number);
  }
  if (info.kind === 'select') return t;
  if (t === '') return NaN;
  const v = Number(t);
  return info.kind === 'percent' ? v / 100 : v;
}

/** Formats a parameter value for its input. */
export function formatParam(info, value) {
  if (value === undefined || value === null) return '';
  if (info.kind === 'numbers') return Array.isArray(value) ? value.join(', ') : String(value);
  if (info.kind === 'percent') return Number.isFinite(value) ? String(+(value * 100).toPrecision(10)) : '';
  return String(value);
}
