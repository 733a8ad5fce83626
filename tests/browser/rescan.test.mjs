// The drawing's placement when what it lies on changes: another machine
// profile's bed, the scan's units or up axis, another scan, "Centre on
// scan", a built-in antenna's size. The fields show what is planned, and a
// scale the page chose to fit one scan is not kept for the next: the
// user's own scale is (found by exploratory QA with real scans).
import assert from 'node:assert/strict';
import { mkdtempSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { after, before, test } from 'node:test';
import {
  ROOT, openPage, waitForPlan, waitIdle, waitKept, waitSettled, withPageServer,
} from './helpers.mjs';

const env = withPageServer();
// The Stanford bunny (tests/data/realworld/SOURCES.md): y up, about 10 mm
// across as read (file default units), outside the marlin bed as it is.
const BUNNY = join(ROOT, 'tests/data/realworld/mesh/stanford-bunny.ply');
// assimp's spider (same SOURCES.md): about 6 x 8 mm.
const SPIDER = join(ROOT, 'tests/data/realworld/mesh/Spider_binary.stl');

let dir;
before(() => { dir = mkdtempSync(join(tmpdir(), 'pcpp-rescan-')); });
after(() => { if (dir) rmSync(dir, { recursive: true, force: true }); });

// A flat 100 x 100 mm plate on the marlin bed: the demo drawing (68 x 50
// mm) fits on it at its own size.
function plate() {
  const path = join(dir, 'plate.obj');
  writeFileSync(path, 'v 10 10 0\nv 110 10 0\nv 110 110 0\nv 10 110 0\nf 1 2 3\nf 1 3 4\n');
  return path;
}

// Opens a scan and waits until it is read and its plan done (planned or
// refused: the spider lies outside the bed as it is).
async function openScan(page, path, name) {
  await page.setInputFiles('#scan-input', path);
  await page.waitForFunction((n) => window.pcpp.state.info && window.pcpp.state.info.name === n
    && !window.pcpp.state.busy && !window.pcpp.state.queued, name, { timeout: 120_000 });
}

const scale = (page) => page.evaluate(() => window.pcpp.settings.placement.scale);

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

test('a scale the page chose to fit one scan is not kept for the next, nor across "Centre on scan" and a reload: the user\'s is', async () => {
  const platePath = plate();
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitForPlan(page);
  assert.equal(await scale(page), 1);

  // The spider: the demo drawing shrunk to fit it, with the core's note.
  await openScan(page, SPIDER, 'Spider_binary.stl');
  const spider = await scale(page);
  assert.ok(spider < 0.15, `${spider}`);
  assert.match(await page.textContent('#pl-note'), /scaled by 0\.\d+ to fit/);

  // The plate is larger: the drawing at the user's scale again, no note.
  await openScan(page, platePath, 'plate.obj');
  await waitSettled(page);
  assert.equal(await scale(page), 1);
  assert.equal(await page.inputValue('#pl-scale'), '1');
  assert.equal(await page.textContent('#pl-note'), '');

  // The spider again, then "Centre on scan" twice: fitted from the user's
  // scale each time, the same scale.
  await openScan(page, SPIDER, 'Spider_binary.stl');
  assert.equal(await scale(page), spider);
  for (const k of [1, 2]) {
    await page.click('#center-btn');
    await page.waitForTimeout(100);
    await waitIdle(page);
    assert.equal(await scale(page), spider, `centred ${k} time(s)`);
  }

  // Across a reload: the plate after it still gets the user's scale.
  await waitKept(page);
  await page.reload();
  await page.waitForFunction(() => window.pcpp && window.pcpp.state.info
    && window.pcpp.state.info.name === 'Spider_binary.stl' && !window.pcpp.state.busy, null, { timeout: 120_000 });
  assert.equal(await scale(page), spider);
  assert.match(await page.textContent('#pl-note'), /scaled by 0\.\d+ to fit/);
  await openScan(page, platePath, 'plate.obj');
  await waitSettled(page);
  assert.equal(await scale(page), 1);

  // A scale the user types is theirs: fitted down for the spider, back for
  // the plate.
  await page.fill('#pl-scale', '0.5');
  await waitSettled(page);
  await openScan(page, SPIDER, 'Spider_binary.stl');
  assert.ok(Math.abs(await scale(page) - spider) < 1e-12);
  await openScan(page, platePath, 'plate.obj');
  await waitSettled(page);
  assert.equal(await scale(page), 0.5);
  assert.deepEqual(problems, []);
  await context.close();
});

test('new units or up axis for the scan centre the drawing again from the user\'s scale, with a note for the scan as now read', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitForPlan(page);
  // Read in mm (the file's default), the bunny is 10 mm across: the demo
  // drawing is shrunk to fit it.
  await openScan(page, BUNNY, 'stanford-bunny.ply');
  const small = await scale(page);
  assert.ok(small < 0.2, `${small}`);
  assert.match(await page.textContent('#pl-note'), /footprint \(9\.\d x 9\.\d mm\)/);

  // In cm it is 10 times as large: the drawing fits at its own size, on
  // the middle of the footprint, and the note of the 10 mm scan is gone.
  await page.selectOption('#scan-units', 'cm');
  await page.waitForFunction(() => window.pcpp.state.info.units === 'cm' && !window.pcpp.state.busy
    && !window.pcpp.state.queued, null, { timeout: 120_000 });
  assert.equal(await scale(page), 1);
  assert.equal(await page.inputValue('#pl-scale'), '1');
  assert.equal(await page.textContent('#pl-note'), '');

  // Up +Y turns it: centred again on its footprint as now read.
  const bbox = await page.evaluate(() => JSON.stringify(window.pcpp.state.info.bbox_mm));
  await page.selectOption('#scan-up', 'y');
  await page.waitForFunction((b) => JSON.stringify(window.pcpp.state.info.bbox_mm) !== b
    && !window.pcpp.state.busy && !window.pcpp.state.queued, bbox, { timeout: 120_000 });
  // (The demo drawing over the upright bunny dispenses far above its
  // flanks: written only with the risk accepted.)
  await page.check('#accept-risk');
  await page.click('#place-bed-btn');
  await waitSettled(page);
  assert.equal(await scale(page), 1);
  const r = await page.evaluate(async () => {
    const j = JSON.parse(await window.pcpp.state.lastPlan.report());
    const pts = j.toolpath.flat();
    const mid = (k) => (Math.min(...pts.map((p) => p[k])) + Math.max(...pts.map((p) => p[k]))) / 2;
    const [lo, hi] = j.mesh.bbox_mm;
    return { path: [mid(0), mid(1)], scan: [(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2] };
  });
  for (const k of [0, 1]) assert.ok(Math.abs(r.path[k] - r.scan[k]) < 3, JSON.stringify(r));
  assert.deepEqual(problems, []);
  await context.close();
});

// The drawing's size in the note, mm.
const noteSize = (note) => {
  const m = /the drawing \((\d+\.\d) x (\d+\.\d) mm\) is larger than 90% of the scan's footprint/.exec(note);
  return m ? [Number(m[1]), Number(m[2])] : null;
};

test('a built-in antenna shrunk to fit the scan is fitted again from its own size when its size changes, the note about the antenna as it now is', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitForPlan(page);
  await bunnyOnBed(page);
  // The Hilbert loop at its default 20 mm does not fit the 10 mm bunny.
  await page.selectOption('#path-source', 'hilbert');
  await waitSettled(page);
  const fitted = await scale(page);
  assert.ok(fitted < 0.5, `${fitted}`);
  const size20 = noteSize(await page.textContent('#pl-note'));
  assert.ok(size20, await page.textContent('#pl-note'));

  // 30 mm: fitted again from its own size, the note of the 30 mm loop.
  await page.fill('#hb-size', '30');
  await page.dispatchEvent('#hb-size', 'change');
  await waitSettled(page);
  const size30 = noteSize(await page.textContent('#pl-note'));
  assert.ok(size30 && Math.abs(size30[0] - 1.5 * size20[0]) < 0.2, `${size20} -> ${size30}`);
  assert.ok(Math.abs(await scale(page) - fitted / 1.5) < 1e-3, `${fitted} -> ${await scale(page)}`);

  // 6 mm fits: planned at its own size, the note gone.
  await page.fill('#hb-size', '6');
  await page.dispatchEvent('#hb-size', 'change');
  await waitSettled(page);
  assert.equal(await scale(page), 1);
  assert.equal(await page.evaluate(() => window.pcpp.state.lastPlan.placement.scale), 1);
  assert.equal(await page.textContent('#pl-note'), '');
  assert.deepEqual(problems, []);
  await context.close();
});
