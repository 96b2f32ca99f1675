// What the worker benchmarks share (benches/optimal_page.mjs, benches/measure_page.mjs): the
// run's header line (date, commit, machine load), and headless Chromium on the repository's
// server with one module Worker per build of a module, each running the bench's own worker
// source. Not a benchmark itself.
import { chromium } from 'playwright-core';
import { execFileSync } from 'node:child_process';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { startServer } from '../scripts/serve.mjs';

export const root = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..');

/** The machine's `uptime` line. */
export const uptime = () => execFileSync('uptime', { encoding: 'utf8' }).trim();

/** Prints the run's date, commit and load; returns the load line. */
export function header() {
  const load = uptime();
  const commit = execFileSync('git', ['rev-parse', '--short', 'HEAD'], { cwd: root, encoding: 'utf8' }).trim();
  console.log(`${new Date().toISOString()} commit ${commit}; ${load}`);
  return load;
}

/**
 * A worker's source: it imports and initialises the module named by its first message
 * (`{ type: 'init', url }`), answers `{ ready: true }`, then runs `handler` (the body of an
 * async function of `data`, with the module as `mod`) on every later message.
 */
export const workerSource = (handler) => `
let mod;
onmessage = async ({ data }) => {
  if (data.type === 'init') {
    mod = await import(data.url);
    await mod.default();
    postMessage({ ready: true });
    return;
  }
${handler}
};`;

/**
 * Runs `body(page)` with `window.__workers[i]` a module Worker of `source` (a
 * [`workerSource`]) initialised with `modules[i]` (paths under the repository root), then closes the browser and the server.
 */
export async function withWorkers(source, modules, body) {
  const { server, url } = await startServer({ port: 0 });
  const browser = await chromium.launch({
    executablePath: process.env.CHROMIUM ?? '/usr/bin/chromium',
    args: ['--no-sandbox', '--disable-gpu', '--no-first-run', '--disable-background-networking', '--disable-component-update', '--disable-sync'],
  });
  try {
    const page = await browser.newPage();
    // A document of the server's origin (its 404 page) without the page's own work: the
    // workers are all that runs.
    await page.goto(`${url}/benches/blank`);
    // One worker per module, as the page keeps one measured-data worker.
    await page.evaluate(async ([src, urls]) => {
      const blob = URL.createObjectURL(new Blob([src], { type: 'text/javascript' }));
      window.__workers = await Promise.all(urls.map((u) => new Promise((done, fail) => {
        const w = new Worker(blob, { type: 'module' });
        w.onerror = (e) => fail(new Error(e.message));
        w.onmessage = () => done(w);
        w.postMessage({ type: 'init', url: new URL(u, location.href).href });
      })));
    }, [source, modules.map((m) => `/${m}`)]);
    await body(page);
  } finally {
    await browser.close();
    server.close();
  }
}
