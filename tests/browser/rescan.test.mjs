// The drawing's placement when what it lies on changes: another machine
// profile's bed, the scan's units or up axis, another scan, "Centre on
// scan", a built-in antenna's size. The fields show what is planned, and a
// scale the page chose to fit one scan is not kept for the next: the
// user's own scale is (found by exploratory QA with real scans).
import assert from 'node:assert/strict';
import { join } from 'node:path';
import { test } from 'node:test';
import { ROOT, openPage, waitForPlan, waitIdle, waitSettled, withPageServer } from './helpers.mjs';

const env = withPageServer();
// The Stanford bunny (tests/data/realworld/SOURCES.md): y up, about 10 mm
// across as read (file default units), outside the marlin bed as it is.
const BUNNY = join(ROOT, 'tests/data/realworld/mesh/stanford-bunny.ply');
// assimp's spider (same SOURCES.md): about 6 x 8 mm.
const SPIDER = join(ROOT, 'tests/data/realworld/mesh/Spider_binary.stl');

// The placement fields as typed, the settings and the plan on screen's.
const placements = (page) => page.evaluate(() => {
  const v = (id) => Number(document.getElementById(id).value);
  const s = window.pcpp.settings.placement;
  const p = window.pcpp.state.lastPlan.placement;
  return {
    form: [v('pl-x'), v('pl-y'), v('pl-rot'), v('pl-scale')],
    settings: [s.x, s.y, s.rot, s.scale],
    planned: [...p.offset_mm, p.rotation_deg, p.scale],
  };
});

// Opens the bunny (up +Y) and places it on the bed: the demo drawing is
// centred on it, scaled to fit.
async function bunnyOnBed(page) {
  await page.selectOption('#scan-up', 'y');
  await page.setInputFiles('#scan-input', BUNNY);
  await page.waitForSelector('#place-banner:not([hidden])', { timeout: 120_000 });
  await waitIdle(page);
  await page.click('#place-bed-btn');
  await waitSettled(page);
}

test('another dialect moves the scan to its bed: the offset fields show the offsets planned, and a nudge moves from there', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitForPlan(page);
  await bunnyOnBed(page);
  const marlin = await placements(page);
  assert.deepEqual(marlin.form, marlin.settings);
  assert.deepEqual(marlin.form, marlin.planned);

  await page.selectOption('#dialect', 'grbl');
  await waitSettled(page);
  const grbl = await placements(page);
  assert.notDeepEqual(grbl.planned, marlin.planned, 'grbl has another bed: the drawing went with the scan');
  assert.deepEqual(grbl.form, grbl.planned, 'the fields show the offsets planned');
  assert.deepEqual(grbl.settings, grbl.planned);

  // One more millimetre in Offset Y moves the drawing 1 mm, still on the
  // scan.
  await page.fill('#pl-y', String(grbl.form[1] + 1));
  await waitSettled(page);
  assert.equal(await page.isHidden('#error-panel'), true, await page.textContent('#error-message'));
  const nudged = await placements(page);
  assert.ok(Math.abs(nudged.planned[1] - grbl.planned[1] - 1) < 1e-9, JSON.stringify([grbl, nudged]));
  assert.equal(nudged.planned[0], grbl.planned[0]);
  assert.deepEqual(problems, []);
  await context.close();
});
