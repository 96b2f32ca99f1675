// The playground: one state object (page.js, state.js), editors built from it (editors.js),
// one call into wasm per frame (renderPlayground, below), and the numbers, tables and exports
// of the last good result (results.js); the solved families are designed off the main thread
// (designs.js). A bad value shows its message next to its field (matched by the error's `field`
// against the inputs' data-field) while the last good charts and numbers stay; with nothing
// good on screen yet (a link, a reload), a shaper that cannot be designed is left out instead
// (render). This file: the frame (update, render), the history (changed, the URL hash) and the
// start-up wiring (main).
import * as api from '../pkg/page/playground.js';
import { DEFAULT_STATE, PRESETS, MAX_MODES, checkState, clone, toHash, fromHash } from './state.js';
import { commandFor, parseParam } from './params.js';
import { setupMeasure } from './measure.js';
import { setupCorner, updateCorner } from './corner.js'; // corner (issue 23 item 3)
import { $, el, readNumber, notice, download } from './dom.js';
import { page } from './page.js';
import { rebuild, commandFields, clearErrors, showError, plantEditors } from './editors.js';
import { showResults, showExport } from './results.js';
import { updateRealisation, withoutRealise } from './realise.js'; // realisation (issue 23, item 1)
import { updateCommandView } from './command_load.js'; // profile and list commands (issue 23 item 2)
import { scheduler, QUIET_MS, designKey, holding, designerError, forgetFailedLoads, requestDesign, pump, compileModule } from './designs.js';

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
    if (resized && page.lastGood) schedule();
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
  // renderPlayground and the designs never see the shapers' realisations (web/realise.js).
  const st = { ...page.state, shapers: withoutRealise(page.state.shapers), view: { ...page.state.view, pixelRatio: window.devicePixelRatio || 1 } };
  try {
    const { result, kept, left, waiting, waitingKeys } = render(st, canvases);
    page.lastGood = { state: clone(page.state), result, left: left.map((l) => l.index), waiting };
    scheduler.holdSince = null;
    clearTimeout(scheduler.holdTimer);
    if (!waiting.length) scheduler.dragging = false;
    showResults(result, page.state, kept);
    // realisation (issue 23, item 1): the view of what each realised shaper's controller runs
    updateRealisation(page.state, result, kept, { showError, schedule, solvedFamilies: page.solvedFamilies });
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
      scheduler.holdSince = null;
      showError(error);
      // Nothing good to keep on screen (a link or a reload): say why the charts are empty.
      if (!page.lastGood && !$('general-error').textContent) $('general-error').textContent = `Nothing can be drawn until this is fixed: ${error?.message ?? error}`;
    }
  }
  updateCorner(); // corner (issue 23 item 3): redrawn only when its own inputs changed
  updateCommandView(page.state, api.drawSpectrum); // a profile's spectrum (issue 23 item 2)
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
    const since = scheduler.designs.get(keys[i])?.since;
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
  const sinceEdit = performance.now() - scheduler.lastEdit;
  const quiet = !scheduler.dragging || sinceEdit >= QUIET_MS;
  scheduler.awaitingQuiet = false;
  st.shapers.forEach((s, i) => {
    const known = scheduler.designs.get(keys[i]);
    if (known?.shaper && !quiet) {
      waiting.push(i);
      scheduler.awaitingQuiet = true;
    } else if (known?.pending || (!known && page.solvedFamilies.has(s.family))) waiting.push(i);
    else kept.push(i);
  });
  if (scheduler.awaitingQuiet) {
    clearTimeout(scheduler.quietTimer);
    scheduler.quietTimer = setTimeout(schedule, QUIET_MS - sinceEdit + 1);
  }
  const want = () => {
    scheduler.wantedKeys = new Set(waiting.map((i) => keys[i]));
    waiting.forEach((i) => requestDesign(keys[i], requests[i]));
    pump();
  };
  want();
  for (;;) {
    let error;
    let k = kept.find((i) => scheduler.designs.get(keys[i])?.error);
    if (k !== undefined) {
      error = designerError(scheduler.designs.get(keys[k]), k);
    } else {
      if (waiting.length && (!kept.length || holding())) throw Object.assign(new Error('designing'), { kind: 'designing', waiting, keys: waiting.map((i) => keys[i]) });
      const drawn = kept.length === st.shapers.length ? { ...st } : {
        ...st,
        shapers: kept.map((i) => st.shapers[i]),
        view: { ...st.view, mapShaper: Math.max(0, kept.indexOf(st.view.mapShaper ?? 0)), seriesColors: kept },
      };
      drawn.designed = kept.map((i) => scheduler.designs.get(keys[i])?.shaper ?? null);
      try {
        const result = api.renderPlayground(drawn, canvases);
        // What the worker's design brings along: a sampled shaper's cost report (bounds; issue 23
        // item 2), an si or direct shaper's solver report (`design`'s `solver`: polished or not).
        kept.forEach((i, j) => {
          const known = scheduler.designs.get(keys[i]);
          result.results[j].sampled ??= known?.report ?? null;
          result.results[j].solver = known?.shaper?.solver ?? null;
        });
        return { result, kept, left, waiting, waitingKeys: waiting.map((i) => keys[i]) };
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
    const mayLeave = k >= 0 && kept.length > 1 && (!page.lastGood || page.lastGood.left.length > 0 || page.lastGood.waiting.length > 0);
    if (!mayLeave) throw error;
    left.push({ index: k, error });
    kept = kept.filter((i) => i !== k);
  }
}

let frame = 0;
let editing = false;
/** Schedules one update for the next frame and records the state in the URL. */
function changed(commit = false) {
  forgetFailedLoads();
  scheduler.lastEdit = performance.now();
  const hash = toHash(page.state);
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
  page.state = next;
  rebuild();
  if (push) changed(true);
  else update();
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
  if (s && page.lastGood && JSON.stringify(s) === JSON.stringify(page.state)) return;
  loadState(s ?? clone(DEFAULT_STATE), { push: false });
}

async function main() {
  const wasmModule = await compileModule('playground_bg.wasm');
  await api.default({ module_or_path: wasmModule });
  page.changed = changed;
  page.schedule = schedule;
  page.families = api.families();
  page.solvedFamilies = new Set(page.families.filter((f) => f.solver === 'always').map((f) => f.name));
  $('preset').append(...PRESETS.map((p) => el('option', { value: p.id }, p.title)));
  $('preset').addEventListener('change', () => {
    const p = PRESETS.find((x) => x.id === $('preset').value);
    if (p) loadState(clone(p.state));
  });
  $('add-mode').addEventListener('click', () => {
    const last = page.state.modes[page.state.modes.length - 1];
    page.state.modes.push({ frequencyHz: Number(((last?.frequencyHz || 1) * 2.5).toPrecision(4)), damping: last?.damping ?? 0.02 });
    rebuild();
    changed(true);
  });
  $('add-shaper').addEventListener('click', () => {
    const used = new Set(page.state.shapers.map((s) => s.family));
    const next = page.families.find((f) => !used.has(f.name) && f.parameters.length === 0) ?? page.families[0];
    page.state.shapers.push({ family: next.name });
    rebuild();
    changed(true);
  });
  $('vtol').addEventListener('input', () => { page.state.view.vtol = parseParam({ kind: 'percent' }, $('vtol').value); changed(); });
  $('scv').addEventListener('input', () => { page.state.view.scv = readNumber($('scv')); changed(); });
  $('mismatch').addEventListener('input', () => {
    page.state.view.mismatch = readNumber($('mismatch'));
    if (Number.isFinite(page.state.view.mismatch)) $('mismatch-slider').value = String(page.state.view.mismatch);
    plantEditors();
    changed();
  });
  $('mismatch-slider').addEventListener('input', () => {
    $('mismatch').value = $('mismatch-slider').value;
    page.state.view.mismatch = Number($('mismatch-slider').value);
    plantEditors();
    changed();
  });
  $('plant-kind').addEventListener('change', () => {
    const kind = $('plant-kind').value;
    // A two-mass spring of 1 kg and 1 kg with mode 1's frequency and damping (web/plant_view.js).
    const w = 2 * Math.PI * (page.state.modes[0].frequencyHz || 1);
    page.state.view.plant = kind === 'pendulum' ? { kind, gravity: 9.81, initialAngle: 0 }
      : kind === 'twoMass' ? { kind, baseMass: 1, tipMass: 1, stiffness: +(w * w / 2).toPrecision(6), dampingCoefficient: +((page.state.modes[0].damping || 0) * w).toPrecision(6) } : { kind };
    plantEditors();
    changed(true);
  });
  $('command-kind').addEventListener('change', () => {
    page.state.view.command = commandFor($('command-kind').value, page.state.view.command, page.state.modes);
    $('command-params').replaceChildren(...commandFields());
    changed(true);
  });
  $('map-shaper').addEventListener('change', () => { page.state.view.mapShaper = Number($('map-shaper').value); changed(true); });
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
  $('save-state').addEventListener('click', () => download('input-shaping-state.json', JSON.stringify(page.state, null, 2)));
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
    acceptModes(modes) { page.state.modes = modes.slice(0, MAX_MODES); rebuild(); changed(true); },
  });
  setupCorner(); // corner (issue 23 item 3)
  // For the benchmark script: a full update, timed.
  window.__playground = { update, get state() { return page.state; } };
}

main().catch((error) => {
  $('general-error').textContent = `The page could not start: ${error?.message ?? error}`;
});
