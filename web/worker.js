// The planning Worker: all planning runs here, so the page never freezes;
// cancelling terminates this worker. It keeps one wasm Session (the scan
// imported, registered and indexed) while the scan and its registration
// settings stay the same, and the drawing set on it, so a placement or
// nozzle change re-plans without re-importing or re-reading the SVG.
//
// The scan arrives as a File (or null: a demo part, named by `part`). Posting a File copies no
// bytes; this worker reads it in slices straight into wasm memory
// (ScanBuffer), so the page's main thread never holds the scan and JS never
// holds it whole. The files opened with it (`external`) are read the same
// way, only those the scan names (a .gltf's .bin buffers). Results go back
// as typed arrays whose buffers are transferred, not copied.
import { carryDrawingBy, initSync, initPanicHook, memoryBytes, ScanBuffer, Sha256Stream } from '../pkg/pcpp.js';

// Slices of the file read per step: progress every 8 MiB.
const CHUNK = 8 << 20;
// Above this size the previous scan is freed before the new one is read, so
// a tab holds one large scan at a time (the page still has the previous
// file and re-reads it if the new one fails).
const FREE_FIRST_BYTES = 64 << 20;

let session = null;
let sessionKey = null;
// The session's scan and how it is read (its key without the fiducials'
// registration), and the registration the drawing's placement was last
// made on (`frame`: the registered bounds and matrix): a plan that
// registers the same scan anew carries the drawing from that one to the
// new one. A registration too far off its printer points to plan on (a
// mistyped point, the holes paired wrongly) carries nothing: the drawing
// is carried from the last good one once the points are right.
let sessionScanKey = null;
let frame = null;
// The last drawing the page sent {key, name, bytes}, and the key of the
// one set on the session.
let svg = null;
let pathKey = null;
// The plan in progress (a promise): a G-code check waits for it, so it runs
// on the scan that plan reads.
let planning = Promise.resolve();

const post = (msg, transfer) => self.postMessage(msg, transfer || []);
const mib = (n) => (n / (1 << 20)).toFixed(1);

function errorOf(err) {
  // A trap (out of memory, or a bug) leaves the wasm instance unusable:
  // the page restarts this worker.
  const crashed = typeof WebAssembly !== 'undefined' && err instanceof WebAssembly.RuntimeError;
  const out = {
    message: String((err && err.message) || err),
    kind: crashed ? 'crash' : (err && err.kind) || 'other',
  };
  // G-code refused for its motion: the check's summary, and the planners
  // compared on the same settings.
  if (err && err.touching) out.touching = err.touching;
  // A refusal that accepting the risk would not lift either.
  if (err && err.blocked) out.blocked = true;
  // A scan made huge by stray vertices: no units mend it.
  if (err && err.stray) out.stray = true;
  // A machine profile's field that cannot write the job: {file, field}.
  if (err && err.profile) out.profile = { file: String(err.profile.file), field: String(err.profile.field) };
  if (err && err.comparison) {
    out.comparison = err.comparison;
    out.comparisonNotes = err.comparisonNotes || [];
  }
  // What the refused plan warned of (the drawing's notes, the plan's).
  if (err && err.warnings) out.warnings = err.warnings;
  // A refused plan's paths and placement: the page shows them.
  if (err && err.view) out.view = err.view;
  if (err && err.placement) out.placement = err.placement;
  return out;
}

function progress(id, step, label, fraction, first) {
  post({ type: 'progress', id, stage: step === 'plan' ? 'plan' : 'scan', step, label, fraction, first });
}

// The SHA-256s of scan files found by the page's second worker (this same
// script, `hashFile`), by the page's file key: {promise, resolve, reject}.
// The scan is imported without hashing it and the session is given its
// digest once it is indexed (`loadScan`), as the CLI hashes on a second
// thread beside the import.
const digests = new Map();
function digestOf(key) {
  let e = digests.get(key);
  if (!e) {
    e = {};
    e.promise = new Promise((resolve, reject) => { e.resolve = resolve; e.reject = reject; });
    e.promise.catch(() => {});
    digests.set(key, e);
  }
  return e;
}

// The second worker's task: a file's SHA-256, read in slices.
async function hashFile(m) {
  try {
    const h = new Sha256Stream();
    for (let at = 0; at < m.blob.size; at += CHUNK) {
      h.update(new Uint8Array(await m.blob.slice(at, at + CHUNK).arrayBuffer()));
    }
    const digest = h.finish();
    post({ type: 'hashed', key: m.key, digest }, [digest.buffer]);
  } catch (err) {
    post({ type: 'hashed', key: m.key, error: `could not read ${m.name} to hash it: ${errorOf(err).message}` });
  }
}

// A File read in slices into a new ScanBuffer named `name`, with progress;
// its SHA-256 found here unless `hashed` is false.
async function readFile(id, blob, name, first, hashed = true) {
  progress(id, 'read', `reading ${name} (${mib(blob.size)} MiB)`, 0, first);
  const buf = new ScanBuffer(name, blob.size, hashed);
  try {
    for (let at = 0; at < blob.size; at += CHUNK) {
      const part = new Uint8Array(await blob.slice(at, at + CHUNK).arrayBuffer());
      buf.write(part);
      const done = at + part.length;
      progress(id, 'read', `reading ${name}: ${mib(done)} of ${mib(blob.size)} MiB`, done / blob.size);
    }
  } catch (err) {
    buf.free();
    throw err;
  }
  return buf;
}

// Reads into `buf` the files its scan names (a .gltf's buffers) from
// `files`, matched as the core matches them (the browser gives names
// only); returns those it needs and was not given ({path, file_name}).
async function readExternal(id, buf, files) {
  const missing = [];
  const added = new Set();
  for (const need of buf.externalFiles()) {
    const f = files.find((g) => g.name === need.path) || files.find((g) => g.name === need.file_name);
    if (!f) {
      missing.push(need);
    } else if (!added.has(f)) {
      added.add(f);
      buf.addExternalFile(await readFile(id, f, f.name, false));
    }
  }
  return missing;
}

// Reads, imports, registers and indexes the scan, with a progress message
// between the steps.
async function loadScan(m) {
  const { id } = m;
  const { name, blob } = m.scan;
  const external = m.scan.external || [];
  const t0 = performance.now();
  const size = blob ? external.reduce((n, f) => n + f.size, blob.size) : 0;
  if (session && size > FREE_FIRST_BYTES) {
    session.free();
    session = null;
    sessionKey = null;
    frame = null;
  }
  let buf;
  let missing = [];
  // The page hashes a user's file in its second worker (`m.scan.hashBeside`).
  const beside = !!blob && !!m.scan.hashBeside;
  if (beside && m.scan.sha256) digestOf(m.scan.key).resolve(m.scan.sha256);
  if (blob) {
    buf = await readFile(id, blob, name, true, !beside);
    try {
      missing = await readExternal(id, buf, external);
    } catch (err) {
      buf.free();
      throw err;
    }
  } else {
    buf = ScanBuffer.demoPart(m.scan.part || 'test-part');
  }
  progress(id, 'import', `importing ${name}`, undefined, !blob);
  let imp;
  try {
    imp = buf.importScan(m.scanSettings);
  } catch (err) {
    // The core's message names the file the scan needs; the page says how
    // to give it (not when the scan failed for another reason first, a
    // compressed mesh, say).
    const named = err && err.kind === 'mesh' ? missing.filter((f) => String(err.message).includes(`'${f.path}'`)) : [];
    if (named.length) {
      const files = named.map((f) => f.file_name).join(' and ');
      const how = `select ${name} together with ${files} (both at once in the file dialog, or drop both on the page)`;
      // In place of the core's advice for both the command line and the
      // page, so it is given once (QA: said twice, the second time after
      // no full stop).
      const core = /keep it next to \S+ \(command line\) or select both files together \(page\)/;
      err.message = core.test(err.message)
        ? String(err.message).replace(core, how)
        : `${err.message}\n${how[0].toUpperCase()}${how.slice(1)}.`;
    }
    throw err;
  }
  let s;
  try {
    progress(id, 'register', `finding fiducial holes and registering ${imp.triangles().toLocaleString('en')} triangles`);
    imp.register(m.registration);
    progress(id, 'index', `building the search structure (BVH) over ${imp.triangles().toLocaleString('en')} triangles`);
  } catch (err) {
    imp.free();
    throw err;
  }
  s = imp.index();
  if (session) session.free();
  session = s;
  pathKey = null;
  // Its SHA-256 from the second worker (found by now, as a rule: it reads
  // the file while this one imports and indexes it); a file it could not
  // read fails here, as a scan that cannot be read, and the session goes
  // with it (the page's next plan reads the scan it keeps again). The
  // session refuses to plan or check without it.
  if (beside) {
    let digest;
    try {
      digest = await digestOf(m.scan.key).promise;
    } catch (err) {
      if (session === s) {
        session.free();
        session = null;
        sessionKey = null;
        frame = null;
      }
      throw err;
    }
    // Another scan was read while this one waited (and freed it).
    if (session !== s) throw new Error(`${name} was replaced by another scan while it was read`);
    s.setScanSha256(digest);
  }
  const info = s.info();
  const positions = s.meshPositions();
  const indices = s.meshIndices();
  const seconds = (performance.now() - t0) / 1000;
  progress(id, 'done', `done: ${name}, ${info.triangles.toLocaleString('en')} triangles in ${seconds.toFixed(1)} s`, 1);
  post({ type: 'scan', id, key: m.scan.key, info, seconds, memory: memoryBytes(), positions, indices },
    [positions.buffer, indices.buffer]);
  return info;
}

// A drawing carried with its scan, as the page shows it in its fields and
// plans it: offsets to 1e-4 mm, as the core rounds a centred placement
// (placement::as_shown, which the CLI's --place centre plans too: a
// centred drawing's numbers carry the drawing's import noise, usvg's f32
// mm-to-px scale putting a track centred on 40 mm at 19.99999944368998 mm),
// a scale that is not `sent` to 6 significant digits; a scale kept and the
// rotation are the user's, untouched.
function shownPlacement(p, sent) {
  const mm = (v) => Math.round(v * 1e4) / 1e4 + 0; // + 0: no -0 in a field
  return {
    offset_mm: [mm(p.offset_mm[0]), mm(p.offset_mm[1])],
    rotation_deg: p.rotation_deg,
    scale: p.scale === sent ? p.scale : Number(p.scale.toPrecision(6)),
  };
}

async function plan(m) {
  const { id } = m;
  const key = JSON.stringify([m.scan.key, m.scanSettings, m.registration]);
  let stage = 'scan';
  // The drawing's bytes are kept first: the page sends them once, and a
  // scan that fails to load must not lose them (the next plan, on another
  // scan, would find the drawing before them).
  if (m.svg.bytes) svg = { key: m.svg.key, name: m.svg.name, bytes: m.svg.bytes };
  try {
    if (key !== sessionKey) {
      // The same scan, read the same way and not placed on the bed by hand
      // (the page carries the drawing for that itself), registered anew:
      // the fiducials' printer points were typed again, so the scan stands
      // elsewhere on the printer. The drawing goes with it (below).
      const scanKey = JSON.stringify([m.scan.key, m.scanSettings, m.registration.scan_placement]);
      const was = frame && scanKey === sessionScanKey ? frame : null;
      const info = await loadScan(m);
      sessionKey = key;
      sessionScanKey = scanKey;
      const now = { bbox: info.bbox_mm, matrix: info.registration.matrix };
      const good = info.registration.rms_mm <= m.plan.nozzle.inner_diameter_mm;
      if (!was || m.centre) {
        frame = now;
      } else if (good) {
        frame = now;
        const [lo, hi] = was.bbox;
        const c = carryDrawingBy(m.plan.placement, (lo[2] + hi[2]) / 2, was.matrix, now.matrix);
        const placement = shownPlacement(c, m.plan.placement.scale);
        const sent = m.plan.placement;
        if (placement.offset_mm[0] !== sent.offset_mm[0] || placement.offset_mm[1] !== sent.offset_mm[1]
          || placement.rotation_deg !== sent.rotation_deg) {
          post({ type: 'carried', id, placement });
          m.plan.placement = placement;
        }
      }
    }
    stage = 'plan';
    if (!svg || svg.key !== m.svg.key) throw new Error(`the drawing ${m.svg.name} did not reach the planner; plan again`);
    if (pathKey !== svg.key) {
      session.setPath(svg.bytes, svg.name);
      pathKey = svg.key;
    }
    if (m.centre) {
      // A new scan or drawing: the drawing centred on the scan (the core's
      // centre_drawing), told to the page before planning, so it keeps the
      // placement even if this plan fails. It starts from the user's scale
      // (1 for a new drawing), not from one fitted to another scan.
      // A Scale the user typed is kept (`fit` false), as --place
      // centre,ROT,SCALE keeps it.
      const c = session.centreDrawing({ ...m.plan.placement, scale: m.centre.scale }, m.centre.fit !== false);
      if (c) {
        // Already as the fields show it (the core's placement::as_shown).
        const { placement } = c;
        m.plan.placement = placement;
        post({ type: 'centred', id, placement, note: c.note });
      }
    }
    progress(id, 'plan', m.compare ? 'planning and comparing every planner' : 'planning');
    const t0 = performance.now();
    // The report's JSON is written only when the page asks for it (a
    // download): tens of MB for a large drawing, at every re-plan.
    const r = session.planLive(m.plan, m.dialect, m.acceptRisk, m.profileFile, m.compare, false);
    const planMs = performance.now() - t0;
    const v = r.view;
    const transfer = [r.gcode.buffer, ...viewBuffers(v)];
    for (const sr of r.series || []) transfer.push(sr.error.buffer, sr.defects.buffer);
    post({
      type: 'result', id, gcode: r.gcode, reportId: r.reportId, summary: r.summary, view: v,
      comparison: r.comparison, comparisonNotes: r.comparisonNotes, series: r.series, planMs, memory: memoryBytes(),
    }, transfer);
    post({ type: 'done', id });
  } catch (err) {
    const e = errorOf(err);
    post({ type: 'error', id, stage, ...e }, e.view ? viewBuffers(e.view) : []);
  }
}

// The buffers of a plan's view (its typed arrays), transferred.
const viewBuffers = (v) => [v.pieces.buffer, v.ta.buffer, v.tool.buffer, v.defects.buffer, v.slope.buffer,
  v.kappa.buffer, v.error.buffer];

// A G-code program (a File, read here like the scan, never on the page's
// main thread; or bytes the page sent) given to `run` on the session's
// scan after any plan in flight; `run` returns the answer's fields and
// the buffers to transfer. Answered as `type`, an error included.
async function onProgram(m, type, run) {
  const { id, name } = m;
  try {
    const bytes = m.bytes || new Uint8Array(await m.file.arrayBuffer());
    await planning;
    if (!session) throw new Error('No scan read yet: load a scan (or the demo) first.');
    const [fields, transfer] = run(bytes);
    post({ type, id, name, ...fields }, transfer);
  } catch (err) {
    const e = errorOf(err);
    post({ type, id, name, ...e, error: e.message });
  }
}

// Checks a G-code File against the session's scan.
function check(m) {
  return onProgram(m, 'check', (bytes) => {
    const result = session.checkGcode(bytes, m.name, m.nozzle, m.tol, m.dialect);
    const transfer = result.moves ? [result.moves.buffer, result.kinds.buffer] : [];
    return [{ scan: session.info().name, result }, transfer];
  });
}

// The print preview of a G-code program (the plan's bytes, or a File being
// checked): its moves timed at its feeds and each move's clearance, by the
// core (Session.previewGcode).
function preview(m) {
  return onProgram(m, 'preview', (bytes) => {
    const r = session.previewGcode(bytes, m.name, m.nozzle, m.tol, m.dialect, m.profileFile, m.speed);
    // The bytes go back for the page's line readout: it never reads the
    // file itself.
    return [{ result: r, bytes }, [r.moves.buffer, r.lines.buffer, r.rapid.buffer, r.starts.buffer,
      r.durations.buffer, r.clearance.buffer, r.classes.buffer, bytes.buffer]];
  });
}

self.onmessage = (e) => {
  const m = e.data;
  if (m.type === 'init') {
    try {
      initSync({ module: m.module });
      initPanicHook();
      post({ type: 'ready' });
    } catch (err) {
      post({ type: 'error', id: -1, stage: 'init', ...errorOf(err) });
    }
  } else if (m.type === 'plan') {
    planning = plan(m);
  } else if (m.type === 'hash') {
    hashFile(m);
  } else if (m.type === 'sha256') {
    // A scan's SHA-256 found by the page's second worker (or why not).
    if (m.error) digestOf(m.key).reject(new Error(m.error));
    else digestOf(m.key).resolve(m.digest);
  } else if (m.type === 'check') {
    check(m);
  } else if (m.type === 'preview') {
    preview(m);
  } else if (m.type === 'report') {
    // The JSON report of the last plan (`reportId`), written now.
    try {
      if (!session) throw new Error('no plan to report: the planner holds no scan');
      const bytes = session.reportJson(m.reportId);
      post({ type: 'report', id: m.id, bytes }, [bytes.buffer]);
    } catch (err) {
      post({ type: 'report', id: m.id, error: errorOf(err).message });
    }
  } else if (m.type === 'pick') {
    // The first surface point along the view's ray, on the session's scan.
    if (!session) {
      post({ type: 'pick', id: m.id, error: 'No scan read yet.' });
      return;
    }
    try {
      post({ type: 'pick', id: m.id, hit: session.pick(m.origin, m.direction) });
    } catch (err) {
      post({ type: 'pick', id: m.id, error: errorOf(err).message });
    }
  }
};
