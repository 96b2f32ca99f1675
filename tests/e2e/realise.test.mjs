// End-to-end: the realisation view (issue 23, item 1) in headless Chromium. The summary line's
// V at the mode against the JS API's `realizeShaper` (the library's pkg/, not the page's module)
// and against a closed form computed here (Marlin FT_MOTION's ZV: the echo on the 1 ms grid),
// pixels on the realisation chart, the state in the URL, a bad period named at its field with
// the last good view kept, no console errors, and a screenshot.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { openBrowser, canvasInfo, type, settle, SCREENSHOTS } from './browser.mjs';
import { PRESETS, toHash } from '../../web/state.js';

let env;
before(async () => { env = await openBrowser(); });
after(async () => { await env?.close(); });

const printer = PRESETS.find((p) => p.id === 'printer');

/** The page at `state`, with the realisation view drawn. */
async function open(state) {
  const opened = await env.page({ hash: toHash(state) });
  await opened.page.waitForSelector('#realisation:not([hidden])', { timeout: 20000 });
  await settle(opened.page);
  return opened;
}

/** The summary line of shaper k (the library's text after the "on …, as …: " head). */
const summaryOf = (page, k) => page.$eval(`#realisation-summary li[data-shaper="${k}"] .realisation-text`, (n) => n.textContent);

/** The realisation table as { rowName: [cell per realised shaper] }. */
const table = (page) => page.$$eval('#realisation-table tbody tr', (rows) => Object.fromEntries(rows.map((r) => [r.cells[0].textContent, [...r.cells].slice(1).map((c) => c.textContent)])));

/** `realizeShaper` of the library's JS API (pkg/input_shaping.js), run in the page. */
function realize(page, spec, options) {
  return page.evaluate(async ([s, o]) => {
    const api = await import('/pkg/input_shaping.js');
    await api.default({ module_or_path: '/pkg/input_shaping_bg.wasm' });
    const r = api.realizeShaper(s, o);
    return { summary: r.summary, modes: r.modes, realised: r.realised };
  }, [spec, options]);
}

/** Residual vibration of impulses [[t, A]] at f Hz, ζ (Singhose 2009 eq. 11), computed here. */
function residual(impulses, f, z) {
  const w = 2 * Math.PI * f;
  const wd = w * Math.sqrt(1 - z * z);
  const tn = impulses.at(-1)[0];
  let c = 0;
  let s = 0;
  for (const [t, a] of impulses) {
    const e = a * Math.exp(z * w * (t - tn));
    c += e * Math.cos(wd * t);
    s += e * Math.sin(wd * t);
  }
  return Math.hypot(c, s);
}

test('the printer preset: FT_MOTION moves the ZV echo to the 1 ms grid; the line says V as realizeShaper does', async () => {
  const { page, problems, fetched } = await open(printer.state);
  // Shaper 1: ZV at 48 Hz, ζ = 0.07 on FT_MOTION. Its echo at half the damped period, 10.44 ms,
  // is rounded to 10 ms (Ni[1] = LROUND(…·FTM_FS), Marlin ft_motion/shaping.cpp); amplitudes
  // 1/(1+K), K/(1+K) with K = e^(−ζπ/√(1−ζ²)).
  const [f, z] = [48, 0.07];
  const k = Math.exp((-z * Math.PI) / Math.sqrt(1 - z * z));
  const want = residual([[0, 1 / (1 + k)], [0.010, k / (1 + k)]], f, z);
  const line = await summaryOf(page, 0);
  assert.match(line, /^times rounded to 1 ms: the 48 Hz ZV acts as a 50\.1 Hz one, V = (\d+\.\d) % at the mode$/);
  const shownV = Number(/V = (\d+\.\d) %/.exec(line)[1]);
  assert.equal(shownV, Number((want * 100).toFixed(1)), `closed form ${want * 100} %`);
  const lib = await realize(page, { ...printer.state.shapers[0], realise: undefined, modes: printer.state.modes },
    { firmware: 'marlinFtMotion', vtol: 0.05 });
  assert.equal(line, lib.summary);
  assert.ok(Math.abs(lib.modes[0].vibrationRealised - want) < 1e-12, `${lib.modes[0].vibrationRealised} vs ${want}`);
  const t = await table(page);
  assert.equal(t['V at mode 1 (48 Hz), designed → run (%)'][0], `≈ 0 → ${Number((want * 100).toPrecision(3))}`);
  assert.equal(t['Duration (ms), designed → run'][0], `${Number((500 / (f * Math.sqrt(1 - z * z))).toPrecision(5))} → 10`);
  // Shaper 3: Klipper runs its own EI; the line is the library's.
  const ei = await realize(page, { family: 'ei', vtol: 0.05, modes: printer.state.modes }, { firmware: 'klipper', vtol: 0.05 });
  assert.equal(await summaryOf(page, 2), ei.summary);
  assert.match(ei.summary, /Klipper's own EI/);
  const info = await canvasInfo(page, 'realisation-chart');
  assert.ok(info.ink > 3000, `realisation chart has ink: ${info.ink} px of ${info.width}x${info.height}`);
  assert.ok(fetched.some((p) => p.endsWith('/pkg/page/realise_view.js')), 'the view was fetched');
  await page.screenshot({ path: `${SCREENSHOTS}realise-printer-1280x800.png`, fullPage: true });
  assert.deepEqual(problems, []);
  await page.close();
});

test('the default page does not fetch the view; choosing a controller fetches and draws it, the URL keeps it', async () => {
  const { page, problems, fetched } = await env.page();
  await settle(page);
  assert.ok(!fetched.some((p) => p.includes('realise_view') || p.includes('recording')), `first load fetched ${fetched.join(', ')}`);
  assert.equal(await page.$eval('#realisation', (n) => n.hidden), true);
  await page.selectOption('#shaper-0-realise', 'generic');
  await page.waitForSelector('#shaper-0-realise-periodS');
  await type(page, 'shaper-0-realise-periodS', '0.05');
  await type(page, 'shaper-0-realise-amplitudeSteps', '8');
  await page.waitForSelector('#realisation:not([hidden])', { timeout: 20000 });
  await settle(page);
  const line = await summaryOf(page, 0);
  // ZVD at 2 Hz, ζ = 0.05: echoes at 0.2503 and 0.5006 s, rounded to 0.25 and 0.5 s.
  const lib = await realize(page, { family: 'zvd', modes: [{ frequencyHz: 2, damping: 0.05 }] },
    { firmware: 'generic', periodS: 0.05, amplitudeSteps: 8, vtol: 0.05 });
  assert.equal(line, lib.summary);
  assert.deepEqual(lib.realised.impulses.map((i) => i.time), [0, 0.25, 0.5]);
  assert.ok(lib.realised.impulses.every((i) => Number.isInteger(i.amplitude * 8)), 'amplitudes on 1/8');
  const hash = await page.evaluate(() => location.hash);
  const state = JSON.parse(decodeURIComponent(hash.slice('#state='.length)));
  assert.deepEqual(state.shapers[0].realise, { firmware: 'generic', periodS: 0.05, amplitudeSteps: 8 });
  const before = await canvasInfo(page, 'realisation-chart');
  assert.ok(before.ink > 2000, `ink ${before.ink}`);
  // The link, opened fresh, shows the same fields and the same line.
  const again = await env.page({ hash });
  await again.page.waitForSelector('#realisation:not([hidden])', { timeout: 20000 });
  await settle(again.page);
  assert.equal(await again.page.$eval('#shaper-0-realise', (n) => n.value), 'generic');
  assert.equal(await again.page.$eval('#shaper-0-realise-periodS', (n) => n.value), '0.05');
  assert.equal(await again.page.$eval('#shaper-0-realise-amplitudeSteps', (n) => n.value), '8');
  assert.equal(await summaryOf(again.page, 0), line);
  assert.deepEqual(again.problems, []);
  await again.page.close();

  // A bad period: its message at the field, the last good line and chart kept.
  await type(page, 'shaper-0-realise-periodS', '-0.01');
  await settle(page);
  const message = await page.$eval('#shaper-0-realise-periodS', (n) => n.closest('.field').querySelector('.error').textContent);
  assert.match(message, /periodS/, message);
  assert.equal(await page.$eval('#shaper-0-realise-periodS', (n) => n.getAttribute('aria-invalid')), 'true');
  assert.equal(await summaryOf(page, 0), line);
  assert.equal((await canvasInfo(page, 'realisation-chart')).hash, before.hash);
  // Fixed again: the message goes.
  await type(page, 'shaper-0-realise-periodS', '0.02');
  await settle(page);
  assert.equal(await page.$eval('#shaper-0-realise-periodS', (n) => n.closest('.field').querySelector('.error').textContent), '');
  assert.notEqual(await summaryOf(page, 0), line);
  // Back to ideal: the view goes, the state loses the realisation.
  await page.selectOption('#shaper-0-realise', 'ideal');
  await settle(page);
  assert.equal(await page.$eval('#realisation', (n) => n.hidden), true);
  assert.ok(!(await page.evaluate(() => location.hash)).includes('realise'));
  await page.screenshot({ path: `${SCREENSHOTS}realise-default-1280x800.png`, fullPage: true });
  assert.deepEqual(problems, []);
  await page.close();
});

test('a firmware that cannot run the design says so at the controller field', async () => {
  // Klipper has no ZVDD and no custom shaper (shaper_defs.py): refused, named at the field.
  const state = structuredClone(printer.state);
  state.shapers = [{ family: 'zv', realise: { firmware: 'marlin' } }, { family: 'zvdd', realise: { firmware: 'klipper' } }];
  const { page, problems } = await open(state);
  const message = await page.$eval('#shaper-1-realise', (n) => n.closest('.field').querySelector('.error').textContent);
  assert.match(message, /Klipper has no 'zvdd' shaper/, message);
  assert.match(await summaryOf(page, 0), /V = /);
  assert.equal(await page.$$eval('#realisation-summary li', (l) => l.length), 1);
  assert.deepEqual(problems, []);
  await page.close();
});
