// The results of the last good frame: the summary and simulation tables, the impulse tables
// and the export. Charts are drawn by wasm (renderPlayground); these are the page's texts.
import * as api from '../pkg/page/playground.js';
import { $, el, fmt, fmtPct, readNumber, syncRows, rebuildIf, COLORS } from './dom.js';
import { page } from './page.js';

/** The impulses each impulse table shows, as JSON (by table body). */
const impulseKeys = new WeakMap();
/**
 * Rows an impulse table shows until its "Show all" button is pressed: a multi-mode ZV-D³ has
 * 125 impulses, and every row's text changes on a frequency edit (the exports have them all).
 */
const IMPULSE_ROWS = 20;
/** Impulse tables (by index) whose every row is shown; reset when the tables are rebuilt. */
const expandedTables = new Set();

export function showResults(result, st, kept) {
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
  // A sampled shaper's cost report (Kamel, Lange & Hirzinger; issue 23 item 2): rows only when one is compared.
  if (results.some((r) => r.family === 'sampled')) {
    const of = (f) => (r) => (r.sampled ? f(r.sampled) : '—');
    rows.push(['Sampled: ramp delay τ, eq. 10 (s)', of((s) => fmt(s.rampDelay, 4))]);
    rows.push(['Sampled: cost J_q, eq. 17 (∫e² dt + AᵀQA)', of((s) => `${fmt(s.cost.total, 4)} (${fmt(s.cost.controlError, 4)} + ${fmt(s.cost.amplitudePenalty, 4)})`)]);
    rows.push(['Sampled: J_q of the minimum-norm shaper', of((s) => fmt(s.baselineCost.total, 4))]);
    rows.push(['Sampled: cost reduction against it (%)', of((s) => fmtPct(s.costReduction))]);
  }
  // Whether the optimisation solver's polish converged (si, direct): a grid solution meets every
  // constraint but may be up to a grid step longer, with the grid's many impulses.
  if (results.some((r) => r.solver)) {
    rows.push(['Optimisation solver', (r) => (r.solver ? (r.solver.polished ? 'polished' : 'grid solution (not polished)') : '—')]);
  }
  syncRows($('summary').tBodies[0], rows.map(([name, f]) => [name, ...results.map((r) => f(r))]));

  showSimulation(result, color, st);

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
  const r = page.lastGood?.result.results[k];
  if (!r) return;
  if (expandedTables.has(k)) expandedTables.delete(k);
  else expandedTables.add(k);
  showImpulseTable(k, r);
}

/** The simulated move's metrics: the unshaped command and every shaper (`color(k)` of result k). */
function showSimulation(result, color, st) {
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
  const plant = { pendulum: 'nonlinear pendulum', twoMass: 'two-mass spring' }[sim.plant] ?? 'modal plant';
  // With a mismatch per mode or in damping (issue 23 item 2), each actual mode with its ζ.
  const perMode = st.view.modeMismatch || st.view.actualDamping;
  const actual = perMode ? sim.plantModesHz.map((f, i) => `${fmt(f, 4)} Hz (ζ ${fmt(sim.plantDamping[i], 3)})`).join(', ')
    : `${sim.plantModesHz.map((f) => fmt(f, 4)).join(', ')} Hz = model × ${fmt(sim.mismatch, 4)}`;
  $('simulation-note').textContent = `(${plant}, actual modes ${actual}; ${sim.samples} samples over ${fmt(sim.duration, 4)} s)`;
}

export function showExport() {
  $('export-error').textContent = '';
  if (!page.lastGood) return;
  const k = Number($('export-shaper').value) || 0;
  const r = page.lastGood.result.results[k];
  if (!r) return;
  const m = page.lastGood.state.modes.map((mode) => `${mode.frequencyHz} Hz, ζ ${mode.damping}`).join('; ');
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
