// End-to-end, issue 24 item 2: six modes with four convolved shapers (ZV, ZVD, ZVDD and
// ZV-D³: 64, 729, 4096 and 5⁶ = 15 625 impulses) draw. ZV-D³ over six modes is past the
// 4096-impulse limit of an expanded shaper: it stays factored, analysed and simulated from its
// factors, its impulses formed only for its table. Pixels on every chart, numbers in the DOM
// against closed forms computed here, no console errors.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { openBrowser, canvasInfo, settle, SCREENSHOTS } from './browser.mjs';

let env;
before(async () => { env = await openBrowser(); });
after(async () => { await env?.close(); });

const FREQS = [1.2, 3.4, 7.9, 13, 21, 34];
const Z = 0.02;
const STATE = {
  modes: FREQS.map((f) => ({ frequencyHz: f, damping: Z })),
  shapers: [{ family: 'zv' }, { family: 'zvd' }, { family: 'zvdd' }, { family: 'zvdn', derivatives: 3 }],
  view: { vtol: 0.05, mismatch: 1.1, mapShaper: 3 },
};

/** Damped period of a mode, s. */
const td = (f) => 1 / (f * Math.sqrt(1 - Z * Z));
/** K = e^{−ζπ/√(1−ζ²)}. */
const K = Math.exp((-Z * Math.PI) / Math.sqrt(1 - Z * Z));

test('six modes with ZV, ZVD, ZVDD and ZV-D³ (15 625 impulses, kept factored) draw every chart', async () => {
  const { page, problems } = await env.page({ hash: `#state=${encodeURIComponent(JSON.stringify(STATE))}` });
  await settle(page);
  const errors = await page.$$eval('.error', (e) => e.map((x) => x.textContent).filter(Boolean));
  assert.deepEqual(errors, []);
  assert.equal(await page.$eval('#general-error', (e) => e.textContent), '');
  // Durations: ZV-Dⁿ over one mode lasts (n+1)/2 damped periods; a convolution the sum.
  const s = await page.$$eval('#summary tbody tr', (rows) => Object.fromEntries(rows.map((r) => [r.cells[0].textContent, [...r.cells].slice(1).map((c) => c.textContent)])));
  const sum = FREQS.reduce((a, f) => a + td(f), 0);
  const durations = s['Duration (s)'].map(Number);
  assert.equal(durations.length, 4);
  [0.5, 1, 1.5, 2].forEach((periods, k) => {
    assert.ok(Math.abs(durations[k] - periods * sum) < 1e-5 * sum, `shaper ${k}: ${durations[k]} vs ${periods * sum}`);
  });
  // ZV-D³'s table: its first impulse, at t = 0, has amplitude Π 1/(1+K)⁴.
  const first = await page.$$eval('#impulses-3 tbody tr', (rows) => rows.slice(0, 1).map((r) => [...r.cells].slice(1).map((c) => Number(c.textContent)))[0]);
  const a0 = (1 / (1 + K) ** 4) ** 6;
  assert.equal(first[0], 0);
  assert.ok(Math.abs(first[1] - a0) < 1e-6 * a0 + 1e-12, `${first[1]} vs ${a0}`);
  const ids = await page.$$eval('.charts canvas', (c) => c.map((x) => x.id).filter(Boolean));
  assert.ok(ids.length >= 6, ids.join());
  for (const id of ids) {
    const info = await canvasInfo(page, id);
    assert.ok(info.ink > 500, `${id} has ink: ${info.ink} px of ${info.width}x${info.height}`);
  }
  // An edit of a mode redesigns all four; still drawn, still no error.
  await page.evaluate(() => { const pg = window.__playground; pg.state.modes[5].frequencyHz = 33; pg.update(); });
  await settle(page);
  assert.deepEqual(await page.$$eval('.error', (e) => e.map((x) => x.textContent).filter(Boolean)), []);
  await page.screenshot({ path: `${SCREENSHOTS}six-modes-four-shapers.png`, fullPage: true });
  assert.deepEqual(problems, []);
  await page.close();
});

// The frame's shapers are handed to the page by a small function made with the `Function`
// constructor (crate/js/bulk.rs). A page served with a Content Security Policy that forbids it
// (`script-src 'self' 'wasm-unsafe-eval'`: wasm allowed, eval not) must get the same frame from
// serde's path: the same summary and impulse tables as without the policy, no error.
test('under a CSP that forbids eval, six modes give the same frame', async () => {
  const hash = `#state=${encodeURIComponent(JSON.stringify(STATE))}`;
  const tables = (page) => page.$$eval('#summary tbody tr, [id^="impulses-"] tbody tr',
    (rows) => rows.map((r) => r.textContent));
  const { page: plain } = await env.page({ hash });
  await settle(plain);
  const want = await tables(plain);
  await plain.close();
  const page = await env.browserPage();
  const problems = [];
  page.on('console', (m) => { if (m.type() === 'error') problems.push(`console: ${m.text()}`); });
  page.on('pageerror', (e) => problems.push(`pageerror: ${e.message}`));
  await page.route(/\/(index\.html)?$/, async (route) => {
    const response = await route.fetch();
    await route.fulfill({
      response,
      headers: { ...response.headers(), 'content-security-policy': "script-src 'self' 'wasm-unsafe-eval'" },
    });
  });
  await page.addInitScript(() => {
    window.__violations = [];
    document.addEventListener('securitypolicyviolation', (e) => window.__violations.push(e.blockedURI));
  });
  const response = await page.goto(env.url + hash);
  assert.equal(response.headers()['content-security-policy'], "script-src 'self' 'wasm-unsafe-eval'");
  await page.waitForSelector('body[data-ready="true"]', { timeout: 20000 });
  await settle(page);
  // The policy is in force: the module's `new Function` was refused (and said so on the console).
  assert.ok((await page.evaluate(() => window.__violations)).includes('eval'), 'eval refused');
  assert.ok(want.length > 20, `${want.length} rows`);
  assert.deepEqual(await tables(page), want);
  assert.deepEqual(problems.filter((p) => !/unsafe-eval/.test(p)), []);
  await page.close();
});
