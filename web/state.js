// The page's whole state as one JSON object, its presets, and its home in the URL hash.
//
// state = {
//   modes:   [{ frequencyHz, damping }]          1 … 6
//   shapers: [{ family, …parameters,              1 … 4
//               realise? }]                       the controller that runs it (web/realise.js)
//   view:    { vtol, scv,                        analysis
//              mismatch,                         simulation: actual frequency = model × mismatch
//              command: { kind: 'step' | 'trapezoid' | 'sCurve', distance, maxVelocity?,
//                         maxAcceleration?, maxJerk? }
//                     | { kind: 'profile', shape, frequencyHz? | modesHz?, deltaHz?, commonHz?,
//                         distance, duration }         Veciana & Cardona's profiles
//                     | { kind: 'sampled', samplePeriod, values: [], interpolation }
//                                                      a list (web/command_view.js),
//              plant: { kind: 'modal' }
//                   | { kind: 'twoMass', baseMass, tipMass, stiffness, dampingCoefficient? }
//                   | { kind: 'pendulum', gravity?, initialAngle?, hoist?: a command (m) },
//              mapShaper }                       which shaper the frequency × damping map shows
//   corner?: { open, path: 'square' | 'ringingTower', sideMm, velocity, accel, scv, magnify,
//              x: [{ frequencyHz, damping }], y: […] }   the printed-corner panel (web/corner_view.js)
// }

export const MAX_MODES = 6;
export const MAX_SHAPERS = 4;

export const COMMAND_KINDS = ['step', 'trapezoid', 'sCurve', 'profile', 'sampled'];
export const PLANT_KINDS = ['modal', 'twoMass', 'pendulum'];
/** The command fields that hold a name, and those that hold a list of numbers. */
const NAME_FIELDS = ['shape', 'interpolation'];
const LIST_FIELDS = ['values', 'modesHz'];

/** A view with the simulation defaults and the given command. */
const view = (command, extra = {}) => ({
  vtol: 0.05, scv: 5, mismatch: 1, command, plant: { kind: 'modal' }, mapShaper: 0, ...extra,
});
const trapezoid = (distance, maxVelocity, maxAcceleration) => ({ kind: 'trapezoid', distance, maxVelocity, maxAcceleration });

export const DEFAULT_STATE = {
  modes: [{ frequencyHz: 2, damping: 0.05 }],
  shapers: [{ family: 'zvd' }],
  view: view(trapezoid(1, 0.75, 8)),
};

/** Presets from the papers (and one printer axis). */
export const PRESETS = [
  {
    id: 'singer-seering',
    title: 'Singer & Seering 1988: one lightly damped mode (ZV, ZVD, ZVDD)',
    state: {
      modes: [{ frequencyHz: 1, damping: 0.05 }],
      shapers: [{ family: 'zv' }, { family: 'zvd' }, { family: 'zvdd' }],
      view: view({ kind: 'step', distance: 1 }),
    },
  },
  {
    id: 'veciana',
    title: 'Veciana & Cardona 2011 test bed: 1.2 Hz and 3.4 Hz',
    state: {
      modes: [{ frequencyHz: 1.2, damping: 0.012 }, { frequencyHz: 3.4, damping: 0.013 }],
      shapers: [{ family: 'zv' }, { family: 'zvd' }],
      view: view({ kind: 'sCurve', distance: 0.5, maxVelocity: 0.5, maxAcceleration: 2, maxJerk: 20 }),
    },
  },
  {
    id: 'kamel',
    title: 'Kamel, Lange & Hirzinger: robot joint, ω = 30 rad/s, ζ = 0.02, T = 12 ms',
    state: {
      modes: [{ frequencyHz: 30 / (2 * Math.PI), damping: 0.02 }],
      shapers: [
        { family: 'sampled', periodS: 0.012, impulses: 36, delaySamples: 17, weight: 0.1, derivatives: 1, plantGain: 8e-4, objective: 'controlError' },
        { family: 'sampled', periodS: 0.012, impulses: 36, delaySamples: 17, weight: 0.1, derivatives: 1, plantGain: 8e-4, objective: 'minimumNorm' },
        { family: 'zvd' },
      ],
      view: view(trapezoid(1, 1, 5)),
    },
  },
  {
    id: 'pelaez',
    title: 'Peláez & Singhose 2002: 0.5 Hz, ζ = 0.002, SI with I = 0.7 at 5 % vs ZVD and EI',
    state: {
      modes: [{ frequencyHz: 0.5, damping: 0.002 }],
      shapers: [{ family: 'si', vtol: 0.05, insensitivity: 0.7 }, { family: 'zvd' }, { family: 'ei', vtol: 0.05 }],
      view: view(trapezoid(1, 0.5, 0.5), { mismatch: 1.2 }),
    },
  },
  {
    id: 'multimode',
    title: 'Two modes, 1 Hz and 2.7 Hz: direct multi-mode ZVD vs convolved ZVD and SI',
    state: {
      modes: [{ frequencyHz: 1, damping: 0.02 }, { frequencyHz: 2.7, damping: 0.02 }],
      shapers: [{ family: 'direct', derivatives: 1 }, { family: 'zvd' }, { family: 'si', vtol: 0.05, insensitivity: 0.3 }],
      view: view(trapezoid(1, 1, 8)),
    },
  },
  {
    id: 'crane',
    title: 'Overhead crane: 6.2 m cable (0.2 Hz), nonlinear pendulum, 4 m move',
    state: {
      // ω = √(g/ℓ): 0.2 Hz is a 6.21 m cable; the simulation swings the nonlinear pendulum.
      modes: [{ frequencyHz: 0.2, damping: 0 }],
      shapers: [{ family: 'zv' }, { family: 'zvd' }, { family: 'ei', vtol: 0.05 }],
      view: view(trapezoid(4, 1, 2), { plant: { kind: 'pendulum', gravity: 9.81, initialAngle: 0 } }),
    },
  },
  // ---- command presets (issue 23 item 2): web/command_view.js ----
  {
    id: 'veciana-profile',
    title: 'Veciana & Cardona 2011: a multi-mode pulse-convolution profile for 1.2 Hz and 3.4 Hz (zeros at both modes)',
    state: {
      // §2.4, Fig. 10: one pulse of 1/1.2 s and one of 1/3.4 s, and a final pulse to 2 s; the
      // unshaped profile leaves no vibration at either (undamped) mode. The shapers shape it again.
      modes: [{ frequencyHz: 1.2, damping: 0.012 }, { frequencyHz: 3.4, damping: 0.013 }],
      shapers: [{ family: 'zv' }, { family: 'zvd' }],
      view: view({ kind: 'profile', shape: 'multiMode', modesHz: [1.2, 3.4], distance: 0.5, duration: 2 }),
    },
  },
  // ---- end of the command presets ----
  // ---- plant presets (issue 23 item 2): web/plant_view.js ----
  {
    id: 'two-mass',
    title: 'Peláez & Singhose 2002 §3: a two-mass spring (1 kg base, 0.5 kg tip) with its rigid-body mode, ZV and ZVD for 1 Hz',
    state: {
      // ω = √(K(M₁ + M₂)/(M₁M₂)) (eq. 18): K = 4π²/3 N/m is 1 Hz; the damper c = 0.08 N·s/m is
      // ζ = c(1/M₁ + 1/M₂)/(2ω) ≈ 0.019. The masses move together (the rigid-body mode) while the tip rings.
      modes: [{ frequencyHz: 1, damping: 0.02 }],
      shapers: [{ family: 'zv' }, { family: 'zvd' }],
      view: view(trapezoid(1, 0.5, 2), { plant: { kind: 'twoMass', baseMass: 1, tipMass: 0.5, stiffness: 13.16, dampingCoefficient: 0.08 } }),
    },
  },
  {
    id: 'crane-hoist',
    title: 'Overhead crane hoisting: 6.2 m cable wound up by 3 m during a 4 m move (ZV and ZVD for the initial length)',
    state: {
      // The shapers are designed for the initial 0.2 Hz; the swing speeds up as the cable shortens.
      modes: [{ frequencyHz: 0.2, damping: 0 }],
      shapers: [{ family: 'zv' }, { family: 'zvd' }],
      view: view(trapezoid(4, 1, 2), { plant: { kind: 'pendulum', gravity: 9.81, initialAngle: 0, hoist: trapezoid(-3, 0.5, 0.5) } }),
    },
  },
  // ---- end of the plant presets ----
  // ---- printer preset (issue 23): realisation (item 1) ----
  {
    id: 'printer',
    title: '3D printer, X 48 Hz / Y 37 Hz: ZV on Marlin FT_MOTION, MZV and EI on Klipper, the ringing tower',
    state: {
      // A measured-looking X axis (the corner below adds Y: 37 Hz, ζ = 0.09). FT_MOTION's 1 ms period moves the ZV's
      // echo from 10.4 to 10 ms; Klipper runs its own MZV and its fitted EI.
      modes: [{ frequencyHz: 48, damping: 0.07 }],
      shapers: [
        { family: 'zv', realise: { firmware: 'marlinFtMotion' } },
        { family: 'mzv', realise: { firmware: 'klipper' } },
        { family: 'ei', vtol: 0.05, realise: { firmware: 'klipper' } },
        { family: 'zvd' },
      ],
      // A 10 mm move at 200 mm/s and 5000 mm/s² (units: mm).
      view: view(trapezoid(10, 200, 5000)),
      // corner (issue 23 item 3): Klipper's ringing tower at 100 mm/s, 3000 mm/s²; X the axis
      // above plus a weaker 97 Hz mode, Y 37 Hz, ζ = 0.09.
      corner: { open: true, path: 'ringingTower', sideMm: 120, velocity: 100, accel: 3000, scv: 5, magnify: 50, x: [{ frequencyHz: 48, damping: 0.07 }, { frequencyHz: 97, damping: 0.04 }], y: [{ frequencyHz: 37, damping: 0.09 }] },
    },
  },
  // ---- end of the printer preset ----
];

const clone = (x) => JSON.parse(JSON.stringify(x));

/**
 * Checks the *shape* of a state read from outside (URL hash, imported file). Values are not
 * judged here — the core does that and names the field — but the structure must be what the
 * page can edit. Returns a fresh state, or throws an Error with a message for a person.
 */
export function checkState(value) {
  const fail = (why) => {
    throw new Error(`Not a playground state: ${why}.`);
  };
  if (!value || typeof value !== 'object' || Array.isArray(value)) fail('expected an object');
  const { modes, shapers, view } = value;
  if (!Array.isArray(modes) || modes.length < 1 || modes.length > MAX_MODES) {
    fail(`"modes" must be a list of 1 to ${MAX_MODES} modes`);
  }
  const num = (x) => typeof x === 'number' || x === null;
  modes.forEach((m, i) => {
    if (!m || typeof m !== 'object' || !num(m.frequencyHz) || !num(m.damping ?? 0)) {
      fail(`modes[${i}] must be { frequencyHz: number, damping: number }`);
    }
  });
  if (!Array.isArray(shapers) || shapers.length < 1 || shapers.length > MAX_SHAPERS) {
    fail(`"shapers" must be a list of 1 to ${MAX_SHAPERS} shapers`);
  }
  shapers.forEach((s, i) => {
    if (!s || typeof s !== 'object' || typeof s.family !== 'string' || s.family.length > 40) {
      fail(`shapers[${i}] must have a "family" name`);
    }
    for (const [k, v] of Object.entries(s)) {
      const ok = typeof v === 'string' ? v.length <= 200 : num(v) || (Array.isArray(v) && v.length <= 64 && v.every(num))
        || (v && typeof v === 'object' && !Array.isArray(v) && JSON.stringify(v).length <= 4000);
      if (!ok) fail(`shapers[${i}].${k} has an unsupported value`);
    }
  });
  if (view !== undefined && (typeof view !== 'object' || view === null || Array.isArray(view))) {
    fail('"view" must be an object');
  }
  checkView(view ?? {}, fail);
  const out = clone({ modes, shapers, view: { ...DEFAULT_STATE.view, ...(view ?? {}) } });
  if (value.corner !== undefined) out.corner = checkCorner(value.corner, fail); // corner (issue 23 item 3)
  out.modes = out.modes.map((m) => ({ frequencyHz: m.frequencyHz, damping: m.damping ?? 0 }));
  return out;
}

// corner (issue 23 item 3)
/** The printed-corner panel's state: its shape only (the core judges the values). */
function checkCorner(c, fail) {
  const num = (x) => typeof x === 'number' || x === null;
  if (!c || typeof c !== 'object' || Array.isArray(c)) fail('"corner" must be an object');
  const out = {};
  for (const [k, v] of Object.entries(c)) {
    if (k === 'open') {
      if (typeof v !== 'boolean') fail('corner.open must be true or false');
    } else if (k === 'path') {
      if (!['square', 'ringingTower'].includes(v)) fail('corner.path must be "square" or "ringingTower"');
    } else if (['sideMm', 'velocity', 'accel', 'scv', 'magnify'].includes(k)) {
      if (!num(v)) fail(`corner.${k} must be a number`);
    } else if (k === 'x' || k === 'y') {
      if (!Array.isArray(v) || v.length < 1 || v.length > MAX_MODES) fail(`corner.${k} must be a list of 1 to ${MAX_MODES} modes`);
      v.forEach((m, i) => {
        if (!m || typeof m !== 'object' || !num(m.frequencyHz) || !num(m.damping ?? 0)) fail(`corner.${k}[${i}] must be { frequencyHz: number, damping: number }`);
      });
      out[k] = v.map((m) => ({ frequencyHz: m.frequencyHz, damping: m.damping ?? 0 }));
      continue;
    } else {
      fail(`corner.${k} is not a setting of the printed corner`);
    }
    out[k] = v;
  }
  return out;
}
// /corner

/** Known view settings: their types. Unknown keys may hold only short plain values. */
function checkView(view, fail) {
  const num = (x) => typeof x === 'number' || x === null;
  const plain = (o) => o && typeof o === 'object' && !Array.isArray(o);
  for (const [k, v] of Object.entries(view)) {
    if (['vtol', 'scv', 'mismatch', 'mapShaper', 'fromHz', 'toHz', 'points', 'samples', 'duration', 'dampingTo'].includes(k)) {
      if (!num(v)) fail(`view.${k} must be a number`);
    } else if (k === 'modeMismatch' || k === 'actualDamping') {
      if (!Array.isArray(v) || v.length > MAX_MODES || !v.every(num)) fail(`view.${k} must be a list of at most ${MAX_MODES} numbers`);
    } else if (k === 'command') {
      checkCommand(v, 'view.command', fail);
    } else if (k === 'plant') {
      if (!plain(v) || !PLANT_KINDS.includes(v.kind)) fail(`view.plant must be { kind: ${PLANT_KINDS.join(' | ')} }`);
      for (const [pk, pv] of Object.entries(v)) {
        if (pk === 'hoist' && v.kind === 'pendulum') {
          if (pv !== null) checkCommand(pv, 'view.plant.hoist', fail);
        } else if (pk !== 'kind' && !num(pv)) fail(`view.plant.${pk} must be a number`);
      }
    } else if (!(num(v) || typeof v === 'boolean' || (typeof v === 'string' && v.length <= 200))) {
      fail(`view.${k} has an unsupported value`);
    }
  }
}

/** A command's shape (at `where`): a known kind; a profile's shape and a list's interpolation
 * are names (letters only), its values and modesHz lists of numbers; every other field a number
 * (the core judges the values and names the field). */
function checkCommand(v, where, fail) {
  if (!v || typeof v !== 'object' || Array.isArray(v) || !COMMAND_KINDS.includes(v.kind)) fail(`${where} must be { kind: ${COMMAND_KINDS.join(' | ')}, … }`);
  for (const [ck, cv] of Object.entries(v)) {
    const ok = ck === 'kind' || typeof cv === 'number' || cv === null
      || (NAME_FIELDS.includes(ck) && typeof cv === 'string' && /^[A-Za-z]{1,40}$/.test(cv))
      || (LIST_FIELDS.includes(ck) && Array.isArray(cv) && cv.every((x) => typeof x === 'number' || x === null));
    if (!ok) fail(`${where}.${ck} must be a number, a name or a list of numbers`);
  }
}

/** The URL hash for a state: `#state=` + URI-encoded JSON (readable, and shareable as is). */
export function toHash(state) {
  return `#state=${encodeURIComponent(JSON.stringify(state))}`;
}

/**
 * The state in a URL hash. Returns `{ state }`, `{ state: null }` for an empty hash, or
 * `{ error }` with a message for a garbled or hostile one.
 */
export function fromHash(hash) {
  if (!hash || hash === '#') return { state: null };
  if (hash.length > 20000) return { error: 'The link is too long to be a playground state.' };
  const m = /^#state=(.*)$/s.exec(hash);
  if (!m) return { error: 'The link does not hold a playground state (expected #state=…).' };
  let parsed;
  try {
    parsed = JSON.parse(decodeURIComponent(m[1]));
  } catch {
    return { error: 'The link’s state is not valid JSON; the last good state is kept.' };
  }
  try {
    return { state: checkState(parsed) };
  } catch (e) {
    return { error: `${e.message} The last good state is kept.` };
  }
}

export { clone };
