// The simulated plant's editors (issue 23 item 2), fetched when a plant other than the modal
// one is first shown (web/editors.js, plantEditors).
//
// - The two-mass spring of Peláez & Singhose 2002 §3 (`{ kind: 'twoMass', baseMass, tipMass,
//   stiffness, dampingCoefficient }`, the library's `Plant::TwoMass`): its masses, spring and
//   damper, with the flexible mode they make (eq. 18). Driven by the command, both masses move
//   together (its rigid-body mode) and the tip rings around them.
// - The crane pendulum's gravity, initial angle and hoisting (`hoist`: the change of the cable
//   length over the move, a trapezoid in m, as the library's pendulum takes it).
// Bad values go to renderPlayground as they are; it names the field (`view.plant.tipMass`,
// `view.plant.hoist.maxVelocity`), the message shows there and the last good charts stay.
import { el, readNumber } from './dom.js';

const $ = (id) => document.getElementById(id);
const fmt = (x, d = 4) => (Number.isFinite(x) ? String(Number(x.toPrecision(d))) : '—');

const TWO_MASS = [
  ['baseMass', 'Base mass M₁ (kg, driven)'],
  ['tipMass', 'Tip mass M₂ (kg)'],
  ['stiffness', 'Spring stiffness K (N/m)'],
  ['dampingCoefficient', 'Damper c (N·s/m)'],
];
const PENDULUM = [['gravity', 'Gravity g (m/s²)'], ['initialAngle', 'Initial swing angle (rad)']];
const HOIST = [
  ['distance', 'Cable length change (m, − winds up)'],
  ['maxVelocity', 'Hoist speed (m/s)'],
  ['maxAcceleration', 'Hoist acceleration (m/s²)'],
  ['start', 'Hoist starts at (s)'],
];

/** A number box for `obj[name]` at data-field `path`; `after` runs after each edit. */
function box(obj, name, path, label, hooks, after = () => {}) {
  const id = `${path.replace(/[^A-Za-z0-9]+/g, '-')}`;
  const input = el('input', { id, type: 'number', step: 'any', inputmode: 'decimal', value: String(obj[name] ?? ''), dataset: { field: `${path}` } });
  input.addEventListener('input', () => {
    if (name === 'start' && input.value.trim() === '') delete obj[name];
    else obj[name] = readNumber(input);
    after();
    hooks.changed();
  });
  return hooks.field(label, input);
}

/** The two-mass spring's flexible mode in words (eq. 18, 2ζω = c(1/M₁ + 1/M₂)). */
function twoMassMode(p, r) {
  const w = Math.sqrt(p.stiffness * (p.baseMass + p.tipMass) / (p.baseMass * p.tipMass));
  const z = (p.dampingCoefficient ?? 0) * (1 / p.baseMass + 1 / p.tipMass) / (2 * w);
  return `Its flexible mode: f = √(K(M₁ + M₂)/(M₁M₂))/2π = ${fmt(w / (2 * Math.PI))} Hz, ζ = ${fmt(z, 3)}`
    + `${r !== 1 && Number.isFinite(r) ? `; simulated with K × r², so at ${fmt((r * w) / (2 * Math.PI))} Hz` : ''}. Both masses follow the command together (the rigid-body mode), the tip rings around them.`;
}

function plantFields(page, hooks) {
  const plant = page.state.view.plant;
  if (plant?.kind === 'twoMass') {
    const note = el('span', { class: 'hint', id: 'two-mass-mode' });
    const say = () => { note.textContent = twoMassMode(plant, page.state.view.mismatch); };
    say();
    return [...TWO_MASS.map(([n, l]) => box(plant, n, `view.plant.${n}`, l, hooks, say)), note];
  }
  if (plant?.kind !== 'pendulum') return [];
  const on = el('input', { id: 'hoist-on', type: 'checkbox' });
  on.checked = Boolean(plant.hoist);
  const fields = el('div', { id: 'hoist-fields', dataset: { fieldGroup: 'view.hoist' } });
  const show = () => {
    fields.replaceChildren(...(plant.hoist ? HOIST.map(([n, l]) => box(plant.hoist, n, `view.plant.hoist.${n}`, l, hooks)) : []),
      el('span', { class: 'error group-error', role: 'alert' }));
  };
  on.addEventListener('change', () => {
    if (on.checked) plant.hoist = { kind: 'trapezoid', distance: -3, maxVelocity: 0.5, maxAcceleration: 0.5 };
    else delete plant.hoist;
    show();
    hooks.changed(true);
  });
  show();
  return [...PENDULUM.map(([n, l]) => box(plant, n, `view.plant.${n}`, l, hooks)),
    el('div', { class: 'field' }, el('label', { for: 'hoist-on' }, on, ' Hoist during the move (the cable length changes)'), el('span', { class: 'error', role: 'alert' })),
    fields];
}

/** Builds the plant's fields. */
export function build(page, hooks) {
  $('plant-params').replaceChildren(...plantFields(page, hooks));
}
