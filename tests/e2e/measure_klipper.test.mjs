// End-to-end: the measured-data path of issue 20 (item 5). Klipper's files from tests/data/klipper/
// (written by benches/reference/sweep_testset.py, with Klipper's own picks for them computed by
// benches/reference/klipper_reference.py in expected.json) go in through the file input, one or
// several at once; per axis the page must show the Klipper-style chart (pixels on the canvas),
// the table like calibrate_shaper's, whose pick must be Klipper's (family, and frequency to
// 0.1 Hz), and the config text; a bad file must name file, line and column beside the drop
// zone and keep the last good result; no console errors.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { openBrowser, canvasInfo, SCREENSHOTS } from './browser.mjs';

const DATA = new URL('../data/klipper/', import.meta.url);
const EXPECTED = JSON.parse(readFileSync(new URL('expected.json', DATA), 'utf8'));
const file = (name) => ({ name, mimeType: 'text/csv', buffer: readFileSync(new URL(name, DATA)) });

let env;
before(async () => { env = await openBrowser(); });
after(async () => { await env?.close(); });

/** Sets the files on the input and waits for the panels of `axes` to be drawn. */
async function drop(page, names, axes) {
  const before = await page.evaluate(() => window.__measureView?.result ?? null);
  await page.setInputFiles('#measure-file', names.map(file));
  await page.waitForFunction(([prev, want]) => {
    const r = window.__measureView?.result;
    if (!r || r === prev) return false;
    const shown = [...document.querySelectorAll('.measure-axis')].map((s) => s.dataset.axis);
    return want.every((a) => shown.includes(a))
      && [...document.querySelectorAll('canvas.klipper-chart')].every((c) => c.dataset.drawn);
  }, [before, axes], { timeout: 180000 });
}

/** The table of an axis as shown: [{ family, frequency, best }]. */
function table(page, axis) {
  return page.$$eval(`.measure-axis[data-axis="${axis}"] table.klipper-table tbody tr`, (rows) => rows.map((r) => ({
    family: r.dataset.family, frequency: Number(r.dataset.frequency), shown: r.cells[2].textContent, best: r.classList.contains('best'),
  })));
}

/** Klipper's pick from expected.json, checked against the row the page marks. */
function assertKlipperPick(rows, key) {
  const want = EXPECTED[key].best;
  const best = rows.find((r) => r.best);
  assert.ok(best, `a pick is marked: ${JSON.stringify(rows)}`);
  assert.equal(best.family, want.name, `${key}: family (${JSON.stringify(rows)})`);
  assert.equal(best.shown, want.freq.toFixed(1), `${key}: frequency as calibrate_shaper prints it`);
  assert.ok(Math.abs(best.frequency - want.freq) <= 0.05 + 1e-9, `${key}: ${best.frequency} Hz against ${want.freq}`);
}

test('"I have a recording" at the top opens the path; the view is fetched only then', async () => {
  const { page, problems, fetched } = await env.page();
  assert.ok(!fetched.includes('/pkg/page/measure_view.js'), 'not in the first load');
  assert.ok(!fetched.includes('/pkg/page/recording_bg.wasm'), 'not in the first load');
  await page.click('#open-recording');
  await page.waitForFunction(() => document.body.dataset.path === 'recording');
  await page.waitForFunction(() => window.__measureView !== undefined, null, { timeout: 30000 });
  assert.ok(fetched.includes('/pkg/page/measure_view.js'), fetched.join(' '));
  // The measured-data section comes first in the layout and is scrolled to.
  const top = await page.evaluate(() => document.getElementById('measure').getBoundingClientRect().top);
  assert.ok(top < 200, `the section is at the top: ${top}`);
  assert.deepEqual(problems, []);
  await page.close();
});

test('a raw Klipper recording: the axis chart, Klipper\'s table and the config', async () => {
  const { page, problems } = await env.page({ width: 1280, height: 1000 });
  await drop(page, ['raw_data_x_single47z08.csv'], ['x']);
  const rows = await table(page, 'x');
  assert.ok(rows.length >= 5, JSON.stringify(rows));
  const chart = await canvasInfo(page, 'klipper-chart-0');
  assert.ok(chart.ink > 5000, `the chart has ink: ${chart.ink}`);
  const config = await page.inputValue('#measure-config-text');
  const best = rows.find((r) => r.best);
  // The frequency as written by firmwareConfig: calibrate_shaper's 0.1 Hz, without a trailing 0.
  const freq = String(Number(best.frequency.toFixed(1)));
  assert.ok(config.startsWith(`[input_shaper]\nshaper_type_x: ${best.family}\nshaper_freq_x: ${freq}\ndamping_ratio_x: 0.1\n`), config);
  assert.match(config, /# in \[printer\]: max_accel: \d+00\n/, config);
  await page.selectOption('#measure-config-format', 'klipperCommand');
  assert.equal(await page.inputValue('#measure-config-text'),
    `SET_INPUT_SHAPER SHAPER_TYPE_X=${best.family} SHAPER_FREQ_X=${freq} DAMPING_RATIO_X=0.1\n`);
  // A firmware that cannot run the pick says so beside the (empty) text, or writes it with a note.
  await page.selectOption('#measure-config-format', 'marlin');
  assert.match(await page.inputValue('#measure-config-text'), /^; x: Marlin runs ZV only/);
  // The raw recording's modes are identified, for the playground.
  await page.waitForSelector('#measure-modes tbody tr[data-mode]');
  assert.equal(await page.isDisabled('#measure-accept'), false);
  // The sweep read from the data (the generator's: 38 -> 56 Hz at 2 Hz/s) is said.
  const said = (await page.textContent('#measure-status')).match(/a sweep of ([\d.]+)–([\d.]+) Hz at ([\d.]+) Hz\/s/);
  assert.ok(said, await page.textContent('#measure-status'));
  assert.ok(Math.abs(Number(said[3]) - 2) < 0.1 && Number(said[1]) < 47.3 && Number(said[2]) > 47.3, said[0]);
  // The optimised table: every family row says its kind, shaper_freq and damping_ratio (a
  // config needs all three); Klipper's pick is the same as in Klipper's table.
  const optimal = await page.$$eval('.measure-axis[data-axis="x"] table.optimal-table tbody tr', (trs) => trs.map((r) => [...r.cells].map((c) => c.textContent)));
  assert.ok(optimal.length >= 2, JSON.stringify(optimal));
  for (const cells of optimal.filter((c) => !c[2].startsWith('custom'))) {
    assert.ok(cells[2] !== '' && Number.isFinite(Number(cells[3])) && Number.isFinite(Number(cells[4])), JSON.stringify(cells));
  }
  const pickRow = optimal.find((c) => c[2] === "Klipper's pick");
  assert.ok(pickRow, JSON.stringify(optimal));
  assert.equal(pickRow[3], rows.find((r) => r.best).shown);
  await page.locator('#measure').screenshot({ path: `${SCREENSHOTS}measure-klipper-raw.png` });
  assertKlipperPick(rows, 'raw_data_x_single47z08.csv');
  assert.deepEqual(problems, []);
  await page.close();
});

/** The test set's raw recording of a 47.3 Hz, ζ 0.08 mode written as RepRapFirmware's M956
 * writes a file (src/Accelerometers/Accelerometers.cpp): `Sample,X,Y,Z`, sample numbers, g to 4
 * decimals, then `Rate <Hz>, overflows 0`. */
function rrfFile() {
  const rows = readFileSync(new URL('raw_data_x_single47z08.csv', DATA), 'utf8').trim().split('\n').slice(1)
    .map((line) => line.split(',').map(Number));
  const rate = Math.round((rows.length - 1) / (rows[rows.length - 1][0] - rows[0][0]));
  const g = (v) => (v / 9806.65).toFixed(4);
  const body = rows.map((r, k) => `${k},${g(r[1])},${g(r[2])},${g(r[3])}`).join('\n');
  return { name: '0_2026-12-05_10.00.00.csv', mimeType: 'text/csv', buffer: Buffer.from(`Sample,X,Y,Z\n${body}\nRate ${rate}, overflows 0\n`) };
}

test('a RepRapFirmware accelerometer file (M956): its kind said, its mode and Klipper\'s table', async () => {
  const { page, problems } = await env.page({ width: 1280, height: 1000 });
  await page.setInputFiles('#measure-file', rrfFile());
  await page.waitForSelector('#measure-modes tbody tr[data-mode]', { timeout: 180000 });
  await page.waitForFunction(() => [...document.querySelectorAll('canvas.klipper-chart')].some((c) => c.dataset.drawn), null, { timeout: 180000 });
  assert.match(await page.textContent('#measure'), /RepRapFirmware accelerometer file \(M956\)/);
  const found = await page.$$eval('#measure-modes tbody td[data-frequency]', (tds) => tds.map((td) => Number(td.dataset.frequency)));
  assert.ok(found.some((f) => Math.abs(f / 47.3 - 1) < 0.01), `47.3 Hz found: ${found}`);
  const rows = await page.$$eval('table.klipper-table tbody tr', (trs) => trs.map((r) => r.dataset.family));
  assert.ok(rows.length >= 5, JSON.stringify(rows));
  assert.ok((await canvasInfo(page, 'klipper-chart-0')).ink > 5000, 'the chart has ink');
  // The file names no axis (M956 names it by board and date): Klipper's per-axis config leaves
  // it out and says why; RepRapFirmware's M593, one shaper for every axis, is written.
  assert.equal(await page.inputValue('#measure-config-text'), '');
  assert.match(await page.textContent('#measure-config-notes'), /not an X, Y or Z axis/);
  await page.selectOption('#measure-config-format', 'rrf');
  const pick = await page.$eval('table.klipper-table tbody tr.best', (r) => [r.dataset.family, Number(r.dataset.frequency)]);
  assert.match(await page.inputValue('#measure-config-text'), new RegExp(`^M593 P"${pick[0]}" F${Number(pick[1].toFixed(1))} S0\\.1\n`));
  await page.locator('#measure').screenshot({ path: `${SCREENSHOTS}measure-rrf.png` });
  assert.deepEqual(problems, []);
  await page.close();
});

test('resonances and calibration files, X and Y together, then a bad file keeps the result', async () => {
  const { page, problems } = await env.page({ width: 1280, height: 1000 });
  await drop(page, ['resonances_x_single47z08.csv', 'calibration_data_y_two38x14.csv'], ['x', 'y']);
  const x = await table(page, 'x');
  const y = await table(page, 'y');
  for (const k of [0, 1]) assert.ok((await canvasInfo(page, `klipper-chart-${k}`)).ink > 5000, `chart ${k} has ink`);
  // The calibration file's fitted curves are drawn (dotted) and named.
  assert.match(await page.textContent('.measure-axis[data-axis="y"]'), /Dotted: the shapers Klipper fitted/);
  const config = await page.inputValue('#measure-config-text');
  assert.match(config, /shaper_type_x: .*\nshaper_freq_x: .*\n(.*\n)*shaper_type_y: /, config);
  await page.locator('#measure').screenshot({ path: `${SCREENSHOTS}measure-klipper-xy.png` });
  await page.screenshot({ path: `${SCREENSHOTS}measure-klipper-full.png`, fullPage: true });
  const hash = (await canvasInfo(page, 'klipper-chart-0')).hash;

  // A bad file: the message names file, line and column; the panels and the config stay.
  await page.setInputFiles('#measure-file', { name: 'resonances_x_bad.csv', mimeType: 'text/csv', buffer: Buffer.from('freq,psd_x,psd_y,psd_z,psd_xyz\n5.0,1,2,3,6\n6.0,1,abc,3,6\n') });
  await page.waitForFunction(() => document.getElementById('measure-error').textContent !== '');
  const error = await page.textContent('#measure-error');
  assert.match(error, /resonances_x_bad\.csv/);
  assert.match(error, /line 3, column 3/);
  assert.equal(await page.inputValue('#measure-config-text'), config, 'the config stays');
  assert.deepEqual(await table(page, 'x'), x, 'the table stays');
  assert.equal((await canvasInfo(page, 'klipper-chart-0')).hash, hash, 'the chart stays');
  // The error sits beside the drop zone.
  assert.ok(await page.$('#measure-drop #measure-error'));
  await page.locator('#measure-drop').screenshot({ path: `${SCREENSHOTS}measure-klipper-error.png` });

  assertKlipperPick(x, 'resonances_x_single47z08.csv');
  assertKlipperPick(y, 'calibration_data_y_two38x14.csv');
  assert.deepEqual(problems, []);
  await page.close();
});

test('two runs of one axis are combined into one panel', async () => {
  const { page, problems } = await env.page();
  await drop(page, ['resonances_x_m1.csv', 'resonances_x_m1run2.csv'], ['x']);
  assert.equal(await page.$$eval('.measure-axis', (s) => s.length), 1);
  assert.match(await page.textContent('.measure-axis[data-axis="x"] h3'), /resonances_x_m1\.csv, resonances_x_m1run2\.csv/);
  assertKlipperPick(await table(page, 'x'), 'resonances_x_m1+resonances_x_m1run2');
  assert.deepEqual(problems, []);
  await page.close();
});

/**
 * A resonances file written here from a closed form (not by the identification code): a mode at
 * 150 Hz, ζ 0.05, seen by an accelerometer under a sweep that ends at 133.3 Hz (Klipper's
 * releases of 2021–2023), so the response still rises where the file's sweep ends; rows every
 * 1.5625 Hz to 200 Hz as Klipper writes them.
 */
function cutOffFile() {
  const rows = ['freq,psd_x,psd_y,psd_z,psd_xyz'];
  for (let k = 0; k <= 128; k++) {
    const f = k * 1.5625;
    const taper = f >= 133.3 ? 0.01 : f > 130.3 ? 0.01 + 0.99 * 0.5 * (1 - Math.cos(Math.PI * (133.3 - f) / 3)) : 1;
    // Base excitation: 1 − s²/(s² + 2ζωs + ω²) at s = iω, times f² (an accelerometer's PSD).
    const [fi, z] = [150, 0.05];
    const [dr, di] = [fi * fi - f * f, 2 * z * fi * f];
    const d2 = dr * dr + di * di;
    const [hr, hi] = [1 + f * f * dr / d2, -f * f * di / d2];
    const x = taper * f * f * (hr * hr + hi * hi) + 20;
    rows.push(`${f.toFixed(1)},${x.toExponential(3)},20,20,${(x + 40).toExponential(3)}`);
  }
  return Buffer.from(`${rows.join('\n')}\n`);
}

test('a response cut off by the sweep\'s end is said so, not shown as "no mode"', async () => {
  const { page, problems } = await env.page({ width: 1280, height: 1000 });
  await page.setInputFiles('#measure-file', { name: 'resonances_x_cutoff.csv', mimeType: 'text/csv', buffer: cutOffFile() });
  await page.waitForSelector('#measure-notes [data-note]', { timeout: 180000 });
  const note = await page.textContent('#measure-notes [data-note]');
  assert.match(note, /still rises where the sweep ends \(1[23]\d\.\d Hz/, note);
  assert.match(note, /higher maximum frequency/, note);
  const id = await page.evaluate(() => window.__measureView.result.identification);
  assert.ok(id.cutOff && id.cutOff.frequencyHz === id.sweepEndHz, JSON.stringify(id.cutOff));
  assert.ok(id.modes.every((m) => m.frequencyHz < 125), JSON.stringify(id.modes.map((m) => m.frequencyHz)));
  assert.equal(await page.$('#measure-modes tbody tr td[colspan="5"]'), null, 'no "no peak" line');
  await page.locator('#measure-modes-part').screenshot({ path: `${SCREENSHOTS}measure-cut-off.png` });
  assert.deepEqual(problems, []);
  await page.close();
});
