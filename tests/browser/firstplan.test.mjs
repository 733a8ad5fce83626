// What the page shows around a failed plan (QA round 2 F6): the figures
// and warnings of the plan left on screen say whose they are, and the demo
// drawing, planned on a user's freshly opened scan, is not reported as the
// user's failure.
import assert from 'node:assert/strict';
import { test } from 'node:test';
import {
  openPage, platePostObj, waitIdle, waitKept, waitSettled, withPageServer,
} from './helpers.mjs';

const env = withPageServer();

const svg = (name, body) => ({
  name,
  mimeType: 'image/svg+xml',
  buffer: Buffer.from('<svg xmlns="http://www.w3.org/2000/svg" width="40mm" height="20mm" viewBox="0 0 40 20">'
    + `${body}</svg>\n`),
});

// The plate with a post as a file for the scan input, and opened, read
// and planned on.
const platePost = () => ({ name: 'plate-post.obj', mimeType: 'text/plain', buffer: Buffer.from(platePostObj()) });
async function openPlatePost(page) {
  await page.setInputFiles('#scan-input', platePost());
  await page.waitForFunction(() => window.pcpp.state.info && window.pcpp.state.info.name === 'plate-post.obj',
    null, { timeout: 120_000 });
  await waitIdle(page);
}

test('after a failed plan the plan left on screen is labelled and greyed as the previous one', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitSettled(page);
  const demo = await page.evaluate(() => window.pcpp.state.lastPlan.svgName);
  assert.equal(await page.textContent('#plan-of'), `${demo} on demo-test-part.ply`);
  assert.equal(await page.evaluate(() => document.getElementById('warnings').classList.contains('stale')), false);

  // A drawing of dots only: read, but nothing to print.
  await page.setInputFiles('#svg-input', svg('dots.svg',
    '<path d="M 10 10 L 10 10 M 30 10 L 30 10" stroke="black" stroke-width="1" fill="none"/>'));
  await page.waitForFunction(() => !document.getElementById('error-panel').hidden, null, { timeout: 120_000 });
  await waitIdle(page);
  assert.match(await page.textContent('#plan-status'), /showing the previous plan/);
  assert.equal(await page.textContent('#plan-of'),
    `the previous plan, not the one that failed: ${demo} on demo-test-part.ply`);
  for (const id of ['warnings', 'stats-table', 'motion-table', 'plot']) {
    assert.equal(await page.evaluate((i) => document.getElementById(i).classList.contains('stale'), id), true, id);
  }
  // Each panel says whose figures it shows (QA round 4 F3), the comparison
  // too: the dots were not compared, so it is the previous plan's.
  for (const id of ['motion-of', 'plot-of', 'compare-of']) {
    assert.equal(await page.textContent(`#${id}`),
      `the previous plan, not the one that failed: ${demo} on demo-test-part.ply`, id);
  }
  assert.equal(await page.evaluate(() => document.getElementById('compare-table').classList.contains('stale')), true);
  // The error is the user's: the panel's error colours.
  assert.equal(await page.evaluate(() => document.getElementById('error-panel').classList.contains('notice')), false);

  // A drawing that plans: its own label, nothing greyed.
  await page.setInputFiles('#svg-input', svg('line.svg', '<path d="M 5 10 L 35 10" stroke="black" fill="none"/>'));
  await waitSettled(page);
  assert.match(await page.textContent('#plan-status'), /^planned line\.svg on demo-test-part\.ply/);
  for (const id of ['plan-of', 'motion-of', 'plot-of', 'compare-of']) {
    assert.equal(await page.textContent(`#${id}`), 'line.svg on demo-test-part.ply', id);
  }
  for (const id of ['warnings', 'plot', 'compare-table']) {
    assert.equal(await page.evaluate((i) => document.getElementById(i).classList.contains('stale'), id), false, id);
  }
  assert.deepEqual(problems, []);
  await context.close();
});

test('the demo drawing refused on a freshly opened scan is a notice about the demo drawing, not an error', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitSettled(page);
  await openPlatePost(page);
  assert.equal(await page.isHidden('#error-panel'), false);
  assert.equal(await page.textContent('#error-title'), 'plate-post.obj is open; the demo drawing does not print on it');
  const message = await page.textContent('#error-message');
  // Why (the refusal as it was), then what to do.
  assert.match(message, /^The nozzle would dispense far above the surface\.\n/);
  assert.match(message, /dispense/);
  assert.match(message, /\nThe demo drawing only shows the page at work: open your drawing \(SVG\) to plan it on this scan\.$/);
  assert.equal(await page.evaluate(() => document.getElementById('error-panel').classList.contains('notice')), true);
  assert.equal(await page.textContent('#plan-status'),
    'plate-post.obj open: the demo drawing does not print on it; open your drawing (SVG)');
  // Not the box that accepts the risk, for a drawing the user never chose
  // (QA round 4 F5).
  assert.doesNotMatch(message, /tick "write G-code even|accept the risk/);
  // The refused plan's comparison shows why, and says so.
  assert.match(await page.textContent('#compare-of'),
    /^the plan that failed, compared: demo-[\w-]+\.svg on plate-post\.obj$/);
  // Planned again (the Plan button), the demo drawing is still not the
  // user's failure (QA round 4 F2).
  await page.click('#plan-btn');
  await page.waitForFunction(() => !window.pcpp.state.busy && !window.pcpp.state.queued, null, { timeout: 120_000 });
  await waitIdle(page);
  assert.equal(await page.textContent('#error-title'), 'plate-post.obj is open; the demo drawing does not print on it');
  assert.equal(await page.evaluate(() => document.getElementById('error-panel').classList.contains('notice')), true);

  // The user's own drawing, scaled up by the user: then the demo drawing
  // chosen again from the list comes back centred at its own size, not
  // at the other drawing's place and scale, and its refusal is a notice
  // again (QA round 5 N1).
  await page.setInputFiles('#svg-input', svg('line.svg', '<path d="M 5 10 L 35 10" stroke="black" fill="none"/>'));
  // (Planned, or read and refused.)
  await page.waitForFunction(() => {
    const st = window.pcpp.state;
    return st.svgFile && st.svgFile.name === 'line.svg';
  }, null, { timeout: 120_000 });
  await waitIdle(page);
  await page.fill('#pl-scale', '3');
  await page.press('#pl-scale', 'Enter');
  await page.waitForFunction(() => Number(window.pcpp.settings.placement.scale) === 3, null, { timeout: 60_000 });
  await waitIdle(page);
  await page.selectOption('#path-source', 'demo');
  await page.waitForFunction(() => Number(window.pcpp.settings.placement.scale) !== 3
    && !window.pcpp.state.busy && !window.pcpp.state.queued, null, { timeout: 120_000 });
  await waitIdle(page);
  // (The settings, not the field: the one typed in keeps its focus.)
  const scale = await page.evaluate(() => Number(window.pcpp.settings.placement.scale));
  assert.ok(scale <= 1, String(scale));
  if (!(await page.isHidden('#error-panel'))) {
    assert.equal(await page.textContent('#error-title'), 'plate-post.obj is open; the demo drawing does not print on it');
  }

  // The user's own drawing refused on the same scan is the user's error.
  await page.setInputFiles('#svg-input', svg('across.svg', '<path d="M 0 10 L 40 10" stroke="black" fill="none"/>'));
  await page.waitForFunction(() => !/demo drawing/.test(document.getElementById('error-title').textContent)
    || /^planned across\.svg/.test(document.getElementById('plan-status').textContent), null, { timeout: 120_000 });
  await waitIdle(page);
  assert.equal(await page.isHidden('#error-panel'), false);
  assert.match(await page.textContent('#error-message'), /dispense/);
  assert.equal(await page.evaluate(() => document.getElementById('error-panel').classList.contains('notice')), false);
  assert.deepEqual(problems, []);
  await context.close();
});

// After a reload the scan is read again: the demo drawing the user left
// where the page put it is still the demo's (a notice); once the user has
// moved it, its refusal is theirs (red), before and after a reload (QA
// round 5 N6: it turned blue again).
test('the demo drawing moved by the user on their scan stays theirs after a reload', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitSettled(page);
  await page.setInputFiles('#scan-input', platePost());
  const reopened = async () => {
    await page.waitForFunction(() => window.pcpp && window.pcpp.state.info
      && window.pcpp.state.info.name === 'plate-post.obj', null, { timeout: 120_000 });
    await waitIdle(page);
  };
  const shown = () => page.evaluate(() => [document.getElementById('error-title').textContent,
    document.getElementById('error-panel').classList.contains('notice')]);
  const notice = ['plate-post.obj is open; the demo drawing does not print on it', true];
  await reopened();
  assert.deepEqual(await shown(), notice);
  await waitKept(page);
  await page.reload();
  await reopened();
  assert.deepEqual(await shown(), notice);

  const x = await page.evaluate(() => Number(window.pcpp.settings.placement.x));
  await page.fill('#pl-x', String(x + 1));
  await page.press('#pl-x', 'Enter');
  await page.waitForFunction((want) => Number(window.pcpp.settings.placement.x) === want, x + 1, { timeout: 60_000 });
  // (Its plan, not the one before it, ends in the panel.)
  await page.waitForFunction(() => !document.getElementById('error-panel').classList.contains('notice')
    || document.getElementById('error-panel').hidden, null, { timeout: 60_000 });
  await waitIdle(page);
  const moved = await shown();
  assert.equal(moved[1], false, moved[0]);
  assert.notEqual(moved[0], notice[0]);
  await waitKept(page);
  await page.reload();
  await reopened();
  assert.equal(await page.evaluate(() => Number(window.pcpp.settings.placement.x)), x + 1);
  assert.deepEqual(await shown(), moved);
  assert.deepEqual(problems, []);
  await context.close();
});

// A drawing the user opened whose plan was refused is theirs all the same:
// a reload reopens it where it lay, refused as before (QA round 7 F7: the
// demo drawing came back, or an older drawing with its G-code offered).
test('a drawing refused on the scan is reopened after a reload, where it lay', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitSettled(page);
  await openPlatePost(page);
  await page.setInputFiles('#svg-input', svg('across.svg', '<path d="M 0 10 L 40 10" stroke="black" fill="none"/>'));
  await page.waitForFunction(() => window.pcpp.state.svgFile && window.pcpp.state.svgFile.name === 'across.svg'
    && !window.pcpp.state.busy && !window.pcpp.state.queued, null, { timeout: 120_000 });
  await waitIdle(page);
  const refused = await page.evaluate(() => [document.getElementById('error-title').textContent,
    document.getElementById('error-panel').classList.contains('notice'), { ...window.pcpp.settings.placement }]);
  assert.equal(refused[1], false, refused[0]);
  assert.equal(await page.isHidden('#dl-gcode'), true);
  await waitKept(page);
  await page.reload();
  await page.waitForFunction(() => window.pcpp && window.pcpp.state.info && window.pcpp.state.info.name === 'plate-post.obj'
    && window.pcpp.state.svgFile && window.pcpp.state.svgFile.name === 'across.svg', null, { timeout: 120_000 });
  await waitIdle(page);
  assert.equal(await page.evaluate(() => window.pcpp.settings.pathSource), 'file');
  assert.deepEqual(await page.evaluate(() => ({ ...window.pcpp.settings.placement })), refused[2]);
  assert.deepEqual(await page.evaluate(() => [document.getElementById('error-title').textContent,
    document.getElementById('error-panel').classList.contains('notice')]), refused.slice(0, 2));
  assert.equal(await page.isHidden('#dl-gcode'), true);
  assert.deepEqual(problems, []);
  await context.close();
});

// A scan larger than the build volume is the scan's problem, whatever the
// drawing: a red error naming the volume, not the demo drawing's notice
// (QA round 4 F1: gltfpack's cow got "open your drawing (SVG)").
test('a scan larger than the build volume is an error about the scan, not the demo drawing\'s notice', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitSettled(page);
  // A 300 x 300 mm plate, 5 mm up, from x = 200: wider than marlin's
  // 220 mm, and the drawing centred on it lies beyond the volume.
  const plate = 'v 200 0 5\nv 500 0 5\nv 500 300 5\nv 200 300 5\nf 1 2 3\nf 1 3 4\n';
  await page.setInputFiles('#scan-input', { name: 'big-plate.obj', mimeType: 'text/plain', buffer: Buffer.from(plate) });
  await page.waitForFunction(() => window.pcpp.state.info && window.pcpp.state.info.name === 'big-plate.obj',
    null, { timeout: 120_000 });
  await waitIdle(page);
  assert.equal(await page.isHidden('#error-panel'), false);
  // (The scan's, not the tool path's: QA round 8 F5.)
  assert.equal(await page.textContent('#error-title'), 'The scan lies outside the printer\'s build volume: no G-code');
  assert.match(await page.textContent('#error-message'), /larger than the volume/);
  assert.equal(await page.evaluate(() => document.getElementById('error-panel').classList.contains('notice')), false);
  assert.deepEqual(problems, []);
  await context.close();
});

// A plate lying on its side in the file (100 x 0.5 mm seen from above,
// 100 mm tall): whatever the refusal, the scan's up axis is said, and the
// demo drawing's notice is not shown for it (QA round 5 N4).
test('a scan seen edge-on from above is told to choose its up axis, not to open a drawing', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitSettled(page);
  const v = [];
  for (const z of [0, 100]) for (const [x, y] of [[0, 0], [100, 0], [100, 0.5], [0, 0.5]]) v.push(`v ${x} ${y} ${z}`);
  const f = [[1, 3, 2], [1, 4, 3], [5, 6, 7], [5, 7, 8], [1, 2, 6], [1, 6, 5], [2, 3, 7], [2, 7, 6], [3, 4, 8], [3, 8, 7],
    [4, 1, 5], [4, 5, 8]].map((t) => `f ${t.join(' ')}`);
  await page.setInputFiles('#scan-input', { name: 'edge-on.obj', mimeType: 'text/plain', buffer: Buffer.from(`${v.join('\n')}\n${f.join('\n')}\n`) });
  await page.waitForFunction(() => window.pcpp.state.info && window.pcpp.state.info.name === 'edge-on.obj',
    null, { timeout: 120_000 });
  await waitIdle(page);
  // The demo drawing is not fitted to the plate's top edge (QA round 20
  // F6: a drawing scaled to fit a footprint of no width): refused, saying
  // the scan is seen edge-on and which control turns it, not the demo
  // drawing's notice.
  await page.waitForFunction(() => !document.getElementById('error-panel').hidden, null, { timeout: 120_000 });
  assert.match(await page.textContent('#error-message'), /the scan is seen edge-on from above, 100\.000 x 0\.500 mm wide and 100\.000 mm tall .*choose its up axis \(Up axis; glTF files are \+Y up\)/);
  assert.doesNotMatch(await page.textContent('#error-title'), /demo drawing/);
  assert.equal(await page.evaluate(() => document.getElementById('error-panel').classList.contains('notice')), false);
  // At the user's own scale (a line across the edge's middle): refused
  // the same way.
  await page.fill('#pl-scale', '1');
  await page.press('#pl-scale', 'Enter');
  await page.waitForFunction(() => !document.getElementById('error-panel').hidden, null, { timeout: 120_000 });
  await waitIdle(page);
  assert.doesNotMatch(await page.textContent('#error-title'), /demo drawing/);
  assert.equal(await page.evaluate(() => document.getElementById('error-panel').classList.contains('notice')), false);
  assert.match(await page.textContent('#error-message'), /edge-on[^]*up axis/);
  assert.deepEqual(problems, []);
  await context.close();
});
