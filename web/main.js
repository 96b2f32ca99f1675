// The playground: one state object (state.js), editors built from it, one call into wasm per
// frame (renderPlayground), and the numbers, charts and exports of the last good result. A bad
// value shows its message next to its field (matched by the error's `field` against the
// inputs' data-field) while the last good charts and numbers stay; with nothing good on screen
// yet (a link, a reload), a shaper that cannot be designed is left out instead (render).
import * as lite from '../pkg/page/playground.js';
import { DEFAULT_STATE, PRESETS, MAX_MODES, MAX_SHAPERS, checkState, clone, toHash, fromHash } from './state.js';
import { COMMAND_PARAMS, commandFor, parseParam, formatParam } from './params.js';
import { setupMeasure } from './measure.js';

const $ = (id) => document.getElementById(id);
const COLORS = ['#0072b2', '#d55e00', '#009e73', '#cc79a7'];

// The page's wasm module (its glue's exports: renderPlayground, families, exportShaper,
// drawSpectrum) leaves out the optimisation solver (87 KB gzip). The solved families (si,
// direct, sampled with an active bound) are designed by a worker with the solver instead
// ("Solved designs", below), fetched when the first one is needed; renderPlayground draws the
// shapers it hands back.
const api = lite;

let state = clone(DEFAULT_STATE);
/** The library's family table (`families()`): names, titles, parameters with their editors. */
let familyTable = [];
/** The families always designed by the solver (`solver: "always"`; a `"whenBounded"` one, sampled,
 * only with bounds: the error tells). */
let solvedFamilies = new Set();
let lastGood = null; // { state, result, left, waiting: the shapers it left out (indices) }

// ---------- small DOM helpers (text only: user text never reaches innerHTML) ----------
function el(tag, props = {}, ...children) {
  const node = document.createElement(tag);
  for (const [k, v] of Object.entries(props)) {
    if (k === 'dataset') Object.assign(node.dataset, v);
    else if (k in node && typeof v !== 'string') node[k] = v;
    else node.setAttribute(k, v);
  }
  node.append(...children.filter((c) => c !== null && c !== undefined));
  return node;
}

const fmt = (x, digits = 6) => (Number.isFinite(x) ? String(Number(x.toPrecision(digits))) : '—');
/** A vibration in %, with rounding-level values (below 1e-9 %) shown as ≈ 0. */
const fmtPct = (fraction) => (Math.abs(fraction) < 1e-11 ? '≈ 0' : fmt(fraction * 100, 4));
const readNumber = (input) => (input.value.trim() === '' ? NaN : Number(input.value));

/**
 * Makes `section` (a thead/tbody) hold `rows` — arrays of cell texts, the first `heads` cells
 * of each row `<th scope="row">`, the rest `<td>` — reusing the rows and cells already there
 * and writing only the texts that changed. Every input event redraws the tables; rebuilding
 * them made the browser restyle and lay out hundreds of new nodes per update. The texts last
 * written are remembered (`shownRows`), so unchanged cells are not read back from the DOM, and a
 * changed one has its text node's data replaced rather than a new node made.
 */
const shownRows = new WeakMap();
function syncRows(section, rows, heads = 1) {
  while (section.rows.length > rows.length) section.deleteRow(-1);
  const shown = shownRows.get(section) ?? [];
  shown.length = Math.min(shown.length, section.rows.length);
  rows.forEach((cells, i) => {
    const tr = section.rows[i] ?? section.appendChild(document.createElement('tr'));
    const last = shown[i];
    if (!last || last.length !== cells.length || last.heads !== heads) {
      tr.replaceChildren(...cells.map((text, j) => (j < heads ? el('th', { scope: 'row' }, text) : el('td', {}, text))));
      shown[i] = Object.assign([...cells], { heads });
      return;
    }
    cells.forEach((text, j) => {
      if (last[j] === text) return;
      const cell = tr.cells[j];
      const node = cell.firstChild;
      if (node && node.nodeType === Node.TEXT_NODE && !node.nextSibling) node.data = text;
      else cell.textContent = text;
      last[j] = text;
    });
  });
  shownRows.set(section, shown);
}

/** Replaces `node`'s children with `build()` only when `key` differs from the last one used. */
function rebuildIf(node, key, build) {
  if (node.dataset.key === key) return false;
  node.replaceChildren(...build());
  node.dataset.key = key;
  return true;
}

// Frequency sliders are logarithmic: 0.01 Hz … 1 kHz over 0 … 1000.
const F_MIN = 0.01;
const F_DECADES = 5;
const sliderToHz = (v) => F_MIN * 10 ** ((F_DECADES * v) / 1000);
const hzToSlider = (f) => Math.min(1000, Math.max(0, (1000 * Math.log10(f / F_MIN)) / F_DECADES));

// ---------- editors ----------
function field(labelText, input, extra = null) {
  const id = input.id;
  return el('div', { class: 'field' }, el('label', { for: id }, labelText), extra ?? input, el('span', { class: 'error', role: 'alert' }));
}

function modeRow(mode, i) {
  const f = el('input', { id: `mode-${i}-frequency`, type: 'number', step: 'any', value: String(mode.frequencyHz ?? ''), dataset: { field: `modes[${i}].frequencyHz` }, inputmode: 'decimal' });
  const fSlider = el('input', { type: 'range', min: '0', max: '1000', step: '1', 'aria-label': `Mode ${i + 1} frequency (logarithmic slider)` });
  const z = el('input', { id: `mode-${i}-damping`, type: 'number', step: 'any', value: String(mode.damping ?? ''), dataset: { field: `modes[${i}].damping` }, inputmode: 'decimal' });
  const zSlider = el('input', { type: 'range', min: '0', max: '0.5', step: '0.001', 'aria-label': `Mode ${i + 1} damping ratio slider` });
  const omega = el('output', { for: f.id, class: 'hint' });
  const syncSliders = () => {
    const fv = readNumber(f);
    if (Number.isFinite(fv) && fv > 0) fSlider.value = String(hzToSlider(fv));
    const zv = readNumber(z);
    if (Number.isFinite(zv)) zSlider.value = String(zv);
    omega.textContent = Number.isFinite(fv) ? `ω = ${fmt(2 * Math.PI * fv, 5)} rad/s` : '';
  };
  syncSliders();
  f.addEventListener('input', () => { state.modes[i].frequencyHz = readNumber(f); syncSliders(); changed(); });
  z.addEventListener('input', () => { state.modes[i].damping = readNumber(z); syncSliders(); changed(); });
  fSlider.addEventListener('input', () => {
    const hz = Number(sliderToHz(Number(fSlider.value)).toPrecision(4));
    f.value = String(hz);
    state.modes[i].frequencyHz = hz;
    syncSliders();
    changed();
  });
  zSlider.addEventListener('input', () => { z.value = zSlider.value; state.modes[i].damping = Number(zSlider.value); syncSliders(); changed(); });
  const remove = el('button', { type: 'button', class: 'remove', 'aria-label': `Remove mode ${i + 1}`, disabled: state.modes.length <= 1 }, '×');
  remove.addEventListener('click', () => { state.modes.splice(i, 1); rebuild(); changed(true); });
  return el('div', { class: 'card mode', dataset: { fieldGroup: `modes[${i}]` } },
    el('div', { class: 'card-head' }, el('strong', {}, `Mode ${i + 1}`), remove),
    field('Frequency (Hz)', f, el('div', { class: 'pair' }, fSlider, f)),
    omega,
    field('Damping ratio ζ', z, el('div', { class: 'pair' }, zSlider, z)));
}

function shaperCard(spec, k) {
  const family = el('select', { id: `shaper-${k}-family`, dataset: { field: `shapers[${k}].family` } },
    ...familyTable.map((f) => el('option', { value: f.name }, f.title)));
  family.value = spec.family;
  if (family.value !== spec.family) {
    family.prepend(el('option', { value: spec.family }, spec.family));
    family.value = spec.family;
  }
  const info = familyTable.find((f) => f.name === spec.family);
  family.addEventListener('change', () => {
    const next = { family: family.value };
    const nextInfo = familyTable.find((f) => f.name === family.value);
    for (const p of nextInfo?.params ?? []) {
      if (p.default !== undefined) next[p.name] = structuredClone(p.default);
    }
    state.shapers[k] = next;
    rebuild();
    changed(true);
  });
  const params = (info?.params ?? []).map((pinfo) => {
    const { name } = pinfo;
    if (!(name in spec) && pinfo.default !== undefined && !pinfo.optional) spec[name] = pinfo.default;
    let input;
    if (pinfo.kind === 'select' || pinfo.kind === 'boolean') {
      const options = pinfo.kind === 'boolean' ? ['false', 'true'] : pinfo.options;
      input = el('select', { id: `shaper-${k}-${name}`, dataset: { field: `shapers[${k}].${name}` } },
        ...options.map((o) => el('option', { value: o }, pinfo.kind === 'boolean' ? (o === 'true' ? 'yes' : 'no') : o)));
      input.value = formatParam(pinfo, spec[name]);
    } else if (pinfo.kind === 'pairs' || pinfo.kind === 'points') {
      input = el('textarea', { id: `shaper-${k}-${name}`, rows: '4', dataset: { field: `shapers[${k}].${name}` } });
      input.value = formatParam(pinfo, spec[name]);
    } else {
      input = el('input', {
        id: `shaper-${k}-${name}`, type: pinfo.kind === 'numbers' ? 'text' : 'number', step: pinfo.kind === 'integer' ? '1' : 'any',
        value: formatParam(pinfo, spec[name]), dataset: { field: `shapers[${k}].${name}` },
      });
      // The limits are in the spec's units: a percent field shows them in %.
      const shown = (x) => formatParam(pinfo.kind === 'percent' ? pinfo : { kind: 'number' }, x);
      if (pinfo.min !== undefined) input.min = shown(pinfo.min);
      if (pinfo.max !== undefined) input.max = shown(pinfo.max);
    }
    input.addEventListener('input', () => {
      const v = parseParam(pinfo, input.value);
      if (v === undefined) delete spec[name];
      else spec[name] = v;
      changed();
    });
    return field(pinfo.label, input);
  });
  const remove = el('button', { type: 'button', class: 'remove', 'aria-label': `Remove shaper ${k + 1}`, disabled: state.shapers.length <= 1 }, '×');
  remove.addEventListener('click', () => { state.shapers.splice(k, 1); rebuild(); changed(true); });
  return el('div', { class: 'card shaper', dataset: { fieldGroup: `shapers[${k}]` } },
    el('div', { class: 'card-head' }, el('span', { class: 'swatch', style: `background:${COLORS[k]}` }), el('strong', {}, `Shaper ${k + 1}`), remove),
    field('Family', family),
    el('span', { class: 'hint' }, info ? `${info.guarantee}. ${info.source}` : ''),
    ...params,
    el('span', { class: 'error group-error', role: 'alert' }));
}

/** The command's parameter fields, for its kind. */
function commandFields() {
  const command = state.view.command;
  return (COMMAND_PARAMS[command.kind] ?? []).map(([name, label]) => {
    const input = el('input', {
      id: `command-${name}`, type: 'number', step: 'any', inputmode: 'decimal',
      value: String(command[name] ?? ''), dataset: { field: `view.command.${name}` },
    });
    input.addEventListener('input', () => { state.view.command[name] = readNumber(input); changed(); });
    return field(label, input);
  });
}

function mapShaperOptions() {
  const sel = $('map-shaper');
  sel.replaceChildren(...state.shapers.map((s, k) => el('option', { value: String(k) },
    `Shaper ${k + 1}: ${familyTable.find((f) => f.name === s.family)?.title ?? s.family}`)));
  if (!(state.view.mapShaper < state.shapers.length)) state.view.mapShaper = 0;
  sel.value = String(state.view.mapShaper ?? 0);
}

function rebuild() {
  $('modes').replaceChildren(...state.modes.map(modeRow));
  $('shapers').replaceChildren(...state.shapers.map(shaperCard));
  $('add-mode').disabled = state.modes.length >= MAX_MODES;
  $('add-shaper').disabled = state.shapers.length >= MAX_SHAPERS;
  $('vtol').value = formatParam({ kind: 'percent' }, state.view.vtol);
  $('scv').value = String(state.view.scv ?? '');
  $('mismatch').value = String(state.view.mismatch ?? '');
  if (Number.isFinite(state.view.mismatch)) $('mismatch-slider').value = String(state.view.mismatch);
  $('plant-kind').value = state.view.plant?.kind ?? 'modal';
  $('command-kind').value = state.view.command?.kind ?? 'step';
  $('command-params').replaceChildren(...commandFields());
  mapShaperOptions();
}

// ---------- errors ----------
function clearErrors() {
  // Only the messages that are showing: writing even an empty text makes the browser lay the
  // page out again, on every input event.
  for (const e of document.querySelectorAll('#controls .error')) if (e.textContent) e.textContent = '';
  for (const e of document.querySelectorAll('[aria-invalid]')) e.removeAttribute('aria-invalid');
  if ($('general-error').textContent) $('general-error').textContent = '';
}

/** Shows a core error next to the input it names (or the closest group), else on top. */
function showError(error) {
  const message = error?.message ?? String(error);
  let path = typeof error?.field === 'string' ? error.field : '';
  while (path) {
    const input = document.querySelector(`[data-field="${CSS.escape(path)}"]`);
    if (input) {
      input.setAttribute('aria-invalid', 'true');
      input.closest('.field').querySelector('.error').textContent = message;
      return;
    }
    const group = document.querySelector(`[data-field-group="${CSS.escape(path)}"]`);
    if (group) {
      group.querySelector('.group-error, .error').textContent = message;
      return;
    }
    const parent = path.replace(/(\.[^.[\]]*|\[\d+\])$/, '');
    // A top-level name ("view") has no parent: stop rather than loop on it.
    path = parent === path ? '' : parent;
  }
  $('general-error').textContent = message;
}

// ---------- results ----------
/** The impulses each impulse table shows, as JSON (by table body). */
const impulseKeys = new WeakMap();
/**
 * Rows an impulse table shows until its "Show all" button is pressed: a multi-mode ZV-D³ has
 * 125 impulses, and every row's text changes on a frequency edit (the exports have them all).
 */
const IMPULSE_ROWS = 20;
/** Impulse tables (by index) whose every row is shown; reset when the tables are rebuilt. */
const expandedTables = new Set();

function showResults(result, st, kept) {
  const { results } = result;
  const color = (k) => COLORS[kept[k]]; // a shaper left out keeps the others' colours
  const labels = JSON.stringify(results.map((r, k) => [r.label, kept[k]]));
  rebuildIf($('summary').tHead, labels, () => [el('tr', {}, el('th', { scope: 'col' }, ''),
    ...results.map((r, k) => el('th', { scope: 'col' }, el('span', { class: 'swatch', style: `background:${color(k)}` }), r.label)))]);
  const period = 1 / (st.modes[0].frequencyHz * Math.sqrt(1 - st.modes[0].damping ** 2));
  const vtolPct = fmt(st.view.vtol * 100, 4);
  const rows = [
    ['Impulses', (r) => String(r.shaper.impulses.length)],
    ['Duration (s)', (r) => fmt(r.shaper.duration)],
    ['Duration (damped periods of mode 1)', (r) => fmt(r.shaper.duration / period, 4)],
    ['Centroid delay (s)', (r) => (r.centroidDelay == null ? '—' : fmt(r.centroidDelay))],
  ];
  st.modes.forEach((m, i) => {
    const tag = st.modes.length > 1 ? ` at mode ${i + 1}` : '';
    rows.push([`Insensitivity I(${vtolPct} %)${tag}`, (r) => fmt(r.insensitivity[i].width, 4)]);
    rows.push([`Band with V ≤ ${vtolPct} %${tag} (Hz)`, (r) => `${fmt(r.insensitivity[i].lowHz, 5)} – ${fmt(r.insensitivity[i].highHz, 5)}`]);
    rows.push([`Residual vibration${tag} (%)`, (r) => fmtPct(r.residualAtModes[i])]);
  });
  rows.push(['Klipper smoothing at 5000 mm/s² (mm)', (r) => (r.klipper == null ? 'n/a (Σ amplitudes = 0)' : fmt(r.klipper.smoothing, 4))]);
  // Klipper's answer is 0 when even a vanishing acceleration smooths more than its 0.12 mm
  // target (long, low-frequency shapers): said in words, not left as a bare 0.
  const maxAccel = (a) => (a == null ? '∞' : a === 0 ? '0 (none keeps smoothing ≤ 0.12 mm)' : fmt(a, 5));
  rows.push(['Klipper max accel, smoothing ≤ 0.12 mm (mm/s²)', (r) => (r.klipper == null ? 'n/a' : maxAccel(r.klipper.maxAccel))]);
  syncRows($('summary').tBodies[0], rows.map(([name, f]) => [name, ...results.map((r) => f(r))]));

  showSimulation(result, color);

  if (rebuildIf($('impulse-tables'), labels, () => results.map((r, k) => el('table', { class: 'impulses', id: `impulses-${k}` },
    el('caption', {}, el('span', { class: 'swatch', style: `background:${color(k)}` }), r.label),
    el('thead', {}, el('tr', {}, el('th', { scope: 'col' }, '#'), el('th', { scope: 'col' }, 'time (s)'), el('th', { scope: 'col' }, 'amplitude'))),
    el('tbody', {}),
    el('tfoot', {}, el('tr', {}, el('td', { colSpan: 3 },
      el('button', { type: 'button', class: 'more', 'aria-controls': `impulses-${k}`, 'aria-expanded': 'false', onclick: () => toggleImpulseTable(k) })))))))) {
    expandedTables.clear();
  }
  results.forEach((r, k) => showImpulseTable(k, r));

  const sel = $('export-shaper');
  const keep = sel.value;
  if (rebuildIf(sel, labels, () => results.map((r, k) => el('option', { value: String(k) }, r.label)))) {
    sel.value = keep && Number(keep) < results.length ? keep : '0';
  }
  showExport();
}

/**
 * Impulse table k for result `r`: every impulse, or the first `IMPULSE_ROWS` of a longer
 * sequence with a button to show them all (and back).
 */
function showImpulseTable(k, r) {
  const table = $(`impulses-${k}`);
  const body = table.tBodies[0];
  const { impulses } = r.shaper;
  const long = impulses.length > IMPULSE_ROWS;
  const all = !long || expandedTables.has(k);
  const shown = all ? impulses : impulses.slice(0, IMPULSE_ROWS);
  const button = table.tFoot.querySelector('button');
  if (table.tFoot.hidden === long) table.tFoot.hidden = !long;
  if (long) {
    const text = all ? `Show the first ${IMPULSE_ROWS}` : `Show all ${impulses.length} impulses`;
    if (button.textContent !== text) button.textContent = text;
    if (button.getAttribute('aria-expanded') !== String(all)) button.setAttribute('aria-expanded', String(all));
  }
  // Unchanged impulses (a mismatch or command edit) are not re-read cell by cell.
  const key = JSON.stringify(shown);
  if (impulseKeys.get(body) === key) return;
  syncRows(body, shown.map((imp, i) => [String(i + 1), fmt(imp.time, 10), fmt(imp.amplitude, 10)]), 0);
  impulseKeys.set(body, key);
}

function toggleImpulseTable(k) {
  const r = lastGood?.result.results[k];
  if (!r) return;
  if (expandedTables.has(k)) expandedTables.delete(k);
  else expandedTables.add(k);
  showImpulseTable(k, r);
}

/** The simulated move's metrics: the unshaped command and every shaper (`color(k)` of result k). */
function showSimulation(result, color) {
  const sim = result.simulation;
  const columns = [{ label: 'Unshaped', color: '#6e6e6e', m: sim.unshaped },
    ...result.results.map((r, k) => ({ label: r.label, color: color(k), m: r.simulation }))];
  rebuildIf($('simulation-summary').tHead, JSON.stringify(columns.map((c) => [c.label, c.color])), () => [el('tr', {}, el('th', { scope: 'col' }, ''),
    ...columns.map((c) => el('th', { scope: 'col' }, el('span', { class: 'swatch', style: `background:${c.color}` }), c.label)))]);
  const pct = (x) => (x == null ? '—' : Math.abs(x) < 1e-9 ? '≈ 0' : fmt(x, 4));
  const num = (x, d = 5) => (x == null ? '—' : fmt(x, d));
  const rows = [
    ['Residual vibration after the move (% of distance)', (m) => pct(m.residualVibrationPercent)],
    ['Settling time, 2 % band (s)', (m) => num(m.settlingTime2)],
    ['Settling time, 5 % band (s)', (m) => num(m.settlingTime5)],
    ['Move ends (s)', (m) => num(m.moveEnd)],
    ['Peak deflection during the move', (m) => num(m.peakDeflection, 4)],
    ['Peak command acceleration', (m) => (m.peakAcceleration == null ? '∞ (velocity jumps)' : fmt(m.peakAcceleration, 5))],
    ['Acceleration peaks + valleys', (m) => String(m.accelerationPeakValleyCount)],
  ];
  syncRows($('simulation-summary').tBodies[0], rows.map(([name, f]) => [name, ...columns.map((c) => (c.m ? f(c.m) : '—'))]));
  const plant = sim.plant === 'pendulum' ? 'nonlinear pendulum' : 'modal plant';
  $('simulation-note').textContent = `(${plant}, actual modes ${sim.plantModesHz.map((f) => fmt(f, 4)).join(', ')} Hz = model × ${fmt(sim.mismatch, 4)}; ${sim.samples} samples over ${fmt(sim.duration, 4)} s)`;
}

function showExport() {
  $('export-error').textContent = '';
  if (!lastGood) return;
  const k = Number($('export-shaper').value) || 0;
  const r = lastGood.result.results[k];
  if (!r) return;
  const m = lastGood.state.modes.map((mode) => `${mode.frequencyHz} Hz, ζ ${mode.damping}`).join('; ');
  const format = $('export-format').value;
  $('fixed-options').hidden = format !== 'cFixed';
  try {
    $('export-output').value = api.exportShaper(r.shaper, {
      format,
      name: 'shaper',
      comment: `input-shaping: ${r.label} for ${m}`,
      amplitudeSteps: readNumber($('export-steps')),
      tickS: readNumber($('export-tick')),
    });
  } catch (e) {
    $('export-output').value = '';
    $('export-error').textContent = e.message;
  }
}

// ---------- update loop ----------
// The charts' CSS sizes, kept by a ResizeObserver (its callbacks run just after a layout, so
// reading the sizes there is free). Reading clientWidth in update() instead would force a
// layout of the whole page on every edit, since the previous update changed the tables' texts.
const canvasSizes = new WeakMap();
const resizeObserver = typeof ResizeObserver === 'function'
  ? new ResizeObserver((entries) => {
    let resized = false;
    for (const { target } of entries) {
      const size = [target.clientWidth, target.clientHeight];
      const old = canvasSizes.get(target);
      if (!old || old[0] !== size[0] || old[1] !== size[1]) resized = true;
      canvasSizes.set(target, size);
    }
    if (resized && lastGood) schedule();
  })
  : null;

function sizeCanvas(canvas) {
  let size = canvasSizes.get(canvas);
  if (!size) {
    size = [canvas.clientWidth, canvas.clientHeight];
    canvasSizes.set(canvas, size);
    resizeObserver?.observe(canvas);
  }
  const ratio = window.devicePixelRatio || 1;
  const w = Math.max(1, Math.round(size[0] * ratio));
  const h = Math.max(1, Math.round(size[1] * ratio));
  if (canvas.width !== w || canvas.height !== h) {
    canvas.width = w;
    canvas.height = h;
  }
}

/** Recomputes and redraws everything; returns the time it took in ms (for the benchmark). */
function update() {
  const t0 = performance.now();
  clearErrors();
  const canvases = {
    impulses: $('impulses-chart'), sensitivity: $('sensitivity-chart'), damping: $('damping-chart'), map: $('map-chart'),
    response: $('response-chart'), command: $('command-chart'), spectrum: $('spectrum-chart'), robustness: $('robustness-chart'),
  };
  Object.values(canvases).forEach(sizeCanvas);
  const st = { ...state, view: { ...state.view, pixelRatio: window.devicePixelRatio || 1 } };
  try {
    const { result, kept, left, waiting, waitingKeys } = render(st, canvases);
    lastGood = { state: clone(state), result, left: left.map((l) => l.index), waiting };
    holdSince = null;
    clearTimeout(holdTimer);
    if (!waiting.length) dragging = false;
    showResults(result, state, kept);
    document.body.dataset.ready = 'true';
    left.forEach((l) => showError(l.error));
    showDesigning(waiting, waitingKeys);
    const lines = [];
    if (left.length) {
      const names = numbered(left.map((l) => l.index));
      lines.push(left.length > 1
        ? `Shapers ${names} are left out of the charts and tables: they cannot be designed as they are (the messages are at the shapers).`
        : `Shaper ${names} is left out of the charts and tables: it cannot be designed as it is (the message is at the shaper).`);
    }
    if (waiting.length) {
      const names = numbered(waiting);
      lines.push(`${waiting.length > 1 ? 'Shapers' : 'Shaper'} ${names} ${waiting.length > 1 ? 'are' : 'is'} left out until the optimisation solver has designed ${waiting.length > 1 ? 'them' : 'it'}: the page goes on meanwhile.`);
    }
    if (lines.length) $('general-error').textContent = lines.join(' ');
  } catch (error) {
    if (error?.kind === 'designing') showDesigning(error.waiting, error.keys);
    else {
      showDesigning([], []);
      holdSince = null;
      showError(error);
      // Nothing good to keep on screen (a link or a reload): say why the charts are empty.
      if (!lastGood && !$('general-error').textContent) $('general-error').textContent = `Nothing can be drawn until this is fixed: ${error?.message ?? error}`;
    }
  }
  return performance.now() - t0;
}

/** "1", "1 and 3", "1, 2 and 4": shapers by their numbers on the page. */
function numbered(indices) {
  const n = indices.map((i) => i + 1).sort((a, b) => a - b);
  return n.length > 1 ? `${n.slice(0, -1).join(', ')} and ${n.at(-1)}` : String(n[0]);
}

/**
 * Says at each waiting shaper (`waiting[i]`, its design `keys[i]`) that the optimisation
 * solver is designing it, with the seconds it has waited once that is a second or more, kept
 * up to date every second while one waits.
 */
let designingTicker = 0;
function showDesigning(waiting, keys) {
  const show = () => waiting.forEach((k, i) => {
    const since = designs.get(keys[i])?.since;
    const seconds = since === undefined ? 0 : Math.floor((performance.now() - since) / 1000);
    showError({ field: `shapers[${k}]`, message: `Designing with the optimisation solver…${seconds >= 1 ? ` (${seconds} s)` : ''}` });
  });
  show();
  clearInterval(designingTicker);
  if (waiting.length) designingTicker = setInterval(show, 1000);
}

/** The compared shaper an error is about (its index in the state drawn), or -1. */
function shaperOf(error) {
  const m = /^shapers\[(\d+)\]/.exec(typeof error?.field === 'string' ? error.field : '');
  return m ? Number(m[1]) : -1;
}

/** The error of shaper `j` of a state drawn without some shapers, named as shaper `k` of the
 * whole state (its field and the message's leading field). */
function renamed(error, j, k) {
  if (j === k) return error;
  const from = `shapers[${j}]`;
  const to = `shapers[${k}]`;
  const message = error?.message ?? String(error);
  return { kind: error?.kind, field: to + error.field.slice(from.length), message: message.startsWith(from) ? to + message.slice(from.length) : message };
}

/**
 * Draws the state. A shaper that cannot be designed is left out, the others keeping their
 * colours, when nothing better is on screen: on the first frame (a link or a reload), and
 * while the last frame had left shapers out (edits elsewhere still draw; adding or removing a
 * shaper may move the one left out). Once every shaper drew, an error is thrown instead, so the
 * last good charts stay.
 *
 * A solved family's shaper is designed by the design worker and handed to renderPlayground
 * (`designed`) once it is back. Until then it waits: with every shaper on screen, the frame is
 * held (the last good charts stay, an error of kind "designing" is thrown) for up to HOLD_MS,
 * so a quick design never makes the charts flicker; after that, or with nothing on screen yet,
 * the others draw without it. Returns the result, the shapers drawn (indices), those left out
 * with their errors and those waiting for their design.
 */
function render(st, canvases) {
  const requests = st.shapers.map((s) => ({ ...s, modes: st.modes }));
  const keys = requests.map(designKey);
  const waiting = [];
  const left = [];
  let kept = [];
  // While a drag goes on (see `dragging`), a design that is back waits for a pause.
  const sinceEdit = performance.now() - lastEdit;
  const quiet = !dragging || sinceEdit >= QUIET_MS;
  awaitingQuiet = false;
  st.shapers.forEach((s, i) => {
    const known = designs.get(keys[i]);
    if (known?.shaper && !quiet) {
      waiting.push(i);
      awaitingQuiet = true;
    } else if (known?.pending || (!known && solvedFamilies.has(s.family))) waiting.push(i);
    else kept.push(i);
  });
  if (awaitingQuiet) {
    clearTimeout(quietTimer);
    quietTimer = setTimeout(schedule, QUIET_MS - sinceEdit + 1);
  }
  const want = () => {
    wantedKeys = new Set(waiting.map((i) => keys[i]));
    waiting.forEach((i) => requestDesign(keys[i], requests[i]));
    pump();
  };
  want();
  for (;;) {
    let error;
    let k = kept.find((i) => designs.get(keys[i])?.error);
    if (k !== undefined) {
      error = designerError(designs.get(keys[k]), k);
    } else {
      if (waiting.length && (!kept.length || holding())) throw Object.assign(new Error('designing'), { kind: 'designing', waiting, keys: waiting.map((i) => keys[i]) });
      const drawn = kept.length === st.shapers.length ? { ...st } : {
        ...st,
        shapers: kept.map((i) => st.shapers[i]),
        view: { ...st.view, mapShaper: Math.max(0, kept.indexOf(st.view.mapShaper ?? 0)), seriesColors: kept },
      };
      drawn.designed = kept.map((i) => designs.get(keys[i])?.shaper ?? null);
      try {
        return { result: api.renderPlayground(drawn, canvases), kept, left, waiting, waitingKeys: waiting.map((i) => keys[i]) };
      } catch (e) {
        const j = shaperOf(e);
        k = j < 0 ? -1 : kept[j];
        if (e?.kind === 'unavailable' && k >= 0) {
          // A family the solver designs only with some settings (bounded sampled): it waits too.
          waiting.push(k);
          kept = kept.filter((i) => i !== k);
          want();
          continue;
        }
        error = j < 0 ? e : renamed(e, j, k);
      }
    }
    const mayLeave = k >= 0 && kept.length > 1 && (!lastGood || lastGood.left.length > 0 || lastGood.waiting.length > 0);
    if (!mayLeave) throw error;
    left.push({ index: k, error });
    kept = kept.filter((i) => i !== k);
  }
}

// ---------- solved designs, off the main thread ----------
// The design worker (web/design_worker.js) designs one shaper at a time with the designer
// module (`design` and the optimisation solver), compiled here once, when the first solved
// shaper is asked for. Its answers are kept by request (the shaper's spec with the modes, as
// JSON) for as long as a state may come back to them (back/forward, undoing an edit). A design
// that the state on screen no longer asks for is stopped, by ending the worker, once it has run
// for STALE_MS (a quick one is left to finish: starting a worker costs more than it saves).
const HOLD_MS = 250;
const STALE_MS = 300;
const QUIET_MS = 150;
const KEPT_DESIGNS = 64;
/** key → { pending: true, request, since } | { shaper } | { error, retry? } */
const designs = new Map();
let wantedKeys = new Set(); // the keys the last frame waited for
let designerModule = null; // the promise of the compiled designer module
let designer = null; // { worker, ready, key: the design running or null, since }
let designId = 0;
let staleTimer = 0;
let holdSince = null; // when the frame on screen began to be held for a design (-Infinity: stop)
let holdTimer = 0;
// A drag: a design came back for a state the page had already left. Until a frame draws every
// shaper again, solved shapers stay out while edits keep coming (QUIET_MS apart at most), so
// they do not blink in and out of the charts whenever a design happens to keep up.
let dragging = false;
let lastEdit = -Infinity; // when the state was last edited (performance.now())
let awaitingQuiet = false; // the last frame left a designed shaper out for the drag
let quietTimer = 0;

/** A design request's key in `designs`: `design`'s spec ({ …shaper, modes }) as JSON. */
const designKey = (request) => JSON.stringify(request);

/** Whether to keep the last good charts while a design is on its way (see render). */
function holding() {
  if (!lastGood || lastGood.waiting.length) return false;
  holdSince ??= performance.now();
  const left = HOLD_MS - (performance.now() - holdSince);
  if (left <= 0) return false;
  clearTimeout(holdTimer);
  holdTimer = setTimeout(schedule, left);
  return true;
}

/** The design worker's error for shaper `k`, named to it (`shapers[k].…`). */
function designerError({ error }, k) {
  const at = `shapers[${k}]`;
  const f = typeof error.field === 'string' ? error.field : '';
  const field = !f ? at : f.startsWith('[') ? at + f : `${at}.${f}`;
  const message = f && error.message.startsWith(f) ? field + error.message.slice(f.length) : `${at}: ${error.message}`;
  return { kind: error.kind, field, message };
}

/** After an edit, a design whose solver could not be loaded is asked for again. */
function forgetFailedLoads() {
  for (const [k, v] of designs) if (v.retry) designs.delete(k);
}

function requestDesign(key, request) {
  if (designs.has(key)) return;
  designs.set(key, { pending: true, request, since: performance.now() });
  // Keep the cache bounded: drop the oldest answers first.
  if (designs.size > KEPT_DESIGNS) {
    for (const [k, v] of designs) {
      if (designs.size <= KEPT_DESIGNS) break;
      if (!v.pending) designs.delete(k);
    }
  }
}

/** Starts the next wanted design if the worker is free; stops one nobody wants any more. */
function pump() {
  // Requests no frame waits for any more are forgotten (asked again if their state comes back).
  for (const [k, v] of designs) if (v.pending && !wantedKeys.has(k) && designer?.key !== k) designs.delete(k);
  if (designer?.key && !wantedKeys.has(designer.key)) {
    const age = performance.now() - designer.since;
    if (age >= STALE_MS) {
      designer.worker.terminate();
      designs.delete(designer.key);
      designer = null;
    } else {
      clearTimeout(staleTimer);
      staleTimer = setTimeout(pump, STALE_MS - age + 1);
    }
  }
  const next = [...wantedKeys].find((k) => designs.get(k)?.pending && designer?.key !== k);
  if (next && !designer?.key) runDesign(next);
  if (awaitingQuiet || [...wantedKeys].some((k) => designs.get(k)?.pending)) document.body.dataset.fetching = 'designs'; // for the tests
  else delete document.body.dataset.fetching;
}

function runDesign(key) {
  designerModule ??= compileModule('designer_bg.wasm');
  if (!designer) {
    const worker = new Worker(new URL('./design_worker.js', import.meta.url), { type: 'module' });
    const ready = designerModule.then((module) => {
      try {
        worker.postMessage({ module });
      } catch {
        worker.postMessage({ module: null }); // not cloneable here: the worker fetches it
      }
    });
    designer = { worker, ready, key: null, since: 0 };
    const mine = designer;
    worker.addEventListener('message', ({ data }) => answered(mine, data));
    worker.addEventListener('error', (e) => answered(mine, { id: mine.id, error: { kind: 'load', message: `The design worker failed (${e.message ?? e})` } }));
  }
  const d = designer;
  d.key = key;
  d.id = ++designId;
  d.since = performance.now();
  const { request } = designs.get(key);
  d.ready.then(() => d.worker.postMessage({ id: d.id, request }), (e) => {
    designerModule = null; // the next request tries again
    answered(d, { id: d.id, error: { kind: 'load', message: `The optimisation solver could not be loaded (${e?.message ?? e})` } });
  });
}

/** The worker's answer: kept, the next design started and the page redrawn with it. */
function answered(d, { id, shaper, error }) {
  if (d !== designer || id !== d.id || !d.key) return; // from a worker since ended, or late
  // A design back for a state already left (a slider being dragged, the next step not drawn
  // yet): holding the charts for each next one would make the whole page follow the drag at
  // the designs' pace, so the others draw now, without the solved shaper.
  const current = state.shapers.some((s) => designKey({ ...s, modes: state.modes }) === d.key);
  if (!current) {
    dragging = true;
    if (holdSince !== null) holdSince = -Infinity;
  }
  const failedToLoad = error?.kind === 'load';
  // An error without a kind is a trap (the core's errors all have one): the module may be
  // left in a bad state, so the next design starts a fresh worker.
  const trapped = error && !error.kind;
  designs.set(d.key, shaper ? { shaper } : { error, retry: failedToLoad || trapped });
  d.key = null;
  if (failedToLoad || trapped) {
    d.worker.terminate();
    designer = null;
  }
  pump();
  schedule();
}

let frame = 0;
let editing = false;
/** Schedules one update for the next frame and records the state in the URL. */
function changed(commit = false) {
  forgetFailedLoads();
  lastEdit = performance.now();
  const hash = toHash(state);
  if (hash !== location.hash) {
    // One history entry per editing gesture: push at its start, replace while it goes on.
    if (!editing || commit) history.pushState(null, '', hash);
    else history.replaceState(null, '', hash);
    editing = !commit;
  }
  schedule();
}

/** Schedules one update for the next frame (several requests in a frame make one update). */
function schedule() {
  if (!frame) frame = requestAnimationFrame(() => { frame = 0; update(); });
}

function loadState(next, { push = true } = {}) {
  forgetFailedLoads();
  state = next;
  rebuild();
  if (push) changed(true);
  else update();
}

function notice(text) {
  $('notice').textContent = text;
}

/** Loads the state in the URL hash; a garbled one is refused with a message and the current
 * (or, on first load, the default) state is kept. */
function fromLocation({ startup = false } = {}) {
  const { state: s, error } = fromHash(location.hash);
  if (error) {
    if (startup) loadState(clone(DEFAULT_STATE), { push: false });
    $('general-error').textContent = error;
    return;
  }
  if (s && lastGood && JSON.stringify(s) === JSON.stringify(state)) return;
  loadState(s ?? clone(DEFAULT_STATE), { push: false });
}

/**
 * A wasm module of the page, compiled. The page's is instantiated here and handed to the
 * measured-data worker, which ranks shapers with it without fetching or compiling it again; the
 * designer module is handed to the design worker. This file runs as the bundle
 * pkg/page/main.js (scripts/bundle.sh), beside the .wasm files, as the glue inside it does.
 */
async function compileModule(file) {
  const response = await fetch(new URL(file, import.meta.url));
  if (!response.ok) throw new Error(`could not load the wasm module (HTTP ${response.status})`);
  try {
    return await WebAssembly.compileStreaming(response.clone());
  } catch {
    // Served without the application/wasm MIME type: compile from the bytes.
    return WebAssembly.compile(await response.arrayBuffer());
  }
}

async function main() {
  const wasmModule = await compileModule('playground_bg.wasm');
  await lite.default({ module_or_path: wasmModule });
  familyTable = api.families();
  solvedFamilies = new Set(familyTable.filter((f) => f.solver === 'always').map((f) => f.name));
  $('preset').append(...PRESETS.map((p) => el('option', { value: p.id }, p.title)));
  $('preset').addEventListener('change', () => {
    const p = PRESETS.find((x) => x.id === $('preset').value);
    if (p) loadState(clone(p.state));
  });
  $('add-mode').addEventListener('click', () => {
    const last = state.modes[state.modes.length - 1];
    state.modes.push({ frequencyHz: Number(((last?.frequencyHz || 1) * 2.5).toPrecision(4)), damping: last?.damping ?? 0.02 });
    rebuild();
    changed(true);
  });
  $('add-shaper').addEventListener('click', () => {
    const used = new Set(state.shapers.map((s) => s.family));
    const next = familyTable.find((f) => !used.has(f.name) && f.parameters.length === 0) ?? familyTable[0];
    state.shapers.push({ family: next.name });
    rebuild();
    changed(true);
  });
  $('vtol').addEventListener('input', () => { state.view.vtol = parseParam({ kind: 'percent' }, $('vtol').value); changed(); });
  $('scv').addEventListener('input', () => { state.view.scv = readNumber($('scv')); changed(); });
  $('mismatch').addEventListener('input', () => {
    state.view.mismatch = readNumber($('mismatch'));
    if (Number.isFinite(state.view.mismatch)) $('mismatch-slider').value = String(state.view.mismatch);
    changed();
  });
  $('mismatch-slider').addEventListener('input', () => {
    $('mismatch').value = $('mismatch-slider').value;
    state.view.mismatch = Number($('mismatch-slider').value);
    changed();
  });
  $('plant-kind').addEventListener('change', () => {
    state.view.plant = $('plant-kind').value === 'pendulum' ? { kind: 'pendulum', gravity: 9.81, initialAngle: 0 } : { kind: 'modal' };
    changed(true);
  });
  $('command-kind').addEventListener('change', () => {
    state.view.command = commandFor($('command-kind').value, state.view.command);
    $('command-params').replaceChildren(...commandFields());
    changed(true);
  });
  $('map-shaper').addEventListener('change', () => { state.view.mapShaper = Number($('map-shaper').value); changed(true); });
  $('controls').addEventListener('change', () => { editing = false; });
  $('controls').addEventListener('submit', (e) => e.preventDefault());
  $('export-shaper').addEventListener('change', showExport);
  $('export-format').addEventListener('change', showExport);
  $('export-steps').addEventListener('input', showExport);
  $('export-tick').addEventListener('input', showExport);
  $('export-copy').addEventListener('click', () => navigator.clipboard?.writeText($('export-output').value).then(() => notice('Export copied.'), () => notice('Copy failed: select the text and copy it.')));
  $('export-download').addEventListener('click', () => {
    const ext = { csv: 'csv', json: 'json', c: 'h', cFixed: 'h', rrf: 'g' }[$('export-format').value];
    download(`shaper.${ext}`, $('export-output').value);
  });
  $('copy-link').addEventListener('click', () => navigator.clipboard?.writeText(location.href).then(() => notice('Link copied.'), () => notice('Copy failed: copy the address bar.')));
  $('save-state').addEventListener('click', () => download('input-shaping-state.json', JSON.stringify(state, null, 2)));
  $('load-state').addEventListener('change', async () => {
    const file = $('load-state').files[0];
    $('load-state').value = '';
    if (!file) return;
    try {
      if (file.size > 100000) throw new Error('The file is too large to be a playground state.');
      const next = checkState(JSON.parse(await file.text()));
      loadState(next);
      notice(`Loaded ${file.name}.`);
    } catch (e) {
      $('general-error').textContent = `Could not load ${file.name}: ${e.message}`;
    }
  });
  window.addEventListener('popstate', () => fromLocation());
  window.addEventListener('hashchange', () => fromLocation());
  let resizeTimer;
  window.addEventListener('resize', () => { clearTimeout(resizeTimer); resizeTimer = setTimeout(update, 100); });
  fromLocation({ startup: true });
  // Measured data: identified modes replace the editor's modes with one click.
  setupMeasure({
    wasmModule,
    drawSpectrum: (...args) => api.drawSpectrum(...args),
    acceptModes(modes) { state.modes = modes.slice(0, MAX_MODES); rebuild(); changed(true); },
  });
  // For the benchmark script: a full update, timed.
  window.__playground = { update, get state() { return state; } };
}

function download(name, text) {
  const url = URL.createObjectURL(new Blob([text], { type: 'text/plain' }));
  const a = el('a', { href: url, download: name });
  document.body.append(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(url), 1000);
}

main().catch((error) => {
  $('general-error').textContent = `The page could not start: ${error?.message ?? error}`;
});
