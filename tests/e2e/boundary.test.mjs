// The boundary fuzz in headless Chromium (issue 21 item 1): tests/boundary/fuzz.mjs run inside
// the page's browser against every module of pkg/, with real canvases for the drawing exports.
// 0 traps, 0 errors other than the documented `Error` naming the argument, every export still
// answering its valid call. BOUNDARY_CALLS sets the calls per module (default 1500 here);
// `npm run test:boundary:long` makes 10⁶.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { openBrowser } from './browser.mjs';

const CALLS = Number(process.env.BOUNDARY_CALLS ?? 1500);
const SEED = Number(process.env.BOUNDARY_SEED ?? 20261204);
const MODULES = [
  ['pkg/input_shaping', CALLS],
  ['pkg/page/playground', Math.ceil(CALLS / 4)],
  ['pkg/page/designer', Math.ceil(CALLS / 10)],
  ['pkg/page/recording', Math.ceil(CALLS / 4)],
  ['pkg/page/corner', Math.ceil(CALLS / 4)],
];

let env;
before(async () => { env = await openBrowser(); });
after(async () => { await env?.close(); });

for (const [path, calls] of MODULES) {
  test(`${path} in Chromium: ${calls} hostile calls, no trap, only documented errors`, async () => {
    const page = await env.browserPage();
    const problems = [];
    page.on('pageerror', (e) => problems.push(`pageerror: ${e.message}`));
    await page.goto(`${env.url}/tests/boundary/`);
    const r = await page.evaluate(async ({ path, calls, seed }) => {
      const { fuzz } = await import('/tests/boundary/fuzz.mjs');
      const api = await import(`/${path}.js`);
      await api.default({ module_or_path: `/${path}_bg.wasm` });
      const canvas = () => {
        const c = document.createElement('canvas');
        c.width = 200;
        c.height = 120;
        return c;
      };
      return fuzz(api, { calls, seed, env: { canvas } });
    }, { path, calls, seed: SEED });
    const failures = r.failures.map((f) => `${f.what}: ${f.export}(${f.call}) → ${f.error}`).join('\n');
    console.log(`# ${path} in Chromium: ${r.calls} calls over ${r.exports.length} exports: ${r.returned} returned, ${r.documented} documented errors, ${r.traps} traps, ${r.other} other, ${r.wrongField} naming another field`);
    assert.ok(r.exports.length > 0, 'no export found');
    assert.equal(r.traps, 0, `traps:\n${failures}`);
    assert.equal(r.other, 0, `errors other than the documented Error:\n${failures}`);
    assert.equal(r.wrongField, 0, `errors whose field does not name the argument:\n${failures}`);
    assert.equal(r.extraRejected, 0, `extra arguments rejected:\n${failures}`);
    assert.ok(r.stillAnswering, `an export no longer answers its valid call:\n${failures}`);
    assert.ok(r.unchanged, `an export's valid call changed its answer:\n${failures}`);
    assert.deepEqual(problems, []);
    await page.close();
  });
}
