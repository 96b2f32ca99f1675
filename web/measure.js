// Measured data (issues 7 and 20), the part in the page's first load: the "I have a recording"
// entry at the top, the drop zone and the file input. Everything else — the worker, the
// recording module (which draws the Klipper-style charts), the tables — is in
// web/measure_view.js, its own bundle, fetched when the path is first opened (the button, a
// file chosen or dropped), so the page's first load does not grow with it.

const $ = (id) => document.getElementById(id);
let view = null; // the measured-data view's module, once imported
let hooks = null;

/** The view, imported once (bundled: pkg/page/measure_view.js, beside this bundle). */
function openView() {
  view ??= import(new URL('./measure_view.js', import.meta.url).href).then((m) => {
    m.setupView(hooks);
    return m;
  }).catch((e) => {
    view = null;
    $('measure-error').textContent = `Could not load the measured-data view: ${e?.message ?? e}`;
    throw e;
  });
  return view;
}

function load(files) {
  const list = [...files];
  if (list.length) openView().then((m) => m.load(list), () => {});
}

/** Shows the measured-data path first and scrolls to it. */
function openPath() {
  document.body.dataset.path = 'recording';
  $('measure').scrollIntoView({ behavior: 'smooth', block: 'start' });
  $('measure-drop').focus({ preventScroll: true });
  openView().catch(() => {});
}

/**
 * Wires the section; `h.acceptModes(modes)` puts modes into the playground's editor,
 * `h.wasmModule` is the page's compiled module without the solver (the worker ranks shapers
 * with it; null: the worker fetches it), `h.drawSpectrum` draws with the page's module in use.
 */
export function setupMeasure(h) {
  hooks = h;
  const input = $('measure-file');
  input.addEventListener('change', () => {
    const files = [...input.files];
    input.value = '';
    load(files);
  });
  const drop = $('measure-drop');
  drop.addEventListener('dragover', (e) => { e.preventDefault(); drop.classList.add('over'); });
  drop.addEventListener('dragleave', () => drop.classList.remove('over'));
  drop.addEventListener('drop', (e) => {
    e.preventDefault();
    drop.classList.remove('over');
    load(e.dataTransfer?.files ?? []);
  });
  drop.addEventListener('keydown', (e) => { if (e.key === 'Enter' || e.key === ' ') { e.preventDefault(); input.click(); } });
  $('open-recording').addEventListener('click', openPath);
  window.__measure = { load: (files) => load(Array.isArray(files) ? files : [files]), open: openView };
}
