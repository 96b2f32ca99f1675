// End-to-end: the profile and list commands (issue 23 item 2) in headless Chromium. The
// profile's zeros on the page against the closed form computed here (Veciana & Cardona 2011
// eq. 13: a pulse of width 1/f₀ is zero at k·f₀) and against the JS API's `profileSpectrum` (the
// library's pkg/); pixels on the profile's spectrum and on the charts; a list typed in; a bad
// value named at its field (with the index of a bad sample) while the last good charts stay;
// the state in the URL; the view not fetched by the default page; no console errors; screenshots.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { openBrowser, canvasInfo, type, settle, SCREENSHOTS } from './browser.mjs';
import { PRESETS, toHash } from '../../web/state.js';

let env;
before(async () => { env = await openBrowser(); });
after(async () => { await env?.close(); });

const preset = PRESETS.find((p) => p.id === 'veciana-profile');
const fmt = (x) => String(Number(x.toPrecision(4)));
const zerosText = (page) => page.$eval('#command-zeros', (n) => n.textContent);
const errorAt = (page, id) => page.$eval(`#${id}`, (n) => n.closest('.field').querySelector('.error').textContent);
/** The unshaped move's end (s) in the simulated-move table. */
const moveEnd = (page) => page.$$eval('#simulation-summary tbody tr', (rows) => rows.find((r) => r.cells[0].textContent === 'Move ends (s)').cells[1].textContent);
const stateOf = (page) => page.evaluate(() => JSON.parse(decodeURIComponent(location.hash.slice('#state='.length))));

/** The zeros of `profileSpectrum` of the library's JS API (pkg/input_shaping.js), run in the page. */
function libraryZeros(page, command, upToHz) {
  return page.evaluate(async ([c, top]) => {
    const api = await import('/pkg/input_shaping.js');
    await api.default({ module_or_path: '/pkg/input_shaping_bg.wasm' });
    return api.profileSpectrum(c, { toHz: top, points: 2 }).zeros;
  }, [command, upToHz]);
}

async function openView(hash) {
  const opened = await env.page({ hash });
  await opened.page.waitForSelector('#command-view:not([hidden])', { timeout: 20000 });
  await settle(opened.page);
  return opened;
}

test('the multi-mode profile preset: zeros at k × 1.2 Hz and k × 3.4 Hz, marked and listed, both modes on a zero', async () => {
  const { page, problems, fetched } = await openView(toHash(preset.state));
  const text = await zerosText(page);
  // Closed form (eq. 13 per pulse): the pulses of 1/1.2 s and 1/3.4 s up to 3 × 3.4 Hz.
  const top = 3 * 3.4;
  const want = [];
  for (const f0 of [1.2, 3.4]) for (let k = 1; k * f0 <= top * (1 + 1e-12); k++) want.push(k * f0);
  want.sort((a, b) => a - b);
  const listed = [...text.matchAll(/(\d+(?:\.\d+)?) Hz(?: \(order \d: tangent\))?(?: = mode \d)?[;.]/g)].map((m) => Number(m[1]));
  assert.deepEqual(listed, want.map((f) => Number(fmt(f))), text);
  assert.match(text, /1\.2 Hz = mode 1;/);
  assert.match(text, /3\.4 Hz = mode 2;/);
  assert.match(text, /Every mode is on a zero\./);
  // The final pulse, 2 − 1/1.2 − 1/3.4 s: its zeros every 1/that Hz.
  assert.match(text, new RegExp(`every ${fmt(1 / (2 - 1 / 1.2 - 1 / 3.4)).replace('.', '\\.')} Hz`));
  const lib = await libraryZeros(page, preset.state.view.command, top);
  assert.deepEqual(lib.filter((z) => !z.finalPulse).map((z) => fmt(z.frequencyHz)), want.map(fmt));
  for (const id of ['command-zeros-chart', 'spectrum-chart', 'command-chart', 'response-chart']) {
    const info = await canvasInfo(page, id);
    assert.ok(info.ink > 2000, `${id} has ink: ${info.ink} px of ${info.width}x${info.height}`);
  }
  assert.equal(await page.$eval('#command-kind', (n) => n.value), 'profile');
  assert.equal(await page.$eval('#command-shape', (n) => n.value), 'multiMode');
  assert.equal(await page.$eval('#command-modesHz', (n) => n.value), '1.2, 3.4');
  assert.ok(fetched.some((p) => p.endsWith('/pkg/page/command_view.js')), 'the view was fetched');
  await page.screenshot({ path: `${SCREENSHOTS}command-profile-1280x800.png`, fullPage: true });
  // A mode moved off its zero (the range unchanged): the line says so, the chart stays as drawn.
  const chart = (await canvasInfo(page, 'command-zeros-chart')).hash;
  await type(page, 'mode-0-frequency', '1.3');
  await settle(page);
  assert.match(await zerosText(page), /1\.2 Hz; 2\.4 Hz;.* Not on a zero: mode 1 \(1\.3 Hz\)\.$/);
  assert.equal((await canvasInfo(page, 'command-zeros-chart')).hash, chart);
  assert.deepEqual(problems, []);
  await page.close();
});

test('a profile picked on the default page: its fields, its zeros, a bad duration named with the charts kept, the URL', async () => {
  const { page, problems, fetched } = await env.page();
  await settle(page);
  assert.ok(!fetched.some((p) => p.includes('command_view') || p.includes('recording')), `first load fetched ${fetched.join(', ')}`);
  await page.selectOption('#command-kind', 'profile');
  await page.waitForSelector('#command-view:not([hidden])', { timeout: 20000 });
  await settle(page);
  // The default: Veciana's triangle for mode 1 (2 Hz), 2.6 periods long; its double zeros at
  // k × 2 Hz; the final pulse's (0.3 s: every 3.33 Hz) are not marked.
  assert.equal(await page.$eval('#command-shape', (n) => n.value), 'triangle');
  assert.equal(await page.$eval('#command-frequencyHz', (n) => n.value), '2');
  assert.equal(await page.$eval('#command-duration', (n) => n.value), '1.3');
  assert.match(await zerosText(page), /^Zeros of the triangle profile .*: 2 Hz \(order 2: tangent\) = mode 1; 4 Hz \(order 2: tangent\); 6 Hz \(order 2: tangent\)\. The final pulse adds zeros every 3\.333 Hz/);
  // The robust trapezium (Fig. 8): zeros at f₀ ± Δf, Δf = 10 % of f₀ by default.
  await page.selectOption('#command-shape', 'robustTrapezium');
  await settle(page);
  assert.equal(await page.$eval('#command-deltaHz', (n) => n.value), '0.2');
  let text = await zerosText(page);
  assert.match(text, /: 1\.8 Hz; 2\.2 Hz;/, text);
  assert.match(text, /Not on a zero: mode 1 \(2 Hz\)\./, text);
  await type(page, 'command-deltaHz', '0.1');
  await settle(page);
  text = await zerosText(page);
  assert.match(text, /: 1\.9 Hz; 2\.1 Hz;/, text);
  const lib = await libraryZeros(page, { kind: 'profile', shape: 'robustTrapezium', frequencyHz: 2, deltaHz: 0.1, distance: 1, duration: 1.3 }, 6);
  assert.deepEqual(lib.filter((z) => !z.finalPulse).slice(0, 2).map((z) => fmt(z.frequencyHz)), ['1.9', '2.1']);
  const state = await stateOf(page);
  assert.deepEqual(state.view.command, { kind: 'profile', distance: 1, shape: 'robustTrapezium', frequencyHz: 2, duration: 1.3, deltaHz: 0.1 });
  const charts = {};
  for (const id of ['command-zeros-chart', 'response-chart', 'command-chart']) charts[id] = (await canvasInfo(page, id)).hash;

  // A duration shorter than the pulses: named at its field, the charts and the zeros kept.
  await type(page, 'command-duration', '0.8');
  await settle(page);
  const message = await errorAt(page, 'command-duration');
  assert.match(message, /^view\.command\.duration: must be at least the sum of the pulses/, message);
  assert.equal(await page.$eval('#command-duration', (n) => n.getAttribute('aria-invalid')), 'true');
  for (const [id, hash] of Object.entries(charts)) assert.equal((await canvasInfo(page, id)).hash, hash, `${id} kept`);
  assert.equal(await zerosText(page), text);
  await type(page, 'command-duration', '1.3');
  await settle(page);
  assert.equal(await errorAt(page, 'command-duration'), '');

  // The link, opened fresh: the same fields and zeros.
  const hash = await page.evaluate(() => location.hash);
  const again = await openView(hash);
  assert.equal(await again.page.$eval('#command-shape', (n) => n.value), 'robustTrapezium');
  assert.equal(await again.page.$eval('#command-deltaHz', (n) => n.value), '0.1');
  assert.equal(await zerosText(again.page), text);
  assert.deepEqual(again.problems, []);
  await again.page.close();

  // Back to a trapezoid: the view goes.
  await page.selectOption('#command-kind', 'trapezoid');
  await settle(page);
  assert.equal(await page.$eval('#command-view', (n) => n.hidden), true);
  assert.deepEqual(problems, []);
  await page.close();
});

test('a list typed in: the charts follow; a bad sample is named with its index, the charts kept; the URL', async () => {
  const { page, problems } = await env.page();
  await settle(page);
  await page.selectOption('#command-kind', 'sampled');
  await page.waitForSelector('#command-values', { timeout: 20000 });
  await settle(page);
  const first = (await canvasInfo(page, 'response-chart')).hash;
  await type(page, 'command-values', '0 0.2, 0.5\n0.9;1 1 1\n1');
  await type(page, 'command-samplePeriod', '0.1');
  await settle(page);
  assert.deepEqual((await stateOf(page)).view.command, { kind: 'sampled', samplePeriod: 0.1, values: [0, 0.2, 0.5, 0.9, 1, 1, 1, 1], interpolation: 'linear' });
  const good = {};
  for (const id of ['response-chart', 'command-chart', 'spectrum-chart']) {
    const info = await canvasInfo(page, id);
    assert.ok(info.ink > 2000, `${id} ink ${info.ink}`);
    good[id] = info.hash;
  }
  assert.notEqual(good['response-chart'], first, 'the response follows the list');
  // The numbers in the DOM follow too: the list stops changing at its 5th sample, t = 0.4 s.
  assert.equal(await moveEnd(page), '0.4');

  await type(page, 'command-values', '0, 0.2, x, 1');
  await settle(page);
  const message = await errorAt(page, 'command-values');
  assert.match(message, /^view\.command\.values\[2\]: /, message);
  for (const [id, hash] of Object.entries(good)) assert.equal((await canvasInfo(page, id)).hash, hash, `${id} kept`);
  await type(page, 'command-samplePeriod', '-1');
  await settle(page);
  await type(page, 'command-values', '0, 0.2, 0.5, 1');
  await settle(page);
  assert.match(await errorAt(page, 'command-samplePeriod'), /^view\.command\.samplePeriod: /);
  await type(page, 'command-samplePeriod', '0.1');
  await page.selectOption('#command-interpolation', 'hold');
  await settle(page);
  assert.equal(await errorAt(page, 'command-values'), '');
  assert.equal(await errorAt(page, 'command-samplePeriod'), '');
  assert.equal(await moveEnd(page), '0.3');

  const hash = await page.evaluate(() => location.hash);
  const again = await env.page({ hash });
  await again.page.waitForSelector('#command-values', { timeout: 20000 });
  await settle(again.page);
  assert.equal(await again.page.$eval('#command-values', (n) => n.value), '0, 0.2, 0.5, 1');
  assert.equal(await again.page.$eval('#command-samplePeriod', (n) => n.value), '0.1');
  assert.equal(await again.page.$eval('#command-interpolation', (n) => n.value), 'hold');
  assert.equal(await again.page.$eval('#command-view', (n) => n.hidden), true);
  assert.equal((await canvasInfo(again.page, 'response-chart')).hash, (await canvasInfo(page, 'response-chart')).hash);
  await again.page.screenshot({ path: `${SCREENSHOTS}command-sampled-1280x800.png`, fullPage: true });
  assert.deepEqual(again.problems, []);
  await again.page.close();
  assert.deepEqual(problems, []);
  await page.close();
});
