// End-to-end: the built page in headless Chromium. Numbers in the DOM against the closed
// forms, pixels on the canvases, the error path, no console errors, and screenshots.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { openBrowser, canvasInfo, type, SCREENSHOTS } from './browser.mjs';

let env;
before(async () => { env = await openBrowser(); });
after(async () => { await env?.close(); });

/** ZVD with damping, Singhose 2009 eq. 17 — computed here independently of the wasm. */
function zvd(f, z) {
  const k = Math.exp((-z * Math.PI) / Math.sqrt(1 - z * z));
  const td = 1 / (f * Math.sqrt(1 - z * z));
  const d = (1 + k) ** 2;
  return [[0, 1 / d], [td / 2, (2 * k) / d], [td, (k * k) / d]];
}

async function impulseRows(page) {
  return page.$$eval('#impulses tbody tr', (rows) => rows.map((r) => [...r.cells].slice(1).map((c) => Number(c.textContent))));
}

test('the default page shows the ZVD shaper of the closed form and draws both charts', async () => {
  const { page, problems } = await env.page();
  const rows = await impulseRows(page);
  const want = zvd(2, 0.05);
  assert.equal(rows.length, 3);
  rows.forEach(([t, a], i) => {
    assert.ok(Math.abs(t - want[i][0]) < 1e-6, `time ${i}: ${t} vs ${want[i][0]}`);
    assert.ok(Math.abs(a - want[i][1]) < 1e-6, `amplitude ${i}: ${a} vs ${want[i][1]}`);
  });
  assert.equal(await page.textContent('#duration'), `${Number(want[2][0].toPrecision(6))} s`);
  assert.equal(await page.isVisible('#derivatives'), false, 'n is only asked for ZV-Dⁿ');
  for (const id of ['impulses-chart', 'sensitivity-chart']) {
    const info = await canvasInfo(page, id);
    assert.ok(info.ink > 2000, `${id} has ink: ${info.ink} px of ${info.width}x${info.height}`);
  }
  await page.screenshot({ path: `${SCREENSHOTS}default-1280x800.png`, fullPage: true });
  assert.deepEqual(problems, []);
  await page.close();
});

test('changing the mode and family changes the numbers as the core predicts', async () => {
  const { page, problems } = await env.page();
  await page.selectOption('#family', 'zv');
  await type(page, 'frequency', 10);
  await type(page, 'damping', 0);
  await page.waitForFunction(() => document.querySelectorAll('#impulses tbody tr').length === 2);
  const rows = await impulseRows(page);
  assert.deepEqual(rows, [[0, 0.5], [0.05, 0.5]]);
  // ZV at ζ = 0: I(5 %) = 2 − 4·acos(0.05)/π = 0.06369 (Singhose 2009 Fig. 7: 0.06).
  assert.equal(await page.textContent('#insensitivity'), '0.06369');
  assert.match(await page.textContent('#omega'), /62\.832 rad\/s/);
  await page.selectOption('#family', 'zvdn');
  assert.equal(await page.isVisible('#derivatives'), true);
  await type(page, 'derivatives', 4);
  await page.waitForFunction(() => document.querySelectorAll('#impulses tbody tr').length === 6);
  assert.deepEqual(problems, []);
  await page.close();
});

test('a bad value shows a message at its field and keeps the last good result', async () => {
  const { page, problems } = await env.page();
  const before = {
    imp: await canvasInfo(page, 'impulses-chart'),
    sens: await canvasInfo(page, 'sensitivity-chart'),
    rows: await impulseRows(page),
  };
  await type(page, 'damping', 1.5);
  const message = await page.textContent('#damping-error');
  assert.match(message, /damping/);
  assert.match(message, /1\.5/);
  assert.equal(await page.getAttribute('#damping', 'aria-invalid'), 'true');
  assert.equal(await page.textContent('#frequency-error'), '');
  assert.deepEqual(await impulseRows(page), before.rows);
  assert.equal((await canvasInfo(page, 'impulses-chart')).hash, before.imp.hash);
  assert.equal((await canvasInfo(page, 'sensitivity-chart')).hash, before.sens.hash);
  await page.screenshot({ path: `${SCREENSHOTS}error-1280x800.png`, fullPage: true });

  await type(page, 'frequency', -4);
  assert.match(await page.textContent('#frequency-error'), /greater than 0/);
  await type(page, 'frequency', '');
  assert.match(await page.textContent('#frequency-error'), /finite/);
  await type(page, 'frequency', 2);
  await type(page, 'damping', 0.05);
  assert.equal(await page.textContent('#damping-error'), '');
  assert.equal(await page.getAttribute('#damping', 'aria-invalid'), null);
  await type(page, 'vtol', 150);
  assert.match(await page.textContent('#vtol-error'), /below 1/);
  assert.deepEqual(problems, [], 'errors are shown on the page, not thrown');
  await page.close();
});

test('the page works at phone size', async () => {
  const { page, problems } = await env.page({ width: 390, height: 844 });
  const info = await canvasInfo(page, 'sensitivity-chart');
  assert.ok(info.ink > 1000);
  await page.screenshot({ path: `${SCREENSHOTS}phone-390x844.png`, fullPage: true });
  assert.deepEqual(problems, []);
  await page.close();
});
