// End-to-end: the built page in headless Chromium. Numbers in the DOM against closed forms
// computed here (independently of the wasm), pixels on the canvases, the error paths, the URL
// state, exports, no console errors, and screenshots.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { openBrowser, canvasInfo, type, settle, SCREENSHOTS } from './browser.mjs';
import { PRESETS } from '../../web/state.js';

let env;
before(async () => { env = await openBrowser(); });
after(async () => { await env?.close(); });

/** ZVD with damping, Singhose 2009 eq. 17. */
function zvd(f, z) {
  const k = Math.exp((-z * Math.PI) / Math.sqrt(1 - z * z));
  const td = 1 / (f * Math.sqrt(1 - z * z));
  const d = (1 + k) ** 2;
  return [[0, 1 / d], [td / 2, (2 * k) / d], [td, (k * k) / d]];
}

/** Every row of impulse table k (pressing its "Show all" first if it shows only 20). */
async function impulseRows(page, k = 0) {
  await page.evaluate((id) => document.querySelector(`#${id} tfoot:not([hidden]) button[aria-expanded="false"]`)?.click(), `impulses-${k}`);
  return shownImpulseRows(page, k);
}

/** The rows impulse table k shows, as they are. */
async function shownImpulseRows(page, k = 0) {
  return page.$$eval(`#impulses-${k} tbody tr`, (rows) => rows.map((r) => [...r.cells].slice(1).map((c) => Number(c.textContent))));
}

/** The numbers table as { rowName: [cell per shaper] }. */
async function summary(page) {
  return page.$$eval('#summary tbody tr', (rows) => Object.fromEntries(rows.map((r) => [r.cells[0].textContent, [...r.cells].slice(1).map((c) => c.textContent)])));
}


test('the default page shows the ZVD shaper of the closed form and draws both charts', async () => {
  const { page, problems } = await env.page();
  const rows = await impulseRows(page);
  const want = zvd(2, 0.05);
  assert.equal(rows.length, 3);
  rows.forEach(([t, a], i) => {
    assert.ok(Math.abs(t - want[i][0]) < 1e-9, `time ${i}: ${t} vs ${want[i][0]}`);
    assert.ok(Math.abs(a - want[i][1]) < 1e-9, `amplitude ${i}: ${a} vs ${want[i][1]}`);
  });
  const s = await summary(page);
  assert.deepEqual(s['Duration (s)'], [String(Number(want[2][0].toPrecision(6)))]);
  assert.deepEqual(s['Duration (damped periods of mode 1)'], ['1']);
  for (const id of ['impulses-chart', 'sensitivity-chart']) {
    const info = await canvasInfo(page, id);
    assert.ok(info.ink > 2000, `${id} has ink: ${info.ink} px of ${info.width}x${info.height}`);
  }
  await page.screenshot({ path: `${SCREENSHOTS}default-1280x800.png`, fullPage: true });
  assert.deepEqual(problems, []);
  await page.close();
});

test('every element id on the page is unique (two canvases once shared one)', async () => {
  const { page, problems } = await env.page();
  const ids = await page.$$eval('[id]', (nodes) => nodes.map((n) => n.id));
  const repeated = [...new Set(ids.filter((id, i) => ids.indexOf(id) !== i))];
  assert.deepEqual(repeated, [], `repeated ids: ${repeated.join(', ')}`);
  assert.ok(ids.includes('spectrum-chart') && ids.includes('measured-spectrum-chart'));
  assert.deepEqual(problems, []);
  await page.close();
});

test('changing a mode and the family changes the numbers as the core predicts', async () => {
  const { page, problems } = await env.page();
  await page.selectOption('#shaper-0-family', 'zv');
  await type(page, 'mode-0-frequency', 10);
  await type(page, 'mode-0-damping', 0);
  await settle(page);
  assert.deepEqual(await impulseRows(page), [[0, 0.5], [0.05, 0.5]]);
  // ZV at ζ = 0: I(5 %) = 2 − 4·acos(0.05)/π = 0.06369 (Singhose 2009 Fig. 7: 0.06).
  const s = await summary(page);
  assert.deepEqual(s['Insensitivity I(5 %)'], ['0.06369']);
  assert.match(await page.textContent('.mode output'), /62\.832 rad\/s/);
  await page.selectOption('#shaper-0-family', 'zvdn');
  assert.equal(await page.isVisible('#shaper-0-derivatives'), true);
  await type(page, 'shaper-0-derivatives', 4);
  await settle(page);
  assert.equal((await impulseRows(page)).length, 6);
  assert.deepEqual(problems, []);
  await page.close();
});

test('a long impulse table shows its first 20 rows until "Show all" is pressed', async () => {
  const { page, problems } = await env.page();
  await page.selectOption('#shaper-0-family', 'zvdn');
  await type(page, 'shaper-0-derivatives', 24);
  await settle(page);
  // ZV-D²⁴ at 2 Hz, ζ 0.05: 26 impulses, A_i = C(25, i)·Kⁱ/(1 + K)²⁵ at i·Td/2 — the
  // two-impulse solution of Singer & Seering 1988 eq. 6 (1/(1 + K), K/(1 + K) at 0, Td/2)
  // convolved with itself 25 times, which zeroes the first 24 derivatives of eq. 6 (their
  // eq. 8); their ZVD and ZVDD are the cases of 2 and 3 factors.
  const [f, z] = [2, 0.05];
  const K = Math.exp((-z * Math.PI) / Math.sqrt(1 - z * z));
  const td = 1 / (f * Math.sqrt(1 - z * z));
  const choose = (n, k) => { let c = 1; for (let j = 1; j <= k; j++) c = (c * (n - k + j)) / j; return c; };
  const want = Array.from({ length: 26 }, (_, i) => [(i * td) / 2, (choose(25, i) * K ** i) / (1 + K) ** 25]);
  const check = (rows) => rows.forEach(([t, a], i) => {
    assert.ok(Math.abs(t - want[i][0]) < 1e-9, `time ${i}: ${t} vs ${want[i][0]}`);
    assert.ok(Math.abs(a - want[i][1]) < 1e-9 * Math.max(1, want[i][1]), `amplitude ${i}: ${a} vs ${want[i][1]}`);
  });
  assert.deepEqual((await summary(page))['Impulses'], ['26']);
  const button = page.locator('#impulses-0 tfoot button');
  assert.equal(await button.textContent(), 'Show all 26 impulses');
  assert.equal(await button.getAttribute('aria-expanded'), 'false');
  let rows = await shownImpulseRows(page);
  assert.equal(rows.length, 20);
  check(rows);
  // Keyboard alone: focus the button and press Enter.
  await button.focus();
  await page.keyboard.press('Enter');
  rows = await shownImpulseRows(page);
  assert.equal(rows.length, 26);
  check(rows);
  assert.equal(await button.textContent(), 'Show the first 20');
  assert.equal(await button.getAttribute('aria-expanded'), 'true');
  // Expanded, the table follows edits; collapsed again, 20 rows.
  await type(page, 'mode-0-frequency', 4);
  await settle(page);
  rows = await shownImpulseRows(page);
  assert.equal(rows.length, 26);
  assert.ok(Math.abs(rows[25][0] - want[25][0] / 2) < 1e-9, `last impulse at ${rows[25][0]}`);
  await button.click();
  assert.equal((await shownImpulseRows(page)).length, 20);
  // A short sequence has no button.
  await type(page, 'shaper-0-derivatives', 2);
  await settle(page);
  assert.equal((await shownImpulseRows(page)).length, 4);
  assert.equal(await page.isVisible('#impulses-0 tfoot'), false);
  assert.deepEqual(problems, []);
  await page.close();
});

test('modes can be added and removed, shapers compared', async () => {
  const { page, problems } = await env.page();
  await page.click('#add-mode');
  await settle(page);
  assert.equal(await page.locator('.mode').count(), 2);
  // Two modes by convolution: ZVD ⊗ ZVD = 9 impulses (Singer & Seering 1988 §2.3).
  assert.equal((await impulseRows(page)).length, 9);
  const s = await summary(page);
  assert.ok('Insensitivity I(5 %) at mode 2' in s);
  await page.click('#add-shaper');
  await settle(page);
  assert.equal(await page.locator('.shaper').count(), 2);
  assert.equal((await summary(page))['Impulses'].length, 2);
  for (let i = 0; i < 4; i++) await page.click('#add-mode').catch(() => {});
  assert.equal(await page.locator('.mode').count(), 6);
  assert.equal(await page.isDisabled('#add-mode'), true);
  await page.click('button[aria-label="Remove mode 6"]');
  await page.click('button[aria-label="Remove mode 5"]');
  await page.click('button[aria-label="Remove mode 4"]');
  await page.click('button[aria-label="Remove mode 3"]');
  await page.click('button[aria-label="Remove mode 2"]');
  await settle(page);
  assert.equal(await page.locator('.mode').count(), 1);
  assert.equal(await page.isDisabled('button[aria-label="Remove mode 1"]'), true);
  await page.screenshot({ path: `${SCREENSHOTS}compare-1280x800.png`, fullPage: true });
  assert.deepEqual(problems, []);
  await page.close();
});

test('every family is selectable and draws', async () => {
  const { page, problems } = await env.page();
  const names = await page.$$eval('#shaper-0-family option', (o) => o.map((x) => x.value));
  assert.ok(names.length >= 4, names.join());
  for (const name of names) {
    await page.selectOption('#shaper-0-family', name);
    await settle(page);
    const errors = await page.$$eval('.error', (e) => e.map((x) => x.textContent).filter(Boolean));
    assert.deepEqual(errors, [], `family ${name} with its default parameters`);
    assert.ok((await impulseRows(page)).length >= 1, name);
    assert.ok((await canvasInfo(page, 'sensitivity-chart')).ink > 1000, name);
  }
  assert.deepEqual(problems, []);
  await page.close();
});

test('every preset loads and draws', async () => {
  const { page, problems } = await env.page();
  const ids = await page.$$eval('#preset option', (o) => o.map((x) => x.value).filter(Boolean));
  assert.ok(ids.length >= 3);
  for (const id of ids) {
    await page.selectOption('#preset', id);
    await settle(page);
    const errors = await page.$$eval('.error', (e) => e.map((x) => x.textContent).filter(Boolean));
    assert.deepEqual(errors, [], `preset ${id}`);
    assert.ok((await canvasInfo(page, 'impulses-chart')).ink > 1000, id);
    await page.screenshot({ path: `${SCREENSHOTS}preset-${id}.png`, fullPage: true });
  }
  assert.deepEqual(problems, []);
  await page.close();
});

/** Peláez & Singhose 2002's carrousel (0.5 Hz, ζ 0.002) and an SI shaper at Vtol 5 % sampled at
 * six frequencies over I = 0.7 ([0.325, 0.675] Hz), with ZVD beside it. */
const SI_STATE = {
  modes: [{ frequencyHz: 0.5, damping: 0.002 }],
  shapers: [{ family: 'si', vtol: 0.05, insensitivity: 0.7, sampleFrequenciesHz: [0.325, 0.395, 0.465, 0.535, 0.605, 0.675] }, { family: 'zvd' }],
};
/** The same problem solved by scipy SLSQP from random starts (benches/si_slsqp.py), an
 * independent design: t and A of its four impulses. */
const SI_SLSQP = [[0, 0.16417], [0.96332, 0.3381], [1.93253, 0.33631], [2.89507, 0.16142]];

function assertSlsqp(rows) {
  assert.equal(rows.length, 4, JSON.stringify(rows));
  rows.forEach(([t, a], i) => {
    assert.ok(Math.abs(t - SI_SLSQP[i][0]) < 2e-5, `time ${i}: ${t} vs ${SI_SLSQP[i][0]}`);
    assert.ok(Math.abs(a - SI_SLSQP[i][1]) < 2e-5, `amplitude ${i}: ${a} vs ${SI_SLSQP[i][1]}`);
  });
}

test('a solved family is designed by the design worker, whose module is fetched once, as the core designs it', async () => {
  const { page, problems, fetched } = await env.page();
  // The default page (ZVD) loads the page's module only.
  assert.ok(fetched.includes('/pkg/page/playground_bg.wasm'), fetched.join(' '));
  assert.ok(!fetched.some((f) => f.startsWith('/pkg/page/design')), fetched.join(' '));
  const before = await canvasInfo(page, 'impulses-chart');
  await page.evaluate((s) => { location.hash = `#state=${encodeURIComponent(JSON.stringify(s))}`; }, SI_STATE);
  await settle(page);
  assert.equal(fetched.filter((f) => f === '/pkg/page/designer_bg.wasm').length, 1, fetched.join(' '));
  assert.equal(fetched.filter((f) => f === '/pkg/page/playground_bg.wasm').length, 1, fetched.join(' '));
  assertSlsqp(await impulseRows(page, 0));
  assert.equal((await impulseRows(page, 1)).length, 3);
  const errors = await page.$$eval('.error', (e) => e.map((x) => x.textContent).filter(Boolean));
  assert.deepEqual(errors, []);
  assert.equal(await page.textContent('#general-error'), '');
  const after = await canvasInfo(page, 'impulses-chart');
  assert.ok(after.ink > 1000 && after.hash !== before.hash, 'the SI shaper is drawn');
  // Later edits use the worker already there: nothing is fetched again.
  const count = fetched.length;
  await type(page, 'mode-0-damping', 0.004);
  await settle(page);
  assert.deepEqual(fetched.slice(count), []);
  assert.equal((await impulseRows(page, 0)).length, 4);
  assert.deepEqual(problems, []);
  await page.close();
});

test('a link with a solved family draws with the page\'s module and adds the solved shaper when it is designed', async () => {
  const { page, problems, fetched } = await env.page({ hash: `#state=${encodeURIComponent(JSON.stringify(SI_STATE))}` });
  await settle(page);
  assert.ok(fetched.includes('/pkg/page/playground_bg.wasm'), fetched.join(' '));
  assert.ok(fetched.includes('/pkg/page/designer_bg.wasm'), fetched.join(' '));
  assertSlsqp(await impulseRows(page, 0));
  assert.equal(await page.textContent('#general-error'), '');
  // A 0.5 Hz shaper smooths more than Klipper's 0.12 mm target at any acceleration: Klipper's
  // max accel is 0, said in words.
  assert.deepEqual((await summary(page))['Klipper max accel, smoothing ≤ 0.12 mm (mm/s²)'], ['0 (none keeps smoothing ≤ 0.12 mm)', '0 (none keeps smoothing ≤ 0.12 mm)']);
  // The solver's report (`design`'s `solver`): this SI polished; the ZVD has none.
  assert.deepEqual((await summary(page))['Optimisation solver'], ['polished', '—']);
  await page.screenshot({ path: `${SCREENSHOTS}si-link-1280x800.png`, fullPage: true });
  // 1 and 3 Hz at I 0.5 (ζ 0.02, Vtol 5 %) falls back to the grid solution (tests/specified.rs,
  // the_design_report_says_whether_the_polish_converged): said in the table.
  const fallback = {
    modes: [{ frequencyHz: 1, damping: 0.02 }, { frequencyHz: 3, damping: 0.02 }],
    shapers: [{ family: 'si', vtol: 0.05, insensitivity: 0.5 }, { family: 'zvd' }],
  };
  await page.evaluate((s) => { location.hash = `#state=${encodeURIComponent(JSON.stringify(s))}`; }, fallback);
  await settle(page);
  await page.waitForFunction(() => document.getElementById('general-error').textContent === '', null, { timeout: 30000 })
    .catch(() => {});
  assert.deepEqual((await summary(page))['Optimisation solver'], ['grid solution (not polished)', '—']);
  assert.ok(Number((await summary(page)).Impulses[0]) > 30, JSON.stringify((await summary(page)).Impulses));
  // Back to a state without a solved family.
  await page.evaluate(() => { location.hash = `#state=${encodeURIComponent(JSON.stringify({ modes: [{ frequencyHz: 2, damping: 0.05 }], shapers: [{ family: 'zvd' }] }))}`; });
  await settle(page);
  assert.equal((await impulseRows(page, 0)).length, 3);
  assert.deepEqual(problems, []);
  await page.close();
});

test('if the designer\'s module cannot be fetched, the shaper says so, the last good result stays, and the next edit tries again', async () => {
  const { page, problems } = await env.page();
  const before = { imp: await canvasInfo(page, 'impulses-chart'), rows: await impulseRows(page) };
  await page.route('**/designer*', (r) => r.abort());
  await page.evaluate((s) => { location.hash = `#state=${encodeURIComponent(JSON.stringify(s))}`; }, SI_STATE);
  await settle(page);
  const message = await page.$$eval('.error', (e) => e.map((x) => x.textContent).filter(Boolean));
  assert.equal(message.length, 1, JSON.stringify(message));
  assert.match(message[0], /^shapers\[0\]: The optimisation solver could not be loaded \(.+\)$/);
  assert.equal((await canvasInfo(page, 'impulses-chart')).hash, before.imp.hash, 'the last good chart stays');
  assert.deepEqual(await impulseRows(page), before.rows, 'the last good numbers stay');
  await page.unroute('**/designer*');
  await type(page, 'mode-0-damping', 0.003);
  await settle(page);
  assert.deepEqual(await page.$$eval('.error', (e) => e.map((x) => x.textContent).filter(Boolean)), []);
  assert.equal((await impulseRows(page, 0)).length, 4);
  // The aborted requests are the only console errors.
  assert.deepEqual(problems.filter((p) => !/Failed to load resource|designer/.test(p)), []);
  await page.close();
});

test('dragging a mode keeps the other shapers live and ends with the solved shaper designed where it stopped', async (t) => {
  const pelaez = PRESETS.find((p) => p.id === 'pelaez').state;
  // The design worker's answers reach the page `window.__designDelayMs` late (0 until the drag):
  // a one-mode SI is designed in a few milliseconds, so without the delay a page that waited
  // on it would follow the drag as well as a live one, and the count would measure only how
  // loaded the machine is (a frame-counting version of this test drew 18 of 40 steps in one CI
  // run, 36 on a quiet machine).
  const init = () => {
    const Real = window.Worker;
    window.Worker = class extends Real {
      addEventListener(type, listener, options) {
        if (type !== 'message') return super.addEventListener(type, listener, options);
        return super.addEventListener(type, (e) => {
          const ms = window.__designDelayMs ?? 0;
          if (ms > 0) setTimeout(() => listener.call(this, e), ms);
          else listener.call(this, e);
        }, options);
      }
    };
  };
  const { page, problems } = await env.page({ hash: `#state=${encodeURIComponent(JSON.stringify(pelaez))}`, init });
  await settle(page);
  const before = await impulseRows(page, 0);
  assert.ok(before.length >= 3, JSON.stringify(before));
  // 40 steps of the first mode's frequency, as a slider drag sends them, the designs answered
  // 3 s late; after each step the ZVD's impulse table (shaper 2, designed by the page's module)
  // is watched for up to 1.5 s. A live page draws it within HOLD_MS (250 ms, the first step) or
  // a frame or two (the others); a page that waited for the solved design would draw none.
  const { zvdChanges, slowest } = await page.evaluate(async () => {
    window.__designDelayMs = 3000;
    const input = document.getElementById('mode-0-frequency');
    const rows = () => [...document.querySelectorAll('table.impulses')].find((t) => t.caption.textContent === 'ZVD').tBodies[0].textContent;
    const frame = () => new Promise((r) => requestAnimationFrame(r));
    let last = rows();
    let changes = 0;
    let slowest = 0;
    for (let i = 1; i <= 40; i++) {
      input.value = String(0.5 + i * 0.002);
      input.dispatchEvent(new Event('input', { bubbles: true }));
      const t0 = performance.now();
      while (rows() === last && performance.now() - t0 < 1500) await frame();
      if (rows() !== last) {
        changes++;
        slowest = Math.max(slowest, performance.now() - t0);
      }
      last = rows();
    }
    return { zvdChanges: changes, slowest };
  });
  t.diagnostic(`the slowest step drew its ZVD after ${slowest.toFixed(0)} ms`);
  assert.equal(zvdChanges, 40, `the ZVD followed the drag: ${zvdChanges} of 40 steps drawn (slowest ${slowest.toFixed(0)} ms)`);
  await settle(page);
  // The design worker's SI for the last frequency lands after the drag (on a loaded machine
  // after settle's two frames: "Shaper 1 is left out until the optimisation solver has
  // designed it" is then still shown), and then nothing is left out.
  await page.waitForFunction(() => document.getElementById('general-error').textContent === '', null, { timeout: 30000 })
    .catch(() => {});
  assert.equal(await page.textContent('#general-error'), '');
  const shown = await impulseRows(page, 0);
  // The same state opened afresh: the SI shown after the drag is the one for 0.58 Hz.
  const state = await page.evaluate(() => window.__playground.state);
  assert.equal(state.modes[0].frequencyHz, 0.58);
  const fresh = await env.page({ hash: `#state=${encodeURIComponent(JSON.stringify(state))}` });
  await settle(fresh.page);
  assert.deepEqual(shown, await impulseRows(fresh.page, 0));
  // One mode: the SI's times scale as 1/f (its band is relative to the mode).
  const scaled = before.at(-1)[0] * 0.5 / 0.58;
  assert.ok(Math.abs(shown.at(-1)[0] / scaled - 1) < 0.01, `the SI is the one for 0.58 Hz: ${shown.at(-1)[0]} vs ${scaled}`);
  assert.deepEqual(problems, []);
  assert.deepEqual(fresh.problems, []);
  await fresh.page.close();
  await page.close();
});

test('a solved design that fails says why at its shaper; the others draw', async () => {
  // No SI of at most 0.5 s exists for a 0.5 Hz mode (a period is 2 s).
  const st = { modes: [{ frequencyHz: 0.5, damping: 0.002 }], shapers: [{ family: 'si', vtol: 0.05, insensitivity: 0.7, maxDuration: 0.5 }, { family: 'zvd' }] };
  const { page, problems } = await env.page({ hash: `#state=${encodeURIComponent(JSON.stringify(st))}` });
  await settle(page);
  const messages = await page.$$eval('#controls .error', (e) => e.map((x) => x.textContent).filter(Boolean));
  assert.equal(messages.length, 1, JSON.stringify(messages));
  assert.match(messages[0], /^shapers\[0\]: infeasible: no shaper of at most maxDuration = 0\.5 s meets the constraints/);
  assert.match(await page.textContent('#general-error'), /^Shaper 1 is left out of the charts and tables: it cannot be designed as it is/);
  const tables = await page.$$eval('table.impulses caption', (c) => c.map((x) => x.textContent));
  assert.deepEqual(tables, ['ZVD']);
  // Without the limit it is designed and joins the others.
  await page.evaluate((s) => { location.hash = `#state=${encodeURIComponent(JSON.stringify(s))}`; }, { ...st, shapers: [{ family: 'si', vtol: 0.05, insensitivity: 0.7 }, { family: 'zvd' }] });
  await settle(page);
  assert.equal(await page.textContent('#general-error'), '');
  assert.equal((await page.$$eval('table.impulses', (t) => t.length)), 2);
  assert.deepEqual(problems, []);
  await page.close();
});

test('a design that traps ends the design worker; after the next edit a fresh one designs it', async () => {
  const { page, problems } = await env.page();
  // A stand-in worker whose design traps, as a panicking module would (an error without a kind).
  await page.route('**/design_worker.js', (r) => r.fulfill({
    contentType: 'text/javascript',
    body: "self.onmessage = ({ data }) => { if ('id' in data) postMessage({ id: data.id, error: { message: 'RuntimeError: unreachable' } }); };",
  }));
  await page.evaluate((s) => { location.hash = `#state=${encodeURIComponent(JSON.stringify(s))}`; }, SI_STATE);
  await settle(page);
  const messages = await page.$$eval('#controls .error', (e) => e.map((x) => x.textContent).filter(Boolean));
  assert.deepEqual(messages, ['shapers[0]: RuntimeError: unreachable']);
  await page.unroute('**/design_worker.js');
  await type(page, 'mode-0-damping', 0.004);
  await settle(page);
  assert.deepEqual(await page.$$eval('#controls .error', (e) => e.map((x) => x.textContent).filter(Boolean)), []);
  assert.equal((await impulseRows(page, 0)).length, 4);
  assert.deepEqual(problems, []);
  await page.close();
});

test('a sampled shaper with an amplitude bound, which only the solver designs, goes to the design worker too', async () => {
  const { page, problems, fetched } = await env.page();
  const kamel = (bound) => ({
    modes: [{ frequencyHz: 30 / (2 * Math.PI), damping: 0.02 }],
    shapers: [{ family: 'sampled', periodS: 0.012, impulses: 36, delaySamples: 17, weight: 0.1, derivatives: 1, plantGain: 8e-4, objective: 'controlError', ...bound }, { family: 'zvd' }],
  });
  // Kamel, Lange & Hirzinger's control-error shaper without bounds (closed form, the page's
  // own module) has negative amplitudes ...
  await page.evaluate((s) => { location.hash = `#state=${encodeURIComponent(JSON.stringify(s))}`; }, kamel({}));
  await settle(page);
  const free = await impulseRows(page, 0);
  assert.equal(free.length, 36);
  assert.ok(free.some(([, a]) => a < -1e-3), JSON.stringify(free));
  assert.ok(!fetched.includes('/pkg/page/designer_bg.wasm'), fetched.join(' '));
  // ... with A ≥ 0 (eq. 7) the page's module answers "unavailable" and the worker designs it.
  await page.evaluate((s) => { location.hash = `#state=${encodeURIComponent(JSON.stringify(s))}`; }, kamel({ amplitudeMin: 0 }));
  await settle(page);
  assert.ok(fetched.includes('/pkg/page/designer_bg.wasm'), fetched.join(' '));
  const bounded = await impulseRows(page, 0);
  assert.ok(bounded.length > 0 && bounded.length <= 36, JSON.stringify(bounded));
  assert.ok(bounded.every(([, a]) => a > -1e-6), JSON.stringify(bounded));
  assert.ok(Math.abs(bounded.reduce((sum, [, a]) => sum + a, 0) - 1) < 1e-4, 'unity gain');
  assert.deepEqual(await page.$$eval('.error', (e) => e.map((x) => x.textContent).filter(Boolean)), []);
  assert.deepEqual(problems, []);
  await page.close();
});

test('a sampled shaper’s cost report in the Numbers table: the JS API’s sampledReport, bounded (the worker) or not', async () => {
  const { page, problems } = await env.page();
  const spec = (bound) => ({ family: 'sampled', periodS: 0.012, impulses: 36, delaySamples: 17, weight: 0.1, derivatives: 1, plantGain: 8e-4, objective: 'controlError', ...bound });
  const modes = [{ frequencyHz: 30 / (2 * Math.PI), damping: 0.02 }];
  const fmt = (x, d) => (Number.isFinite(x) ? String(Number(x.toPrecision(d))) : '—');
  const rows = () => page.$$eval('#summary tbody tr', (r) => Object.fromEntries(r.map((x) => [x.cells[0].textContent, [...x.cells].slice(1).map((c) => c.textContent)])));
  for (const bound of [{}, { amplitudeMin: 0 }]) {
    await page.evaluate((s) => { location.hash = `#state=${encodeURIComponent(JSON.stringify(s))}`; }, { modes, shapers: [spec(bound), { family: 'zvd' }] });
    await settle(page);
    await page.waitForFunction(() => document.querySelectorAll('#impulses-0 tbody tr').length > 0);
    const lib = await page.evaluate(async (s) => {
      const api = await import('/pkg/input_shaping.js');
      await api.default({ module_or_path: '/pkg/input_shaping_bg.wasm' });
      return api.sampledReport(s);
    }, { ...spec(bound), modes });
    const r = await rows();
    const what = JSON.stringify(bound);
    assert.deepEqual(r['Sampled: ramp delay τ, eq. 10 (s)'], [fmt(lib.rampDelay, 4), '—'], what);
    assert.deepEqual(r['Sampled: cost J_q, eq. 17 (∫e² dt + AᵀQA)'], [`${fmt(lib.cost.total, 4)} (${fmt(lib.cost.controlError, 4)} + ${fmt(lib.cost.amplitudePenalty, 4)})`, '—'], what);
    assert.deepEqual(r['Sampled: J_q of the minimum-norm shaper'], [fmt(lib.baselineCost.total, 4), '—'], what);
    assert.deepEqual(r['Sampled: cost reduction against it (%)'], [fmt(lib.costReduction * 100, 4), '—'], what);
    // Kamel et al. §6: the control-error shaper costs less than the minimum-norm one.
    assert.ok(lib.costReduction > 0, `${what}: ${lib.costReduction}`);
  }
  // No sampled shaper compared: no such rows.
  await page.evaluate(() => { location.hash = `#state=${encodeURIComponent(JSON.stringify({ modes: [{ frequencyHz: 2, damping: 0.05 }], shapers: [{ family: 'zvd' }] }))}`; });
  await settle(page);
  assert.ok(!Object.keys(await rows()).some((k) => k.startsWith('Sampled')));
  assert.deepEqual(problems, []);
  await page.close();
});

test('a slow solved design never freezes the page, and one nobody wants any more is stopped', async () => {
  const { page, problems } = await env.page();
  // SI at I = 0.3 over six modes: about two minutes of solving (README, "What takes longer
  // than a frame"), with a ZVD beside it.
  const slow = {
    modes: [1.2, 3.4, 7.9, 13, 21, 34].map((f) => ({ frequencyHz: f, damping: 0.02 })),
    shapers: [{ family: 'si', vtol: 0.05, insensitivity: 0.3 }, { family: 'zvd' }],
  };
  await page.evaluate((s) => { location.hash = `#state=${encodeURIComponent(JSON.stringify(s))}`; }, slow);
  // The ZVD draws without the SI, which says it is being designed.
  await page.waitForFunction(() => /^Shaper 1 is left out until the optimisation solver has designed it/.test(document.getElementById('general-error').textContent), null, { timeout: 20000 });
  assert.equal(await page.getAttribute('body', 'data-fetching'), 'designs');
  const messages = await page.$$eval('#controls .error', (e) => e.map((x) => x.textContent).filter(Boolean));
  assert.equal(messages.length, 1, JSON.stringify(messages));
  assert.match(messages[0], /^Designing with the optimisation solver…( \(\d+ s\))?$/);
  assert.equal((await impulseRows(page, 0)).length, 729, 'the ZVD over six modes is shown');
  // The message counts the seconds the design has taken, every second.
  await page.waitForFunction(() => [...document.querySelectorAll('#controls .error')].some((e) => /^Designing with the optimisation solver… \([1-9]\d* s\)$/.test(e.textContent)), null, { timeout: 20000 });
  // The page still answers edits meanwhile: a mismatch edit is drawn before the design is back.
  assert.match(await page.textContent('#simulation-note'), /model × 1;/);
  await type(page, 'mismatch', 1.3);
  await page.waitForFunction(() => /model × 1\.3;/.test(document.getElementById('simulation-note').textContent), null, { timeout: 20000 });
  assert.equal(await page.getAttribute('body', 'data-fetching'), 'designs', 'the design is still running');
  // A state that no longer needs it: the running design is stopped and the new one runs at
  // once (waiting for the old one would take minutes; settle gives up after 20 s).
  await page.evaluate((s) => { location.hash = `#state=${encodeURIComponent(JSON.stringify(s))}`; }, SI_STATE);
  await settle(page);
  assertSlsqp(await impulseRows(page, 0));
  assert.equal(await page.textContent('#general-error'), '');
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
  await type(page, 'mode-0-damping', 1.5);
  await settle(page);
  const message = await page.textContent('[data-field="modes[0].damping"] ~ .error, .field:has([data-field="modes[0].damping"]) .error');
  assert.match(message, /damping/);
  assert.match(message, /1\.5/);
  assert.equal(await page.getAttribute('#mode-0-damping', 'aria-invalid'), 'true');
  assert.deepEqual(await impulseRows(page), before.rows);
  assert.equal((await canvasInfo(page, 'impulses-chart')).hash, before.imp.hash);
  assert.equal((await canvasInfo(page, 'sensitivity-chart')).hash, before.sens.hash);
  await page.screenshot({ path: `${SCREENSHOTS}error-1280x800.png`, fullPage: true });

  await type(page, 'mode-0-frequency', -4);
  await settle(page);
  assert.match(await page.textContent('.field:has(#mode-0-frequency) .error'), /greater than 0/);
  await type(page, 'mode-0-frequency', '');
  await settle(page);
  assert.match(await page.textContent('.field:has(#mode-0-frequency) .error'), /finite/);
  await type(page, 'mode-0-frequency', 2);
  await type(page, 'mode-0-damping', 0.05);
  await settle(page);
  assert.equal(await page.$$eval('.error', (e) => e.map((x) => x.textContent).join('')), '');
  await type(page, 'vtol', 150);
  await settle(page);
  assert.match(await page.textContent('.field:has(#vtol) .error'), /below 1/);
  await type(page, 'vtol', 5);
  await page.selectOption('#shaper-0-family', 'zvdn');
  await type(page, 'shaper-0-derivatives', 99);
  await settle(page);
  assert.match(await page.textContent('.field:has(#shaper-0-derivatives) .error'), /too large/);
  assert.deepEqual(problems, [], 'errors are shown on the page, not thrown');
  await page.close();
});

/** Impulse rows equal to `want` ([time, amplitude]) to the table's 10 digits. */
function assertClose(rows, want) {
  assert.equal(rows.length, want.length);
  rows.forEach(([t, a], i) => {
    assert.ok(Math.abs(t - want[i][0]) < 1e-9 && Math.abs(a - want[i][1]) < 1e-9, `impulse ${i}: ${[t, a]} vs ${want[i]}`);
  });
}

/** Pixels of a canvas within 30 of `rgb` in every channel. */
async function colorPixels(page, id, rgb) {
  return page.evaluate(([canvasId, [r, g, b]]) => {
    const c = document.getElementById(canvasId);
    const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
    let n = 0;
    for (let i = 0; i < d.length; i += 4) if (Math.abs(d[i] - r) < 30 && Math.abs(d[i + 1] - g) < 30 && Math.abs(d[i + 2] - b) < 30) n++;
    return n;
  }, [id, rgb]);
}

test('a link with a shaper that cannot be designed draws the others in their colours, says so, and keeps the last good charts once all drew', async () => {
  const BLUE = [0, 114, 178];
  const VERMILLION = [213, 94, 0];
  const GREEN = [0, 158, 115];
  // Shaper 2's EI hump of 90 % is out of range: nothing good is on screen yet, so it is left out.
  const state = { modes: [{ frequencyHz: 2, damping: 0.05 }], shapers: [{ family: 'zv' }, { family: 'ei', vtol: 0.9 }, { family: 'zvd' }] };
  const { page, problems } = await env.page({ hash: `#state=${encodeURIComponent(JSON.stringify(state))}` });
  assert.match(await page.textContent('#general-error'), /^Shaper 2 is left out of the charts and tables/);
  assert.match(await page.textContent('.field:has([data-field="shapers[1].vtol"]) .error'), /^shapers\[1\]\.vtol: tolerable vibration must lie between 0\.001 and 0\.5/);
  const heads = () => page.$$eval('#summary thead th', (th) => th.slice(1).map((h) => [h.textContent, getComputedStyle(h.querySelector('.swatch')).backgroundColor]));
  assert.deepEqual(await heads(), [['ZV', 'rgb(0, 114, 178)'], ['ZVD', 'rgb(0, 158, 115)']]);
  assertClose(await impulseRows(page, 1), zvd(2, 0.05));
  assert.ok(await colorPixels(page, 'impulses-chart', BLUE) > 100, 'ZV in blue');
  assert.ok(await colorPixels(page, 'impulses-chart', GREEN) > 100, 'ZVD keeps its green');
  assert.equal(await colorPixels(page, 'impulses-chart', VERMILLION), 0, 'nothing in the left-out shaper\'s colour');
  // An edit elsewhere still draws, the shaper still left out.
  await type(page, 'mode-0-frequency', 3);
  await settle(page);
  assertClose(await impulseRows(page, 1), zvd(3, 0.05));
  assert.match(await page.textContent('#general-error'), /^Shaper 2 is left out/);
  // A shaper added in the meantime and failing too is left out as well.
  await page.click('#add-shaper');
  await page.selectOption('#shaper-3-family', 'ei');
  await type(page, 'shaper-3-vtol', 80);
  await settle(page);
  assert.match(await page.textContent('#general-error'), /^Shapers 2 and 4 are left out/);
  assert.deepEqual((await heads()).map((h) => h[0]), ['ZV', 'ZVD']);
  await page.click('button[aria-label="Remove shaper 4"]');
  await settle(page);
  assert.match(await page.textContent('#general-error'), /^Shaper 2 is left out/);
  // Fixed: all three drawn, in their colours.
  await page.selectOption('#shaper-1-family', 'zvdd');
  await settle(page);
  assert.equal(await page.textContent('#general-error'), '');
  assert.deepEqual((await heads()).map((h) => h[1]), ['rgb(0, 114, 178)', 'rgb(213, 94, 0)', 'rgb(0, 158, 115)']);
  assert.ok(await colorPixels(page, 'impulses-chart', VERMILLION) > 100, 'ZVDD in vermillion');
  // Broken again once everything drew: the message at the field, the last good charts stay.
  await page.selectOption('#shaper-1-family', 'zvdn');
  await settle(page);
  const drawn = await canvasInfo(page, 'impulses-chart');
  await type(page, 'shaper-1-derivatives', 99);
  await settle(page);
  assert.match(await page.textContent('.field:has(#shaper-1-derivatives) .error'), /too large/);
  assert.equal(await page.textContent('#general-error'), '');
  assert.equal((await canvasInfo(page, 'impulses-chart')).hash, drawn.hash);
  assert.deepEqual(problems, []);
  await page.close();
});

test('a link that cannot be drawn at all says why at the field and on top', async () => {
  const state = { modes: [{ frequencyHz: 2, damping: 0.05 }], shapers: [{ family: 'ei', vtol: 0.9 }] };
  const page = await env.browserPage();
  await page.goto(`${env.url}#state=${encodeURIComponent(JSON.stringify(state))}`);
  await page.waitForFunction(() => document.getElementById('general-error')?.textContent);
  assert.match(await page.textContent('#general-error'), /^Nothing can be drawn until this is fixed: shapers\[0\]\.vtol: /);
  assert.match(await page.textContent('.field:has([data-field="shapers[0].vtol"]) .error'), /^shapers\[0\]\.vtol: /);
  await page.close();
});

test('the state lives in the URL: reload, back/forward, and hostile hashes', async () => {
  const { page, problems } = await env.page();
  await type(page, 'mode-0-frequency', 7);
  await page.locator('#mode-0-frequency').dispatchEvent('change');
  await settle(page);
  assert.match(decodeURIComponent(new URL(page.url()).hash), /"frequencyHz":7/);
  await page.reload();
  await page.waitForSelector('body[data-ready="true"]');
  assert.equal(await page.inputValue('#mode-0-frequency'), '7');
  await page.selectOption('#shaper-0-family', 'zv');
  await settle(page);
  assert.equal((await impulseRows(page)).length, 2);
  await page.goBack();
  await settle(page);
  assert.equal(await page.inputValue('#shaper-0-family'), 'zvd');
  assert.equal((await impulseRows(page)).length, 3);
  await page.goForward();
  await settle(page);
  assert.equal(await page.inputValue('#shaper-0-family'), 'zv');

  const rowsBefore = await impulseRows(page);
  for (const hash of ['#state=%7Bnot json', '#garbage', '#state=' + encodeURIComponent('{"modes":"x"}'),
    '#state=' + encodeURIComponent(JSON.stringify({ modes: [{ frequencyHz: 1 }], shapers: [{ family: '<img src=x onerror=alert(1)>' }] }))]) {
    await page.evaluate((h) => { location.hash = h; }, hash);
    await settle(page);
    const text = await page.textContent('body');
    assert.ok(!(await page.$('img[src="x"]')), 'no markup from the hash');
    if (hash.includes('img')) {
      assert.match(text, /unknown variant/);
    } else {
      assert.match(await page.textContent('#general-error'), /state|link/i, hash);
      assert.deepEqual(await impulseRows(page), rowsBefore);
    }
  }
  assert.deepEqual(problems, []);
  await page.close();
});

test('exports hold the designed shaper exactly', async () => {
  const { page, problems } = await env.page();
  await page.selectOption('#shaper-0-family', 'zv');
  await type(page, 'mode-0-frequency', 2);
  await type(page, 'mode-0-damping', 0);
  await settle(page);
  const out = async (format) => {
    await page.selectOption('#export-format', format);
    return page.inputValue('#export-output');
  };
  assert.equal(await out('csv'), 'time_s,amplitude\n0,0.5\n0.25,0.5\n');
  assert.equal(await out('json'), '{"impulses":[{"time":0,"amplitude":0.5},{"time":0.25,"amplitude":0.5}],"duration":0.25}');
  assert.equal(await out('rrf'), 'M593 P"custom" H0.5 T0.25');
  assert.match(await out('c'), /static const float shaper_amplitude\[SHAPER_COUNT\] = \{ 5\.00000000e-1f, 5\.00000000e-1f \};/);
  assert.match(await out('c'), /ZV for 2 Hz, ζ 0/);
  // 8-bit amplitudes and a 1 ms tick: [128, 127] (largest remainder keeps the sum 255) at [0, 250].
  await page.selectOption('#export-format', 'cFixed');
  await page.fill('#export-steps', '255');
  await page.fill('#export-tick', '0.001');
  const fixed = await page.inputValue('#export-output');
  assert.match(fixed, /shaper_amplitude_q\[SHAPER_COUNT\] = \{ 128, 127 \}|shaper_amplitude_q\[SHAPER_COUNT\] = \{ 127, 128 \}/);
  assert.match(fixed, /shaper_time_ticks\[SHAPER_COUNT\] = \{ 0, 250 \}/);
  await page.fill('#export-steps', '0');
  assert.match(await page.textContent('#export-error'), /amplitudeSteps/);
  assert.deepEqual(problems, []);
  await page.close();
});

test('the page works at phone size', async () => {
  const { page, problems } = await env.page({ width: 390, height: 844 });
  const info = await canvasInfo(page, 'sensitivity-chart');
  assert.ok(info.ink > 1000);
  const overflow = await page.evaluate(() => document.documentElement.scrollWidth - window.innerWidth);
  assert.ok(overflow <= 1, `no horizontal scrolling of the page: ${overflow}px`);
  await page.screenshot({ path: `${SCREENSHOTS}phone-390x844.png`, fullPage: true });
  assert.deepEqual(problems, []);
  await page.close();
});
