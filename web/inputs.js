// Inputs and uploads: a scan, an SVG, a machine profile or a G-code file
// opened or dropped on the page, the demo parts, and the last scan and SVG
// kept in this browser (store.js) and reopened on the next visit.
import { checkProfile, checkScanSize, checkSvgSize } from '../pkg/pcpp.js';
import { checkGcodeFile, drawCheckedMoves } from './check.js';
import { $, hooks, settings, state } from './page.js';
import {
  SCAN_PLACE_DEFAULT, cancelCentre, moveScan, requestCentre, setNote, showFitNote, showScanPlacement,
  userPlacements,
} from './placement.js';
import {
  FILE_DEFAULTS_NOTE, demoInfo, demoUiSettings, pathSourceBefore, saveSettings, syncProfileOption, writeForm,
} from './settings.js';
import { clearError, showError } from './status.js';
import { keepInput, keptInput } from './store.js';

// Set while a kept scan is reopened: still set at the next start means the
// page closed or crashed reading it, and it is not reopened again.
const RESTORING_KEY = 'pcpp.restoring.v1';

// G-code programs a user may check against the scan (by their extension).
const GCODE_FILE = /\.(gcode|gco|g|nc|ngc|tap)$/i;
// A .txt is either: a G-code program or a point cloud (XYZ rows), told
// apart by its first lines (textKind).
const TEXT_FILE = /\.txt$/i;
// Scans, by the extensions the core reads (a glTF first: only it names
// other files, its buffers in .bin files).
const GLTF_FILE = /\.(gltf|glb)$/i;
const SCAN_FILE = /\.(gltf|glb|obj|ply|stl|xyz|csv|txt|asc|pts|pcd)$/i;
// (.svgz: Inkscape's compressed SVG, a drawing the core names as such.)
const SVG_FILE = /\.svgz?$/i;
// A machine profile (the Machine panel's "Open profile…" reads the same).
const PROFILE_FILE = /\.json$/i;

// Whether `name` is a scan's by its extension (a file of another kind
// that could not be read is an error about its kind, not about a scan).
export const isScanName = (name) => SCAN_FILE.test(name);

// How much of a .txt is read to tell what it is: a few dozen lines. Only
// this head passes through this thread; a scan's bytes are still read by
// the worker.
const SNIFF_BYTES = 8192;
const SNIFF_LINES = 100;
// A point cloud's row: 2 to 6 numbers (x y z, then normals or colour)
// separated by spaces, tabs, commas or semicolons.
const NUMBER = /^[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$/;
// A G-code line: a word first (G1, M104, T0, N10), a comment, or an
// address letter with its number anywhere (X1.2 on a modal line).
const GCODE_START = /^[GMTN;(]/i;
const GCODE_WORD = /[A-Z]\s*[-+]?(\d|\.\d)/i;

// What the text `head` (a .txt's first bytes) holds, line by line:
// 'gcode' or 'scan' (a point cloud), by which kind of line is in the
// majority; lines of neither kind (a cloud's header "x y z", "#"
// comments) do not count. With neither it is taken for G-code, whose
// check names what it cannot read.
function textKind(head, cut = false) {
  // A drawing saved as .txt (an SVG's XML).
  if (/^\uFEFF?\s*<(\?xml|svg|!DOCTYPE svg|!--)/i.test(head)) return 'svg';
  const lines = head.split(/\r?\n|\r/);
  // A head cut from a longer file ends in a partial line.
  if (cut) lines.pop();
  let gcode = 0;
  let cloud = 0;
  let seen = 0;
  for (const raw of lines) {
    const line = raw.trim();
    if (!line) continue;
    if (++seen > SNIFF_LINES) break;
    const fields = line.split(/[\s,;]+/).filter((f) => f);
    if (fields.length >= 2 && fields.length <= 6 && fields.every((f) => NUMBER.test(f))) cloud++;
    else if (GCODE_START.test(line) || GCODE_WORD.test(line)) gcode++;
  }
  return cloud > gcode ? 'scan' : 'gcode';
}

// What a dropped or opened file is: 'svg', 'gcode', 'profile' or 'scan'
// (a scan, or a file a scan names), a .txt by its first lines.
async function fileKind(file) {
  if (SVG_FILE.test(file.name)) return 'svg';
  if (GCODE_FILE.test(file.name)) return 'gcode';
  if (PROFILE_FILE.test(file.name)) return 'profile';
  if (!TEXT_FILE.test(file.name)) return 'scan';
  let head;
  try {
    head = await file.slice(0, SNIFF_BYTES).text();
  } catch {
    // Unreadable: the check says so, naming the file.
    return 'gcode';
  }
  return textKind(head, file.size > SNIFF_BYTES);
}

// Files opened together (selected at once, or dropped): drawings, G-code
// programs and machine profiles (.json) each on their own; of the others, one is the scan and
// the rest go with it, for the files it names (a .gltf's .bin buffers:
// the worker reads only those the scan needs). `scans`: chosen through
// "Open scan…", every file is the scan or goes with it (a .txt there is
// a point cloud, never a program to check).
function openFiles(files, scans = false) {
  // Only a .txt is read before it is opened: the others open at once, in
  // the order they came (a scan, then a drawing right after it).
  if (!scans && files.some((f) => TEXT_FILE.test(f.name))) {
    reading(() => Promise.all(files.map(fileKind))).then((kinds) => openKinds(files, kinds));
    return;
  }
  openKinds(files, files.map((f) => {
    if (scans) return 'scan';
    if (SVG_FILE.test(f.name)) return 'svg';
    if (PROFILE_FILE.test(f.name)) return 'profile';
    return GCODE_FILE.test(f.name) ? 'gcode' : 'scan';
  }));
}

// `read()`'s promise, counted as a file being read (state.reading) until
// it settles: until then the plan on screen is the one before the file.
async function reading(read) {
  state.reading++;
  try {
    return await read();
  } finally {
    state.reading--;
  }
}

function openKinds(files, kinds) {
  const rest = [];
  files.forEach((f, i) => {
    if (kinds[i] === 'svg') openSvg(f);
    else if (kinds[i] === 'gcode') checkGcodeFile(f);
    else if (kinds[i] === 'profile') openProfile(f);
    else rest.push(f);
  });
  if (rest.length === 0) return;
  const scan = rest.find((f) => GLTF_FILE.test(f.name)) || rest.find((f) => SCAN_FILE.test(f.name)) || rest[0];
  openScan(scan, rest.filter((f) => f !== scan));
  // The page reads one scan: the others selected with it are not read
  // (only the files a scan names are).
  const others = rest.filter((f) => f !== scan && SCAN_FILE.test(f.name));
  if (others.length) {
    $('scan-note').textContent = `${others.length + 1} scans selected at once: ${scan.name} was opened, `
      + `${others.map((f) => f.name).join(', ')} ${others.length > 1 ? 'were' : 'was'} not (open one scan at a time).`;
  }
}

// `external`: the files opened with it (Files), for those it names.
function openScan(file, external) {
  // Past the page's limit the file is refused before a byte is read, and
  // the loaded scan stays.
  try {
    checkScanSize(file.name, file.size);
  } catch (e) {
    showError(`Could not open the scan ${file.name}`,
      `${e.message}\nStill using ${state.scan ? state.scan.name : 'no scan'}.`, file.name);
    return;
  }
  // The File itself goes to the worker, which reads it into wasm memory:
  // the scan's bytes never pass through this thread or a JS string.
  const entry = {
    key: `file-${state.nextKey++}`, name: file.name, size: file.size, blob: file, external,
  };
  $('scan-note').textContent = '';
  state.pendingScan = entry;
  // Units and an up axis chosen for the scan loaded before belong to that
  // file: another file is read in its own defaults (a scan read in inches
  // last time is not the next one's unit), and the choice is dropped once
  // it is read (kept while a file that cannot be read changes nothing).
  // One chosen while the demo part was shown is taken as meant for this
  // file (the demo is the page's part, not the user's).
  const prev = state.scan;
  if ((settings.scanUnits || settings.scanUp) && prev && !prev.part) {
    entry.fileDefaults = { units: settings.scanUnits, up: settings.scanUp, from: prev.name };
  }
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
  hooks.schedulePlan(0);
}

async function openSvg(file) {
  try {
    checkSvgSize(file.name, file.size);
  } catch (e) {
    showError(`Could not open the SVG ${file.name}`, e.message, file.name);
    return;
  }
  // The user may place the drawing while its bytes are read (type in
  // Offset X right after choosing the file): that placement stands, it is
  // not centred over (a typed 20 became the centre's 19.99999944).
  const placed = userPlacements();
  let bytes;
  try {
    // Bytes go to wasm as a Uint8Array, never through a JS string.
    bytes = new Uint8Array(await reading(() => file.arrayBuffer()));
  } catch (e) {
    showError(`Could not read ${file.name}`, e.message);
    return;
  }
  // The path source it replaces, taken back if it cannot be read, and
  // that drawing's placement: kept in the browser until this one is
  // planned or refused (main.js keeps it then; a drawing that cannot be
  // read, or is too long for the page, is not reopened, so neither is
  // where it was centred), and taken back if this one is cancelled.
  const prev = state.pendingSvg;
  const was = prev ? prev.pathSource : settings.pathSource;
  const before = prev ? prev.before : { placement: { ...settings.placement }, fit: settings.fit };
  state.pendingSvg = {
    key: `file-${state.nextKey++}`, name: file.name, bytes, pathSource: was, before,
  };
  settings.pathSource = 'file';
  // A new drawing lands on the scan, unless the user placed it meanwhile.
  if (userPlacements() === placed) requestCentre(true);
  saveSettings();
  writeForm();
  hooks.schedulePlan(0);
}

// What a .json that pcpp wrote, and that is not a profile, is: a dropped
// demo folder's report or registration was read as a profile, and refused
// for a missing field. Null for anything else (the core checks it).
function otherJson(text) {
  let v;
  try {
    v = JSON.parse(text);
  } catch {
    return null;
  }
  if (!v || typeof v !== 'object' || Array.isArray(v)) return null;
  if (v.program === 'pcpp') {
    return `It is a ${v.planners ? 'comparison' : 'plan report'} that pcpp wrote; the page does not read reports back.`;
  }
  if ('printer_points' in v && 'registration' in v) {
    return 'It is the registration pcpp demo wrote (fiducials and G): type its printer points in '
      + 'Registration, Printer points P.';
  }
  return null;
}

// The dialect list's entry in use, as the page names it.
const profileLabel = () => $('dialect').selectedOptions[0]?.textContent || settings.dialect;

// A user's machine profile: checked by the core (the error names the file
// and the field); a bad file changes nothing, the previous dialect stays.
// A valid one is used on trial (state.pendingProfile) until a plan writes
// its G-code: one that cannot write this job's (its end block homes, or
// moves into the part; its travel height leaves the build volume) is not
// taken either, and the profile used before it comes back (main.js).
async function openProfile(file) {
  let text;
  try {
    text = await reading(() => file.text());
  } catch (e) {
    showError(`Could not read ${file.name}`, e.message);
    return;
  }
  const other = otherJson(text);
  if (other) {
    showError(`${file.name} is not a machine profile`,
      `${other}\nStill using ${profileLabel()}.`, file.name);
    return;
  }
  let name;
  try {
    name = checkProfile(text, file.name);
  } catch (e) {
    showError(`Could not use the machine profile ${file.name}`,
      `${e.message}\nStill using ${profileLabel()}.`, file.name);
    return;
  }
  clearError();
  // What the page goes back to if it cannot write this job's G-code: the
  // profile before it (the one before a profile still on trial), where
  // the drawing lay, and whether it wrote the plan on screen for the
  // settings as they are (the plan goes once the scan is read again on
  // the new bed).
  const trial = state.pendingProfile;
  const inputs = hooks.currentInputs();
  const before = trial ? trial.before : {
    dialect: settings.dialect,
    customProfile: settings.customProfile,
    placement: { ...settings.placement },
    planned: !!inputs && !!state.lastPlan && state.lastPlan.inputs === inputs,
  };
  // Its bed may differ: a scan placed on the bed moves with it.
  moveScan(() => {
    settings.customProfile = { name, file: file.name, text };
    settings.dialect = 'custom';
  });
  state.pendingProfile = {
    profile: settings.customProfile, before, placement: { ...settings.placement }, inputs: hooks.currentInputs(),
  };
  syncProfileOption();
  showScanPlacement();
  saveSettings();
  writeForm();
  hooks.schedulePlan(0);
}

// The profile on trial wrote a plan's G-code (or failed for something
// else than itself): it is the user's profile, kept over a reload.
export function adoptPendingProfile() {
  if (!state.pendingProfile) return;
  state.pendingProfile = null;
  saveSettings();
}

// The profile on trial cannot write this job's G-code: the one used before
// it comes back (built-in or the user's), with the drawing where it lay
// if it was not moved since. Returns how the dialect list names it.
export function dropPendingProfile() {
  const trial = state.pendingProfile;
  if (!trial) return profileLabel();
  state.pendingProfile = null;
  const { before } = trial;
  const unmoved = JSON.stringify(settings.placement) === JSON.stringify(trial.placement);
  moveScan(() => {
    settings.dialect = before.dialect;
    settings.customProfile = before.customProfile;
  });
  // (As it was, not carried back and rounded.)
  if (unmoved) settings.placement = { ...before.placement };
  syncProfileOption();
  showScanPlacement();
  saveSettings();
  writeForm();
  return profileLabel();
}

export function bindFiles() {
  $('check-draw').addEventListener('click', () => drawCheckedMoves(state.viewShows !== 'check'));
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
  // The scan input takes several files at once: a .gltf with its .bin.
  const scanInput = $('scan-input');
  scanInput.addEventListener('change', () => {
    if (scanInput.files) openFiles([...scanInput.files], true);
    scanInput.value = '';
  });
  const svgInput = $('svg-input');
  svgInput.addEventListener('change', () => {
    const f = svgInput.files && svgInput.files[0];
    if (f) openFiles([f]);
    svgInput.value = '';
  });
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
    openFiles([...e.dataTransfer.files]);
  });
}

// A demo part's scan: the worker makes its bytes itself.
export function demoScanEntry(part) {
  const info = demoInfo(part);
  return { key: `demo-${info.name}`, name: info.scan_name, size: 0, blob: null, part: info.name };
}

// Loads a demo part: its scan, drawing, placement and fiducials (the test
// part's three holes; the other parts are made in the printer frame).
export function loadDemo(part = settings.demoPart) {
  const demo = demoUiSettings(part);
  settings.demoPart = demo.demoPart;
  settings.fidSource = demo.fidSource;
  settings.fidMethod = demo.fidMethod;
  settings.fidPrinterText = demo.fidPrinterText;
  settings.pathSource = 'demo';
  settings.placement = demo.placement;
  settings.fit = null;
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
  $('scan-note').textContent = '';
  state.svgFile = null;
  state.pendingSvg = null;
  keep('scan', null);
  keep('svg', null);
  saveSettings();
  writeForm();
  hooks.schedulePlan(0);
}

// A file that could not be read changes nothing: no centring for it (a
// new drawing opened with it is still centred).
export function dropCentre() {
  if (state.centre && !state.centre.fresh) cancelCentre();
}

// The pending scan is not read after all (its request was cancelled):
// the scan before it stays, and a kept scan being reopened is no longer
// kept (as when it cannot be read).
export function dropPendingScan() {
  const scan = state.pendingScan;
  if (!scan) return;
  if (scan.restored) {
    endRestoring();
    keep('scan', null);
  }
  state.pendingScan = null;
  dropCentre();
  $('scan-name').textContent = state.scan.name;
  showScanPlacement();
}

// The pending drawing is not planned after all (its request was
// cancelled): back to the path before it, where it was placed.
export function dropPendingSvg() {
  const svg = state.pendingSvg;
  if (!svg) return;
  state.pendingSvg = null;
  cancelCentre();
  settings.pathSource = pathSourceBefore(svg);
  if (svg.before) {
    settings.placement = { ...svg.before.placement };
    settings.fit = svg.before.fit;
    showFitNote();
  }
  saveSettings();
  writeForm();
}

// The pending scan was read: it becomes the scan, and the demo's fiducial
// settings it was read without are dropped for good. `info`, the scan as
// the worker read it, names the files it was read from besides itself
// (by the paths the scan gives; the browser's files have names only):
// those are kept with it, not every file opened with it.
export function acceptScan(info) {
  // A new file accepted: a file the page could not read before it is
  // past.
  clearError('file');
  const scan = state.pendingScan;
  state.scan = scan;
  state.pendingScan = null;
  if (info) {
    const used = new Set(info.external_files.map((f) => f.name.split('/').pop()));
    scan.external = (scan.external || []).filter((f) => used.has(f.name));
  }
  if (scan.restored) endRestoring();
  else keep('scan', scan.blob ? { name: scan.name, file: scan.blob, external: scan.external || [] } : null);
  if (scan.unregistered) {
    delete scan.unregistered;
    settings.fidSource = 'none';
    // The demo part's printer points with it: shown, they looked like a
    // registration of the new scan.
    settings.fidPrinterText = '';
    saveSettings();
    writeForm();
  }
  if (scan.fileDefaults) {
    const { units, up, from } = scan.fileDefaults;
    delete scan.fileDefaults;
    settings.scanUnits = '';
    settings.scanUp = '';
    saveSettings();
    writeForm();
    const chosen = [units && `units ${units}`, up && `up axis ${up.startsWith('-') ? '' : '+'}${up.toUpperCase()}`].filter(Boolean).join(' and ');
    $('scan-note').textContent = `${FILE_DEFAULTS_NOTE} ${chosen} were chosen for ${from} `
      + '(Units and Up axis above set them for this file).';
  }
  if (scan.asScanned) {
    // A new scan is read as it is; the banner offers to place it.
    delete scan.asScanned;
    settings.scanPlace = { ...SCAN_PLACE_DEFAULT };
    saveSettings();
  }
  showScanPlacement();
}

// ---------- the last inputs, kept for the next visit ----------

// Writes to the browser's store in the background; `state.keeping` counts
// the writes not finished (tests wait for 0 before reloading).
export function keep(kind, value) {
  state.keeping++;
  keepInput(kind, value)
    .catch(() => {
      // Not kept (quota, private mode): the next visit starts without it.
    })
    .finally(() => { state.keeping--; });
}

export function endRestoring() {
  try {
    localStorage.removeItem(RESTORING_KEY);
  } catch {
    // Nothing to clear.
  }
}

// Reopens the scan and SVG of the last visit, if the browser kept them.
export async function restoreInputs() {
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
  // The files kept with it (a .gltf's .bin buffers); a scan kept without
  // one it needs fails to reopen, naming it.
  const external = Array.isArray(scan.external) ? scan.external.filter((f) => f instanceof Blob) : [];
  state.pendingScan = {
    key: `file-${state.nextKey++}`, name: scan.name, size: scan.file.size, blob: scan.file, external, restored: true,
  };
  $('scan-name').textContent = `${state.scan.name} (reopening ${scan.name}…)`;
}
