// The settings and their form: defaults (the demo part's), storage in
// localStorage, the settings object the core reads (job::JobSettings), the
// path to plan (a file, an antenna or a demo drawing) and the binding of
// every field, which re-plans as it changes.
import {
  antennaSvg, demoPart, demoParts, dialects, parsePoints, pathBounds, planners,
} from '../pkg/pcpp.js';
import { fmtPoints, pointsEdited } from './fiducials.js';
import { $, hooks, num, settings, state } from './page.js';
import {
  SCAN_PLACE_DEFAULT, enterReading, leaveReading, moveScan, requestCentre, sanitizeFit, sanitizeScanPlace,
  scanPlacementFor, showScanPlacement, userPlaced,
} from './placement.js';

const STORE_KEY = 'pcpp.settings.v1';
// Common dispensing-tip gauges: inner / outer diameter, mm.
const GAUGES = [
  ['20 G', 0.603, 0.908],
  ['22 G', 0.413, 0.718],
  ['25 G', 0.26, 0.515],
  ['27 G', 0.21, 0.413],
  ['30 G', 0.159, 0.312],
];
const encoder = new TextEncoder();

// A built-in demo part (wasm demoPart): its drawing, names and settings,
// made once per part.
export function demoInfo(name) {
  let info = state.demoParts.get(name);
  if (!info) {
    info = demoPart(name);
    state.demoParts.set(name, info);
  }
  return info;
}

export function demoUiSettings(part = 'test-part') {
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
    // The page's fit of the drawing to the scan: null while the scale is
    // the user's, else {userScale, note}: the page scaled the drawing from
    // the user's scale down to `placement.scale` to fit the scan, as the
    // core's note says. The next scan is fitted from the user's scale.
    fit: null,
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
    // Whether the demo drawing on the user's scan was last planned where
    // the user placed it (main.js's `demoOnUserScan`): kept over a reload,
    // where the scan is read again (QA round 5 N6).
    demoMoved: false,
  };
}

export function loadSettings() {
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
  base.fit = sanitizeFit(base.fit);
  return base;
}

// The path source a pending drawing (state.pendingSvg) goes back to: the
// one it replaced (the demo's drawing when that was a file no longer
// there).
export function pathSourceBefore(svg) {
  const was = svg.pathSource;
  return was === 'file' && !state.svgFile ? 'demo' : was || 'demo';
}

// What the next visit starts from. A drawing not yet planned is not kept
// (main.js keeps a drawing once planned or refused): nor are its path
// source and placement, but those of the drawing kept, as it was placed
// (a drawing too long for the page left its centring and fit on the good
// one).
// A machine profile on trial is not kept either (main.js takes it once it
// wrote a plan's G-code): the profile before it is, with where the drawing
// lay on that profile's bed.
function keptSettings() {
  let kept = settings;
  const trial = state.pendingProfile;
  if (trial) {
    kept = {
      ...kept,
      dialect: trial.before.dialect,
      customProfile: trial.before.customProfile,
      placement: JSON.stringify(kept.placement) === JSON.stringify(trial.placement)
        ? trial.before.placement : kept.placement,
    };
  }
  const svg = state.pendingSvg;
  if (settings.pathSource !== 'file' || !svg || !svg.before) return kept;
  return {
    ...kept,
    pathSource: pathSourceBefore(svg),
    placement: svg.before.placement,
    fit: svg.before.fit,
  };
}

export function saveSettings() {
  try {
    localStorage.setItem(STORE_KEY, JSON.stringify(keptSettings()));
  } catch {
    // Private mode or a full quota: settings just do not persist.
  }
}

// A typed number field's text as a setting: NaN while it is empty (not
// 0, which `Number('')` gives), named as empty when planning (`filled`).
const typedNumber = (v) => (String(v).trim() === '' ? NaN : Number(v));

// A number field's value; an empty field is named as such (it read as 0:
// "nozzle inner diameter (mm) = 0: must be a number greater than 0").
function filled(label, v) {
  if (v === null || v === undefined || Number.isNaN(v) || String(v).trim() === '') {
    throw new Error(`${label}: the field is empty; type a number`);
  }
  return num(v);
}

// What the library reads: a `job::JobSettings` for planning on `scan`.
export function jobSettings(scan) {
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
      // A new file is read in its own defaults (inputs.js, openScan).
      units: (scan && scan.fileDefaults) ? null : s.scanUnits || null,
      up_axis: (scan && scan.fileDefaults) ? null : s.scanUp || null,
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
      nozzle: {
        inner_diameter_mm: filled('Inner Ø d (mm)', s.nozzle.id),
        outer_diameter_mm: filled('Outer Ø do (mm)', s.nozzle.od),
      },
      process: {
        tolerance_mm: filled('Tolerance (mm)', s.process.tol),
        speed_mm_s: filled('Speed (mm/s)', s.process.speed),
        dwell_s: filled('Dwell (s)', s.process.dwell),
      },
      planner: s.planner,
      placement: {
        offset_mm: [filled('Offset X (mm)', s.placement.x), filled('Offset Y (mm)', s.placement.y)],
        rotation_deg: filled('Rotation (°)', s.placement.rot),
        scale: filled('Scale', s.placement.scale),
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
export function currentSvg() {
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

// The note that a new scan was read in its file's own units and up axis,
// not those chosen for the scan before it (inputs.js acceptScan), is past
// once the user chooses them for this one (QA round 20 F4: it went on
// naming the previous file).
function fileDefaultsNoteDone() {
  const note = $('scan-note');
  if (note.textContent.startsWith(FILE_DEFAULTS_NOTE)) note.textContent = '';
}

// How that note begins.
export const FILE_DEFAULTS_NOTE = "Read in the file's own units and up axis:";

// [element id, getter, setter, when to re-plan]: 'live' on every input
// event at once (sliders; the comparison of every planner waits for the
// release), 'typed' on every keystroke after a short pause, otherwise on
// change. Re-plans are coalesced: only the newest settings are planned.
const FIELDS = [
  ['scan-units', () => settings.scanUnits, (v) => { settings.scanUnits = v; fileDefaultsNoteDone(); }],
  ['scan-up', () => settings.scanUp, (v) => { settings.scanUp = v; fileDefaultsNoteDone(); }],
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
  ['pl-x', () => settings.placement.x, (v) => { settings.placement.x = typedNumber(v); }, 'typed'],
  ['pl-y', () => settings.placement.y, (v) => { settings.placement.y = typedNumber(v); }, 'typed'],
  ['pl-rot', () => settings.placement.rot, (v) => { settings.placement.rot = typedNumber(v); }, 'typed'],
  ['pl-scale', () => settings.placement.scale, (v) => { settings.placement.scale = typedNumber(v); settings.fit = null; }, 'typed'],
  ['pl-rot-range', () => settings.placement.rot, (v) => { settings.placement.rot = Number(v); }, 'live'],
  ['pl-scale-range', () => settings.placement.scale, (v) => { settings.placement.scale = Number(v); settings.fit = null; }, 'live'],
  ['nz-id', () => settings.nozzle.id, (v) => { settings.nozzle.id = typedNumber(v); }, 'typed'],
  ['nz-od', () => settings.nozzle.od, (v) => { settings.nozzle.od = typedNumber(v); }, 'typed'],
  ['pr-tol', () => settings.process.tol, (v) => { settings.process.tol = typedNumber(v); }, 'typed'],
  ['pr-speed', () => settings.process.speed, (v) => { settings.process.speed = typedNumber(v); }, 'typed'],
  ['pr-dwell', () => settings.process.dwell, (v) => { settings.process.dwell = typedNumber(v); }, 'typed'],
  ['planner', () => settings.planner, (v) => { settings.planner = v; }],
  ['dialect', () => settings.dialect, (v) => { settings.dialect = v; }],
  ['accept-risk', () => settings.acceptRisk, (v) => { settings.acceptRisk = v; }],
];

// A setting as its field's text.
const fieldText = (v) => (v === null || v === undefined || (typeof v === 'number' && Number.isNaN(v)) ? '' : String(v));

// Fields the page changed while the user was in them, not yet rewritten.
// A field with the caret is not rewritten: writing it drops the user's
// selection, so what they type next is added to the page's number (a
// drawing centred while Offset X was selected for typing read
// '19.99999944368998' + '20'). It is written when the user leaves it,
// unless they typed in it since: then it holds their value.
const unsynced = new Set();

// Whether `el` is a field the user may be typing in now.
const typingIn = (el) => el === document.activeElement
  && (el.tagName === 'TEXTAREA' || (el.tagName === 'INPUT' && !['checkbox', 'range'].includes(el.type)));

// Writes field `id` (element `el`) from the setting `v`, except under the
// user's cursor (see `unsynced`).
function putField(id, el, v) {
  if (el.type === 'checkbox') {
    el.checked = !!v;
    return;
  }
  const text = fieldText(v);
  if (el.value === text) {
    unsynced.delete(id);
  } else if (typingIn(el)) {
    unsynced.add(id);
  } else {
    el.value = text;
    unsynced.delete(id);
  }
}

export function writeForm() {
  for (const [id, get] of FIELDS) putField(id, $(id), get());
  syncGauge();
  syncVisibility();
}

export function syncGauge() {
  const id = Number(settings.nozzle.id);
  const od = Number(settings.nozzle.od);
  const i = GAUGES.findIndex(([, a, b]) => a === id && b === od);
  $('gauge').value = i >= 0 ? String(i) : 'custom';
}

export function syncVisibility() {
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
export function writeField(id) {
  const f = FIELDS.find((x) => x[0] === id);
  if (f) putField(id, $(id), f[1]());
}

export function bindForm() {
  for (const [id, get, set, mode] of FIELDS) {
    const el = $(id);
    // Antenna SVGs measure from their page's corner, so a new size moves
    // the antenna; keep its centre where the user placed it.
    const antennaField = /^(sp|hb|mp)-/.test(id);
    const handler = () => {
      // Typed in: the field holds the user's value, not one to write.
      unsynced.delete(id);
      // An antenna's size is physical: one the page shrank to fit the scan
      // is fitted again at its new size from the user's scale (kept
      // shrunk, an 8 mm loop was printed at 83 %, under the note of the
      // 20 mm one).
      const refit = antennaField && !!settings.fit;
      const before = antennaField && !refit ? pathCentre() : null;
      // Turned or sized here, the drawing keeps its middle where it is;
      // typed, too, while it lies where the page centred it.
      const centred = TYPED.has(id) && centredStill();
      const pivot = PIVOTED.has(id) || centred ? pivotNow() : null;
      const value = el.type === 'checkbox' ? el.checked : el.value;
      const reread = id === 'scan-units' || id === 'scan-up';
      if (reread) leaveReading();
      // A new profile has its own bed: a scan placed on it moves, and the
      // drawing with it.
      if (id === 'dialect') {
        // Chosen by the user: a profile on trial is the user's custom
        // profile from now on, whatever is chosen.
        state.pendingProfile = null;
        moveScan(() => set(value));
      }
      else set(value);
      // The user places the drawing: no centring over it.
      if (/^pl-/.test(id)) userPlaced();
      if (id === 'fid-printer' || id === 'fid-scan') pointsEdited();
      if (pivot) keepCentre(pivot);
      if (centred) {
        state.centredAt = { x: settings.placement.x, y: settings.placement.y };
        // The core centres it again at the new turn and size, as `--place
        // centre,ROT,SCALE` does: off a gap under the footprint's middle
        // too (QA round 17 F7: a Scale typed on a gear kept the drawing
        // over its bore, 66 % printed, where the CLI's moved it off). The
        // user's scale is kept; one the page fitted is fitted again.
        requestCentre(false, !settings.fit);
      }
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
      // A drawing chosen from the list starts at its own size, centred on
      // the scan; so does the demo drawing on a user's scan (QA round 5 N1:
      // it came back where the other drawing lay, at its scale, mostly off
      // the scan); on its demo part it keeps the part's own placement.
      // The demo drawing placed so by the page is not the user's again
      // until they place it (main.js's `demoOnUserScan`).
      const scan = state.pendingScan || state.scan;
      const demoOnUserScan = settings.pathSource === 'demo' && scan && scan.blob;
      if (id === 'path-source' && demoOnUserScan) {
        delete scan.placementsAtFirstPlan;
        settings.demoMoved = false;
      }
      if (id === 'path-source' && (['spiral', 'hilbert', 'monopole'].includes(settings.pathSource) || demoOnUserScan)) {
        requestCentre(true);
      }
      // Read in other units or turned up another way, the scan is another
      // scan for the drawing: where it lay and the scale fitted to the
      // misread scan say nothing of this one, unless it was read this way
      // before (the placement it had then).
      if (reread) {
        enterReading();
        writeForm();
        saveSettings();
      } else if (refit) requestCentre();
      if (mode === 'live') {
        state.interacting = true;
        hooks.planNow();
      } else {
        hooks.schedulePlan(mode === 'typed' ? 120 : 350);
      }
    };
    el.addEventListener(mode || el.tagName === 'TEXTAREA' ? 'input' : 'change', handler);
    // Left without typing: the page's value it was not written with.
    el.addEventListener('blur', () => {
      if (unsynced.delete(id)) el.value = fieldText(get());
    });
    if (mode === 'live') {
      // The slider is let go: plan once more with the comparison.
      el.addEventListener('change', () => hooks.endInteraction());
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
    hooks.schedulePlan(0);
  });
  const dialect = $('dialect');
  for (const d of dialects()) dialect.add(new Option(d, d));
  const planner = $('planner');
  for (const p of planners()) planner.add(new Option(p, p));
  const plot = $('plot-series');
  plot.add(new Option('every planner', 'all'));
  for (const p of planners()) plot.add(new Option(p, p));
  plot.addEventListener('change', () => hooks.showErrorPlot());
  const demo = $('demo-part');
  for (const p of demoParts()) {
    const o = new Option(p.name, p.name);
    o.title = p.description;
    demo.add(o);
  }
  demo.addEventListener('change', () => hooks.loadDemo(demo.value));
  syncProfileOption();
}

// The dialect list's entry for the user's own profile, if one is loaded.
export function syncProfileOption() {
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

// The centre of the path's box as imported (before placement), or null;
// found once per drawing (a slider asks at every step).
let boxCentre = { key: null, centre: null };
function pathCentre() {
  try {
    const svg = currentSvg();
    if (boxCentre.key !== svg.key) {
      const b = pathBounds(svg.bytes, svg.name);
      boxCentre = { key: svg.key, centre: [(b[0] + b[2]) / 2, (b[1] + b[3]) / 2] };
    }
    return boxCentre.centre;
  } catch {
    return null;
  }
}

// The fields that turn and size the drawing. The core turns and scales a
// drawing about its SVG origin (the CLI's --place), most often a corner:
// turned there, a drawing centred on the scan swung off it (at 180 deg
// only a corner of it was printed). The page keeps the middle of the
// drawing's box where it is instead, by moving the offset with the turn
// or size: the placement handed to the core means what it always did.
// The typed Rotation and Scale fields stay the numbers of --place, as
// typed beside a typed offset (the CLI's placement, tests/browser/upload).
const PIVOTED = new Set(['pl-rot-range', 'pl-scale-range']);

// The typed Rotation and Scale keep the middle too while the drawing lies
// where the page centred it (QA round 16 F8: a Scale typed after the
// page centred a drawing grew it from its SVG origin, off the scan, where
// the CLI's --place centre,ROT,SCALE centres it at that scale). Once its
// offset is moved or typed, they are the numbers of --place again.
const TYPED = new Set(['pl-rot', 'pl-scale']);
const centredStill = () => !!state.centredAt && num(settings.placement.x) === num(state.centredAt.x)
  && num(settings.placement.y) === num(state.centredAt.y);

// The middle kept over a run of turns and sizes: {svg, centre (the box's,
// drawing frame), world (where it is on the printer), origin (the
// placement the run started from), x, y, rot, scale (the placement the
// last step left)}. Each step is placed from the same point, so a slider
// dragged back and forth does not creep, and back at the run's turn and
// size the drawing is exactly where it started.
let pivotRun = null;

// To 0.01 mm, as a drag or an arrow key places the drawing (view.js).
const round2 = (v) => Math.round(v * 100) / 100;

// Whether the placement value `v` (a setting, maybe text being typed) is
// `was`, or not a number yet (a '-' typed before the digits).
const sameOrUntyped = (was, v) => num(v) === was || !Number.isFinite(num(v));

// The middle to keep for a turn or size about to be set, or null.
function pivotNow() {
  let svg;
  try {
    svg = currentSvg();
  } catch {
    return null;
  }
  const centre = pathCentre();
  const p = settings.placement;
  const [x, y, rot, scale] = [p.x, p.y, p.rot, p.scale].map(num);
  if (!centre || !Number.isFinite(x) || !Number.isFinite(y)) return null;
  const r = pivotRun;
  if (r && r.svg === svg.key && r.x === x && r.y === y && sameOrUntyped(r.rot, p.rot)
    && sameOrUntyped(r.scale, p.scale)) return r;
  const v = placed(centre);
  if (!v.every(Number.isFinite)) return null;
  const at = { x, y, rot, scale };
  return {
    svg: svg.key, centre, world: [x + v[0], y + v[1]], origin: at, ...at,
  };
}

// The turn or size was set: the offset that puts the middle back.
function keepCentre(pivot) {
  const p = settings.placement;
  const rot = num(p.rot);
  const scale = num(p.scale);
  const v = placed(pivot.centre);
  if (!v.every(Number.isFinite)) {
    // Not a number yet: the drawing waits where it is.
    pivotRun = pivot;
    return;
  }
  const o = pivot.origin;
  const back = rot === o.rot && scale === o.scale;
  const x = back ? o.x : round2(pivot.world[0] - v[0]);
  const y = back ? o.y : round2(pivot.world[1] - v[1]);
  p.x = x;
  p.y = y;
  pivotRun = {
    ...pivot, x, y, rot, scale,
  };
  writeField('pl-x');
  writeField('pl-y');
}

// A drawing-frame vector after the placement's rotation and scale.
function placed([x, y]) {
  const s = num(settings.placement.scale);
  const a = (num(settings.placement.rot) * Math.PI) / 180;
  return [s * (Math.cos(a) * x - Math.sin(a) * y), s * (Math.sin(a) * x + Math.cos(a) * y)];
}
