// The single-file build (dist/pcpp.html) works opened from file:// with no
// server: wasm inlined, the worker started from a Blob URL.
import assert from 'node:assert/strict';
import { existsSync } from 'node:fs';
import { join } from 'node:path';
import { pathToFileURL } from 'node:url';
import { after, before, test } from 'node:test';
import { DIST, download, launch, openPage, viewPixels, waitForPlan } from './helpers.mjs';

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
