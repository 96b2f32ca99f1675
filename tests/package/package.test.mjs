// The installable package (issue 21, item 3): `scripts/pack.sh` (npm run pack) writes
// input-shaping-<version>.tgz; it is installed into an empty project (npm install of the local
// file, offline) and example.mjs — identify a mode from a recording, design, analyse, simulate —
// runs there unchanged: in Node (the exports map's `node` entry), in esbuild bundles for Node
// and for the browser, and in headless Chromium without a bundler (an import map), where
// `init()` fetches the wasm next to the glue. Needs pkg/ built (the build layer) and Chromium.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { copyFileSync, mkdirSync, mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';
import { startServer } from '../../scripts/serve.mjs';

const root = fileURLToPath(new URL('../../', import.meta.url));
const here = fileURLToPath(new URL('./', import.meta.url));
const esbuild = join(root, 'node_modules/.bin/esbuild');
let tmp; // the scratch directory: dist/ (the tarball) and app/ (the empty project)
let dir; // tmp/app
let tgz;

const sh = (cmd, args, cwd = dir) => execFileSync(cmd, args, { cwd, encoding: 'utf8', stdio: ['ignore', 'pipe', 'pipe'] });

before(() => {
  tmp = mkdtempSync(join(tmpdir(), 'input-shaping-package-'));
  sh('bash', [join(root, 'scripts/pack.sh'), '--out', join(tmp, 'dist')], root);
  const version = /^version = "([^"]+)"/m.exec(readFileSync(join(root, 'Cargo.toml'), 'utf8'))[1];
  tgz = join(tmp, 'dist', `input-shaping-${version}.tgz`);
  dir = join(tmp, 'app');
  mkdirSync(dir);
  writeFileSync(join(dir, 'package.json'), JSON.stringify({ name: 'app', private: true, type: 'module' }));
  copyFileSync(join(here, 'example.mjs'), join(dir, 'example.mjs'));
  writeFileSync(join(dir, 'main.mjs'), "import { run } from './example.mjs';\nconsole.log(JSON.stringify(await run()));\n");
  sh('npm', ['install', '--offline', '--no-audit', '--no-fund', '--no-package-lock', tgz]);
});
after(() => { if (tmp) rmSync(tmp, { recursive: true, force: true }); });

/** V of a shaper at a mode, Singhose 2009 eq. 11, written here independently of the crate. */
function vibration(impulses, { frequencyHz, damping }) {
  const w = 2 * Math.PI * frequencyHz;
  const wd = w * Math.sqrt(1 - damping * damping);
  const tn = impulses.at(-1).time;
  let c = 0;
  let s = 0;
  for (const { time, amplitude } of impulses) {
    const e = amplitude * Math.exp(-damping * w * (tn - time));
    c += e * Math.cos(wd * time);
    s += e * Math.sin(wd * time);
  }
  return Math.hypot(c, s);
}

/** What every run of the example must give (the recording is the decay of a 40 Hz, ζ 0.03 mode). */
function check(r, where) {
  const msg = `${where}: ${JSON.stringify(r)}`;
  assert.equal(r.sampleRateHz, 1000, msg);
  assert.ok(Math.abs(r.mode.frequencyHz - 40) < 0.04, `identified frequency: ${msg}`);
  assert.ok(Math.abs(r.mode.damping - 0.03) < 0.003, `identified damping: ${msg}`);
  assert.equal(r.impulses.length, 3, msg);
  assert.ok(Math.abs(r.impulses.reduce((s, i) => s + i.amplitude, 0) - 1) < 1e-12, msg);
  // ZVD at the identified mode leaves (almost) nothing at it, and at the true mode a little
  // that eq. 11, computed here, confirms.
  assert.ok(vibration(r.impulses, r.mode) < 1e-9, msg);
  const v = vibration(r.impulses, { frequencyHz: 40, damping: 0.03 });
  assert.ok(Math.abs(r.vibrationAtTrueMode - v) < 1e-9, msg);
  assert.ok(r.vibrationAtTrueMode < 0.01, msg);
  assert.ok(r.band.lowHz < r.mode.frequencyHz && r.mode.frequencyHz < r.band.highHz && r.band.width > 0.2, msg);
  assert.ok(r.unshapedResidualPercent > 1, msg);
  assert.ok(r.shapedResidualPercent < r.unshapedResidualPercent / 20, msg);
  assert.deepEqual(r.error, { isError: true, kind: 'invalid', field: 'modes[0].damping' }, msg);
}

test('the tarball holds the library only: the API module, its types, the Node entry, README, licences', () => {
  const files = sh('tar', ['-tzf', tgz]).trim().split('\n').map((f) => f.replace(/^package\//, '')).sort();
  assert.deepEqual(files, [
    'LICENSE-APACHE', 'LICENSE-MIT', 'README.md', 'input_shaping.d.ts', 'input_shaping.js',
    'input_shaping_bg.wasm', 'input_shaping_bg.wasm.d.ts', 'node.js', 'package.json',
  ]);
  const pkg = JSON.parse(readFileSync(join(dir, 'node_modules/input-shaping/package.json'), 'utf8'));
  assert.equal(pkg.exports['.'].node, './node.js');
  assert.equal(pkg.exports['.'].default, './input_shaping.js');
});

test('Node: imported by name from the installed package, the example runs', () => {
  check(JSON.parse(sh('node', ['main.mjs'])), 'node');
});

test('esbuild bundle for Node (the wasm copied next to it) runs', () => {
  sh(esbuild, ['main.mjs', '--bundle', '--platform=node', '--format=esm', '--outfile=out-node/main.mjs', '--log-level=warning']);
  copyFileSync(join(dir, 'node_modules/input-shaping/input_shaping_bg.wasm'), join(dir, 'out-node/input_shaping_bg.wasm'));
  check(JSON.parse(sh('node', ['out-node/main.mjs'])), 'esbuild, node');
});

test('headless Chromium: an import map, an esbuild bundle, and the bundle with the wasm imported by the file loader', async () => {
  // The page runs the example and puts its result (or the error) on window.result.
  const page = (script) => `<!doctype html><meta charset="utf-8"><link rel="icon" href="data:,">${script}`;
  const runner = "import { run } from './example.mjs';\nwindow.result = await run().catch((e) => ({ failed: String(e) }));\n";
  writeFileSync(join(dir, 'importmap.html'), page(
    '<script type="importmap">{ "imports": { "input-shaping": "./node_modules/input-shaping/input_shaping.js" } }</script>'
    + `<script type="module">${runner}</script>`));
  writeFileSync(join(dir, 'web.mjs'), runner);
  sh(esbuild, ['web.mjs', '--bundle', '--format=esm', '--outfile=out-web/web.js', '--log-level=warning']);
  copyFileSync(join(dir, 'node_modules/input-shaping/input_shaping_bg.wasm'), join(dir, 'out-web/input_shaping_bg.wasm'));
  writeFileSync(join(dir, 'bundle.html'), page('<script type="module" src="./out-web/web.js"></script>'));
  // The file loader: esbuild copies the wasm and hands its URL to init().
  writeFileSync(join(dir, 'loader.mjs'), "import wasmUrl from 'input-shaping/input_shaping_bg.wasm';\n"
    + "import init from 'input-shaping';\n// esbuild gives the path relative to the bundle: resolve it there, not against the page.\nawait init({ module_or_path: new URL(wasmUrl, import.meta.url) });\n" + runner);
  sh(esbuild, ['loader.mjs', '--bundle', '--format=esm', '--outdir=out-loader', '--loader:.wasm=file', '--log-level=warning']);
  writeFileSync(join(dir, 'loader.html'), page('<script type="module" src="./out-loader/loader.js"></script>'));

  const { server, url } = await startServer({ port: 0, root: dir });
  const browser = await chromium.launch({
    executablePath: process.env.CHROMIUM ?? '/usr/bin/chromium',
    args: ['--no-sandbox', '--disable-gpu', '--no-first-run', '--disable-background-networking'],
  });
  try {
    for (const html of ['importmap.html', 'bundle.html', 'loader.html']) {
      const tab = await browser.newPage();
      const problems = [];
      tab.on('pageerror', (e) => problems.push(e.message));
      tab.on('console', (m) => { if (m.type() === 'error') problems.push(`console: ${m.text()}`); });
      tab.on('requestfailed', (q) => problems.push(`request failed: ${q.url()}`));
      await tab.goto(url + html);
      await tab.waitForFunction(() => window.result !== undefined, null, { timeout: 30000 })
        .catch((e) => assert.fail(`${html}: no result (${e.message}); ${problems.join('; ')}`));
      const r = await tab.evaluate(() => window.result);
      assert.deepEqual(problems, [], html);
      assert.equal(r.failed, undefined, `${html}: ${r.failed}`);
      check(r, `chromium, ${html}`);
      await tab.close();
    }
  } finally {
    await browser.close();
    await new Promise((ok) => server.close(ok));
  }
});
