// Regression tests for the page's state after a cancel, a reload and a
// turn, found by exploratory QA: a cancelled scan import left the page
// half-stuck and loaded later anyway; a drawing too long for the page
// left its placement on the good drawing reopened after a reload; the
// Turn slider turned the drawing about its SVG origin, off the scan.
import assert from 'node:assert/strict';
import { mkdtempSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { after, before, test } from 'node:test';
import {
  download, openPage, waitIdle, waitKept, waitSettled, withPageServer,
} from './helpers.mjs';

const env = withPageServer();

let dir;
before(() => { dir = mkdtempSync(join(tmpdir(), 'pcpp-pagestate-')); });
after(() => { if (dir) rmSync(dir, { recursive: true, force: true }); });

const svgFile = (name, text) => ({ name, mimeType: 'image/svg+xml', buffer: Buffer.from(text) });

// A 30 x 10 mm zigzag, small enough to fit the demo part at full size.
const SMALL_SVG = '<svg xmlns="http://www.w3.org/2000/svg" width="60mm" height="40mm" viewBox="0 0 60 40">'
  + '<path d="M 5 5 L 15 15 L 25 5 L 35 15" fill="none" stroke="black"/></svg>\n';

// A point cloud of `n` x `n` points over 100 x 100 mm, 5 mm up with a
// gentle wave: some 15 MB for n = 800, seconds to mesh in the page.
function bigCloud(n) {
  const rows = [];
  for (let j = 0; j < n; j++) {
    for (let i = 0; i < n; i++) {
      const x = (100 * i) / (n - 1);
      const y = (100 * j) / (n - 1);
      rows.push(`${x.toFixed(4)} ${y.toFixed(4)} ${(5 + 0.3 * Math.sin(x / 5) * Math.cos(y / 7)).toFixed(4)}`);
    }
  }
  return `${rows.join('\n')}\n`;
}

// The middle of the box of the planned surface path (Ta) in XY.
const taCentre = (page) => page.evaluate(() => {
  const ta = window.pcpp.state.lastPlan.view.ta;
  let [x0, y0, x1, y1] = [Infinity, Infinity, -Infinity, -Infinity];
  for (let i = 0; i < ta.length; i += 3) {
    x0 = Math.min(x0, ta[i]);
    x1 = Math.max(x1, ta[i]);
    y0 = Math.min(y0, ta[i + 1]);
    y1 = Math.max(y1, ta[i + 1]);
  }
  return [(x0 + x1) / 2, (y0 + y1) / 2];
});

const near = (a, b, tol, what) => assert.ok(Math.hypot(a[0] - b[0], a[1] - b[1]) < tol,
  `${what}: (${a}) is not (${b})`);

// A slider moved through `values` (input events), then let go (change).
const slide = (page, id, values) => page.evaluate(([i, vs]) => {
  const el = document.getElementById(i);
  for (const v of vs) {
    el.value = String(v);
    el.dispatchEvent(new Event('input', { bubbles: true }));
  }
  el.dispatchEvent(new Event('change', { bubbles: true }));
}, [id, values]);

// The G-code header's placement line says what the fields show.
async function headerMatchesFields(page) {
  const gcode = await page.evaluate(() => window.pcpp.state.lastPlan.gcode);
  const line = gcode.split('\n').find((l) => /offset \(.*\) mm, rotation .* deg, scale /.test(l));
  assert.ok(line, 'no placement line in the G-code header');
  const [x, y, rot, scale] = await Promise.all(['#pl-x', '#pl-y', '#pl-rot', '#pl-scale'].map((s) => page.inputValue(s)));
  assert.ok(line.includes(`offset (${x}, ${y}) mm, rotation ${rot} deg, scale ${scale}`), `${line} vs ${[x, y, rot, scale]}`);
}

test('a chosen file still being read keeps the page unsettled: the plan waited for is the new drawing\'s', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitSettled(page);
  // A slow disk: the drawing's bytes arrive a second and a half after it
  // is chosen, and until then the demo's plan is on screen, settled.
  await page.evaluate(() => {
    const read = Blob.prototype.arrayBuffer;
    Blob.prototype.arrayBuffer = function slow() {
      return new Promise((ok) => setTimeout(ok, 1500)).then(() => read.call(this));
    };
  });
  await page.setInputFiles('#svg-input', svgFile('small.svg', SMALL_SVG));
  assert.equal(await page.evaluate(() => window.pcpp.state.reading), 1);
  await waitSettled(page);
  assert.equal(await page.evaluate(() => window.pcpp.state.lastPlan.svgName), 'small.svg');
  assert.equal(await page.evaluate(() => window.pcpp.state.reading), 0);
  assert.deepEqual(problems, []);
  await context.close();
});

test('a cancelled scan import is dropped: the scan before it, its name and its G-code stay, and nothing resumes it', async () => {
  const cloud = join(dir, 'big_cloud.xyz');
  writeFileSync(cloud, bigCloud(800));
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitSettled(page);
  const good = await page.evaluate(() => window.pcpp.state.lastPlan.gcode);
  const status = await page.textContent('#plan-status');

  await page.setInputFiles('#scan-input', cloud);
  // Cancelled as soon as the import shows it runs (the Cancel button).
  const log = await page.evaluate(() => new Promise((ok, fail) => {
    const s = window.pcpp.state;
    const cancel = document.getElementById('cancel-btn');
    const until = Date.now() + 60_000;
    const poll = () => {
      if (s.busy && s.pendingScan && s.busy.scan === s.pendingScan && !cancel.hidden) {
        cancel.click();
        ok(s.progressLog.slice());
      } else if (Date.now() > until) {
        fail(new Error('the import was never seen running'));
      } else setTimeout(poll, 0);
    };
    poll();
  }));
  assert.ok(log.some((l) => /big_cloud\.xyz/.test(l)), JSON.stringify(log));
  assert.equal(await page.evaluate(() => window.pcpp.state.pendingScan), null);
  assert.equal(await page.textContent('#scan-name'), 'demo-test-part.ply');
  assert.equal(await page.textContent('#plan-status'), `cancelled reading big_cloud.xyz: ${status}`);
  // The plan on screen is still the plan of the inputs: its G-code offered.
  assert.equal(await page.isVisible('#dl-gcode'), true);
  assert.equal((await download(page, 'dl-gcode')).bytes.toString('utf8'), good);
  // Its report went with the ended worker: not offered.
  assert.equal(await page.isHidden('#dl-report'), true);
  // Nothing comes back later.
  await page.waitForTimeout(1500);
  assert.equal(await page.textContent('#scan-name'), 'demo-test-part.ply');
  assert.equal(await page.evaluate(() => window.pcpp.state.busy), null);

  // The next action plans on the scan kept, not the cancelled one.
  await page.setInputFiles('#svg-input', svgFile('small.svg', SMALL_SVG));
  await waitSettled(page);
  const st = await page.evaluate(() => {
    const s = window.pcpp.state;
    return {
      scan: s.scan.name, info: s.info.name, planned: s.lastPlan.scanName, svg: s.lastPlan.svgName, log: s.progressLog,
    };
  });
  assert.deepEqual({ ...st, log: undefined }, {
    scan: 'demo-test-part.ply', info: 'demo-test-part.ply', planned: 'demo-test-part.ply', svg: 'small.svg', log: undefined,
  });
  assert.ok(!st.log.some((l) => /big_cloud/.test(l)), JSON.stringify(st.log));
  assert.equal(await page.textContent('#scan-name'), 'demo-test-part.ply');
  assert.equal(await page.isVisible('#dl-report'), true);
  assert.deepEqual(problems, []);
  await context.close();
});

test('a cancelled drawing goes back to the drawing before it, where it was placed, and its G-code is offered', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitSettled(page);
  const good = await page.evaluate(() => window.pcpp.state.lastPlan.gcode);
  const placement = await page.evaluate(() => ({ ...window.pcpp.settings.placement }));
  // The watch is set before the file is given: a small drawing is read and
  // planned in a few milliseconds, which a watch set after it could miss
  // (the test then waited for ever on a busy machine); and it gives up
  // after a minute rather than hang.
  const cancelled = page.evaluate(() => new Promise((ok, fail) => {
    const s = window.pcpp.state;
    const until = Date.now() + 60_000;
    const poll = () => {
      if (s.busy && s.pendingSvg && s.busy.svg === s.pendingSvg) {
        document.getElementById('cancel-btn').click();
        ok();
      } else if (Date.now() > until) {
        fail(new Error('the drawing was never seen being read or planned'));
      } else setTimeout(poll, 0);
    };
    poll();
  }));
  await page.setInputFiles('#svg-input', svgFile('small.svg', SMALL_SVG));
  await cancelled;
  assert.equal(await page.evaluate(() => window.pcpp.state.pendingSvg), null);
  assert.equal(await page.textContent('#svg-name'), 'demo: test-part drawing');
  assert.deepEqual(await page.evaluate(() => ({ ...window.pcpp.settings.placement })), placement);
  assert.match(await page.textContent('#plan-status'), /^cancelled small\.svg: planned demo-test-part-lines\.svg on demo-test-part\.ply/);
  assert.equal((await download(page, 'dl-gcode')).bytes.toString('utf8'), good);
  // A later plan is the demo drawing's again.
  await page.click('#plan-btn');
  await waitSettled(page);
  assert.equal(await page.evaluate(() => window.pcpp.state.lastPlan.svgName), 'demo-test-part-lines.svg');
  assert.deepEqual(problems, []);
  await context.close();
});

test('after a drawing too long for the page, a reload reopens the last good drawing at its own placement', async () => {
  // 20 000 octagons 16 mm across (straight sides: few points to read, as
  // many samples as circles): fitted to the part, some 2 million samples.
  const circles = ['<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="100mm" viewBox="0 0 100 100">'];
  const corners = [...Array(8).keys()].map((k) => [8 * Math.cos((k * Math.PI) / 4), 8 * Math.sin((k * Math.PI) / 4)]);
  for (let j = 0; j < 100; j++) {
    for (let i = 0; i < 200; i++) {
      const d = corners.map(([x, y], k) => `${k ? 'L' : 'M'}${(i / 2 + x).toFixed(2)} ${(j + y).toFixed(2)}`).join(' ');
      circles.push(`<path d="${d} Z" fill="none" stroke="black"/>`);
    }
  }
  circles.push('</svg>\n');
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitSettled(page);
  await page.setInputFiles('#svg-input', svgFile('small.svg', SMALL_SVG));
  await page.waitForFunction(() => window.pcpp.state.lastPlan.svgName === 'small.svg');
  await waitSettled(page);
  const good = await page.evaluate(() => ({ ...window.pcpp.settings.placement }));

  await page.setInputFiles('#svg-input', svgFile('circles.svg', circles.join('\n')));
  await page.waitForFunction(() => window.pcpp.state.planId > 0 && !document.getElementById('error-panel').hidden,
    null, { timeout: 120_000 });
  await waitIdle(page);
  assert.equal(await page.textContent('#error-title'), 'The path is too long for the page', await page.textContent('#error-message'));
  // The failed drawing was centred and fitted where the good one was not.
  const failed = await page.evaluate(() => ({ ...window.pcpp.settings.placement }));
  assert.notDeepEqual(failed, good);
  assert.ok(failed.scale < 1, JSON.stringify(failed));

  await waitKept(page);
  await page.reload();
  await page.waitForFunction(() => window.pcpp && window.pcpp.state.lastPlan, null, { timeout: 120_000 });
  await waitSettled(page);
  assert.equal(await page.textContent('#svg-name'), 'small.svg');
  assert.deepEqual(await page.evaluate(() => ({ ...window.pcpp.settings.placement })), good);
  const planned = await page.evaluate(() => window.pcpp.state.lastPlan.placement);
  assert.deepEqual(planned, { offset_mm: [good.x, good.y], rotation_deg: good.rot, scale: good.scale });
  assert.equal(await page.isHidden('#error-panel'), true, await page.textContent('#error-message'));
  assert.deepEqual(problems, []);
  await context.close();
});

test('the Turn and Size sliders turn and size the drawing about its middle', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitSettled(page);
  const start = await page.evaluate(() => ({ ...window.pcpp.settings.placement }));
  const centre = await taCentre(page);

  // Half a turn with the slider: the drawing stays on the part, its
  // middle where it was.
  await slide(page, 'pl-rot-range', [30, 90, 150, 180]);
  await waitIdle(page);
  assert.equal(await page.isHidden('#error-panel'), true, await page.textContent('#error-message'));
  await waitSettled(page, 30_000);
  assert.equal(await page.evaluate(() => window.pcpp.state.lastPlan.placement.rotation_deg), 180);
  near(await taCentre(page), centre, 0.05, 'the middle after half a turn');
  await headerMatchesFields(page);

  // A quarter turn (the box of the turned drawing is its box turned, so
  // the same middle).
  await slide(page, 'pl-rot-range', [120, 90]);
  await waitSettled(page, 30_000);
  assert.equal(await page.evaluate(() => window.pcpp.state.lastPlan.placement.rotation_deg), 90);
  near(await taCentre(page), centre, 0.05, 'the middle at 90 degrees');
  await headerMatchesFields(page);

  // Smaller with the Size slider.
  await slide(page, 'pl-scale-range', [0.9, 0.8]);
  await waitSettled(page, 30_000);
  assert.equal(await page.evaluate(() => window.pcpp.state.lastPlan.placement.scale), 0.8);
  near(await taCentre(page), centre, 0.05, 'the middle at 0.8 times');
  await headerMatchesFields(page);

  // At 45 degrees the turned drawing's own box is larger: the middle of
  // the drawing's box (from the unturned plan, centre - offset) is where
  // the placement puts it.
  await slide(page, 'pl-rot-range', [60, 45]);
  await waitSettled(page, 30_000);
  const p = await page.evaluate(() => window.pcpp.state.lastPlan.placement);
  const c = [centre[0] - start.x, centre[1] - start.y];
  const a = (45 * Math.PI) / 180;
  const at = [p.offset_mm[0] + p.scale * (Math.cos(a) * c[0] - Math.sin(a) * c[1]),
    p.offset_mm[1] + p.scale * (Math.sin(a) * c[0] + Math.cos(a) * c[1])];
  near(at, centre, 0.05, 'the middle at 45 degrees');
  await headerMatchesFields(page);

  // Back to no turn and full size: exactly where it started.
  await slide(page, 'pl-scale-range', [1]);
  await slide(page, 'pl-rot-range', [0]);
  await waitSettled(page, 30_000);
  assert.deepEqual(await page.evaluate(() => ({ ...window.pcpp.settings.placement })), start);
  assert.deepEqual(problems, []);
  await context.close();
});
