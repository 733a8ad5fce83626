// A .gltf whose buffer is a separate .bin (Blender's "glTF Separate",
// Sketchfab's downloads): selected or dropped together they load, the
// G-code equals the CLI's for the same two files, and both are kept for
// the next visit; the .gltf alone is refused naming the .bin, and the
// scan loaded before stays.
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { existsSync, mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { after, before, test } from 'node:test';
import {
  ROOT, download, openPage, waitForPlan, waitIdle, waitKept, waitSettled, withPageServer,
} from './helpers.mjs';

const CLI = join(ROOT, 'target/debug/pcpp');
const env = withPageServer();

let dir;
before(() => {
  dir = mkdtempSync(join(tmpdir(), 'pcpp-gltf-'));
});
after(() => {
  if (dir) rmSync(dir, { recursive: true, force: true });
});

// A 40 x 40 mm sheet with a ridge, as a glTF exporter writes it: metres,
// +Y up (the printer's (x, y, z) is the file's (x, z, -y)), f32 positions
// and u32 indices in one buffer at `uri`. Returns [gltf text, bin bytes].
function sheetGltf(uri) {
  const n = 41;
  const pos = Buffer.alloc(12 * n * n);
  const lo = [Infinity, Infinity, Infinity];
  const hi = [-Infinity, -Infinity, -Infinity];
  for (let j = 0; j < n; j++) {
    for (let i = 0; i < n; i++) {
      const x = i;
      const y = j;
      const z = 5 + 1.5 * Math.exp(-((x - 20) ** 2) / 30) + Math.exp(-((x - 12) ** 2 + (y - 28) ** 2) / 10);
      const v = [x / 1000, z / 1000, -y / 1000].map(Math.fround);
      v.forEach((c, k) => {
        pos.writeFloatLE(c, 12 * (j * n + i) + 4 * k);
        lo[k] = Math.min(lo[k], c);
        hi[k] = Math.max(hi[k], c);
      });
    }
  }
  const idx = [];
  for (let j = 0; j < n - 1; j++) {
    for (let i = 0; i < n - 1; i++) {
      const a = j * n + i;
      // Counter-clockwise seen from above in the printer frame.
      idx.push(a, a + 1, a + n + 1, a, a + n + 1, a + n);
    }
  }
  const ind = Buffer.alloc(4 * idx.length);
  idx.forEach((v, k) => ind.writeUInt32LE(v, 4 * k));
  const bin = Buffer.concat([pos, ind]);
  const gltf = JSON.stringify({
    asset: { version: '2.0', generator: 'pcpp browser test' },
    scene: 0,
    scenes: [{ nodes: [0] }],
    nodes: [{ mesh: 0 }],
    meshes: [{ primitives: [{ attributes: { POSITION: 0 }, indices: 1 }] }],
    accessors: [
      { bufferView: 0, componentType: 5126, count: n * n, type: 'VEC3', min: lo, max: hi },
      { bufferView: 1, componentType: 5125, count: idx.length, type: 'SCALAR' },
    ],
    bufferViews: [
      { buffer: 0, byteOffset: 0, byteLength: pos.length },
      { buffer: 0, byteOffset: pos.length, byteLength: ind.length },
    ],
    buffers: [{ byteLength: bin.length, uri }],
  });
  return [gltf, bin];
}

// The drawing's origin put at printer (x, y) mm, unturned and full size,
// then the plan awaited: it must plan without an error.
async function placeByHand(page, x, y) {
  await page.fill('#pl-x', String(x));
  await page.fill('#pl-y', String(y));
  await page.fill('#pl-rot', '0');
  await page.fill('#pl-scale', '1');
  await page.dispatchEvent('#pl-scale', 'change');
  await waitIdle(page);
  await waitSettled(page);
  assert.equal(await page.isHidden('#error-panel'), true, await page.textContent('#error-message'));
}

const LINE_SVG = '<svg xmlns="http://www.w3.org/2000/svg" width="40mm" height="40mm" viewBox="0 0 40 40">'
  + '<path d="M 4 20 L 36 20 L 36 30" fill="none" stroke="black"/></svg>\n';

test('a .gltf and its .bin selected together plan as the CLI plans them, and are kept for the next visit', async (t) => {
  const [gltf, bin] = sheetGltf('sheet%20scan.bin');
  const gltfPath = join(dir, 'sheet.gltf');
  const binPath = join(dir, 'sheet scan.bin');
  const svgPath = join(dir, 'line.svg');
  writeFileSync(gltfPath, gltf);
  writeFileSync(binPath, bin);
  writeFileSync(svgPath, LINE_SVG);

  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitForPlan(page);
  await page.setInputFiles('#scan-input', [gltfPath, binPath]);
  await page.waitForFunction(() => window.pcpp.state.info && window.pcpp.state.info.name === 'sheet.gltf',
    null, { timeout: 120_000 });
  await page.setInputFiles('#svg-input', svgPath);
  // Placed by hand once the drawing is read (a new drawing is centred).
  await page.waitForFunction(() => window.pcpp.state.pendingSvg || window.pcpp.state.svgFile);
  await page.selectOption('#planner', 'pcpp-guarded');
  await placeByHand(page, 0, 40);
  assert.equal(await page.textContent('#scan-name'), 'sheet.gltf');
  const info = await page.evaluate(() => window.pcpp.state.info);
  assert.equal(info.triangles, 3200);
  assert.deepEqual(info.external_files.map((f) => [f.name, f.bytes]), [['sheet scan.bin', bin.length]]);
  const gcode = await download(page, 'dl-gcode');
  const text = gcode.bytes.toString('utf8');
  assert.match(text, /^; scan file: sheet\.gltf \(\d+ bytes, sha256 [0-9a-f]{64}\)$/m);
  assert.match(text, new RegExp(`^; scan external file: sheet scan\\.bin \\(${bin.length} bytes, sha256 [0-9a-f]{64}\\)$`, 'm'));
  const settings = await page.evaluate(() => window.pcpp.state.lastPlan.summary.settings);
  assert.deepEqual(settings.placement, { offset_mm: [0, 40], rotation_deg: 0, scale: 1 });

  // Kept with its .bin: reopened after a reload, the same plan.
  await waitKept(page);
  await page.reload();
  await waitSettled(page);
  assert.equal(await page.textContent('#scan-name'), 'sheet.gltf');
  assert.equal(await page.isHidden('#error-panel'), true, await page.textContent('#error-message'));
  assert.equal(await page.evaluate(() => window.pcpp.state.lastPlan.gcode), text);
  assert.deepEqual(problems, []);
  await context.close();

  if (!existsSync(CLI)) {
    t.skip(`${CLI} not built (cargo build --bin pcpp)`);
    return;
  }
  const out = join(dir, 'cli.gcode');
  const n = settings.nozzle;
  const p = settings.process;
  execFileSync(CLI, ['plan', '--scan', gltfPath, '--path', svgPath, '-o', out, '--planner', 'pcpp-guarded',
    '--place', '0,40,0,1', '--nozzle-id', String(n.inner_diameter_mm), '--nozzle-od', String(n.outer_diameter_mm),
    '--tol', String(p.tolerance_mm), '--speed', String(p.speed_mm_s), '--dwell', String(p.dwell_s)],
  { stdio: ['ignore', 'ignore', 'pipe'] });
  assert.equal(readFileSync(out, 'utf8'), text, 'the page G-code differs from the CLI G-code');
});

test('a .gltf dropped with its .bin loads; alone it is refused naming the .bin, and the scan stays', async () => {
  const [gltf, bin] = sheetGltf('ridge.bin');
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitForPlan(page);
  const before = await page.evaluate(() => window.pcpp.state.lastPlan.gcode);

  // Selected alone: refused, naming the .bin; the demo and its plan stay,
  // still offered (nothing it was planned from changed).
  const alone = join(dir, 'ridge.gltf');
  writeFileSync(alone, gltf);
  await page.setInputFiles('#scan-input', alone);
  await page.waitForSelector('#error-panel:not([hidden])', { timeout: 120_000 });
  await waitIdle(page);
  assert.equal(await page.textContent('#error-title'), 'Could not read the scan ridge.gltf');
  const message = await page.textContent('#error-message');
  // The file named once, in the title.
  assert.match(message, /^buffer 0 is stored in the external file 'ridge\.bin', which was not given/);
  // Said once (QA: twice), in place of the core's advice for both.
  assert.match(message, /which was not given: select ridge\.gltf together with ridge\.bin \(both at once in the file dialog, or drop both on the page\), or export the scan as one \.glb/);
  assert.equal(message.match(/together/g).length, 1, message);
  // The page's advice only, not the command line's.
  assert.doesNotMatch(message, /command line|\(page\)/);
  assert.match(message, /Still using the previous scan, demo-test-part\.ply\./);
  assert.equal(await page.textContent('#scan-name'), 'demo-test-part.ply');
  assert.equal(await page.evaluate(() => window.pcpp.state.scan.name), 'demo-test-part.ply');
  assert.equal(await page.evaluate(() => window.pcpp.state.lastPlan.gcode), before);
  assert.equal((await download(page, 'dl-gcode')).bytes.toString('utf8'), before);
  await page.click('#plan-btn');
  await waitForPlan(page);
  assert.equal((await download(page, 'dl-gcode')).bytes.toString('utf8'), before);

  // Dropped together (with a file it does not need): it loads.
  await page.evaluate(([g, b]) => {
    const dt = new DataTransfer();
    dt.items.add(new File(['not needed'], 'notes.md'));
    dt.items.add(new File([Uint8Array.from(atob(b), (c) => c.charCodeAt(0))], 'ridge.bin'));
    dt.items.add(new File([g], 'ridge.gltf', { type: 'model/gltf+json' }));
    window.dispatchEvent(new DragEvent('drop', { dataTransfer: dt, cancelable: true }));
  }, [gltf, bin.toString('base64')]);
  await page.waitForFunction(() => window.pcpp.state.info && window.pcpp.state.info.name === 'ridge.gltf',
    null, { timeout: 120_000 });
  await waitIdle(page);
  await waitForPlan(page);
  assert.equal(await page.textContent('#scan-name'), 'ridge.gltf');
  assert.equal(await page.evaluate(() => window.pcpp.state.scan.external.map((f) => f.name).join()), 'ridge.bin');
  // The bytes read are both files' (QA: the .gltf's alone).
  const both = Buffer.byteLength(gltf) + bin.length;
  const shown = both >= 1024 ? `${(both / 1024).toFixed(1)} KiB` : `${both} bytes`;
  assert.match(await page.textContent('#scan-info'), new RegExp(`; ${shown.replace('.', '\\.')} read in `));
  await context.close();
});

// A Draco-compressed .glb (Google's encoder, tests/data/realworld/SOURCES.md;
// the demo part): the page decodes it and plans the G-code the CLI writes
// for the same file.
test('a Draco-compressed .glb loads and plans as the CLI plans it', async (t) => {
  const glbPath = join(ROOT, 'tests/data/realworld/mesh/test-part-draco.glb');
  const svgPath = join(dir, 'draco-line.svg');
  writeFileSync(svgPath, LINE_SVG);
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitForPlan(page);
  await page.setInputFiles('#scan-input', glbPath);
  await page.waitForFunction(() => window.pcpp.state.info && window.pcpp.state.info.name === 'test-part-draco.glb',
    null, { timeout: 120_000 });
  await page.setInputFiles('#svg-input', svgPath);
  await page.waitForFunction(() => window.pcpp.state.pendingSvg || window.pcpp.state.svgFile);
  await placeByHand(page, 20, 60);
  const info = await page.evaluate(() => window.pcpp.state.info);
  // The part's 247,490 triangles less those its quantization collapsed.
  assert.ok(info.triangles > 247_000 && info.triangles < 247_490, String(info.triangles));
  const text = (await download(page, 'dl-gcode')).bytes.toString('utf8');
  assert.match(text, /^; scan file: test-part-draco\.glb \(\d+ bytes, sha256 [0-9a-f]{64}\)$/m);
  const settings = await page.evaluate(() => window.pcpp.state.lastPlan.summary.settings);
  assert.deepEqual(settings.placement, { offset_mm: [20, 60], rotation_deg: 0, scale: 1 });
  assert.deepEqual(problems, []);
  await context.close();

  if (!existsSync(CLI)) {
    t.skip(`${CLI} not built (cargo build --bin pcpp)`);
    return;
  }
  const out = join(dir, 'draco-cli.gcode');
  const n = settings.nozzle;
  const p = settings.process;
  execFileSync(CLI, ['plan', '--scan', glbPath, '--path', svgPath, '-o', out, '--planner', settings.planner,
    '--place', '20,60,0,1', '--nozzle-id', String(n.inner_diameter_mm), '--nozzle-od', String(n.outer_diameter_mm),
    '--tol', String(p.tolerance_mm), '--speed', String(p.speed_mm_s), '--dwell', String(p.dwell_s)],
  { stdio: ['ignore', 'ignore', 'pipe'] });
  assert.equal(readFileSync(out, 'utf8'), text, 'the page G-code differs from the CLI G-code');
});

// gltfpack's meshopt-compressed .gltf with a fallback (tests/data/realworld/
// SOURCES.md): selected with its compressed .bin only, it loads (the
// fallback's file, for readers without meshopt, is never asked for), and its
// G-code names the one external file read.
test('a meshopt-compressed .gltf loads with its .bin, its fallback file not asked for', async () => {
  const mesh = (f) => join(ROOT, 'tests/data/realworld/mesh', f);
  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitForPlan(page);
  await page.setInputFiles('#scan-input', [mesh('bunny-meshopt-cf.gltf'), mesh('bunny-meshopt-cf.bin')]);
  await page.waitForFunction(() => window.pcpp.state.info && window.pcpp.state.info.name === 'bunny-meshopt-cf.gltf',
    null, { timeout: 120_000 });
  await waitIdle(page);
  const info = await page.evaluate(() => window.pcpp.state.info);
  assert.equal(info.triangles, 3674);
  const bin = readFileSync(mesh('bunny-meshopt-cf.bin'));
  assert.deepEqual(info.external_files.map((f) => [f.name, f.bytes]), [['bunny-meshopt-cf.bin', bin.length]]);
  assert.equal(await page.textContent('#scan-name'), 'bunny-meshopt-cf.gltf');
  assert.deepEqual(problems, []);
  await context.close();
});
