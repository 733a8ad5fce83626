// The page opens with the built-in demo planned, draws it, and offers the
// G-code; the screenshot of the planned demo is kept in target/.
import assert from 'node:assert/strict';
import { mkdirSync } from 'node:fs';
import { test } from 'node:test';
import { join } from 'node:path';
import { ROOT, download, openPage, viewPixels, waitForPlan, withPageServer } from './helpers.mjs';

const env = withPageServer();

test('the demo plans on load, is drawn, and its G-code downloads', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitForPlan(page);
  // The comparison of every planner arrives after the plan.
  await page.waitForFunction(() => document.querySelectorAll('#compare-table tbody tr').length === 5);
  const planners = await page.$$eval('#compare-table tbody tr td:first-child', (tds) => tds.map((t) => t.textContent));
  assert.deepEqual(planners, ['constant', 'slope', 'pcpp', 'pcpp-guarded', 'even']);

  // Registration against the demo's three holes: residuals shown, RMS small.
  const rms = await page.textContent('#rms');
  assert.match(rms, /^0\.0\d* mm$/);
  assert.equal(await page.$eval('#rms', (e) => e.classList.contains('bad')), false);

  // The canvas shows the mesh and the path, read back from WebGL.
  const px = await viewPixels(page);
  assert.ok(px.mesh > px.total * 0.05, `mesh pixels: ${JSON.stringify(px)}`);
  assert.ok(px.good > 200, `good-path pixels: ${JSON.stringify(px)}`);
  assert.ok(px.ta > 100, `surface-path pixels: ${JSON.stringify(px)}`);

  const gcode = await download(page, 'dl-gcode');
  assert.equal(gcode.name, 'demo-test-part-lines-even.gcode');
  const text = gcode.bytes.toString('utf8');
  assert.match(text, /G1 /);
  assert.match(text, /demo-test-part\.ply/);
  // The report is written by the worker when its link is pressed, not at
  // every plan: no link before, the same bytes as the plan's own after,
  // and the keyboard presses it too.
  assert.equal(await page.getAttribute('#dl-report', 'href'), null);
  assert.equal(await page.getAttribute('#dl-report', 'tabindex'), '0');
  const report = await download(page, 'dl-report');
  assert.equal(report.name, 'demo-test-part-lines-even.json');
  const json = JSON.parse(report.bytes.toString('utf8'));
  assert.equal(json.planner, 'even');
  assert.equal(json.toolpath.length, 6);
  assert.equal(report.bytes.toString('utf8'), await page.evaluate(() => window.pcpp.state.lastPlan.report()));
  assert.ok(report.bytes.toString('utf8').endsWith('}\n'));
  const again = await Promise.all([page.waitForEvent('download'), page.focus('#dl-report').then(() => page.keyboard.press('Enter'))]);
  assert.equal(again[0].suggestedFilename(), 'demo-test-part-lines-even.json');

  mkdirSync(join(ROOT, 'target'), { recursive: true });
  await page.screenshot({ path: join(ROOT, 'target/screenshot-demo.png'), fullPage: true });
  assert.deepEqual(problems, []);
  await context.close();
});

test('settings persist across reloads and a placement change re-plans', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitForPlan(page);
  const before = await page.evaluate(() => window.pcpp.state.lastPlan.gcode);
  await page.fill('#pl-x', '1.5');
  await page.waitForFunction((g) => {
    const s = window.pcpp.state;
    return !s.busy && !s.queued && s.lastPlan && s.lastPlan.gcode !== g
      && !document.getElementById('dl-gcode').hidden;
  }, before, { timeout: 120_000 });
  const json = JSON.parse(await page.evaluate(() => window.pcpp.state.lastPlan.report()));
  assert.equal(json.settings.placement.offset_mm[0], 1.5);
  await page.reload();
  await waitForPlan(page);
  assert.equal(await page.inputValue('#pl-x'), '1.5');
  assert.deepEqual(problems, []);
  await context.close();
});
