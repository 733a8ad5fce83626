// A raw point cloud (issue 14) uploaded through the page's scan input is
// meshed in the page as the CLI meshes it: the page says what it did, the
// G-code equals the CLI's for the same cloud, and the edge-length setting
// re-meshes it (a bad value gets an error that names the file and keeps
// the plan).
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { existsSync, mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { after, before, test } from 'node:test';
import { ROOT, download, openPage, waitForPlan, waitIdle, withPageServer } from './helpers.mjs';

const CLI = join(ROOT, 'target/debug/pcpp');

const env = withPageServer();
let dir;
before(() => {
  dir = mkdtempSync(join(tmpdir(), 'pcpp-cloud-'));
});
after(() => {
  if (dir) rmSync(dir, { recursive: true, force: true });
});

// A 40 x 40 mm sheet on the bed (x 80..120, y 60..100) sampled every
// 0.5 mm with a little jitter, as CSV with a header and normals, with a
// 2 mm dropout that must stay a hole.
function cloudCsv() {
  const rows = ['x,y,z,nx,ny,nz'];
  let seed = 12345;
  const rnd = () => {
    seed = (seed * 1103515245 + 12345) % 2147483648;
    return seed / 2147483648;
  };
  for (let j = 0; j <= 80; j++) {
    for (let i = 0; i <= 80; i++) {
      const x = 80 + i * 0.5 + 0.1 * (rnd() - 0.5);
      const y = 60 + j * 0.5 + 0.1 * (rnd() - 0.5);
      if (Math.hypot(x - 110, y - 90) < 1) continue;
      const z = 2 + 1.5 * Math.exp(-((x - 100) ** 2) / 60) + 0.5 * Math.sin(y / 5);
      rows.push(`${x.toFixed(4)},${y.toFixed(4)},${z.toFixed(4)},0,0,1`);
    }
  }
  return `${rows.join('\n')}\n`;
}

const SVG = `<svg xmlns="http://www.w3.org/2000/svg" width="20mm" height="20mm" viewBox="0 0 20 20">
  <path d="M 1 2 L 19 2 L 19 6 L 1 6 L 1 10 L 19 10" fill="none" stroke="black"/>
</svg>
`;

test('a CSV point cloud is meshed in the page as by the CLI, and its edge limit is a setting', async (t) => {
  const scanPath = join(dir, 'sheet-cloud.csv');
  const svgPath = join(dir, 'meander.svg');
  writeFileSync(scanPath, cloudCsv());
  writeFileSync(svgPath, SVG);

  const { page, context, problems } = await openPage(env.chrome.browser, env.server.url);
  await waitForPlan(page);
  await page.setInputFiles('#scan-input', scanPath);
  await page.setInputFiles('#svg-input', svgPath);
  await waitIdle(page);
  await waitForPlan(page);
  assert.equal(await page.isHidden('#error-panel'), true, await page.textContent('#error-message'));
  assert.equal(await page.textContent('#scan-name'), 'sheet-cloud.csv');
  const info = await page.textContent('#scan-info');
  assert.match(info, /^XYZ, /);
  assert.match(info, /point cloud: 6\d{3} points meshed into \d+ triangles, edges up to 1\.[2-5]\d\d mm in XY \(3 x the median point spacing 0\.[45]\d\d mm\)/);

  const gcode = await download(page, 'dl-gcode');
  const report = JSON.parse((await download(page, 'dl-report')).bytes.toString('utf8'));
  const cloud = report.mesh.point_cloud;
  assert.ok(cloud && cloud.points > 6000 && !cloud.max_edge_given, JSON.stringify(report.mesh));

  // A bad limit: an error that names the file, the plan kept.
  await page.fill('#scan-max-edge', '-1');
  await page.dispatchEvent('#scan-max-edge', 'change');
  await waitIdle(page);
  await page.waitForSelector('#error-panel', { state: 'visible', timeout: 60_000 });
  const err = await page.textContent('#error-message');
  assert.match(err, /sheet-cloud\.csv/);
  assert.match(err, /maximum edge length/);
  assert.equal(await page.isEnabled('#dl-gcode'), true);

  // A limit set by hand re-meshes the cloud.
  await page.fill('#scan-max-edge', '0.9');
  await page.dispatchEvent('#scan-max-edge', 'change');
  await page.waitForFunction(() => /as set;/.test(document.getElementById('scan-info').textContent),
    null, { timeout: 60_000 });
  await waitIdle(page);
  await waitForPlan(page);
  assert.match(await page.textContent('#scan-info'), /edges up to 0\.900 mm in XY \(as set;/);
  await page.fill('#scan-max-edge', '');
  await page.dispatchEvent('#scan-max-edge', 'change');
  await page.waitForFunction(() => /3 x the median/.test(document.getElementById('scan-info').textContent),
    null, { timeout: 60_000 });
  await waitIdle(page);
  await waitForPlan(page);
  await context.close();
  assert.deepEqual(problems, []);

  if (!existsSync(CLI)) {
    t.skip(`${CLI} not built (cargo build --bin pcpp)`);
    return;
  }
  const pl = report.settings.placement;
  const out = join(dir, 'cli.gcode');
  execFileSync(CLI, ['plan', '--scan', scanPath, '--path', svgPath, '-o', out,
    '--place', `${pl.offset_mm[0]},${pl.offset_mm[1]},${pl.rotation_deg},${pl.scale}`],
  { stdio: ['ignore', 'ignore', 'pipe'] });
  assert.ok(readFileSync(out).equals(gcode.bytes), 'the page G-code differs from the CLI G-code');
});
