// End-to-end: the printed-corner panel (issue 23 item 3) on the built page in headless Chromium.
// Not in the first load; the printer preset opens it on Klipper's ringing tower; the numbers in
// its table equal the JS API's (simulateCorner of the library module, pkg/input_shaping.js, with
// the same spec and each shaper); pixels of the unshaped and shaped tracks on the canvas; the
// state in the URL (a link opens the same panel with the same numbers); a bad field keeps the
// last good chart and table and names the field; no console errors; a screenshot.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { openBrowser, canvasInfo, type, settle, SCREENSHOTS } from './browser.mjs';

let env;
before(async () => { env = await openBrowser(); });
after(async () => { await env?.close(); });

async function cornerReady(page) {
  await page.waitForSelector('body[data-corner-ready="true"]', { timeout: 60000 });
  await settle(page);
}

/** The corner table: { rowName: [cells] }. */
async function table(page) {
  return page.$$eval('#corner-table tbody tr', (rows) => Object.fromEntries(rows.map((r) => [r.cells[0].textContent, [...r.cells].slice(1).map((c) => c.textContent)])));
}

/** The same rows from the JS API: simulateCorner per shaper, formatted as the page formats. */
async function fromApi(page) {
  return page.evaluate(async () => {
    const api = await import('/pkg/input_shaping.js');
    await api.default();
    const { spec, shapers, labels } = window.__cornerView.last();
    const um = window.__cornerView.formatMicrons;
    const row = (corners) => {
      const max = (f) => corners.reduce((m, c) => Math.max(m, f(c)), 0);
      return [um(max((c) => c.peakDeviation)), um(max((c) => c.ringing)), ...corners.flatMap((c) => [um(c.peakDeviation), um(c.ringing)])];
    };
    const rows = { unshaped: row(api.simulateCorner(spec).unshaped.corners) };
    shapers.forEach((s, i) => {
      const r = api.simulateCorner({ ...spec, x: { ...spec.x, shaper: s }, y: { ...spec.y, shaper: s } });
      rows[labels[i]] = row(r.shaped.corners);
    });
    return rows;
  });
}

/** Pixels of `rgb` (within 40 per channel) on the corner chart. */
async function pixelsOf(page, rgb) {
  return page.evaluate((want) => {
    const c = document.getElementById('corner-chart');
    const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
    let n = 0;
    for (let i = 0; i < d.length; i += 4) {
      if (Math.abs(d[i] - want[0]) < 40 && Math.abs(d[i + 1] - want[1]) < 40 && Math.abs(d[i + 2] - want[2]) < 40) n++;
    }
    return n;
  }, rgb);
}

test('the printer preset shows the corner; its numbers are the JS API\'s; the URL brings it back', async () => {
  const { page, problems, fetched } = await env.page();
  assert.ok(!fetched.some((p) => /corner/.test(p)), `the first load fetched the corner view: ${fetched.filter((p) => /corner/.test(p))}`);
  await page.selectOption('#preset', 'printer');
  await cornerReady(page);
  assert.ok(fetched.some((p) => p.endsWith('/corner_view.js')) && fetched.some((p) => p.endsWith('/corner_bg.wasm')));
  const shown = await table(page);
  assert.deepEqual(Object.keys(shown), ['unshaped', '1. zv', '2. mzv', '3. ei', '4. zvd']);
  // The ringing tower: five corners, two numbers each, after the two largest.
  for (const cells of Object.values(shown)) assert.equal(cells.length, 2 + 2 * 5);
  assert.deepEqual(shown, await fromApi(page));
  // Every shaper leaves less ringing than the unshaped print on the long walls (corners 2 and 3).
  const ringing = (cells, k) => (cells[2 + 2 * k + 1] === '≈ 0' ? 0 : Number(cells[2 + 2 * k + 1]));
  for (const name of ['1. zv', '2. mzv', '3. ei', '4. zvd']) {
    for (const k of [1, 2]) assert.ok(ringing(shown[name], k) < ringing(shown.unshaped, k), `${name} corner ${k + 1}: ${ringing(shown[name], k)} vs ${ringing(shown.unshaped, k)}`);
  }
  const info = await canvasInfo(page, 'corner-chart');
  assert.ok(info.ink > 5000, `ink ${info.ink}`);
  assert.ok(await pixelsOf(page, [110, 110, 110]) > 300, 'the unshaped track (grey) is drawn');
  // The shaped tracks nearly coincide on the walls: the last drawn (4. zvd, pink) shows most.
  assert.ok(await pixelsOf(page, [204, 121, 167]) > 300, 'the shaped tracks are drawn (the last one, pink, on top)');
  await page.$eval('#corner', (s) => s.scrollIntoView());
  await page.locator('#corner').screenshot({ path: `${SCREENSHOTS}corner-printer-1280x800.png` });
  const hash = await page.evaluate(() => location.hash);
  const state = JSON.parse(decodeURIComponent(hash.slice('#state='.length)));
  assert.equal(state.corner.open, true);
  assert.equal(state.corner.path, 'ringingTower');
  const again = await env.page({ hash });
  await cornerReady(again.page);
  assert.deepEqual(await table(again.page), shown);
  assert.deepEqual(again.problems, []);
  await again.page.close();
  assert.deepEqual(problems, []);
  await page.close();
});

test('a bad corner field names the field and keeps the last good chart and table; a good one redraws', async () => {
  const { page, problems } = await env.page();
  await page.click('#corner-panel > summary');
  await cornerReady(page);
  assert.match(await page.evaluate(() => location.hash), /%22corner%22/);
  const before = await canvasInfo(page, 'corner-chart');
  const rows = await table(page);
  assert.deepEqual(Object.keys(rows), ['unshaped', '1. zvd']);
  assert.equal(rows.unshaped.length, 2 + 2 * 3); // the square: three corners
  for (const [id, value, field] of [['corner-velocity', '0', 'velocity'], ['corner-x-z0', '1.5', 'x.modes[0].damping'], ['corner-side', '', 'path.sideMm']]) {
    const good = await page.inputValue(`#${id}`);
    await type(page, id, value);
    await settle(page);
    const message = await page.textContent(`#${id}-error`);
    assert.ok(message.startsWith(field), `${id}: "${message}" names ${field}`);
    assert.equal(await page.getAttribute(`#${id}`, 'aria-invalid'), 'true');
    assert.equal((await canvasInfo(page, 'corner-chart')).hash, before.hash, `${id}: the chart is kept`);
    assert.deepEqual(await table(page), rows, `${id}: the table is kept`);
    await type(page, id, good);
    await settle(page);
    assert.equal(await page.textContent(`#${id}-error`), '');
  }
  await type(page, 'corner-velocity', '80');
  await settle(page);
  assert.notDeepEqual(await table(page), rows);
  assert.deepEqual(await table(page), await fromApi(page));
  assert.match(await page.evaluate(() => location.hash), /%22velocity%22%3A80/);
  assert.notEqual((await canvasInfo(page, 'corner-chart')).hash, before.hash);
  assert.deepEqual(problems, []);
  await page.close();
});
