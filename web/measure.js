// Measured data (issue 7): load a recording, show its spectrum with the detected peaks, the
// identified modes with their uncertainties, and the ranked shaper recommendation. The reading
// (in 1 MB chunks, with progress), the identification and the ranking run in a worker
// (web/measure_worker.js), so a 10⁶-row file never freezes the page; a bad file leaves the last
// good result on screen. The worker and its own module are fetched when the first file is
// opened, not with the page; for the ranking it is handed the page's compiled module.

const $ = (id) => document.getElementById(id);
/** Largest file accepted (a 10⁷-row Klipper file is ~350 MB). */
const MAX_FILE_BYTES = 512 * 1024 * 1024;

let worker = null;
let identification = null; // the last good result
let fft = null; // the FFT magnitude of the current channel, when shown
let request = 0; // id of the latest request: older answers are ignored
let fileName = '';
let acceptModes = () => {};
let wasmModule = null; // the page's compiled module, for the worker's ranking
let drawSpectrum = null; // the page's module's drawSpectrum

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
const METHOD = { halfPower: 'half-power', spectrumFit: 'spectrum fit', freeDecay: 'free-decay fit' };

function status(text) { $('measure-status').textContent = text; }
function showError(text) { $('measure-error').textContent = text; }

function options() {
  return {
    channel: Number($('measure-channel').value || 0),
    signal: $('measure-signal').value,
    maxModes: Number($('measure-max-modes').value),
  };
}

function load(file) {
  showError('');
  if (file.size > MAX_FILE_BYTES) {
    showError(`Could not read ${file.name}: it is ${(file.size / 1e6).toFixed(0)} MB; at most ${MAX_FILE_BYTES / 1e6} MB are read`);
    return;
  }
  fileName = file.name;
  startWorker();
  const progress = $('measure-progress');
  progress.value = 0;
  progress.hidden = false;
  status(`Reading ${file.name}…`);
  // A new file starts from its first channel.
  worker.postMessage({ id: ++request, type: 'load', file, options: { ...options(), channel: 0 } });
}

function analyse() {
  if (!identification) return;
  worker.postMessage({ id: ++request, type: 'analyse', options: options() });
}

function onMessage({ data }) {
  if (data.id !== request) return;
  const progress = $('measure-progress');
  if (data.type === 'progress') {
    progress.value = data.fraction;
    status(`Reading ${fileName}: ${data.rows.toLocaleString('en')} rows…`);
  } else if (data.type === 'analysing') {
    progress.hidden = true;
    status(`Analysing ${data.rows.toLocaleString('en')} samples…`);
  } else if (data.type === 'error') {
    progress.hidden = true;
    showError(`Could not read ${fileName}: ${data.message.replace(/^recording: /, '')}`);
    status(identification ? 'The previous result is still shown.' : '');
  } else if (data.type === 'fft') {
    fft = data.spectrum;
    draw();
  } else if (data.type === 'result') {
    progress.hidden = true;
    fft = null;
    if (data.rankingError) showError(`Could not rank the shapers for these modes: ${data.rankingError}`);
    show(data);
    if ($('measure-view').value === 'fft') requestFft();
    $('measure-file-name').textContent = fileName;
  }
}

function startWorker() {
  if (worker) return;
  worker = new Worker(new URL('./measure_worker.js', import.meta.url), { type: 'module' });
  worker.addEventListener('message', onMessage);
  worker.addEventListener('error', (e) => showError(`The measurement worker failed: ${e.message ?? e}`));
  try {
    worker.postMessage({ type: 'module', module: wasmModule });
  } catch {
    worker.postMessage({ type: 'module', module: null }); // not cloneable here: the worker fetches it
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

function show({ recording: r, identification: id, recommendation: rec }) {
  identification = id;
  fillChannels(r.channels, id.channel);
  status(`${r.format === 'klipper' ? 'Klipper raw accelerometer file' : 'CSV'}: ${r.rows.toLocaleString('en')} samples `
    + `at ${fmt(r.sampleRateHz, 6)} Hz over ${fmt(r.durationS, 4)} s`
    + `${r.resampled ? ` (uneven time stamps, jitter ${pct(r.timing.jitter)}, resampled)` : ''}; channel ${id.channel}; `
    + `Welch PSD with ${id.spectrum.segmentLength}-sample segments (${fmt(id.spectrum.resolutionHz, 3)} Hz bins, ${id.spectrum.segments} averaged)`
    + `${id.freeDecay ? `; free decay found at ${fmt(id.freeDecay.startS, 3)}–${fmt(id.freeDecay.endS, 3)} s` : ''}.`);
  showModes(id);
  showRecommendation(rec);
  draw();
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
    drawSpectrum(canvas, showFft ? fft : identification.spectrum, {
      peaksHz: identification.modes.map((m) => m.frequencyHz), maxHz, pixelRatio: ratio,
      ...(showFft ? { title: 'Measured spectrum (FFT magnitude of the whole record)', yLabel: '|X|² (dB)' } : {}),
    });
  } catch (e) {
    showError(`Could not draw the spectrum: ${e?.message ?? e}`);
  }
}

/**
 * Wires the section; `hooks.acceptModes(modes)` puts modes into the playground's editor,
 * `hooks.wasmModule` is the page's compiled module without the solver (the worker ranks
 * shapers with it; null: the worker fetches it), `hooks.drawSpectrum` draws with the page's
 * module in use.
 */
export function setupMeasure(hooks) {
  acceptModes = hooks.acceptModes;
  wasmModule = hooks.wasmModule;
  drawSpectrum = hooks.drawSpectrum;
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
  $('measure-view').addEventListener('change', () => {
    if ($('measure-view').value === 'fft' && !fft) requestFft();
    else draw();
  });
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
