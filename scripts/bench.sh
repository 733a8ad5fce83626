#!/usr/bin/env bash
# Issue 5's speed benchmarks, one command (`npm run bench`): writes the
# workloads W1-W3 into target/workloads (when missing or stale), runs the
# criterion benches of the native stages (benches/pipeline.rs), builds the
# Node-target wasm package and times the same stages in it
# (scripts/bench-wasm.mjs), measures native peak memory holding W1 ready
# (examples/peak_memory.rs), and prints one markdown table, also saved to
# target/bench/table.md. Progress goes to stderr, the table to stdout.
#
# The stages run single-threaded (PCPP_THREADS=1: the per-thread work, the
# same as wasm32, which has one thread). The end-to-end row runs `pcpp plan`
# as a user does, on every core, timed by the kernel's wall clock and peak
# resident set (scripts/bench_e2e.py, needs python3), beside a reference
# run: the same scan loaded with trimesh and the same points projected with
# Embree (scripts/reference_trimesh.py; its packages go into
# target/bench/venv the first time, left out when they cannot be had).
# Needs no stdin, works as root; the toolchain comes from scripts/setup.sh
# (idempotent).
#   PCPP_BENCH_QUICK=1  a fast smoke run (criterion --quick, fewer wasm runs)
#   PCPP_BENCH_N=300    a smaller film (grid cells per side, default 1000);
#                       the targets are for the full size
#   PCPP_BENCH_CLOCK    cpu (default): CPU time of the thread running the
#                       stage (/proc/thread-self/schedstat), so that other
#                       processes on a shared machine do not inflate it;
#                       wall: elapsed time (use it on a quiet machine)
set -euo pipefail
cd "$(dirname "$0")/.."
export PATH="$HOME/.cargo/bin:$PATH"

log() { printf '[bench] %s\n' "$*" >&2; }
CELLS="${PCPP_BENCH_N:-1000}"
QUICK="${PCPP_BENCH_QUICK:-0}"
export PCPP_BENCH_CLOCK="${PCPP_BENCH_CLOCK:-cpu}"
LOAD_START="$(cut -d' ' -f1 /proc/loadavg)"
WL=target/workloads
OUT=target/bench
mkdir -p "$OUT"

PCPP_SKIP_BROWSER=1 bash scripts/setup.sh </dev/null

log "building the release examples"
cargo build --release --example workloads --example peak_memory </dev/null >&2

# Regenerate when missing, of another size, or older than the generator.
if [ ! -f "$WL/workloads.json" ] \
  || ! grep -q "\"cells\": $CELLS\b" "$WL/workloads.json" \
  || [ target/release/examples/workloads -nt "$WL/workloads.json" ]; then
  log "writing the workloads into $WL ($CELLS cells per side)"
  rm -f "$WL/workloads.json"
  PCPP_BENCH_N="$CELLS" target/release/examples/workloads "$WL" </dev/null >&2
else
  log "workloads in $WL are up to date"
fi

log "native peak memory holding W1 ready (examples/peak_memory.rs)"
target/release/examples/peak_memory "$WL/W1.ply" </dev/null >"$OUT/native-memory.txt"
cat "$OUT/native-memory.txt" >&2
log "native peak memory holding W4 (a million raw points) ready"
target/release/examples/peak_memory "$WL/W4.xyz" </dev/null >"$OUT/native-memory-w4.txt"
cat "$OUT/native-memory-w4.txt" >&2

log "criterion benches (cargo bench --bench pipeline)"
if [ "$QUICK" = 1 ]; then
  CRITERION_ARGS=(--quick)
else
  CRITERION_ARGS=(--warm-up-time 1 --measurement-time 3)
fi
# Estimates older than this marker are from an earlier run: refused below.
touch "$OUT/.started"
PCPP_THREADS=1 PCPP_BENCH_N="$CELLS" cargo bench --bench pipeline -- "${CRITERION_ARGS[@]}" </dev/null >&2

log "wasm package for Node (wasm-pack, release)"
wasm-pack build --release --target nodejs --out-dir target/pkg-node --no-pack </dev/null >&2

log "wasm timings in Node (scripts/bench-wasm.mjs)"
WASM_ARGS=(--pkg target/pkg-node --workloads "$WL" --json "$OUT/wasm.json")
[ "$QUICK" = 1 ] && WASM_ARGS+=(--quick)
node scripts/bench-wasm.mjs "${WASM_ARGS[@]}" </dev/null

log "end to end: pcpp plan of W2 on W1.ply, every core (scripts/bench_e2e.py)"
rm -f "$OUT/e2e.json" "$OUT/e2e-reference.json"
E2E_RUNS=5
[ "$QUICK" = 1 ] && E2E_RUNS=2
if command -v python3 >/dev/null; then
  cargo build --release --bin pcpp </dev/null >&2
  PLACE="$(node -p "require('./$WL/W2.settings.json').plan.placement.offset_mm.join(',')")"
  PLAN=(target/release/pcpp plan -q --scan "$WL/W1.ply" --path "$WL/W2.svg" --place "$PLACE" -o "$OUT/W2.gcode")
  "${PLAN[@]}" </dev/null >&2
  python3 scripts/bench_e2e.py --runs "$E2E_RUNS" -- "${PLAN[@]}" </dev/null >"$OUT/e2e.json"
  VENV="$OUT/venv"
  has_reference() { "$VENV/bin/python" -c 'import trimesh, embreex' 2>/dev/null; }
  if ! has_reference; then
    log "installing the reference's packages into $VENV (numpy, trimesh, embreex)"
    { python3 -m venv "$VENV" && "$VENV/bin/pip" install -q numpy 'trimesh==5.2.0' 'embreex==4.4.0.post1'; } \
      </dev/null >&2 || log "could not install them: the reference run is left out"
  fi
  if has_reference; then
    log "reference: the same scan and points with trimesh + Embree (scripts/reference_trimesh.py)"
    python3 scripts/bench_e2e.py --runs "$E2E_RUNS" -- \
      "$VENV/bin/python" scripts/reference_trimesh.py "$WL/W1.ply" "$OUT/W2.gcode" \
      </dev/null >"$OUT/e2e-reference.json"
  fi
else
  log "no python3: the end-to-end row is left out"
fi

MACHINE="$(lscpu 2>/dev/null | sed -n 's/^Model name: *//p' | head -n1)"
MACHINE="${MACHINE:-unknown CPU}, $(nproc) cores, $(awk '/MemTotal/ {printf "%.0f GiB", $2/1048576}' /proc/meminfo)"
COMMIT="$(git rev-parse --short HEAD 2>/dev/null || echo unknown)"
git diff --quiet HEAD -- src benches 2>/dev/null || COMMIT="$COMMIT + local changes"

LOAD="$LOAD_START at the start, $(cut -d' ' -f1 /proc/loadavg) at the end"
CELLS="$CELLS" QUICK="$QUICK" MACHINE="$MACHINE" COMMIT="$COMMIT" LOAD="$LOAD" \
  RUSTC="$(rustc --version)" node --input-type=module - <<'EOF' | tee "$OUT/table.md"
import { readFileSync, readdirSync, existsSync, statSync } from 'node:fs';
import { join } from 'node:path';

const die = (m) => { console.error(`[bench] ${m}`); process.exit(1); };
const started = statSync('target/bench/.started').mtimeMs;

// Criterion's own files: benchmark.json names each bench, estimates.json
// has its statistics in ns. Keyed by full id ("group/function").
const crit = {};
for (const group of readdirSync('target/criterion')) {
  const gdir = join('target/criterion', group);
  if (!statSync(gdir).isDirectory()) continue;
  for (const b of readdirSync(gdir)) {
    const meta = join(gdir, b, 'new', 'benchmark.json');
    const est = join(gdir, b, 'new', 'estimates.json');
    if (!existsSync(meta) || !existsSync(est)) continue;
    const m = JSON.parse(readFileSync(meta, 'utf8'));
    crit[m.full_id] = {
      fresh: statSync(est).mtimeMs >= started,
      median_s: JSON.parse(readFileSync(est, 'utf8')).median.point_estimate / 1e9,
      bytes: m.throughput?.Bytes,
    };
  }
}
const bench = (id) => {
  const b = crit[id];
  if (!b) die(`criterion has no results for '${id}' (target/criterion)`);
  if (!b.fresh) die(`criterion's results for '${id}' are from an earlier run`);
  return b;
};
const wasm = JSON.parse(readFileSync('target/bench/wasm.json', 'utf8'));
const mem = readFileSync('target/bench/native-memory.txt', 'utf8');
const peakRss = Number(/peak_rss_bytes=(\d+)/.exec(mem)?.[1] ?? die('no peak_rss_bytes'));

const plyS = bench('import/W1 binary PLY + index').median_s;
const obj = bench('import/W1 OBJ text');
const objMbS = obj.bytes / 1e6 / obj.median_s;
const objSessionS = bench('import/W1 OBJ + index').median_s;
const w2S = bench('plan/W2 spiral on W1 (default planner + quality)').median_s;
const w3S = bench('plan/W3 raster on W1 (default planner + quality)').median_s;
const w2JobS = bench('job/W2 plan + report + G-code').median_s;
const w3JobS = bench('job/W3 plan + report + G-code').median_s;
const w4MeshS = bench('cloud/W4 points: XYZ import + mesh').median_s;
const w4TriS = bench('cloud/W4 points: triangulate').median_s;
const w4SessionS = bench('cloud/W4 points: XYZ + index').median_s;
const memW4 = readFileSync('target/bench/native-memory-w4.txt', 'utf8');
const peakW4 = Number(/peak_rss_bytes=(\d+)/.exec(memW4)?.[1] ?? die('no peak_rss_bytes for W4'));
const readJson = (p) => (existsSync(p) ? JSON.parse(readFileSync(p, 'utf8')) : null);
const e2e = readJson('target/bench/e2e.json');
const ref = readJson('target/bench/e2e-reference.json');

const f = (x, d) => x.toFixed(d);
const ms = (s) => (s < 0.1 ? f(s * 1e3, 1) : f(s * 1e3, 0)) + ' ms';
const yes = (ok) => (ok ? 'yes' : 'no');
const rows = [
  // step, target native, measured native, ok, target wasm, measured wasm, ok
  ['W1 binary PLY import + acceleration structure', '<= 0.8 s', f(plyS, 2) + ' s', plyS <= 0.8,
    '<= 1.2 s', f(wasm.ply_page_s, 2) + ' s (a)', wasm.ply_page_s <= 1.2],
  ['W1 OBJ import', '>= 200 MB/s', f(objMbS, 0) + ' MB/s', objMbS >= 200,
    '>= 120 MB/s', f(wasm.obj_import_mb_s, 0) + ' MB/s (a)', wasm.obj_import_mb_s >= 120],
  ['plan W2 on W1 (project, spline, the default planner with its safe-motion stage, quality)', '<= 5 ms', ms(w2S), w2S <= 0.005,
    '<= 10 ms', ms(wasm.w2_plan_ms / 1e3) + ' (b)', wasm.w2_plan_ms <= 10],
  ['plan W3 on W1', '<= 150 ms', ms(w3S), w3S <= 0.15,
    '<= 250 ms', ms(wasm.w3_plan_ms / 1e3) + ' (b)', wasm.w3_plan_ms <= 250],
  ['peak memory holding W1 ready to plan', '<= 250 MB', f(peakRss / 1e6, 0) + ' MB (c)', peakRss <= 250e6,
    '<= 250 MB', f(wasm.memory_w1_ready_bytes / 1e6, 0) + ' MB (d)', wasm.memory_w1_ready_bytes <= 250e6],
  ['W4 1 M raw points (XYZ): read + 2.5-D Delaunay mesh', '<= 2 s', f(w4MeshS, 2) + ' s (e)', w4MeshS <= 2,
    '-', '-', true],
  ['W4 read + mesh + holes + index (Session)', '-', f(w4SessionS, 2) + ' s', true,
    '-', wasm.w4_session_s == null ? 'not run' : f(wasm.w4_session_s, 2) + ' s', true],
  ['peak memory holding W4 ready to plan', '-', f(peakW4 / 1e6, 0) + ' MB (c)', true, '-', '-', true],
];
if (e2e) {
  const beside = (mine, theirs, unit, scale, d) => theirs == null ? ' (no reference run)'
    : ` (reference ${f(theirs * scale, d)} ${unit}: ${f(theirs / mine, 1)}x)`;
  rows.push(['end to end: `pcpp plan` of W2 on W1.ply, wall clock, every core (f)', '<= 0.2 s',
    f(e2e.wall_median_s, 2) + ' s' + beside(e2e.wall_median_s, ref?.wall_median_s, 's', 1, 2),
    e2e.wall_median_s <= 0.2, '-', '-', true]);
  rows.push(['peak memory of that run (f)', '<= 150 MB',
    f(e2e.peak_bytes / 1e6, 0) + ' MB' + beside(e2e.peak_bytes, ref?.peak_bytes, 'MB', 1e-6, 0),
    e2e.peak_bytes <= 150e6, '-', '-', true]);
}
const e = process.env;
const out = [];
const clock = e.PCPP_BENCH_CLOCK === 'cpu' && wasm.clock === 'cpu'
  ? "CPU time of the thread running each stage (other processes' share left out)"
  : 'wall time';
out.push(`Measured ${new Date().toISOString().slice(0, 10)} on ${e.MACHINE}, stages single-threaded, ` +
  `${clock}; load average ${e.LOAD}; commit ${e.COMMIT}; ${e.RUSTC}; Node ${wasm.node}.`);
out.push(`W1 ${wasm.triangles.toLocaleString('en-US')} triangles (${f(wasm.ply_bytes / 1e6, 1)} MB PLY, ` +
  `${f(wasm.obj_bytes / 1e6, 1)} MB OBJ), W2 ${wasm.w2_points} points, W3 ${wasm.w3_points} points` +
  (e.CELLS !== '1000' ? ` (PCPP_BENCH_N=${e.CELLS}: not the issue's size)` : '') +
  (e.QUICK === '1' ? '; quick run (PCPP_BENCH_QUICK=1)' : '') + '.');
out.push('');
out.push('| step | target native | measured native | target wasm | measured wasm | met? (native / wasm) |');
out.push('|---|---|---|---|---|---|');
for (const [step, tn, mn, okn, tw, mw, okw] of rows) {
  out.push(`| ${step} | ${tn} | ${mn} | ${tw} | ${mw} | ${yes(okn)} / ${yes(okw)} |`);
}
out.push('');
const steps = (t) => `write ${ms(t.read_ms / 1e3)}, import ${ms(t.import_ms / 1e3)}, ` +
  `register (topology, holes) ${ms(t.register_ms / 1e3)}, index ${ms(t.index_ms / 1e3)}, and ` +
  `beside them the SHA-256 ${ms(t.hash_ms / 1e3)}`;
out.push(`(a) In wasm, the page's steps (web/worker.js, each timed; the page finds the file's ` +
  `SHA-256 in a second worker beside the others, as the CLI on a second thread, so the PLY row ` +
  `is the sum of the others): W1.obj ${steps(wasm.obj_staged)}; W1.ply ` +
  `${steps(wasm.ply_staged)}. The OBJ row is the importer alone (importScan). A whole Session ` +
  `from the PLY's bytes, hash included, in one call: ${f(wasm.ply_session_s, 2)} s. From the ` +
  `OBJ's bytes (hash, import, holes, index): ${f(wasm.obj_session_mb_s, 0)} MB/s in ` +
  `wasm, ${f(obj.bytes / 1e6 / objSessionS, 0)} MB/s natively. Natively the stages here run on ` +
  `one thread (PCPP_THREADS=1), the PLY row's SHA-256 (SHA-NI) included.`);
out.push('');
out.push(`(b) Session.plan: the plan, its report and G-code, the G-code converted to JS, the ` +
  `report kept and its JSON not written (the page writes it only for a download, as the CLI ` +
  `only with --report; W3's is 35.6 MB); the same job natively (job::run_on): W2 ${ms(w2JobS)}, ` +
  `W3 ${ms(w3JobS)}.`);
out.push('');
out.push(`(c) Peak resident set (VmHWM) of examples/peak_memory.rs, which prepares the scan as ` +
  `the CLI does (job::prepare_scan_owned: the file's bytes freed once read, then the mesh, its ` +
  `topology and index); ${f(Number(/ rss_bytes=(\d+)/.exec(mem)?.[1] ?? 0) / 1e6, 0)} MB ` +
  `resident once ready.`);
out.push('');
out.push(`(d) memory.buffer.byteLength holding a Session on W1.ply (wasm memory never shrinks: ` +
  `also the peak while preparing it).`);
out.push('');
out.push(`(e) of which the triangulation alone (spade's bulk load, the nearest-neighbour spacing, ` +
  `the edge-length filter) ${f(w4TriS, 2)} s.`);
out.push('');
if (e2e) {
  out.push(`(f) Median of ${e2e.runs} runs of the whole command (read the files, import, hash, ` +
    `index, plan, check every move, write the G-code), wall clock and peak resident set from ` +
    `the kernel (scripts/bench_e2e.py); the reference loads the same PLY with trimesh and ` +
    `projects the points of the G1 moves pcpp wrote for W2 with Embree, nothing more ` +
    `(scripts/reference_trimesh.py): the ratio is how many times longer or larger it is.`);
  out.push('');
}
out.push(`Medians (wasm: W1 imports ${wasm.runs.ply_ms.length}x, plans ${wasm.runs.w2_ms.length}x and ` +
  `${wasm.runs.w3_ms.length}x after a warm-up). The W1 imports follow the demo part, as in the ` +
  `page, which loads it when it opens: the first took ${f(wasm.ply_session_first_s, 2)} s; in a ` +
  `Node that had run nothing it took ${f(wasm.ply_session_cold_s, 2)} s (V8's baseline code ` +
  `throughout). MB = 10^6 bytes.`);
console.log(out.join('\n'));
EOF
