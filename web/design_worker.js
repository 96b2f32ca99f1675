// The design worker: designs the solved families (si, direct, and sampled with an active
// amplitude or increment bound) off the page's main thread, with the module that carries the
// optimisation solver (pkg/page/designer.js: the `design` export and the solver, nothing
// else). A design that takes seconds never freezes the page, and the page stops one that no
// state needs any more by ending this worker (web/main.js, "Solved designs").
// Messages in: { module } first (the designer module, compiled by the page; null: fetch it
// here), then { id, request } (`design`'s spec: { family, modes, …parameters }). Out:
// { id, shaper } (as `design` returns it; a sampled shaper with `report`, its cost report as
// `sampledReport` gives it) or { id, error: { kind, field, message } }.
import init, { design, sampledReport } from '../pkg/page/designer.js';

let ready = null;
self.onmessage = async ({ data }) => {
  if ('module' in data) {
    ready = init(data.module ? { module_or_path: data.module } : undefined);
    return;
  }
  const { id, request } = data;
  try {
    await ready;
  } catch (e) {
    postMessage({ id, error: { kind: 'load', message: `The optimisation solver could not be loaded (${e?.message ?? e})` } });
    return;
  }
  try {
    if (request?.family === 'sampled') {
      // The design and its cost against the minimum-norm shaper (issue 23 item 2), in one call.
      const { impulses, duration, ...report } = sampledReport(request);
      postMessage({ id, shaper: { impulses, duration }, report });
    } else {
      postMessage({ id, shaper: design(request) });
    }
  } catch (e) {
    postMessage({ id, error: { kind: e?.kind, field: e?.field, message: e?.message ?? String(e) } });
  }
};
