// Fiducials on the page: a point picked on the 3-D view lands on the mesh
// and becomes a scan point; the holes are paired with the printer points
// in an order the user chooses (a wrong order shows a large RMS, the right
// one ~0 on the demo).
import assert from 'node:assert/strict';
import { test } from 'node:test';
import { openPage, waitForPlan, waitIdle, waitSettled, withPageServer } from './helpers.mjs';

const env = withPageServer();

const scanPoints = (page) => page.evaluate(() => window.pcpp.settings.fidScanText
  .split('\n').filter((l) => l.trim()).map((l) => l.split(',').map(Number)));

test('a click in pick mode adds the surface point under the pointer as a scan point', async (t) => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitForPlan(page);
  await page.click('#top-view');
  await page.click('#pick-btn');
  assert.equal(await page.getAttribute('#pick-btn', 'aria-pressed'), 'true');
  assert.equal(await page.isVisible('#fid-scan'), true);
  const box = await page.locator('#view').boundingBox();
  // Looking straight down at the part's centre (40, 40): a little below the
  // centre is the flat band y 26-34 mm between regions 1 and 2, at the
  // base height of 5 mm.
  await page.mouse.click(box.x + box.width / 2, box.y + box.height * 0.58);
  await page.waitForFunction(() => window.pcpp.settings.fidScanText.trim() !== '');
  let pts = await scanPoints(page);
  assert.equal(pts.length, 1);
  const [x, y, z] = pts[0];
  assert.ok(x > 30 && x < 50 && y > 26 && y < 34, `picked ${pts[0]}`);
  assert.ok(Math.abs(z - 5) < 0.01, `z ${z} at (${x}, ${y}), expected the base height 5 mm`);
  assert.match(await page.textContent('#pick-status'), /Sr1/);

  // Off the part the ray misses: nothing is added.
  await page.mouse.click(box.x + 5, box.y + 5);
  await page.waitForFunction(() => /missed/.test(document.getElementById('pick-status').textContent));
  pts = await scanPoints(page);
  assert.equal(pts.length, 1);

  // A second click at the centre lands in region 2 (y 34-48 mm, bumps and
  // dips), inside the scan's box; both picks are drawn as markers.
  await page.mouse.click(box.x + box.width / 2, box.y + box.height * 0.5);
  await page.waitForFunction(() => window.pcpp.settings.fidScanText.trim().split('\n').length === 2);
  pts = await scanPoints(page);
  const [lo, hi] = await page.evaluate(() => window.pcpp.state.info.bbox_mm);
  assert.ok(pts[1][1] > 34 && pts[1][1] < 48, `${pts[1]}`);
  assert.ok(pts[1][2] >= lo[2] - 1e-6 && pts[1][2] <= hi[2] + 1e-6, `${pts[1]} within ${lo}..${hi}`);
  t.diagnostic(`picked ${JSON.stringify(pts)}`);

  // Esc leaves pick mode; a click then only turns the view.
  await page.keyboard.press('Escape');
  assert.equal(await page.getAttribute('#pick-btn', 'aria-pressed'), 'false');
  await page.mouse.click(box.x + box.width / 2, box.y + box.height * 0.6);
  await page.waitForTimeout(300);
  assert.equal((await scanPoints(page)).length, 2);
  assert.deepEqual(problems, []);
  await context.close();
});

test('the order of the holes paired with the printer points sets the registration', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitForPlan(page);
  await page.waitForSelector('#fid-pair-2');
  // The demo part is in the printer frame: each printer point's hole is the
  // one at the same place.
  const right = await page.evaluate(() => {
    const { info } = window.pcpp.state;
    const holes = info.holes.slice(0, 8);
    const printer = window.pcpp.settings.fidPrinterText.split('\n').map((l) => l.split(',').map(Number));
    return printer.map((p) => {
      let best = 0;
      holes.forEach((h, k) => {
        const d = Math.hypot(h.scan[0] - p[0], h.scan[1] - p[1], h.scan[2] - p[2]);
        const b = holes[best].scan;
        if (d < Math.hypot(b[0] - p[0], b[1] - p[1], b[2] - p[2])) best = k;
      });
      return String(best);
    });
  });
  // Auto registration preselects the right pairs.
  for (let i = 0; i < 3; i++) assert.equal(await page.inputValue(`#fid-pair-${i}`), right[i]);

  // Swap the first two: the fit cannot match, the RMS is flagged.
  await page.selectOption('#fid-pair-0', right[1]);
  await page.selectOption('#fid-pair-1', right[0]);
  await page.waitForFunction(() => {
    const r = document.getElementById('rms');
    return r && r.classList.contains('bad');
  }, null, { timeout: 120_000 });
  await waitIdle(page);
  assert.equal(await page.inputValue('#fid-source'), 'points');
  const bad = Number.parseFloat(await page.textContent('#rms'));
  assert.ok(bad > 1, `rms ${bad}`);
  // Each pair shows its residual.
  const residuals = await page.$$eval('#fid-pairs tr td:last-child', (tds) => tds.map((t) => t.textContent));
  assert.equal(residuals.length, 3);
  for (const r of residuals) assert.match(r, /^\d+\.\d{4} mm$/);

  // Back to the right order: the RMS is ~0 again.
  await page.selectOption('#fid-pair-0', right[0]);
  await page.selectOption('#fid-pair-1', right[1]);
  await page.waitForFunction(() => {
    const r = document.getElementById('rms');
    return r && !r.classList.contains('bad') && Number.parseFloat(r.textContent) < 1e-3;
  }, null, { timeout: 120_000 });
  await waitForPlan(page);
  assert.ok(Number.parseFloat(await page.textContent('#rms')) < 1e-3);
  assert.deepEqual(problems, []);
  await context.close();
});

// Printer points that no choice of holes fits (collinear here) left the
// header saying "registered (lsq, 3 fiducials, RMS residual 0.000 mm)"
// beside "Could not register": it says the scan is not registered until
// the points fit again.
test('the header says the scan is not registered while its fiducials do not fit', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitSettled(page);
  const good = await page.inputValue('#fid-printer');
  assert.match(await page.textContent('#reg-status'), /^registered \(lsq, 3 fiducials/);
  await page.fill('#fid-printer', '10, 10, 5\n20, 20, 5\n30, 30, 5');
  await page.waitForFunction(() => /^Could not register/.test(document.getElementById('error-title').textContent),
    null, { timeout: 120_000 });
  await waitIdle(page);
  assert.equal(await page.textContent('#reg-status'), 'not registered: the fiducials do not fit (see the error)');
  assert.equal(await page.$eval('#reg-status', (e) => e.parentElement.classList.contains('unregistered')), true);
  // Nor the last registration's residuals (a perfect 0.0000 beside the
  // error).
  assert.equal(await page.textContent('#fid-residuals'), 'No residuals: the registration failed (see the error).');
  // The points back: registered again.
  await page.fill('#fid-printer', good);
  await waitSettled(page);
  assert.match(await page.textContent('#reg-status'), /^registered \(lsq, 3 fiducials/);
  assert.match(await page.textContent('#fid-residuals'), /^Residuals: /);
  assert.equal(await page.isHidden('#error-panel'), true, await page.textContent('#error-message'));
  assert.deepEqual(problems, []);
  await context.close();
});

// The part sits elsewhere on the printer than where it was scanned, and
// turned: typed printer points move the registered scan, and the drawing
// placed on it stayed where it was, so the next plan printed the few lines
// still over the part and warned that the others missed it. The drawing
// goes with the scan (as when the scan is placed on the bed by hand) and
// stays on the same spot of the part.
test('a registration that moves the scan carries the drawing with it', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitSettled(page);
  const before = await page.evaluate(() => ({
    placement: { ...window.pcpp.settings.placement },
    printer: window.pcpp.settings.fidPrinterText,
    points: window.pcpp.state.lastPlan.summary.quality.points,
  }));
  assert.match(await page.textContent('#reg-status'), /^registered \(lsq, 3 fiducials/);
  // The part a quarter turn anticlockwise and moved: (x, y) -> (150 - y, 20 + x).
  const move = ([x, y]) => [150 - y, 20 + x];
  const points = before.printer.split('\n').filter((l) => l.trim()).map((l) => l.split(',').map(Number));
  const typed = points.map(([x, y, z]) => `${move([x, y]).join(', ')}, ${z}`);
  // First with one point mistyped by 5 mm: registered far off its printer
  // points, so no plan, and the drawing is not carried there (nor back).
  const wrong = [...typed];
  wrong[2] = wrong[2].replace(/^(-?[\d.]+)/, (x) => String(Number(x) + 5));
  await page.fill('#fid-printer', wrong.join('\n'));
  await page.waitForFunction(() => /^The registration puts the scan/.test(document.getElementById('error-title').textContent),
    null, { timeout: 120_000 });
  await waitIdle(page);
  assert.deepEqual(await page.evaluate(() => ({ ...window.pcpp.settings.placement })), before.placement);
  await page.fill('#fid-printer', typed.join('\n'));
  await page.waitForFunction(() => {
    const info = window.pcpp.state.info;
    return info && info.bbox_mm[1][0] > 140;
  }, null, { timeout: 120_000 });
  await waitSettled(page);
  assert.equal(await page.isHidden('#error-panel'), true, await page.textContent('#error-message'));
  const after = await page.evaluate(() => ({
    placement: { ...window.pcpp.settings.placement },
    planned: window.pcpp.state.lastPlan.summary.settings.placement,
    points: window.pcpp.state.lastPlan.summary.quality.points,
    warnings: document.getElementById('warnings').textContent,
  }));
  const want = move([before.placement.x, before.placement.y]);
  const p = after.placement;
  const says = `${JSON.stringify(before.placement)} -> ${JSON.stringify(p)}`;
  assert.ok(Math.abs(p.x - want[0]) < 1e-3 && Math.abs(p.y - want[1]) < 1e-3, says);
  assert.equal(Number(p.rot), Number(before.placement.rot) + 90, says);
  assert.equal(Number(p.scale), Number(before.placement.scale));
  // What was planned is the carried drawing, all of it, shown in the fields.
  assert.deepEqual(after.planned.offset_mm, [p.x, p.y]);
  assert.equal(after.points, before.points);
  assert.doesNotMatch(after.warnings, /misses the scan|off the scan/);
  assert.equal(Number(await page.inputValue('#pl-x')), Number(p.x));
  assert.equal(await page.isVisible('#dl-gcode'), true);

  // No fiducials: the scan is back where it was scanned, and so is the
  // drawing.
  await page.selectOption('#fid-source', 'none');
  await page.waitForFunction(() => {
    const info = window.pcpp.state.info;
    return info && info.bbox_mm[1][0] < 100;
  }, null, { timeout: 120_000 });
  await waitSettled(page);
  const back = await page.evaluate(() => ({ ...window.pcpp.settings.placement }));
  assert.ok(Math.abs(back.x - before.placement.x) < 1e-3 && Math.abs(back.y - before.placement.y) < 1e-3,
    `${JSON.stringify(before.placement)} -> ${JSON.stringify(back)}`);
  assert.equal(Number(back.rot), Number(before.placement.rot));
  assert.equal(await page.isHidden('#error-panel'), true, await page.textContent('#error-message'));
  assert.deepEqual(problems, []);
  await context.close();
});
