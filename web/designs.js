// The design scheduler: solved designs, off the main thread. Its requests, answers and timers
// are kept in one object, `scheduler`; main.js's render() asks it what a frame waits for.
import { page } from './page.js';

// The design worker (web/design_worker.js) designs one shaper at a time with the designer
// module (`design` and the optimisation solver), compiled here once, when the first solved
// shaper is asked for. Its answers are kept by request (the shaper's spec with the modes, as
// JSON) for as long as a state may come back to them (back/forward, undoing an edit). A design
// that the state on screen no longer asks for is stopped, by ending the worker, once it has run
// for STALE_MS (a quick one is left to finish: starting a worker costs more than it saves).
export const HOLD_MS = 250;
const STALE_MS = 300;
export const QUIET_MS = 150;
const KEPT_DESIGNS = 64;
/** Everything the scheduler keeps, in one object. */
export const scheduler = {
  /** key → { pending: true, request, since } | { shaper, report? (a sampled shaper's cost) } | { error, retry? } */
  designs: new Map(),
  /** The keys the last frame waited for. */
  wantedKeys: new Set(),
  /** The promise of the compiled designer module. */
  designerModule: null,
  /** { worker, ready, key: the design running or null, since, id } */
  designer: null,
  /** The id of the last design asked of the worker. */
  designId: 0,
  staleTimer: 0,
  /** When the frame on screen began to be held for a design (-Infinity: stop). */
  holdSince: null,
  holdTimer: 0,
  // A drag: a design came back for a state the page had already left. Until a frame draws every
  // shaper again, solved shapers stay out while edits keep coming (QUIET_MS apart at most), so
  // they do not blink in and out of the charts whenever a design happens to keep up.
  dragging: false,
  /** When the state was last edited (performance.now()). */
  lastEdit: -Infinity,
  /** The last frame left a designed shaper out for the drag. */
  awaitingQuiet: false,
  quietTimer: 0,
};

/** A design request's key in `designs`: `design`'s spec ({ …shaper, modes }) as JSON. */
export const designKey = (request) => JSON.stringify(request);

/** Whether to keep the last good charts while a design is on its way (see main.js, render). */
export function holding() {
  if (!page.lastGood || page.lastGood.waiting.length) return false;
  scheduler.holdSince ??= performance.now();
  const left = HOLD_MS - (performance.now() - scheduler.holdSince);
  if (left <= 0) return false;
  clearTimeout(scheduler.holdTimer);
  scheduler.holdTimer = setTimeout(page.schedule, left);
  return true;
}

/** The design worker's error for shaper `k`, named to it (`shapers[k].…`). */
export function designerError({ error }, k) {
  const at = `shapers[${k}]`;
  const f = typeof error.field === 'string' ? error.field : '';
  const field = !f ? at : f.startsWith('[') ? at + f : `${at}.${f}`;
  const message = f && error.message.startsWith(f) ? field + error.message.slice(f.length) : `${at}: ${error.message}`;
  return { kind: error.kind, field, message };
}

/** After an edit, a design whose solver could not be loaded is asked for again. */
export function forgetFailedLoads() {
  for (const [k, v] of scheduler.designs) if (v.retry) scheduler.designs.delete(k);
}

export function requestDesign(key, request) {
  if (scheduler.designs.has(key)) return;
  scheduler.designs.set(key, { pending: true, request, since: performance.now() });
  // Keep the cache bounded: drop the oldest answers first.
  if (scheduler.designs.size > KEPT_DESIGNS) {
    for (const [k, v] of scheduler.designs) {
      if (scheduler.designs.size <= KEPT_DESIGNS) break;
      if (!v.pending) scheduler.designs.delete(k);
    }
  }
}

/** Starts the next wanted design if the worker is free; stops one nobody wants any more. */
export function pump() {
  // Requests no frame waits for any more are forgotten (asked again if their state comes back).
  for (const [k, v] of scheduler.designs) if (v.pending && !scheduler.wantedKeys.has(k) && scheduler.designer?.key !== k) scheduler.designs.delete(k);
  if (scheduler.designer?.key && !scheduler.wantedKeys.has(scheduler.designer.key)) {
    const age = performance.now() - scheduler.designer.since;
    if (age >= STALE_MS) {
      scheduler.designer.worker.terminate();
      scheduler.designs.delete(scheduler.designer.key);
      scheduler.designer = null;
    } else {
      clearTimeout(scheduler.staleTimer);
      scheduler.staleTimer = setTimeout(pump, STALE_MS - age + 1);
    }
  }
  const next = [...scheduler.wantedKeys].find((k) => scheduler.designs.get(k)?.pending && scheduler.designer?.key !== k);
  if (next && !scheduler.designer?.key) runDesign(next);
  if (scheduler.awaitingQuiet || [...scheduler.wantedKeys].some((k) => scheduler.designs.get(k)?.pending)) document.body.dataset.fetching = 'designs'; // for the tests
  else delete document.body.dataset.fetching;
}

function runDesign(key) {
  scheduler.designerModule ??= compileModule('designer_bg.wasm');
  if (!scheduler.designer) {
    const worker = new Worker(new URL('./design_worker.js', import.meta.url), { type: 'module' });
    const ready = scheduler.designerModule.then((module) => {
      try {
        worker.postMessage({ module });
      } catch {
        worker.postMessage({ module: null }); // not cloneable here: the worker fetches it
      }
    });
    scheduler.designer = { worker, ready, key: null, since: 0 };
    const mine = scheduler.designer;
    worker.addEventListener('message', ({ data }) => answered(mine, data));
    worker.addEventListener('error', (e) => answered(mine, { id: mine.id, error: { kind: 'load', message: `The design worker failed (${e.message ?? e})` } }));
  }
  const d = scheduler.designer;
  d.key = key;
  d.id = ++scheduler.designId;
  d.since = performance.now();
  const { request } = scheduler.designs.get(key);
  d.ready.then(() => d.worker.postMessage({ id: d.id, request }), (e) => {
    scheduler.designerModule = null; // the next request tries again
    answered(d, { id: d.id, error: { kind: 'load', message: `The optimisation solver could not be loaded (${e?.message ?? e})` } });
  });
}

/** The worker's answer: kept, the next design started and the page redrawn with it. */
function answered(d, { id, shaper, report, error }) {
  if (d !== scheduler.designer || id !== d.id || !d.key) return; // from a worker since ended, or late
  // A design back for a state already left (a slider being dragged, the next step not drawn
  // yet): holding the charts for each next one would make the whole page follow the drag at
  // the designs' pace, so the others draw now, without the solved shaper.
  const current = page.state.shapers.some((s) => designKey({ ...s, modes: page.state.modes }) === d.key);
  if (!current) {
    scheduler.dragging = true;
    if (scheduler.holdSince !== null) scheduler.holdSince = -Infinity;
  }
  const failedToLoad = error?.kind === 'load';
  // An error without a kind is a trap (the core's errors all have one): the module may be
  // left in a bad state, so the next design starts a fresh worker.
  const trapped = error && !error.kind;
  scheduler.designs.set(d.key, shaper ? { shaper, report } : { error, retry: failedToLoad || trapped });
  d.key = null;
  if (failedToLoad || trapped) {
    d.worker.terminate();
    scheduler.designer = null;
  }
  pump();
  page.schedule();
}

/**
 * A wasm module of the page, compiled. The page's is instantiated here and handed to the
 * measured-data worker, which ranks shapers with it without fetching or compiling it again; the
 * designer module is handed to the design worker. This file runs as the bundle
 * pkg/page/main.js (scripts/bundle.sh), beside the .wasm files, as the glue inside it does.
 */
export async function compileModule(file) {
  const response = await fetch(new URL(file, import.meta.url));
  if (!response.ok) throw new Error(`could not load the wasm module (HTTP ${response.status})`);
  try {
    return await WebAssembly.compileStreaming(response.clone());
  } catch {
    // Served without the application/wasm MIME type: compile from the bytes.
    return WebAssembly.compile(await response.arrayBuffer());
  }
}
