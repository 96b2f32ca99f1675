// End-to-end: the playground's analysis and simulation charts (V(ζ), the frequency × damping
// map, the simulated response with a model mismatch, the command, its spectrum, robustness
// against duration) in headless Chromium — ink on every canvas, every canvas reacting to its
// inputs, the simulated residual in the DOM against a closed form, the view state in the URL,
// the error paths, every preset, and screenshots.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { openBrowser, canvasInfo, type, settle, SCREENSHOTS } from './browser.mjs';

const CANVASES = ['impulses-chart', 'sensitivity-chart', 'damping-chart', 'map-chart', 'response-chart',
  'command-chart', 'spectrum-chart', 'robustness-chart'];

let env;
before(async () => { env = await openBrowser(); });
after(async () => { await env?.close(); });


async function hashes(page) {
  const out = {};
  for (const id of CANVASES) out[id] = (await canvasInfo(page, id)).hash;
  return out;
}

/** The simulation table as { rowName: [unshaped, shaper 1, …] }. */
async function simulation(page) {
  return page.$$eval('#simulation-summary tbody tr', (rows) => Object.fromEntries(rows.map((r) => [r.cells[0].textContent, [...r.cells].slice(1).map((c) => c.textContent)])));
}
const RESIDUAL = 'Residual vibration after the move (% of distance)';
const pctValue = (text) => (text === '≈ 0' ? 0 : Number(text));

async function errors(page) {
  return page.$$eval('.error', (e) => e.map((x) => x.textContent).filter(Boolean));
}

test('every chart canvas has ink, sized for devicePixelRatio, and changes when its inputs change', async () => {
  const { page, problems } = await env.page();
  for (const id of CANVASES) {
    const info = await canvasInfo(page, id);
    assert.ok(info.ink > 3000, `${id} has ink: ${info.ink} px of ${info.width}x${info.height}`);
    const css = await page.$eval(`#${id}`, (c) => [c.clientWidth, c.clientHeight, window.devicePixelRatio]);
    assert.equal(info.width, Math.round(css[0] * css[2]), `${id} width follows devicePixelRatio`);
  }
  const before = await hashes(page);
  // The damping of the mode moves every chart: the designs, V(ζ)'s marker, the map's cross,
  // the simulated plant, and the robustness table (designed for mode 1).
  await type(page, 'mode-0-damping', 0.1);
  await settle(page);
  assert.deepEqual(await errors(page), []);
  const after = await hashes(page);
  for (const id of CANVASES) assert.notEqual(after[id], before[id], `${id} redrawn for ζ = 0.1`);
  // The mismatch moves the response (and the actual-mode markers of the spectrum) only.
  await type(page, 'mismatch', 1.2);
  await settle(page);
  const mismatched = await hashes(page);
  assert.notEqual(mismatched['response-chart'], after['response-chart']);
  assert.notEqual(mismatched['spectrum-chart'], after['spectrum-chart']);
  assert.equal(mismatched['impulses-chart'], after['impulses-chart']);
  assert.equal(mismatched['map-chart'], after['map-chart']);
  // The command moves the command chart, the response and the spectrum.
  await page.selectOption('#command-kind', 'sCurve');
  await settle(page);
  const curved = await hashes(page);
  for (const id of ['command-chart', 'response-chart', 'spectrum-chart']) assert.notEqual(curved[id], mismatched[id], id);
  assert.equal(await page.isVisible('#command-maxJerk'), true);
  // The map shows the shaper picked for it.
  await page.click('#add-shaper');
  await settle(page);
  const two = await hashes(page);
  await page.selectOption('#map-shaper', '1');
  await settle(page);
  assert.notEqual((await hashes(page))['map-chart'], two['map-chart']);
  assert.deepEqual(problems, []);
  await page.close();
});

test('the mismatch control: r = 1 leaves no residual, r = 1.2 leaves what V predicts', async () => {
  const { page, problems } = await env.page();
  // ZVD at the exact mode: V = 0 (Singhose 2009 eq. 17), so the shaped trapezoid leaves none.
  let sim = await simulation(page);
  assert.equal(sim[RESIDUAL][1], '≈ 0', `shaped residual at r = 1: ${sim[RESIDUAL]}`);
  assert.ok(pctValue(sim[RESIDUAL][0]) > 1, `unshaped residual: ${sim[RESIDUAL][0]}`);
  // r = 1.2 at the model's damping: the shaped move now leaves some.
  await type(page, 'mismatch', 1.2);
  await settle(page);
  assert.ok(pctValue((await simulation(page))[RESIDUAL][1]) > 0.05, 'residual at r = 1.2');
  // Undamped mode, plant at 1.2 × the model: the shaped residual is the unshaped one times
  // V_ZVD = cos²(π r / 2) (ZVD = ZV ⊗ ZV, each |cos(π r/2)| at ζ = 0; Singhose 2009 eq. 11).
  await type(page, 'mode-0-damping', 0);
  await type(page, 'mismatch', 1.2);
  await settle(page);
  sim = await simulation(page);
  const [unshaped, shaped] = sim[RESIDUAL].map(pctValue);
  const v = Math.cos((Math.PI * 1.2) / 2) ** 2;
  assert.ok(shaped > 0.1, `shaped residual at r = 1.2: ${shaped} %`);
  assert.ok(Math.abs(shaped / unshaped - v) < 0.01 * v, `ratio ${shaped / unshaped} vs V = ${v}`);
  assert.match(await page.textContent('#simulation-note'), /2\.4 Hz = model × 1\.2/);
  // The slider works from the keyboard and updates the number field.
  await page.focus('#mismatch-slider');
  await page.keyboard.press('ArrowLeft');
  await settle(page);
  assert.equal(await page.inputValue('#mismatch'), '1.19');
  assert.ok(pctValue((await simulation(page))[RESIDUAL][1]) < shaped, 'closer to the model, less residual');
  assert.deepEqual(problems, []);
  await page.close();
});

test('errors in the simulation controls show at their field and keep the last good charts', async () => {
  const { page, problems } = await env.page();
  const good = await hashes(page);
  const rows = await simulation(page);
  await type(page, 'mismatch', -1);
  await settle(page);
  assert.match(await page.textContent('.field:has(#mismatch) .error'), /view\.mismatch/);
  assert.equal(await page.getAttribute('#mismatch', 'aria-invalid'), 'true');
  assert.deepEqual(await hashes(page), good, 'nothing redrawn');
  assert.deepEqual(await simulation(page), rows, 'the numbers stay');
  await type(page, 'mismatch', 1);
  await type(page, 'command-maxVelocity', 0);
  await settle(page);
  assert.match(await page.textContent('.field:has(#command-maxVelocity) .error'), /view\.command\.maxVelocity/);
  await type(page, 'command-maxVelocity', 0.75);
  // The pendulum cannot follow a step (its trolley position would jump).
  await page.selectOption('#plant-kind', 'pendulum');
  await settle(page);
  const swinging = await hashes(page);
  assert.notEqual(swinging['response-chart'], good['response-chart'], 'the pendulum responds differently');
  await page.selectOption('#command-kind', 'step');
  await settle(page);
  assert.match(await page.textContent('.field:has(#command-kind) .error'), /view\.command.*jump/);
  assert.deepEqual(await hashes(page), swinging);
  await page.selectOption('#command-kind', 'trapezoid');
  await settle(page);
  assert.deepEqual(await errors(page), []);
  assert.match(await page.textContent('#simulation-note'), /pendulum/);
  assert.deepEqual(problems, [], 'errors are shown on the page, not thrown');
  await page.close();
});

test('the view settings live in the URL; hostile view values are rejected', async () => {
  const { page, problems } = await env.page();
  await type(page, 'mismatch', 1.3);
  await page.selectOption('#command-kind', 'sCurve');
  await page.selectOption('#plant-kind', 'pendulum');
  await settle(page);
  const hash = decodeURIComponent(new URL(page.url()).hash);
  assert.match(hash, /"mismatch":1\.3/);
  assert.match(hash, /"kind":"sCurve"/);
  assert.match(hash, /"kind":"pendulum"/);
  await page.reload();
  await page.waitForSelector('body[data-ready="true"]');
  assert.equal(await page.inputValue('#mismatch'), '1.3');
  assert.equal(await page.inputValue('#command-kind'), 'sCurve');
  assert.equal(await page.inputValue('#plant-kind'), 'pendulum');
  const base = { modes: [{ frequencyHz: 1, damping: 0 }], shapers: [{ family: 'zv' }] };
  for (const view of [
    { command: { kind: '<img src=x onerror=alert(1)>' } },
    { command: { kind: 'step', distance: '<b>1</b>' } },
    { plant: { kind: 'pendulum', gravity: [1, 2] } },
    { mismatch: 'large' },
    { extra: { nested: true } },
  ]) {
    await page.evaluate((h) => { location.hash = h; }, `#state=${encodeURIComponent(JSON.stringify({ ...base, view }))}`);
    await settle(page);
    assert.match(await page.textContent('#general-error'), /Not a playground state: view/, JSON.stringify(view));
    assert.ok(!(await page.$('img[src="x"], #results b')), 'no markup from the hash');
    assert.equal(await page.inputValue('#mismatch'), '1.3', 'the last good state is kept');
  }
  assert.deepEqual(problems, []);
  await page.close();
});

test('every preset loads and draws all charts', async () => {
  const { page, problems } = await env.page();
  const ids = await page.$$eval('#preset option', (o) => o.map((x) => x.value).filter(Boolean));
  for (const want of ['singer-seering', 'veciana', 'pelaez', 'kamel', 'crane', 'printer']) assert.ok(ids.includes(want), want);
  for (const id of ids) {
    await page.selectOption('#preset', id);
    await settle(page);
    assert.deepEqual(await errors(page), [], `preset ${id}`);
    for (const c of CANVASES) assert.ok((await canvasInfo(page, c)).ink > 2000, `${id}: ${c}`);
    const sim = await simulation(page);
    assert.ok(sim[RESIDUAL].every((x) => x !== '—'), `${id}: residuals ${sim[RESIDUAL]}`);
    await page.screenshot({ path: `${SCREENSHOTS}charts-preset-${id}.png`, fullPage: true });
  }
  await page.selectOption('#preset', 'crane');
  await settle(page);
  assert.equal(await page.inputValue('#plant-kind'), 'pendulum');
  assert.match(await page.textContent('#simulation-note'), /nonlinear pendulum/);
  assert.deepEqual(problems, []);
  await page.close();
});

test('screenshots of all charts at 1280 × 800 and 390 × 844', async () => {
  for (const [width, height] of [[1280, 800], [390, 844]]) {
    const { page, problems } = await env.page({ width, height });
    await page.selectOption('#preset', 'veciana');
    await type(page, 'mismatch', 1.1);
    await settle(page);
    for (const c of CANVASES) assert.ok((await canvasInfo(page, c)).ink > 2000, `${width}: ${c}`);
    const overflow = await page.evaluate(() => document.documentElement.scrollWidth - window.innerWidth);
    assert.ok(overflow <= 1, `no horizontal scrolling of the page at ${width}px: ${overflow}px`);
    await page.screenshot({ path: `${SCREENSHOTS}charts-${width}x${height}.png`, fullPage: true });
    await page.locator('.charts').screenshot({ path: `${SCREENSHOTS}charts-only-${width}x${height}.png` });
    assert.deepEqual(problems, []);
    await page.close();
  }
});
