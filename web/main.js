// The page: settings, files, the planning worker, the 3-D view and the
// report. Planning happens only in Rust (the worker's wasm Session, the
// same `job` code as the CLI); this file moves bytes and settings around
// and shows results. Text from files and errors is set with textContent.
import { loadWasm, startWorker } from './engine.js';
import { BEST, fmtPoints, initFiducials, pointsEdited, safePoints, showFiducials } from './fiducials.js';
import {
  SCAN_PLACE_DEFAULT, cancelCentre, centreRequest, initPlacement, moveScan, onCentred, requestCentre,
  sanitizeScanPlace, scanPlacementFor, setNote, showScanPlacement,
} from './placement.js';
import { drawPlot, plannerColor } from './plot.js';
import { keepInput, keptInput } from './store.js';
import {
  Viewer,
  antennaSvg,
  checkProfile,
  checkScanSize,
  checkSvgSize,
  clearanceCapAboveTolMm,
  demoPart,
  demoParts,
  dialects,
  pageLimits,
  parsePoints,
  pathBounds,
  planners,
  version,
} from '../pkg/pcpp.js';

const $ = (id) => document.getElementById(id);
const STORE_KEY = 'pcpp.settings.v1';
// Set while a kept scan is reopened: still set at the next start means the
// page closed or crashed reading it, and it is not reopened again.
const RESTORING_KEY = 'pcpp.restoring.v1';
// Common dispensing-tip gauges: inner / outer diameter, mm.
const GAUGES = [
  ['20 G', 0.603, 0.908],
  ['22 G', 0.413, 0.718],
  ['25 G', 0.26, 0.515],
  ['27 G', 0.21, 0.413],
  ['30 G', 0.159, 0.312],
];
const STAGES = ['read', 'import', 'register', 'index', 'plan'];
const encoder = new TextEncoder();
const decoder = new TextDecoder();

const state = {
  // The accepted scan {key, name, size, blob}: blob is the user's File
  // (handed to the worker, which reads it) or null for the demo.
  scan: null,
  pendingScan: null, // a scan loaded but not yet read by the worker
  svgFile: null, // the accepted SVG file {key, name, bytes}
  pendingSvg: null,
  svgMade: null, // the last generated path {key, name, bytes} (antennas, demo)
  nextKey: 1,
  module: null,
  worker: null,
  sentSvgKey: null, // the drawing whose bytes the current worker holds
  busy: null, // the plan request in flight
  queued: false, // a newer request waits for it: only the newest is planned
  // Every change of an input or setting counts up; a plan is offered for
  // download only if nothing changed since it was requested.
  gen: 0,
  planId: 0,
  lastPlan: null,
  // The last comparison of every planner {rows, series, gen} (series: the
  // per-point errors of each planner, for the plot; null after a failed plan).
  lastComparison: null,
  demoParts: new Map(), // demo part name -> its drawing and settings (wasm demoPart)
  checkId: 0, // the G-code check in flight
  checking: null, // {id, name} of the check in flight
  checkMoves: null, // the last checked program's {moves, kinds} for the view
  viewShowsCheck: false, // the view draws those moves instead of the plan
  interacting: false, // a drag or slider in progress: skip the comparison
  centre: null, // {token}: the next plan centres the drawing on the scan (placement.js)
  info: null, // the scan as the worker read it
  viewer: null,
  redraw: 0,
  frames: 0, // frames the view has drawn (tests read the rate)
  debounce: 0,
  memory: 0, // the worker's wasm memory after the last scan read (bytes)
  keeping: 0, // writes of the last inputs to the browser's store under way
  progressTimer: 0,
  progressLabel: '',
  urls: [],
  picking: false, // "pick on mesh" mode: a click on the view adds a scan point
  moving: false, // "move path" mode: a drag in the view moves the placement
  pickId: 0,
  // Re-planning figures: plans finished, the last planner time and the
  // last time from request to plan on screen (ms), requests sent while
  // another was in flight (always 0: never a backlog).
  stats: { plans: 0, planMs: [], latencyMs: [], overlapped: 0 },
  progressLog: [], // progress labels of the last scan read (tests read it)
};

let settings = null;

// ---------- settings ----------

// A built-in demo part (wasm demoPart): its drawing, names and settings,
// made once per part.
function demoInfo(name) {
  let info = state.demoParts.get(name);
  if (!info) {
    info = demoPart(name);
    state.demoParts.set(name, info);
  }
  return info;
}

function demoUiSettings(part = 'test-part') {
  const d = demoInfo(part).settings;
  const pl = d.plan.placement;
  return {
    demoPart: part,
    scanUnits: '',
    scanUp: '',
    scanMaxEdge: '',
    fidSource: d.registration.fiducials === 'auto' ? 'auto' : 'none',
    fidMethod: d.registration.method,
    dotDiameter: d.registration.dot_diameter_mm,
    // An unregistered scan placed on the bed (placement.js).
    scanPlace: { ...SCAN_PLACE_DEFAULT },
    fidScanText: '',
    fidPrinterText: fmtPoints(d.registration.printer_points),
    pathSource: 'demo',
    spiral: { turns: null, pitch_mm: 1.5, inner_radius_mm: 1 },
    hilbert: { order: 3, size_mm: 20 },
    monopole: { height_mm: 20, base_mm: 15, feed_mm: 5 },
    placement: { x: pl.offset_mm[0], y: pl.offset_mm[1], rot: pl.rotation_deg, scale: pl.scale },
    nozzle: { id: d.plan.nozzle.inner_diameter_mm, od: d.plan.nozzle.outer_diameter_mm },
    process: {
      tol: d.plan.process.tolerance_mm,
      speed: d.plan.process.speed_mm_s,
      dwell: d.plan.process.dwell_s,
    },
    planner: d.plan.planner,
    dialect: 'marlin',
    // A user's machine profile {name, file, text}; dialect 'custom' uses it.
    customProfile: null,
    acceptRisk: false,
  };
}

function loadSettings() {
  const base = demoUiSettings();
  try {
    const saved = JSON.parse(localStorage.getItem(STORE_KEY) || 'null');
    if (saved && typeof saved === 'object') {
      for (const k of Object.keys(base)) {
        if (!(k in saved)) continue;
        const b = base[k];
        base[k] = b && typeof b === 'object' ? { ...b, ...saved[k] } : saved[k];
      }
    }
  } catch {
    // Unreadable saved settings: start from the demo's.
  }
  // A saved "SVG file" source needs the kept SVG (restoreInputs).
  const cp = base.customProfile;
  if (!cp || typeof cp.text !== 'string' || typeof cp.name !== 'string') base.customProfile = null;
  if (base.dialect === 'custom' && !base.customProfile) base.dialect = 'marlin';
  if (!demoParts().some((p) => p.name === base.demoPart)) base.demoPart = 'test-part';
  if (!planners().includes(base.planner)) base.planner = demoUiSettings().planner;
  base.scanPlace = sanitizeScanPlace(base.scanPlace);
  return base;
}

function saveSettings() {
  try {
    localStorage.setItem(STORE_KEY, JSON.stringify(settings));
  } catch {
    // Private mode or a full quota: settings just do not persist.
  }
}

const num = (v) => (v === null || v === '' || v === undefined ? NaN : Number(v));

// What the library reads: a `job::JobSettings` for planning on `scan`.
function jobSettings(scan) {
  const s = settings;
  let fiducials = 'none';
  let printer = [];
  if (s.fidSource !== 'none' && !(scan && scan.unregistered)) {
    printer = parseField('printer points P', s.fidPrinterText);
    fiducials = s.fidSource === 'auto' ? 'auto' : { points: parseField('scan points Sr', s.fidScanText) };
  }
  const dot = num(s.dotDiameter);
  if (!(dot > 0)) throw new Error('fiducial dot diameter: type a diameter in mm, greater than 0 (default 1)');
  return {
    scan: {
      units: s.scanUnits || null,
      up_axis: s.scanUp || null,
      max_edge_mm: String(s.scanMaxEdge ?? '').trim() === '' ? null : num(s.scanMaxEdge),
    },
    registration: {
      fiducials,
      printer_points: printer,
      method: s.fidMethod,
      dot_diameter_mm: dot,
      scan_placement: scanPlacementFor(scan),
    },
    plan: {
      nozzle: { inner_diameter_mm: num(s.nozzle.id), outer_diameter_mm: num(s.nozzle.od) },
      process: {
        tolerance_mm: num(s.process.tol),
        speed_mm_s: num(s.process.speed),
        dwell_s: num(s.process.dwell),
      },
      planner: s.planner,
      placement: {
        offset_mm: [num(s.placement.x), num(s.placement.y)],
        rotation_deg: num(s.placement.rot),
        scale: num(s.placement.scale),
      },
    },
  };
}

function parseField(label, text) {
  try {
    return parsePoints(text || '');
  } catch (e) {
    throw new Error(`${label}: ${e.message}`);
  }
}

function antennaParams(kind) {
  const p = { ...settings[kind] };
  if (kind === 'spiral' && (p.turns === null || p.turns === '' || Number.isNaN(p.turns))) delete p.turns;
  for (const k of Object.keys(p)) p[k] = num(p[k]);
  if (kind === 'hilbert') p.order = Math.round(p.order);
  return p;
}

// The path to plan: {key, name, bytes}. Generated paths are keyed by their
// parameters and made once per key (a drag re-plans many times a second).
function currentSvg() {
  const made = (key, name, text) => {
    if (!state.svgMade || state.svgMade.key !== key) {
      state.svgMade = { key, name, bytes: encoder.encode(text()) };
    }
    return state.svgMade;
  };
  switch (settings.pathSource) {
    case 'file': {
      const f = state.pendingSvg || state.svgFile;
      if (!f) throw new Error('no SVG file loaded: open one, or choose another path source');
      return f;
    }
    case 'spiral':
    case 'hilbert':
    case 'monopole': {
      const kind = settings.pathSource;
      const params = antennaParams(kind);
      return made(`antenna-${kind}-${JSON.stringify(params)}`, `antenna-${kind}.svg`,
        () => antennaSvg(kind, params));
    }
    default: {
      const part = demoInfo(settings.demoPart);
      return made(`demo-${part.name}`, part.path_name, () => part.svg);
    }
  }
}

// ---------- form binding ----------

// [element id, getter, setter, when to re-plan]: 'live' on every input
// event at once (sliders; the comparison of every planner waits for the
// release), 'typed' on every keystroke after a short pause, otherwise on
// change. Re-plans are coalesced: only the newest settings are planned.
const FIELDS = [
  ['scan-units', () => settings.scanUnits, (v) => { settings.scanUnits = v; }],
  ['scan-up', () => settings.scanUp, (v) => { settings.scanUp = v; }],
  ['scan-max-edge', () => settings.scanMaxEdge, (v) => { settings.scanMaxEdge = v; }],
  ['fid-source', () => settings.fidSource, (v) => { settings.fidSource = v; }],
  ['fid-method', () => settings.fidMethod, (v) => { settings.fidMethod = v; }],
  ['fid-dot', () => settings.dotDiameter, (v) => { settings.dotDiameter = v === '' ? NaN : Number(v); }, 'typed'],
  ['fid-scan', () => settings.fidScanText, (v) => { settings.fidScanText = v; }],
  ['fid-printer', () => settings.fidPrinterText, (v) => { settings.fidPrinterText = v; }],
  ['path-source', () => settings.pathSource, (v) => { settings.pathSource = v; }],
  ['sp-turns', () => settings.spiral.turns, (v) => { settings.spiral.turns = v === '' ? null : Number(v); }],
  ['sp-pitch', () => settings.spiral.pitch_mm, (v) => { settings.spiral.pitch_mm = Number(v); }],
  ['sp-inner', () => settings.spiral.inner_radius_mm, (v) => { settings.spiral.inner_radius_mm = Number(v); }],
  ['hb-order', () => settings.hilbert.order, (v) => { settings.hilbert.order = Number(v); }],
  ['hb-size', () => settings.hilbert.size_mm, (v) => { settings.hilbert.size_mm = Number(v); }],
  ['mp-height', () => settings.monopole.height_mm, (v) => { settings.monopole.height_mm = Number(v); }],
  ['mp-base', () => settings.monopole.base_mm, (v) => { settings.monopole.base_mm = Number(v); }],
  ['mp-feed', () => settings.monopole.feed_mm, (v) => { settings.monopole.feed_mm = Number(v); }],
  ['pl-x', () => settings.placement.x, (v) => { settings.placement.x = Number(v); }, 'typed'],
  ['pl-y', () => settings.placement.y, (v) => { settings.placement.y = Number(v); }, 'typed'],
  ['pl-rot', () => settings.placement.rot, (v) => { settings.placement.rot = Number(v); }, 'typed'],
  ['pl-scale', () => settings.placement.scale, (v) => { settings.placement.scale = Number(v); }, 'typed'],
  ['pl-rot-range', () => settings.placement.rot, (v) => { settings.placement.rot = Number(v); }, 'live'],
  ['pl-scale-range', () => settings.placement.scale, (v) => { settings.placement.scale = Number(v); }, 'live'],
  ['nz-id', () => settings.nozzle.id, (v) => { settings.nozzle.id = Number(v); }, 'typed'],
  ['nz-od', () => settings.nozzle.od, (v) => { settings.nozzle.od = Number(v); }, 'typed'],
  ['pr-tol', () => settings.process.tol, (v) => { settings.process.tol = Number(v); }, 'typed'],
  ['pr-speed', () => settings.process.speed, (v) => { settings.process.speed = Number(v); }, 'typed'],
  ['pr-dwell', () => settings.process.dwell, (v) => { settings.process.dwell = Number(v); }, 'typed'],
  ['planner', () => settings.planner, (v) => { settings.planner = v; }],
  ['dialect', () => settings.dialect, (v) => { settings.dialect = v; }],
  ['accept-risk', () => settings.acceptRisk, (v) => { settings.acceptRisk = v; }],
];

function writeForm() {
  for (const [id, get] of FIELDS) {
    const el = $(id);
    const v = get();
    if (el.type === 'checkbox') el.checked = !!v;
    else el.value = v === null || v === undefined || (typeof v === 'number' && Number.isNaN(v)) ? '' : String(v);
  }
  syncGauge();
  syncVisibility();
}

function syncGauge() {
  const id = Number(settings.nozzle.id);
  const od = Number(settings.nozzle.od);
  const i = GAUGES.findIndex(([, a, b]) => a === id && b === od);
  $('gauge').value = i >= 0 ? String(i) : 'custom';
}

function syncVisibility() {
  const part = demoInfo(settings.demoPart);
  $('path-source').querySelector('option[value="demo"]').textContent = `demo: ${part.name} drawing`;
  $('demo-part').value = part.name;
  $('demo-part').title = part.description;
  for (const k of ['spiral', 'hilbert', 'monopole']) $(`antenna-${k}`).hidden = settings.pathSource !== k;
  $('fid-scan-wrap').hidden = settings.fidSource !== 'points' && !state.picking;
  const svg = settings.pathSource === 'file' ? state.pendingSvg || state.svgFile : null;
  $('svg-name').textContent = settings.pathSource === 'file'
    ? (svg ? svg.name : 'no SVG file loaded')
    : $('path-source').selectedOptions[0].textContent;
}

// Number fields and their sliders show the same setting.
const PAIRS = { 'pl-rot': 'pl-rot-range', 'pl-rot-range': 'pl-rot', 'pl-scale': 'pl-scale-range', 'pl-scale-range': 'pl-scale' };

// Writes one field from the settings (not the one being typed in: that
// would rewrite "1." as "1" under the user's cursor).
function writeField(id) {
  const f = FIELDS.find((x) => x[0] === id);
  if (!f) return;
  const el = $(id);
  const v = f[1]();
  el.value = v === null || v === undefined || (typeof v === 'number' && Number.isNaN(v)) ? '' : String(v);
}

function bindForm() {
  for (const [id, , set, mode] of FIELDS) {
    const el = $(id);
    // Antenna SVGs measure from their page's corner, so a new size moves
    // the antenna; keep its centre where the user placed it.
    const antennaField = /^(sp|hb|mp)-/.test(id);
    const handler = () => {
      const before = antennaField ? pathCentre() : null;
      const value = el.type === 'checkbox' ? el.checked : el.value;
      // A new profile has its own bed: a scan placed on it moves, and the
      // drawing with it.
      if (id === 'dialect') moveScan(() => set(value));
      else set(value);
      if (/^pl-/.test(id)) {
        // The user places the drawing: no centring over it.
        cancelCentre();
        setNote('');
      }
      if (id === 'fid-printer' || id === 'fid-scan') pointsEdited();
      const after = before ? pathCentre() : null;
      if (before && after) {
        const [dx, dy] = placed([before[0] - after[0], before[1] - after[1]]);
        settings.placement.x = +(num(settings.placement.x) + dx).toFixed(3);
        settings.placement.y = +(num(settings.placement.y) + dy).toFixed(3);
        writeForm();
      }
      if (PAIRS[id]) writeField(PAIRS[id]);
      saveSettings();
      syncGauge();
      syncVisibility();
      showScanPlacement();
      if (id === 'path-source' && ['spiral', 'hilbert', 'monopole'].includes(settings.pathSource)) {
        requestCentre(true);
      }
      if (mode === 'live') {
        state.interacting = true;
        planNow();
      } else {
        schedulePlan(mode === 'typed' ? 120 : 350);
      }
    };
    el.addEventListener(mode || el.tagName === 'TEXTAREA' ? 'input' : 'change', handler);
    if (mode === 'live') {
      // The slider is let go: plan once more with the comparison.
      el.addEventListener('change', () => endInteraction());
    }
  }
  const gauge = $('gauge');
  GAUGES.forEach(([name, id, od], i) => gauge.add(new Option(`${name}  (${id} / ${od} mm)`, String(i))));
  gauge.add(new Option('custom', 'custom'));
  gauge.addEventListener('change', () => {
    const g = GAUGES[Number(gauge.value)];
    if (!g) return;
    settings.nozzle.id = g[1];
    settings.nozzle.od = g[2];
    saveSettings();
    writeForm();
    schedulePlan(0);
  });
  const dialect = $('dialect');
  for (const d of dialects()) dialect.add(new Option(d, d));
  const planner = $('planner');
  for (const p of planners()) planner.add(new Option(p, p));
  const plot = $('plot-series');
  plot.add(new Option('every planner', 'all'));
  for (const p of planners()) plot.add(new Option(p, p));
  plot.addEventListener('change', showErrorPlot);
  const demo = $('demo-part');
  for (const p of demoParts()) {
    const o = new Option(p.name, p.name);
    o.title = p.description;
    demo.add(o);
  }
  demo.addEventListener('change', () => loadDemo(demo.value));
  syncProfileOption();
}

// The dialect list's entry for the user's own profile, if one is loaded.
function syncProfileOption() {
  const dialect = $('dialect');
  let opt = dialect.querySelector('option[value="custom"]');
  const cp = settings.customProfile;
  if (!cp) {
    if (opt) opt.remove();
    return;
  }
  if (!opt) {
    opt = new Option('', 'custom');
    dialect.add(opt);
  }
  opt.textContent = `custom: ${cp.name} (${cp.file})`;
}

// ---------- errors and status ----------

function showError(title, message) {
  $('error-title').textContent = title;
  $('error-message').textContent = message;
  $('error-panel').hidden = false;
}

function clearError() {
  $('error-panel').hidden = true;
}

function setStatus(text, stale) {
  const el = $('plan-status');
  el.textContent = text;
  el.classList.toggle('stale', !!stale);
}

const GCODE_LABEL = 'Download G-code';
const RISKY_LABEL = 'Download G-code (the nozzle touches the part)…';
const CONFIRM_LABEL = 'Download anyway (the nozzle touches the part)';

function hideDownloads() {
  const g = $('dl-gcode');
  g.hidden = true;
  $('dl-report').hidden = true;
  for (const u of state.urls) URL.revokeObjectURL(u);
  state.urls = [];
  g.removeAttribute('href');
  $('dl-report').removeAttribute('href');
  g.textContent = GCODE_LABEL;
  g.classList.remove('risky', 'armed');
  g.removeAttribute('tabindex');
  state.risky = null;
  $('risk-warning').hidden = true;
}

function linkBytes(el, bytes, type, name) {
  const url = URL.createObjectURL(new Blob([bytes], { type }));
  state.urls.push(url);
  el.href = url;
  el.download = name;
  el.hidden = false;
}

// The G-code and report as the planner wrote them (bytes, no string copy).
// G-code whose moves touch the part (written because the risk was accepted)
// has no link until the user confirms: the first click turns the button
// into "Download anyway", the second downloads.
function offerDownloads(plan) {
  hideDownloads();
  const stem = plan.svgName.replace(/\.[^.]*$/, '') || 'path';
  const gcodeName = `${stem}-${plan.planner}.gcode`;
  const motion = plan.summary.motion;
  if (motion.risk_accepted) {
    const g = $('dl-gcode');
    state.risky = { plan, name: gcodeName };
    g.textContent = RISKY_LABEL;
    g.classList.add('risky');
    g.tabIndex = 0;
    g.hidden = false;
    $('risk-warning-text').textContent = `safe motion: ${plan.summary.motion_line}`;
    $('risk-warning').hidden = false;
  } else {
    linkBytes($('dl-gcode'), plan.gcodeBytes, 'text/plain', gcodeName);
  }
  linkBytes($('dl-report'), plan.reportBytes, 'application/json', `${stem}-${plan.planner}.json`);
}

// The first click on a touching plan's G-code asks for the second.
function onGcodeClick(e) {
  const r = state.risky;
  const g = $('dl-gcode');
  if (!r || g.classList.contains('armed')) return;
  e.preventDefault();
  linkBytes(g, r.plan.gcodeBytes, 'text/plain', r.name);
  g.textContent = CONFIRM_LABEL;
  g.classList.add('armed');
}

function showProgress(stage, label, fraction) {
  $('progress').hidden = false;
  const at = STAGES.indexOf(stage);
  for (const li of $('stages').children) {
    const i = STAGES.indexOf(li.dataset.stage);
    li.classList.toggle('active', i === at);
    li.classList.toggle('done', at >= 0 && i < at);
  }
  $('progress-label').textContent = label || '';
  const bar = $('progress-bar');
  bar.hidden = stage !== 'read' || !(fraction >= 0);
  if (!bar.hidden) bar.value = fraction;
}

// A plan's progress and Cancel appear only once it has taken a moment:
// during a drag, plans of a few milliseconds would make the toolbar flicker.
const PROGRESS_DELAY_MS = 250;

function laterProgress(label) {
  state.progressLabel = label;
  if (state.progressTimer || !$('progress').hidden) return;
  state.progressTimer = setTimeout(() => {
    state.progressTimer = 0;
    if (!state.busy) return;
    $('cancel-btn').hidden = false;
    showProgress('plan', state.progressLabel);
  }, PROGRESS_DELAY_MS);
}

function endProgress() {
  clearTimeout(state.progressTimer);
  state.progressTimer = 0;
  $('progress').hidden = true;
  $('cancel-btn').hidden = true;
}

// ---------- planning ----------

// Something the plan depends on changed: the G-code on offer is stale from
// this moment, not from when the new plan starts.
function markChanged() {
  state.gen++;
  hideDownloads();
  if (state.lastPlan) setStatus('settings changed: re-planning…', true);
}

function schedulePlan(delay) {
  markChanged();
  clearTimeout(state.debounce);
  state.debounce = setTimeout(requestPlan, delay);
}

// A live change (drag, slider): planned at once if the worker is free,
// else right after the plan in flight (the newest settings only).
function planNow() {
  markChanged();
  requestPlan();
}

function endInteraction() {
  if (!state.interacting) return;
  state.interacting = false;
  saveSettings();
  // Once more with the comparison of every planner (the surface path is
  // kept by the worker, so this only plans).
  requestPlan();
}

function requestPlan() {
  clearTimeout(state.debounce);
  if (state.busy) {
    state.queued = true;
    return;
  }
  runPlan();
}

function runPlan() {
  const scan = state.pendingScan || state.scan;
  let job;
  let svg;
  try {
    job = jobSettings(scan);
    svg = currentSvg();
  } catch (e) {
    showError('Cannot plan', e.message);
    setStatus(state.lastPlan ? 'plan failed: showing the previous plan' : 'plan failed', true);
    return;
  }
  if (state.busy) state.stats.overlapped++;
  const id = ++state.planId;
  const compare = !state.interacting;
  const centre = centreRequest();
  state.busy = { id, gen: state.gen, scan, svg, job, planner: job.plan.planner, compare, centre, t0: performance.now() };
  state.queued = false;
  laterProgress('starting');
  if (!state.interacting) setStatus('planning…');
  // The worker keeps the last drawing it was sent: its bytes go only when
  // the drawing changes, as a copy whose buffer is transferred.
  const msgSvg = { key: svg.key, name: svg.name };
  const transfer = [];
  if (state.sentSvgKey !== svg.key) {
    msgSvg.bytes = svg.bytes.slice();
    transfer.push(msgSvg.bytes.buffer);
    state.sentSvgKey = svg.key;
  }
  state.worker.postMessage({
    type: 'plan',
    id,
    // A File is a handle: posting it copies no bytes (the worker reads it).
    scan: { key: scan.key, name: scan.name, blob: scan.blob, part: scan.part },
    scanSettings: job.scan,
    registration: job.registration,
    svg: msgSvg,
    plan: job.plan,
    // A built-in name, or the user's profile as JSON text (named by its file).
    dialect: settings.dialect === 'custom' && settings.customProfile
      ? settings.customProfile.text : settings.dialect,
    profileFile: settings.dialect === 'custom' && settings.customProfile
      ? settings.customProfile.file : undefined,
    acceptRisk: !!settings.acceptRisk,
    compare,
    // Centre the drawing on the scan before planning (a new scan or drawing).
    centre,
  }, transfer);
}

function finish() {
  state.busy = null;
  endProgress();
  if (state.queued) runPlan();
}

// What the page keeps of a plan: the bytes to download (decoded to text
// only when asked), what the tables show and the per-point arrays.
function keptPlan(m, busy) {
  let gcode = null;
  let reportJson = null;
  return {
    gcodeBytes: m.gcode,
    reportBytes: m.report,
    get gcode() { gcode ??= decoder.decode(m.gcode); return gcode; },
    get reportJson() { reportJson ??= decoder.decode(m.report); return reportJson; },
    summary: m.summary,
    view: m.view,
    svgName: busy.svg.name,
    planner: busy.planner,
    // What the worker planned (it may have centred the drawing).
    placement: m.summary.settings.placement,
    gen: busy.gen,
    compared: !!m.comparison,
  };
}

function onWorkerMessage(e) {
  const m = e.data;
  const busy = state.busy;
  if (m.type === 'ready') return;
  if (m.type === 'pick') {
    onPick(m);
    return;
  }
  if (m.type === 'check') {
    onCheck(m);
    return;
  }
  if (!busy || m.id !== busy.id) {
    if (m.type === 'error' && m.stage === 'init') showError('Could not start the planner', m.message);
    return;
  }
  switch (m.type) {
    case 'progress':
      if (m.stage === 'scan') {
        if (m.first) state.progressLog = [];
        state.progressLog.push(m.label);
        // Reading a scan takes a while: shown at once.
        $('cancel-btn').hidden = false;
        showProgress(m.step === 'done' ? 'plan' : m.step, m.label, m.fraction);
      } else {
        if ($('progress').hidden) laterProgress(m.label);
        else showProgress('plan', m.label);
      }
      break;
    case 'scan':
      if (state.pendingScan && state.pendingScan.key === m.key) {
        acceptScan();
      }
      state.memory = m.memory;
      showScan(m.info, m.positions, m.indices, m.seconds);
      break;
    case 'centred':
      onCentred(m, busy);
      break;
    case 'result': {
      if (settings.pathSource === 'file' && state.pendingSvg && busy.svg === state.pendingSvg) {
        state.svgFile = state.pendingSvg;
        state.pendingSvg = null;
        keep('svg', { name: state.svgFile.name, bytes: state.svgFile.bytes });
      }
      state.lastPlan = keptPlan(m, busy);
      const latency = performance.now() - busy.t0;
      const st = state.stats;
      st.plans++;
      st.planMs.push(m.planMs);
      st.latencyMs.push(latency);
      if (st.planMs.length > 1000) { st.planMs.shift(); st.latencyMs.shift(); }
      $('plan-time').textContent = `plan ${Math.round(m.planMs)} ms, on screen ${Math.round(latency)} ms after the change`;
      clearError();
      if (m.comparison) state.lastComparison = { rows: m.comparison, series: m.series, gen: busy.gen };
      showPlan(state.lastPlan);
      if (busy.gen === state.gen) {
        offerDownloads(state.lastPlan);
        const touching = m.summary.motion.program.touching_moves;
        setStatus(touching > 0
          ? `planned ${busy.svg.name} on ${state.scan.name} with ${busy.planner}: ${touching} move(s) touch the part; `
            + 'the G-code downloads only after a confirmation'
          : `planned ${busy.svg.name} on ${state.scan.name} with ${busy.planner}`, touching > 0);
      } else {
        // Shown while the user goes on changing things; not offered.
        setStatus('settings changed: re-planning…', true);
      }
      if (m.comparison) showComparison(m.comparison, busy.planner, m.summary.settings.process.tolerance_mm);
      else $('compare-table').classList.add('stale');
      break;
    }
    case 'done':
      finish();
      break;
    case 'error':
      onPlanError(m, busy);
      finish();
      break;
    default:
      break;
  }
}

function onPlanError(m, busy) {
  let title = 'Planning failed';
  let message = m.message;
  if (m.kind === 'crash') {
    // The wasm instance trapped (most likely out of memory): a new worker.
    restartWorker();
    title = m.stage === 'scan' ? `The planner ran out of memory or failed reading ${busy.scan.name}` : 'The planner stopped';
    message += '\nThe planner was restarted';
    if (state.pendingScan && busy.scan === state.pendingScan) {
      if (state.pendingScan.restored) {
        endRestoring();
        keep('scan', null);
      }
      state.pendingScan = null;
      dropCentre();
      message += `; still using the previous scan, ${state.scan.name}`;
    }
    message += '.';
    $('scan-name').textContent = state.scan.name;
  } else if (m.stage === 'scan' && (m.kind === 'mesh' || m.kind === 'limit' || m.kind === 'other')
    && state.pendingScan && busy.scan === state.pendingScan) {
    // The file could not be read: keep working with the previous scan.
    title = `Could not read the scan ${state.pendingScan.name}`;
    if (state.pendingScan.restored) {
      endRestoring();
      keep('scan', null);
    }
    state.pendingScan = null;
    dropCentre();
    $('scan-name').textContent = state.scan.name;
    message += `\nStill using the previous scan, ${state.scan.name}.`;
  } else if (m.stage === 'scan') {
    title = m.kind === 'mesh' ? 'Could not read the scan' : 'Registration failed';
    if (state.pendingScan && busy.scan === state.pendingScan) {
      // Readable but not registered: it stays loaded until the fiducials fit.
      acceptScan();
      $('scan-name').textContent = state.scan.name;
    }
  } else if (m.kind === 'svg' && state.pendingSvg && busy.svg === state.pendingSvg) {
    title = `Could not read the SVG ${state.pendingSvg.name}`;
    state.pendingSvg = null;
    // The drawing stays where it was.
    cancelCentre();
    if (!state.svgFile) settings.pathSource = 'demo';
    writeForm();
    message += state.svgFile
      ? `\nStill using the previous SVG, ${state.svgFile.name}.`
      : '\nBack to the demo paths.';
  } else if (m.kind === 'limit') {
    title = 'The path is too long for the page';
  } else if (m.kind === 'touching') {
    title = `The nozzle would touch the part with ${busy.planner}: no G-code`;
    message += '\nThe settings, the drawing and the previous plan stay as they were.';
  }
  // A plan refused for its motion still compared the planners on the
  // settings that failed: the table shows why.
  if (m.comparison) {
    state.lastComparison = { rows: m.comparison, series: null, gen: busy.gen };
    showComparison(m.comparison, busy.planner, busy.job.plan.process.tolerance_mm);
  }
  showError(title, message);
  // Nothing stale on offer; the previous plan stays on screen, where it was
  // planned.
  hideDownloads();
  if (state.viewer) {
    state.viewer.setPathOffset(0, 0, 0);
    requestDraw();
  }
  setStatus(state.lastPlan ? 'plan failed: showing the previous plan, no download' : 'plan failed', true);
}

// A file that could not be read changes nothing: no centring for it (a
// new drawing opened with it is still centred).
function dropCentre() {
  if (state.centre && !state.centre.fresh) cancelCentre();
}

// The pending scan was read: it becomes the scan, and the demo's fiducial
// settings it was read without are dropped for good.
function acceptScan() {
  const scan = state.pendingScan;
  state.scan = scan;
  state.pendingScan = null;
  if (scan.restored) endRestoring();
  else keep('scan', scan.blob ? { name: scan.name, file: scan.blob } : null);
  if (scan.unregistered) {
    delete scan.unregistered;
    settings.fidSource = 'none';
    saveSettings();
    writeForm();
  }
  if (scan.asScanned) {
    // A new scan is read as it is; the banner offers to place it.
    delete scan.asScanned;
    settings.scanPlace = { ...SCAN_PLACE_DEFAULT };
    saveSettings();
  }
  showScanPlacement();
}

function cancelPlan() {
  if (!state.busy) return;
  // The only way to stop wasm mid-computation: end the worker.
  restartWorker();
  state.busy = null;
  state.queued = false;
  endProgress();
  hideDownloads();
  setStatus('cancelled', true);
}

function restartWorker() {
  state.worker.terminate();
  state.worker = makeWorker();
  if (state.checking) {
    // The new worker never got the check in flight.
    $('check-verdict').textContent = `${state.checking.name} was not checked: the planner was restarted; check it again`;
    $('check-verdict').className = 'verdict bad';
    state.checking = null;
  }
}

function makeWorker() {
  const w = startWorker(state.module);
  // A new worker holds no scan and no drawing.
  state.sentSvgKey = null;
  w.onmessage = onWorkerMessage;
  w.onerror = (e) => {
    showError('The planner stopped', e.message || 'the worker failed to load');
    state.busy = null;
    endProgress();
  };
  return w;
}

// ---------- showing results ----------

const fmt = (v, d = 3) => (v === null || v === undefined || !Number.isFinite(v) ? '∞' : v.toFixed(d));

function showScan(info, positions, indices, seconds) {
  state.info = info;
  $('scan-name').textContent = info.name;
  const [lo, hi] = info.bbox_mm;
  $('scan-info').textContent = `${info.format.toUpperCase()}, ${info.triangles.toLocaleString('en')} triangles, `
    + `${fmt(hi[0] - lo[0], 1)} × ${fmt(hi[1] - lo[1], 1)} × ${fmt(hi[2] - lo[2], 1)} mm (${info.units}); `
    + `${(info.bytes / (1 << 20)).toFixed(1)} MiB read in ${fmt(seconds, 1)} s; `
    + `planner memory ${(state.memory / (1 << 30)).toFixed(2)} of 4 GiB`
    + (info.cloud_text ? `; ${info.cloud_text}` : '');
  if (state.viewer) {
    try {
      state.viewer.setMesh(positions, indices);
    } catch (e) {
      showError('Could not draw the scan', e.message);
    }
  }
  showFiducials();
  updateMarkers();
  showScanPlacement();
  requestDraw();
}

// G (the registration, row-major 4 x 4) applied to a scanner-frame point.
function applyG(m, p) {
  return [0, 1, 2].map((r) => m[r][0] * p[0] + m[r][1] * p[1] + m[r][2] * p[2] + m[r][3]);
}

// Holes, printer points P and the typed or picked scan points Sr, drawn in
// the view's (printer) frame.
function updateMarkers() {
  const info = state.info;
  if (state.viewer && info) {
    const printer = settings.fidSource === 'none' ? [] : safePoints(settings.fidPrinterText);
    const showScan = settings.fidSource === 'points' || state.picking;
    const picked = showScan
      ? safePoints(settings.fidScanText).map((p) => applyG(info.registration.matrix, p)) : [];
    try {
      // The holes listed (the best candidates), not every scanner hole.
      const holes = info.holes.filter((h) => h.candidate).slice(0, BEST);
      state.viewer.setMarkers(holes.map((h) => h.printer), printer, picked);
    } catch (e) {
      showError('Could not draw the fiducials', e.message);
    }
    requestDraw();
  }
}

function showPlan(plan) {
  const { summary, view } = plan;
  if (state.viewer) {
    try {
      state.viewer.setPathArrays(view.pieces, view.ta, view.tool, view.defects);
    } catch (e) {
      showError('Could not draw the paths', e.message);
    }
    setViewShowsCheck(false);
    updateDragOffset();
    requestDraw();
  }
  const st = summary.stats;
  const pl = summary.settings.placement;
  const rows = [
    ['placement', `(${pl.offset_mm[0]}, ${pl.offset_mm[1]}) mm, ${pl.rotation_deg}°, × ${pl.scale}`, 'shown-placement'],
    ['pieces', st.subpaths],
    ['points', st.points],
    ['tool-path length', `${fmt(st.length_mm, 2)} mm`],
    ['height change', `${fmt(st.height_change_mm)} mm`],
    ['max inclination', `${fmt(st.max_inclination_deg, 1)}°`],
    ['min radius of curvature', `${fmt(st.min_radius_mm)} mm`],
    ['print time', `${fmt(st.print_time_s, 1)} s`],
    ['registration RMS', `${fmt(summary.registration_rms_mm, 4)} mm`],
  ];
  const body = $('stats-table').tBodies[0];
  body.replaceChildren(...rows.map(([k, v, id]) => {
    const tr = document.createElement('tr');
    const a = document.createElement('td');
    const b = document.createElement('td');
    a.textContent = k;
    b.textContent = String(v);
    if (id) b.id = id;
    tr.append(a, b);
    return tr;
  }));
  $('warnings').replaceChildren(...summary.warnings.map((w) => {
    const li = document.createElement('li');
    li.textContent = w;
    return li;
  }));
  showMotion(summary);
  // A long path's plot waits for the end of a drag.
  if (!state.interacting || view.defects.length < 20000) showErrorPlot();
}

// The plot of the plan on screen: every planner's errors (the last
// comparison, if it was made for this plan), or one planner's coloured by
// defect. During a drag only the plan being dragged is drawn.
function showErrorPlot() {
  const plan = state.lastPlan;
  if (!plan) return;
  const { view, summary } = plan;
  const c = state.lastComparison;
  const n = view.defects.length;
  const series = c && c.gen === plan.gen && c.series && c.series.every((x) => x.error.length === n)
    ? c.series
    : [{ planner: plan.planner, error: view.error, defects: view.defects }];
  const choice = $('plot-series').value;
  let shown;
  if (choice === 'all') {
    // The planner on screen last, on top of the others.
    shown = [...series.filter((x) => x.planner !== plan.planner), ...series.filter((x) => x.planner === plan.planner)];
  } else {
    shown = series.filter((x) => x.planner === choice);
  }
  $('plot-legend').replaceChildren(...(choice === 'all' ? series : []).map((x) => {
    const li = document.createElement('li');
    const sw = document.createElement('i');
    sw.className = 'sw';
    sw.style.background = plannerColor(x.planner);
    li.append(sw, x.planner);
    return li;
  }));
  $('plot-note').textContent = shown.length === 0
    ? `${choice}: compared after the drag or change ends`
    : choice === 'all' ? `${shown.length} planner(s), one colour each` : `${choice}, coloured by predicted defect`;
  drawPlot($('plot'), view, shown, choice === 'all', summary.settings.nozzle.inner_diameter_mm);
}

// A clearance as the tables show it: null is "more than tol + the cap"
// (the planners' check finds the smallest clearance only that far).
function fmtClearance(c, tol) {
  return c === null || c === undefined ? `>${fmt(tol + clearanceCapAboveTolMm())}` : fmt(c);
}

function cell(tr, text, cls, title) {
  const td = document.createElement('td');
  td.textContent = text;
  if (cls) td.className = cls;
  if (title) td.title = title;
  tr.append(td);
  return td;
}

function showComparison(rows, selected, tol) {
  $('compare-table').classList.remove('stale');
  const body = $('compare-table').tBodies[0];
  body.replaceChildren(...rows.map((r) => {
    const q = r.quality;
    const mo = r.motion;
    const tr = document.createElement('tr');
    tr.dataset.planner = r.planner;
    if (r.planner === selected) tr.className = 'selected';
    for (const v of [r.planner, fmt(q.mean_abs_error_mm, 4), fmt(q.mean_negative_error_mm, 4),
      fmt(q.mean_positive_error_mm, 4), `${fmt(q.contact_pct, 1)}%`, `${fmt(q.flattening_pct, 1)}%`,
      `${fmt(q.floating_pct, 1)}%`, `${fmt(q.contact_pct + q.flattening_pct + q.floating_pct, 1)}%`]) {
      cell(tr, v);
    }
    cell(tr, String(mo.backward_moves), 'backward');
    const t = mo.tol_mm ?? tol;
    // Below tol the nozzle touches (or comes too close to) the surface.
    const touching = mo.touching_moves > 0 || (mo.min_clearance_mm !== null && mo.min_clearance_mm < t);
    cell(tr, fmtClearance(mo.min_clearance_mm, t), touching ? 'clearance bad' : 'clearance',
      touching ? `${mo.touching_moves} print move(s) closer than tol = ${t} mm` : `tol = ${t} mm`);
    cell(tr, String(mo.waypoints), 'waypoints');
    return tr;
  }));
}

// The plan's quality and safe motion (spec section 6f): the check of every
// move its G-code commands, next to the predicted quality.
function showMotion(summary) {
  const q = summary.quality;
  const m = summary.motion;
  const p = m.program;
  const touching = p.touching_moves > 0;
  let clear = 'no move passes near the scan';
  if (p.min_clearance_mm !== null && p.min_clearance_mm !== undefined) {
    const at = p.min_clearance_at ? ` at (${p.min_clearance_at.map((v) => fmt(v, 2)).join(', ')})` : '';
    const line = p.min_clearance_line ? `, G-code line ${p.min_clearance_line}` : '';
    clear = `${fmt(p.min_clearance_mm)} mm${at}${line}`;
  }
  const rows = [
    ['planner', summary.planner],
    ['predicted quality', `mean |e| ${fmt(q.mean_abs_error_mm, 4)} mm; defects `
      + `${fmt(q.contact_pct + q.flattening_pct + q.floating_pct, 1)}% (contact ${fmt(q.contact_pct, 1)}%, `
      + `flattening ${fmt(q.flattening_pct, 1)}%, floating ${fmt(q.floating_pct, 1)}%)`],
    ['min clearance, all moves', clear, 'motion-min-clear', touching ? 'bad' : ''],
    ['moves too close (< tol)', `${p.touching_moves} of ${p.moves} (tol ${m.tol_mm} mm)`, 'motion-touching',
      touching ? 'bad' : ''],
    ['waypoints added', `${m.waypoints} (+${fmt(m.extra_length_mm)} mm)`, 'motion-waypoints'],
    ['backward moves', String(m.backward_moves), 'motion-backward'],
    ['max sideways offset', `${fmt(m.max_sideways_mm)} mm`],
  ];
  if (m.risk_accepted) rows.push(['risk', 'accepted: G-code with moves closer than tol', 'motion-risk', 'bad']);
  const body = $('motion-table').tBodies[0];
  body.replaceChildren(...rows.map(([k, v, id, cls]) => {
    const tr = document.createElement('tr');
    cell(tr, k);
    const td = cell(tr, v, cls);
    if (id) td.id = id;
    return tr;
  }));
  $('motion-touches').replaceChildren(...p.touching.slice(0, 5).map((t) => {
    const li = document.createElement('li');
    li.textContent = fmtTouch(t);
    return li;
  }));
}

// A touching move in the core's words (motion::Touch's Display).
function fmtTouch(t) {
  return `${t.line ? `line ${t.line}: ` : ''}the move ${fmtPoint(t.from)} -> ${fmtPoint(t.to)} comes too close at `
    + `${fmtPoint(t.at)}: the nozzle would have to be ${fmt(t.rise_mm)} mm higher there`;
}

// ---------- files ----------

// G-code programs a user may check against the scan (by their extension).
const GCODE_FILE = /\.(gcode|gco|g|nc|ngc|tap|txt)$/i;

async function openFile(file) {
  if (/\.svg$/i.test(file.name)) {
    await openSvg(file);
    return;
  }
  if (GCODE_FILE.test(file.name)) {
    checkGcodeFile(file);
    return;
  }
  // Past the page's limit the file is refused before a byte is read, and
  // the loaded scan stays.
  try {
    checkScanSize(file.name, file.size);
  } catch (e) {
    showError(`Could not open the scan ${file.name}`,
      `${e.message}\nStill using ${state.scan ? state.scan.name : 'no scan'}.`);
    return;
  }
  // The File itself goes to the worker, which reads it into wasm memory:
  // the scan's bytes never pass through this thread or a JS string.
  const entry = { key: `file-${state.nextKey++}`, name: file.name, size: file.size, blob: file };
  state.pendingScan = entry;
  // The demo's fiducials belong to the demo part: a new scan is read
  // unregistered until the user sets its fiducials (the settings change
  // only once the scan is read, so a bad file changes nothing).
  const demo = demoUiSettings();
  if (settings.fidSource === 'auto' && settings.fidPrinterText === demo.fidPrinterText) {
    entry.unregistered = true;
  }
  // A new scan is read as it is (the banner offers to place it on the bed),
  // and the drawing is centred on it.
  if (settings.scanPlace.on) entry.asScanned = true;
  requestCentre();
  $('scan-name').textContent = `${state.scan ? state.scan.name : '—'} (reading ${file.name}…)`;
  saveSettings();
  writeForm();
  schedulePlan(0);
}

async function openSvg(file) {
  try {
    checkSvgSize(file.name, file.size);
  } catch (e) {
    showError(`Could not open the SVG ${file.name}`, e.message);
    return;
  }
  let bytes;
  try {
    // Bytes go to wasm as a Uint8Array, never through a JS string.
    bytes = new Uint8Array(await file.arrayBuffer());
  } catch (e) {
    showError(`Could not read ${file.name}`, e.message);
    return;
  }
  state.pendingSvg = { key: `file-${state.nextKey++}`, name: file.name, bytes };
  settings.pathSource = 'file';
  // A new drawing lands on the scan.
  requestCentre(true);
  saveSettings();
  writeForm();
  schedulePlan(0);
}

// A user's machine profile: checked by the core (the error names the file
// and the field); a bad file changes nothing, the previous dialect stays.
async function openProfile(file) {
  let text;
  try {
    text = await file.text();
  } catch (e) {
    showError(`Could not read ${file.name}`, e.message);
    return;
  }
  let name;
  try {
    name = checkProfile(text, file.name);
  } catch (e) {
    showError(`Could not use the machine profile ${file.name}`,
      `${e.message}\nStill using ${$('dialect').selectedOptions[0]?.textContent || settings.dialect}.`);
    return;
  }
  clearError();
  // Its bed may differ: a scan placed on the bed moves with it.
  moveScan(() => {
    settings.customProfile = { name, file: file.name, text };
    settings.dialect = 'custom';
  });
  syncProfileOption();
  showScanPlacement();
  saveSettings();
  writeForm();
  schedulePlan(0);
}

// ---------- checking a G-code file against the scan ----------

// A user's G-code (ours or another tool's) checked by the core against the
// scan the worker holds, with the nozzle and tol of the settings: the
// worker reads the File (as it reads a scan), after any plan in flight.
function checkGcodeFile(file) {
  const limit = pageLimits().gcode_bytes;
  if (file.size > limit) {
    const message = `${file.name}: the file is ${(file.size / (1 << 20)).toFixed(1)} MiB, more than the `
      + `${limit / (1 << 20)} MiB the G-code check reads; split the program and check each part`;
    showCheckError(file.name, message);
    return;
  }
  const s = settings;
  const id = ++state.checkId;
  const nozzle = { inner_diameter_mm: num(s.nozzle.id), outer_diameter_mm: num(s.nozzle.od) };
  const tol = num(s.process.tol);
  state.checking = { id, name: file.name };
  state.checkMoves = null;
  $('check-draw').hidden = true;
  $('check-panel').hidden = false;
  $('check-verdict').textContent = `checking ${file.name}…`;
  $('check-verdict').className = 'verdict';
  $('check-details').replaceChildren();
  state.worker.postMessage({ type: 'check', id, file, name: file.name, nozzle, tol });
}

function showCheckError(name, message) {
  state.checkMoves = null;
  $('check-draw').hidden = true;
  if (state.viewShowsCheck) drawCheckedMoves(false);
  $('check-panel').hidden = false;
  $('check-verdict').textContent = `could not check ${name}`;
  $('check-verdict').className = 'verdict bad';
  $('check-details').replaceChildren();
  showError(`Could not check ${name}`, message);
}

// A move that comes too close, as the core's own message words it.
const fmtPoint = (p) => `(${p.map((v) => fmt(v)).join(', ')})`;

function onCheck(m) {
  if (m.id !== state.checkId) return;
  state.checking = null;
  if (m.error) {
    showCheckError(m.name, m.error);
    return;
  }
  const c = m.result;
  const sum = c.summary;
  const verdict = $('check-verdict');
  const against = `${c.file.name} against ${m.scan} (nozzle outer diameter ${c.outer_diameter_mm} mm, tol ${c.tol_mm} mm)`;
  verdict.textContent = c.clear
    ? `clear: none of the ${sum.moves} moves comes closer than tol; ${against}`
    : `${sum.touching_moves} of ${sum.moves} moves touch: closer than tol; ${against}`;
  verdict.className = c.clear ? 'verdict good' : 'verdict bad';
  const details = [];
  const p = (text, id, cls) => {
    const el = document.createElement('p');
    el.textContent = text;
    if (id) el.id = id;
    if (cls) el.className = cls;
    details.push(el);
    return el;
  };
  p(sum.min_clearance_mm === null || sum.min_clearance_mm === undefined
    ? 'minimum clearance: no move passes near the scan'
    : `minimum clearance ${fmt(sum.min_clearance_mm)} mm`
      + `${sum.min_clearance_line ? ` at line ${sum.min_clearance_line}` : ''}`
      + `${sum.min_clearance_at ? ` ${fmtPoint(sum.min_clearance_at)}` : ''}`,
  'check-min', sum.min_clearance_mm !== null && sum.min_clearance_mm < c.tol_mm ? 'bad' : '');
  if (sum.touching.length) {
    const table = document.createElement('table');
    table.id = 'check-touching';
    table.className = 'num';
    const head = table.createTHead().insertRow();
    for (const h of ['line', 'move from → to', 'worst at', 'clearance mm', 'higher by mm']) {
      const th = document.createElement('th');
      th.textContent = h;
      head.append(th);
    }
    const body = table.createTBody();
    for (const t of sum.touching) {
      const tr = body.insertRow();
      cell(tr, t.line ? String(t.line) : '—', 'line');
      cell(tr, `${fmtPoint(t.from)} → ${fmtPoint(t.to)}`);
      cell(tr, fmtPoint(t.at));
      cell(tr, fmt(t.clearance_mm));
      cell(tr, fmt(t.rise_mm), 'bad');
    }
    details.push(table);
    if (sum.touching_moves > sum.touching.length) {
      p(`… and ${sum.touching_moves - sum.touching.length} more touching move(s)`);
    }
  }
  if (c.unchecked_lines.length) {
    p(`${c.unchecked_lines.length} move(s) not checked (their position is not in the file): lines `
      + `${c.unchecked_lines.slice(0, 10).join(', ')}${c.unchecked_lines.length > 10 ? ', …' : ''}`, 'check-unchecked');
  }
  if (c.notes.length) {
    const ul = document.createElement('ul');
    ul.id = 'check-notes';
    ul.className = 'warnings small';
    for (const n of c.notes) {
      const li = document.createElement('li');
      li.textContent = n;
      ul.append(li);
    }
    details.push(ul);
  }
  $('check-details').replaceChildren(...details);
  state.checkMoves = c.moves ? { moves: c.moves, kinds: c.kinds } : null;
  $('check-draw').hidden = !state.checkMoves;
  if (state.viewShowsCheck) drawCheckedMoves(!!state.checkMoves);
}

// The view draws the checked program's moves (on) or the plan's paths.
function drawCheckedMoves(on) {
  if (!state.viewer) return;
  try {
    if (on && state.checkMoves) {
      state.viewer.setMoves(state.checkMoves.moves, state.checkMoves.kinds);
    } else if (state.lastPlan) {
      const v = state.lastPlan.view;
      state.viewer.setPathArrays(v.pieces, v.ta, v.tool, v.defects);
      updateDragOffset();
    } else {
      state.viewer.setPathArrays(new Uint32Array(0), new Float32Array(0), new Float32Array(0), new Uint8Array(0));
    }
  } catch (e) {
    showError('Could not draw the moves', e.message);
    return;
  }
  setViewShowsCheck(on && !!state.checkMoves);
  requestDraw();
}

function setViewShowsCheck(on) {
  state.viewShowsCheck = on;
  const b = $('check-draw');
  b.setAttribute('aria-pressed', on ? 'true' : 'false');
  b.textContent = on ? 'Back to the plan in the 3-D view' : 'Draw in the 3-D view';
}

function bindFiles() {
  $('check-draw').addEventListener('click', () => drawCheckedMoves(!state.viewShowsCheck));
  const gcodeInput = $('gcode-input');
  gcodeInput.addEventListener('change', () => {
    const f = gcodeInput.files && gcodeInput.files[0];
    if (f) checkGcodeFile(f);
    gcodeInput.value = '';
  });
  const profileInput = $('profile-input');
  profileInput.addEventListener('change', () => {
    const f = profileInput.files && profileInput.files[0];
    if (f) openProfile(f);
    profileInput.value = '';
  });
  for (const id of ['scan-input', 'svg-input']) {
    const input = $(id);
    input.addEventListener('change', () => {
      const f = input.files && input.files[0];
      if (f) openFile(f);
      input.value = '';
    });
  }
  const overlay = $('drop-overlay');
  let depth = 0;
  window.addEventListener('dragenter', (e) => {
    e.preventDefault();
    depth++;
    overlay.hidden = false;
  });
  window.addEventListener('dragleave', () => {
    depth = Math.max(0, depth - 1);
    if (depth === 0) overlay.hidden = true;
  });
  window.addEventListener('dragover', (e) => e.preventDefault());
  window.addEventListener('drop', (e) => {
    e.preventDefault();
    depth = 0;
    overlay.hidden = true;
    for (const f of e.dataTransfer.files) openFile(f);
  });
}

// A demo part's scan: the worker makes its bytes itself.
function demoScanEntry(part) {
  const info = demoInfo(part);
  return { key: `demo-${info.name}`, name: info.scan_name, size: 0, blob: null, part: info.name };
}

// Loads a demo part: its scan, drawing, placement and fiducials (the test
// part's three holes; the other parts are made in the printer frame).
function loadDemo(part = settings.demoPart) {
  const demo = demoUiSettings(part);
  settings.demoPart = demo.demoPart;
  settings.fidSource = demo.fidSource;
  settings.fidMethod = demo.fidMethod;
  settings.fidPrinterText = demo.fidPrinterText;
  settings.pathSource = 'demo';
  settings.placement = demo.placement;
  settings.scanUnits = '';
  settings.scanUp = '';
  settings.scanMaxEdge = '';
  // The demo parts are made in the printer frame, placed where they print.
  settings.scanPlace = { ...SCAN_PLACE_DEFAULT };
  cancelCentre();
  setNote('');
  state.pendingScan = null;
  state.scan = demoScanEntry(settings.demoPart);
  $('scan-name').textContent = state.scan.name;
  state.svgFile = null;
  state.pendingSvg = null;
  keep('scan', null);
  keep('svg', null);
  saveSettings();
  writeForm();
  schedulePlan(0);
}

// The centre of the path's box as imported (before placement), or null.
function pathCentre() {
  try {
    const svg = currentSvg();
    const b = pathBounds(svg.bytes, svg.name);
    return [(b[0] + b[2]) / 2, (b[1] + b[3]) / 2];
  } catch {
    return null;
  }
}

// A drawing-frame vector after the placement's rotation and scale.
function placed([x, y]) {
  const s = num(settings.placement.scale);
  const a = (num(settings.placement.rot) * Math.PI) / 180;
  return [s * (Math.cos(a) * x - Math.sin(a) * y), s * (Math.sin(a) * x + Math.cos(a) * y)];
}

// ---------- picking scan points on the mesh ----------

function setPicking(on) {
  state.picking = on;
  if (on && state.moving) setMoving(false);
  const b = $('pick-btn');
  b.setAttribute('aria-pressed', on ? 'true' : 'false');
  b.textContent = on ? 'Picking: click the scan (Esc stops)' : 'Pick on mesh';
  $('view').classList.toggle('picking', on);
  $('pick-status').textContent = on ? 'Click the 3-D view where a scan point Sr is; drag still turns the view.' : '';
  syncVisibility();
  updateMarkers();
}

// Asks the worker (which holds the scan) where the camera ray through the
// clicked pixel first meets the mesh.
function pickAt(x, y) {
  let ray;
  try {
    ray = state.viewer.pickRay(x, y);
  } catch (e) {
    $('pick-status').textContent = e.message;
    return;
  }
  if (!state.info) {
    $('pick-status').textContent = 'No scan read yet.';
    return;
  }
  state.worker.postMessage({ type: 'pick', id: ++state.pickId, origin: ray.slice(0, 3), direction: ray.slice(3, 6) });
}

function onPick(m) {
  if (m.id !== state.pickId) return;
  if (m.error) {
    $('pick-status').textContent = m.error;
    return;
  }
  if (!m.hit) {
    $('pick-status').textContent = 'That click missed the scan.';
    return;
  }
  const pts = safePoints(settings.fidScanText);
  pts.push(m.hit.scan);
  settings.fidScanText = fmtPoints(pts);
  const nPrinter = safePoints(settings.fidPrinterText).length;
  $('pick-status').textContent = `Picked Sr${pts.length} (${m.hit.scan.map((v) => fmt(v)).join(', ')}); `
    + `${pts.length} of ${nPrinter} printer point(s) P.`;
  // Register as soon as every P has its scan point (not before: fewer
  // points cannot register).
  const ready = pts.length === nPrinter && pts.length >= 3;
  if (ready) settings.fidSource = 'points';
  saveSettings();
  writeForm();
  updateMarkers();
  if (ready) schedulePlan(0);
}

// ---------- moving the path on the scan ----------

function setMoving(on) {
  state.moving = on;
  $('move-btn').setAttribute('aria-pressed', on ? 'true' : 'false');
  $('view').classList.toggle('moving', on);
  if (on && state.picking) setPicking(false);
}

// The device pixel of a pointer event on the canvas.
function canvasPixel(canvas, e) {
  const rect = canvas.getBoundingClientRect();
  return [(e.clientX - rect.left) * (canvas.width / rect.width),
    (e.clientY - rect.top) * (canvas.height / rect.height)];
}

// Where the camera ray through a pixel meets the plane z = zPlane (printer
// frame): the point of the scan the pointer holds during a drag. Null when
// the ray runs parallel to the plane or away from it.
function groundPoint([px, py], zPlane) {
  let r;
  try {
    r = state.viewer.pickRay(px, py);
  } catch {
    return null;
  }
  const [ox, oy, oz, dx, dy, dz] = r;
  if (Math.abs(dz) < 1e-9) return null;
  const t = (zPlane - oz) / dz;
  if (!(t > 0)) return null;
  return [ox + t * dx, oy + t * dy];
}

// The height a drag moves the path at: the mean of the surface path on
// screen, else the scan's middle (in the top view any height gives the
// same XY).
function dragPlaneZ() {
  const v = state.lastPlan && state.lastPlan.view;
  if (v && v.ta.length >= 3) {
    let z = 0;
    for (let i = 2; i < v.ta.length; i += 3) z += v.ta[i];
    return z / (v.ta.length / 3);
  }
  const [lo, hi] = state.info.bbox_mm;
  return (lo[2] + hi[2]) / 2;
}

// Offsets are kept to 0.01 mm: what the fields show is what is planned.
const round2 = (v) => Math.round(v * 100) / 100;

function movePlacementTo(x, y) {
  const nx = round2(x);
  const ny = round2(y);
  if (nx === num(settings.placement.x) && ny === num(settings.placement.y)) return;
  settings.placement.x = nx;
  settings.placement.y = ny;
  cancelCentre();
  setNote('');
  writeField('pl-x');
  writeField('pl-y');
  state.interacting = true;
  updateDragOffset();
  planNow();
}

// While the placement differs from that of the plan on screen by a shift
// only, the view draws that plan shifted, so the path follows the pointer
// at the frame rate while the plan at the new placement is computed.
function updateDragOffset() {
  if (!state.viewer) return;
  const p = state.lastPlan && state.lastPlan.placement;
  const s = settings.placement;
  let dx = 0;
  let dy = 0;
  if (p && p.rotation_deg === num(s.rot) && p.scale === num(s.scale)) {
    dx = num(s.x) - p.offset_mm[0];
    dy = num(s.y) - p.offset_mm[1];
    if (!Number.isFinite(dx) || !Number.isFinite(dy)) {
      dx = 0;
      dy = 0;
    }
  }
  state.viewer.setPathOffset(dx, dy, 0);
  requestDraw();
}

// ---------- 3-D view ----------

function requestDraw() {
  if (!state.viewer || state.redraw) return;
  state.redraw = requestAnimationFrame(() => {
    state.redraw = 0;
    state.frames++;
    state.viewer.draw();
  });
}

function bindView() {
  const canvas = $('view');
  try {
    state.viewer = new Viewer(canvas);
  } catch (e) {
    showError('No 3-D view', e.message);
    return;
  }
  const resize = () => {
    const dpr = window.devicePixelRatio || 1;
    const w = Math.max(1, Math.round(canvas.clientWidth * dpr));
    const h = Math.max(1, Math.round(canvas.clientHeight * dpr));
    if (canvas.width !== w || canvas.height !== h) {
      canvas.width = w;
      canvas.height = h;
    }
    state.viewer.resize(w, h);
    requestDraw();
  };
  new ResizeObserver(resize).observe(canvas);
  resize();
  let drag = null;
  canvas.addEventListener('contextmenu', (e) => e.preventDefault());
  canvas.addEventListener('pointerdown', (e) => {
    drag = {
      x: e.clientX, y: e.clientY, x0: e.clientX, y0: e.clientY,
      pan: e.button === 2 || e.button === 1 || e.shiftKey,
      move: null,
    };
    // Move mode, or Ctrl/Alt/Cmd-drag in any mode: the drag moves the path.
    const wantMove = e.button === 0 && !e.shiftKey && (state.moving || e.ctrlKey || e.altKey || e.metaKey);
    if (wantMove && state.info) {
      const z = dragPlaneZ();
      const g = groundPoint(canvasPixel(canvas, e), z);
      if (g) {
        drag.move = { z, g0: g, px: num(settings.placement.x), py: num(settings.placement.y), moved: false };
      }
    }
    canvas.setPointerCapture(e.pointerId);
  });
  canvas.addEventListener('pointermove', (e) => {
    if (!drag) return;
    if (drag.move) {
      const g = groundPoint(canvasPixel(canvas, e), drag.move.z);
      if (!g) return;
      drag.move.moved = true;
      movePlacementTo(drag.move.px + g[0] - drag.move.g0[0], drag.move.py + g[1] - drag.move.g0[1]);
      return;
    }
    const dpr = window.devicePixelRatio || 1;
    const dx = (e.clientX - drag.x) * dpr;
    const dy = (e.clientY - drag.y) * dpr;
    drag.x = e.clientX;
    drag.y = e.clientY;
    if (drag.pan) state.viewer.pan(dx, dy);
    else state.viewer.orbit(dx, dy);
    requestDraw();
  });
  const end = () => {
    if (drag && drag.move && drag.move.moved) endInteraction();
    drag = null;
  };
  canvas.addEventListener('pointerup', (e) => {
    // In pick mode a click (no drag) picks; a drag still turns the view.
    if (drag && !drag.move && state.picking && !drag.pan
      && Math.hypot(e.clientX - drag.x0, e.clientY - drag.y0) < 4) {
      const [px, py] = canvasPixel(canvas, e);
      pickAt(px, py);
    }
    end();
  });
  canvas.addEventListener('pointercancel', end);
  canvas.addEventListener('wheel', (e) => {
    e.preventDefault();
    state.viewer.zoom(e.deltaMode === 1 ? e.deltaY * 20 : e.deltaY);
    requestDraw();
  }, { passive: false });
  // In move mode the arrow keys nudge the path: 0.5 mm, 5 mm with Shift.
  const ARROWS = { ArrowLeft: [-1, 0], ArrowRight: [1, 0], ArrowUp: [0, 1], ArrowDown: [0, -1] };
  canvas.addEventListener('keydown', (e) => {
    const d = ARROWS[e.key];
    if (!state.moving || !d) return;
    e.preventDefault();
    const step = e.shiftKey ? 5 : 0.5;
    movePlacementTo(num(settings.placement.x) + d[0] * step, num(settings.placement.y) + d[1] * step);
  });
  canvas.addEventListener('keyup', (e) => { if (ARROWS[e.key]) endInteraction(); });
  $('reset-view').addEventListener('click', () => { state.viewer.resetView(); requestDraw(); });
  $('top-view').addEventListener('click', () => { state.viewer.topView(); requestDraw(); });
  $('move-btn').addEventListener('click', () => setMoving(!state.moving));
}

// ---------- the last inputs, kept for the next visit ----------

// Writes to the browser's store in the background; `state.keeping` counts
// the writes not finished (tests wait for 0 before reloading).
function keep(kind, value) {
  state.keeping++;
  keepInput(kind, value)
    .catch(() => {
      // Not kept (quota, private mode): the next visit starts without it.
    })
    .finally(() => { state.keeping--; });
}

function endRestoring() {
  try {
    localStorage.removeItem(RESTORING_KEY);
  } catch {
    // Nothing to clear.
  }
}

// Reopens the scan and SVG of the last visit, if the browser kept them.
async function restoreInputs() {
  let svg;
  let scan;
  try {
    [svg, scan] = await Promise.all([keptInput('svg'), keptInput('scan')]);
  } catch {
    svg = null;
    scan = null;
  }
  if (svg && svg.bytes instanceof Uint8Array && typeof svg.name === 'string') {
    state.svgFile = { key: `file-${state.nextKey++}`, name: svg.name, bytes: svg.bytes };
  } else if (settings.pathSource === 'file') {
    settings.pathSource = 'demo';
  }
  if (!scan || !(scan.file instanceof Blob) || typeof scan.name !== 'string') return;
  let crashed = null;
  try {
    crashed = localStorage.getItem(RESTORING_KEY);
    localStorage.setItem(RESTORING_KEY, scan.name);
  } catch {
    // Without localStorage there is no crash guard; reopen anyway.
  }
  if (crashed !== null) {
    endRestoring();
    keep('scan', null);
    showError(`The last scan, ${crashed}, was not reopened`,
      'The page closed or stopped while reading it last time. Open it again if you need it.');
    return;
  }
  state.pendingScan = {
    key: `file-${state.nextKey++}`, name: scan.name, size: scan.file.size, blob: scan.file, restored: true,
  };
  $('scan-name').textContent = `${state.scan.name} (reopening ${scan.name}…)`;
}

// ---------- start ----------

async function start() {
  try {
    state.module = await loadWasm();
  } catch (e) {
    showError('Could not load the planner (WebAssembly)', e.message);
    return;
  }
  $('version').textContent = `v${version()}`;
  $('scan-limit').textContent = `${pageLimits().scan_bytes / (1 << 20)} MiB`;
  settings = loadSettings();
  const page = {
    state,
    settings: () => settings,
    saveSettings,
    writeForm,
    schedulePlan,
    showError,
    clearError,
    updateMarkers,
    // The profile to write with: [dialect or the profile's JSON, its file
    // name, the name to show].
    profile: () => (settings.dialect === 'custom' && settings.customProfile
      ? [settings.customProfile.text, settings.customProfile.file, settings.customProfile.name]
      : [settings.dialect, undefined, settings.dialect]),
  };
  initPlacement(page);
  initFiducials(page);
  bindForm();
  writeForm();
  bindFiles();
  bindView();
  $('plan-btn').addEventListener('click', requestPlan);
  $('cancel-btn').addEventListener('click', cancelPlan);
  $('demo-btn').addEventListener('click', () => loadDemo($('demo-part').value));
  $('dl-gcode').addEventListener('click', onGcodeClick);
  $('dl-gcode').addEventListener('keydown', (e) => {
    // A touching plan's button has no link until confirmed: keys click it.
    if ((e.key === 'Enter' || e.key === ' ') && state.risky && !$('dl-gcode').classList.contains('armed')) {
      onGcodeClick(e);
    }
  });
  $('center-btn').addEventListener('click', () => {
    // The core centres it on the scan's footprint, scaled down to fit.
    requestCentre();
    schedulePlan(0);
  });
  $('error-close').addEventListener('click', clearError);
  $('pick-btn').addEventListener('click', () => setPicking(!state.picking));
  $('clear-scan-btn').addEventListener('click', () => {
    settings.fidScanText = '';
    $('pick-status').textContent = '';
    saveSettings();
    writeForm();
    updateMarkers();
    if (settings.fidSource === 'points') schedulePlan(0);
  });
  window.addEventListener('keydown', (e) => { if (e.key === 'Escape' && state.picking) setPicking(false); });
  state.worker = makeWorker();
  state.scan = demoScanEntry(settings.demoPart);
  $('scan-name').textContent = state.scan.name;
  await restoreInputs();
  writeForm();
  // For tests and the curious: read-only access to the page's state.
  window.pcpp = { state, get settings() { return settings; } };
  requestPlan();
}

start();
