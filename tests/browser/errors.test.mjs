// Bad input shows the error panel naming the cause, keeps what was loaded
// and the previous plan on screen, and offers no stale download.
import assert from 'node:assert/strict';
import { test } from 'node:test';
import { download, openPage, viewPixels, waitForPlan, waitIdle, withPageServer } from './helpers.mjs';

const env = withPageServer();

const file = (name, text) => ({ name, mimeType: 'application/octet-stream', buffer: Buffer.from(text) });

test('a corrupt scan shows the error, keeps the previous plan, offers no download', async () => {
  const { page, context } = await openPage(env.chrome.browser, env.server.url);
  await waitForPlan(page);
  const before = await page.evaluate(() => window.pcpp.state.lastPlan.gcode);

  await page.setInputFiles('#scan-input', file('broken.stl', 'solid broken\nfacet normal 0 0 1\n outer loop\n  vertex 1 2\n'));
  await page.waitForSelector('#error-panel:not([hidden])');
  await waitIdle(page);
  const message = await page.textContent('#error-message');
  const title = await page.textContent('#error-title');
  assert.match(title, /broken\.stl/);
  assert.match(message, /broken\.stl/);
  assert.match(message, /demo-test-part\.ply/); // still using the previous scan
  assert.equal(await page.isHidden('#dl-gcode'), true);
  assert.equal(await page.isHidden('#dl-report'), true);
  // The previous plan stays on screen and in memory.
  assert.equal(await page.evaluate(() => window.pcpp.state.lastPlan.gcode), before);
  assert.equal(await page.textContent('#scan-name'), 'demo-test-part.ply');
  const px = await viewPixels(page);
  assert.ok(px.mesh > 1000 && px.good > 100, JSON.stringify(px));

  // Planning again uses the previous scan and offers the G-code again.
  await page.click('#plan-btn');
  await waitForPlan(page);
  const again = await download(page, 'dl-gcode');
  assert.equal(again.bytes.toString('utf8'), before);
  await context.close();
});

test('a corrupt SVG names the file and falls back; bad settings name the parameter', async () => {
  const { page, context } = await openPage(env.chrome.browser, env.server.url);
  await waitForPlan(page);
  await page.setInputFiles('#svg-input', file('nonsense.svg', '<svg xmlns="http://www.w3.org/2000/svg"><path d="M 0 0 L'));
  await page.waitForSelector('#error-panel:not([hidden])');
  await waitIdle(page);
  assert.match(await page.textContent('#error-title'), /nonsense\.svg/);
  assert.equal(await page.isHidden('#dl-gcode'), true);
  assert.equal(await page.inputValue('#path-source'), 'demo');

  await page.fill('#nz-od', '0.1'); // smaller than the inner diameter
  await page.dispatchEvent('#nz-od', 'change');
  await page.waitForFunction(() => /outer diameter/.test(document.getElementById('error-message').textContent));
  await waitIdle(page);
  assert.equal(await page.isHidden('#dl-gcode'), true);
  assert.equal(await page.inputValue('#nz-od'), '0.1'); // what the user typed stays
  await context.close();
});

test('fiducial residuals are shown and an RMS above d/2 is highlighted', async () => {
  const { page, context } = await openPage(env.chrome.browser, env.server.url);
  await waitForPlan(page);
  assert.equal(await page.$eval('#rms', (e) => e.classList.contains('bad')), false);
  // Move one printer point by 2 mm: the best rigid fit leaves ~0.9 mm RMS.
  await page.fill('#fid-printer', '4, 4, 5\n78, 4, 5\n4, 76, 5');
  await page.waitForFunction(() => {
    const r = document.getElementById('rms');
    return r && r.classList.contains('bad');
  }, null, { timeout: 120_000 });
  await waitIdle(page);
  const rms = Number.parseFloat(await page.textContent('#rms'));
  assert.ok(rms > 0.3015, `${rms}`);
  await context.close();
});

test('cancel ends the worker; a dropped SVG then plans on a fresh one', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitForPlan(page);
  // Plan and cancel in one task: a re-plan on the kept session now ends in
  // well under 100 ms, faster than two separate clicks from the test.
  await page.evaluate(() => {
    document.getElementById('plan-btn').click();
    document.getElementById('cancel-btn').click();
  });
  assert.equal(await page.textContent('#plan-status'), 'cancelled');
  assert.equal(await page.isHidden('#dl-gcode'), true);
  // Drag and drop, as a user would drop a file on the page.
  await page.evaluate(() => {
    const svg = '<svg xmlns="http://www.w3.org/2000/svg" width="80mm" height="80mm" viewBox="0 0 80 80">'
      + '<path d="M 10 40 L 70 40" stroke="black"/></svg>';
    const dt = new DataTransfer();
    dt.items.add(new File([svg], 'dropped.svg', { type: 'image/svg+xml' }));
    window.dispatchEvent(new DragEvent('drop', { dataTransfer: dt, cancelable: true }));
  });
  await page.waitForFunction(() => document.getElementById('svg-name').textContent === 'dropped.svg');
  await waitIdle(page);
  await waitForPlan(page);
  assert.equal(await page.evaluate(() => window.pcpp.state.lastPlan.svgName), 'dropped.svg');
  assert.deepEqual(problems, []);
  await context.close();
});
