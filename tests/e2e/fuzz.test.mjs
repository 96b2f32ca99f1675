// Reliability of the page (issue 6): random strings typed into every input and random URL
// hashes never cause an uncaught exception or console error, never blank the page, and the
// last good charts stay. Seeded, so a failure replays; FUZZ_STEPS=5000 npm run test:e2e for a
// longer run.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { openBrowser, canvasInfo } from './browser.mjs';

const STEPS = Number(process.env.FUZZ_STEPS ?? 150);
const SEED = Number(process.env.FUZZ_SEED ?? 20261122);

/** Mulberry32: a tiny deterministic PRNG. */
function rng(seed) {
  let a = seed >>> 0;
  return () => {
    a = (a + 0x6d2b79f5) >>> 0;
    let t = a;
    t = Math.imul(t ^ (t >>> 15), t | 1);
    t ^= t + Math.imul(t ^ (t >>> 7), t | 61);
    return ((t ^ (t >>> 14)) >>> 0) / 4294967296;
  };
}

const NASTY = ['', ' ', '-', '.', 'e', '1e309', '-1e309', 'NaN', 'Infinity', '-0', '0', '1e-320', '9'.repeat(400),
  '<script>alert(1)</script>', '"><img src=x onerror=alert(1)>', '${x}', '1,2,3', '0.9999999999', '1', '-5', '3.5e2',
  '٣', '🙂', '\u0000', '1'.repeat(20), '0x10', '  42  '];

function randomText(r) {
  if (r() < 0.6) return NASTY[Math.floor(r() * NASTY.length)];
  if (r() < 0.5) return String((r() - 0.3) * 10 ** Math.floor(r() * 8 - 3));
  const n = Math.floor(r() * 12);
  return Array.from({ length: n }, () => String.fromCharCode(32 + Math.floor(r() * 95))).join('');
}

function randomHash(r) {
  const kinds = [
    () => `#state=${encodeURIComponent(randomText(r))}`,
    () => `#${randomText(r)}`,
    () => `#state=${encodeURIComponent(JSON.stringify({ modes: [{ frequencyHz: randomText(r), damping: r() }], shapers: [{ family: 'zv' }] }))}`,
    () => `#state=${encodeURIComponent(JSON.stringify({ modes: Array.from({ length: Math.floor(r() * 9) }, () => ({ frequencyHz: r() * 100, damping: r() })), shapers: [{ family: ['zv', 'zvd', 'nope', 'zvdn'][Math.floor(r() * 4)], derivatives: Math.floor(r() * 60) }], view: { vtol: r() } }))}`,
    () => `#state=%E0%A4%A`,
  ];
  return kinds[Math.floor(r() * kinds.length)]();
}

let env;
before(async () => { env = await openBrowser(); });
after(async () => { await env?.close(); });

test(`${STEPS} random inputs and hashes: no exception, never blank, last good result kept`, async () => {
  const { page, problems } = await env.page();
  await page.evaluate(() => {
    window.__alerts = 0;
    window.alert = () => { window.__alerts += 1; };
  });
  const r = rng(SEED);
  for (let step = 0; step < STEPS; step++) {
    if (r() < 0.15) {
      await page.evaluate((h) => { location.hash = h; }, randomHash(r));
    } else if (r() < 0.1) {
      const buttons = await page.$$('button:not([disabled]):not(#copy-link):not(#export-copy):not(#save-state):not(#export-download):visible');
      if (buttons.length) await buttons[Math.floor(r() * buttons.length)].click();
    } else {
      // Only what a person can reach: the measured-data view's controls are hidden until it opens.
      const inputs = await page.$$('input[type=number]:visible, input[type=text]:visible, select:visible, textarea:not([readonly]):visible');
      const input = inputs[Math.floor(r() * inputs.length)];
      const tag = await input.evaluate((e) => e.tagName);
      if (tag === 'SELECT') {
        const values = await input.evaluate((e) => [...e.options].map((o) => o.value));
        await input.selectOption(values[Math.floor(r() * values.length)]);
      } else {
        await input.evaluate((e, v) => { e.value = v; e.dispatchEvent(new Event('input', { bubbles: true })); }, randomText(r));
      }
    }
    if (step % 10 === 9) {
      await page.evaluate(() => new Promise((res) => requestAnimationFrame(() => requestAnimationFrame(res))));
      assert.deepEqual(problems, [], `step ${step}`);
      // Never blank: both charts keep their ink and the impulse table has rows.
      assert.ok((await canvasInfo(page, 'impulses-chart')).ink > 500, `impulse chart blank at step ${step}`);
      assert.ok((await canvasInfo(page, 'sensitivity-chart')).ink > 500, `sensitivity chart blank at step ${step}`);
      assert.ok((await page.$$('#impulses-0 tbody tr')).length >= 1, `impulse table empty at step ${step}`);
    }
  }
  assert.equal(await page.evaluate(() => window.__alerts), 0, 'no injected script ran');
  assert.equal(await page.$('img[src="x"]'), null);
  // The page still works: a valid state loads and computes.
  await page.evaluate(() => { location.hash = '#state=' + encodeURIComponent(JSON.stringify({ modes: [{ frequencyHz: 2, damping: 0 }], shapers: [{ family: 'zv' }], view: { vtol: 0.05, scv: 5 } })); });
  await page.waitForFunction(() => document.querySelector('#impulses-0 tbody tr:nth-child(2) td:nth-child(2)')?.textContent === '0.25');
  assert.deepEqual(problems, []);
  await page.close();
});

// Every input, select and textarea on the page, one by one (the random walk above may miss
// some): nasty strings typed into each, every option of each select chosen. After each: no
// console error or uncaught exception, charts not blank, and whenever the page shows an error
// (a field marked aria-invalid or an error message) the impulse table is exactly what it was
// before that input — the last good result is kept.
const SWEEP = ['NaN', '', '-1', '1e309', 'abc', '0', '<b>x</b>', '1e-320', '-0', '99999999'];

async function frame(page) {
  await page.evaluate(() => new Promise((res) => requestAnimationFrame(() => requestAnimationFrame(res))));
}

async function tableText(page) {
  return page.evaluate(() => document.querySelector('#impulses-0')?.textContent ?? '');
}

async function errorShown(page) {
  return page.evaluate(() => document.querySelector('[aria-invalid="true"]') !== null
    || [...document.querySelectorAll('.error, .group-error, #general-error')].some((e) => e.textContent.trim() !== ''));
}

test('every input and select, one by one: errors shown next to it, last good result kept', async () => {
  const { page, problems } = await env.page();
  // Two good states, alternated so that every reset really changes the hash (and reloads).
  const good = (k) => '#state=' + encodeURIComponent(JSON.stringify({ modes: [{ frequencyHz: k % 2 ? 2 : 2.5, damping: 0.05 }], shapers: [{ family: 'zvd' }], view: { vtol: 0.05, scv: 5 } }));
  let resets = 0;
  let errorsSeen = 0;
  const selector = 'input:not([type=file]):not([type=hidden]):not([readonly]), select, textarea:not([readonly])';
  const count = (await page.$$(selector)).length;
  let visible = 0;
  for (const e of await page.$$(selector)) if (await e.isVisible()) visible++;
  assert.ok(visible >= 4, `only ${visible} visible inputs found`);
  let touched = 0;
  for (let i = 0; i < count; i++) {
    for (const text of SWEEP) {
      await page.evaluate((h) => { location.hash = h; }, good(resets++));
      await frame(page);
      const inputs = await page.$$(selector);
      if (i >= inputs.length) break;
      const input = inputs[i];
      if (!(await input.isVisible())) break;
      if (text === SWEEP[0]) touched++;
      const before = await tableText(page);
      const tag = await input.evaluate((e) => e.tagName);
      const kind = await input.evaluate((e) => e.type);
      if (tag === 'SELECT') {
        const values = await input.evaluate((e) => [...e.options].map((o) => o.value));
        await input.selectOption(values[SWEEP.indexOf(text) % values.length]);
      } else if (kind === 'checkbox' || kind === 'radio') {
        await input.click();
      } else {
        await input.evaluate((e, v) => { e.value = v; e.dispatchEvent(new Event('input', { bubbles: true })); e.dispatchEvent(new Event('change', { bubbles: true })); }, text);
      }
      await frame(page);
      assert.deepEqual(problems, [], `input ${i} (${tag} ${kind}) with ${JSON.stringify(text)}`);
      assert.ok((await canvasInfo(page, 'impulses-chart')).ink > 500, `impulse chart blank after input ${i}`);
      assert.ok((await canvasInfo(page, 'sensitivity-chart')).ink > 500, `sensitivity chart blank after input ${i}`);
      if (await errorShown(page)) {
        errorsSeen++;
        assert.equal(await tableText(page), before, `input ${i} (${tag}) = ${JSON.stringify(text)}: error shown but the result changed`);
      }
      if (tag === 'SELECT' || kind === 'checkbox' || kind === 'radio') break;
    }
  }
  assert.ok(touched >= visible, `touched ${touched} of ${visible} visible inputs`);
  // The sweep must have provoked errors (NaN, '', 1e309 in number fields), or it checked nothing.
  assert.ok(errorsSeen >= visible, `only ${errorsSeen} errors shown over ${visible} inputs`);
  console.log(`# sweep: ${touched} inputs, ${errorsSeen} errors shown, last good result kept each time`);
  await page.close();
});
