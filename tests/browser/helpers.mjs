// Shared set-up for the browser tests: the built page (dist/) served on a
// free 127.0.0.1 port by scripts/serve.mjs, and Debian's Chromium driven by
// playwright-core with the flags measured in shared/toolchain.md.
import { after, before } from 'node:test';
import { spawn } from 'node:child_process';
import { createServer } from 'node:net';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';

export const ROOT = resolve(dirname(fileURLToPath(import.meta.url)), '../..');
export const DIST = join(ROOT, 'dist');

const FLAGS = [
  '--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
  '--disable-background-networking', '--disable-component-update', '--disable-sync',
  '--use-angle=swiftshader', '--enable-unsafe-swiftshader',
];

function freePort() {
  return new Promise((ok, fail) => {
    const s = createServer();
    s.once('error', fail);
    s.listen(0, '127.0.0.1', () => {
      const { port } = s.address();
      s.close(() => ok(port));
    });
  });
}

export async function startServer() {
  const port = await freePort();
  const proc = spawn(process.execPath, [join(ROOT, 'scripts/serve.mjs'), DIST], {
    env: { ...process.env, PORT: String(port) },
    stdio: ['ignore', 'pipe', 'inherit'],
  });
  await new Promise((ok, fail) => {
    proc.once('exit', (code) => fail(new Error(`server exited with ${code}`)));
    proc.stdout.on('data', (d) => { if (String(d).includes('127.0.0.1')) ok(); });
  });
  return { url: `http://127.0.0.1:${port}/`, stop: () => proc.kill() };
}

// Playwright gives every launch a fresh temporary profile (it refuses a
// --user-data-dir flag), and adds --headless itself.
export async function launch() {
  const browser = await chromium.launch({
    executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
    args: FLAGS.filter((f) => f !== '--headless'),
    headless: true,
  });
  return { browser, close: () => browser.close() };
}

// A fresh page that records console errors and uncaught exceptions.
export async function openPage(browser, url) {
  const context = await browser.newContext({ acceptDownloads: true, viewport: { width: 1280, height: 1000 } });
  const page = await context.newPage();
  const problems = [];
  page.on('pageerror', (e) => problems.push(`pageerror: ${e.message}`));
  page.on('console', (m) => { if (m.type() === 'error') problems.push(`console: ${m.text()}`); });
  await page.goto(url);
  return { page, context, problems };
}

// Waits until the current plan finished and offered its G-code.
export async function waitForPlan(page, timeout = 120_000) {
  await page.waitForFunction(() => {
    const s = window.pcpp && window.pcpp.state;
    return s && !s.busy && !s.reading && s.lastPlan && !document.getElementById('dl-gcode').hidden;
  }, null, { timeout });
}

export async function waitIdle(page, timeout = 120_000) {
  await page.waitForFunction(() => window.pcpp && window.pcpp.state && !window.pcpp.state.busy
    && !window.pcpp.state.queued && !window.pcpp.state.reading, null, { timeout });
}

// Waits until the browser has stored the last inputs (before a reload).
export async function waitKept(page, timeout = 60_000) {
  await page.waitForFunction(() => window.pcpp && window.pcpp.state.keeping === 0, null, { timeout });
}

// Settled: nothing in flight or waiting, no drag, the plan on screen is
// for the current settings, compared, and offered for download.
export async function waitSettled(page, timeout = 120_000) {
  await page.waitForFunction(() => {
    const s = window.pcpp && window.pcpp.state;
    return s && !s.busy && !s.queued && !s.reading && !s.interacting && s.lastPlan && s.lastPlan.gen === s.gen
      && s.lastPlan.compared && !document.getElementById('dl-gcode').hidden;
  }, null, { timeout });
}

// Records, from now on, every moment a G-code download is offered whose
// plan is not the one for the settings of that moment, and counts the
// browser's frames.
export async function startProbe(page) {
  await page.evaluate(() => {
    const probe = { raf: 0, staleOffers: [], t0: performance.now() };
    window.__probe = probe;
    const tick = () => {
      probe.raf++;
      probe.handle = requestAnimationFrame(tick);
    };
    probe.handle = requestAnimationFrame(tick);
    const dl = document.getElementById('dl-gcode');
    probe.observer = new MutationObserver(() => {
      const s = window.pcpp.state;
      if (dl.hidden || !dl.getAttribute('href')) return;
      const p = s.lastPlan.placement;
      const now = window.pcpp.settings.placement;
      if (s.lastPlan.gen !== s.gen || p.offset_mm[0] !== now.x || p.offset_mm[1] !== now.y
        || p.rotation_deg !== now.rot || p.scale !== now.scale) {
        probe.staleOffers.push({ planned: p, current: { ...now } });
      }
    });
    probe.observer.observe(dl, { attributes: true, attributeFilter: ['hidden', 'href'] });
  });
}

export async function stopProbe(page) {
  return page.evaluate(() => {
    const p = window.__probe;
    cancelAnimationFrame(p.handle);
    p.observer.disconnect();
    return { raf: p.raf, seconds: (performance.now() - p.t0) / 1000, staleOffers: p.staleOffers };
  });
}

// Downloads through the page's link and returns the bytes and file name.
export async function download(page, linkId) {
  const [dl] = await Promise.all([page.waitForEvent('download'), page.click(`#${linkId}`)]);
  const path = await dl.path();
  const { readFileSync } = await import('node:fs');
  return { name: dl.suggestedFilename(), bytes: readFileSync(path) };
}

// Runs in the page (sent as source by countViewPixels): the 3-D view's
// pixels, read from a 2-D copy of its WebGL canvas, counted into `out`.
function countInPage(out, classify) {
  const gl = document.getElementById('view');
  const c = document.createElement('canvas');
  c.width = gl.width;
  c.height = gl.height;
  const ctx = c.getContext('2d');
  ctx.drawImage(gl, 0, 0);
  const d = ctx.getImageData(0, 0, c.width, c.height).data;
  for (let i = 0; i < d.length; i += 4) {
    const p = i / 4;
    classify(out, d[i], d[i + 1], d[i + 2], p % c.width, Math.floor(p / c.width));
  }
  return out;
}

// Counts the 3-D view's pixels: `out` holds the counters' starting values,
// `classify(out, r, g, b, x, y)` adds each pixel (x, y from the top-left).
// Both go to the page as source: `classify` may use only its arguments.
export async function countViewPixels(page, out, classify) {
  return page.evaluate(`(${countInPage})(${JSON.stringify(out)}, ${classify})`);
}

// Counts view pixels by class: background, mesh (blue-grey), path (the
// saturated defect colours and the white Ta).
export async function viewPixels(page) {
  const start = { total: 0, background: 0, mesh: 0, good: 0, defect: 0, ta: 0 };
  return countViewPixels(page, start, (out, r, g, b) => {
    out.total++;
    if (Math.abs(r - 23) < 6 && Math.abs(g - 26) < 6 && Math.abs(b - 33) < 6) out.background++;
    else if (g > r + 90 && g > b + 60) out.good++;
    else if ((r > g + 100 && r > b + 100) || (b > r + 120 && b > g + 50) || (r > 200 && g > 100 && g < 190 && b < 60)) out.defect++;
    else if (r > 225 && g > 225 && b > 225) out.ta++;
    else if (b > r + 4 && b >= g && b - r < 70 && r > 30) out.mesh++;
  });
}

// One static server and one browser for a test file, started before its
// tests and stopped after them.
export function withPageServer() {
  const env = {};
  before(async () => {
    env.server = await startServer();
    env.chrome = await launch();
  });
  after(async () => {
    await env.chrome?.close();
    env.server?.stop();
  });
  return env;
}

// Two closed boxes as OBJ text: an 80 x 80 x 2 mm plate and a 20 mm post
// standing on its middle (a drawing across it dispenses far above the
// plate beside the post).
export function platePostObj() {
  const lines = [];
  const faces = [];
  const box = ([x0, y0, z0], [x1, y1, z1]) => {
    const base = lines.length;
    for (const z of [z0, z1]) for (const [x, y] of [[x0, y0], [x1, y0], [x1, y1], [x0, y1]]) lines.push(`v ${x} ${y} ${z}`);
    const q = (a, b, c, d) => faces.push(`f ${base + a} ${base + b} ${base + c}`, `f ${base + a} ${base + c} ${base + d}`);
    q(1, 4, 3, 2); q(5, 6, 7, 8);
    q(1, 2, 6, 5); q(2, 3, 7, 6); q(3, 4, 8, 7); q(4, 1, 5, 8);
  };
  box([0, 0, 0], [80, 80, 2]);
  box([30, 30, 2], [50, 50, 22]);
  return `${lines.join('\n')}\n${faces.join('\n')}\n`;
}
