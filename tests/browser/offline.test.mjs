// The single-file build (dist/pcpp.html) works opened from file:// with no
// server: wasm inlined, the worker started from a Blob URL.
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { createHash } from 'node:crypto';
import { copyFileSync, existsSync, mkdtempSync, readFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { pathToFileURL } from 'node:url';
import { after, before, test } from 'node:test';
import { DIST, ROOT, download, launch, openPage, viewPixels, waitForPlan, waitIdle } from './helpers.mjs';

let chrome;
before(async () => {
  chrome = await launch();
});
after(async () => {
  await chrome?.close();
});

test('dist/pcpp.html plans the demo from file://', async () => {
  const file = join(DIST, 'pcpp.html');
  assert.ok(existsSync(file), 'run scripts/build-web.sh first');
  const { page, context, problems } = await openPage(chrome.browser, pathToFileURL(file).href);
  const requests = [];
  page.on('request', (r) => { if (!/^(data|blob|file):/.test(r.url())) requests.push(r.url()); });
  await waitForPlan(page);
  const px = await viewPixels(page);
  assert.ok(px.mesh > 1000 && px.good > 100, JSON.stringify(px));
  const gcode = await download(page, 'dl-gcode');
  assert.match(gcode.bytes.toString('utf8'), /G1 /);
  assert.deepEqual(requests, []);
  assert.deepEqual(problems, []);
  await context.close();
});

// The same page from file:// with a scan of the user's: its SHA-256 is
// found by a second worker started from the same Blob URL, and the
// G-code names the scan by it; the report is written when its link is
// pressed.
test('dist/pcpp.html plans a scan of the user\'s from file://, hashed by its second worker', async (t) => {
  const cli = join(ROOT, 'target/debug/pcpp');
  if (!existsSync(cli)) {
    t.skip(`${cli} not built (cargo build --bin pcpp)`);
    return;
  }
  const dir = mkdtempSync(join(tmpdir(), 'pcpp-offline-'));
  try {
    execFileSync(cli, ['demo', '-o', dir], { stdio: 'ignore' });
    const scan = join(dir, 'my-part.ply');
    copyFileSync(join(dir, 'demo-test-part.ply'), scan);
    const sha = createHash('sha256').update(readFileSync(scan)).digest('hex');
    const { page, context, problems } = await openPage(chrome.browser, pathToFileURL(join(DIST, 'pcpp.html')).href);
    await waitForPlan(page);
    await page.setInputFiles('#scan-input', scan);
    await page.waitForFunction(() => document.getElementById('scan-name').textContent === 'my-part.ply');
    await waitIdle(page);
    await waitForPlan(page);
    const gcode = (await download(page, 'dl-gcode')).bytes.toString('utf8');
    assert.match(gcode, new RegExp(`my-part\\.ply \\(\\d+ bytes, sha256 ${sha}\\)`));
    const report = JSON.parse((await download(page, 'dl-report')).bytes.toString('utf8'));
    assert.equal(report.inputs[0].sha256, sha);
    assert.deepEqual(problems, []);
    await context.close();
  } finally {
    rmSync(dir, { recursive: true, force: true });
  }
});
