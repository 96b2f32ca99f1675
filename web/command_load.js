// Profile and list commands (issue 23 item 2), the part in the page's first load: which command
// kinds web/command_view.js edits, and its loader. That view — the fields of Veciana &
// Cardona's profiles and of a typed or pasted list, and the profile's spectrum with its zeros
// (`profileSpectrum` of the recording module) — is its own bundle, fetched when a
// command of those kinds is first shown, so the first load does not grow with it.
import { page } from './page.js';

/** The command kinds whose fields web/command_view.js builds. */
export const LAZY_COMMANDS = ['profile', 'sampled'];

let view = null; // the module (a promise), once imported
let loaded = null; // the module itself, once there
let draw = null; // the playground module's drawSpectrum, from the last update

function load() {
  view ??= import(new URL('./command_view.js', import.meta.url).href).then((m) => {
    loaded = m;
    if (draw) m.update(page.state, draw);
    return m;
  }).catch((e) => {
    view = null;
    document.getElementById('general-error').textContent = `Could not load the command editor: ${e?.message ?? e}`;
  });
  return view;
}

/**
 * The fields of `command` (a LAZY_COMMANDS kind): now if the view is there, else none now and
 * the fields (and the view) once it is. `hooks = { field, changed }` (web/editors.js).
 */
export function lazyCommandFields(command, hooks) {
  if (loaded) return loaded.fields(command, hooks);
  load().then((m) => {
    const c = page.state.view.command;
    if (!m || !LAZY_COMMANDS.includes(c?.kind)) return;
    document.getElementById('command-params').replaceChildren(...m.fields(c, hooks));
  });
  return [];
}

/** Updates the profile's spectrum view after a frame (`drawSpectrum` the playground module's). */
export function updateCommandView(state, drawSpectrum) {
  draw = drawSpectrum;
  if (loaded) loaded.update(state, drawSpectrum);
  else if (LAZY_COMMANDS.includes(state.view.command?.kind)) load();
}
