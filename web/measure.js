// Measured data (issue 7): load a recording, show its spectrum with the detected peaks, the
// identified modes with their uncertainties, and the ranked shaper recommendation. The core
// does the work (RecordingParser, identifyModes, recommendShaper, drawSpectrum); this module
// reads the file in chunks so a 10⁶-row file never freezes the page, and keeps the last good
// result on screen when a file is bad.
import { RecordingParser, identifyModes, recommendShaper, drawSpectrum } from '../pkg/input_shaping.js';

const $ = (id) => document.getElementById(id);
/** Bytes read per step; the page yields to the browser between steps. */
const CHUNK_BYTES = 1 << 20;
/** Largest file accepted (a 10⁷-row Klipper file is ~350 MB). */
const MAX_FILE_BYTES = 512 * 1024 * 1024;

let recording = null; // the last good recording
let identification = null; // and what was found in it
let loadToken = 0;
let acceptModes = () => {};

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
const nextFrame = () => new Promise((resolve) => setTimeout(resolve, 0));
const METHOD = { halfPower: 'half-power', spectrumFit: 'spectrum fit', freeDecay: 'free-decay fit' };

function status(text) { $('measure-status').textContent = text; }
function showError(text) { $('measure-error').textContent = text; }

/** Reads `file` in chunks into a RecordingParser, with progress; returns the recording. */
async function readRecording(file, token) {
  if (file.size > MAX_FILE_BYTES) {
    throw new Error(`${file.name} is ${(file.size / 1e6).toFixed(0)} MB; at most ${MAX_FILE_BYTES / 1e6} MB are read`);
  }
  const progress = $('measure-progress');
  progress.hidden = false;
  progress.value = 0;
  const parser = new RecordingParser({});
  const decoder = new TextDecoder('utf-8');
  try {
    for (let offset = 0; offset < file.size; offset += CHUNK_BYTES) {
      const bytes = await file.slice(offset, offset + CHUNK_BYTES).arrayBuffer();
      if (token !== loadToken) return null; // another file was chosen meanwhile
      parser.push(decoder.decode(bytes, { stream: true }));
      progress.value = Math.min(1, (offset + bytes.byteLength) / Math.max(1, file.size));
      status(`Reading ${file.name}: ${parser.rows.toLocaleString('en')} rows…`);
      await nextFrame();
    }
    parser.push(decoder.decode());
    return parser.finish();
  } finally {
    parser.free();
    progress.hidden = true;
  }
}

async function load(file) {
  const token = ++loadToken;
  showError('');
  try {
    const rec = await readRecording(file, token);
    if (!rec) return;
    status(`Analysing ${rec.rows.toLocaleString('en')} samples…`);
    await nextFrame();
    const previous = recording;
    recording = rec;
    fillChannels(rec);
    if (!analyse({ keepOnError: previous })) return;
    $('measure-file-name').textContent = file.name;
  } catch (e) {
    showError(describe(file.name, e));
    status(recording ? 'The previous recording is still shown.' : '');
  }
}

/** "data.csv, line 12, column 3 (`accel_y`): `abc` is not a number". */
function describe(name, e) {
  const message = e?.message ?? String(e);
  return `Could not read ${name}: ${message.replace(/^recording: /, '')}`;
}

function fillChannels(rec) {
  const select = $('measure-channel');
  const before = select.value;
  select.replaceChildren(...rec.channels.map((c, i) => el('option', { value: String(i) }, c.name)));
  const same = rec.channels.findIndex((c) => c.name === before);
  select.value = String(same >= 0 ? same : 0);
}

/** Identifies and recommends for the current recording; false (and the old result kept) on error. */
function analyse({ keepOnError = null } = {}) {
  if (!recording) return false;
  const options = {
    channel: Number($('measure-channel').value || 0),
    signal: $('measure-signal').value,
    maxModes: Number($('measure-max-modes').value),
  };
  let id;
  let rec = null;
  try {
    id = identifyModes(recording, options);
    if (id.modes.length > 0) rec = recommendShaper(id.spectrum, id.modes, {});
  } catch (e) {
    showError(`Could not analyse the recording: ${e?.message ?? e}`);
    if (keepOnError) { recording = keepOnError; fillChannels(recording); }
    return false;
  }
  identification = id;
  const r = recording;
  status(`${r.format === 'klipper' ? 'Klipper raw accelerometer file' : 'CSV'}: ${r.rows.toLocaleString('en')} samples `
    + `at ${fmt(r.sampleRateHz, 6)} Hz over ${fmt(r.durationS, 4)} s`
    + `${r.resampled ? ` (uneven time stamps, jitter ${pct(r.timing.jitter)}, resampled)` : ''}; channel ${id.channel}; `
    + `Welch PSD with ${id.spectrum.segmentLength}-sample segments (${fmt(id.spectrum.resolutionHz, 3)} Hz bins, ${id.spectrum.segments} averaged)`
    + `${id.freeDecay ? `; free decay found at ${fmt(id.freeDecay.startS, 3)}–${fmt(id.freeDecay.endS, 3)} s` : ''}.`);
  showModes(id);
  showRecommendation(rec);
  draw();
  return true;
}

function showModes(id) {
  const body = $('measure-modes').tBodies[0];
  body.replaceChildren(...id.modes.map((m, i) => el('tr', { 'data-mode': String(i) },
    el('td', {}, String(i + 1)),
    el('td', { class: 'num', 'data-frequency': String(m.frequencyHz) }, `${fmt(m.frequencyHz, 5)} ± ${fmt(m.frequencyUncertaintyHz, 2)}`),
    el('td', { class: 'num', 'data-damping': String(m.damping) }, `${fmt(m.damping, 3)} ± ${fmt(m.dampingUncertainty, 2)}`),
    el('td', {}, METHOD[m.method] ?? m.method),
    el('td', { class: 'hint' }, m.estimates.map((e) => `${METHOD[e.method] ?? e.method}: ${fmt(e.frequencyHz, 5)} Hz, ζ ${fmt(e.damping, 3)}`).join('; ')))));
  if (id.modes.length === 0) {
    body.replaceChildren(el('tr', {}, el('td', { colspan: '5' }, 'No resonance peak stands out of the spectrum in this channel.')));
  }
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
  const canvas = $('spectrum-chart');
  const ratio = window.devicePixelRatio || 1;
  const width = Math.max(300, canvas.clientWidth || 640);
  canvas.width = Math.round(width * ratio);
  canvas.height = Math.round(width * 0.42 * ratio);
  const top = Math.max(0, ...identification.modes.map((m) => m.frequencyHz));
  const maxHz = top > 0 ? Math.min(identification.spectrum.sampleRateHz / 2, 2.5 * top) : undefined;
  try {
    drawSpectrum(canvas, identification.spectrum, {
      peaksHz: identification.modes.map((m) => m.frequencyHz), maxHz, pixelRatio: ratio,
    });
  } catch (e) {
    showError(`Could not draw the spectrum: ${e?.message ?? e}`);
  }
}

/** Wires the section; `hooks.acceptModes(modes)` puts modes into the playground's editor. */
export function setupMeasure(hooks) {
  acceptModes = hooks.acceptModes;
  const input = $('measure-file');
  input.addEventListener('change', () => {
    const file = input.files[0];
    input.value = '';
    if (file) load(file);
  });
  const drop = $('measure-drop');
  drop.addEventListener('dragover', (e) => { e.preventDefault(); drop.classList.add('over'); });
  drop.addEventListener('dragleave', () => drop.classList.remove('over'));
  drop.addEventListener('drop', (e) => {
    e.preventDefault();
    drop.classList.remove('over');
    const file = e.dataTransfer?.files?.[0];
    if (file) load(file);
  });
  for (const id of ['measure-channel', 'measure-signal', 'measure-max-modes']) {
    $(id).addEventListener('change', () => { showError(''); analyse(); });
  }
  $('measure-accept').addEventListener('click', () => {
    if (!identification || identification.modes.length === 0) return;
    acceptModes(identification.modes.map((m) => ({
      frequencyHz: Number(m.frequencyHz.toPrecision(5)),
      damping: Number(Math.min(0.99, Math.max(0, m.damping)).toPrecision(3)),
    })));
  });
  let resizeTimer;
  window.addEventListener('resize', () => { clearTimeout(resizeTimer); resizeTimer = setTimeout(draw, 100); });
  window.__measure = { load, get identification() { return identification; } };
}
