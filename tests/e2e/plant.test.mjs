// End-to-end: the simulated plant's editors (issue 23 item 2) in headless Chromium — the
// two-mass spring with its rigid-body mode, the crane's hoisting, and the mismatch per mode and
// in damping. The simulated-move table on the page against the JS API's own `simulate` (the
// library's pkg/, run in the page) on the same plant, command and samples; pixels on the
// response chart; a bad value named at its field while the last good charts stay; the state in
// the URL; the editor not fetched by the default page; no console errors; screenshots.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { openBrowser, canvasInfo, type, settle, SCREENSHOTS } from './browser.mjs';
import { PRESETS, toHash } from '../../web/state.js';

let env;
before(async () => { env = await openBrowser(); });
after(async () => { await env?.close(); });

const fmt = (x, d) => (x == null ? '—' : Math.abs(x) < 1e-9 && d === 4 ? '≈ 0' : String(Number(x.toPrecision(d))));
const errorAt = (page, id) => page.$eval(`#${id}`, (n) => n.closest('.field').querySelector('.error').textContent);
const stateOf = (page) => page.evaluate(() => JSON.parse(decodeURIComponent(location.hash.slice('#state='.length))));
/** The simulated-move table: { row name: [unshaped, shaper 1, …] }. */
const table = (page) => page.$$eval('#simulation-summary tbody tr', (rows) => Object.fromEntries(rows.map((r) => [r.cells[0].textContent, [...r.cells].slice(1).map((c) => c.textContent)])));
const note = (page) => page.$eval('#simulation-note', (n) => n.textContent);

/** A preset's state with the simulation's window fixed (10 s, 1001 samples: 0.01 s apart). */
function fixed(id) {
  const { state } = PRESETS.find((p) => p.id === id);
  return { ...state, view: { ...state.view, duration: 10, samples: 1001 } };
}

/** `simulate` of the library's JS API for `plant`, unshaped and with each family (designed
 * for `modes`), over the same 10 s at 0.01 s: the metrics of each move. */
function library(page, plant, command, families, modes) {
  return page.evaluate(async ([p, c, fams, ms]) => {
    const api = await import('/pkg/input_shaping.js');
    await api.default({ module_or_path: '/pkg/input_shaping_bg.wasm' });
    const run = (shaper) => api.simulate({ plant: p, command: c, shaper, duration: 10, samplePeriod: 0.01 });
    const first = run(null);
    return { modesHz: first.modesHz, metrics: [first.unshaped.metrics, ...fams.map((f) => run({ family: f, modes: ms }).shaped.metrics)] };
  }, [plant, command, families, modes]);
}

/** The table's residual vibration and settling rows against the library's metrics. */
function assertSame(rows, metrics) {
  const pct = (x) => fmt(x, 4);
  assert.deepEqual(rows['Residual vibration after the move (% of distance)'], metrics.map((m) => pct(m.residualVibrationPercent)));
  assert.deepEqual(rows['Settling time, 5 % band (s)'], metrics.map((m) => fmt(m.settlingTime5, 5)));
  assert.deepEqual(rows['Peak deflection during the move'], metrics.map((m) => fmt(m.peakDeflection, 4)));
}

test('the two-mass preset: the table is the library’s two-mass simulation; a bad tip mass is named, the charts kept; the URL', async () => {
  const state = fixed('two-mass');
  const { page, problems, fetched } = await env.page({ hash: toHash(state) });
  await page.waitForSelector('#view-plant-tipMass', { timeout: 20000 });
  await settle(page);
  assert.equal(await page.$eval('#plant-kind', (n) => n.value), 'twoMass');
  assert.ok(fetched.some((p) => p.endsWith('/pkg/page/plant_view.js')), 'the editor was fetched');
  const plant = state.view.plant;
  const lib = await library(page, plant, state.view.command, ['zv', 'zvd'], state.modes);
  // eq. 18: ω = √(K(M₁ + M₂)/(M₁M₂)) = √(13.16 · 3) rad/s.
  const f = Math.sqrt(13.16 * 1.5 / 0.5) / (2 * Math.PI);
  assert.equal(fmt(lib.modesHz[0], 4), fmt(f, 4));
  assert.match(await note(page), new RegExp(`^\\(two-mass spring, actual modes ${fmt(f, 4).replace('.', '\\.')} Hz = model × 1;`));
  assert.match(await page.$eval('#two-mass-mode', (n) => n.textContent), new RegExp(`f = .* = ${fmt(f, 4).replace('.', '\\.')} Hz, ζ = ${fmt(0.08 * 3 / (2 * 2 * Math.PI * f), 3).replace('.', '\\.')}`));
  assertSame(await table(page), lib.metrics);
  // The rigid-body mode: the move ends where the command does, the tip rings unshaped.
  assert.ok(lib.metrics[0].residualVibrationPercent > 1, `unshaped rings: ${lib.metrics[0].residualVibrationPercent}`);
  const good = {};
  for (const id of ['response-chart', 'command-chart', 'spectrum-chart']) {
    const info = await canvasInfo(page, id);
    assert.ok(info.ink > 2000, `${id} ink ${info.ink}`);
    good[id] = info.hash;
  }
  await page.locator('#simulation').screenshot({ path: `${SCREENSHOTS}plant-two-mass-editor.png` });
  await page.screenshot({ path: `${SCREENSHOTS}plant-two-mass-1280x800.png`, fullPage: true });

  // A stiffer spring: the response follows.
  await type(page, 'view-plant-stiffness', '20');
  await settle(page);
  assert.notEqual((await canvasInfo(page, 'response-chart')).hash, good['response-chart']);
  const edited = {};
  for (const id of Object.keys(good)) edited[id] = (await canvasInfo(page, id)).hash;
  // A bad tip mass: named at its field, the last good charts kept.
  await type(page, 'view-plant-tipMass', '-1');
  await settle(page);
  assert.match(await errorAt(page, 'view-plant-tipMass'), /^view\.plant\.tipMass: /);
  assert.equal(await page.$eval('#view-plant-tipMass', (n) => n.getAttribute('aria-invalid')), 'true');
  for (const [id, hash] of Object.entries(edited)) assert.equal((await canvasInfo(page, id)).hash, hash, `${id} kept`);
  await type(page, 'view-plant-tipMass', '0.5');
  await settle(page);
  assert.equal(await errorAt(page, 'view-plant-tipMass'), '');
  assert.deepEqual((await stateOf(page)).view.plant, { ...plant, stiffness: 20 });
  assert.deepEqual(problems, []);
  await page.close();
});

test('the default page does not fetch the plant editor; picking the two-mass spring gives mode 1’s frequency', async () => {
  const { page, problems, fetched } = await env.page();
  await settle(page);
  assert.ok(!fetched.some((p) => p.includes('plant_view')), `first load fetched ${fetched.join(', ')}`);
  await page.selectOption('#plant-kind', 'twoMass');
  await page.waitForSelector('#view-plant-stiffness', { timeout: 20000 });
  await settle(page);
  // Mode 1 is 2 Hz, ζ 0.05: 1 kg and 1 kg, K = ω²/2, c = ζω.
  const w = 4 * Math.PI;
  assert.deepEqual((await stateOf(page)).view.plant, { kind: 'twoMass', baseMass: 1, tipMass: 1, stiffness: +(w * w / 2).toPrecision(6), dampingCoefficient: +(0.05 * w).toPrecision(6) });
  assert.match(await note(page), /^\(two-mass spring, actual modes 2 Hz = model × 1;/);
  assert.deepEqual(problems, []);
  await page.close();
});

test('the crane hoisting: the table is the library’s hoisted pendulum; a hoist that winds the cable up entirely is named', async () => {
  const state = fixed('crane-hoist');
  const { page, problems } = await env.page({ hash: toHash(state) });
  await page.waitForSelector('#view-plant-hoist-distance', { timeout: 20000 });
  await settle(page);
  assert.equal(await page.$eval('#hoist-on', (n) => n.checked), true);
  const length = 9.81 / (2 * Math.PI * 0.2) ** 2;
  const plant = { kind: 'pendulum', length, gravity: 9.81, damping: 0, initialAngle: 0, hoist: state.view.plant.hoist };
  const lib = await library(page, plant, state.view.command, ['zv', 'zvd'], state.modes);
  assertSame(await table(page), lib.metrics);
  // Hoisting changes the swing: against the same move without it.
  const still = await library(page, { ...plant, hoist: null }, state.view.command, ['zv'], state.modes);
  assert.notEqual(fmt(still.metrics[1].residualVibrationPercent, 4), fmt(lib.metrics[1].residualVibrationPercent, 4));
  const good = (await canvasInfo(page, 'response-chart')).hash;
  await page.locator('#simulation').screenshot({ path: `${SCREENSHOTS}plant-hoist-editor.png` });
  // The cable wound up by more than its length (7 m at 2 m/s, 2 m/s²: within the 10 s), the
  // message at the hoist's fields, the charts kept.
  await type(page, 'view-plant-hoist-maxVelocity', '2');
  await type(page, 'view-plant-hoist-maxAcceleration', '2');
  await settle(page);
  const faster = (await canvasInfo(page, 'response-chart')).hash;
  assert.notEqual(faster, good, 'a faster hoist, another swing');
  await type(page, 'view-plant-hoist-distance', '-7');
  await settle(page);
  const message = await page.$$eval('#hoist-fields .error', (ns) => ns.map((n) => n.textContent).join(''));
  assert.match(message, /hoist/, message);
  assert.equal((await canvasInfo(page, 'response-chart')).hash, faster);
  // A bad speed: named at its field.
  await type(page, 'view-plant-hoist-distance', '-3');
  await type(page, 'view-plant-hoist-maxAcceleration', '0.5');
  await type(page, 'view-plant-hoist-maxVelocity', '0');
  await settle(page);
  assert.match(await errorAt(page, 'view-plant-hoist-maxVelocity'), /^view\.plant\.hoist\.maxVelocity: /);
  await type(page, 'view-plant-hoist-maxVelocity', '0.5');
  await settle(page);
  // Hoisting off: the link holds no hoist.
  await page.uncheck('#hoist-on');
  await settle(page);
  assert.equal((await stateOf(page)).view.plant.hoist, undefined);
  assert.notEqual((await canvasInfo(page, 'response-chart')).hash, good);
  assert.deepEqual(problems, []);
  await page.close();
});

test('hostile plant values in a link are refused as a state (web/state.js)', async () => {
  const { fromHash } = await import('../../web/state.js');
  const base = PRESETS.find((p) => p.id === 'crane-hoist').state;
  const withPlant = (plant) => toHash({ ...base, view: { ...base.view, plant } });
  assert.ok(fromHash(withPlant(base.view.plant)).state, 'the preset passes');
  for (const plant of [
    { kind: 'pendulum', hoist: { kind: 'trapezoid', distance: '<b>1</b>', maxVelocity: 1, maxAcceleration: 1 } },
    { kind: 'pendulum', hoist: { kind: '<img>', distance: 1 } },
    { kind: 'pendulum', hoist: 'x' },
    { kind: 'modal', hoist: { kind: 'step', distance: 1 } },
    { kind: 'twoMass', baseMass: '1', tipMass: 1, stiffness: 1 },
    { kind: 'twoMass', baseMass: { a: 1 }, tipMass: 1, stiffness: 1 },
  ]) {
    const { error, state } = fromHash(withPlant(plant));
    assert.equal(state, undefined, JSON.stringify(plant));
    assert.match(error, /view\.plant/, error);
  }
});

test('a mismatch per mode and in damping: the table is the library’s simulation of those modes; a bad ratio is named; the URL; a removed mode takes its entries along', async () => {
  const modes = [{ frequencyHz: 2, damping: 0.05 }, { frequencyHz: 5, damping: 0.02 }];
  const command = { kind: 'trapezoid', distance: 1, maxVelocity: 0.8, maxAcceleration: 8 };
  const state = { modes, shapers: [{ family: 'zv' }, { family: 'zvd' }], view: { command, mismatch: 1.1, duration: 10, samples: 1001, plant: { kind: 'modal' } } };
  const { page, problems } = await env.page({ hash: toHash(state) });
  await settle(page);
  assert.equal(await page.$eval('#mode-mismatch-group', (n) => n.open), false, 'closed while unused');
  assert.match(await note(page), /actual modes 2\.2, 5\.5 Hz = model × 1\.1;/);
  const before = (await canvasInfo(page, 'response-chart')).hash;
  await page.click('#mode-mismatch-group > summary');
  await type(page, 'modeMismatch-1', '0.9');
  await type(page, 'actualDamping-1', '0.1');
  await settle(page);
  // Mode 2: 5 Hz × 1.1 × 0.9 = 4.95 Hz at ζ 0.1; mode 1 as the common ratio makes it.
  assert.match(await note(page), /actual modes 2\.2 Hz \(ζ 0\.05\), 4\.95 Hz \(ζ 0\.1\);/);
  const actual = [{ frequencyHz: 2.2, damping: 0.05 }, { frequencyHz: 4.95, damping: 0.1 }];
  const lib = await library(page, { kind: 'modal', modes: actual }, command, ['zv', 'zvd'], modes);
  assertSame(await table(page), lib.metrics);
  const good = (await canvasInfo(page, 'response-chart')).hash;
  assert.notEqual(good, before, 'the response follows');
  assert.deepEqual((await stateOf(page)).view.modeMismatch, [1, 0.9]);
  assert.deepEqual((await stateOf(page)).view.actualDamping, [null, 0.1]);
  await page.screenshot({ path: `${SCREENSHOTS}plant-mode-mismatch-1280x800.png`, fullPage: true });

  // A bad ratio: named at its field, the last good charts kept; cleared, back to the default 1.
  await type(page, 'modeMismatch-0', '-1');
  await settle(page);
  assert.match(await errorAt(page, 'modeMismatch-0'), /0\.05/);
  assert.equal((await canvasInfo(page, 'response-chart')).hash, good);
  await type(page, 'modeMismatch-0', '');
  await settle(page);
  assert.equal(await errorAt(page, 'modeMismatch-0'), '');
  assert.equal((await canvasInfo(page, 'response-chart')).hash, good);

  // Removing mode 1 takes its entries along: mode 2's stay with it.
  await page.click('button[aria-label="Remove mode 1"]');
  await settle(page);
  const st = await stateOf(page);
  assert.deepEqual([st.view.modeMismatch, st.view.actualDamping], [[0.9], [0.1]]);
  assert.match(await note(page), /actual modes 4\.95 Hz \(ζ 0\.1\);/);
  assert.deepEqual(problems, []);
  await page.close();
});
