// Large files: a scan is never read on the page's main thread (the worker
// reads the File in slices into wasm memory) and its import shows progress
// by stage; files past the page's limits are refused before a byte is
// read, with a message naming the file and the limit, and what was loaded
// (scan, drawing, plan, download) stays. The last scan and SVG are kept by
// the browser for the next visit.
import assert from 'node:assert/strict';
import { closeSync, ftruncateSync, mkdtempSync, openSync, rmSync, writeFileSync, writeSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { after, before, test } from 'node:test';
import {
  ROOT, download, openPage, waitForPlan, waitIdle, waitKept, waitSettled, withPageServer,
} from './helpers.mjs';

const env = withPageServer();
const MIB = 1 << 20;

let dir;
before(() => {
  dir = mkdtempSync(join(tmpdir(), 'pcpp-files-'));
});
after(() => {
  if (dir) rmSync(dir, { recursive: true, force: true });
});

// A file of `bytes` zeros that takes no disk space (sparse).
function sparseFile(name, bytes) {
  const path = join(dir, name);
  const fd = openSync(path, 'w');
  ftruncateSync(fd, bytes);
  closeSync(fd);
  return path;
}

// A binary PLY of an n x n grid over the demo's 80 x 80 mm (2 n^2
// triangles, 5 mm up with a gentle wave), so the demo's lines land on it.
function gridPly(name, n) {
  const path = join(dir, name);
  const fd = openSync(path, 'w');
  writeSync(fd, Buffer.from(`ply\nformat binary_little_endian 1.0\nelement vertex ${(n + 1) ** 2}\n`
    + 'property float x\nproperty float y\nproperty float z\n'
    + `element face ${2 * n * n}\nproperty list uchar int vertex_indices\nend_header\n`));
  const h = 80 / n;
  for (let j = 0; j <= n; j++) {
    const row = Buffer.alloc(12 * (n + 1));
    for (let i = 0; i <= n; i++) {
      row.writeFloatLE(i * h, 12 * i);
      row.writeFloatLE(j * h, 12 * i + 4);
      row.writeFloatLE(5 + 0.3 * Math.sin(i * h * 0.2) * Math.cos(j * h * 0.15), 12 * i + 8);
    }
    writeSync(fd, row);
  }
  for (let j = 0; j < n; j++) {
    const row = Buffer.alloc(26 * n);
    for (let i = 0; i < n; i++) {
      const a = j * (n + 1) + i;
      for (const [k, tri] of [[a, a + 1, a + n + 2], [a, a + n + 2, a + n + 1]].entries()) {
        const o = 26 * i + 13 * k;
        row.writeUInt8(3, o);
        tri.forEach((v, m) => row.writeInt32LE(v, o + 1 + 4 * m));
      }
    }
    writeSync(fd, row);
  }
  closeSync(fd);
  return path;
}

// Counts, on the page's main thread, every read of a Blob or File's bytes.
async function countMainThreadReads(page) {
  await page.evaluate(() => {
    window.__reads = [];
    for (const m of ['arrayBuffer', 'text', 'stream', 'slice', 'bytes']) {
      const orig = Blob.prototype[m];
      if (!orig) continue;
      Blob.prototype[m] = function wrapped(...args) {
        window.__reads.push(`${this.name || 'blob'}.${m}`);
        return orig.apply(this, args);
      };
    }
    for (const m of ['readAsArrayBuffer', 'readAsText', 'readAsBinaryString', 'readAsDataURL']) {
      const orig = FileReader.prototype[m];
      FileReader.prototype[m] = function wrapped(blob, ...args) {
        window.__reads.push(`${blob.name || 'blob'}.${m}`);
        return orig.call(this, blob, ...args);
      };
    }
  });
}

test('a scan past 512 MiB is refused before it is read; the loaded scan, plan and download stay', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitForPlan(page);
  const before = await page.evaluate(() => window.pcpp.state.lastPlan.gcode);
  const huge = sparseFile('huge-scan.stl', 600 * MIB);
  await countMainThreadReads(page);
  await page.setInputFiles('#scan-input', huge);
  await page.waitForSelector('#error-panel:not([hidden])');
  assert.equal(await page.textContent('#error-title'), 'Could not open the scan huge-scan.stl');
  const message = await page.textContent('#error-message');
  assert.match(message, /^the file is 600\.0 MiB, more than the 512 MiB this page reads/);
  assert.match(message, /command line/);
  assert.match(message, /Still using demo-test-part\.ply\./);
  // Nothing was read, nothing went to the worker, nothing changed.
  const s = await page.evaluate(() => ({
    reads: window.__reads,
    pending: window.pcpp.state.pendingScan,
    busy: window.pcpp.state.busy,
    scan: window.pcpp.state.scan.name,
  }));
  assert.deepEqual(s, { reads: [], pending: null, busy: null, scan: 'demo-test-part.ply' });
  assert.equal(await page.textContent('#scan-name'), 'demo-test-part.ply');
  assert.equal(await page.textContent('#scan-limit'), '512 MiB');
  // The plan on screen is still valid for what is loaded: still offered.
  const again = await download(page, 'dl-gcode');
  assert.equal(again.bytes.toString('utf8'), before);
  assert.deepEqual(problems, []);
  await context.close();
});

test('an SVG past 64 MiB is refused before it is read; the drawing stays', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitForPlan(page);
  await page.setInputFiles('#svg-input', sparseFile('huge.svg', 65 * MIB));
  await page.waitForSelector('#error-panel:not([hidden])');
  assert.equal(await page.textContent('#error-title'), 'Could not open the SVG huge.svg');
  assert.match(await page.textContent('#error-message'), /^the file is 65\.0 MiB, more than the 64 MiB/);
  assert.equal(await page.inputValue('#path-source'), 'demo');
  assert.equal(await page.isVisible('#dl-gcode'), true);
  assert.deepEqual(problems, []);
  await context.close();
});

test('a 23 MiB scan is read in the worker with progress by stage, never on the main thread', async () => {
  const path = gridPly('grid.ply', 800); // 1.28 M triangles, 23.2 MiB
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitForPlan(page);
  await countMainThreadReads(page);
  // What the progress line shows, as it changes.
  await page.evaluate(() => {
    window.__shown = [];
    const label = document.getElementById('progress-label');
    new MutationObserver(() => {
      const bar = document.getElementById('progress-bar');
      window.__shown.push([label.textContent, bar.hidden ? null : bar.value]);
    }).observe(label, { childList: true, characterData: true, subtree: true });
  });
  await page.setInputFiles('#scan-input', path);
  await page.waitForFunction(() => window.pcpp.state.info && window.pcpp.state.info.name === 'grid.ply',
    null, { timeout: 300_000 });
  await waitIdle(page, 300_000);
  await waitForPlan(page);
  assert.equal(await page.isHidden('#error-panel'), true, await page.textContent('#error-message'));
  const { log, reads, shown } = await page.evaluate(() => ({
    log: window.pcpp.state.progressLog, reads: window.__reads, shown: window.__shown,
  }));
  assert.deepEqual(reads, [], 'the main thread read the scan');
  assert.match(log[0], /^reading grid\.ply \(23\.2 MiB\)$/);
  assert.ok(log.includes('reading grid.ply: 8.0 of 23.2 MiB'), log.join('\n'));
  assert.ok(log.includes('reading grid.ply: 23.2 of 23.2 MiB'), log.join('\n'));
  const after = log.slice(log.indexOf('reading grid.ply: 23.2 of 23.2 MiB') + 1);
  assert.equal(after[0], 'importing grid.ply');
  assert.match(after[1], /^finding fiducial holes and registering 1,280,000 triangles$/);
  assert.match(after[2], /^building the search structure \(BVH\) over 1,280,000 triangles$/);
  assert.match(after[3], /^done: grid\.ply, 1,280,000 triangles in \d+\.\d s$/);
  // The reading stage showed a filling bar.
  const fractions = shown.filter(([l, v]) => /^reading grid\.ply:/.test(l) && v !== null).map(([, v]) => v);
  assert.ok(fractions.length >= 3 && fractions.at(-1) === 1, JSON.stringify(shown));
  assert.match(await page.textContent('#scan-info'),
    /^PLY, 1,280,000 triangles, 80\.0 × 80\.0 × 0\.6 mm \(mm\); 23\.2 MiB read in \d+\.\d s; planner memory \d\.\d\d of 4 GiB$/);
  assert.equal(await page.textContent('#scan-name'), 'grid.ply');
  assert.deepEqual(problems, []);
  await context.close();
});

test('the last scan and SVG are reopened after a reload; a scan the page closed while reading is not', async () => {
  const scanPath = gridPly('sheet.ply', 60);
  const svgPath = join(dir, 'line.svg');
  writeFileSync(svgPath, '<svg xmlns="http://www.w3.org/2000/svg" width="80mm" height="80mm" viewBox="0 0 80 80">'
    + '<path d="M 10 40 L 70 40 L 70 50" fill="none" stroke="black"/></svg>\n');
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitSettled(page);
  await page.setInputFiles('#scan-input', scanPath);
  await page.setInputFiles('#svg-input', svgPath);
  // The SVG is read asynchronously: until its plan starts, the scan's plan
  // (on the demo drawing) looks settled.
  await page.waitForFunction(() => {
    const p = window.pcpp.state.lastPlan;
    return p && p.gcode && p.gcode.includes('; path file: line.svg');
  }, null, { timeout: 120_000 });
  await waitSettled(page);
  assert.equal(await page.textContent('#scan-name'), 'sheet.ply');
  const before = await page.evaluate(() => window.pcpp.state.lastPlan.gcode);
  await waitKept(page);

  await page.reload();
  await waitSettled(page);
  assert.equal(await page.textContent('#scan-name'), 'sheet.ply');
  assert.equal(await page.textContent('#svg-name'), 'line.svg');
  assert.equal(await page.evaluate(() => window.pcpp.state.lastPlan.gcode), before);

  // As if the tab had died while reopening it: not reopened again.
  await page.evaluate(() => localStorage.setItem('pcpp.restoring.v1', 'sheet.ply'));
  await page.reload();
  await waitSettled(page);
  assert.equal(await page.textContent('#error-title'), 'The last scan, sheet.ply, was not reopened');
  assert.equal(await page.textContent('#scan-name'), 'demo-test-part.ply');
  assert.equal(await page.textContent('#svg-name'), 'line.svg');

  // Load demo forgets the kept files.
  await page.click('#demo-btn');
  await waitSettled(page);
  await waitKept(page);
  await page.reload();
  await waitSettled(page);
  assert.equal(await page.textContent('#scan-name'), 'demo-test-part.ply');
  assert.equal(await page.inputValue('#path-source'), 'demo');
  assert.deepEqual(problems, []);
  await context.close();
});

// Two scans selected at once: one is read, and the page says which, and
// that the other is not (it had silently used the first; found by
// exploratory QA).
test('several scans selected at once: the page says which one it reads', async () => {
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitForPlan(page);
  const mesh = (name) => join(ROOT, 'tests/data/realworld/mesh', name);
  await page.setInputFiles('#scan-input', [mesh('stanford-bunny.ply'), mesh('Spider_binary.stl')]);
  await page.waitForFunction(() => window.pcpp.state.info.name !== 'demo-test-part.ply'
    && !window.pcpp.state.busy && !window.pcpp.state.queued, null, { timeout: 120_000 });
  const name = await page.textContent('#scan-name');
  const other = name === 'stanford-bunny.ply' ? 'Spider_binary.stl' : 'stanford-bunny.ply';
  const note = await page.textContent('#scan-note');
  assert.equal(note, `2 scans selected at once: ${name} was opened, ${other} was not (open one scan at a time).`);
  // The next scan opened alone: no note.
  await page.setInputFiles('#scan-input', mesh('Spider_binary.stl'));
  assert.equal(await page.textContent('#scan-note'), '');
  await waitIdle(page);
  assert.deepEqual(problems, []);
  await context.close();
});
