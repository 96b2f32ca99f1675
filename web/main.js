// The page: reads the controls, makes one call into wasm per update (renderPlayground), shows
// the numbers, and on a bad value shows the message next to its field while the last good
// charts and numbers stay.
import init, { renderPlayground, families } from '../pkg/input_shaping.js';

const $ = (id) => document.getElementById(id);

// Which input a core error's `field` belongs to.
const FIELD_INPUT = [
  [/^modes\[0\]\.frequencyHz/, 'frequency'],
  [/^modes\[0\]\.damping/, 'damping'],
  [/^(shaper\.)?derivatives/, 'derivatives'],
  [/^(shaper\.)?family|^shaper$/, 'family'],
  [/^view\.vtol|^(shaper\.)?vtol/, 'vtol'],
];

function readNumber(id) {
  const text = $(id).value.trim();
  return text === '' ? NaN : Number(text);
}

function readState() {
  const family = $('family').value;
  const shaper = { family };
  if (family === 'zvdn') shaper.derivatives = readNumber('derivatives');
  // EI-type families design their humps at the page's tolerable vibration.
  const info = familyTable.find((f) => f.name === family);
  if (info && info.parameters.includes('vtol')) shaper.vtol = readNumber('vtol') / 100;
  return {
    modes: [{ frequencyHz: readNumber('frequency'), damping: readNumber('damping') }],
    shaper,
    view: { vtol: readNumber('vtol') / 100, pixelRatio: window.devicePixelRatio || 1 },
  };
}

function sizeCanvas(canvas) {
  const ratio = window.devicePixelRatio || 1;
  const w = Math.max(1, Math.round(canvas.clientWidth * ratio));
  const h = Math.max(1, Math.round(canvas.clientHeight * ratio));
  if (canvas.width !== w || canvas.height !== h) {
    canvas.width = w;
    canvas.height = h;
  }
}

function clearErrors() {
  for (const el of document.querySelectorAll('.error')) el.textContent = '';
  for (const el of document.querySelectorAll('[aria-invalid]')) el.removeAttribute('aria-invalid');
}

function showError(error) {
  const field = error && typeof error.field === 'string' ? error.field : '';
  const message = error && error.message ? error.message : String(error);
  const match = FIELD_INPUT.find(([re]) => re.test(field));
  const id = match ? match[1] : null;
  if (id) {
    $(`${id}-error`).textContent = message;
    $(id).setAttribute('aria-invalid', 'true');
  } else {
    $('general-error').textContent = message;
  }
}

const fmt = (x, digits = 6) => (Number.isFinite(x) ? Number(x.toPrecision(digits)).toString() : '—');

function showNumbers(result, state) {
  const { shaper, insensitivity, centroidDelay } = result;
  $('duration').textContent = `${fmt(shaper.duration)} s`;
  $('delay').textContent = centroidDelay == null ? '—' : `${fmt(centroidDelay)} s`;
  const band = insensitivity[0];
  const vtolPct = fmt(state.view.vtol * 100, 4);
  $('insensitivity-label').textContent = `Insensitivity I(${vtolPct} %)`;
  $('insensitivity').textContent = fmt(band.width, 4);
  $('band').textContent = `${fmt(band.lowHz, 5)} – ${fmt(band.highHz, 5)} Hz`;
  const body = $('impulses').tBodies[0];
  body.replaceChildren(
    ...shaper.impulses.map((imp, i) => {
      const row = document.createElement('tr');
      for (const text of [String(i + 1), fmt(imp.time, 8), fmt(imp.amplitude, 8)]) {
        const td = document.createElement('td');
        td.textContent = text;
        row.append(td);
      }
      return row;
    }),
  );
}

function showOmega() {
  const f = readNumber('frequency');
  $('omega').textContent = Number.isFinite(f) ? `ω = ${fmt(2 * Math.PI * f, 5)} rad/s` : '';
}

function update() {
  clearErrors();
  showOmega();
  $('derivatives-field').hidden = $('family').value !== 'zvdn';
  const info = familyTable.find((f) => f.name === $('family').value);
  $('family-guarantee').textContent = info ? `${info.guarantee} (${info.source})` : '';
  const state = readState();
  const canvases = { impulses: $('impulses-chart'), sensitivity: $('sensitivity-chart') };
  Object.values(canvases).forEach(sizeCanvas);
  try {
    const result = renderPlayground(state, canvases);
    showNumbers(result, state);
    document.body.dataset.ready = 'true';
  } catch (error) {
    showError(error);
  }
}

// Keeps each slider and its number field in step.
function pair(sliderId, inputId) {
  $(sliderId).addEventListener('input', () => {
    $(inputId).value = $(sliderId).value;
    update();
  });
  $(inputId).addEventListener('input', () => {
    const v = readNumber(inputId);
    if (Number.isFinite(v)) $(sliderId).value = String(v);
    update();
  });
}

let familyTable = [];

async function main() {
  await init();
  // Only the families whose parameters this page has inputs for (the others — eihump,
  // bangbang, onoff, custom — need fields it does not show yet).
  const supported = new Set(['derivatives', 'vtol']);
  familyTable = families().filter((f) => f.parameters.every((p) => supported.has(p)));
  $('family').replaceChildren(
    ...familyTable.map((f) => {
      const option = document.createElement('option');
      option.value = f.name;
      option.textContent = f.title;
      return option;
    }),
  );
  $('family').value = 'zvd';
  pair('frequency-slider', 'frequency');
  pair('damping-slider', 'damping');
  for (const id of ['family', 'derivatives', 'vtol']) $(id).addEventListener('input', update);
  $('controls').addEventListener('submit', (e) => e.preventDefault());
  let resizeTimer;
  window.addEventListener('resize', () => {
    clearTimeout(resizeTimer);
    resizeTimer = setTimeout(update, 100);
  });
  update();
}

main().catch((error) => {
  $('general-error').textContent = `The page could not start: ${error.message ?? error}`;
});
