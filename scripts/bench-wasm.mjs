#!/usr/bin/env node
// Times the issue-5 stages in the wasm build, in Node, single-threaded, on
// the workloads written by `cargo run --release --example workloads`:
//   - Session from W1.ply's bytes (import, fiducial holes, registration,
//     the surface's acceleration structure);
//   - Session from W1.obj's bytes (MB/s of the file, with the holes and
//     the index);
//   - W1.obj and W1.ply through the page's own steps (ScanBuffer.write,
//     importScan, register, index), each timed: importScan is the importer
//     alone, the stage the native `import/W1 OBJ text` bench times;
//   - Session.plan of W2 and W3 on W1 (plan, report and G-code, the G-code
//     converted to JS, the report kept with its JSON left unwritten, as the
//     page plans: the same job as the native job::run_on);
//   - wasm memory (memory.buffer.byteLength) holding W1 ready to plan. Wasm
//     memory never shrinks, so this is also the peak while it was prepared.
// Before the W1 imports it loads the demo part as the page does when it
// opens (web/worker.js: ScanBuffer.demoPart, importScan, register, index):
// V8 first runs wasm in its baseline tier and moves a function to its
// optimizing tier only on a later call, so a page's first own scan is read
// by code the demo already warmed. The first W1.ply Session in a Node that
// has run nothing is timed too, in a child process (--cold).
// Medians over a few runs; PCPP_BENCH_CLOCK=cpu times CPU time of the thread
// running the wasm instead of wall time. It builds nothing: scripts/bench.sh runs
//   wasm-pack build --release --target nodejs --out-dir target/pkg-node --no-pack
// first. Progress goes to stderr, the results as JSON to stdout (or --json).
//
//   node scripts/bench-wasm.mjs [--pkg target/pkg-node] [--workloads target/workloads]
//                               [--json FILE] [--quick] [--cold]
import { createRequire } from 'node:module';
import { execFileSync } from 'node:child_process';
import { readFileSync, writeFileSync, existsSync } from 'node:fs';
import { resolve, join, dirname } from 'node:path';
import { fileURLToPath } from 'node:url';
import { performance } from 'node:perf_hooks';

const root = resolve(dirname(fileURLToPath(import.meta.url)), '..');
const args = process.argv.slice(2);
function opt(name, dflt) {
  const i = args.indexOf(name);
  if (i < 0) return dflt;
  if (i + 1 >= args.length) die(`${name} needs a value`);
  return args[i + 1];
}
function die(msg) {
  console.error(`bench-wasm: ${msg}`);
  process.exit(1);
}
const pkgDir = resolve(root, opt('--pkg', 'target/pkg-node'));
const dir = resolve(root, opt('--workloads', 'target/workloads'));
const jsonOut = opt('--json', null);
const quick = args.includes('--quick');
// Runs per step (the first run of the planning steps is a warm-up, not counted).
const runs = quick
  ? { ply: 1, obj: 1, w2: 3, w3: 1 }
  : { ply: 5, obj: 3, w2: 20, w3: 5 };

const glue = join(pkgDir, 'pcpp.js');
if (!existsSync(glue)) {
  die(`${glue} is missing: build it with wasm-pack build --release --target nodejs --out-dir target/pkg-node --no-pack`);
}
for (const f of ['W1.ply', 'W1.obj', 'W2.svg', 'W3.svg', 'W2.settings.json', 'W3.settings.json']) {
  if (!existsSync(join(dir, f))) {
    die(`${join(dir, f)} is missing: cargo run --release --example workloads -- ${dir}`);
  }
}

// wasm-bindgen's nodejs glue keeps its instance to itself (no `__wasm`
// export in 0.2.130): catch it as the glue instantiates, to read its memory.
const instances = [];
const RealInstance = WebAssembly.Instance;
WebAssembly.Instance = new Proxy(RealInstance, {
  construct(target, argv, newTarget) {
    const inst = Reflect.construct(target, argv, newTarget);
    instances.push(inst);
    return inst;
  },
});
const pcpp = createRequire(import.meta.url)(glue);
WebAssembly.Instance = RealInstance;
const memory = instances.map((i) => i.exports.memory).find((m) => m instanceof WebAssembly.Memory);
if (!memory) die('could not find the wasm memory of the pcpp module');
pcpp.initPanicHook();

const read = (f) => new Uint8Array(readFileSync(join(dir, f)));
const settings = (f) => JSON.parse(readFileSync(join(dir, f), 'utf8'));
const ply = read('W1.ply');
const obj = read('W1.obj');
const w2 = { svg: read('W2.svg'), s: settings('W2.settings.json') };
const w3 = { svg: read('W3.svg'), s: settings('W3.settings.json') };

function median(xs) {
  const s = [...xs].sort((a, b) => a - b);
  const m = s.length >> 1;
  return s.length % 2 ? s[m] : 0.5 * (s[m - 1] + s[m]);
}
// Wall time, or with PCPP_BENCH_CLOCK=cpu the CPU time of Node's main
// thread, the one that runs the wasm (Linux /proc/thread-self/schedstat, ns;
// fs's sync calls run on the calling thread): on a shared machine the time
// other processes take is then left out. V8's helper threads (optimizing
// compiler, GC) are not counted either way round.
const schedstat = '/proc/thread-self/schedstat';
const threadCpuMs = () => Number(readFileSync(schedstat, 'utf8').split(' ')[0]) / 1e6;
let clock = 'wall';
if (process.env.PCPP_BENCH_CLOCK === 'cpu') {
  if (existsSync(schedstat) && Number.isFinite(threadCpuMs())) clock = 'cpu';
  else console.error(`[bench-wasm] PCPP_BENCH_CLOCK=cpu: no ${schedstat} here, timing wall time`);
}
const now = clock === 'cpu' ? threadCpuMs : () => performance.now();
function time(f) {
  const t0 = now();
  const r = f();
  return [now() - t0, r];
}
const log = (msg) => console.error(`[bench-wasm] ${msg}`);
const mb = (b) => (b / 1e6).toFixed(1);

const session = (bytes, name) => new pcpp.Session(bytes, name, w2.s.scan, w2.s.registration);

// --cold: one W1.ply Session in this fresh Node, its seconds to stdout.
if (args.includes('--cold')) {
  const [ms, s] = time(() => session(ply, 'W1.ply'));
  s.free();
  process.stdout.write(`${ms / 1e3}\n`);
  process.exit(0);
}
const coldArgs = [fileURLToPath(import.meta.url), '--pkg', pkgDir, '--workloads', dir, '--cold'];
const plyColdS = Number(execFileSync(process.execPath, coldArgs, { encoding: 'utf8' }).trim());
log(`Session(W1.ply) in a fresh Node: ${(plyColdS * 1e3).toFixed(0)} ms`);

// 0. The demo part, as the page loads it when it opens (web/worker.js).
{
  const buf = pcpp.ScanBuffer.demoPart('test-part');
  const imp = buf.importScan(w2.s.scan);
  imp.register(w2.s.registration);
  const demo = imp.index();
  demo.free();
}

// 1. W1 PLY -> Session; wasm memory measured once, holding the first one,
// before anything else has grown it.
const plyMs = [];
let memoryBytes = 0;
let triangles = 0;
for (let k = 0; k < runs.ply; k++) {
  const [ms, s] = time(() => session(ply, 'W1.ply'));
  plyMs.push(ms);
  if (k === 0) {
    memoryBytes = memory.buffer.byteLength;
    triangles = s.info().triangles;
    log(`W1.ply holds ${triangles} triangles; wasm memory ${mb(memoryBytes)} MB`);
  }
  s.free();
  log(`Session(W1.ply, ${mb(ply.length)} MB): ${ms.toFixed(0)} ms`);
}

// 2. W1 OBJ -> Session.
const objMs = [];
for (let k = 0; k < runs.obj; k++) {
  const [ms, s] = time(() => session(obj, 'W1.obj'));
  objMs.push(ms);
  s.free();
  log(`Session(W1.obj, ${mb(obj.length)} MB): ${ms.toFixed(0)} ms, ${(obj.length / 1e3 / ms).toFixed(1)} MB/s`);
}

// 2b. W4, a million raw points as XYZ text -> Session (meshed, holes,
// index), when the workloads have it.
const w4Path = join(dir, 'W4.xyz');
const w4Ms = [];
let w4Triangles = 0;
if (existsSync(w4Path)) {
  const w4 = readFileSync(w4Path);
  for (let k = 0; k < runs.obj; k++) {
    const [ms, s] = time(() => session(w4, 'W4.xyz'));
    w4Ms.push(ms);
    w4Triangles = s.info().triangles;
    s.free();
    log(`Session(W4.xyz, ${mb(w4.length)} MB): ${ms.toFixed(0)} ms, ${w4Triangles} triangles`);
  }
}

// 2c. The page's own steps (web/worker.js), each timed: the file written
// into wasm memory in 8 MiB chunks (ScanBuffer.write), the import alone
// (importScan), the holes, topology and registration (register), the
// surface and its index (index); and its SHA-256 (Sha256Stream), which the
// page finds in a second worker beside those steps, as the CLI hashes on a
// second thread.
function staged(bytes, name) {
  const chunk = 8 << 20;
  let t0 = now();
  const h = new pcpp.Sha256Stream();
  for (let at = 0; at < bytes.length; at += chunk) h.update(bytes.subarray(at, at + chunk));
  h.finish();
  const hash_ms = now() - t0;
  t0 = now();
  const buf = new pcpp.ScanBuffer(name, bytes.length, false);
  for (let at = 0; at < bytes.length; at += chunk) buf.write(bytes.subarray(at, at + chunk));
  const read_ms = now() - t0;
  t0 = now();
  const imp = buf.importScan(w2.s.scan);
  const import_ms = now() - t0;
  t0 = now();
  imp.register(w2.s.registration);
  const register_ms = now() - t0;
  t0 = now();
  const s = imp.index();
  const index_ms = now() - t0;
  s.free();
  return { read_ms, import_ms, register_ms, index_ms, hash_ms };
}
function stagedRuns(bytes, name, n) {
  const all = [];
  for (let k = 0; k < n; k++) {
    const t = staged(bytes, name);
    all.push(t);
    log(`${name} in the page's steps: write ${t.read_ms.toFixed(0)} ms, import ` +
      `${t.import_ms.toFixed(0)} ms (${(bytes.length / 1e3 / t.import_ms).toFixed(1)} MB/s), ` +
      `register ${t.register_ms.toFixed(0)} ms, index ${t.index_ms.toFixed(0)} ms; ` +
      `SHA-256 beside them ${t.hash_ms.toFixed(0)} ms`);
  }
  const med = (key) => median(all.map((t) => t[key]));
  return { read_ms: med('read_ms'), import_ms: med('import_ms'), register_ms: med('register_ms'),
    index_ms: med('index_ms'), hash_ms: med('hash_ms'),
    // The page's path to a session: every step but the hash.
    path_ms: median(all.map((t) => t.read_ms + t.import_ms + t.register_ms + t.index_ms)), runs: all };
}
const objStaged = stagedRuns(obj, 'W1.obj', runs.obj);
const plyStaged = stagedRuns(ply, 'W1.ply', runs.obj);

// 3. Plans on one W1 Session (accept risk: the timing must not depend on
// whether some raster point could not be cleared).
const scan = session(ply, 'W1.ply');
function planRuns(w, name, n) {
  const plan = (withReport) => scan.plan(w.svg, name, w.s.plan, 'marlin', true, undefined, withReport);
  const [, first] = time(() => plan(true)); // warm-up, with the report's JSON for its figures
  const report = JSON.parse(first.report_json);
  const ms = [];
  for (let k = 0; k < n; k++) ms.push(time(() => plan(false))[0]);
  log(`plan ${name}: ${report.stats.points} points, median ${median(ms).toFixed(1)} ms over ${n}`);
  return { ms, points: report.stats.points };
}
const p2 = planRuns(w2, 'W2.svg', runs.w2);
const p3 = planRuns(w3, 'W3.svg', runs.w3);
scan.free();

const result = {
  clock,
  node: process.version,
  pcpp: pcpp.version(),
  triangles,
  ply_bytes: ply.length,
  obj_bytes: obj.length,
  ply_session_s: median(plyMs) / 1e3,
  // The page's path (planning worker) to a W1.ply session, its SHA-256
  // found beside it in a second worker.
  ply_page_s: plyStaged.path_ms / 1e3,
  // The first import after the demo part, as a page's first own scan.
  ply_session_first_s: plyMs[0] / 1e3,
  // The first import in a Node that has run nothing: V8's baseline code
  // throughout (a function moves to the optimizing tier on a later call).
  ply_session_cold_s: plyColdS,
  obj_session_s: median(objMs) / 1e3,
  obj_session_mb_s: obj.length / 1e6 / (median(objMs) / 1e3),
  obj_import_mb_s: obj.length / 1e3 / objStaged.import_ms,
  obj_staged: objStaged,
  ply_staged: plyStaged,
  w4_session_s: w4Ms.length ? median(w4Ms) / 1e3 : null,
  w4_triangles: w4Triangles,
  w2_plan_ms: median(p2.ms),
  w2_points: p2.points,
  w3_plan_ms: median(p3.ms),
  w3_points: p3.points,
  memory_w1_ready_bytes: memoryBytes,
  memory_end_bytes: memory.buffer.byteLength,
  runs: { ply_ms: plyMs, obj_ms: objMs, w2_ms: p2.ms, w3_ms: p3.ms },
};
const text = JSON.stringify(result, null, 2) + '\n';
if (jsonOut) writeFileSync(jsonOut, text);
else process.stdout.write(text);
