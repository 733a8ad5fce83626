// A real scan straight from its scanner (the Stanford bunny: y up, centred
// near the origin, partly at negative x and z, so outside the marlin
// profile's build volume as loaded) and a spiral, through the page's own
// file inputs: the banner says where the scan lies (the core's words), one
// click on "Place on the bed" gives G-code whose header and the page's
// header say "unregistered, placed on the bed", the drawing lies on the
// scan's footprint, and a reload keeps it all. Then the fiducials: holes
// chosen by a click, printer points pasted, residuals per fiducial.
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import {
  existsSync, mkdtempSync, readFileSync, rmSync, writeFileSync,
} from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { after, before, test } from 'node:test';
import { pageText } from '../../web/page.js';
import { ROOT, download, openPage, waitForPlan, waitIdle, waitKept, waitSettled, withPageServer } from './helpers.mjs';

const env = withPageServer();
const BUNNY = join(ROOT, 'tests/data/realworld/mesh/stanford-bunny.ply');
const CLI = join(ROOT, 'target/debug/pcpp');

let dir;
before(() => { dir = mkdtempSync(join(tmpdir(), 'pcpp-place-')); });
after(() => { if (dir) rmSync(dir, { recursive: true, force: true }); });

// An Archimedean spiral, 5 turns from r 1 to 16 mm, as one polyline: 32 mm
// across, larger than the bunny, so it is also scaled to fit.
function spiralSvg() {
  const pts = [];
  for (let i = 0; i <= 600; i++) {
    const a = (i / 600) * 5 * 2 * Math.PI;
    const r = 1 + (15 * i) / 600;
    pts.push(`${(r * Math.cos(a)).toFixed(4)} ${(r * Math.sin(a)).toFixed(4)}`);
  }
  return `<svg xmlns="http://www.w3.org/2000/svg" width="34mm" height="34mm" viewBox="-17 -17 34 34">
  <path id="spiral" d="M ${pts.join(' L ')}" fill="none" stroke="black"/>
</svg>
`;
}

// XY bounds of points.
function xyBounds(points) {
  const lo = [Infinity, Infinity];
  const hi = [-Infinity, -Infinity];
  for (const [x, y] of points) {
    lo[0] = Math.min(lo[0], x); lo[1] = Math.min(lo[1], y);
    hi[0] = Math.max(hi[0], x); hi[1] = Math.max(hi[1], y);
  }
  return [lo, hi];
}

test('a scan in its scanner frame and a spiral: one click on "Place on the bed" gives G-code on the part', async (t) => {
  const svgPath = join(dir, 'spiral.svg');
  writeFileSync(svgPath, spiralSvg());
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitForPlan(page);
  // The demo part lies in the volume: no banner.
  assert.equal(await page.isHidden('#place-banner'), true);
  assert.match(await page.textContent('#reg-status'), /^registered \(lsq, 3 fiducials/);

  await page.selectOption('#scan-up', 'y');
  await page.setInputFiles('#scan-input', BUNNY);
  await page.setInputFiles('#svg-input', svgPath);
  await page.waitForSelector('#place-banner:not([hidden])', { timeout: 120_000 });
  await waitIdle(page);
  assert.equal(await page.textContent('#scan-name'), 'stanford-bunny.ply');
  const banner = await page.textContent('#place-banner-text');
  assert.match(banner, /^The scan lies outside the build volume of profile marlin \(x 0\.\.220/);
  assert.match(banner, /'Place on the bed'/);
  // And that nothing was written (QA round 4 F6).
  assert.match(banner, /fiducials\. No G-code was written\.$/);
  assert.match(await page.textContent('#reg-status'), /^unregistered, taken as it is/);
  // As it is, no G-code and no download: the banner says why, no red error
  // repeats it.
  assert.equal(await page.isHidden('#error-panel'), true, await page.textContent('#error-message'));
  assert.match(await page.textContent('#plan-status'), /outside the build volume/);
  assert.equal(await page.isHidden('#dl-gcode'), true);
  // The drawing was centred on the scan's footprint (scanner frame) and
  // scaled down to fit, with the core's note.
  const first = await page.evaluate(() => ({ ...window.pcpp.settings.placement }));
  assert.ok(first.scale < 0.35 && first.scale > 0.1, JSON.stringify(first));
  assert.match(await page.textContent('#pl-note'), /scaled by 0\.\d{3} to fit/);
  const scanInfo = await page.evaluate(() => window.pcpp.state.info);
  const [slo, shi] = scanInfo.bbox_mm;
  // The spiral's middle is at (17, -17) mm of its page (y up).
  for (const k of [0, 1]) {
    const mid = [first.x, first.y][k] + [17, -17][k] * first.scale;
    assert.ok(Math.abs(mid - (slo[k] + shi[k]) / 2) < 0.5, `${JSON.stringify(first)} on ${slo}..${shi}`);
  }

  if (existsSync(CLI)) {
    // The banner's sentence is the CLI's, from the same core function (in
    // the page's words for the fix: its button, not the flag).
    let err = '';
    try {
      execFileSync(CLI, ['plan', '--scan', BUNNY, '--path', svgPath, '--up-axis', 'y', '--place', 'centre',
        '-o', join(dir, 'no.gcode')], { stdio: ['ignore', 'ignore', 'pipe'] });
    } catch (e) {
      err = String(e.stderr);
    }
    const sentence = banner.replace(/\. No G-code was written\.$/, '');
    assert.ok(pageText(err).includes(sentence.charAt(0).toLowerCase() + sentence.slice(1)), `${err}\nvs\n${sentence}`);
  } else {
    t.diagnostic(`${CLI} not built: the banner is not compared with the CLI's message`);
  }

  // One click.
  await page.click('#place-bed-btn');
  await waitSettled(page);
  assert.equal(await page.isHidden('#error-panel'), true, await page.textContent('#error-message'));
  assert.equal(await page.isHidden('#place-banner'), true);
  assert.equal(await page.isVisible('#scan-place'), true);
  assert.equal(await page.textContent('#reg-status'), 'unregistered, placed on the bed');
  // The drawing printed smaller than drawn is said where the user looks
  // after a plan, not only in the Placement panel's note.
  assert.match(await page.textContent('#plan-status'),
    /^planned .* with even \(the drawing scaled ×0\.\d+ to fit the scan; Placement sets its scale\)$/);

  const gcode = await download(page, 'dl-gcode');
  const text = gcode.bytes.toString('utf8');
  assert.ok(text.split('\n').some((l) => l.startsWith('; registration: unregistered, placed on the bed')),
    text.slice(0, 1500));
  const report = JSON.parse((await download(page, 'dl-report')).bytes.toString('utf8'));
  assert.equal(report.registration.status.kind, 'placed-on-bed');
  assert.equal(report.inputs[0].name, 'stanford-bunny.ply');

  // The scan lies on the bed, inside the volume; the drawing's tool path
  // (report) and the G-code's print moves lie within its footprint.
  const [lo, hi] = report.mesh.bbox_mm;
  assert.ok(Math.abs(lo[2]) < 1e-9, `lowest point at z ${lo[2]}`);
  assert.ok(Math.abs((lo[0] + hi[0]) / 2 - 110) < 1e-6 && Math.abs((lo[1] + hi[1]) / 2 - 110) < 1e-6,
    `footprint ${lo}..${hi}`);
  const [dlo, dhi] = xyBounds(report.toolpath.flat());
  for (const k of [0, 1]) {
    assert.ok(dlo[k] >= lo[k] && dhi[k] <= hi[k], `drawing ${dlo}..${dhi} outside the footprint ${lo}..${hi}`);
  }
  // Print moves: the G1 moves between marlin's dispense on (M106) and off
  // (M107).
  const printXY = [];
  let on = false;
  for (const l of text.split('\n')) {
    if (/^M106\b/.test(l)) on = true;
    if (/^M107\b/.test(l)) on = false;
    if (!on || !/^G1\b/.test(l)) continue;
    const x = l.match(/X(-?[\d.]+)/);
    const y = l.match(/Y(-?[\d.]+)/);
    if (x && y) printXY.push([Number(x[1]), Number(y[1])]);
  }
  assert.ok(printXY.length > 100, `${printXY.length} print moves`);
  const [glo, ghi] = xyBounds(printXY);
  for (const k of [0, 1]) {
    assert.ok(glo[k] >= lo[k] - 1e-3 && ghi[k] <= hi[k] + 1e-3, `G-code ${glo}..${ghi} vs ${lo}..${hi}`);
  }
  // The drawing went with the scan: still centred on its footprint.
  const placed = await page.evaluate(() => ({ ...window.pcpp.settings.placement }));
  assert.equal(placed.scale, first.scale);
  assert.ok(Math.abs((dlo[0] + dhi[0]) / 2 - 110) < 3 && Math.abs((dlo[1] + dhi[1]) / 2 - 110) < 3,
    `drawing centre ${(dlo[0] + dhi[0]) / 2}, ${(dlo[1] + dhi[1]) / 2}`);

  // An emptied field names itself and moves nothing.
  await page.fill('#bed-dx', '');
  assert.match(await page.textContent('#bed-note'), /Move X \(mm\): type a number/);
  assert.equal(await page.evaluate(() => window.pcpp.settings.scanPlace.dx), 0);
  // Moved by hand: the scan and the drawing move 5 mm in x; the header
  // says so.
  await page.fill('#bed-dx', '5');
  await waitSettled(page);
  const moved = await page.evaluate(() => ({ ...window.pcpp.settings.placement }));
  assert.ok(Math.abs(moved.x - placed.x - 5) < 1e-3, `${placed.x} -> ${moved.x}`);
  assert.equal(await page.textContent('#reg-status'), 'unregistered, placed on the bed (turned 0 deg, moved (5, 0, 0) mm)');
  const g2 = (await download(page, 'dl-gcode')).bytes.toString('utf8');
  assert.ok(g2.includes('; registration: unregistered, placed on the bed (turned 0 deg, moved (5, 0, 0) mm)'));

  // Moved below the bed (Move Z -50): refused by name, no download (it
  // wrote G-code 50 mm into a part standing on the bed); the bed note
  // says how to move it back, not to place it on the bed.
  await page.fill('#bed-dz', '-50');
  await page.waitForSelector('#error-panel:not([hidden])', { timeout: 120_000 });
  await waitIdle(page);
  assert.equal(await page.textContent('#error-title'), 'The scan is moved below the bed: no G-code');
  assert.match(await page.textContent('#error-message'), /moved 50\.000 mm down/);
  assert.equal(await page.isHidden('#dl-gcode'), true);
  assert.match(await page.textContent('#bed-note'), /move it back inside \(Move X, Y and Z/);
  assert.doesNotMatch(await page.textContent('#bed-note'), /place it on the bed/);
  await page.fill('#bed-dz', '0');
  await waitSettled(page);
  assert.equal(await page.isHidden('#error-panel'), true, await page.textContent('#error-message'));

  // A reload keeps the scan, its placement on the bed and the drawing's.
  await waitKept(page);
  await page.reload();
  await waitSettled(page);
  assert.equal(await page.textContent('#scan-name'), 'stanford-bunny.ply');
  assert.equal(await page.textContent('#reg-status'), 'unregistered, placed on the bed (turned 0 deg, moved (5, 0, 0) mm)');
  assert.deepEqual(await page.evaluate(() => ({ ...window.pcpp.settings.placement })), moved);
  assert.equal(await page.inputValue('#bed-dx'), '5');
  assert.equal(await page.isHidden('#place-banner'), true);
  assert.equal(await page.isHidden('#error-panel'), true, await page.textContent('#error-message'));
  assert.deepEqual(problems, []);
  await context.close();
});

// A box from `lo` to `hi` (x, y, z, mm) as an OBJ file for the scan input.
function slabObj(name, lo, hi) {
  const v = [];
  for (const z of [lo[2], hi[2]]) {
    for (const [x, y] of [[lo[0], lo[1]], [hi[0], lo[1]], [hi[0], hi[1]], [lo[0], hi[1]]]) v.push(`v ${x} ${y} ${z}`);
  }
  const f = ['f 1 3 2', 'f 1 4 3', 'f 5 6 7', 'f 5 7 8', 'f 1 2 6', 'f 1 6 5', 'f 2 3 7', 'f 2 7 6',
    'f 3 4 8', 'f 3 8 7', 'f 4 1 5', 'f 4 5 8'];
  return { name, mimeType: 'text/plain', buffer: Buffer.from(`${v.join('\n')}\n${f.join('\n')}\n`) };
}

// A ring scanned about the scanner's origin (outside the build volume):
// the drawing is centred over its band, with a note naming where; placed
// on the bed, the drawing goes with the scan and the note, whose places
// are the scanner frame's, goes (QA round 7 F10: it stayed, 70 mm off).
test('the note of a drawing centred off a gap goes once the scan is placed on the bed', async () => {
  const lines = [];
  const n = 64;
  for (let k = 0; k < n; k++) {
    const a = (2 * Math.PI * k) / n;
    for (const r of [20, 40]) lines.push(`v ${(r * Math.cos(a)).toFixed(4)} ${(r * Math.sin(a)).toFixed(4)} 1`);
  }
  for (let k = 0; k < n; k++) {
    const [i, j] = [2 * k + 1, 2 * ((k + 1) % n) + 1];
    lines.push(`f ${i} ${i + 1} ${j + 1}`, `f ${i} ${j + 1} ${j}`);
  }
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitSettled(page);
  await page.setInputFiles('#scan-input', { name: 'ring0.obj', mimeType: 'text/plain', buffer: Buffer.from(`${lines.join('\n')}\n`) });
  await page.waitForFunction(() => window.pcpp.state.info && window.pcpp.state.info.name === 'ring0.obj', null, { timeout: 120_000 });
  await waitIdle(page);
  // A 10 mm circle: centred on the middle, all of it over the gap.
  await page.setInputFiles('#svg-input', { name: 'circle.svg', mimeType: 'image/svg+xml',
    buffer: Buffer.from('<svg xmlns="http://www.w3.org/2000/svg" width="12mm" height="12mm" viewBox="0 0 12 12">'
      + '<circle cx="6" cy="6" r="5" fill="none" stroke="black"/></svg>\n') });
  await page.waitForFunction(() => /lies over a gap in the scan/.test(document.getElementById('pl-note').textContent),
    null, { timeout: 120_000 });
  await waitIdle(page);
  assert.match(await page.textContent('#pl-note'), /^the middle of the scan's footprint \(0\.000, 0\.000\) lies over a gap in the scan: the drawing is centred at \(/);
  await page.click('#place-bed-btn');
  await waitIdle(page);
  assert.equal(await page.textContent('#pl-note'), '');
  assert.deepEqual(problems, []);
  await context.close();
});

// A scan reaching 2 mm below the bed whose tool path lies inside the
// volume: G-code is written, with the warning, and the banner says so; the
// same banner on a refused plan says nothing was written (QA round 4 F6:
// both read the same).
test('the banner of a scan out of the volume says whether G-code was written', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitSettled(page);
  // A slab 80 x 80 mm, from 2 mm below the bed to 1 mm above it.
  await page.setInputFiles('#scan-input', slabObj('slab.obj', [60, 60, -2], [140, 140, 1]));
  await page.waitForFunction(() => window.pcpp.state.info && window.pcpp.state.info.name === 'slab.obj', null, { timeout: 120_000 });
  await waitSettled(page);
  assert.equal(await page.isVisible('#place-banner'), true);
  const banner = await page.textContent('#place-banner-text');
  assert.match(banner, /^The scan lies outside the build volume of profile marlin /);
  assert.match(banner, /[a-z]\. G-code was written: the tool path itself lies inside the volume \(its header carries this warning\)\.$/);
  const gcode = await download(page, 'dl-gcode');
  assert.match(gcode.bytes.toString('utf8'), /the scan lies outside the build volume/);
  assert.deepEqual(problems, []);
  await context.close();
});

// A scan placed on the bed, then read in units that make it larger than
// the printer: refused as the scan's problem, as it is when not placed
// (QA round 7 F8: planned, with a warning only).
test('a scan placed on the bed and read larger than the printer is refused', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitSettled(page);
  await page.setInputFiles('#scan-input', slabObj('slab60.obj', [-100, 0, 0], [-40, 60, 3]));
  await page.waitForFunction(() => window.pcpp.state.info && window.pcpp.state.info.name === 'slab60.obj', null, { timeout: 120_000 });
  await waitIdle(page);
  await page.click('#place-bed-btn');
  await waitIdle(page);
  await page.selectOption('#scan-units', 'cm');
  await page.waitForFunction(() => window.pcpp.state.info && window.pcpp.state.info.units === 'cm', null, { timeout: 120_000 });
  await page.waitForFunction(() => /larger than the printer/.test(document.getElementById('error-title').textContent),
    null, { timeout: 120_000 });
  await waitIdle(page);
  assert.equal(await page.textContent('#error-title'), 'The scan is larger than the printer: no G-code');
  assert.match(await page.textContent('#error-message'), /it is larger than the volume \(x 600\.0 mm, the volume 220\.0 mm\)/);
  assert.match(await page.textContent('#error-message'), /To write it anyway, tick/);
  assert.equal(await page.isHidden('#dl-gcode'), true);
  // Read in metres, 3 m tall: the tool path leaves the volume too, which
  // the box does not lift; the refusal says so and does not offer the box
  // (QA round 11 L1).
  await page.selectOption('#scan-units', 'm');
  await page.waitForFunction(() => window.pcpp.state.info && window.pcpp.state.info.units === 'm', null, { timeout: 120_000 });
  await page.waitForFunction(() => /would write no G-code either/.test(document.getElementById('error-message').textContent),
    null, { timeout: 120_000 });
  await waitIdle(page);
  const said = await page.textContent('#error-message');
  assert.match(said, /; but accepting the risk would write no G-code either: subpath \d+, point \d+ at .* lies outside the build volume/);
  assert.doesNotMatch(said, /To write it anyway, tick/);
  assert.deepEqual(problems, []);
  await context.close();
});

test('fiducials: candidates ranked for the dot diameter, chosen by a click, printer points pasted, residuals shown', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitForPlan(page);
  const printer = await page.evaluate(() => window.pcpp.settings.fidPrinterText);
  // Start unregistered, with no scan points.
  await page.selectOption('#fid-source', 'none');
  await page.fill('#fid-printer', '');
  await waitSettled(page);
  assert.match(await page.textContent('#reg-status'), /^unregistered, taken as it is/);
  assert.match(await page.textContent('#fid-holes'), /^3 of 3 hole\(s\) could be 1\.00 mm dots/);
  const rows = await page.$$eval('#fid-holes li', (li) => li.map((l) => l.textContent));
  assert.equal(rows.length, 3);
  for (const r of rows) assert.match(r, /^choose1?\d?\. Ø 1\.0\d\d mm, roundness 0\.\d\d, score [01]\.\d\d at/);

  // Three clicks choose the holes as Sr1..Sr3; the note asks for P.
  for (const k of [0, 1, 2]) await page.click(`#fid-hole-${k} button`);
  assert.equal(await page.textContent('#fid-hole-2 button'), 'Sr3');
  assert.match(await page.textContent('#fid-choose-note'), /type or paste the printer coordinates/);
  // The holes are the test part's in the printer's order? Paste P in the
  // order of the chosen holes: the nearest printer point of each.
  const ordered = await page.evaluate((text) => {
    const p = text.split('\n').map((l) => l.split(',').map(Number));
    const holes = window.pcpp.state.info.holes.slice(0, 3);
    return holes.map((h) => p.reduce((b, q) => (Math.hypot(q[0] - h.scan[0], q[1] - h.scan[1]) < Math.hypot(b[0] - h.scan[0], b[1] - h.scan[1]) ? q : b)).join(', ')).join('\n');
  }, printer);
  await page.fill('#fid-printer', ordered);
  await page.waitForFunction(() => /^registered \(lsq, 3 fiducials/.test(document.getElementById('reg-status').textContent),
    null, { timeout: 120_000 });
  await waitSettled(page);
  assert.equal(await page.inputValue('#fid-source'), 'points');
  const residuals = await page.$$eval('#fid-holes .residual', (s) => s.map((x) => x.textContent));
  assert.equal(residuals.length, 3);
  for (const r of residuals) assert.match(r, /^residual 0\.0000 mm$/);
  const gcode = (await download(page, 'dl-gcode')).bytes.toString('utf8');
  assert.ok(/; registration: registered \(lsq, 3 fiducials, RMS residual 0\.000 mm\)/.test(gcode));

  // Another dot diameter: 5 mm dots do not match 1 mm holes.
  await page.fill('#fid-dot', '5');
  await page.waitForFunction(() => /None of the 3 hole\(s\) looks like a 5\.00 mm dot/
    .test(document.getElementById('fid-holes').textContent), null, { timeout: 120_000 });
  // Not a number: a clear message, the previous plan stays.
  await page.fill('#fid-dot', '');
  await page.waitForSelector('#error-panel:not([hidden])');
  assert.match(await page.textContent('#error-message'), /fiducial dot diameter/);
  await page.fill('#fid-dot', '1');
  await waitSettled(page);
  assert.deepEqual(problems, []);
  await context.close();
});

// QA round 15 F3: a drawing larger than the scan is told to scale down,
// not to centre it (which it is); the page says it with its own field.
test('a drawing too large for the scan is told in the page\'s words to scale down', (t) => {
  if (!existsSync(CLI)) {
    t.skip(`${CLI} not built`);
    return;
  }
  const plate = join(dir, 'plate80.obj');
  writeFileSync(plate, 'v 0 0 0\nv 80 0 0\nv 80 80 0\nv 0 80 0\nf 1 2 3\nf 1 3 4\n');
  const wide = join(dir, 'wide.svg');
  writeFileSync(wide, '<svg xmlns="http://www.w3.org/2000/svg" width="200mm" height="60mm" viewBox="0 0 200 60">'
    + '<path d="M 0 10 L 200 10 M 0 30 L 200 30 M 0 50 L 200 50" stroke="black" fill="none"/></svg>');
  let err = '';
  try {
    execFileSync(CLI, ['plan', '--scan', plate, '--path', wide, '--place-scan', 'bed', '--place', 'centre,0,1',
      '-o', join(dir, 'wide.gcode')], { stdio: ['ignore', 'ignore', 'pipe'] });
  } catch (e) {
    err = String(e.stderr);
  }
  assert.match(err, /the scanned surface is smaller than the drawing/);
  const shown = pageText(err);
  assert.match(shown, /scale the drawing down or turn it \(a smaller Scale, or another Rotation\)/);
  assert.doesNotMatch(shown, /--place centre/);
  // QA round 16 F3: a square scaled up around the whole scan (no part of
  // it over the surface) is told to scale down, not to move.
  const square = join(dir, 'square.svg');
  writeFileSync(square, '<svg xmlns="http://www.w3.org/2000/svg" width="40mm" height="40mm" viewBox="0 0 40 40">'
    + '<path d="M 1 1 L 39 1 L 39 39 L 1 39 Z" stroke="black" fill="none"/></svg>');
  err = '';
  try {
    execFileSync(CLI, ['plan', '--scan', plate, '--path', square, '--place-scan', 'bed', '--place', 'centre,0,3',
      '-o', join(dir, 'square.gcode')], { stdio: ['ignore', 'ignore', 'pipe'] });
  } catch (e) {
    err = String(e.stderr);
  }
  assert.match(err, /around the whole scan/);
  const around = pageText(err);
  assert.match(around, /scale the drawing down \(a smaller Scale\)/);
  assert.doesNotMatch(around, /--place centre/);
});

// QA round 16 F8: a Scale typed after the page centred the drawing grew it
// from its SVG origin, off the scan ("only 60 % ... lie over the scan"),
// where `pcpp plan --place centre,ROT,SCALE` centres it at that scale.
// Typed while the drawing lies where the page centred it, Rotation and
// Scale keep it centred, as the CLI's centre does; once its offset is
// typed, they are --place's numbers again.
test('a Scale typed after the page centred the drawing keeps it centred, as the CLI\'s centre does', async (t) => {
  const plate = join(dir, 'plate40.obj');
  // Odd sizes, so that the centred offsets are not round (QA round 18 F6).
  writeFileSync(plate, 'v 0 0 1\nv 40.3217 0 1\nv 40.3217 39.8761 1\nv 0 39.8761 1\nf 1 2 3\nf 1 3 4\n');
  const svg = join(dir, 'offcorner.svg');
  // Its line far from the SVG origin, so scaling about the origin moves it.
  writeFileSync(svg, '<svg xmlns="http://www.w3.org/2000/svg" width="30mm" height="30mm" viewBox="0 0 30 30">'
    + '<path d="M 14.137 20.411 L 26 20 L 26 26" stroke="black" fill="none"/></svg>');
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitSettled(page);
  await page.setInputFiles('#scan-input', plate);
  await page.waitForFunction(() => window.pcpp.state.info && window.pcpp.state.info.name === 'plate40.obj',
    null, { timeout: 120_000 });
  await waitSettled(page);
  await page.setInputFiles('#svg-input', svg);
  await page.waitForFunction(() => document.getElementById('svg-name').textContent === 'offcorner.svg',
    null, { timeout: 120_000 });
  await waitSettled(page);
  const placement = () => page.evaluate(() => Object.fromEntries(
    Object.entries(window.pcpp.settings.placement).map(([k, v]) => [k, Number(v)]),
  ));
  const centred = await placement();
  await page.fill('#pl-scale', '1.5');
  await waitSettled(page);
  const scaled = await placement();
  assert.equal(scaled.scale, 1.5);
  assert.notDeepEqual([scaled.x, scaled.y], [centred.x, centred.y]);
  assert.doesNotMatch(await page.textContent('#plan-status'), /lie over the scan|beside/);
  if (existsSync(CLI)) {
    const report = join(dir, 'centred.json');
    execFileSync(CLI, ['plan', '--scan', plate, '--path', svg, '--place', `centre,${centred.rot},1.5`,
      '-o', join(dir, 'centred.gcode'), '--report', report], { stdio: 'ignore' });
    const cli = JSON.parse(readFileSync(report, 'utf8')).settings.placement;
    // The core's centring, not the page's to 0.01 mm (QA round 18 F6:
    // "Centre on scan" then a Scale planned 0.004 mm off the CLI's
    // --place centre,0,SCALE on every move): the same G-code bytes.
    assert.deepEqual([cli.offset_mm[0], cli.offset_mm[1]], [scaled.x, scaled.y]);
    const pageGcode = await page.evaluate(() => {
      const g = window.pcpp.state.lastPlan.gcode;
      return typeof g === 'string' ? g : new TextDecoder().decode(g);
    });
    assert.equal(pageGcode, readFileSync(join(dir, 'centred.gcode'), 'utf8'));
  } else {
    t.diagnostic(`${CLI} not built: the placement is not compared with the CLI's`);
  }
  // Its offset typed: the typed Scale is --place's number again, about
  // the SVG origin.
  await page.fill('#pl-x', String(scaled.x + 1));
  await waitSettled(page);
  await page.fill('#pl-scale', '1.2');
  await waitSettled(page);
  const typed = await placement();
  assert.deepEqual([typed.x, typed.y, typed.scale], [scaled.x + 1, scaled.y, 1.2]);
  assert.deepEqual(problems, []);
  await context.close();
});

// QA round 17 F7: on a scan with a gap under its footprint's middle (a
// gear's bore), a Scale typed after the page centred the drawing kept it
// over the gap, where `--place centre,ROT,SCALE` moves it off. Typed while
// centred, the core centres it again, as the CLI does.
test('a Scale typed while centred moves the drawing off a gap and stays the user\'s, as the CLI\'s centre does', async () => {
  // A 60 mm frame around a 20 mm hole.
  const frame = join(dir, 'frame60.obj');
  const v = [[0, 0], [60, 0], [60, 60], [0, 60], [20, 20], [40, 20], [40, 40], [20, 40]];
  const f = [[1, 2, 6], [1, 6, 5], [2, 3, 7], [2, 7, 6], [3, 4, 8], [3, 8, 7], [4, 1, 5], [4, 5, 8]];
  writeFileSync(frame, v.map(([x, y]) => `v ${x} ${y} 1\n`).join('') + f.map((t) => `f ${t.join(' ')}\n`).join(''));
  const svg = join(dir, 'square30.svg');
  writeFileSync(svg, '<svg xmlns="http://www.w3.org/2000/svg" width="30mm" height="30mm" viewBox="0 0 30 30">'
    + '<path d="M 1 1 H 29 V 29 H 1 Z" stroke="black" fill="none"/></svg>');
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitSettled(page);
  await page.setInputFiles('#scan-input', frame);
  await page.waitForFunction(() => window.pcpp.state.info && window.pcpp.state.info.name === 'frame60.obj',
    null, { timeout: 120_000 });
  await waitSettled(page);
  await page.setInputFiles('#svg-input', svg);
  await page.waitForFunction(() => document.getElementById('svg-name').textContent === 'square30.svg',
    null, { timeout: 120_000 });
  await waitSettled(page);
  await page.fill('#pl-scale', '0.5');
  await waitSettled(page);
  await waitIdle(page);
  const scaled = await page.evaluate(() => Object.fromEntries(
    Object.entries(window.pcpp.settings.placement).map(([k, n]) => [k, Number(n)]),
  ));
  assert.equal(scaled.scale, 0.5);
  assert.match(await page.textContent('#plan-status'), /^planned square30\.svg on frame60\.obj/);
  const report = join(dir, 'frame-centred.json');
  execFileSync(CLI, ['plan', '--scan', frame, '--path', svg, '--place', `centre,${scaled.rot},0.5`,
    '-o', join(dir, 'frame-centred.gcode'), '--report', report], { stdio: 'ignore' });
  const cli = JSON.parse(readFileSync(report, 'utf8')).settings.placement;
  assert.ok(Math.abs(cli.offset_mm[0] - scaled.x) <= 0.011 && Math.abs(cli.offset_mm[1] - scaled.y) <= 0.011,
    `${JSON.stringify(cli)} vs ${JSON.stringify(scaled)}`);
  // A Scale larger than the scan is the user's too: centred again, not
  // fitted back down (as --place centre,ROT,SCALE keeps a scale given).
  await page.fill('#pl-scale', '3');
  // Planned, or refused (most of a 90 mm square lies off a 60 mm frame).
  await page.waitForFunction(() => {
    const s = window.pcpp.state;
    const status = document.getElementById('plan-status').textContent;
    return !s.busy && !s.queued && !/planning/.test(status)
      && ((s.lastPlan && s.lastPlan.gen === s.gen) || /^no G-code: /.test(status));
  }, null, { timeout: 120_000 });
  assert.match(await page.textContent('#plan-status'), /^no G-code: /);
  assert.equal(Number(await page.evaluate(() => window.pcpp.settings.placement.scale)), 3);
  assert.equal(await page.inputValue('#pl-scale'), '3');
  assert.deepEqual(problems, []);
  await context.close();
});
