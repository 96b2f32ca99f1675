// The editors: the modes, the compared shapers (their parameters from the family table,
// `families()`), the command's fields, and the error messages shown next to them. They edit
// `page.state` and call `page.changed()`.
import { $, el, fmt, readNumber, COLORS } from './dom.js';
import { page } from './page.js';
import { MAX_MODES, MAX_SHAPERS } from './state.js';
import { COMMAND_PARAMS, parseParam, formatParam } from './params.js';
import { realiseFields } from './realise.js'; // realisation (issue 23, item 1)
import { LAZY_COMMANDS, lazyCommandFields } from './command_load.js'; // profile and list commands (issue 23 item 2)

// Frequency sliders are logarithmic: 0.01 Hz … 1 kHz over 0 … 1000.
const F_MIN = 0.01;
const F_DECADES = 5;
const sliderToHz = (v) => F_MIN * 10 ** ((F_DECADES * v) / 1000);
const hzToSlider = (f) => Math.min(1000, Math.max(0, (1000 * Math.log10(f / F_MIN)) / F_DECADES));

function field(labelText, input, extra = null) {
  const id = input.id;
  return el('div', { class: 'field' }, el('label', { for: id }, labelText), extra ?? input, el('span', { class: 'error', role: 'alert' }));
}

function modeRow(mode, i) {
  const f = el('input', { id: `mode-${i}-frequency`, type: 'number', step: 'any', value: String(mode.frequencyHz ?? ''), dataset: { field: `modes[${i}].frequencyHz` }, inputmode: 'decimal' });
  const fSlider = el('input', { type: 'range', min: '0', max: '1000', step: '1', 'aria-label': `Mode ${i + 1} frequency (logarithmic slider)` });
  const z = el('input', { id: `mode-${i}-damping`, type: 'number', step: 'any', value: String(mode.damping ?? ''), dataset: { field: `modes[${i}].damping` }, inputmode: 'decimal' });
  const zSlider = el('input', { type: 'range', min: '0', max: '0.5', step: '0.001', 'aria-label': `Mode ${i + 1} damping ratio slider` });
  const omega = el('output', { for: f.id, class: 'hint' });
  const syncSliders = () => {
    const fv = readNumber(f);
    if (Number.isFinite(fv) && fv > 0) fSlider.value = String(hzToSlider(fv));
    const zv = readNumber(z);
    if (Number.isFinite(zv)) zSlider.value = String(zv);
    omega.textContent = Number.isFinite(fv) ? `ω = ${fmt(2 * Math.PI * fv, 5)} rad/s` : '';
  };
  syncSliders();
  f.addEventListener('input', () => { page.state.modes[i].frequencyHz = readNumber(f); syncSliders(); page.changed(); });
  z.addEventListener('input', () => { page.state.modes[i].damping = readNumber(z); syncSliders(); page.changed(); });
  fSlider.addEventListener('input', () => {
    const hz = Number(sliderToHz(Number(fSlider.value)).toPrecision(4));
    f.value = String(hz);
    page.state.modes[i].frequencyHz = hz;
    syncSliders();
    page.changed();
  });
  zSlider.addEventListener('input', () => { z.value = zSlider.value; page.state.modes[i].damping = Number(zSlider.value); syncSliders(); page.changed(); });
  const remove = el('button', { type: 'button', class: 'remove', 'aria-label': `Remove mode ${i + 1}`, disabled: page.state.modes.length <= 1 }, '×');
  remove.addEventListener('click', () => {
    page.state.modes.splice(i, 1);
    for (const key of PER_MODE) if (page.state.view[key]) setEntries(key, page.state.view[key].filter((_, j) => j !== i));
    rebuild();
    page.changed(true);
  });
  return el('div', { class: 'card mode', dataset: { fieldGroup: `modes[${i}]` } },
    el('div', { class: 'card-head' }, el('strong', {}, `Mode ${i + 1}`), remove),
    field('Frequency (Hz)', f, el('div', { class: 'pair' }, fSlider, f)),
    omega,
    field('Damping ratio ζ', z, el('div', { class: 'pair' }, zSlider, z)));
}

function shaperCard(spec, k) {
  const family = el('select', { id: `shaper-${k}-family`, dataset: { field: `shapers[${k}].family` } },
    ...page.families.map((f) => el('option', { value: f.name }, f.title)));
  family.value = spec.family;
  if (family.value !== spec.family) {
    family.prepend(el('option', { value: spec.family }, spec.family));
    family.value = spec.family;
  }
  const info = page.families.find((f) => f.name === spec.family);
  family.addEventListener('change', () => {
    const next = { family: family.value };
    const nextInfo = page.families.find((f) => f.name === family.value);
    for (const p of nextInfo?.params ?? []) {
      if (p.default !== undefined) next[p.name] = structuredClone(p.default);
    }
    page.state.shapers[k] = next;
    rebuild();
    page.changed(true);
  });
  const params = (info?.params ?? []).map((pinfo) => {
    const { name } = pinfo;
    if (!(name in spec) && pinfo.default !== undefined && !pinfo.optional) spec[name] = structuredClone(pinfo.default);
    let input;
    if (pinfo.kind === 'select' || pinfo.kind === 'boolean') {
      const options = pinfo.kind === 'boolean' ? ['false', 'true'] : pinfo.options;
      input = el('select', { id: `shaper-${k}-${name}`, dataset: { field: `shapers[${k}].${name}` } },
        ...options.map((o) => el('option', { value: o }, pinfo.kind === 'boolean' ? (o === 'true' ? 'yes' : 'no') : o)));
      input.value = formatParam(pinfo, spec[name]);
    } else if (pinfo.kind === 'pairs' || pinfo.kind === 'points') {
      input = el('textarea', { id: `shaper-${k}-${name}`, rows: '4', dataset: { field: `shapers[${k}].${name}` } });
      input.value = formatParam(pinfo, spec[name]);
    } else {
      input = el('input', {
        id: `shaper-${k}-${name}`, type: pinfo.kind === 'numbers' ? 'text' : 'number', step: pinfo.kind === 'integer' ? '1' : 'any',
        value: formatParam(pinfo, spec[name]), dataset: { field: `shapers[${k}].${name}` },
      });
      // The limits are in the spec's units: a percent field shows them in %.
      const shown = (x) => formatParam(pinfo.kind === 'percent' ? pinfo : { kind: 'number' }, x);
      if (pinfo.min !== undefined) input.min = shown(pinfo.min);
      if (pinfo.max !== undefined) input.max = shown(pinfo.max);
    }
    input.addEventListener('input', () => {
      const v = parseParam(pinfo, input.value);
      if (v === undefined) delete spec[name];
      else spec[name] = v;
      page.changed();
    });
    return field(pinfo.label, input);
  });
  const remove = el('button', { type: 'button', class: 'remove', 'aria-label': `Remove shaper ${k + 1}`, disabled: page.state.shapers.length <= 1 }, '×');
  remove.addEventListener('click', () => { page.state.shapers.splice(k, 1); rebuild(); page.changed(true); });
  return el('div', { class: 'card shaper', dataset: { fieldGroup: `shapers[${k}]` } },
    el('div', { class: 'card-head' }, el('span', { class: 'swatch', style: `background:${COLORS[k]}` }), el('strong', {}, `Shaper ${k + 1}`), remove),
    field('Family', family),
    el('span', { class: 'hint' }, info ? `${info.guarantee}. ${info.source}` : ''),
    ...params,
    ...realiseFields(spec, k, { field, changed: (c) => page.changed(c), rebuild }), // realisation (issue 23, item 1)
    el('span', { class: 'error group-error', role: 'alert' }));
}

/** The command's parameter fields, for its kind (a profile's and a list's come with their
 * view, web/command_view.js, fetched when first needed). */
export function commandFields() {
  const command = page.state.view.command;
  if (LAZY_COMMANDS.includes(command.kind)) return lazyCommandFields(command, { field, changed: (c) => page.changed(c) });
  return (COMMAND_PARAMS[command.kind] ?? []).map(([name, label]) => {
    const input = el('input', {
      id: `command-${name}`, type: 'number', step: 'any', inputmode: 'decimal',
      value: String(command[name] ?? ''), dataset: { field: `view.command.${name}` },
    });
    input.addEventListener('input', () => { page.state.view.command[name] = readNumber(input); page.changed(); });
    return field(label, input);
  });
}

// ---------- mismatch per mode and in damping (issue 23 item 2) ----------
/** `view.modeMismatch[i]` (rᵢ, default 1) and `view.actualDamping[i]` (default null: the model's). */
const PER_MODE = ['modeMismatch', 'actualDamping'];
const DEFAULTS = { modeMismatch: 1, actualDamping: null };

/** Sets `view[key]` to `list` without its trailing defaults (none left: no key, the plain ratio). */
function setEntries(key, list) {
  const out = [...list];
  while (out.length && (out[out.length - 1] ?? null) === DEFAULTS[key]) out.pop();
  if (out.length) page.state.view[key] = out;
  else delete page.state.view[key];
}

/** One row per mode: its own ratio rᵢ and its actual damping ratio (blank: the defaults). */
function modeMismatchRows() {
  const view = page.state.view;
  const box = (key, i) => {
    const v = view[key]?.[i];
    const input = el('input', {
      id: `${key}-${i}`, type: 'number', step: 'any', inputmode: 'decimal', placeholder: key === 'modeMismatch' ? '1' : 'model’s',
      value: v == null || v === DEFAULTS[key] ? '' : String(v), dataset: { field: `view.${key}[${i}]` },
    });
    input.addEventListener('input', () => {
      const list = [...(page.state.view[key] ?? [])];
      while (list.length <= i) list.push(DEFAULTS[key]);
      list[i] = input.value.trim() === '' ? DEFAULTS[key] : readNumber(input);
      setEntries(key, list);
      page.changed();
    });
    return input;
  };
  $('mode-mismatch').replaceChildren(...page.state.modes.map((_, i) => el('div', { class: 'pair' },
    field(`Mode ${i + 1}: rᵢ`, box('modeMismatch', i)), field(`Mode ${i + 1}: actual ζ`, box('actualDamping', i)))));
  if (PER_MODE.some((k) => view[k])) $('mode-mismatch-group').open = true;
}

// The plant's fields (issue 23 item 2): web/plant_view.js, fetched when a plant other than the
// modal one is first shown.
let plantView = null;
export function plantEditors() {
  if (page.state.view.plant?.kind === 'modal') {
    $('plant-params').replaceChildren();
    return;
  }
  (plantView ??= import(new URL('./plant_view.js', import.meta.url).href)).then((m) => m.build(page, { field, changed: (c) => page.changed(c) }), (e) => {
    plantView = null;
    $('general-error').textContent = `Could not load the plant editor: ${e?.message ?? e}`;
  });
}

function mapShaperOptions() {
  const sel = $('map-shaper');
  sel.replaceChildren(...page.state.shapers.map((s, k) => el('option', { value: String(k) },
    `Shaper ${k + 1}: ${page.families.find((f) => f.name === s.family)?.title ?? s.family}`)));
  if (!(page.state.view.mapShaper < page.state.shapers.length)) page.state.view.mapShaper = 0;
  sel.value = String(page.state.view.mapShaper ?? 0);
}

export function rebuild() {
  $('modes').replaceChildren(...page.state.modes.map(modeRow));
  $('shapers').replaceChildren(...page.state.shapers.map(shaperCard));
  $('add-mode').disabled = page.state.modes.length >= MAX_MODES;
  $('add-shaper').disabled = page.state.shapers.length >= MAX_SHAPERS;
  $('vtol').value = formatParam({ kind: 'percent' }, page.state.view.vtol);
  $('scv').value = String(page.state.view.scv ?? '');
  $('mismatch').value = String(page.state.view.mismatch ?? '');
  if (Number.isFinite(page.state.view.mismatch)) $('mismatch-slider').value = String(page.state.view.mismatch);
  modeMismatchRows();
  $('plant-kind').value = page.state.view.plant?.kind ?? 'modal';
  plantEditors();
  $('command-kind').value = page.state.view.command?.kind ?? 'step';
  $('command-params').replaceChildren(...commandFields());
  mapShaperOptions();
}

// ---------- errors ----------
export function clearErrors() {
  // Only the messages that are showing: writing even an empty text makes the browser lay the
  // page out again, on every input event.
  for (const e of document.querySelectorAll('#controls .error')) if (e.textContent) e.textContent = '';
  for (const e of document.querySelectorAll('[aria-invalid]')) e.removeAttribute('aria-invalid');
  if ($('general-error').textContent) $('general-error').textContent = '';
}

/** Shows a core error next to the input it names (or the closest group), else on top. */
export function showError(error) {
  const message = error?.message ?? String(error);
  let path = typeof error?.field === 'string' ? error.field : '';
  while (path) {
    const input = document.querySelector(`[data-field="${CSS.escape(path)}"]`);
    if (input) {
      input.setAttribute('aria-invalid', 'true');
      input.closest('.field').querySelector('.error').textContent = message;
      return;
    }
    const group = document.querySelector(`[data-field-group="${CSS.escape(path)}"]`);
    if (group) {
      group.querySelector('.group-error, .error').textContent = message;
      return;
    }
    const parent = path.replace(/(\.[^.[\]]*|\[\d+\])$/, '');
    // A top-level name ("view") has no parent: stop rather than loop on it.
    path = parent === path ? '' : parent;
  }
  $('general-error').textContent = message;
}
