// What your controller runs (issue 23, item 1), the part in the page's first load: the
// "Realised by" fields of each compared shaper's card, and the loader of the view. The view —
// `realizeShaper` and `drawRealisation` of the recording module, the chart and the table — is
// web/realise_view.js, its own bundle, fetched when a shaper is first realised by something
// other than the ideal controller, so the first load does not grow with it.
//
// State: `shapers[k].realise = { firmware, periodS?, amplitudeSteps?, maxImpulses? }`; absent
// (or firmware "ideal") is the design itself. renderPlayground never sees it (withoutRealise).
import { el, readNumber } from './dom.js';

/** The controllers, as `realizeShaper` names them, with the page's words. */
export const CONTROLLERS = [
  ['ideal', 'ideal (the design itself)'],
  ['klipper', 'Klipper'],
  ['kalico', 'Kalico'],
  ['rrf', 'RepRapFirmware 3.6'],
  ['marlin', 'Marlin, classic input shaping (ZV)'],
  ['marlinFtMotion', 'Marlin FT_MOTION'],
  ['prusa', 'Prusa (Buddy firmware)'],
  ['generic', 'generic controller (period T, steps N)'],
];

/** The numeric options each controller reads, with their labels and placeholders (defaults). */
const NUMBERS = {
  marlin: [['periodS', 'Timer tick (s)', '5e-7 (2 MHz)']],
  marlinFtMotion: [['periodS', 'Trajectory period (s)', '0.001']],
  generic: [
    ['periodS', 'Period T (s)', 'times kept'],
    ['amplitudeSteps', 'Amplitude steps N', 'kept'],
    ['maxImpulses', 'Most impulses', 'no cap'],
  ],
};

/** True when shaper `spec` is realised by a controller other than the ideal one. */
export const isRealised = (spec) => Boolean(spec?.realise?.firmware && spec.realise.firmware !== 'ideal');

/** The shaper specs without their realisation (what renderPlayground and the designs read). */
export const withoutRealise = (shapers) => shapers.map((s) => {
  if (!('realise' in s)) return s;
  const { realise, ...rest } = s;
  return rest;
});

/**
 * The "Realised by" fields of shaper card k: the controller, then its numbers. `field(label,
 * input)` wraps an input with its label and error slot (editors.js); `changed(commit)` records
 * the edit; `rebuild()` redraws the editors (the fields change with the controller).
 */
export function realiseFields(spec, k, { field, changed, rebuild }) {
  const r = spec.realise ?? {};
  const select = el('select', { id: `shaper-${k}-realise`, dataset: { field: `shapers[${k}].realise.firmware` } },
    ...CONTROLLERS.map(([v, t]) => el('option', { value: v }, t)));
  select.value = r.firmware ?? 'ideal';
  if (select.value !== (r.firmware ?? 'ideal')) {
    select.prepend(el('option', { value: r.firmware }, String(r.firmware)));
    select.value = r.firmware;
  }
  select.addEventListener('change', () => {
    if (select.value === 'ideal') delete spec.realise;
    else spec.realise = { firmware: select.value };
    rebuild();
    changed(true);
  });
  const numbers = (NUMBERS[r.firmware] ?? []).map(([name, label, placeholder]) => {
    const input = el('input', {
      id: `shaper-${k}-realise-${name}`, type: 'number', step: name === 'periodS' ? 'any' : '1', inputmode: 'decimal',
      placeholder, value: r[name] === undefined || r[name] === null ? '' : String(r[name]),
      dataset: { field: `shapers[${k}].realise.${name}` },
    });
    input.addEventListener('input', () => {
      // Blank: the controller's default. Anything else goes to realizeShaper, which says why a
      // value is wrong (the message shows here, the last good view stays).
      if (input.value.trim() === '' && !input.validity.badInput) delete spec.realise[name];
      else spec.realise[name] = readNumber(input);
      changed();
    });
    return field(label, input);
  });
  return [field('Realised by', select), ...numbers];
}

let view = null; // the view's module (a promise), once imported
let loaded = null; // the module itself, once there

/**
 * Updates the realisation view for the frame just drawn: `st` the state drawn (with the
 * realisations), `result` renderPlayground's, `kept` the shapers it drew (indices into
 * st.shapers). The first time a shaper is realised, fetches the view and schedules a frame once
 * it is there (`hooks.schedule`); with none realised, hides the view. Returns nothing; errors of
 * a realisation are shown with `hooks.showError` next to their field.
 */
export function updateRealisation(st, result, kept, hooks) {
  const any = st.shapers.some(isRealised);
  if (loaded) {
    loaded.update(st, result, kept, hooks);
    return;
  }
  const section = document.getElementById('realisation');
  if (!any) {
    if (section && !section.hidden) section.hidden = true;
    return;
  }
  view ??= import(new URL('./realise_view.js', import.meta.url).href).then(async (m) => {
    await m.ready();
    loaded = m;
    hooks.schedule();
    return m;
  }).catch((e) => {
    view = null;
    document.getElementById('general-error').textContent = `Could not load the realisation view: ${e?.message ?? e}`;
  });
}
