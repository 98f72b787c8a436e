// Open a page in headless Chromium and report how it loaded (tests, benchmark):
//
//   node page-check.mjs ROOT PATH [--runs N] [--frame] [--size WxH]
//
// Serves ROOT (serve.mjs), opens http://127.0.0.1:PORT/PATH with a fresh
// profile each run, waits for window.sunbeamReady (set by index.html when the
// first frame is drawn) and prints one JSON object: the page's own load time
// (ms from script start to first frame), the wall time from navigation to ready,
// the map's size, and every console error or warning and page error. Exit 1 when
// the page reported an error. --frame adds what the canvas shows (`frame`:
// index.html's window.sunbeamFrameStats(), mean display values, the lit fraction
// and 8 x 6 block means), after a second frame. --size: the viewport (800x600).
//
// PATH may carry the page's parameters, e.g. 'threejs/index.html?env=none'.
import { startServer } from './serve.mjs';
import { resolve } from 'node:path';

const [root, path, ...rest] = process.argv.slice(2);
if (!root || !path) {
  console.error('usage: node page-check.mjs ROOT PATH [--runs N] [--frame] [--size WxH]');
  process.exit(1);
}
const at = rest.indexOf('--runs');
const runs = at >= 0 ? Number(rest[at + 1]) : 1;
const withFrame = rest.includes('--frame');
const sizeAt = rest.indexOf('--size');
const [width, height] = sizeAt >= 0 ? rest[sizeAt + 1].split('x').map(Number) : [800, 600];
const server = await startServer(resolve(root));
const url = `http://127.0.0.1:${server.address().port}/${path}`;
const { chromium } = await import('playwright-core');
const out = { url, runs: [] };
let failed = false;
try {
  for (let r = 0; r < runs; r++) {
    const browser = await chromium.launch({
      executablePath: process.env.CHROMIUM ?? '/usr/bin/chromium',
      args: ['--no-sandbox', '--disable-gpu', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--disable-quic',
        '--no-first-run', '--disable-background-networking', '--disable-component-update', '--disable-sync'],
    });
    const page = await browser.newPage({ viewport: { width, height } });
    const problems = [];
    page.on('console', (m) => { if (m.type() === 'error' || m.type() === 'warning') problems.push(`console ${m.type()}: ${m.text()}`); });
    page.on('pageerror', (e) => problems.push(`page error: ${e.message}`));
    const t0 = Date.now();
    await page.goto(url);
    await page.waitForFunction(() => window.sunbeamReady !== undefined, null, { timeout: 60000 });
    const wallMs = Date.now() - t0;
    const ready = await page.evaluate(() => window.sunbeamReady);
    if (withFrame && !ready.error) ready.frame = await page.evaluate(() => window.sunbeamFrameStats());
    const real = problems.filter((s) => !/GPU stall due to ReadPixels|Automatic fallback to software WebGL/.test(s));
    if (ready.error || real.length) failed = true;
    out.runs.push({ ...ready, wallMs, problems: real });
    await browser.close();
  }
} finally {
  server.close();
}
console.log(JSON.stringify(out));
process.exit(failed ? 1 : 0);
