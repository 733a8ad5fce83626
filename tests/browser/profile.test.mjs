// A user's machine profile loaded from a file joins the dialect list and
// writes the G-code; a bad one shows an error naming the file and the
// field and keeps the previous dialect.
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { join } from 'node:path';
import { test } from 'node:test';
import { ROOT, download, openPage, waitForPlan, waitIdle, withPageServer } from './helpers.mjs';

const env = withPageServer();

const marlin = () => JSON.parse(readFileSync(join(ROOT, 'src/gcode/profiles/marlin.json'), 'utf8'));
const file = (name, text) => ({ name, mimeType: 'application/json', buffer: Buffer.from(text) });

test('a custom machine profile changes the G-code; a bad one names its field', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitForPlan(page);
  const before = (await download(page, 'dl-gcode')).bytes.toString('utf8');
  assert.doesNotMatch(before, /M117 lab printer ready/);

  // Invalid: a field of the wrong type. The error names file and field; the
  // dialect stays marlin.
  const bad = marlin();
  bad.decimals = 'three';
  await page.setInputFiles('#profile-input', file('broken-profile.json', JSON.stringify(bad)));
  await page.waitForSelector('#error-panel:not([hidden])');
  const message = await page.textContent('#error-message');
  assert.equal(await page.textContent('#error-title'), 'Could not use the machine profile broken-profile.json');
  assert.match(message, /decimals/);
  assert.equal(await page.inputValue('#dialect'), 'marlin');
  await waitIdle(page);
  assert.equal(await page.isHidden('#dl-gcode'), false); // the plan still stands

  // Valid: its start block appears in the G-code.
  const good = marlin();
  good.name = 'lab-printer';
  good.start = ['G21', 'G90', 'M117 lab printer ready'];
  await page.setInputFiles('#profile-input', file('lab-printer.json', JSON.stringify(good)));
  await page.waitForFunction(() => document.getElementById('dialect').value === 'custom');
  assert.equal(await page.isHidden('#error-panel'), true);
  assert.match(await page.$eval('#dialect', (s) => s.selectedOptions[0].textContent), /lab-printer/);
  await page.waitForFunction((g) => {
    const s = window.pcpp.state;
    return !s.busy && !s.queued && s.lastPlan && s.lastPlan.gcode !== g
      && !document.getElementById('dl-gcode').hidden;
  }, before, { timeout: 120_000 });
  const after = (await download(page, 'dl-gcode')).bytes.toString('utf8');
  assert.match(after, /^M117 lab printer ready$/m);

  // The profile survives a reload and stays selected.
  await page.reload();
  await waitForPlan(page);
  assert.equal(await page.inputValue('#dialect'), 'custom');
  assert.match((await download(page, 'dl-gcode')).bytes.toString('utf8'), /M117 lab printer ready/);

  // Back to a built-in dialect.
  await page.selectOption('#dialect', 'grbl');
  await waitIdle(page);
  await waitForPlan(page);
  assert.doesNotMatch((await download(page, 'dl-gcode')).bytes.toString('utf8'), /M117 lab printer ready/);
  assert.deepEqual(problems, []);
  await context.close();
});

// A profile dropped on the page was taken for a scan ("Could not read the
// scan lab-printer.json ... not a scan this program reads"): a .json is a
// machine profile, dropped or opened with others.
test('a machine profile dropped on the page is used as the profile', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitForPlan(page);
  const good = marlin();
  good.name = 'dropped-printer';
  good.start = ['G21', 'G90', 'M117 dropped profile'];
  await page.evaluate(([name, text]) => {
    const dt = new DataTransfer();
    dt.items.add(new File([text], name, { type: 'application/json' }));
    window.dispatchEvent(new DragEvent('drop', { dataTransfer: dt, cancelable: true }));
  }, ['dropped-printer.json', JSON.stringify(good)]);
  await page.waitForFunction(() => document.getElementById('dialect').value === 'custom');
  await waitIdle(page);
  await waitForPlan(page);
  assert.equal(await page.isHidden('#error-panel'), true, await page.textContent('#error-message'));
  assert.equal(await page.textContent('#scan-name'), 'demo-test-part.ply');
  assert.match((await download(page, 'dl-gcode')).bytes.toString('utf8'), /^M117 dropped profile$/m);
  assert.deepEqual(problems, []);
  await context.close();
});

// The demo folder's other .json files (a plan report, a comparison, the
// registration) dropped on the page were read as machine profiles and
// refused for a missing field; each is named for what it is, and the
// dialect stays.
test('a report or registration dropped on the page is named, not read as a profile', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitForPlan(page);
  const cases = [
    ['demo-even-report.json', { program: 'pcpp', version: '0.1.0', planner: 'even' }, /a plan report that pcpp wrote/],
    ['demo-comparison.json', { program: 'pcpp', version: '0.1.0', planners: [] }, /a comparison that pcpp wrote/],
    ['demo-registration.json', { fiducials: 'auto', printer_points: [[4, 4, 5]], registration: {} },
      /the registration pcpp demo wrote/],
  ];
  for (const [name, value, expected] of cases) {
    await page.evaluate(([n, text]) => {
      const dt = new DataTransfer();
      dt.items.add(new File([text], n, { type: 'application/json' }));
      window.dispatchEvent(new DragEvent('drop', { dataTransfer: dt, cancelable: true }));
    }, [name, JSON.stringify(value)]);
    await page.waitForFunction((n) => document.getElementById('error-title').textContent.startsWith(n), name);
    assert.equal(await page.textContent('#error-title'), `${name} is not a machine profile`);
    assert.match(await page.textContent('#error-message'), expected);
    assert.equal(await page.inputValue('#dialect'), 'marlin');
  }
  assert.deepEqual(problems, []);
  await context.close();
});
