// A machine profile that passes validation but cannot write this job's
// G-code (its end block homes, or drives the nozzle into the part; its
// travel clearance leaves the build volume) is not taken, as a profile that
// fails validation is not: the error names the file and the field, and the
// profile used before it (the user's or a built-in) stays, with its plan
// and G-code. QA: it replaced the user's working profile, which had to be
// found and opened again.
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { join } from 'node:path';
import { test } from 'node:test';
import { ROOT, download, openPage, waitForPlan, waitIdle, waitSettled, withPageServer } from './helpers.mjs';

const env = withPageServer();

const marlin = () => JSON.parse(readFileSync(join(ROOT, 'src/gcode/profiles/marlin.json'), 'utf8'));

// A profile made from Marlin's: `name` and what `change` sets.
function profileText(name, change) {
  const p = marlin();
  p.name = name;
  change(p);
  return JSON.stringify(p);
}

const labBench = () => profileText('lab-bench', (p) => { p.start = ['G21', 'G90', 'M107', 'M117 lab bench ready']; });
const labTwo = () => profileText('lab-two', (p) => { p.start = ['G21', 'G90', 'M107', 'M117 lab two ready']; });

// Valid profiles whose G-code cannot be written for the demo job: the file,
// its text, and what the error must say of its field.
const BAD = [
  ['end_G28.json', profileText('end-g28', (p) => { p.end = ['M107', 'G28']; }), /end_G28\.json, field `end\[1\]`/],
  ['end_Z0.json', profileText('end-z0', (p) => { p.end = ['M107', 'G1 Z0', 'M84']; }), /end_Z0\.json, field `end`/],
  ['clearance.json', profileText('far-clearance', (p) => { p.safe_travel_clearance_mm = 1e6; }),
    /safe_travel_clearance_mm` \(1000000 mm in clearance\.json\)/],
];

async function openProfile(page, name, text) {
  await page.setInputFiles('#profile-input', { name, mimeType: 'application/json', buffer: Buffer.from(text) });
}

const dialectText = (page) => page.$eval('#dialect', (s) => s.selectedOptions[0].textContent);
const customOption = (page) => page.$eval('#dialect', (s) => {
  const o = s.querySelector('option[value="custom"]');
  return o ? o.textContent : null;
});

// The plan on screen is current and its G-code offered (without a new plan
// clearing the error).
async function waitOffered(page) {
  await waitIdle(page);
  await page.waitForFunction(() => {
    const s = window.pcpp.state;
    return !s.busy && !s.queued && s.lastPlan && s.lastPlan.gen === s.gen && !document.getElementById('dl-gcode').hidden;
  }, null, { timeout: 120_000 });
}

// A profile (`name`, `text`) is opened, and refused: the error names it and
// `field`, and says the profile `label` is still used; the dialect is still
// `value`, shown as `label`, and the G-code offered is `gcode` again.
async function expectRefused(page, [name, text, field], value, label, gcode) {
  await openProfile(page, name, text);
  // The plan with it failed: its error names the file.
  await page.waitForFunction((n) => !document.getElementById('error-panel').hidden
    && document.getElementById('error-panel').textContent.includes(n)
    && !window.pcpp.state.busy && !window.pcpp.state.queued, name, { timeout: 120_000 });
  assert.equal(await page.inputValue('#dialect'), value);
  assert.equal(await dialectText(page), label);
  const title = `Could not use the machine profile ${name}`;
  assert.equal(await page.textContent('#error-title'), title);
  const message = await page.textContent('#error-message');
  assert.match(message, field);
  assert.match(message, new RegExp(`Still using ${label.replace(/[()]/g, '\\$&')}\\.`));
  await waitOffered(page);
  // The error stays on screen beside the plan kept.
  assert.equal(await page.isHidden('#error-panel'), false);
  assert.equal(await page.textContent('#error-title'), title);
  assert.doesNotMatch(await page.textContent('#plan-status'), /failed|re-planning/);
  assert.equal((await download(page, 'dl-gcode')).bytes.toString('utf8'), gcode);
}

test('a profile that cannot write the G-code is not taken: the custom profile before it stays', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitSettled(page);
  await openProfile(page, 'lab-bench.json', labBench());
  await page.waitForFunction(() => document.getElementById('dialect').value === 'custom');
  await waitSettled(page);
  assert.equal(await page.isHidden('#error-panel'), true);
  const label = 'custom: lab-bench (lab-bench.json)';
  assert.equal(await dialectText(page), label);
  const gcode = (await download(page, 'dl-gcode')).bytes.toString('utf8');
  assert.match(gcode, /^M117 lab bench ready$/m);

  for (const bad of BAD) await expectRefused(page, bad, 'custom', label, gcode);

  // The profile kept is the one the next visit uses.
  await page.reload();
  await waitForPlan(page);
  assert.equal(await page.inputValue('#dialect'), 'custom');
  assert.equal(await dialectText(page), label);
  assert.equal((await download(page, 'dl-gcode')).bytes.toString('utf8'), gcode);
  assert.deepEqual(problems, []);
  await context.close();
});

test('a good second profile replaces the first; a bad third one leaves the second', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitSettled(page);
  await openProfile(page, 'lab-bench.json', labBench());
  await page.waitForFunction(() => document.getElementById('dialect').value === 'custom');
  await waitSettled(page);
  await openProfile(page, 'lab-two.json', labTwo());
  await page.waitForFunction(() => /lab-two/.test(document.getElementById('dialect').selectedOptions[0].textContent));
  await waitSettled(page);
  assert.equal(await page.isHidden('#error-panel'), true);
  const label = 'custom: lab-two (lab-two.json)';
  assert.equal(await dialectText(page), label);
  const gcode = (await download(page, 'dl-gcode')).bytes.toString('utf8');
  assert.match(gcode, /^M117 lab two ready$/m);
  assert.doesNotMatch(gcode, /lab bench/);

  await expectRefused(page, BAD[0], 'custom', label, gcode);
  await page.reload();
  await waitForPlan(page);
  assert.equal(await dialectText(page), label);
  assert.deepEqual(problems, []);
  await context.close();
});

test('a built-in dialect in use stays selected when a profile cannot write the G-code', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitSettled(page);
  await page.selectOption('#dialect', 'grbl');
  await waitSettled(page);
  const grbl = (await download(page, 'dl-gcode')).bytes.toString('utf8');
  await expectRefused(page, BAD[1], 'grbl', 'grbl', grbl);
  // No profile of the user's joined the list.
  assert.equal(await customOption(page), null);

  // With a profile of the user's loaded but a built-in one in use, both stay.
  await openProfile(page, 'lab-bench.json', labBench());
  await page.waitForFunction(() => document.getElementById('dialect').value === 'custom');
  await waitSettled(page);
  await page.selectOption('#dialect', 'marlin');
  await waitSettled(page);
  const marlinCode = (await download(page, 'dl-gcode')).bytes.toString('utf8');
  await expectRefused(page, BAD[0], 'marlin', 'marlin', marlinCode);
  assert.equal(await customOption(page), 'custom: lab-bench (lab-bench.json)');
  await page.reload();
  await waitForPlan(page);
  assert.equal(await page.inputValue('#dialect'), 'marlin');
  assert.equal(await customOption(page), 'custom: lab-bench (lab-bench.json)');
  assert.deepEqual(problems, []);
  await context.close();
});

test('a plan that fails for something else keeps a newly opened good profile', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitSettled(page);
  // The drawing is moved off the scan: the plan fails for that.
  await page.fill('#pl-x', '150');
  await page.waitForFunction(() => /misses the scan/.test(document.getElementById('error-message').textContent),
    null, { timeout: 120_000 });
  await waitIdle(page);
  await openProfile(page, 'lab-bench.json', labBench());
  await page.waitForFunction(() => document.getElementById('dialect').value === 'custom');
  await page.waitForFunction(() => /misses the scan/.test(document.getElementById('error-message').textContent)
    && !window.pcpp.state.busy && !window.pcpp.state.queued, null, { timeout: 120_000 });
  await waitIdle(page);
  const label = 'custom: lab-bench (lab-bench.json)';
  assert.equal(await page.inputValue('#dialect'), 'custom');
  assert.equal(await dialectText(page), label);
  // Kept over a reload, and written with once the drawing is on the scan.
  await page.reload();
  await page.waitForFunction(() => window.pcpp && window.pcpp.state && window.pcpp.state.info);
  await waitIdle(page);
  assert.equal(await dialectText(page), label);
  await page.fill('#pl-x', '0');
  await waitSettled(page);
  assert.match((await download(page, 'dl-gcode')).bytes.toString('utf8'), /^M117 lab bench ready$/m);
  assert.deepEqual(problems, []);
  await context.close();
});

test('a setting changed with the profile: planned again with the profile kept, its error stays', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitSettled(page);
  await openProfile(page, 'lab-bench.json', labBench());
  await page.waitForFunction(() => document.getElementById('dialect').value === 'custom');
  await waitSettled(page);
  // The drawing moved and, before it is planned, the profile dropped on
  // the page: one plan, of both.
  await page.evaluate(([name, text]) => {
    const x = document.getElementById('pl-x');
    x.value = '2.5';
    x.dispatchEvent(new Event('input', { bubbles: true }));
    const dt = new DataTransfer();
    dt.items.add(new File([text], name, { type: 'application/json' }));
    window.dispatchEvent(new DragEvent('drop', { dataTransfer: dt, cancelable: true }));
  }, [BAD[0][0], BAD[0][1]]);
  await page.waitForFunction(() => /end_G28\.json/.test(document.getElementById('error-message').textContent),
    null, { timeout: 120_000 });
  await waitOffered(page);
  assert.equal(await dialectText(page), 'custom: lab-bench (lab-bench.json)');
  assert.equal(await page.isHidden('#error-panel'), false);
  assert.equal(await page.textContent('#error-title'), 'Could not use the machine profile end_G28.json');
  const gcode = (await download(page, 'dl-gcode')).bytes.toString('utf8');
  assert.match(gcode, /^M117 lab bench ready$/m);
  assert.match(gcode, /placement: offset \(2\.5, 80\) mm/);
  assert.deepEqual(problems, []);
  await context.close();
});

// On another bed the scan placed on the bed is read again there, and the
// plan on screen goes with it: the profile before it plans it again.
test('a scan placed on the bed: a profile with another bed that cannot write the G-code is not taken', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitSettled(page);
  await page.evaluate(() => document.getElementById('place-bed-btn').click());
  await page.waitForFunction(() => window.pcpp.settings.scanPlace.on);
  await waitSettled(page);
  const placement = await page.evaluate(() => JSON.stringify(window.pcpp.settings.placement));
  const gcode = (await download(page, 'dl-gcode')).bytes.toString('utf8');
  const bigVolume = (p) => { p.build_volume = { min_mm: [0, 0, 0], max_mm: [300, 300, 250] }; };
  const homing = ['big_G28.json', profileText('big-g28', (p) => { bigVolume(p); p.end = ['M107', 'G28']; }),
    /big_G28\.json, field `end\[1\]`/];
  await expectRefused(page, homing, 'marlin', 'marlin', gcode);
  // A printer smaller than the scan.
  const small = ['small.json', profileText('small', (p) => { p.build_volume = { min_mm: [0, 0, 0], max_mm: [50, 50, 50] }; }),
    /build volume of profile small/];
  await expectRefused(page, small, 'marlin', 'marlin', gcode);
  assert.equal(await page.evaluate(() => JSON.stringify(window.pcpp.settings.placement)), placement);
  assert.deepEqual(problems, []);
  await context.close();
});
