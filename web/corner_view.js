// The printed corner (issue 23 item 3): the view, fetched when its panel is first opened
// (web/corner.js). An XY path — a square or the outline of Klipper's ringing tower — planned
// with Klipper's square-corner-velocity rule at the given speed and acceleration, X and Y each
// with their own modes, printed unshaped and with each compared shaper (designed for X's modes
// on X and Y's on Y); the chart draws the nozzle's track with its deviation magnified, the table
// the peak deviation and the ringing after each corner. One call into the corner module
// (renderCorner) per change of the panel's fields or of the compared shapers; a bad field keeps
// the last good chart and table and says what is wrong beside the field.
import init, { renderCorner } from '../pkg/page/corner.js';

const $ = (id) => document.getElementById(id);

/** The panel's values when the state has none (a 3D printer's X and Y, a 40 mm square). */
export const CORNER_DEFAULTS = {
  path: 'square', sideMm: 40, velocity: 150, accel: 5000, scv: 5, magnify: 50,
  x: [{ frequencyHz: 45, damping: 0.1 }], y: [{ frequencyHz: 38, damping: 0.08 }],
};
/** Samples a print is drawn from at most (the page's frame budget; the JS API's default is finer). */
const MAX_SAMPLES = 3000;

const ready = init({ module_or_path: new URL('./corner_bg.wasm', import.meta.url) });
let built = false;
let written = ''; // the corner state the fields show
let lastKey = ''; // what the chart and table were last drawn from
let last = null; // { spec, shapers, labels, frame }: the last good frame (for the tests)
// The page's shared object (web/page.js) as main.js's bundle has it: this bundle is separate, so
// it is handed over (update) rather than imported (an import would be a second copy).
let page = null;

function el(tag, props = {}, ...children) {
  const node = document.createElement(tag);
  for (const [k, v] of Object.entries(props)) {
    if (k === 'dataset') Object.assign(node.dataset, v);
    else node.setAttribute(k, v);
  }
  node.append(...children);
  return node;
}

/** A labelled number input for `field` (the error field it answers to). */
function numberField(id, label, field, unit) {
  return el('label', { class: 'corner-field' }, `${label} `,
    el('input', { id, type: 'number', step: 'any', dataset: { cornerField: field } }),
    unit ? ` ${unit}` : '',
    el('span', { class: 'field-error', id: `${id}-error`, role: 'alert' }));
}

function axisFields(axis) {
  const A = axis.toUpperCase();
  return el('fieldset', { class: 'corner-axis corner-fields' }, el('legend', {}, `${A} axis modes`),
    numberField(`corner-${axis}-f0`, 'mode 1', `${axis}.modes[0].frequencyHz`, 'Hz'),
    numberField(`corner-${axis}-z0`, 'damping ζ', `${axis}.modes[0].damping`),
    numberField(`corner-${axis}-f1`, 'mode 2 (blank: none)', `${axis}.modes[1].frequencyHz`, 'Hz'),
    numberField(`corner-${axis}-z1`, 'damping ζ', `${axis}.modes[1].damping`));
}

function build() {
  const pathSelect = el('select', { id: 'corner-path', dataset: { cornerField: 'path.kind' } },
    el('option', { value: 'square' }, 'square'),
    el('option', { value: 'ringingTower' }, 'ringing tower (Klipper)'));
  $('corner-body').replaceChildren(
    el('div', { class: 'corner-fields' },
      el('label', { class: 'corner-field' }, 'path ', pathSelect),
      numberField('corner-side', 'side', 'path.sideMm', 'mm'),
      numberField('corner-velocity', 'velocity', 'velocity', 'mm/s'),
      numberField('corner-accel', 'accel', 'accel', 'mm/s²'),
      numberField('corner-scv', 'square corner velocity', 'squareCornerVelocity', 'mm/s'),
      numberField('corner-magnify', 'deviation drawn ×', 'magnify')),
    el('div', { class: 'corner-axes' }, axisFields('x'), axisFields('y')),
    el('canvas', { id: 'corner-chart', class: 'tall', 'aria-label': 'Printed path with the nozzle deviation magnified, unshaped and shaped' }),
    el('table', { id: 'corner-table' }, el('caption', {}, 'After each corner: peak deviation across the next wall and its ringing amplitude (µm)'),
      el('thead'), el('tbody')),
  );
  $('corner-body').addEventListener('input', readFields);
  $('corner-body').addEventListener('change', readFields);
  built = true;
}

const num = (id) => { const v = $(id).value.trim(); return v === '' ? NaN : Number(v); };

/** The fields into page.state.corner (as typed: the core judges the values). */
function readFields() {
  const modes = (axis) => {
    const out = [{ frequencyHz: num(`corner-${axis}-f0`), damping: num(`corner-${axis}-z0`) }];
    if ($(`corner-${axis}-f1`).value.trim() !== '') out.push({ frequencyHz: num(`corner-${axis}-f1`), damping: num(`corner-${axis}-z1`) });
    return out;
  };
  const c = {
    open: true, path: $('corner-path').value, sideMm: num('corner-side'), velocity: num('corner-velocity'),
    accel: num('corner-accel'), scv: num('corner-scv'), magnify: num('corner-magnify'), x: modes('x'), y: modes('y'),
  };
  // JSON has no NaN: an empty or unreadable field is kept as null, which the core names.
  page.state.corner = JSON.parse(JSON.stringify(c));
  written = JSON.stringify(page.state.corner);
  page.changed();
}

/** The state (defaults filled in) into the fields, when it changed elsewhere (a preset, a link). */
function showState(c) {
  const set = (id, v) => { $(id).value = v === null || v === undefined || Number.isNaN(v) ? '' : String(v); };
  $('corner-path').value = c.path;
  set('corner-side', c.sideMm); set('corner-velocity', c.velocity); set('corner-accel', c.accel);
  set('corner-scv', c.scv); set('corner-magnify', c.magnify);
  for (const axis of ['x', 'y']) {
    const m = c[axis] ?? [];
    set(`corner-${axis}-f0`, m[0]?.frequencyHz); set(`corner-${axis}-z0`, m[0]?.damping);
    set(`corner-${axis}-f1`, m[1]?.frequencyHz); set(`corner-${axis}-z1`, m[1]?.damping);
  }
}

/** The corner state with the defaults filled in. */
export function cornerState(state) {
  return { ...CORNER_DEFAULTS, ...(state.corner ?? {}) };
}

/** The spec renderCorner and simulateCorner take for corner state `c`. */
export function cornerSpec(c) {
  const path = c.path === 'ringingTower'
    ? { kind: 'ringingTower', sideMm: c.sideMm ?? 120 }
    : { kind: 'square', sideMm: c.sideMm };
  const modes = (list) => (Array.isArray(list) ? list : []).map((m) => ({ frequencyHz: m.frequencyHz, damping: m.damping ?? 0 }));
  const spec = {
    path, velocity: c.velocity, accel: c.accel, squareCornerVelocity: c.scv, magnify: c.magnify,
    x: { modes: modes(c.x) }, y: { modes: modes(c.y) },
  };
  // A coarser sampling than the API's default when the print is long: at most MAX_SAMPLES.
  const fastest = Math.max(...[...spec.x.modes, ...spec.y.modes].map((m) => m.frequencyHz).filter(Number.isFinite), 1);
  const side = Number.isFinite(c.sideMm) ? c.sideMm : 0;
  const length = c.path === 'ringingTower' ? 4 * side : 4 * side;
  const estimate = length / (c.velocity > 0 ? c.velocity : 1) + 0.1;
  const period = Math.max(1 / (25 * fastest), estimate / MAX_SAMPLES);
  if (Number.isFinite(period) && period > 0) spec.samplePeriodS = Number(period.toPrecision(3));
  return spec;
}

/** mm as µm, 3 digits; rounding-level values (below 10⁻⁶ µm, an exact shaper's) as ≈ 0. */
const um = (mm) => (!Number.isFinite(mm) ? '—' : Math.abs(mm) < 1e-9 ? '≈ 0' : String(Number((mm * 1000).toPrecision(3))));
export { um as formatMicrons };

function showTable(frame) {
  const corners = frame.unshaped.corners.length;
  const head = ['print', 'largest peak', 'largest ringing'];
  for (let k = 0; k < corners; k++) head.push(`corner ${k + 1}: peak`, `ringing`);
  $('corner-table').tHead.replaceChildren(el('tr', {}, ...head.map((h) => el('th', { scope: 'col' }, h))));
  const rows = [frame.unshaped, ...frame.shapers].map((p) => el('tr', {},
    el('th', { scope: 'row' }, p.label), el('td', {}, um(p.peakDeviation)), el('td', {}, um(p.ringing)),
    ...p.corners.flatMap((c) => [el('td', {}, um(c.peakDeviation)), el('td', {}, um(c.ringing))])));
  for (const l of frame.leftOut) {
    rows.push(el('tr', { class: 'left-out' }, el('th', { scope: 'row' }, l.label), el('td', { colspan: String(head.length - 1) }, `left out: ${l.message}`)));
  }
  $('corner-table').tBodies[0].replaceChildren(...rows);
}

let errorShown = false;
function clearErrors() {
  if (!errorShown) return;
  errorShown = false;
  for (const s of $('corner-body').querySelectorAll('.field-error')) s.textContent = '';
  for (const i of $('corner-body').querySelectorAll('[aria-invalid]')) i.removeAttribute('aria-invalid');
  $('corner-error').textContent = '';
}

function showError(e) {
  errorShown = true;
  const field = e?.field;
  const input = field ? $('corner-body').querySelector(`[data-corner-field="${CSS.escape(field)}"]`) : null;
  if (input) {
    input.setAttribute('aria-invalid', 'true');
    const slot = $(`${input.id}-error`);
    if (slot) slot.textContent = e.message;
  }
  $('corner-error').textContent = `${e?.message ?? e} The last good chart is kept.`;
}

/**
 * Recomputes and redraws when the corner state, the compared shapers or the canvas changed;
 * `shared` is the page's shared object (web/page.js: its state and `changed`).
 */
export async function update(shared) {
  if (shared) page = shared;
  await ready;
  if (!built) build();
  const c = cornerState(page.state);
  const shown = JSON.stringify(page.state.corner ?? null);
  if (shown !== written) {
    showState(c);
    written = shown;
  }
  const canvas = $('corner-chart');
  const ratio = window.devicePixelRatio || 1;
  const w = Math.max(1, Math.round(canvas.clientWidth * ratio));
  const h = Math.max(1, Math.round(canvas.clientHeight * ratio));
  const shapers = page.state.shapers.map((s) => ({ ...s }));
  const key = JSON.stringify({ c, shapers, w, h, ratio });
  clearErrors();
  if (key === lastKey) return; // back to what is drawn (a bad value undone): nothing to redo
  const spec = cornerSpec(c);
  const labels = shapers.map((s, i) => `${i + 1}. ${s.family}`);
  try {
    if (canvas.width !== w || canvas.height !== h) { canvas.width = w; canvas.height = h; }
    const frame = renderCorner(spec, shapers, canvas, { pixelRatio: ratio, labels });
    showTable(frame);
    last = { spec, shapers, labels, frame };
    lastKey = key;
    document.body.dataset.cornerReady = 'true';
  } catch (e) {
    showError(e);
  }
}

window.__cornerView = { last: () => last, cornerSpec, formatMicrons: um };
