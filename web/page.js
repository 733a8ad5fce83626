// What the page's modules share: finding and making elements, the page's
// state and settings (and the machine profile they choose), number formats,
// and the hooks main.js fills in. Modules import this one and each other
// only in one direction (the single-file build, scripts/single-file.mjs,
// joins them in dependency order and allows no cycle); a call back up (to
// plan again, say) goes through `hooks`.

export const $ = (id) => document.getElementById(id);

// A new element with its text, and its class and id when given (text from
// files and errors is set as text, never as HTML).
export function el(tag, text, cls, id) {
  const e = document.createElement(tag);
  if (text !== undefined) e.textContent = text;
  if (cls) e.className = cls;
  if (id) e.id = id;
  return e;
}

// A table cell appended to the row `tr`.
export function cell(tr, text, cls, title) {
  const td = el('td', text, cls);
  if (title) td.title = title;
  tr.append(td);
  return td;
}

// A legend entry: a swatch of the CSS colour `background` and its label.
export function swatch(background, label) {
  const sw = el('i', undefined, 'sw');
  sw.style.background = background;
  const li = el('li');
  li.append(sw, label);
  return li;
}

// The settings the user edits (persisted in localStorage by settings.js):
// one object for the page's life, filled by loadSettings.
export const settings = {};

// Calls into modules that import this one's users: schedulePlan(delay),
// planNow(), requestPlan(), endInteraction(), loadDemo(part),
// showErrorPlot(), viewShowsChanged(), viewClick(px, py) -> handled,
// planShown(plan), currentInputs() -> what a plan now is planned from.
export const hooks = {};

// The machine profile a plan or preview is written with: `dialect` a
// built-in name or the user's profile as JSON text, `file` that profile's
// file name (for its errors), `name` the name the page shows.
export function profile() {
  const cp = settings.dialect === 'custom' && settings.customProfile;
  return cp
    ? { dialect: cp.text, file: cp.file, name: cp.name }
    : { dialect: settings.dialect, file: undefined, name: settings.dialect };
}

// The core's messages are shared with the command line, and some say how
// to fix a problem with a flag. Where the page has a control for it, the
// page names the control instead (a flag means nothing in the page). A
// message the core words otherwise is shown as it is.
const PAGE_WORDS = [
  [/\(--place-scan bed\)/g, "('Place on the bed')"],
  [/\(--place-scan bed,DX,DY,DZ\[,ROT\]\)/g, '(Move X, Y and Z)'],
  [/\(the DZ of --place-scan bed,DX,DY,DZ\)/g, '(Move Z)'],
  [/Give a DZ of 0 or more/g, 'Give a Move Z of 0 or more'],
  [/give it with the placement \(--place centre,ROT,SCALE\), which is kept as given/g,
    'type it in Scale, which is planned as typed'],
  [/\(a smaller SCALE or another ROT in --place centre,ROT,SCALE\)/g, '(a smaller Scale, or another Rotation)'],
  [/\(a smaller SCALE in --place centre,ROT,SCALE\)/g, '(a smaller Scale)'],
  [/\(--place centre puts the drawing on the scan's footprint\)/g,
    "('Centre on scan' puts the drawing on the scan's footprint)"],
  [/\(--up-axis y, z or -z; glTF files are \+Y up\)/g, '(Up axis; glTF files are +Y up)'],
  [/\(--up-axis\)/g, '(Up axis)'],
  [/\(--up-axis reads \+Z, \+Y or -Z as up\)/g, '(Up axis offers +Z, +Y and -Z)'],
  [/\(--up-axis (-?)([yz])\)/g, (_, sign, a) => `(Up axis: ${sign || '+'}${a.toUpperCase()})`],
  [/\(--up-axis; a depth camera's frame, z the distance from the camera, is -z\)/g,
    "(Up axis; a depth camera's frame, z the distance from the camera, is -Z)"],
  [/\(--scan-units (\w+) --up-axis (-?)([yz])\)/g, (_, u, sign, a) => `(Units: ${u}; Up axis: ${sign || '+'}${a.toUpperCase()})`],
  [/\(--scan-units (\w+)\)/g, '(Units: $1)'],
  [/\(--scan-units (\w+) if it really is this (small|large)\)/g, '(Units: $1 if it really is this $2)'],
  [/\(--max-edge\)/g, '(Cloud max edge)'],
  [/check it with the program's \(--nozzle-od ([\d.]+) --tol ([\d.]+)\)/g,
    "check it with the program's (Nozzle and process: outer diameter $1 mm, tol $2 mm)"],
  [/give it as the scan \(--scan\), and the G-code file the printer runs as the program/g,
    'open it as the scan, and check the G-code file the printer runs'],
  [/\(--accept-risk\)/g, "(the box 'write G-code even where it is refused (at my risk)')"],
  [/keep it next to \S+ \(command line\) or select both files together \(page\)/g, 'select both files together'],
  [/e\.g\. placed on the bed: --place-scan bed\)/g, "e.g. placed on the bed: 'Place on the bed')"],
  [/\(--dialect ([\w-]+)\)/g, '(Dialect: $1)'],
  [/\(--profile with that profile's file\)/g, "('Machine profile…' with that profile's file)"],
];

export function pageText(text) {
  let t = String(text);
  for (const [from, to] of PAGE_WORDS) t = t.replace(from, to);
  return t;
}

export const num = (v) => (v === null || v === '' || v === undefined ? NaN : Number(v));

export const fmt = (v, d = 3) => (v === null || v === undefined || !Number.isFinite(v) ? '∞' : v.toFixed(d));

// A point as the core's messages write it.
export const fmtPoint = (p) => `(${p.map((v) => fmt(v)).join(', ')})`;

export const state = {
  // The accepted scan {key, name, size, blob}: blob is the user's File
  // (handed to the worker, which reads it) or null for the demo.
  scan: null,
  pendingScan: null, // a scan loaded but not yet read by the worker
  svgFile: null, // the accepted SVG file {key, name, bytes}
  pendingSvg: null,
  // A machine profile opened but not yet shown to write this job's G-code
  // ({profile, before, placement, inputs}; inputs.js openProfile): the
  // profile used before it (`before`) comes back if it cannot (main.js).
  pendingProfile: null,
  // The error on screen says why a profile was not taken: the plan with
  // the profile kept does not clear it (main.js).
  keepProfileError: false,
  svgMade: null, // the last generated path {key, name, bytes} (antennas, demo)
  nextKey: 1,
  module: null,
  worker: null,
  sentSvgKey: null, // the drawing whose bytes the current worker holds
  busy: null, // the plan request in flight
  queued: false, // a newer request waits for it: only the newest is planned
  // Files chosen whose bytes are still being read (inputs.js): until then
  // the plan on screen is the one before them.
  reading: 0,
  // Every change of an input or setting counts up; a plan is offered for
  // download only if nothing changed since it was requested.
  gen: 0,
  planId: 0,
  lastPlan: null,
  // A refused plan's paths where the drawing lay ({view, placement, mesh,
  // inputs}), shown instead of the last plan's (QA round 7 F3; see
  // view.js showRefused, dropRefused).
  refused: null,
  // The last plan refused for the inputs as they were then ({inputs,
  // title, status}): a scan file that then cannot be read changes none of
  // them, and the refusal stands (QA round 15 F1: the status said
  // "re-planning" for good and the failed comparison went).
  lastRefusal: null,
  // Workers started so far: a plan's report is asked of the worker that
  // made it (a restarted one holds none).
  workerGen: 0,
  reportId: 0, // the report request in flight counts up
  reportAsks: new Map(), // request id -> {resolve, reject}
  // Scan files' SHA-256s by file key (Uint8Array), and those being found
  // by the hashing worker (main.js's hashScan).
  digests: new Map(),
  hashing: new Map(),
  hashWorker: null,
  // The last comparison of every planner {rows, series, gen} (series: the
  // per-point errors of each planner, for the plot; null after a failed plan).
  lastComparison: null,
  demoParts: new Map(), // demo part name -> its drawing and settings (wasm demoPart)
  checkId: 0, // the G-code check in flight
  checking: null, // {id, name} of the check in flight
  checkMoves: null, // the last checked program's {moves, kinds} for the view
  checked: null, // the last file checked clear or not {file, name, nozzle, tol} (the preview reads it)
  // The G-code file last asked to be checked {file, name, frame}, checked
  // again when a plan leaves the worker's scan in another frame; the
  // frame the worker's scan is in (`busy.checkFrame` of the last plan).
  checkSource: null,
  // The check's verdict while a plan in flight may move the scan
  // (`checkFrameLeaving`).
  checkVerdictKept: null,
  // The offset {x, y} the page last centred the drawing at (the core's
  // centring, or kept centred by a typed Rotation or Scale since).
  centredAt: null,
  workerFrame: null,
  // What the view draws as its lines: 'plan' (Ta and T*), 'check' (a
  // checked program's moves) or 'preview' (the previewed program, with
  // the nozzle).
  viewShows: 'plan',
  interacting: false, // a drag or slider in progress: skip the comparison
  centre: null, // {token}: the next plan centres the drawing on the scan (placement.js)
  info: null, // the scan as the worker read it
  // Set when the scan's registration failed after `info` was read (the
  // fiducials do not fit): the header says so instead of the last one.
  regFailed: false,
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
