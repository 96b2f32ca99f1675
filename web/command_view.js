// Profile and list commands (issue 23 item 2): the view, fetched when such a command is first
// shown (web/command_load.js loads it).
//
// - The fields of Veciana & Cardona's pulse-convolution profiles (`{ kind: 'profile', shape,
//   … }`, docs/js-api.md) and of a sampled command typed or pasted as a list (`{ kind:
//   'sampled', samplePeriod, values, interpolation }`). Bad values go to renderPlayground as they
//   are, which names the field (`view.command.values[3]`): the message shows at the field, the
//   last good charts stay, as everywhere on the page.
// - The profile's spectrum: |U(f)|² of its velocity in dB with a labelled marker at each zero
//   of its pulses (`profileSpectrum` of the recording module: the zeros in closed form, Veciana
//   & Cardona 2011 eq. 13), and the zeros listed with the model's modes they fall on. Its own
//   chart, not markers on the command spectrum chart: on that chart's linear axis, with up to
//   four shaped commands over the profile, a zero is a line among many; in dB it is a notch.
import initRecording, { profileSpectrum } from '../pkg/page/recording.js';
import { el, readNumber } from './dom.js';

const $ = (id) => document.getElementById(id);
const fmt = (x, digits = 4) => (Number.isFinite(x) ? String(Number(x.toPrecision(digits))) : '—');

/** The profiles (`shape`), with the page's words and the fields each reads. */
const SHAPES = [
  ['pulse', 'Pulse: a trapezium (§2.1)', ['frequencyHz']],
  ['triangle', 'Triangle: robust, tangent zero (§2.3)', ['frequencyHz']],
  ['robustTrapezium', 'Robust trapezium: zeros at f₀ ± Δf (Fig. 8)', ['frequencyHz', 'deltaHz']],
  ['multiMode', 'Multi-mode: one pulse per mode (§2.4)', ['modesHz', 'commonHz']],
];
const LABELS = {
  frequencyHz: 'Mode frequency f₀ (Hz)',
  deltaHz: 'Band half-width Δf (Hz)',
  modesHz: 'Mode frequencies (Hz), one pulse each',
  commonHz: 'Common frequency f_cmd (Hz, optional)',
  distance: 'Distance',
  duration: 'Duration (s)',
  samplePeriod: 'Sample period (s)',
  values: 'Samples (position): commas, spaces or new lines',
};
/** The fields a command of this kind (and shape) reads, kept on a shape change. */
const OWN = ['kind', 'shape', 'frequencyHz', 'deltaHz', 'modesHz', 'commonHz', 'distance', 'duration'];

/** Numbers in `text` split at commas, semicolons, spaces and new lines; NaN for a bad entry
 * (the core then names it with its index). */
export const parseList = (text) => String(text).split(/[\s,;]+/).filter(Boolean).map(Number);

function input(name, value, extra = {}) {
  const text = Array.isArray(value) ? value.join(', ') : value === undefined || value === null ? '' : String(value);
  const type = Array.isArray(value) || name === 'modesHz' ? 'text' : 'number';
  return el('input', { id: `command-${name}`, type, step: 'any', inputmode: 'decimal', value: text, dataset: { field: `view.command.${name}` }, ...extra });
}

/** The profile's fields: its shape, then the numbers that shape reads. */
function profileFields(command, { field, changed }) {
  const shape = el('select', { id: 'command-shape', dataset: { field: 'view.command.shape' } },
    ...SHAPES.map(([v, t]) => el('option', { value: v }, t)));
  shape.value = command.shape;
  const rebuild = () => $('command-params').replaceChildren(...profileFields(command, { field, changed }));
  shape.addEventListener('change', () => {
    reshape(command, shape.value);
    rebuild();
    changed(true);
  });
  const names = [...(SHAPES.find(([v]) => v === command.shape)?.[2] ?? []), 'distance', 'duration'];
  return [field('Profile', shape), el('span', { class: 'hint' }, 'Veciana & Cardona 2011: the velocity is a convolution of pulses, its spectrum zero at each pulse’s multiples of 1/width; the final pulse takes the rest of the duration.'),
    ...names.map((name) => {
      const box = input(name, command[name]);
      box.addEventListener('input', () => {
        if (name === 'modesHz') command.modesHz = parseList(box.value);
        else if (name === 'commonHz' && box.value.trim() === '') delete command.commonHz;
        else command[name] = readNumber(box);
        changed();
      });
      return field(LABELS[name], box);
    })];
}

/** Sets `command` to profile `shape`, keeping its distance and frequency and, if long enough
 * for the new pulses, its duration. */
function reshape(command, shape) {
  const f = command.frequencyHz > 0 ? command.frequencyHz : command.modesHz?.find((x) => x > 0) ?? 1;
  for (const k of Object.keys(command)) if (!OWN.includes(k)) delete command[k];
  command.shape = shape;
  let pulses;
  if (shape === 'multiMode') {
    command.modesHz = Array.isArray(command.modesHz) && command.modesHz.length ? command.modesHz : [f];
    delete command.frequencyHz;
    delete command.deltaHz;
    pulses = command.modesHz.reduce((s, x) => s + 1 / x, command.commonHz > 0 ? 1 / command.commonHz : 0);
  } else {
    command.frequencyHz = f;
    delete command.modesHz;
    delete command.commonHz;
    if (shape === 'robustTrapezium') command.deltaHz = Number.isFinite(command.deltaHz) && command.deltaHz < f ? command.deltaHz : Number((0.1 * f).toPrecision(3));
    else delete command.deltaHz;
    pulses = shape === 'pulse' ? 1 / f : shape === 'triangle' ? 2 / f : 1 / (f + command.deltaHz) + 1 / (f - command.deltaHz);
  }
  if (!(command.duration >= pulses)) command.duration = Number((1.5 * pulses).toPrecision(3));
}

/** The list's fields: its period, its samples and how they are read in between. */
function sampledFields(command, { field, changed }) {
  const period = input('samplePeriod', command.samplePeriod);
  period.addEventListener('input', () => { command.samplePeriod = readNumber(period); changed(); });
  const values = el('textarea', { id: 'command-values', rows: '4', dataset: { field: 'view.command.values' } });
  values.value = Array.isArray(command.values) ? command.values.join(', ') : '';
  values.addEventListener('input', () => { command.values = parseList(values.value); changed(); });
  const how = el('select', { id: 'command-interpolation', dataset: { field: 'view.command.interpolation' } },
    el('option', { value: 'linear' }, 'straight lines between samples'), el('option', { value: 'hold' }, 'each held to the next (steps)'));
  how.value = command.interpolation ?? 'linear';
  how.addEventListener('change', () => { command.interpolation = how.value; changed(true); });
  return [field(LABELS.samplePeriod, period), field(LABELS.values, values),
    el('span', { class: 'hint' }, 'Sample k at t = k × period; the last one is kept. Shaped sample by sample, as a controller would (Singer & Seering 1988, Fig. 10).'),
    field('Between samples', how)];
}

/** The command's fields (web/editors.js, commandFields): `hooks = { field, changed }`. */
export function fields(command, hooks) {
  return command.kind === 'profile' ? profileFields(command, hooks) : sampledFields(command, hooks);
}

// ---------- the profile's spectrum ----------
let started = null; // the recording module's instantiation
let ready = false;
let latest = null; // the last update's arguments, drawn once the module is there
let drawnKey = '';
let drawn = null; // the zeros drawn: { zeros, marked }
const MAX_MARKED = 12;

/** The view's section, made the first time (after the charts). */
function section() {
  let s = $('command-view');
  if (!s) {
    s = el('div', { id: 'command-view', hidden: true },
      el('h2', {}, 'The profile’s spectrum and its zeros'),
      el('p', { id: 'command-zeros', class: 'realisation-summary' }),
      el('canvas', { id: 'command-zeros-chart', 'aria-label': 'Spectrum of the profile command in dB, its zeros marked' }));
    document.querySelector('#results .charts').after(s);
  }
  return s;
}

/** Updates the view for the state just drawn; draws only when the profile, the modes or the
 * chart's size changed. A profile the library refuses keeps the last good view (the frame's own
 * error, the same one, shows at the field). */
export function update(state, drawSpectrum) {
  const command = state.view.command;
  const s = section();
  if (command?.kind !== 'profile') {
    if (!s.hidden) s.hidden = true;
    return;
  }
  latest = [state, drawSpectrum];
  if (!ready) {
    started ??= initRecording().then(() => { ready = true; update(...latest); });
    return;
  }
  if (s.hidden) s.hidden = false;
  const canvas = $('command-zeros-chart');
  const ratio = window.devicePixelRatio || 1;
  const size = [Math.round(canvas.clientWidth * ratio), Math.round(canvas.clientHeight * ratio)];
  const modes = state.modes.map((m) => m.frequencyHz);
  const own = [command.frequencyHz + (command.deltaHz || 0), ...(command.modesHz ?? []), command.commonHz];
  const top = 3 * Math.max(...[...modes, ...own].filter((f) => Number.isFinite(f) && f > 0), 1);
  // The chart depends on the profile and its range only: a mode edit within the range only
  // rewrites the line (which modes are on a zero).
  const key = JSON.stringify([command, top, size]);
  if (key !== drawnKey) {
    let u;
    try {
      u = profileSpectrum(command, { toHz: top, points: 1200 });
    } catch {
      return;
    }
    drawnKey = key;
    drawn = { zeros: u.zeros, marked: u.zeros.filter((z) => !z.finalPulse || z.order > 1).slice(0, MAX_MARKED) };
    [canvas.width, canvas.height] = size;
    drawSpectrum(canvas, { frequencyHz: u.frequencyHz, psd: u.magnitude.map((m) => m * m) },
      { peaksHz: spaced(drawn.marked.map((z) => z.frequencyHz), designed(command), top / 25), maxHz: top, pixelRatio: ratio, title: 'Profile spectrum |U(f)|² (velocity), its pulses’ zeros (spaced labels; all in the line above)', yLabel: '|U|² (dB)' });
  }
  const text = describe(drawn.zeros, drawn.marked, state.modes, command);
  if ($('command-zeros').textContent !== text) $('command-zeros').textContent = text;
}

/** The frequencies the profile was designed for (its pulses' first zeros). */
const designed = (c) => [c.frequencyHz, c.frequencyHz - c.deltaHz, c.frequencyHz + c.deltaHz, ...(c.modesHz ?? []), c.commonHz]
  .filter((f) => Number.isFinite(f) && f > 0);

/** The zeros to label on the chart: those at `first` (the design frequencies) first, then the
 * others at least `gap` Hz from every one labelled (closer labels overlap; the line lists all). */
function spaced(zeros, first, gap) {
  const onMode = (f) => first.some((m) => Math.abs(m - f) <= 1e-6 * f);
  const out = zeros.filter(onMode);
  for (const f of zeros) if (!onMode(f) && out.every((g) => Math.abs(g - f) >= gap)) out.push(f);
  return out.sort((a, b) => a - b);
}

/** The zeros in words: each marked one (its order, the mode on it), then the final pulse's. */
function describe(zeros, marked, modes, command) {
  const on = (f) => modes.findIndex((m) => Math.abs(m.frequencyHz - f) <= 1e-6 * f);
  const parts = marked.map((z) => {
    const k = on(z.frequencyHz);
    return `${fmt(z.frequencyHz)} Hz${z.order > 1 ? ` (order ${z.order}: tangent)` : ''}${k >= 0 ? ` = mode ${k + 1}` : ''}`;
  });
  const last = zeros.filter((z) => z.finalPulse && z.order === 1);
  const missed = modes.map((m, i) => [m.frequencyHz, i]).filter(([f]) => !zeros.some((z) => Math.abs(z.frequencyHz - f) <= 1e-6 * f));
  const spacing = last.length ? ` The final pulse adds zeros every ${fmt(last[0].frequencyHz)} Hz (not marked).` : '';
  const miss = missed.length ? ` Not on a zero: ${missed.map(([f, i]) => `mode ${i + 1} (${fmt(f)} Hz)`).join(', ')}.` : ' Every mode is on a zero.';
  return `Zeros of the ${command.shape} profile (closed form, Veciana & Cardona 2011 eq. 13): ${parts.join('; ') || 'none in range'}.${spacing}${miss}`;
}
