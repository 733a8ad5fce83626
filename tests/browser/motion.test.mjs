// Safe motion in the page (spec section 6f): every planner compared with its
// backward moves and clearance; the plan's motion summary; G-code whose
// moves touch the part refused (the message names the G-code lines) or,
// with the risk accepted, offered only after a second, explicit click; any
// G-code file checked against the loaded scan; the demo parts' menu.
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import {
  existsSync, mkdtempSync, readFileSync, rmSync, writeFileSync,
} from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { after, before, test } from 'node:test';
import {
  ROOT, download, openPage, platePostObj, viewPixels, waitIdle, waitSettled, withPageServer,
} from './helpers.mjs';

const env = withPageServer();
const CLI = join(ROOT, 'target/debug/pcpp');

let dir;
before(() => {
  dir = mkdtempSync(join(tmpdir(), 'pcpp-motion-'));
});
after(() => {
  if (dir) rmSync(dir, { recursive: true, force: true });
});

const PLANNERS = ['constant', 'slope', 'pcpp', 'pcpp-guarded', 'even'];
const gcodeFile = (name, text) => ({ name, mimeType: 'text/plain', buffer: Buffer.from(text) });

// The comparison table as {planner: {column: text}}, and the classes of
// the clearance cells.
const compareTable = (page) => page.evaluate(() => {
  const heads = [...document.querySelectorAll('#compare-table thead th')].map((th) => th.textContent);
  const rows = {};
  for (const tr of document.querySelectorAll('#compare-table tbody tr')) {
    const cells = [...tr.children];
    rows[cells[0].textContent] = Object.fromEntries(cells.map((td, i) => [heads[i], td.textContent]));
    rows[cells[0].textContent].clearanceBad = tr.querySelector('td.clearance').classList.contains('bad');
  }
  return { heads, rows };
});

// The demo's stepped block planned with the paper's slope planner, which
// runs the nozzle into the steps' walls: refused for touching.
async function refusedOnSteppedBlock(page) {
  await waitSettled(page);
  await page.selectOption('#demo-part', 'stepped-block');
  await page.waitForFunction(() => document.getElementById('scan-name').textContent === 'demo-stepped-block.ply');
  await waitSettled(page);
  await page.selectOption('#planner', 'slope');
  await page.waitForFunction(() => /touch/.test(document.getElementById('error-title').textContent)
    && !document.getElementById('error-panel').hidden, null, { timeout: 120_000 });
  await waitIdle(page);
}

test('every planner is compared with its defects, backward moves, clearance and waypoints; the plot shows each', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitSettled(page);
  const { heads, rows } = await compareTable(page);
  assert.deepEqual(heads, ['planner', 'mean |e| mm', 'mean e− mm', 'mean e+ mm', 'contact', 'flattening',
    'floating', 'defects', 'backward', 'min clear mm', 'waypoints']);
  assert.deepEqual(Object.keys(rows), PLANNERS);
  const report = JSON.parse(await page.evaluate(() => window.pcpp.state.lastPlan.report()));
  assert.equal(report.planner, 'even');
  const tol = report.settings.process.tolerance_mm;
  // even, the default, never falls back along the drawn path and keeps tol.
  assert.equal(rows.even.backward, '0');
  assert.ok(Number(rows.even['min clear mm']) >= tol, rows.even['min clear mm']);
  assert.equal(rows.even.clearanceBad, false);
  assert.ok(Number(rows.even.waypoints) > 0);
  for (const p of PLANNERS) {
    const r = rows[p];
    // defects = contact + flattening + floating
    const sum = ['contact', 'flattening', 'floating'].reduce((a, k) => a + Number.parseFloat(r[k]), 0);
    assert.ok(Math.abs(Number.parseFloat(r.defects) - sum) <= 0.15, `${p}: ${JSON.stringify(r)}`);
    // A clearance either a number or more than tol + 0.05 mm (not found
    // below that); below tol it is marked as a problem.
    const c = r['min clear mm'];
    if (c.startsWith('>')) {
      assert.equal(c, `>${(tol + 0.05).toFixed(3)}`);
    } else {
      assert.equal(r.clearanceBad, Number(c) < tol, `${p}: ${c}`);
    }
  }
  // The paper's constant stand-off runs into the part's walls.
  assert.ok(Number(rows.constant['min clear mm']) < 0 && rows.constant.clearanceBad, JSON.stringify(rows.constant));

  // The plan's safe-motion summary, next to its quality: the check of
  // every move the G-code commands.
  const motion = report.motion;
  assert.equal(motion.program.touching_moves, 0);
  assert.equal(await page.textContent('#motion-min-clear'),
    `${motion.program.min_clearance_mm.toFixed(3)} mm at (${motion.program.min_clearance_at.map((v) => v.toFixed(2)).join(', ')}), `
    + `G-code line ${motion.program.min_clearance_line}`);
  assert.equal(await page.textContent('#motion-waypoints'), `${motion.waypoints} (+${motion.extra_length_mm.toFixed(3)} mm)`);
  assert.equal(await page.textContent('#motion-backward'), '0');
  // What the quality figures describe, as the G-code's header says (QA
  // round 6 F4, F5).
  assert.match(await page.textContent('#motion-quality'),
    new RegExp(`; section 7, at the ${report.stats.points} planned points, not the ${motion.waypoints} waypoint\\(s\\), `
      + `with contact also where the nozzle's body or a straight move meets the part; `
      + `the tip up to ${motion.max_off_line_mm.toFixed(3).replace('.', '\\.')} mm off the drawn line, stepped sideways or leading its point round a corner, which section 7 does not see$`));
  assert.match(await page.textContent('#motion-touching'), /^0 of \d+ \(tol 0\.1 mm\)$/);
  assert.equal(await page.isHidden('#risk-warning'), true);

  // The plot draws every planner, one colour each, even among them.
  const legend = await page.$$eval('#plot-legend li', (lis) => lis.map((li) => li.textContent));
  assert.deepEqual(legend.sort(), [...PLANNERS].sort());
  const plotColours = () => page.evaluate(() => {
    const c = document.getElementById('plot');
    const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
    const count = (r, g, b) => {
      let n = 0;
      for (let i = 0; i < d.length; i += 4) {
        if (Math.abs(d[i] - r) < 3 && Math.abs(d[i + 1] - g) < 3 && Math.abs(d[i + 2] - b) < 3) n++;
      }
      return n;
    };
    // even's and constant's colours (web/plot.js), and the defect colours.
    return { even: count(0x14, 0xa0, 0x4a), constant: count(0x8a, 0x8f, 0x99), good: count(0x28, 0xd2, 0x46) };
  });
  const all = await plotColours();
  assert.ok(all.even > 100 && all.constant > 100, JSON.stringify(all));
  // One planner alone: coloured by defect.
  await page.selectOption('#plot-series', 'even');
  const one = await plotColours();
  assert.ok(one.even === 0 && one.constant === 0 && one.good > 100, JSON.stringify(one));
  assert.deepEqual(problems, []);
  await context.close();
});

test('a plan whose G-code touches the part names its lines and offers nothing; accepting the risk needs a second click', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitSettled(page);
  await page.selectOption('#demo-part', 'stepped-block');
  await page.waitForFunction(() => document.getElementById('scan-name').textContent === 'demo-stepped-block.ply');
  await waitSettled(page);
  const good = await page.evaluate(() => window.pcpp.state.lastPlan.gcode);
  assert.match(good, /; planner: even/);
  assert.match(good, /^; scan file: demo-stepped-block\.ply /m);
  const before = await page.evaluate(() => [...document.querySelectorAll('.side input, .side select, .side textarea')]
    .filter((el) => el.id && el.type !== 'file').map((el) => [el.id, el.type === 'checkbox' ? el.checked : el.value]));

  // The paper's slope planner runs the nozzle into the steps' walls.
  await page.selectOption('#planner', 'slope');
  await page.waitForFunction(() => /touch/.test(document.getElementById('error-title').textContent)
    && !document.getElementById('error-panel').hidden, null, { timeout: 120_000 });
  await waitIdle(page);
  assert.equal(await page.textContent('#error-title'), 'The nozzle would touch the part with slope: no G-code');
  const message = await page.textContent('#error-message');
  assert.match(message, /G-code move\(s\) of planner slope would bring the nozzle/);
  assert.match(message, /line \d+: the move \([-\d., ]+\) -> \([-\d., ]+\) comes too close at \([-\d., ]+\): the nozzle would have to be \d+\.\d{3} mm higher there/);
  assert.equal(await page.isHidden('#dl-gcode'), true);
  assert.equal(await page.isHidden('#dl-report'), true);
  // The refused tool path is in the view (QA round 7 F3).
  assert.equal(await page.textContent('#plan-status'), 'no G-code: the refused tool path is shown where the drawing lies (see above)');
  assert.match(message, /the view shows the refused tool path/);
  // Its contact points stand out: markers, not a few short red segments
  // among hundreds of green ones (QA round 8 F6).
  const px = await viewPixels(page);
  assert.ok(px.defect > 400, JSON.stringify(px)); // 83 before
  // Settings, drawing and previous plan stay.
  const afterSettings = await page.evaluate(() => [...document.querySelectorAll('.side input, .side select, .side textarea')]
    .filter((el) => el.id && el.type !== 'file').map((el) => [el.id, el.type === 'checkbox' ? el.checked : el.value]));
  assert.deepEqual(afterSettings, before.map(([k, v]) => [k, k === 'planner' ? 'slope' : v]));
  assert.equal(await page.evaluate(() => window.pcpp.state.lastPlan.gcode), good);
  assert.equal(await page.textContent('#svg-name'), 'demo: stepped-block drawing');
  // The planners were still compared on these settings: slope's row says why.
  const { rows } = await compareTable(page);
  assert.equal(rows.slope.clearanceBad, true);
  assert.ok(Number(rows.slope['min clear mm']) < 0);
  assert.equal(await page.$eval('#compare-table tr.selected td', (td) => td.textContent), 'slope');

  // With the risk accepted the plan is written, with a WARNING line, and
  // its G-code is downloaded only after a second click.
  await page.check('#accept-risk');
  await waitSettled(page);
  assert.equal(await page.isHidden('#error-panel'), true);
  const warning = await page.textContent('#risk-warning-text');
  assert.match(warning, /^safe motion: WARNING: \d+ of \d+ moves come closer to the surface than tol 0\.1 mm \(min clearance -\d+\.\d{3} mm at line \d+\); written only because the risk was accepted/);
  assert.equal(await page.isHidden('#risk-warning'), false);
  assert.match(await page.textContent('#motion-touching'), /^[1-9]\d* of \d+ \(tol 0\.1 mm\)$/);
  assert.equal(await page.getAttribute('#dl-gcode', 'href'), null);
  let downloads = 0;
  page.on('download', () => { downloads++; });
  await page.click('#dl-gcode');
  await page.waitForTimeout(500);
  assert.equal(downloads, 0, 'the first click downloaded the touching G-code');
  assert.equal(await page.textContent('#dl-gcode'), 'Download anyway (the nozzle touches the part)');
  const gcode = await download(page, 'dl-gcode');
  assert.equal(gcode.name, 'demo-stepped-block-path-slope.gcode');
  const text = gcode.bytes.toString('utf8');
  const line = text.split('\n').find((l) => l.includes('safe motion:'));
  assert.equal(line, `; ${warning}`);
  assert.match(line, /WARNING/);
  // The report downloads as any other.
  const report = JSON.parse((await download(page, 'dl-report')).bytes.toString('utf8'));
  assert.equal(report.motion.risk_accepted, true);

  // Any change takes the confirmation back.
  await page.selectOption('#planner', 'even');
  await waitSettled(page);
  assert.equal(await page.textContent('#dl-gcode'), 'Download G-code');
  assert.equal(await page.isHidden('#risk-warning'), true);
  assert.deepEqual(problems, []);
  await context.close();
});

// QA round 8 F1: after a refusal, a failure with no tool path of its own
// (the drawing moved off the scan) kept the refused path in the view under
// "showing the previous plan".
test('a failure with no tool path of its own takes a refused one out of the view', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await refusedOnSteppedBlock(page);
  assert.equal(await page.evaluate(() => window.pcpp.state.refused !== null), true);
  // A drawing that cannot be read changes nothing the refusal was planned
  // from (the drawing before it is kept): the refused path stays, and the
  // status says so (a reviewer's finding on QA round 8 F1's fix).
  await page.setInputFiles('#svg-input', { name: 'bad.svg', mimeType: 'image/svg+xml', buffer: Buffer.from('<svg') });
  await page.waitForFunction(() => /Could not read the SVG/.test(document.getElementById('error-title').textContent),
    null, { timeout: 120_000 });
  await waitIdle(page);
  assert.equal(await page.evaluate(() => window.pcpp.state.refused !== null), true);
  assert.equal(await page.textContent('#plan-status'), 'no G-code: the refused tool path is shown where the drawing lies (see above)');
  await page.fill('#pl-x', '500');
  await page.waitForFunction(() => /misses the scan/.test(document.getElementById('error-message').textContent),
    null, { timeout: 120_000 });
  await waitIdle(page);
  assert.equal(await page.evaluate(() => window.pcpp.state.refused), null);
  assert.equal(await page.textContent('#plan-status'), 'plan failed: showing the previous plan, no download');
  assert.deepEqual(problems, []);
  await context.close();
});

// The review of QA round 15 F2's fix: a plan that failed in its surface
// path (the drawing moved off the scan) said nothing of the drawing's own
// notes in the page, which `pcpp plan` prints with the same failure.
test('a drawing moved off the scan fails with its own notes said, as the CLI says them', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitSettled(page);
  const svg = '<svg xmlns="http://www.w3.org/2000/svg" width="20mm" height="20mm" viewBox="0 0 20 20">'
    + '<path d="M2 10 L18 10" stroke="black" fill="none"/><text x="2" y="5">ANT</text></svg>';
  await page.setInputFiles('#svg-input', { name: 'labelled.svg', mimeType: 'image/svg+xml', buffer: Buffer.from(svg) });
  await page.waitForFunction(() => document.getElementById('svg-name').textContent === 'labelled.svg',
    null, { timeout: 120_000 });
  await waitSettled(page);
  await page.fill('#pl-x', '500');
  await page.waitForFunction(() => /misses the scan/.test(document.getElementById('error-message').textContent),
    null, { timeout: 120_000 });
  await waitIdle(page);
  const text = await page.textContent('#error-message');
  assert.match(text, /This plan also warned:\n• 1 text element\(s\) skipped: text is not converted to paths/);
  // The CLI's failure on the same drawing says the same note.
  const scan = join(dir, 'demo-test-part.ply');
  const drawing = join(dir, 'labelled.svg');
  writeFileSync(drawing, svg);
  execFileSync(CLI, ['demo', '--out', dir], { stdio: 'ignore' });
  let stderr = '';
  try {
    execFileSync(CLI, ['plan', '--scan', scan, '--path', drawing, '--place', '500,0', '-o', join(dir, 'off.gcode')],
      { stdio: ['ignore', 'ignore', 'pipe'] });
  } catch (e) {
    stderr = e.stderr.toString();
  }
  assert.match(stderr, /1 text element\(s\) skipped: text is not converted to paths/);
  assert.match(stderr, /misses the scan/);
  assert.deepEqual(problems, []);
  await context.close();
});

// QA round 16 F4: a green "clear" verdict stayed after the scan was moved
// (its program then cut 3.3 mm into the part as placed), re-read or
// replaced. The program is checked again whenever a plan leaves the scan
// in another frame, and the verdict says it is stale meanwhile.
test('a checked G-code is checked again when the scan moves, and clear again when it moves back', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitSettled(page);
  const own = await download(page, 'dl-gcode');
  const verdictOf = async (pattern) => {
    await page.waitForFunction((p) => {
      const v = document.getElementById('check-verdict').textContent;
      return new RegExp(p).test(v) && !/^checking |to be checked again/.test(v);
    }, pattern.source, { timeout: 120_000 });
    return page.textContent('#check-verdict');
  };
  await page.setInputFiles('#gcode-input', gcodeFile(own.name, own.bytes));
  assert.match(await verdictOf(/^clear/), /^clear: none of the \d+ moves comes closer than tol; /);
  // The part 5 mm further along X on the stage: its printer points moved.
  const points = await page.inputValue('#fid-printer');
  const moved = points.split('\n').map((l) => {
    const [x, ...rest] = l.split(',').map(Number);
    return [x + 5, ...rest].join(', ');
  }).join('\n');
  const beforeId = await page.evaluate(() => window.pcpp.state.checkId);
  await page.fill('#fid-printer', moved);
  await page.waitForFunction((id) => window.pcpp.state.checkId > id, beforeId, { timeout: 120_000 });
  await waitSettled(page);
  const after = await verdictOf(/./);
  assert.doesNotMatch(after, /^clear/);
  assert.equal(await page.$eval('#check-verdict', (e) => e.classList.contains('good')), false);
  // Why, in the panel itself when the check could not be made.
  if (/^could not check/.test(after)) assert.ok((await page.textContent('#check-details')).length > 20);
  // Back where it was planned: clear again, with no new file opened.
  const movedId = await page.evaluate(() => window.pcpp.state.checkId);
  await page.fill('#fid-printer', points);
  await page.waitForFunction((id) => window.pcpp.state.checkId > id, movedId, { timeout: 120_000 });
  await waitSettled(page);
  assert.match(await verdictOf(/^clear/), /^clear: none of the \d+ moves comes closer than tol; /);
  assert.equal(await page.$eval('#check-verdict', (e) => e.classList.contains('good')), true);
  // A tol the program was not planned for is checked again too.
  const tolId = await page.evaluate(() => window.pcpp.state.checkId);
  await page.fill('#pr-tol', '0.5');
  await page.waitForFunction((id) => window.pcpp.state.checkId > id, tolId, { timeout: 120_000 });
  await waitSettled(page);
  assert.match(await verdictOf(/tol 0\.5 mm/), /tol 0\.5 mm\)/);
  assert.doesNotMatch(await page.textContent('#check-verdict'), /^clear/);
  assert.deepEqual(problems, []);
  await context.close();
});

// The demo's own G-code downloaded and checked: clear.
async function checkOwnGcode(page) {
  const own = await download(page, 'dl-gcode');
  await page.setInputFiles('#gcode-input', gcodeFile(own.name, own.bytes));
  await page.waitForFunction(() => /^clear: /.test(document.getElementById('check-verdict').textContent),
    null, { timeout: 120_000 });
}

// QA round 18 F7: a G-code checked against one scan, checked again by the
// page once another scan file was opened, put a red "Could not check" panel
// at the top on every scan opened after it. Its reason is said in the check
// panel; the red panel is for what the user just did.
test('a checked G-code that cannot be checked against a newly opened scan says so in its panel only', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitSettled(page);
  await checkOwnGcode(page);
  const checks = await page.evaluate(() => window.pcpp.state.checkId);
  // Another part: a 150 mm plate, far from where the demo's program runs.
  const plate = 'v 300 300 2\nv 450 300 2\nv 450 450 2\nv 300 450 2\nf 1 2 3\nf 1 3 4\n';
  await page.setInputFiles('#scan-input', { name: 'plate150.obj', mimeType: 'text/plain', buffer: Buffer.from(plate) });
  await page.waitForFunction((id) => window.pcpp.state.checkId > id && !window.pcpp.state.checking
    && !/^checking |to be checked again/.test(document.getElementById('check-verdict').textContent), checks,
  { timeout: 120_000 });
  await waitIdle(page);
  assert.match(await page.textContent('#check-verdict'), /^could not check demo-test-part-lines-even\.gcode/);
  assert.match(await page.textContent('#check-details'), /planned on another scan file|passes over the scan/);
  const title = await page.$eval('#error-panel', (e) => (e.hidden ? '' : document.getElementById('error-title').textContent));
  assert.doesNotMatch(title, /^Could not check/);
  assert.deepEqual(problems, []);
  await context.close();
});

// QA round 17 F6: a scan file that could not be read left the verdict at
// "to be checked again" for good, though the scan had not moved and no
// check followed.
test('a scan file not read leaves the checked G-code\'s verdict as it was', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitSettled(page);
  await checkOwnGcode(page);
  const before = await page.textContent('#check-verdict');
  const checks = await page.evaluate(() => window.pcpp.state.checkId);
  await page.setInputFiles('#scan-input', { name: 'broken.stl', mimeType: 'model/stl',
    buffer: Buffer.from('solid broken\nfacet normal 0 0 1\n outer loop\n  vertex 1 2\n') });
  await page.waitForFunction(() => /^Could not read the scan broken\.stl/.test(document.getElementById('error-title').textContent),
    null, { timeout: 120_000 });
  await waitIdle(page);
  assert.equal(await page.textContent('#check-verdict'), before);
  assert.equal(await page.$eval('#check-verdict', (e) => e.classList.contains('good')), true);
  assert.equal(await page.$eval('#check-details', (e) => e.classList.contains('stale')), false);
  // Nothing moved: no check was needed, and none was made.
  assert.equal(await page.evaluate(() => window.pcpp.state.checkId), checks);
  assert.deepEqual(problems, []);
  await context.close();
});

test('a G-code file is checked against the scan: the demo\'s own is clear, a cutting move and an arc are named by line', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitSettled(page);
  assert.equal(await page.isHidden('#check-panel'), true);
  const own = await download(page, 'dl-gcode');
  await page.setInputFiles('#gcode-input', gcodeFile(own.name, own.bytes));
  await page.waitForFunction(() => /^clear/.test(document.getElementById('check-verdict').textContent));
  const verdict = await page.textContent('#check-verdict');
  assert.match(verdict, /^clear: none of the \d+ moves comes closer than tol; demo-test-part-lines-even\.gcode against demo-test-part\.ply \(nozzle outer diameter 0\.908 mm, tol 0\.1 mm\)$/);
  assert.match(await page.textContent('#check-min'), /^minimum clearance 0\.1\d\d mm at line \d+ \(/);
  assert.equal(await page.$('#check-touching'), null);
  // Its moves drawn in the 3-D view in place of the plan's paths (feed
  // moves light, no defect colours), and back.
  const planPx = await viewPixels(page);
  await page.click('#check-draw');
  await page.waitForFunction(() => document.getElementById('check-draw').getAttribute('aria-pressed') === 'true');
  await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
  const movesPx = await viewPixels(page);
  assert.ok(movesPx.good < 20 && movesPx.ta > planPx.ta && movesPx.mesh > 1000, `${JSON.stringify(planPx)} / ${JSON.stringify(movesPx)}`);
  await page.click('#check-draw');
  await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
  const backPx = await viewPixels(page);
  assert.ok(backPx.good > 200, JSON.stringify(backPx));

  // The same program, its header saying the scan was read in inches, +Y
  // up: checked against the scan as loaded, it is not shown clear (QA: a
  // 44 mm cow checked as a 1.7 mm one passed), and the page names its
  // controls, not the command line's flags.
  const otherwise = own.bytes.toString('utf8').replace(/\n; scan read in: mm, \+Z up\n/, '\n; scan read in: in, +Y up\n');
  assert.notEqual(otherwise, own.bytes.toString('utf8'));
  await page.setInputFiles('#gcode-input', gcodeFile('inches.gcode', Buffer.from(otherwise)));
  // Its verdict, not the "checking inches.gcode…" shown while it runs (a
  // CI run read that line).
  await page.waitForFunction(() => {
    const v = document.getElementById('check-verdict').textContent;
    return /inches\.gcode/.test(v) && !/^checking /.test(v);
  });
  const said = await page.textContent('#check-verdict');
  assert.match(said, /^not shown clear: no move comes closer than tol to the scan as loaded, but the program was planned on the scan read or placed another way \(the program was planned with the scan read in in, \+Y up, this check reads it in mm, \+Z up: read it as it was then \(Units: in; Up axis: \+Y\)\); inches\.gcode against/);
  assert.equal(await page.$eval('#check-verdict', (e) => e.classList.contains('bad')), true);

  // The same program, its header saying it was planned for a larger
  // nozzle kept further off: the page's nozzle is smaller, so a clear
  // check does not show it clear, and the page names its controls (QA
  // round 6 F1).
  const larger = own.bytes.toString('utf8').replace(/\n; nozzle: d [\d.]+ mm, do [\d.]+ mm\n/, '\n; nozzle: d 1.2 mm, do 1.6 mm\n')
    .replace(/\n; process: tol [\d.]+ mm/, '\n; process: tol 0.25 mm');
  assert.notEqual(larger, own.bytes.toString('utf8'));
  await page.setInputFiles('#gcode-input', gcodeFile('larger.gcode', Buffer.from(larger)));
  await page.waitForFunction(() => {
    const v = document.getElementById('check-verdict').textContent;
    return /larger\.gcode/.test(v) && !/^checking /.test(v);
  });
  assert.match(await page.textContent('#check-verdict'), /^not shown clear: no move comes closer than tol with this nozzle, but the program was planned for a nozzle of outer diameter 1\.6 mm kept 0\.25 mm from the surface \(its header\), and this check asks less \(outer diameter 0\.908 mm, tol 0\.1 mm\): check it with the program's \(Nozzle and process: outer diameter 1\.6 mm, tol 0\.25 mm\); larger\.gcode against/);
  assert.equal(await page.$eval('#check-verdict', (e) => e.classList.contains('bad')), true);

  // Written at a risk its header names: clear of the part, and the risk
  // said beside the verdict (QA round 7 F13).
  const risky = own.bytes.toString('utf8').replace(/\n(; safe motion: [^\n]*)\n/,
    '\n$1; WARNING: written only because the risk was accepted: the tool path dispenses 9.518 mm above the surface\n');
  assert.notEqual(risky, own.bytes.toString('utf8'));
  await page.setInputFiles('#gcode-input', gcodeFile('risky.gcode', Buffer.from(risky)));
  await page.waitForFunction(() => {
    const v = document.getElementById('check-verdict').textContent;
    return /risky\.gcode/.test(v) && !/^checking /.test(v);
  });
  assert.match(await page.textContent('#check-verdict'),
    /^clear: none of the \d+ moves comes closer than tol; but its header says it was written only because the risk was accepted: the tool path dispenses 9\.518 mm above the surface; risky\.gcode against /);
  assert.equal(await page.$eval('#check-verdict', (e) => e.classList.contains('bad')), true);

  // A header naming another machine profile: the note says which, with
  // the page's control that checks it as planned (review of stop 44: the
  // command line's alone said it).
  const other = own.bytes.toString('utf8').replace('\n; profile: marlin\n', '\n; profile: aerotech\n');
  assert.notEqual(other, own.bytes.toString('utf8'));
  await page.setInputFiles('#gcode-input', gcodeFile('other.gcode', Buffer.from(other)));
  await page.waitForFunction(() => {
    const v = document.getElementById('check-verdict').textContent;
    return /other\.gcode/.test(v) && !/^checking /.test(v);
  });
  assert.match(await page.textContent('#check-notes'),
    /the program's header says it was written for profile aerotech, and this check reads it for profile marlin \(its bed, its reading of the G-code\): check it for profile aerotech \(Dialect: aerotech\) to check it as it was planned/);

  // Down beside the scan and along there: clear of what was scanned, but
  // not a green "clear" (QA round 8 F4); the moves named below it.
  const beside = 'G21 G90\nG0 X15.4 Y16 Z30\nG0 X150 Y16 Z30\nG1 Z1 F300\nG1 X160 Y16\nG0 Z30\n';
  await page.setInputFiles('#gcode-input', gcodeFile('beside.gcode', beside));
  await page.waitForFunction(() => {
    const v = document.getElementById('check-verdict').textContent;
    return /beside\.gcode/.test(v) && !/^checking /.test(v);
  });
  assert.match(await page.textContent('#check-verdict'),
    /^clear of the scanned surface: none of the 4 moves comes closer than tol, but 3 move\(s\) pass beside the scan or over a hole in it, where nothing is known of the part \(named in the notes\); beside\.gcode against demo-test-part\.ply/);
  assert.deepEqual(await page.$eval('#check-verdict', (e) => [...e.classList]), ['verdict', 'warn']);
  assert.match(await page.textContent('#check-notes'), /3 move\(s\) pass beside the scan or over a hole in it lower than tol above its top \(lines 4, 5, 6;/);

  // Down beside a 2 mm wall of the test part, then up across its corner.
  const cut = 'G21 G90\nG0 X15.4 Y16 Z30\nG1 X15.4 Y16 Z5.603 F300\nG1 X16.230 Y16 Z7.603\nG0 Z30\n';
  await page.setInputFiles('#gcode-input', gcodeFile('cut.gcode', cut));
  await page.waitForFunction(() => /touch/.test(document.getElementById('check-verdict').textContent));
  assert.match(await page.textContent('#check-verdict'), /^1 of \d+ moves touch: closer than tol; cut\.gcode against demo-test-part\.ply/);
  assert.equal(await page.$eval('#check-verdict', (e) => e.classList.contains('bad')), true);
  const touching = await page.$$eval('#check-touching tbody tr', (trs) => trs.map((tr) => [...tr.children].map((td) => td.textContent)));
  assert.equal(touching.length, 1);
  assert.equal(touching[0][0], '4');
  assert.equal(touching[0][1], '(15.400, 16.000, 5.603) → (16.230, 16.000, 7.603)');
  assert.ok(Number(touching[0][4]) > 1, touching[0].join(' | '));
  assert.match(await page.textContent('#check-min'), /^minimum clearance -\d\.\d{3} mm at line 4 /);
  const notes = await page.$$eval('#check-notes li', (lis) => lis.map((li) => li.textContent));
  assert.ok(notes.some((n) => /^line 2: the program starts by rising above the scan/.test(n)), notes.join('\n'));

  // An arc: the reader's error names the line; the plan stays offered.
  await page.setInputFiles('#gcode-input', gcodeFile('arc.nc', 'G21 G90\nG0 X10 Y10 Z30\nG2 X20 Y10 I5 J0\n'));
  await page.waitForFunction(() => /arc\.nc/.test(document.getElementById('error-title').textContent));
  assert.equal(await page.textContent('#error-title'), 'Could not check arc.nc');
  assert.match(await page.textContent('#error-message'), /^arc\.nc, line 3: arcs \(`G2` at column 1\) are not supported/);
  assert.equal(await page.textContent('#check-verdict'), 'could not check arc.nc');
  assert.equal(await page.isHidden('#dl-gcode'), false);
  assert.deepEqual(problems, []);
  await context.close();
});

test('the demo menu loads each generated part with its drawing and placement', async (t) => {
  const cli = existsSync(CLI);
  if (!cli) t.diagnostic(`${CLI} not built (cargo build --bin pcpp): the G-code is not compared with the CLI's`);
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitSettled(page);
  const parts = await page.$$eval('#demo-part option', (os) => os.map((o) => o.value));
  assert.deepEqual(parts, ['test-part', 'stepped-block', 'dimpled-hemisphere', 'folded-film', 'wrinkled-film']);
  for (const part of [...parts.slice(1), parts[0]]) {
    await page.selectOption('#demo-part', part);
    const scan = part === 'test-part' ? 'demo-test-part.ply' : `demo-${part}.ply`;
    const path = part === 'test-part' ? 'demo-test-part-lines.svg' : `demo-${part}-path.svg`;
    await page.waitForFunction((s) => {
      const p = window.pcpp.state.lastPlan;
      return p && p.gcode.includes(`; scan file: ${s}`);
    }, scan, { timeout: 120_000 });
    await waitSettled(page);
    assert.equal(await page.isHidden('#error-panel'), true, await page.textContent('#error-message'));
    assert.equal(await page.textContent('#scan-name'), scan);
    assert.equal(await page.textContent('#svg-name'), `demo: ${part} drawing`);
    const report = JSON.parse(await page.evaluate(() => window.pcpp.state.lastPlan.report()));
    assert.deepEqual(report.inputs.map((i) => i.name), [scan, path]);
    // The part's own placement, as `pcpp demo --part` plans it; only the
    // test part registers on fiducial holes.
    const placement = await page.evaluate(() => window.pcpp.settings.placement);
    assert.deepEqual(report.settings.placement,
      { offset_mm: [placement.x, placement.y], rotation_deg: placement.rot, scale: placement.scale });
    assert.equal(await page.inputValue('#fid-source'), part === 'test-part' ? 'auto' : 'none');
    assert.equal(report.motion.program.touching_moves, 0);
    assert.equal(await page.$$eval('#compare-table tbody tr', (trs) => trs.length), 5);
    const px = await viewPixels(page);
    assert.ok(px.mesh > px.total * 0.03 && px.good > 50, `${part}: ${JSON.stringify(px)}`);
    // The same G-code as `pcpp demo --part` writes for the default planner
    // (the test part is registered on its holes here, not there: its plan
    // is compared with the CLI's in live.test.mjs).
    if (cli && part !== 'test-part') {
      const out = join(dir, part);
      execFileSync(CLI, ['demo', '--part', part, '--out', out], { stdio: ['ignore', 'ignore', 'pipe'] });
      const want = readFileSync(join(out, `demo-${part}-even.gcode`), 'utf8');
      const got = await page.evaluate(() => window.pcpp.state.lastPlan.gcode);
      assert.ok(got === want, `${part}: the page's G-code differs from pcpp demo --part ${part}`);
    }
  }
  // The last part stays across a reload.
  await page.selectOption('#demo-part', 'folded-film');
  await page.waitForFunction(() => document.getElementById('scan-name').textContent === 'demo-folded-film.ply');
  await waitSettled(page);
  await page.reload();
  await waitSettled(page);
  assert.equal(await page.inputValue('#demo-part'), 'folded-film');
  assert.equal(await page.textContent('#scan-name'), 'demo-folded-film.ply');
  assert.deepEqual(problems, []);
  await context.close();
});

test('G-code written at the user\'s risk for another refusal than touching names that risk, not touching', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitSettled(page);
  // The demo drawing across a post far narrower than the drawing's lines
  // are long: the tool path would dispense far above the plate beside it.
  await page.setInputFiles('#scan-input', { name: 'plate-post.obj', mimeType: 'text/plain', buffer: Buffer.from(platePostObj()) });
  await page.waitForFunction(() => window.pcpp.state.info && window.pcpp.state.info.name === 'plate-post.obj',
    null, { timeout: 120_000 });
  await waitIdle(page);
  assert.match(await page.textContent('#error-panel'), /dispense far above the surface/);
  await page.check('#accept-risk');
  await waitSettled(page);
  assert.equal(await page.isHidden('#error-panel'), true);
  assert.equal(await page.isHidden('#risk-warning'), false);
  // No move touches: the warning, the button and the status say what was
  // accepted instead.
  assert.equal(await page.evaluate(() => window.pcpp.state.lastPlan.summary.motion.program.touching_moves), 0);
  assert.equal(await page.textContent('#risk-warning-head'), 'Written only because you accepted the risk.');
  assert.match(await page.textContent('#risk-warning-text'), /written only because the risk was accepted: the tool path dispenses \d+\.\d{3} mm above the surface/);
  assert.equal(await page.textContent('#dl-gcode'), 'Download G-code (at your risk)…');
  const status = await page.textContent('#plan-status');
  assert.match(status, /^planned .* on plate-post\.obj with even: written only because the risk was accepted \(the tool path dispenses \d+\.\d{3} mm above the surface .*\); the G-code downloads only after a confirmation/);
  assert.doesNotMatch(status + await page.textContent('#risk-warning'), /touch/);
  await page.click('#dl-gcode');
  assert.equal(await page.textContent('#dl-gcode'), 'Download anyway (at your risk)');
  assert.deepEqual(problems, []);
  await context.close();
});

// A 12 x 12 mm plate as OBJ text (two triangles).
const SMALL_PLATE = 'v 0 0 1\nv 12 0 1\nv 12 12 1\nv 0 12 1\nf 1 2 3\nf 1 3 4\n';

test('a drawing mostly beside the scan is refused, and written only once the risk is accepted', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitSettled(page);
  // A plate (QA F10: a script saw exit 0 for 5 % of a drawing printed).
  await page.setInputFiles('#scan-input', { name: 'small-plate.obj', mimeType: 'text/plain', buffer: Buffer.from(SMALL_PLATE) });
  await page.waitForFunction(() => window.pcpp.state.info && window.pcpp.state.info.name === 'small-plate.obj',
    null, { timeout: 120_000 });
  await waitIdle(page);
  // The page fits the drawing to the new scan; moved 10 mm along X, most
  // of it lies beside the plate.
  const x = Number(await page.inputValue('#pl-x'));
  // What the view is given to draw (its paths' tool points), from here on.
  const minX = (tool) => { let m = Infinity; for (let i = 0; i < tool.length; i += 3) m = Math.min(m, tool[i]); return m; };
  const planned = await page.evaluate(`(${minX})(window.pcpp.state.lastPlan.view.tool)`);
  await page.evaluate(() => {
    const v = window.pcpp.state.viewer;
    const set = v.setPathArrays.bind(v);
    window.drawnTool = null;
    v.setPathArrays = (pieces, ta, tool, defects) => { window.drawnTool = Array.from(tool); return set(pieces, ta, tool, defects); };
  });
  await page.fill('#pl-x', String(x + 10));
  await page.waitForFunction(() => !document.getElementById('error-panel').hidden, null, { timeout: 60_000 });
  await waitIdle(page);
  assert.equal(await page.textContent('#error-title'), 'Most of the drawing lies beside the scan: no G-code');
  // The refused tool path is drawn where the drawing now lies, 10 mm on
  // (QA round 7 F3: the view kept the previous plan where it was), and the
  // status says so.
  const drawn = await page.evaluate(`window.drawnTool && (${minX})(window.drawnTool)`);
  assert.ok(drawn !== null && Math.abs(drawn - (planned + 10)) < 1, `${planned} -> ${drawn}`);
  assert.equal(await page.evaluate(() => window.pcpp.state.refused.placement.offset_mm[0]), x + 10);
  assert.match(await page.textContent('#plan-status'), /no G-code: the refused tool path is shown where the drawing lies/);
  const text = await page.textContent('#error-panel');
  assert.match(text, /only \d+\.\d of the drawing's \d+\.\d mm \(\d+ %\) lie over the scan/);
  // The page's words, not the command line's.
  assert.match(text, /'Centre on scan' puts the drawing on the scan's footprint/);
  assert.match(text, /tick "write G-code even where it is refused \(at my risk\)"/);
  assert.doesNotMatch(text, /--/);
  // What the plan warned of is said with its refusal (QA round 15 F2:
  // only the previous plan's warnings were on screen), less the share
  // over the scan, which the refusal says.
  assert.match(text, /This plan also warned:\n• [^\n]*(lies off the scan|misses the scan)/);
  assert.doesNotMatch(text, /and are printed/);
  await page.check('#accept-risk');
  await waitSettled(page);
  assert.equal(await page.isHidden('#error-panel'), true);
  assert.match(await page.textContent('#risk-warning-text'),
    /written only because the risk was accepted: only \d+\.\d of the drawing's \d+\.\d mm \(\d+ %\) lie over the scan and are printed/);
  // Planned: the plan's paths are the view's again.
  assert.equal(await page.evaluate(() => window.pcpp.state.refused), null);
  assert.deepEqual(problems, []);
  await context.close();
});

// A 42.6 degree ramp (20 x 20 mm, two facets) and a line drawn up it, with
// QA round 12 H1's nozzle and tol: every height that keeps tol floats, so
// even floats all along while the paper's pcpp sits lower with its nozzle
// within tol of the ramp. The page says so under the table, in the words
// `pcpp compare` prints (job::comparison_notes).
test('the comparison notes a planner whose fewer defects come from moves closer than tol, as the CLI does', async () => {
  const k = Math.tan((42.6 * Math.PI) / 180);
  const P = [[0, 0, 0], [20, 0, 20 * k], [20, 20, 20 * k], [0, 20, 0]];
  const facets = [[0, 1, 2], [0, 2, 3]].map((t) => ` facet normal 0 0 0\n  outer loop\n${
    t.map((i) => `   vertex ${P[i].join(' ')}\n`).join('')}  endloop\n endfacet\n`).join('');
  const stl = `solid ramp\n${facets}endsolid ramp\n`;
  const svg = '<svg xmlns="http://www.w3.org/2000/svg" width="20mm" height="20mm" viewBox="0 0 20 20">'
    + '<path d="M 4 10 L 16 10" fill="none" stroke="black"/></svg>';
  const scanPath = join(dir, 'ramp.stl');
  const svgPath = join(dir, 'up-the-ramp.svg');
  writeFileSync(scanPath, stl);
  writeFileSync(svgPath, svg);
  const cli = execFileSync(CLI, ['compare', '-q', '--place', 'centre', '--nozzle-id', '0.26', '--nozzle-od', '0.51',
    '--tol', '0.05', '--scan', scanPath, '--path', svgPath], { encoding: 'utf8' });
  const cliNotes = cli.split('\n').filter((l) => l.startsWith('note: ')).map((l) => l.slice('note: '.length));
  assert.ok(cliNotes.some((n) => /^pcpp shows fewer defects than even/.test(n)), cli);

  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitSettled(page);
  // The demo part's comparison has nothing to note.
  assert.equal(await page.locator('#compare-notes li').count(), 0);
  await page.setInputFiles('#scan-input', scanPath);
  await page.setInputFiles('#svg-input', svgPath);
  await waitSettled(page);
  for (const [id, v] of [['#nz-id', '0.26'], ['#nz-od', '0.51'], ['#pr-tol', '0.05']]) {
    await page.fill(id, v);
    await page.dispatchEvent(id, 'change');
  }
  await page.waitForFunction((n) => document.querySelectorAll('#compare-notes li').length === n,
    cliNotes.length, { timeout: 120_000 });
  await waitSettled(page);
  assert.match(await page.textContent('#compare-of'), /^up-the-ramp\.svg on ramp\.stl$/);
  const notes = await page.$$eval('#compare-notes li', (lis) => lis.map((li) => li.textContent));
  assert.deepEqual(notes, cliNotes);
  const { rows } = await compareTable(page);
  assert.equal(rows.pcpp.clearanceBad, true);
  assert.equal(rows.even.clearanceBad, false);
  assert.deepEqual(problems, []);
  await context.close();
});

// QA round 15 F1: after a refused plan, a scan file that cannot be read
// left "settings changed: re-planning…" on screen while nothing planned,
// emptied the planners' table and said nothing of the refusal. Nothing the
// refusal was planned from changed: it stands, and says so.
test('a broken scan after a refused plan keeps the refusal, its status and its comparison', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await refusedOnSteppedBlock(page);
  const status = await page.textContent('#plan-status');
  assert.equal(status, 'no G-code: the refused tool path is shown where the drawing lies (see above)');
  const table = await compareTable(page);
  assert.equal(table.rows.slope.clearanceBad, true);

  await page.setInputFiles('#scan-input', { name: 'broken.stl', mimeType: 'application/octet-stream',
    buffer: Buffer.from('solid broken\nfacet normal 0 0 1\n outer loop\n  vertex 1 2\n') });
  await page.waitForFunction(() => /broken\.stl/.test(document.getElementById('error-title').textContent));
  await waitIdle(page);
  const message = await page.textContent('#error-message');
  assert.match(message, /Still using the previous scan, demo-stepped-block\.ply\./);
  assert.match(message, /Its plan stays refused: The nozzle would touch the part with slope: no G-code\./);
  assert.equal(await page.textContent('#plan-status'), status);
  assert.deepEqual(await compareTable(page), table);
  assert.equal(await page.isHidden('#dl-gcode'), true);
  // A drawing that cannot be read goes back to the refused one; a broken
  // scan after it still finds the refusal standing.
  await page.setInputFiles('#svg-input', { name: 'broken.svg', mimeType: 'image/svg+xml', buffer: Buffer.from('<svg><path d="M 0 0 L') });
  await page.waitForFunction(() => /broken\.svg/.test(document.getElementById('error-title').textContent));
  await waitIdle(page);
  await page.setInputFiles('#scan-input', { name: 'broken2.stl', mimeType: 'application/octet-stream',
    buffer: Buffer.from('solid broken\nfacet normal 0 0 1\n outer loop\n  vertex 1 2\n') });
  await page.waitForFunction(() => /broken2\.stl/.test(document.getElementById('error-title').textContent));
  await waitIdle(page);
  assert.match(await page.textContent('#error-message'), /Its plan stays refused: The nozzle would touch the part with slope/);
  assert.equal(await page.textContent('#plan-status'), status);
  assert.deepEqual(problems, []);
  await context.close();
});
