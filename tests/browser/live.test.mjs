// Live re-planning: dragging the path on the scan, turning and scaling it
// with the sliders, or typing a nozzle diameter re-plans in the worker as
// the input changes, only the newest placement is planned (no backlog), no
// stale G-code is ever offered, and the plan left on screen is the last
// placement's: its download equals a fresh plan there (the CLI's, and the
// page's own after a reload). The drag test prints the frame rate and the
// re-planning figures it measured.
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { existsSync, mkdtempSync, readFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { after, before, test } from 'node:test';
import { ROOT, download, openPage, startProbe, stopProbe, waitSettled, withPageServer } from './helpers.mjs';

const env = withPageServer();
const CLI = join(ROOT, 'target/debug/pcpp');

let dir;
before(() => {
  dir = mkdtempSync(join(tmpdir(), 'pcpp-live-'));
});
after(() => {
  if (dir) rmSync(dir, { recursive: true, force: true });
});

const median = (v) => {
  const s = [...v].sort((a, b) => a - b);
  return s.length ? s[Math.floor(s.length / 2)] : NaN;
};

// The CLI's plan of the demo at `placement`, with the page's demo
// registration (auto fiducials against its printer points).
function cliDemoGcode(placement, printerText) {
  const demoDir = join(dir, 'demo');
  if (!existsSync(join(demoDir, 'demo-test-part.ply'))) {
    execFileSync(CLI, ['demo', '--out', demoDir], { stdio: ['ignore', 'ignore', 'pipe'] });
  }
  const out = join(dir, `cli-${placement.x}-${placement.y}.gcode`);
  execFileSync(CLI, ['plan', '--scan', join(demoDir, 'demo-test-part.ply'),
    '--path', join(demoDir, 'demo-test-part-lines.svg'), '-o', out,
    '--place', `${placement.x},${placement.y},${placement.rot},${placement.scale}`,
    '--fiducials', 'auto', '--printer-points', printerText.trim().split('\n').join(';')],
  { stdio: ['ignore', 'ignore', 'pipe'] });
  return readFileSync(out);
}

test('a drag moves the path on the scan and re-plans as it goes; the last placement is planned and downloadable', async (t) => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitSettled(page);
  await page.click('#top-view');
  await page.click('#move-btn');
  assert.equal(await page.getAttribute('#move-btn', 'aria-pressed'), 'true');
  const start = await page.evaluate(() => ({ ...window.pcpp.settings.placement }));
  const box = await page.locator('#view').boundingBox();
  const cx = box.x + box.width / 2;
  const cy = box.y + box.height / 2;
  await startProbe(page);
  const before = await page.evaluate(() => {
    const s = window.pcpp.state;
    return { frames: s.frames, plans: s.stats.plans, n: s.stats.planMs.length };
  });

  // 80 pointer moves, right and up, a little over a second of dragging;
  // halfway the test waits until a plan made during the drag is on screen.
  // (Not so far that most of the drawing leaves the scan: that is refused,
  // and the test wants a plan to download.)
  const moves = 80;
  await page.mouse.move(cx, cy);
  await page.mouse.down();
  const t0 = Date.now();
  for (let i = 1; i <= moves; i++) {
    await page.mouse.move(cx + (40 * i) / moves, cy - (16 * i) / moves + 8 * Math.sin((Math.PI * i) / 20));
    await page.waitForTimeout(12);
    if (i === moves / 2) {
      await page.waitForFunction((n) => window.pcpp.state.stats.plans > n, before.plans, { timeout: 60_000 });
    }
  }
  const dragSeconds = (Date.now() - t0) / 1000;
  const during = await page.evaluate(() => {
    const s = window.pcpp.state;
    return { frames: s.frames, plans: s.stats.plans, interacting: s.interacting };
  });
  await page.mouse.up();
  await waitSettled(page);
  const probe = await stopProbe(page);
  const after = await page.evaluate(() => {
    const s = window.pcpp.state;
    return {
      plans: s.stats.plans,
      planMs: s.stats.planMs,
      latencyMs: s.stats.latencyMs,
      overlapped: s.stats.overlapped,
      placement: { ...window.pcpp.settings.placement },
      planned: s.lastPlan.placement,
      shown: document.getElementById('shown-placement').textContent,
      x: document.getElementById('pl-x').value,
      y: document.getElementById('pl-y').value,
      planTime: document.getElementById('plan-time').textContent,
      printer: window.pcpp.settings.fidPrinterText,
    };
  });
  const planMs = after.planMs.slice(before.n);
  const latency = after.latencyMs.slice(before.n);
  const livePlans = during.plans - before.plans;
  const fps = (during.frames - before.frames) / dragSeconds;
  console.log(`live re-planning (demo part, ${moves} pointer moves in ${dragSeconds.toFixed(2)} s): `
    + `view drew ${during.frames - before.frames} frames = ${fps.toFixed(1)} fps; browser ${(probe.raf / probe.seconds).toFixed(1)} fps `
    + `over the drag and settling; ${livePlans} re-plans during the drag + ${after.plans - during.plans} after release; `
    + `planner ${median(planMs).toFixed(0)} ms median (max ${Math.max(...planMs).toFixed(0)}), `
    + `change to plan on screen ${median(latency).toFixed(0)} ms median (max ${Math.max(...latency).toFixed(0)})`);

  assert.equal(during.interacting, true);
  assert.ok(livePlans >= 1, 'plans were shown during the drag');
  // Coalesced: never a request while another was in flight, and far fewer
  // plans than pointer moves when planning is slower than the moves.
  assert.equal(after.overlapped, 0);
  assert.ok(after.plans - before.plans <= moves + 1, `${after.plans - before.plans} plans for ${moves} moves`);
  assert.deepEqual(probe.staleOffers, [], 'a download was offered for another placement than the current one');
  // The path moved right and up (printer +x, +y in the top view) ...
  assert.ok(after.placement.x > start.x + 3 && after.placement.y > start.y + 1,
    `moved from ${JSON.stringify(start)} to ${JSON.stringify(after.placement)}`);
  // ... and what is on screen is the last position's plan.
  assert.deepEqual(after.planned.offset_mm, [after.placement.x, after.placement.y]);
  assert.equal(Number(after.x), after.placement.x);
  assert.equal(Number(after.y), after.placement.y);
  assert.ok(after.shown.startsWith(`(${after.placement.x}, ${after.placement.y}) mm`), after.shown);
  assert.match(after.planTime, /^plan \d+ ms, on screen \d+ ms/);
  const gcode = await download(page, 'dl-gcode');
  const text = gcode.bytes.toString('utf8');
  const header = text.split('\n').find((l) => l.includes('placement: offset'));
  assert.ok(header.includes(`${after.placement.x}, ${after.placement.y}) mm`), header);

  // A fresh plan at that placement: the page's own after a reload (the
  // placement is kept) ...
  await page.reload();
  await waitSettled(page);
  assert.equal(Number(await page.inputValue('#pl-x')), after.placement.x);
  const fresh = await download(page, 'dl-gcode');
  assert.ok(fresh.bytes.equals(gcode.bytes), 'the G-code after the drag differs from a fresh plan at its placement');
  assert.deepEqual(problems, []);
  await context.close();

  // ... and the command line's.
  if (!existsSync(CLI)) {
    t.skip(`${CLI} not built (cargo build --bin pcpp)`);
    return;
  }
  const cli = cliDemoGcode(after.placement, after.printer);
  if (!cli.equals(gcode.bytes)) {
    const a = cli.toString('utf8').split('\n');
    const b = text.split('\n');
    const i = a.findIndex((l, k) => l !== b[k]);
    assert.fail(`the G-code after the drag differs from the CLI at the same placement, first at line ${i + 1}:\n`
      + `CLI:  ${a[i]}\npage: ${b[i]}`);
  }
});

test('the rotation and scale sliders, typed nozzle sizes and arrow keys re-plan as they change', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitSettled(page);
  await startProbe(page);
  const plans0 = await page.evaluate(() => window.pcpp.state.stats.plans);
  // A slider dragged from 0 to 12 degrees: input events, then change.
  for (let deg = 1; deg <= 12; deg++) {
    await page.evaluate((v) => {
      const el = document.getElementById('pl-rot-range');
      el.value = String(v);
      el.dispatchEvent(new Event('input', { bubbles: true }));
    }, deg);
    await page.waitForTimeout(25);
  }
  assert.equal(await page.evaluate(() => window.pcpp.state.interacting), true);
  await page.dispatchEvent('#pl-rot-range', 'change');
  await waitSettled(page);
  let report = JSON.parse(await page.evaluate(() => window.pcpp.state.lastPlan.report()));
  assert.equal(report.settings.placement.rotation_deg, 12);
  assert.equal(await page.inputValue('#pl-rot'), '12'); // the number field follows
  assert.equal(await page.$eval('#compare-table', (e) => e.classList.contains('stale')), false);

  await page.evaluate(() => {
    const el = document.getElementById('pl-scale-range');
    for (const v of ['0.9', '0.85', '0.8']) {
      el.value = v;
      el.dispatchEvent(new Event('input', { bubbles: true }));
    }
    el.dispatchEvent(new Event('change', { bubbles: true }));
  });
  await waitSettled(page);
  report = JSON.parse(await page.evaluate(() => window.pcpp.state.lastPlan.report()));
  assert.equal(report.settings.placement.scale, 0.8);

  // Typing a nozzle size re-plans without a change event or a click.
  await page.fill('#nz-id', '0.41');
  await page.fill('#nz-od', '0.72');
  await waitSettled(page);
  report = JSON.parse(await page.evaluate(() => window.pcpp.state.lastPlan.report()));
  assert.deepEqual(report.settings.nozzle, { inner_diameter_mm: 0.41, outer_diameter_mm: 0.72 });

  // In move mode the arrow keys nudge the path: 0.5 mm, 5 mm with Shift.
  const at = await page.evaluate(() => ({ ...window.pcpp.settings.placement }));
  await page.click('#move-btn');
  await page.focus('#view');
  await page.keyboard.press('ArrowRight');
  await page.keyboard.press('Shift+ArrowUp');
  await waitSettled(page);
  report = JSON.parse(await page.evaluate(() => window.pcpp.state.lastPlan.report()));
  assert.deepEqual(report.settings.placement.offset_mm, [at.x + 0.5, at.y + 5]);

  const probe = await stopProbe(page);
  assert.deepEqual(probe.staleOffers, []);
  const st = await page.evaluate(() => window.pcpp.state.stats);
  assert.ok(st.plans - plans0 >= 3, `${st.plans - plans0} plans`);
  assert.equal(st.overlapped, 0);
  assert.deepEqual(problems, []);
  await context.close();
});
