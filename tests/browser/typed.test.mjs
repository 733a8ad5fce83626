// A number the user types in the drawing's placement is the number shown,
// kept and planned, whatever the page does meanwhile; a number the page
// computes (the drawing centred on the scan) is shown rounded. One CI run
// of the kept-settings test (errors.test.mjs) read Offset X, typed as 20,
// as '19.9999994436899820': the page centred the new drawing at
// 19.99999944368998 mm (the SVG's mm scale is f32 in usvg) and wrote it
// into the field Playwright had just selected to type in, so the typed
// '20' was added after it.
import assert from 'node:assert/strict';
import { test } from 'node:test';
import {
  download, openPage, waitKept, waitSettled, withPageServer,
} from './helpers.mjs';

const env = withPageServer();

// A 40 x 40 mm drawing whose box centre is (20, 23) mm from its top-left
// corner: on the demo part (80 x 80 mm, centred at 40, 40) it is centred at
// offset (20, 63).
const TRACK_SVG = `<svg xmlns="http://www.w3.org/2000/svg" width="40mm" height="40mm" viewBox="0 0 40 40">
  <path d="M 4 20 L 36 20 L 36 26 L 4 26" fill="none" stroke="black"/>
</svg>
`;
const track = (name = 'track.svg') => ({ name, mimeType: 'image/svg+xml', buffer: Buffer.from(TRACK_SVG) });

const placement = (page) => page.evaluate(() => ({ ...window.pcpp.settings.placement }));
const offsetLine = async (page) => (await download(page, 'dl-gcode')).bytes.toString('utf8')
  .split('\n').find((l) => l.includes('placement: offset'));

// "Centre on scan" pressed while the caret stays in Offset X, as when a
// centring lands while the user is about to type there.
async function centreWhileIn(page, id) {
  await page.evaluate((i) => {
    const el = document.getElementById(i);
    el.focus();
    el.select();
    document.getElementById('center-btn').click(); // a click from script keeps the focus
  }, id);
  await page.waitForFunction(() => window.pcpp.state.centre === null);
  await waitSettled(page);
}

test('a new drawing is centred on round numbers: 20 mm, not 19.99999944', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitSettled(page);
  await page.setInputFiles('#svg-input', track());
  await page.waitForFunction(() => window.pcpp.state.svgFile && window.pcpp.state.svgFile.name === 'track.svg');
  await waitSettled(page);
  assert.deepEqual(await placement(page), { x: 20, y: 63, rot: 0, scale: 1 });
  assert.equal(await page.inputValue('#pl-x'), '20');
  assert.equal(await page.inputValue('#pl-y'), '63');
  assert.match(await offsetLine(page), /placement: offset \(20, 63\) mm/);
  assert.deepEqual(problems, []);
  await context.close();
});

test('a number typed in Offset X while the page centres the drawing is the number kept: it read \'19.9999994436899820\'', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitSettled(page);
  await page.setInputFiles('#svg-input', track());
  await page.waitForFunction(() => window.pcpp.state.svgFile && window.pcpp.state.svgFile.name === 'track.svg');
  await waitSettled(page);
  await page.fill('#pl-x', '5');
  await waitSettled(page);

  // The centring lands with the field's text selected: the field is left
  // as it is under the caret, and what the user types replaces it.
  await centreWhileIn(page, 'pl-x');
  assert.deepEqual(await placement(page), { x: 20, y: 63, rot: 0, scale: 1 });
  await page.keyboard.insertText('12.5');
  assert.equal(await page.inputValue('#pl-x'), '12.5');
  await waitSettled(page);
  assert.deepEqual(await placement(page), { x: 12.5, y: 63, rot: 0, scale: 1 });
  assert.match(await offsetLine(page), /placement: offset \(12\.5, 63\) mm/);

  // Not rewritten under the caret; left without typing, the field shows
  // the centring.
  await centreWhileIn(page, 'pl-x');
  assert.equal(await page.inputValue('#pl-x'), '12.5');
  await page.focus('#pl-y');
  assert.equal(await page.inputValue('#pl-x'), '20');
  assert.equal((await placement(page)).x, 20);

  // Typed again and reloaded: the text as typed.
  await page.fill('#pl-x', '12.5');
  await waitSettled(page);
  await waitKept(page);
  await page.reload();
  await waitSettled(page);
  assert.equal(await page.inputValue('#pl-x'), '12.5');
  assert.match(await offsetLine(page), /placement: offset \(12\.5, 63\) mm/);
  assert.deepEqual(problems, []);
  await context.close();
});

test('a number typed while a new drawing is still being read is kept, not centred over', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitSettled(page);
  // In one task: the drawing is chosen, then Offset X typed before the
  // browser has handed over the file's bytes.
  await page.evaluate((svg) => {
    const input = document.getElementById('svg-input');
    const dt = new DataTransfer();
    dt.items.add(new File([svg], 'track.svg', { type: 'image/svg+xml' }));
    input.files = dt.files;
    input.dispatchEvent(new Event('change', { bubbles: true }));
    const x = document.getElementById('pl-x');
    x.value = '12.5';
    x.dispatchEvent(new Event('input', { bubbles: true }));
  }, TRACK_SVG);
  await page.waitForFunction(() => window.pcpp.state.svgFile && window.pcpp.state.svgFile.name === 'track.svg');
  await waitSettled(page);
  assert.equal((await placement(page)).x, 12.5);
  assert.equal(await page.inputValue('#pl-x'), '12.5');
  assert.match(await offsetLine(page), /placement: offset \(12\.5, /);
  assert.deepEqual(problems, []);
  await context.close();
});
