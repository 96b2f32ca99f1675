// Shared set-up for the end-to-end tests: a static server on 127.0.0.1 started by the test
// itself, and Debian's Chromium driven by playwright-core.
import { chromium } from 'playwright-core';
import { mkdirSync } from 'node:fs';
import { fileURLToPath } from 'node:url';
import { startServer } from '../../scripts/serve.mjs';

export const SCREENSHOTS = fileURLToPath(new URL('./screenshots/', import.meta.url));

const ARGS = [
  '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
  '--disable-background-networking', '--disable-component-update', '--disable-sync',
];

/** Starts the server and the browser; returns helpers and a `close()`. */
export async function openBrowser() {
  mkdirSync(SCREENSHOTS, { recursive: true });
  const { server, url } = await startServer({ port: 0 });
  const browser = await chromium.launch({
    executablePath: process.env.CHROMIUM ?? '/usr/bin/chromium',
    args: ARGS,
  });
  return {
    url,
    /**
     * A fresh page at the playground (with `hash`, if given), with console errors and page
     * errors collected in `problems` and the URL path of every request in `fetched`; `init`, a
     * function run in the page before its own scripts (playwright's `addInitScript`).
     */
    async page({ width = 1280, height = 800, hash = '', init = null } = {}) {
      const page = await browser.newPage({ viewport: { width, height } });
      if (init) await page.addInitScript(init);
      const problems = [];
      const fetched = [];
      page.on('console', (m) => { if (m.type() === 'error') problems.push(`console: ${m.text()}`); });
      page.on('pageerror', (e) => problems.push(`pageerror: ${e.message}`));
      page.on('request', (r) => fetched.push(new URL(r.url()).pathname));
      await page.goto(url + hash);
      await page.waitForSelector('body[data-ready="true"]', { timeout: 20000 });
      return { page, problems, fetched };
    },
    /** A fresh page, nothing loaded (for pages that never become ready). */
    browserPage({ width = 1280, height = 800 } = {}) {
      return browser.newPage({ viewport: { width, height } });
    },
    async close() {
      await browser.close();
      await new Promise((ok) => server.close(ok));
    },
  };
}

/** Number of canvas pixels that are not (near) white, and a hash of all pixels. */
export async function canvasInfo(page, id) {
  return page.evaluate((canvasId) => {
    const c = document.getElementById(canvasId);
    const data = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
    let ink = 0;
    let hash = 0;
    for (let i = 0; i < data.length; i += 4) {
      if (data[i] < 230 || data[i + 1] < 230 || data[i + 2] < 230) ink++;
      hash = (hash * 31 + data[i] + 7 * data[i + 1] + 13 * data[i + 2]) >>> 0;
    }
    return { ink, hash, width: c.width, height: c.height };
  }, id);
}

/**
 * Waits until the page has drawn what it was asked to: two animation frames (an edit's update
 * runs in the next one), and, if that update sent a solved shaper to the design worker, until
 * its design came back and was drawn.
 */
export async function settle(page) {
  const frames = () => page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
  await frames();
  await page.waitForSelector('body:not([data-fetching])', { timeout: 20000 });
  await frames();
}

/** Sets an input's value as a user typing would (fires `input`). */
export async function type(page, id, value) {
  await page.fill(`#${id}`, String(value));
}
