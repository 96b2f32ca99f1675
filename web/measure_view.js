// Measured data (issues 7 and 20): the view, fetched when the path is first opened
// (web/measure.js). Files go to the worker (web/measure_worker.js), which reads them in 1 MB
// chunks with progress, groups them per machine axis, forms Klipper's spectra, ranks the
// shapers and identifies the modes of a raw recording. Per axis the view draws the Klipper-style
// chart (drawKlipperChart of the recording module, instantiated here on the page's thread) and
// the table like calibrate_shaper's; below, the config text to copy; then the identified modes
// with "Use these modes" and the spectrum they came from. A bad file leaves the last good result
// on screen, its error (file, line, column) beside the drop zone.
import initRecording, { drawKlipperChart, firmwareConfig } from '../pkg/page/recording.js';

const $ = (id) => document.getElementById(id);
/** Largest file accepted (a 10⁷-row Klipper file is ~350 MB). */
const MAX_FILE_BYTES = 512 * 1024 * 1024;
/** Shapers' curve colours: matplotlib's cycle, as Klipper's figure (crate/chart/klipper.rs). */
const COLORS = ['#1f77b4', '#ff7f0e', '#2ca02c', '#d62728', '#9467bd', '#8c564b', '#e377c2', '#7f7f7f', '#bcbd22', '#17becf'];
/** The crate's family names that Klipper's config spells otherwise. */
const KLIPPER_NAME = { ei2: '2hump_ei', ei3: '3hump_ei' };

let worker = null;
let hooks = null;
let recordingModule = null; // compiled recording module, for this thread and the worker
let ready = null;
let identification = null; // the last good result's modes
let result = null; // the last good result
let fft = null;
let request = 0;
let fileNames = '';

function el(tag, props = {}, ...children) {
  const node = document.createElement(tag);
  for (const [k, v] of Object.entries(props)) {
    if (k in node && typeof v !== 'string') node[k] = v;
    else node.setAttribute(k, v);
  }
  node.append(...children.filter((c) => c !== null && c !== undefined));
  return node;
}
const fmt = (x, digits = 4) => (Number.isFinite(x) ? String(Number(x.toPrecision(digits))) : '—');
const pct = (x) => (Number.isFinite(x) ? `${fmt(100 * x, 3)} %` : '—');
const fixed = (x, d) => (Number.isFinite(x) ? x.toFixed(d) : '—');
/** Klipper's max_accel as it prints it: round(max_accel / 100) · 100. */
const accel = (x) => (Number.isFinite(x) ? String(Math.round(x / 100) * 100) : '—');
/** The optimised table's row kinds (recommendShaper's `kind` with criterion 'optimal'). */
const KIND = { klipper: "Klipper's pick", mainline: 'best mainline', custom: 'custom' };
const METHOD = { halfPower: 'half-power', spectrumFit: 'spectrum fit', freeDecay: 'free-decay fit' };
const AXIS_NAME = (a) => (/^[xyz]$/.test(a) ? `Axis ${a.toUpperCase()}` : a);

function status(text) { $('measure-status').textContent = text; }
function showError(text) { $('measure-error').textContent = text; }

function options() {
  return {
    identify: {
      channel: Number($('measure-channel').value || 0),
      signal: $('measure-signal').value,
      maxModes: Number($('measure-max-modes').value),
    },
    psdChannel: $('measure-psd-channel').value,
  };
}

async function compile(file) {
  const response = await fetch(new URL(file, import.meta.url));
  if (!response.ok) throw new Error(`could not load ${file} (HTTP ${response.status})`);
  try {
    return await WebAssembly.compileStreaming(response.clone());
  } catch {
    return WebAssembly.compile(await response.arrayBuffer());
  }
}

/** The recording module, compiled once, instantiated here (it draws) and handed to the worker. */
function start() {
  ready ??= compile('recording_bg.wasm').then(async (m) => {
    recordingModule = m;
    await initRecording({ module_or_path: m });
  });
  return ready;
}

async function load(files) {
  showError('');
  const big = files.find((f) => f.size > MAX_FILE_BYTES);
  if (big) {
    showError(`Could not read ${big.name}: it is ${(big.size / 1e6).toFixed(0)} MB; at most ${MAX_FILE_BYTES / 1e6} MB are read`);
    return;
  }
  const id = ++request;
  fileNames = files.map((f) => f.name).join(', ');
  const progress = $('measure-progress');
  progress.value = 0;
  progress.hidden = false;
  status(`Reading ${fileNames}…`);
  try {
    await start();
  } catch (e) {
    progress.hidden = true;
    showError(`Could not load the recording module: ${e?.message ?? e}`);
    return;
  }
  startWorker();
  // New files start from their first channel.
  const o = options();
  worker.postMessage({ id, type: 'load', files, options: { ...o, identify: { ...o.identify, channel: 0 } } });
}

function analyse() {
  if (!result) return;
  worker.postMessage({ id: ++request, type: 'analyse', options: options() });
}

function onMessage({ data }) {
  if (data.id !== request) return;
  const progress = $('measure-progress');
  if (data.type === 'progress') {
    progress.value = data.fraction;
    status(`Reading ${data.file}: ${data.rows.toLocaleString('en')} rows…`);
  } else if (data.type === 'analysing') {
    progress.hidden = true;
    status(`Analysing ${data.rows.toLocaleString('en')} samples…`);
  } else if (data.type === 'error') {
    progress.hidden = true;
    const message = data.message.replace(/^recording(?: \(([^)]*)\))?: /, (_, where) => (where ? `${where}: ` : ''));
    // The parser's message names the file when it knows it ("`a.csv`, line 3, column 2 …").
    showError(data.file && message.includes(`\`${data.file}\``) ? `Could not read ${message}` : `Could not read ${data.file ?? fileNames}: ${message}`);
    status(result ? 'The previous result is still shown.' : '');
  } else if (data.type === 'fft') {
    fft = data.spectrum;
    draw();
  } else if (data.type === 'result') {
    progress.hidden = true;
    fft = null;
    if (data.rankingError) showError(`Could not rank the shapers for these modes: ${data.rankingError}`);
    show(data);
    if ($('measure-view').value === 'fft') requestFft();
    $('measure-file-name').textContent = fileNames;
  }
}

function startWorker() {
  if (worker) return;
  worker = new Worker(new URL('./measure_worker.js', import.meta.url), { type: 'module' });
  worker.addEventListener('message', onMessage);
  worker.addEventListener('error', (e) => showError(`The measurement worker failed: ${e.message ?? e}`));
  try {
    worker.postMessage({ type: 'module', module: hooks.wasmModule, recordingModule });
  } catch {
    worker.postMessage({ type: 'module', module: null, recordingModule: null }); // not cloneable: the worker fetches them
  }
}

function requestFft() {
  if (!identification) return;
  worker.postMessage({ id: request, type: 'fft', channel: Number($('measure-channel').value || 0) });
}

function fillChannels(names, selected) {
  const select = $('measure-channel');
  select.replaceChildren(...names.map((n, i) => el('option', { value: String(i) }, n)));
  select.value = String(Math.max(0, names.indexOf(selected)));
}

const FORMAT = {
  klipper: 'Klipper raw accelerometer file', csv: 'CSV', rrf: 'RepRapFirmware accelerometer file (M956)',
  klipperResonances: 'Klipper resonances file (PSD)', klipperCalibration: 'Klipper calibration data (PSD and fitted shapers)',
};

function show(data) {
  result = data;
  const { recording: r, identification: id } = data;
  identification = id;
  $('measure-modes-part').hidden = !id;
  if (id && r) {
    fillChannels(r.channels, id.channel);
    $('measure-channel').parentElement.hidden = r.channels.length === 0;
    status(`${FORMAT[r.format] ?? r.format}${r.sampleRateHz ? `: ${r.rows.toLocaleString('en')} samples ` : ''}`
      + `${r.sampleRateHz ? `at ${fmt(r.sampleRateHz, 6)} Hz over ${fmt(r.durationS, 4)} s` : ''}`
      + `${r.resampled ? ` (uneven time stamps, jitter ${pct(r.timing.jitter)}, resampled)` : ''}; channel ${id.channel ?? 'sum'}; `
      + `${id.spectrum.segments ? `Welch PSD with ${id.spectrum.segmentLength}-sample segments (${fmt(id.spectrum.resolutionHz, 3)} Hz bins, ${id.spectrum.segments} averaged)` : `the file's spectrum (${fmt(id.spectrum.resolutionHz, 3)} Hz bins)`}`
      + `${id.freeDecay ? `; free decay found at ${fmt(id.freeDecay.startS, 3)}–${fmt(id.freeDecay.endS, 3)} s` : ''}`
      + `${id.sweep ? `; ${id.sweep.law === 'exponential' ? 'an exponential' : 'a'} sweep of ${fmt(id.sweep.bandHz[0], 3)}–${fmt(id.sweep.bandHz[1], 3)} Hz at ${fmt(id.sweep.rateHzPerS, 3)} Hz/s${id.sweep.law === 'exponential' ? ' at its centre' : ''} read from the data, modes fitted on the whole record inside it` : ''}.`);
    showModes(id);
    showRecommendation(data.recommendation);
  } else {
    status(`${data.axes.length} axis${data.axes.length === 1 ? '' : 'es'} from ${fileNames}.`
      + `${data.identificationError ? ` The modes are not identified from these files: ${data.identificationError}` : ''}`);
    $('measure-accept').disabled = true;
  }
  showAxes(data.axes);
  draw();
}

// ---- per axis: Klipper's chart and table ---------------------------------------------------

function rowsTable(cls, rows, selected, caption, withLabel) {
  const head = ['', 'shaper', ...(withLabel ? ['kind'] : []), 'frequency (Hz)', 'damping ratio', 'vibrations (%)', 'smoothing', 'max accel (mm/s²)', 'score'];
  return el('div', { class: 'scroll' }, el('table', { class: cls },
    el('caption', {}, caption),
    el('thead', {}, el('tr', {}, ...head.map((h) => el('th', { scope: 'col' }, h)))),
    el('tbody', {}, ...rows.map((r, k) => el('tr', {
      class: k === selected ? 'best' : '', 'data-family': String(r.name ?? ''), 'data-frequency': String(r.freq),
    },
    el('td', {}, r.color ? el('span', { class: 'swatch line', style: `border-color: ${r.color}` }) : ''),
    el('td', { class: 'name' }, r.label ?? r.name),
    ...(withLabel ? [el('td', {}, KIND[r.kind] ?? r.kind ?? '')] : []),
    el('td', { class: 'num' }, fixed(r.freq, 1)),
    el('td', { class: 'num' }, Number.isFinite(r.damping) ? fmt(r.damping, 3) : '—'),
    el('td', { class: 'num' }, Number.isFinite(r.vibrations) ? (100 * r.vibrations).toFixed(1) : '—'),
    el('td', { class: 'num' }, fixed(r.smoothing, 3)),
    el('td', { class: 'num' }, accel(r.maxAccel)),
    el('td', { class: 'num' }, Number.isFinite(r.score) ? r.score.toPrecision(3) : '—'))))));
}

function axisPanel(a, k) {
  const rows = a.klipper?.rows ?? [];
  rows.forEach((r, i) => { r.color = COLORS[i % COLORS.length]; });
  const sel = a.klipper?.selected ?? -1;
  const best = rows[sel];
  const kinds = [...new Set(a.formats.map((f) => FORMAT[f] ?? f))].join(', ');
  const part = el('section', { class: 'measure-axis', 'data-axis': a.axis },
    el('h3', {}, AXIS_NAME(a.axis), ' ', el('span', { class: 'hint' },
      `${a.files.join(', ')} (${kinds}${a.files.length > 1 ? '; fitted together, runs kept apart as calibrate_shaper.py keeps them' : ''})`)),
    el('canvas', { class: 'klipper-chart', id: `klipper-chart-${k}`, 'aria-label': `${AXIS_NAME(a.axis)}: measured PSD with the shapers' vibration ratios` }),
    best ? el('p', { class: 'klipper-pick' }, `Klipper's pick: ${best.name} at ${fixed(best.freq, 1)} Hz — `
      + `vibrations ${(100 * best.vibrations).toFixed(1)} %, smoothing ${fixed(best.smoothing, 3)}, max_accel ≤ ${accel(best.maxAccel)} mm/s².`) : null,
    a.error ? el('p', { class: 'error' }, `Could not rank the shapers: ${a.error}`) : null,
    rows.length ? rowsTable('klipper-table', rows, sel, 'As calibrate_shaper.py ranks them', false) : null,
    a.optimal ? rowsTable('optimal-table', a.optimal.rows, a.optimal.selected, "Klipper's pick, the best mainline-Klipper shaper and the best custom shaper, by Klipper's score", true) : null,
    a.optimal?.note ? el('p', { class: 'hint optimal-note' }, a.optimal.note) : null,
    a.spectrum.fitted.length ? el('p', { class: 'hint' }, `Dotted: the shapers Klipper fitted, as the file has them — ${a.spectrum.fitted.map((c) => `${c.name}${Number.isFinite(c.freq) ? ` (${fixed(c.freq, 1)} Hz)` : ''}`).join(', ')}.`) : null);
  return part;
}

function showAxes(axes) {
  $('measure-axes').replaceChildren(...axes.map(axisPanel));
  $('measure-config-part').hidden = axes.length === 0;
  drawAxes();
  showConfig();
}

function drawAxes() {
  if (!result) return;
  result.axes.forEach((a, k) => {
    const canvas = $(`klipper-chart-${k}`);
    if (!canvas) return;
    const ratio = window.devicePixelRatio || 1;
    const width = Math.max(300, canvas.clientWidth || 640);
    canvas.width = Math.round(width * ratio);
    canvas.height = Math.round(Math.min(460, Math.max(300, width * 0.5)) * ratio);
    const s = a.spectrum;
    const rows = a.klipper?.rows ?? [];
    const sel = a.klipper?.selected ?? -1;
    const channelPsd = { sum: s.psdSum, x: s.psdX, y: s.psdY, z: s.psdZ }[a.channel] ?? s.psdSum;
    const shapers = rows.filter((r) => r.values).map((r) => ({ values: r.values, color: r.color, selected: rows[sel] === r }));
    for (const c of s.fitted) shapers.push({ values: c.values, color: '#555555', dotted: true });
    const best = rows[sel]?.values;
    try {
      drawKlipperChart(canvas, {
        frequencyHz: s.frequencyHz, psdSum: s.psdSum, psdX: s.psdX, psdY: s.psdY, psdZ: s.psdZ, shapers,
        after: best ? Float64Array.from(channelPsd, (p, i) => p * best[i]) : undefined,
      }, { pixelRatio: ratio, title: `Frequency response and shapers (${a.files.join(', ')})`.slice(0, 90) });
      canvas.dataset.drawn = String(shapers.length);
    } catch (e) {
      showError(`Could not draw ${AXIS_NAME(a.axis)}: ${e?.message ?? e}`);
    }
  });
}

// ---- config text -----------------------------------------------------------------------------

/** The config text of each axis's pick for `firmware` (firmwareConfig, crate/export/firmware.rs). */
function configText(firmware) {
  const picks = (result?.axes ?? []).map((a) => ({ a, r: a.klipper?.rows?.[a.klipper.selected] })).filter((p) => p.r);
  const named = picks.filter(({ a }) => /^[xyz]$/.test(a.axis));
  // RepRapFirmware's M593 sets one shaper for every axis (it has no axis parameter), so a lone
  // file with no axis in its name (M956 names its files by board and date) still gives it.
  const anyAxis = firmware === 'rrf' && !named.length && picks.length === 1;
  const axes = anyAxis ? [{ ...picks[0], a: { ...picks[0].a, axis: 'x' } }] : named;
  const notes = anyAxis ? [] : picks.filter((p) => !named.includes(p))
    .map(({ a }) => `${a.axis}: not an X, Y or Z axis (Klipper names the files resonances_x_…, calibration_data_y_…): left out.`);
  if (!axes.length) return { text: '', warnings: notes };
  const out = firmwareConfig({
    firmware,
    axes: axes.map(({ a, r }) => ({
      axis: a.axis,
      family: KLIPPER_NAME[r.name] ?? r.name,
      frequencyHz: Number(r.freq.toFixed(1)),
      ...(Number.isFinite(r.damping) ? { damping: r.damping } : {}),
      ...(r.shaper?.impulses ? { impulses: r.shaper.impulses } : {}),
      ...(Number.isFinite(r.maxAccel) ? { maxAccel: r.maxAccel } : {}),
      modes: (a.modes ?? []).map((m) => ({ frequencyHz: m.frequencyHz, damping: m.damping })),
    })),
  });
  return { text: out.text, warnings: [...notes, ...out.warnings] };
}

function showConfig() {
  const box = $('measure-config-text');
  try {
    const { text, warnings } = configText($('measure-config-format').value);
    box.value = text;
    $('measure-config-error').textContent = '';
    $('measure-config-notes').textContent = warnings.join(' ');
  } catch (e) {
    // A shaper the firmware cannot express: said, never a truncated line.
    box.value = '';
    $('measure-config-notes').textContent = '';
    $('measure-config-error').textContent = e?.message ?? String(e);
  }
}

// ---- identified modes (raw recordings) -------------------------------------------------------

function showModes(id) {
  const body = $('measure-modes').tBodies[0];
  body.replaceChildren(...id.modes.map((m, i) => el('tr', { 'data-mode': String(i) },
    el('td', {}, String(i + 1)),
    el('td', { class: 'num', 'data-frequency': String(m.frequencyHz) }, `${fmt(m.frequencyHz, 5)} ± ${fmt(m.frequencyUncertaintyHz, 2)}`),
    el('td', { class: 'num', 'data-damping': String(m.damping) }, `${fmt(m.damping, 3)} ± ${fmt(m.dampingUncertainty, 2)}`),
    el('td', {}, METHOD[m.method] ?? m.method),
    el('td', { class: 'hint' }, (m.estimates ?? []).map((e) => `${METHOD[e.method] ?? e.method}: ${fmt(e.frequencyHz, 5)} Hz, ζ ${fmt(e.damping, 3)}`).join('; ')))));
  if (id.modes.length === 0 && !(id.notes ?? []).length) {
    body.replaceChildren(el('tr', {}, el('td', { colspan: '5' }, 'No resonance peak stands out of the spectrum in this channel.')));
  }
  // What the identification could not do (a response cut off by the sweep's end), under the table.
  const table = $('measure-modes');
  let notes = $('measure-notes');
  if (!notes) {
    notes = el('div', { id: 'measure-notes' });
    (table.closest('.scroll') ?? table).after(notes);
  }
  notes.replaceChildren(...(id.notes ?? []).map((note) => el('p', { class: 'hint', 'data-note': '' }, note)));
  $('measure-accept').disabled = id.modes.length === 0;
}

function showRecommendation(rec) {
  const body = $('measure-recommend').tBodies[0];
  if (!rec) { body.replaceChildren(); $('measure-recommended').textContent = ''; return; }
  body.replaceChildren(...rec.ranked.map((c, i) => el('tr', { class: i === rec.recommended ? 'best' : '' },
    el('td', {}, String(i + 1)),
    el('td', {}, c.label),
    el('td', { class: 'num' }, `${fmt(c.durationS * 1000, 4)}`),
    el('td', { class: 'num' }, pct(c.remainingVibration)),
    el('td', { class: 'num' }, pct(c.nominalRemainingVibration)),
    el('td', { class: 'num' }, c.smoothing == null ? '—' : fmt(c.smoothing, 3)),
    el('td', { class: 'num' }, c.maxAccel == null ? '—' : String(Math.round(c.maxAccel / 100) * 100)))));
  const best = rec.ranked[rec.recommended];
  $('measure-recommended').textContent = `Recommended: ${best.label} — ${fmt(best.durationS * 1000, 4)} ms, `
    + `remaining vibration ≤ ${pct(best.remainingVibration)} over the measured spectrum and the uncertainty of the modes.`;
}

function draw() {
  if (!identification) return;
  const canvas = $('measured-spectrum-chart');
  const ratio = window.devicePixelRatio || 1;
  const width = Math.max(300, canvas.clientWidth || 640);
  canvas.width = Math.round(width * ratio);
  canvas.height = Math.round(width * 0.42 * ratio);
  const top = Math.max(0, ...identification.modes.map((m) => m.frequencyHz));
  const maxHz = top > 0 ? Math.min(identification.spectrum.sampleRateHz / 2, 2.5 * top) : undefined;
  const showFft = $('measure-view').value === 'fft' && fft;
  canvas.dataset.view = showFft ? 'fft' : 'welch';
  try {
    hooks.drawSpectrum(canvas, showFft ? fft : identification.spectrum, {
      peaksHz: identification.modes.map((m) => m.frequencyHz), maxHz, pixelRatio: ratio,
      ...(showFft ? { title: 'Measured spectrum (FFT magnitude of the whole record)', yLabel: '|X|² (dB)' } : {}),
    });
  } catch (e) {
    showError(`Could not draw the spectrum: ${e?.message ?? e}`);
  }
}

/** Wires the view's controls (once, when it is first opened). See web/measure.js for `h`. */
export function setupView(h) {
  hooks = h;
  start().catch(() => {});
  for (const id of ['measure-channel', 'measure-signal', 'measure-max-modes', 'measure-psd-channel']) {
    $(id).addEventListener('change', () => { showError(''); analyse(); });
  }
  $('measure-view').addEventListener('change', () => {
    if ($('measure-view').value === 'fft' && !fft) requestFft();
    else draw();
  });
  $('measure-accept').addEventListener('click', () => {
    if (!identification || identification.modes.length === 0) return;
    hooks.acceptModes(identification.modes.map((m) => ({
      frequencyHz: Number(m.frequencyHz.toPrecision(5)),
      damping: Number(Math.min(0.99, Math.max(0, m.damping)).toPrecision(3)),
    })));
  });
  $('measure-config-format').addEventListener('change', showConfig);
  $('measure-config-copy').addEventListener('click', () => {
    const text = $('measure-config-text').value;
    const done = () => { $('measure-config-copied').textContent = 'Copied.'; };
    const fallback = () => { $('measure-config-text').select(); $('measure-config-copied').textContent = 'Selected: press Ctrl+C to copy.'; };
    if (navigator.clipboard?.writeText) navigator.clipboard.writeText(text).then(done, fallback);
    else fallback();
  });
  let resizeTimer;
  window.addEventListener('resize', () => { clearTimeout(resizeTimer); resizeTimer = setTimeout(() => { draw(); drawAxes(); }, 100); });
  window.__measureView = { get result() { return result; }, get identification() { return identification; }, configText };
}

export { load };
