// A scan and an SVG uploaded through the page's file inputs plan, and the
// G-code and report the page offers equal, byte for byte, what the CLI
// writes for the same files and settings.
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { createHash } from 'node:crypto';
import { existsSync, mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { after, before, test } from 'node:test';
import { ROOT, download, launch, openPage, startServer, viewPixels, waitForPlan, waitIdle } from './helpers.mjs';

const CLI = join(ROOT, 'target/debug/pcpp');

let server;
let chrome;
let dir;
before(async () => {
  server = await startServer();
  chrome = await launch();
  dir = mkdtempSync(join(tmpdir(), 'pcpp-browser-'));
});
after(async () => {
  await chrome?.close();
  server?.stop();
  if (dir) rmSync(dir, { recursive: true, force: true });
});

// A 4 x 4 cm sheet in centimetres with a smooth ridge and a bump.
function bumpyObj() {
  const n = 41;
  const lines = ['# test sheet, cm'];
  for (let j = 0; j < n; j++) {
    for (let i = 0; i < n; i++) {
      const x = i * 0.1;
      const y = j * 0.1;
      const z = 0.15 * Math.exp(-((x - 2) ** 2) / 0.3) + 0.1 * Math.exp(-((x - 1.2) ** 2 + (y - 2.8) ** 2) / 0.1);
      lines.push(`v ${x.toFixed(4)} ${y.toFixed(4)} ${z.toFixed(5)}`);
    }
  }
  for (let j = 0; j < n - 1; j++) {
    for (let i = 0; i < n - 1; i++) {
      const a = j * n + i + 1;
      lines.push(`f ${a} ${a + 1} ${a + n + 1}`, `f ${a} ${a + n + 1} ${a + n}`);
    }
  }
  return `${lines.join('\n')}\n`;
}

const TRACK_SVG = `<svg xmlns="http://www.w3.org/2000/svg" width="20mm" height="20mm" viewBox="0 0 20 20">
  <path id="meander" d="M 1 2 L 19 2 L 19 6 L 1 6 L 1 10 L 19 10" fill="none" stroke="black"/>
  <circle id="ring" cx="10" cy="15" r="3.5" fill="none" stroke="black"/>
</svg>
`;

async function select(page, id, value) {
  await page.selectOption(`#${id}`, value);
}

test('an uploaded OBJ and SVG plan, and the downloads equal the CLI output', async (t) => {
  const scanPath = join(dir, 'bumpy-sheet.obj');
  const svgPath = join(dir, 'track.svg');
  writeFileSync(scanPath, bumpyObj());
  writeFileSync(svgPath, TRACK_SVG);

  const { page, context, problems } = await openPage(chrome.browser, server.url);
  await waitForPlan(page);
  await page.setInputFiles('#scan-input', scanPath);
  await page.setInputFiles('#svg-input', svgPath);
  await select(page, 'scan-units', 'cm');
  await select(page, 'planner', 'pcpp');
  await select(page, 'dialect', 'grbl');
  await select(page, 'gauge', '2'); // 25 G: 0.26 / 0.515 mm
  await page.fill('#pr-tol', '0.05');
  await page.fill('#pr-speed', '4');
  await page.fill('#pr-dwell', '0.2');
  await page.fill('#pl-x', '10');
  await page.fill('#pl-y', '32');
  await page.fill('#pl-rot', '15');
  await page.fill('#pl-scale', '1.1');
  await page.dispatchEvent('#pr-dwell', 'change');
  await waitIdle(page);
  await waitForPlan(page);
  assert.equal(await page.textContent('#scan-name'), 'bumpy-sheet.obj');
  assert.equal(await page.textContent('#svg-name'), 'track.svg');
  assert.equal(await page.isHidden('#error-panel'), true, await page.textContent('#error-message'));

  const px = await viewPixels(page);
  assert.ok(px.mesh > px.total * 0.03, JSON.stringify(px));
  assert.ok(px.good + px.defect > 100, JSON.stringify(px));

  const gcode = await download(page, 'dl-gcode');
  const report = await download(page, 'dl-report');
  assert.equal(gcode.name, 'track-pcpp.gcode');
  assert.equal(report.name, 'track-pcpp.json');
  const json = JSON.parse(report.bytes.toString('utf8'));
  assert.equal(json.inputs[0].name, 'bumpy-sheet.obj');
  assert.deepEqual(json.settings.placement, { offset_mm: [10, 32], rotation_deg: 15, scale: 1.1 });
  // The scan's SHA-256 was found by the page's second worker, beside the
  // import, and is the one the G-code and the report name.
  const sha = createHash('sha256').update(readFileSync(scanPath)).digest('hex');
  const beside = await page.evaluate(() => {
    const s = window.pcpp.state;
    return Array.from(s.digests.get(s.scan.key) || [], (b) => b.toString(16).padStart(2, '0')).join('');
  });
  assert.equal(beside, sha);
  assert.equal(json.inputs[0].sha256, sha);
  assert.match(gcode.bytes.toString('utf8'), new RegExp(`sha256 ${sha}`));
  await context.close();
  assert.deepEqual(problems, []);

  if (!existsSync(CLI)) {
    t.skip(`${CLI} not built (cargo build --bin pcpp)`);
    return;
  }
  const out = join(dir, 'cli.gcode');
  const rep = join(dir, 'cli.json');
  execFileSync(CLI, ['plan', '--scan', scanPath, '--path', svgPath, '-o', out, '--report', rep,
    '--planner', 'pcpp', '--dialect', 'grbl', '--place', '10,32,15,1.1', '--nozzle-id', '0.26',
    '--nozzle-od', '0.515', '--tol', '0.05', '--speed', '4', '--dwell', '0.2', '--scan-units', 'cm'],
  { stdio: ['ignore', 'ignore', 'pipe'] });
  const cliGcode = readFileSync(out);
  assert.ok(cliGcode.equals(gcode.bytes), 'the page G-code differs from the CLI G-code');
  // The report is the same serde_json text, but a few full-precision
  // numbers come from powf/atan2, whose last bit differs between wasm32's
  // libm and glibc (amplified to ~1e-10 in curvature): compare numbers to
  // 1e-9 (relative above 1), all else exactly.
  const diffs = [];
  compareJson(JSON.parse(readFileSync(rep, 'utf8')), json, '$', diffs);
  assert.deepEqual(diffs, []);
});

function compareJson(a, b, path, out) {
  if (typeof a === 'number' && typeof b === 'number') {
    if (Math.abs(a - b) > 1e-9 * Math.max(1, Math.abs(a), Math.abs(b))) out.push(`${path}: ${a} vs ${b}`);
  } else if (Array.isArray(a) && Array.isArray(b) && a.length === b.length) {
    a.forEach((v, i) => compareJson(v, b[i], `${path}[${i}]`, out));
  } else if (a && b && typeof a === 'object' && typeof b === 'object' && !Array.isArray(a) && !Array.isArray(b)) {
    const keys = Object.keys(a);
    if (keys.join() !== Object.keys(b).join()) out.push(`${path}: keys ${keys} vs ${Object.keys(b)}`);
    else keys.forEach((k) => compareJson(a[k], b[k], `${path}.${k}`, out));
  } else if (a !== b) {
    out.push(`${path}: ${JSON.stringify(a)} vs ${JSON.stringify(b)}`);
  }
}

test('a built-in antenna plans on an uploaded scan, centred on it', async () => {
  const scanPath = join(dir, 'sheet2.obj');
  writeFileSync(scanPath, bumpyObj());
  const { page, context, problems } = await openPage(chrome.browser, server.url);
  await waitForPlan(page);
  await select(page, 'scan-units', 'cm');
  await page.setInputFiles('#scan-input', scanPath);
  await waitIdle(page);
  await select(page, 'path-source', 'hilbert');
  await page.fill('#hb-order', '3');
  await page.fill('#hb-size', '16');
  await page.dispatchEvent('#hb-size', 'change');
  await waitIdle(page);
  await waitForPlan(page);
  // Centred on the 40 x 40 mm sheet.
  const x = Number(await page.inputValue('#pl-x'));
  const y = Number(await page.inputValue('#pl-y'));
  const json = JSON.parse(await page.evaluate(() => window.pcpp.state.lastPlan.report()));
  const xs = json.toolpath.flat().map((p) => p[0]);
  const ys = json.toolpath.flat().map((p) => p[1]);
  const mid = (v) => (Math.min(...v) + Math.max(...v)) / 2;
  assert.ok(Math.abs(mid(xs) - 20) < 1 && Math.abs(mid(ys) - 20) < 1, `centre ${mid(xs)}, ${mid(ys)} (offset ${x}, ${y})`);
  assert.equal(json.inputs[1].name, 'antenna-hilbert.svg');
  const merged = async () => (await page.$$eval('#warnings li', (lis) => lis.map((li) => li.textContent)))
    .filter((w) => w.includes('their filaments will merge'));
  assert.deepEqual(await merged(), []);
  // Order 7 at 16 mm: lines 0.13 mm apart, a fifth of the filament's
  // width, were planned into one band without a word.
  await page.fill('#hb-order', '7');
  await page.dispatchEvent('#hb-order', 'change');
  await waitIdle(page);
  await waitForPlan(page);
  const warned = await merged();
  assert.equal(warned.length, 1, JSON.stringify(warned));
  assert.match(warned[0], /^lines of the drawing come within 0\.12\d mm of each other/);
  assert.deepEqual(problems, []);
  await context.close();
});

// QA round 12 L2: a scan that could not be read leaves the demo part's, and
// the drawing opened next was planned on the demo part with its download
// named after the drawing alone: the file and the button now say which
// part it is for.
test('a drawing planned on the demo part after a scan failed to read says so in its download', async () => {
  const cutPath = join(dir, 'cut-short.stl');
  const svgPath = join(dir, 'track.svg');
  writeFileSync(cutPath, 'solid part\n  facet normal 0 0 1\n    outer loop\n      vertex 0 0 0\n');
  writeFileSync(svgPath, TRACK_SVG);
  const { page, context, problems } = await openPage(chrome.browser, server.url);
  await waitForPlan(page);
  await page.setInputFiles('#scan-input', cutPath);
  await page.waitForSelector('#error-panel:not([hidden])');
  assert.match(await page.textContent('#error-message'), /cut-short\.stl/);
  await page.setInputFiles('#svg-input', svgPath);
  await page.waitForFunction(() => document.querySelector('#svg-name').textContent === 'track.svg');
  await waitIdle(page);
  await waitForPlan(page);
  const gcode = await download(page, 'dl-gcode');
  assert.equal(gcode.name, 'track-on-the-demo-part-even.gcode');
  assert.equal(await page.textContent('#dl-gcode'), 'Download G-code (for the demo part)');
  assert.match(gcode.bytes.toString('utf8'), /demo-test-part\.ply/);
  const report = await download(page, 'dl-report');
  assert.equal(report.name, 'track-on-the-demo-part-even.json');
  assert.deepEqual(problems, []);
  await context.close();
});

// The risky download's button named its risk but not the demo part (left
// from QA round 12 L2): a drawing mostly beside the demo part, written
// because the risk was accepted, says both, before and after the first
// click, and its file is named for the demo part.
test('a drawing written at the user\'s risk on the demo part says so on its button', async () => {
  const widePath = join(dir, 'wide.svg');
  writeFileSync(widePath, `<svg xmlns="http://www.w3.org/2000/svg" width="400mm" height="10mm" viewBox="0 0 400 10">
  <path d="M 1 5 L 399 5" fill="none" stroke="black"/>
</svg>
`);
  const { page, context, problems } = await openPage(chrome.browser, server.url);
  await waitForPlan(page);
  await page.setInputFiles('#svg-input', widePath);
  await page.waitForFunction(() => document.querySelector('#svg-name').textContent === 'wide.svg');
  await waitIdle(page);
  await waitForPlan(page);
  // The page fits it to the part; at full size it lies mostly beside it.
  await page.fill('#pl-scale', '1');
  await page.press('#pl-scale', 'Enter');
  await page.waitForSelector('#error-panel:not([hidden])');
  assert.match(await page.textContent('#error-message'), /lie over the scan/);
  await page.check('#accept-risk');
  await waitIdle(page);
  await waitForPlan(page);
  assert.equal(await page.textContent('#dl-gcode'), 'Download G-code (for the demo part; at your risk)…');
  await page.click('#dl-gcode');
  assert.equal(await page.textContent('#dl-gcode'), 'Download anyway (for the demo part; at your risk)');
  const gcode = await download(page, 'dl-gcode');
  assert.equal(gcode.name, 'wide-on-the-demo-part-even.gcode');
  assert.deepEqual(problems, []);
  await context.close();
});
