// QA round 19 F5: a drag in "Move path" mode keeps the drawing under the
// pointer when the layout above the 3-D view changes during the drag. The
// plan status line grew ("... 6 path(s) of the drawing leave the scan ...")
// and wrapped, the view moved 49 px down, and the same client position then
// meant another canvas pixel: the drawing jumped 15 mm in one 5 px step,
// then hundreds of mm. Now the status line's height is reserved (the view
// stays put whatever it says), and a drag is computed from the pointer's
// movement over the canvas as it lay at the press, so no layout change
// (an error or a warning appearing above the view) makes the drawing jump.
import assert from 'node:assert/strict';
import { test } from 'node:test';
import { openPage, waitSettled, withPageServer } from './helpers.mjs';

const env = withPageServer();

// The tester's long status, three times over: it wraps in any layout.
const LONG = ' (planned with even: 6 path(s) of the drawing leave the scan and are not printed there, '
  + 'listed under Path statistics)';

const viewTop = (page) => page.evaluate(() => document.getElementById('view').getBoundingClientRect().top);
const placement = (page) => page.evaluate(() => {
  const p = window.pcpp.settings.placement;
  return [Number(p.x), Number(p.y)];
});

// From now on, every text the page puts in the status line gets LONG x3
// appended at once (a mutation observer runs before the next event is
// dispatched): the status is long whatever plan finishes in between.
async function forceLongStatus(page) {
  await page.evaluate((long) => {
    const el = document.getElementById('plan-status');
    const tail = long.repeat(3);
    const grow = () => { if (!el.textContent.endsWith(tail)) el.textContent += tail; };
    window.__longStatus = new MutationObserver(grow);
    window.__longStatus.observe(el, { childList: true, characterData: true, subtree: true });
    grow();
  }, LONG);
}

async function stopLongStatus(page) {
  await page.evaluate(() => { window.__longStatus?.disconnect(); });
}

// Drags right in 5 px steps from (x0, y0), running `during(i)` before step
// i; returns the placement before the press and after each step, and the
// view's top at each step.
async function dragSteps(page, x0, y0, steps, during = async () => {}) {
  const trace = [await placement(page)];
  const tops = [await viewTop(page)];
  await page.mouse.move(x0, y0);
  await page.mouse.down();
  for (let i = 1; i <= steps; i++) {
    await during(i);
    await page.mouse.move(x0 + i * 5, y0);
    await page.waitForTimeout(30);
    trace.push(await placement(page));
    tops.push(await viewTop(page));
  }
  await page.mouse.up();
  return { trace, tops };
}

// Each step's movement of the placement, mm.
const stepLengths = (trace) => trace.slice(1).map(([x, y], i) => Math.hypot(x - trace[i][0], y - trace[i][1]));

// No step moves the drawing more than 3 times the largest step before it
// (and more than 3 mm: a 5 px step moves it about 1 mm in the demo's view),
// and the whole drag moved it about as far as the first steps predict.
function assertFollows(trace, what) {
  const steps = stepLengths(trace);
  const shown = JSON.stringify(trace);
  assert.ok(steps[0] > 0.05, `${what}: the first step moved the drawing: ${shown}`);
  for (let i = 1; i < steps.length; i++) {
    const before = Math.max(...steps.slice(0, i));
    assert.ok(steps[i] <= 3 * before && steps[i] < 3,
      `${what}: step ${i + 1} moved the drawing ${steps[i].toFixed(2)} mm after steps of at most ${before.toFixed(2)} mm: ${shown}`);
  }
  const total = Math.hypot(trace.at(-1)[0] - trace[0][0], trace.at(-1)[1] - trace[0][1]);
  const perStep = (steps[0] + steps[1] + steps[2]) / 3;
  const n = steps.length;
  assert.ok(total > 0.5 * perStep * n && total < 1.5 * perStep * n,
    `${what}: ${n} steps of about ${perStep.toFixed(2)} mm moved the drawing ${total.toFixed(2)} mm: ${shown}`);
}

test('the status line growing during a drag moves neither the view nor the drawing (QA round 19 F5)', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitSettled(page);
  await page.click('#move-btn');
  assert.equal(await page.getAttribute('#move-btn', 'aria-pressed'), 'true');
  const box = await page.locator('#view').boundingBox();
  // The tester's steps: press on the part a little right of and below the
  // view's middle, move right in 5 px steps; after 6 steps the status
  // becomes long (as the even planner's was at that placement).
  const x0 = Math.round(box.x + box.width / 2 + 30);
  const y0 = Math.round(box.y + box.height / 2 + 40);
  const { trace, tops } = await dragSteps(page, x0, y0, 14, async (i) => {
    if (i === 7) await forceLongStatus(page);
  });
  const statusHeight = await page.evaluate(() => document.getElementById('plan-status').getBoundingClientRect().height);
  await stopLongStatus(page);
  assert.ok(statusHeight > 0, 'the status line is shown');
  assertFollows(trace, 'long status');
  assert.deepEqual(tops, Array(tops.length).fill(tops[0]), `the view moved during the drag: tops ${tops}`);
  await waitSettled(page);
  assert.deepEqual(problems, []);
  await context.close();
});

test('the view keeps its place whatever the status line says', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitSettled(page);
  const top = await viewTop(page);
  const texts = ['', 'planning…', `planned demo-test-part-lines.svg on demo-test-part.ply${LONG}`,
    `planned demo-test-part-lines.svg on demo-test-part.ply${LONG.repeat(6)}`, 'cancelled'];
  for (const text of texts) {
    const got = await page.evaluate((t) => {
      document.getElementById('plan-status').textContent = t;
      return document.getElementById('view').getBoundingClientRect().top;
    }, text);
    assert.equal(got, top, `the view moved with a status of ${text.length} characters`);
  }
  // Narrower (the side panel's column stays 320 px): still no move.
  await page.setViewportSize({ width: 1000, height: 900 });
  const narrowTop = await viewTop(page);
  for (const text of texts) {
    const got = await page.evaluate((t) => {
      document.getElementById('plan-status').textContent = t;
      return document.getElementById('view').getBoundingClientRect().top;
    }, text);
    assert.equal(got, narrowTop, `at 1000 px wide, the view moved with a status of ${text.length} characters`);
  }
  assert.deepEqual(problems, []);
  await context.close();
});

test('a layout change above the view during a drag does not make the drawing jump', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitSettled(page);
  await page.click('#move-btn');
  const box = await page.locator('#view').boundingBox();
  const x0 = Math.round(box.x + box.width / 2);
  const y0 = Math.round(box.y + box.height / 2);
  // Halfway, a 60 px block appears above the view (as the risk warning or
  // the error panel can while a drag re-plans): the view moves down under
  // the pointer, the drawing must not.
  const { trace, tops } = await dragSteps(page, x0, y0, 12, async (i) => {
    if (i === 7) {
      await page.evaluate(() => {
        const block = document.createElement('div');
        block.id = 'qa19-block';
        block.style.height = '60px';
        document.querySelector('.view-wrap').before(block);
      });
    }
  });
  assert.ok(tops.at(-1) > tops[0] + 40, `the test moved the view: tops ${tops}`);
  assertFollows(trace, 'view moved down');
  await page.evaluate(() => document.getElementById('qa19-block').remove());
  await waitSettled(page);
  assert.deepEqual(problems, []);
  await context.close();
});
