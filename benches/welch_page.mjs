// Benchmark (not a test): Welch PSD of 10^6 samples in the page's wasm, in headless Chromium,
// beside scipy.signal.welch on the same data (benches/welch_scipy.py prints its own line; run
// both with `npm run bench:welch`). Timed: the `welch` call from a Float64Array to the result
// object (typed arrays back), median and best of RUNS after a warm-up.
// Run: npm run build && node benches/welch_page.mjs
import { chromium } from 'playwright-core';
import { startServer } from '../scripts/serve.mjs';

const RUNS = Number(process.env.RUNS ?? 20);
const { server, url } = await startServer({ port: 0 });
const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM ?? '/usr/bin/chromium',
  args: ['--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run', '--disable-background-networking', '--disable-component-update', '--disable-sync'],
});
try {
  const page = await browser.newPage();
  await page.goto(url);
  await page.waitForSelector('body[data-ready="true"]');
  const result = await page.evaluate(async (runs) => {
    const { welch } = await import('./pkg/input_shaping.js');
    const n = 1_000_000;
    const fs = 3200;
    // The same signal as benches/welch_scipy.py: two tones and a deterministic pseudo-noise.
    const x = new Float64Array(n);
    for (let i = 0; i < n; i++) {
      x[i] = Math.sin(2 * Math.PI * 37.3 * i / fs) + 0.5 * Math.sin(2 * Math.PI * 91.7 * i / fs) + 0.3 * ((i * 7919) % 1009) / 1009;
    }
    const cases = [
      ['hann, 4096-sample segments, half overlap', { sampleRateHz: fs, segmentLength: 4096, overlap: 2048 }],
      ["Klipper's settings (Kaiser β = 6, 2048 samples, half overlap)", { preset: 'klipper', sampleRateHz: fs }],
    ];
    const out = [];
    for (const [name, options] of cases) {
      let psd = welch(x, options);
      const times = [];
      for (let r = 0; r < runs; r++) {
        const t0 = performance.now();
        psd = welch(x, options);
        times.push(performance.now() - t0);
      }
      times.sort((a, b) => a - b);
      let sum = 0;
      for (const v of psd.psd) sum += v;
      out.push({ name, median: times[Math.floor(times.length / 2)], best: times[0], bins: psd.psd.length, segments: psd.segments, sum });
    }
    return out;
  }, RUNS);
  for (const r of result) {
    console.log(`wasm welch, 10^6 samples, ${r.name}: median ${r.median.toFixed(1)} ms, best ${r.best.toFixed(1)} ms (${RUNS} runs; ${r.segments} segments, ${r.bins} bins, Σ psd ${r.sum.toPrecision(12)})`);
  }
} finally {
  await browser.close();
  server.close();
}
