// The print preview: the plan's G-code (and an uploaded, checked file)
// played over the scan. The slider moves the nozzle (read back from the
// canvas), the readouts show the G-code line the downloaded file has at
// that move, its position and clearance; the path is coloured by clearance
// or by predicted defect; a click on the path jumps there; play advances;
// the single-file page does the same.
import assert from 'node:assert/strict';
import { existsSync } from 'node:fs';
import { join } from 'node:path';
import { pathToFileURL } from 'node:url';
import { test } from 'node:test';
import {
  DIST, countViewPixels, download, openPage, waitSettled, withPageServer,
} from './helpers.mjs';

const env = withPageServer();

const nextFrames = (page) => page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));

// Turns the preview on and waits for the program of `source` ('plan' or
// 'check') to be shown in the view.
async function previewOn(page, source = 'plan') {
  if ((await page.inputValue('#preview-source')) !== source) await page.selectOption('#preview-source', source);
  if ((await page.getAttribute('#preview-btn', 'aria-pressed')) !== 'true') await page.click('#preview-btn');
  await page.waitForFunction((s) => {
    const st = window.pcpp.state;
    return st.preview.data && st.preview.data.source === s && st.viewShows === 'preview';
  }, source, { timeout: 120_000 });
}

// Moves the slider to `t` seconds, as a user's drag does.
async function slide(page, t) {
  await page.evaluate((v) => {
    const el = document.getElementById('preview-time');
    el.value = String(v);
    el.dispatchEvent(new Event('input', { bubbles: true }));
  }, t);
  await nextFrames(page);
}

const readouts = (page) => page.evaluate(() => ({
  lineNo: Number(document.getElementById('preview-line-no').textContent.replace(/^line /, '')),
  text: document.getElementById('preview-line-text').textContent,
  pos: document.getElementById('preview-pos').textContent,
  clear: document.getElementById('preview-clear').textContent,
  clearClass: document.getElementById('preview-clear').className,
  elapsed: document.getElementById('preview-elapsed').textContent,
  t: window.pcpp.state.preview.t,
  index: window.pcpp.state.preview.index,
}));

// The view's pixels: the nozzle's violet (its centroid), and the path's
// colours by clearance class and defect (src/render.rs).
const pixels = async (page) => {
  const start = { nozzle: 0, nx: 0, ny: 0, green: 0, orange: 0, red: 0, blue: 0 };
  const out = await countViewPixels(page, start, (o, r, g, b, x, y) => {
    const near = ([R, G, B]) => Math.abs(r - R) < 8 && Math.abs(g - G) < 8 && Math.abs(b - B) < 8;
    if (b > 120 && b > r + 20 && r > g + 30) {
      o.nozzle++;
      o.nx += x;
      o.ny += y;
    } else if (near([40, 210, 70])) o.green++;
    else if (near([255, 150, 20])) o.orange++;
    else if (r > 170 && g < 100 && b < 100) o.red++;
    else if (near([40, 120, 255])) o.blue++;
  });
  if (out.nozzle) {
    out.nx /= out.nozzle;
    out.ny /= out.nozzle;
  }
  return out;
};

// The middle of the first move that matches `pred(i, r)` in the preview's
// arrays: {i, t, mid}.
const moveWhere = (page, pred) => page.evaluate((src) => {
  const r = window.pcpp.state.preview.data.r;
  // eslint-disable-next-line no-new-func
  const f = new Function('i', 'r', `return (${src})(i, r);`);
  for (let i = 0; i < r.starts.length; i++) {
    if (f(i, r)) {
      const m = r.moves.slice(6 * i, 6 * i + 6);
      return { i, t: r.starts[i] + r.durations[i] / 2, mid: [0, 1, 2].map((k) => (m[k] + m[k + 3]) / 2), line: r.lines[i] };
    }
  }
  return null;
}, pred.toString());

test('the preview scrubs the plan\'s G-code: the nozzle moves, the line is the file\'s, colours by clearance and defect', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitSettled(page);
  const gcode = (await download(page, 'dl-gcode')).bytes.toString('utf8').split('\n');
  await previewOn(page);
  const status = await page.textContent('#preview-status');
  assert.match(status, /^the plan's G-code demo-test-part-lines-even\.gcode: \d+ moves, .* at its feeds; 0 closer than tol \(0\.100 mm\), \d+ near/);
  const total = await page.evaluate(() => window.pcpp.state.preview.data.total);
  // The plan's print time is inside the program's time (travel and dwell added).
  const printTime = JSON.parse(await page.evaluate(() => window.pcpp.state.lastPlan.report())).stats.print_time_s;
  assert.ok(total > printTime && total < printTime * 3, `${total} s against ${printTime} s printing`);

  // A print move that comes near (tol to tol + 0.1 mm) and one well clear.
  const nearMove = await moveWhere(page, (i, r) => !r.rapid[i] && r.classes[i] === 1 && r.durations[i] > 0.05);
  const clearMove = await moveWhere(page, (i, r) => !r.rapid[i] && r.classes[i] === 0 && r.clearance[i] > 0.4
    && r.durations[i] > 0.2 && r.starts[i] > r.starts[r.starts.length - 1] / 2);
  assert.ok(nearMove && clearMove, JSON.stringify({ nearMove, clearMove }));

  await slide(page, nearMove.t);
  const a = await readouts(page);
  const pa = await pixels(page);
  await slide(page, clearMove.t);
  const b = await readouts(page);
  const pb = await pixels(page);
  // The shown line is the downloaded G-code's line of that move.
  assert.equal(a.lineNo, nearMove.line);
  assert.equal(b.lineNo, clearMove.line);
  assert.equal(a.text, gcode[a.lineNo - 1]);
  assert.equal(b.text, gcode[b.lineNo - 1]);
  assert.match(a.text, /^G1 X/);
  assert.match(a.clear, /^0\.1\d\d mm along this move \(near; tol 0\.100 mm\)$/);
  assert.equal(a.clearClass, 'near');
  assert.match(b.clear, /mm along this move \(clear; tol 0\.100 mm\)$/);
  assert.match(a.elapsed, /^(\d+\.\d s|\d+:\d\d\.\d) of /);
  const posOf = (r) => r.pos.match(/-?\d+\.\d+/g).map(Number);
  for (const [r, m] of [[a, nearMove], [b, clearMove]]) {
    posOf(r).forEach((v, k) => assert.ok(Math.abs(v - m.mid[k]) < 0.01, `${r.pos} against ${m.mid}`));
  }
  // The nozzle is drawn, and it moved on screen.
  assert.ok(pa.nozzle > 30 && pb.nozzle > 30, JSON.stringify({ pa, pb }));
  assert.ok(Math.hypot(pa.nx - pb.nx, pa.ny - pb.ny) > 20, JSON.stringify({ pa, pb }));
  // By clearance: green and orange moves, no defect blue.
  assert.ok(pb.green > 200 && pb.orange > 5 && pb.blue === 0, JSON.stringify(pb));

  // By predicted defect: the floating and flattening points' colours.
  await page.selectOption('#preview-colour', 'defect');
  await nextFrames(page);
  const pd = await pixels(page);
  assert.ok(pd.blue > 0 && pd.green > 200, JSON.stringify(pd));
  assert.notDeepEqual([pd.green, pd.orange, pd.blue], [pb.green, pb.orange, pb.blue]);
  await page.selectOption('#preview-colour', 'clearance');

  // A click on the path jumps there: the middle of the clear move.
  const [px, py] = await page.evaluate((m) => window.pcpp.state.viewer.projectPoint(...m.mid), clearMove);
  await slide(page, 0);
  const box = await page.$eval('#view', (c) => { const r = c.getBoundingClientRect(); return [r.left, r.top, c.width / r.width]; });
  await page.mouse.click(box[0] + px / box[2], box[1] + py / box[2]);
  await nextFrames(page);
  const c = await readouts(page);
  const at = posOf(c);
  assert.ok(Math.hypot(at[0] - clearMove.mid[0], at[1] - clearMove.mid[1], at[2] - clearMove.mid[2]) < 1, `${c.pos} against ${clearMove.mid}`);
  assert.equal(c.text, gcode[c.lineNo - 1]);

  // Play advances the time at the chosen speed-up; pause stops it.
  await page.selectOption('#preview-speed', '10');
  await slide(page, total / 4);
  const t0 = (await readouts(page)).t;
  const wall0 = performance.now();
  await page.click('#preview-play');
  await page.waitForTimeout(600);
  await page.click('#preview-play');
  const wall = (performance.now() - wall0) / 1000;
  const t1 = (await readouts(page)).t;
  // 0.6 s at 10x: about 6 s of the program (less at a slow frame rate),
  // and never more than 10x the wall time from the click on play to the
  // click on pause (which a busy machine stretches past 0.6 s).
  assert.ok(t1 - t0 > 1 && t1 - t0 <= 10 * wall, `${t0} -> ${t1} in ${wall} s`);
  await page.waitForTimeout(200);
  assert.equal((await readouts(page)).t, t1);

  // Back to the plan: the nozzle is gone, the plan's paths are drawn.
  await page.click('#preview-btn');
  await nextFrames(page);
  const back = await pixels(page);
  assert.equal(back.nozzle, 0, JSON.stringify(back));
  assert.equal(await page.evaluate(() => window.pcpp.state.viewShows), 'plan');
  assert.deepEqual(problems, []);
  await context.close();
});

test('an uploaded G-code file, checked against the scan, is previewed with its touching move in red', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitSettled(page);
  // Down beside a 2 mm wall of the test part, then up across its corner.
  const cut = 'G21 G90\nG0 X15.4 Y16 Z30\nG1 X15.4 Y16 Z5.603 F300\nG1 X16.230 Y16 Z7.603\nG0 Z30\n';
  await page.setInputFiles('#gcode-input', { name: 'cut.gcode', mimeType: 'text/plain', buffer: Buffer.from(cut) });
  await page.waitForFunction(() => /touch/.test(document.getElementById('check-verdict').textContent));
  await previewOn(page, 'check');
  assert.match(await page.textContent('#preview-status'), /^checked file cut\.gcode: 3 moves, .* 1 closer than tol \(0\.100 mm\)/);
  // F300 = 5 mm/s: the 24.397 mm descent takes 4.879 s.
  const r = await page.evaluate(() => {
    const d = window.pcpp.state.preview.data.r;
    return { starts: [...d.starts], durations: [...d.durations], classes: [...d.classes] };
  });
  assert.ok(Math.abs(r.durations[0] - 24.397 / 5) < 1e-9, JSON.stringify(r));
  assert.deepEqual(r.classes.slice(0, 2), [0, 2]);
  await slide(page, r.starts[1] + r.durations[1] / 2);
  const a = await readouts(page);
  assert.equal(a.lineNo, 4);
  assert.equal(a.text, 'G1 X16.230 Y16 Z7.603');
  assert.match(a.clear, /^-\d\.\d{3} mm along this move \(closer than tol; tol 0\.100 mm\)$/);
  assert.equal(a.clearClass, 'bad');
  assert.equal(a.pos, '(15.815, 16.000, 6.603) mm');
  const pa = await pixels(page);
  await slide(page, r.starts[0] + 0.1);
  const b = await readouts(page);
  assert.equal(b.lineNo, 3);
  assert.equal(b.text, 'G1 X15.4 Y16 Z5.603 F300');
  const pb = await pixels(page);
  // The touching move in red (seen once the nozzle has left it).
  assert.ok(pb.red > 0 && pa.nozzle > 10 && pb.nozzle > 10, JSON.stringify({ pa, pb }));
  assert.ok(Math.hypot(pa.nx - pb.nx, pa.ny - pb.ny) > 3, JSON.stringify({ pa, pb }));
  // No plan defects for another tool's file: colouring by clearance only.
  assert.equal(await page.$eval('#preview-colour option[value="defect"]', (o) => o.disabled), true);
  // Back to the plan's program.
  await previewOn(page, 'plan');
  assert.match(await page.textContent('#preview-status'), /^the plan's G-code/);
  assert.deepEqual(problems, []);
  await context.close();
});

test('the single-file page previews too', async () => {
  const file = join(DIST, 'pcpp.html');
  assert.ok(existsSync(file), 'run scripts/build-web.sh first');
  const { page, context, problems } = await openPage(env.chrome.browser, pathToFileURL(file).href);
  await waitSettled(page);
  await previewOn(page);
  const total = await page.evaluate(() => window.pcpp.state.preview.data.total);
  await slide(page, total * 0.3);
  const a = await readouts(page);
  const pa = await pixels(page);
  await slide(page, total * 0.6);
  const b = await readouts(page);
  const pb = await pixels(page);
  assert.ok(a.lineNo > 0 && b.lineNo > a.lineNo, JSON.stringify({ a, b }));
  assert.notEqual(a.pos, b.pos);
  assert.ok(pa.nozzle > 10 && pb.nozzle > 10, JSON.stringify({ pa, pb }));
  assert.deepEqual(problems, []);
  await context.close();
});
