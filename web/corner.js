// The printed corner (issue 23 item 3), the part in the page's first load: the panel's
// <details> and its state. Everything else — the fields, the table, the corner module that plans,
// simulates and draws — is web/corner_view.js, its own bundle with its own wasm module
// (pkg/page/corner.js), fetched when the panel is first opened, so the first load does not grow.
import { page } from './page.js';

const $ = (id) => document.getElementById(id);
let view = null; // the view's module, once imported

function openView() {
  view ??= import(new URL('./corner_view.js', import.meta.url).href).catch((e) => {
    view = null;
    $('corner-error').textContent = `Could not load the printed-corner view: ${e?.message ?? e}`;
    throw e;
  });
  return view;
}

/** Redraws the view if it is open (main.js calls this after every frame and state load). */
export function updateCorner() {
  const details = $('corner-panel');
  const open = !!page.state.corner?.open;
  if (details.open !== open) details.open = open;
  if (open) openView().then((m) => m.update(page), () => {});
}

/** Wires the panel: opening it puts `corner.open` in the state (and the URL). */
export function setupCorner() {
  $('corner-panel').addEventListener('toggle', () => {
    const open = $('corner-panel').open;
    if (!!page.state.corner?.open === open) return;
    page.state.corner = { ...(page.state.corner ?? {}), open };
    page.changed(true);
    if (open) openView().then((m) => m.update(page), () => {});
  });
  window.__corner = { open: openView };
}
